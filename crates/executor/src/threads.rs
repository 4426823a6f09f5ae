//! The two threads: the planner thread ([`PlannerSide`]: commands, the executor, keeping the
//! ring a few periods ahead, watching the real-time reports) and the real-time thread
//! ([`crate::rt::RtLoop`] on a [`crate::rt::RealClock`]). [`spawn`] starts both; a front end
//! (the `serve` command) talks to the [`Handle`]: commands in, status out.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use serde::Serialize;

use tezgah_geom::Move;

use crate::command::{Command, RunState, Status};
use crate::drive::Drive;
use crate::error::ExecError;
use crate::executor::Executor;
use crate::realtime::{self, Applied, RealtimeSettings};
use crate::ring::{rings, Rings, RtReport, RtState, Slot};
use crate::rt::{Jitter, RealClock, RtCounters, RtLoop, StopLimits};

/// Set-points the ring holds by default: 32 ms at 1 ms — commands act within that.
pub const DEFAULT_RING: usize = 32;

/// How far the planner keeps ahead of the real-time thread, in set-points.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Lead {
    pub samples: u64,
    pub min: usize,
    pub max: usize,
    pub sum: u64,
}

impl Lead {
    fn record(&mut self, n: usize) {
        if self.samples == 0 || n < self.min {
            self.min = n;
        }
        self.max = self.max.max(n);
        self.sum += n as u64;
        self.samples += 1;
    }

    pub fn mean(&self) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            self.sum as f64 / self.samples as f64
        }
    }
}

/// The planner thread's side of the rings.
pub struct PlannerSide {
    exec: Executor,
    rings: Rings,
    capacity: usize,
    last: Option<RtReport>,
    lead: Lead,
    /// A re-arm waits for room in the ring: no set-point goes before it.
    rearm_pending: bool,
    /// A re-arm is on its way: reports still saying "halted" are older than it.
    rearming: bool,
    /// The executor has been told of the current halt.
    halt_seen: bool,
}

impl PlannerSide {
    /// `capacity` is the set-point ring's size the rings were made with.
    pub fn new(exec: Executor, rings: Rings, capacity: usize) -> Self {
        PlannerSide {
            exec,
            rings,
            capacity,
            last: None,
            lead: Lead::default(),
            rearm_pending: false,
            rearming: false,
            halt_seen: false,
        }
    }

    pub fn executor(&self) -> &Executor {
        &self.exec
    }

    /// The executor's status with what the real-time side reported last.
    pub fn status(&self) -> Status {
        let mut s = self.exec.status();
        if let Some(r) = &self.last {
            s.executing_line = r.line;
            s.underruns = r.underruns;
            s.late_worst_s = r.late_worst;
            s.late_over_half = r.late_over_half;
            s.measured = r.measured.as_slice().to_vec();
        }
        s
    }

    /// The last real-time report read.
    pub fn last_report(&self) -> Option<&RtReport> {
        self.last.as_ref()
    }

    pub fn lead(&self) -> Lead {
        self.lead
    }

    /// One command. An abort in a fault also re-arms the real-time side.
    pub fn command(&mut self, command: Command) -> Result<(), ExecError> {
        let rearm = command == Command::Abort && self.exec.state() == RunState::Fault;
        self.exec.command(command)?;
        if rearm {
            self.rearm_pending = true;
            self.send_rearm();
        }
        Ok(())
    }

    /// Pushes a pending re-arm if the ring has room. The real-time side empties the ring at
    /// every period while halted, but the ring can be full when the abort comes (it was
    /// filled after the reports were read and before the real-time thread, preempted, next
    /// ran): a re-arm dropped then left the real-time side halted for good, discarding every
    /// set-point after (1.19 million in a loaded soak).
    fn send_rearm(&mut self) {
        if self.rearm_pending && self.rings.setpoints.push(Slot::Rearm).is_ok() {
            self.rearm_pending = false;
            self.rearming = true;
            self.halt_seen = false;
        }
    }

    /// Reads the reports, then tops the ring up; returns the set-points pushed.
    pub fn pump(&mut self) -> usize {
        while let Ok(r) = self.rings.reports.pop() {
            // Any report not halted after a re-arm was sent shows it took effect (reports
            // older than it were read when the halt was seen). Every report counts, not only
            // the last: the real-time side can run, underrun and halt again between two pumps,
            // and a last report "halted" then is a new halt, not the old one.
            if self.rearming && r.state != RtState::Halted {
                self.rearming = false;
            }
            self.last = Some(r);
        }
        if let Some(r) = self.last {
            if r.state == RtState::Halted && !self.rearming && !self.halt_seen {
                self.halt_seen = true;
                let why = match r.fault {
                    Some(f) => format!("drive fault: {f}"),
                    None => format!("set-point underrun ({} so far)", r.underruns),
                };
                self.exec.fault(r.commanded, &why);
            }
        }
        self.lead
            .record(self.capacity - self.rings.setpoints.slots());
        self.send_rearm();
        if self.rearm_pending {
            return 0;
        }
        let mut pushed = 0;
        while self.rings.setpoints.slots() > 0 {
            match self.exec.step() {
                Ok(Some(p)) => {
                    // Room was checked: the push cannot fail.
                    let _ = self.rings.setpoints.push(Slot::Point(p.setpoint));
                    pushed += 1;
                }
                _ => break,
            }
        }
        pushed
    }
}

