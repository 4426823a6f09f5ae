//! The jerk-limited, time-optimal 1-D motion along a path: a [`Profile`] of seven constant-jerk
//! phases from speed v0 to speed v1 over a length L, with zero acceleration at both ends.
//!
//! [`Limits`] are validated once; [`solve`] returns a [`Profile`] (the single truth for the
//! timed segment, evaluated with [`Profile::state_at`]) or a named [`ProfileError`]; [`reach`]
//! holds the helpers the look-ahead planner needs. Durations equal Ruckig's one-axis optimum
//! (tests/ruckig_oracle.rs).

mod error;
pub mod knots;
mod limits;
mod phases;
mod ramp;
pub mod reach;
mod roots;
mod solve;

pub use error::{ProfileError, SpeedKind};
pub use limits::{LimitKind, Limits, LimitsError};
pub use phases::{Profile, State};
pub use reach::{
    max_reachable_speed, max_start_speed, min_reachable_speed, min_stopping_distance,
    solve_at_most, speed_change_distance, speed_change_time,
};
pub use solve::solve;
