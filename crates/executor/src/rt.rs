//! The real-time side: once per period take exactly one set-point from the ring and hand it
//! to the drive; report what was applied. Never allocates, locks or blocks (the drive must not
//! either). An empty ring while the machine moves is an underrun: counted, and turned into
//! the joints' jerk-limited stop ([`crate::stop`]) from the last set-point — never a jump.
//! An empty ring at rest is just idling: the last position is held.
//!
//! [`RtLoop::tick`] is one period with no clock, so tests drive it on a virtual clock;
//! [`RtLoop::run`] paces it with a [`Clock`] on its own thread.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use tezgah_kinematics::Joints;

use crate::drive::{Drive, DriveFault};
use crate::ring::{RtEnds, RtReport, RtState, Slot};
use crate::setpoint::SetPoint;
use crate::stop::PlayedStop;
pub use crate::stop::StopLimits;

/// The real-time loop's counters.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RtCounters {
    pub periods: u64,
    /// Set-points taken from the ring and applied.
    pub delivered: u64,
    /// Periods the ring was empty while the machine moved.
    pub underruns: u64,
    /// Set-points discarded while halted.
    pub discarded: u64,
    /// Reports dropped because the report ring was full.
    pub reports_dropped: u64,
}

/// The real-time loop with its drive.
pub struct RtLoop<D: Drive> {
    ends: RtEnds,
    drive: D,
    period: f64,
    limits: StopLimits,
    last: SetPoint,
    state: RtState,
    /// The underrun stop being played, and the line it stops on.
    stop: Option<(PlayedStop, u32)>,
    fault: Option<DriveFault>,
    counters: RtCounters,
    /// Wake-up lateness so far ([`RtLoop::run`] records it; reports carry it).
    jitter: Jitter,
}

fn moving(sp: &SetPoint) -> bool {
    sp.velocity.as_slice().iter().any(|v| *v != 0.0)
        || sp.acceleration.as_slice().iter().any(|a| *a != 0.0)
}

impl<D: Drive> RtLoop<D> {
    /// `start` is where the machine stands (the first period holds it until set-points come).
    pub fn new(ends: RtEnds, drive: D, period: f64, limits: StopLimits, start: Joints) -> Self {
        RtLoop {
            ends,
            drive,
            period,
            limits,
            last: SetPoint::at_rest(0, 0, start),
            state: RtState::Running,
            stop: None,
            fault: None,
            counters: RtCounters::default(),
            jitter: Jitter::default(),
        }
    }

    pub fn counters(&self) -> RtCounters {
        self.counters
    }

    pub fn state(&self) -> RtState {
        self.state
    }

    /// The drive (to read a simulated drive's record after a run).
    pub fn drive(&self) -> &D {
        &self.drive
    }

    /// The last set-point applied.
    pub fn last(&self) -> &SetPoint {
        &self.last
    }

    /// One period.
    pub fn tick(&mut self) {
        let sp = match self.state {
            RtState::Running => self.take(),
            RtState::Stopping => self.stopping(),
            RtState::Halted => {
                self.discard();
                self.last
            }
        };
        let status = self.drive.apply(&sp);
        if let Some(f) = status.fault {
            if self.fault.is_none() {
                self.fault = Some(f);
                // A drive fault stops the machine where it is: the drive has refused the
                // motion, commanding a stop profile to it would be meaningless.
                self.last = SetPoint::at_rest(sp.index, sp.line, status.position);
                self.state = RtState::Halted;
            }
        } else {
            self.last = sp;
        }
        self.counters.periods += 1;
        let report = RtReport {
            period: self.counters.periods,
            index: sp.index,
            line: sp.line,
            state: self.state,
            commanded: sp.position,
            velocity: sp.velocity,
            measured: status.position,
            underruns: self.counters.underruns,
            fault: self.fault,
            late_worst: self.jitter.worst,
            late_over_half: self.jitter.over_half,
        };
        if self.ends.reports.push(report).is_err() {
            self.counters.reports_dropped += 1;
        }
    }