/// A command with the channel its answer goes back on.
type Request = (Command, mpsc::Sender<Result<(), ExecError>>);

/// What the running pair of threads answers with.
pub struct Handle {
    /// Commands whose answers come back to the sender ([`Handle::request`]).
    requests: mpsc::Sender<Request>,
    /// The executor's status, refreshed by the planner thread.
    pub status: Arc<Mutex<Status>>,
    /// The moves of the program loaded last (lines keyed as the status' lines), for a
    /// front end's preview; set by the planner thread when a load succeeds.
    pub program: Arc<Mutex<Option<Arc<Vec<Move>>>>>,
    quit: Arc<AtomicBool>,
    planner: JoinHandle<Lead>,
    rt: JoinHandle<(RtCounters, Jitter)>,
    /// What the real-time thread's scheduling request got ([`crate::realtime`]).
    pub realtime: Applied,
}

/// The threads' figures when they stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figures {
    pub rt: RtCounters,
    pub jitter: Jitter,
    pub lead: Lead,
}

impl Handle {
    /// Hands a command to the planner thread and waits for its answer (within a period or
    /// so): `Ok` once applied, or why it was refused (a refused command changes nothing).
    pub fn request(&self, command: Command) -> Result<(), ExecError> {
        let (reply, answer) = mpsc::channel();
        self.requests
            .send((command, reply))
            .map_err(|_| ExecError::Stopped)?;
        answer.recv().map_err(|_| ExecError::Stopped)?
    }

    /// Stops both threads and returns their figures.
    pub fn stop(self) -> Figures {
        self.quit.store(true, Ordering::Relaxed);
        let lead = self.planner.join().unwrap_or_default();
        let (rt, jitter) = self.rt.join().unwrap_or_default();
        Figures { rt, jitter, lead }
    }
}

/// Starts the planner thread and the real-time thread (period from `exec`) with a ring of
/// `capacity` set-points; the real-time loop starts at `exec`'s current joints and stops on
/// an underrun within the machine's joint limits. The real-time thread first asks for
/// `realtime` scheduling (best effort: [`Handle::realtime`] says what it got).
pub fn spawn<D: Drive + Send + 'static>(
    exec: Executor,
    drive: D,
    capacity: usize,
    realtime: RealtimeSettings,
) -> Handle {
    let period = exec.period();
    let limits = StopLimits::of(exec.machine());
    let (planner_rings, rt_ends) = rings(capacity, 4 * capacity.max(64));
    // The drive's frame (machine joints plus the homing offsets), where set-points live.
    let start = exec.drive_joints();
    let quit = Arc::new(AtomicBool::new(false));
    let status = Arc::new(Mutex::new(exec.status()));
    let (rtx, rrx) = mpsc::channel::<Request>();
    let q = quit.clone();
    let (applied_tx, applied_rx) = mpsc::channel();
    let planner_settings = realtime.for_planner();
    let rt = std::thread::Builder::new()
        .name("tezgah-rt".into())
        .spawn(move || {
            let _ = applied_tx.send(realtime::apply(&realtime));
            let mut rt = RtLoop::new(rt_ends, drive, period, limits, start);
            rt.run(&mut RealClock::new(period), &q)
        })
        .expect("spawning the real-time thread");
    let q = quit.clone();
    let st = status.clone();
    let program = Arc::new(Mutex::new(None));
    let loaded = program.clone();
    let planner = std::thread::Builder::new()
        .name("tezgah-planner".into())
        .spawn(move || {
            // Best effort too; the real-time thread's outcome is the one reported.
            let granted = realtime::apply(&planner_settings).fifo;
            let mut side = PlannerSide::new(exec, planner_rings, capacity);
            while !q.load(Ordering::Relaxed) {
                while let Ok((c, reply)) = rrx.try_recv() {
                    // Commands that build a whole path run time-shared (see
                    // `realtime::time_shared`); the others are quick.
                    let builds = matches!(
                        c,
                        Command::Load { .. }
                            | Command::CycleStart
                            | Command::Resume
                            | Command::Mdi { .. }
                            | Command::RestartFrom { .. }
                    );
                    let load = matches!(c, Command::Load { .. });
                    let answer = if builds {
                        let fifo = planner_settings.fifo_priority;
                        realtime::time_shared(&granted, fifo, || side.command(c))
                    } else {
                        side.command(c)
                    };
                    if load && answer.is_ok() {
                        let moves = side
                            .executor()
                            .program_moves()
                            .map(|m| Arc::new(m.to_vec()));
                        if let Ok(mut p) = loaded.lock() {
                            *p = moves;
                        }
                    }
                    let _ = reply.send(answer);
                }
                side.pump();
                if let Ok(mut s) = st.lock() {
                    *s = side.status();
                }
                // A quarter period: the ring (tens of periods) never runs dry on a sleep.
                std::thread::sleep(Duration::from_secs_f64(period / 4.0));
            }
            side.lead()
        })
        .expect("spawning the planner thread");
    let realtime = applied_rx.recv().unwrap_or(Applied {
        fifo: realtime::Outcome::Refused("the real-time thread did not start".into()),
        memory_locked: realtime::Outcome::NotAsked,
        cpu: realtime::Outcome::NotAsked,
    });
    Handle {
        requests: rtx,
        status,
        program,
        quit,
        planner,
        rt,
        realtime,
    }
}
