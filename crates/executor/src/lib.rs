//! tezgah-executor: the real-time loop, operating modes and drives.
//!
//! Takes timed samples from tezgah-motion and hands one [`SetPoint`] per period to a
//! [`Drive`]. It grows with the executor issue.

pub mod command;
pub mod drive;
pub mod error;
pub mod executor;
pub mod ideal;
pub mod job;
pub mod mdi;
pub mod ring;
pub mod rt;
pub mod scale;
pub mod setpoint;
pub mod stop;
pub mod threads;

pub use drive::{Drive, DriveFault, DriveStatus};
pub use setpoint::SetPoint;
