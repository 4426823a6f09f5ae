//! tezgah-executor: the real-time loop, operating modes and drives.
//!
//! Takes timed samples from tezgah-motion and hands one [`SetPoint`] per period to a
//! [`Drive`]. It grows with the executor issue.

pub mod drive;
pub mod manual;
pub mod setpoint;

pub use drive::{Drive, DriveFault, DriveStatus};
pub use setpoint::SetPoint;
