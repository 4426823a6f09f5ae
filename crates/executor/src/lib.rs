//! tezgah-executor: the real-time loop, operating modes and drives.
//!
//! A planner thread runs the [`executor::Executor`] (modes, commands, jobs planned on demand,
//! re-timed sampling for feed hold and override) and keeps a short lock-free [`ring`] of
//! [`SetPoint`]s filled; the real-time thread ([`rt::RtLoop`]) takes exactly one per period
//! and hands it to a [`Drive`], turning an underrun into a jerk-limited [`stop`]. Commands and
//! status ([`command`]) are plain serde data for a front end.

pub mod command;
pub mod drive;
pub mod error;
pub mod executor;
pub mod job;
pub mod manual;
pub mod mdi;
pub mod overspeed;
pub mod probe;
pub mod probe_moves;
pub mod program;
pub mod realtime;
pub mod ring;
pub mod rt;
pub mod scale;
pub mod setpoint;
pub mod speed_override;
pub mod stop;
pub mod synced;
pub mod threads;

pub use drive::{Drive, DriveFault, DriveStatus};
pub use setpoint::SetPoint;
pub use speed_override::{Override, OverrideError};
