//! The one jerk-limited, time-optimal 1-D motion solver (Ruckig's one-axis problem, Berscheid &
//! Kröger 2021): a [`Profile`] of seven constant-jerk phases, after a brake when the start is
//! outside the limits, from any state (v0, a0) to a target speed ([`reach_velocity`], JOG,
//! homing, every stop) or a target position with an end speed ([`solve_from`]), ending at zero
//! acceleration. The planner, the executor's holds, stops, jogs, increments and homing all
//! use it.
//!
//! [`Limits`] are validated once; [`solve`] is the path's case (a0 = 0, speeds in [0, V],
//! forward only) in closed form, and [`solve_from`] returns exactly its profile there;
//! [`reach`] holds the helpers the look-ahead planner needs. Durations equal Ruckig's
//! (tests/ruckig_oracle.rs, tests/ruckig_state.rs).

mod brake;
mod error;
pub mod knots;
mod limits;
mod phases;
mod ramp;
pub mod reach;
mod roots;
mod solve;
mod target;
mod velocity;

pub use error::{ProfileError, SpeedKind};
pub use limits::{LimitKind, Limits, LimitsError};
pub use phases::{Profile, State};
pub use reach::{
    max_reachable_speed, max_start_speed, min_reachable_speed, min_stopping_distance,
    solve_at_most, speed_change_distance, speed_change_time,
};
pub use solve::solve;
pub use target::solve_from;
pub use velocity::{reach_velocity, stopping_displacement};
