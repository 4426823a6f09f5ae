//! The manual motion the executor has in hand (JOG, INC or HOME) and the jerk-limited stop that
//! replaces it on an abort, a hold or a homing error: one generator polled once per period by
//! `Executor::step`. Positions are in the executor's machine frame except HOME's, which stay in
//! the drive's (power-on) frame until homing ends (see `home.rs`).

use super::{Home, HomeSwitches, Inc, Jog, ManualError};
use crate::setpoint::SetPoint;
use crate::stop::PlayedStop;

/// What is moving.
#[derive(Debug, Clone)]
pub enum ManualMotion {
    Jog(Jog),
    Inc(Inc),
    Home(Box<Home>),
    /// Every joint to rest from its exact state ([`crate::stop`], as the underrun stop).
    Stop(Box<PlayedStop>),
}

impl ManualMotion {
    /// The next period's set-point (index and line are the executor's to set), `None` once
    /// the motion is over.
    pub fn next(&mut self, switches: &dyn HomeSwitches) -> Result<Option<SetPoint>, ManualError> {
        match self {
            ManualMotion::Jog(j) => Ok(j.next()),
            ManualMotion::Inc(i) => Ok(i.next()),
            ManualMotion::Home(h) => h.next_setpoint(&Dyn(switches)),
            ManualMotion::Stop(s) => Ok(s.next().map(|st| SetPoint {
                index: 0,
                line: 0,
                position: st.position,
                velocity: st.velocity,
                acceleration: st.acceleration,
            })),
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