    fn take(&mut self) -> SetPoint {
        loop {
            match self.ends.setpoints.pop() {
                Ok(Slot::Point(sp)) => {
                    self.counters.delivered += 1;
                    return sp;
                }
                // Already running: nothing to re-arm.
                Ok(Slot::Rearm) => continue,
                Err(_) if moving(&self.last) => {
                    self.counters.underruns += 1;
                    // From the last set-point's own state (exact for the played positions, see
                    // `setpoint::History`): within the limits from the first period.
                    let stop = PlayedStop::new(&self.last, &self.limits, self.period);
                    self.stop = Some((stop, self.last.line));
                    self.state = RtState::Stopping;
                    return self.stopping();
                }
                // Idle: the last set-point again (same index: no new set-point was due).
                Err(_) => return self.last,
            }
        }
    }

    fn stopping(&mut self) -> SetPoint {
        // Set-points still arriving belong to the path the stop has left.
        self.discard();
        let Some((stop, line)) = self.stop.as_mut() else {
            self.state = RtState::Halted;
            return self.last;
        };
        let line = *line;
        let Some(s) = stop.next() else {
            self.state = RtState::Halted;
            self.stop = None;
            return self.last;
        };
        if stop.is_over() {
            self.state = RtState::Halted;
            self.stop = None;
        }
        // The stop keeps the index of the set-point it continues: indices stay the producer's
        // (never ahead of what it will send next), so they never go back.
        SetPoint {
            index: self.last.index,
            line,
            position: s.position,
            velocity: s.velocity,
            acceleration: s.acceleration,
        }
    }

    /// Drops set-points until a re-arm (which ends the halt once the stop is over).
    fn discard(&mut self) {
        while let Ok(slot) = self.ends.setpoints.pop() {
            match slot {
                Slot::Point(_) => self.counters.discarded += 1,
                Slot::Rearm if self.state == RtState::Halted => {
                    self.state = RtState::Running;
                    self.fault = None;
                    return;
                }
                Slot::Rearm => {}
            }
        }
    }

    /// Runs periods on `clock` until `quit` is set; returns the counters and the clock's
    /// timing figures. Nothing in the loop allocates.
    pub fn run(&mut self, clock: &mut impl Clock, quit: &AtomicBool) -> (RtCounters, Jitter) {
        self.jitter = Jitter::default();
        while !quit.load(Ordering::Relaxed) {
            let late = clock.wait();
            self.jitter.record(late, self.period);
            self.tick();
        }
        (self.counters, self.jitter)
    }
}

/// Paces the real-time loop.
pub trait Clock {
    /// Waits for the next period's start; returns how late the wake-up was, s (≥ 0).
    fn wait(&mut self) -> f64;
}

/// The wall clock: absolute deadlines k·Ts from the start (no drift), a sleep to just before
/// the deadline and a spin for the rest (sleep alone wakes tens of µs late on a busy machine).
pub struct RealClock {
    start: Instant,
    period: Duration,
    spin: Duration,
    k: u32,
}

impl RealClock {
    pub fn new(period: f64) -> Self {
        RealClock {
            start: Instant::now(),
            period: Duration::from_secs_f64(period),
            spin: Duration::from_micros(200),
            k: 0,
        }
    }
}

impl Clock for RealClock {
    fn wait(&mut self) -> f64 {
        self.k = self.k.wrapping_add(1);
        let deadline = self.start + self.period * self.k;
        let now = Instant::now();
        if deadline > now + self.spin {
            std::thread::sleep(deadline - now - self.spin);
        }
        while Instant::now() < deadline {
            std::hint::spin_loop();
        }
        Instant::now().duration_since(deadline).as_secs_f64()
    }
}

/// Wake-up lateness figures.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Jitter {
    pub periods: u64,
    /// Worst lateness, s.
    pub worst: f64,
    pub sum: f64,
    /// Periods late by more than half a period.
    pub over_half: u64,
}

impl Jitter {
    fn record(&mut self, late: f64, period: f64) {
        self.periods += 1;
        if late > period / 2.0 {
            self.over_half += 1;
        }
        self.worst = self.worst.max(late);
        self.sum += late;
    }

    pub fn mean(&self) -> f64 {
        if self.periods == 0 {
            0.0
        } else {
            self.sum / self.periods as f64
        }
    }
}
