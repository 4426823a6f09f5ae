//! The manual motion the executor has in hand (JOG, INC or HOME) and the jerk-limited stop that
//! replaces it on an abort, a hold or a homing error: one generator polled once per period by
//! `Executor::step`. Positions are in the executor's machine frame except HOME's, which stay in
//! the drive's (power-on) frame until homing ends (see `home.rs`).

use tezgah_kinematics::Joints;
use tezgah_motion::profile::State;

use super::ramp::VelocityRamp;
use super::{Home, HomeSwitches, Inc, Jog, ManualError};
use crate::setpoint::SetPoint;

/// A per-joint time-optimal jerk-limited stop from a moving state (velocity ramps to 0 from
/// each joint's exact position, velocity and acceleration), all joints starting together.
#[derive(Debug, Clone)]
pub struct JointStop {
    ramps: Vec<VelocityRamp>,
    held: Joints,
    period: f64,
    emitted: u64,
    done: bool,
}

impl JointStop {
    /// Stops every joint from `last` (its velocity and acceleration exact) under the joints'
    /// acceleration and jerk limits (internal units).
    pub fn new(last: &SetPoint, max_acceleration: &[f64], max_jerk: &[f64], period: f64) -> Self {
        let ramps = (0..last.position.len())
            .map(|i| {
                let st = State {
                    s: last.position[i],
                    v: last.velocity[i],
                    a: last.acceleration[i],
                    j: 0.0,
                };
                VelocityRamp::new(st, 0.0, max_acceleration[i], max_jerk[i])
            })
            .collect();
        JointStop {
            ramps,
            held: last.position,
            period,
            emitted: 0,
            done: false,
        }
    }

    fn next(&mut self) -> Option<SetPoint> {
        if self.done {
            return None;
        }
        self.emitted += 1;
        let t = self.emitted as f64 * self.period;
        let mut sp = SetPoint::at_rest(0, 0, self.held);
        let mut done = true;
        for (i, r) in self.ramps.iter().enumerate() {
            let st = if t >= r.duration() {
                r.end()
            } else {
                done = false;
                r.state_at(t)
            };
            sp.position[i] = st.s;
            sp.velocity[i] = st.v;
            sp.acceleration[i] = st.a;
        }
        self.done = done;
        Some(sp)
    }
}

/// What is moving.
#[derive(Debug, Clone)]
pub enum ManualMotion {
    Jog(Jog),
    Inc(Inc),
    Home(Box<Home>),
    Stop(JointStop),
}

impl ManualMotion {
    /// The next period's set-point (index and line are the executor's to set), `None` once
    /// the motion is over.
    pub fn next(&mut self, switches: &dyn HomeSwitches) -> Result<Option<SetPoint>, ManualError> {
        match self {
            ManualMotion::Jog(j) => Ok(j.next()),
            ManualMotion::Inc(i) => Ok(i.next()),
            ManualMotion::Home(h) => h.next_setpoint(&Dyn(switches)),
            ManualMotion::Stop(s) => Ok(s.next()),
        }
    }

    /// True for HOME (its positions are in the drive's frame).
    pub fn in_drive_frame(&self) -> bool {
        matches!(self, ManualMotion::Home(_))
    }
}

/// `Home::next_setpoint` takes a sized switch reader.
struct Dyn<'a>(&'a dyn HomeSwitches);

impl HomeSwitches for Dyn<'_> {
    fn tripped(&self, joint: usize, position: f64) -> bool {
        self.0.tripped(joint, position)
    }
}
