//! The feed planner: path items in, timed pieces out. It sits between the path stage
//! ([`crate::path`]) and the interpolator ([`crate::interpolate`]), and streams: memory is
//! bounded by the look-ahead window.
//!
//! Modules: [`joints`] (the machine's joint limits seen along the path), [`limits`] (the speed
//! limit and profile limits of one segment, and the junction cap), [`lookahead`] (grouping,
//! backward and forward passes, one [`crate::Profile`] per group of segments). Long splines
//! arrive cut at their knots where their curvature level changes (the path stage's job), so a
//! segment's speed follows its own curvature.

pub mod joints;
pub mod limits;
pub mod lookahead;

pub use joints::{JointMap, PlanMachine};
pub use limits::{Geometry, PlanOptions, SegmentLimits};
pub use lookahead::{Piece, Planned, Planner};

/// Why planning failed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum PlanError {
    #[error("the planner supports {supported} machines so far, not `{kind}`")]
    UnsupportedKinematics {
        kind: &'static str,
        supported: &'static str,
    },
    #[error("line {line}: no speed limit can be derived for this segment ({reason})")]
    NoLimit { line: u32, reason: String },
    #[error("line {line}: profile: {source}")]
    Profile {
        line: u32,
        source: crate::profile::ProfileError,
    },
    #[error(
        "line {line}: joint {joint} jumps by {jump} (internal units) along the move: the path \
         passes through a singular pose of the machine"
    )]
    JointJump { line: u32, joint: usize, jump: f64 },
    #[error(
        "line {line}: {axis} has no joint on this machine: with tool-centre-point control off \
         (G49, or before G43.4) the program axes drive the joints of their names"
    )]
    NoJoint { line: u32, axis: char },
    #[error("line {line}: dwell of {seconds} s is not a finite, non-negative time")]
    BadDwell { line: u32, seconds: f64 },
    #[error("bad planner option {name}: {value}")]
    Option { name: &'static str, value: f64 },
}
