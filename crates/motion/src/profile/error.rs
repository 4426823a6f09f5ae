//! Named failures of the profile solver and its helpers. Inputs are checked up front; a request
//! that is valid but cannot be met (an end speed out of reach in the given distance) is reported
//! with what can be reached, never clamped silently.

use thiserror::Error;

use super::limits::LimitsError;

/// Why a profile (or a helper's answer) could not be produced.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum ProfileError {
    #[error(transparent)]
    Limits(#[from] LimitsError),
    /// A speed that is NaN, negative, or above the speed limit.
    #[error("{which} speed must be in [0, {max_velocity}], got {value}")]
    Speed {
        which: SpeedKind,
        value: f64,
        max_velocity: f64,
    },
    /// A start state (speed, acceleration or position) that is not finite.
    #[error("start state must be finite, got speed {v} and acceleration {a}")]
    Start { v: f64, a: f64 },
    /// A target speed that is not finite, or (for a position target) beyond ±V.
    #[error(
        "target speed must be finite (and within the speed limit for a position target), got {0}"
    )]
    Target(f64),
    /// A target distance that is not finite.
    #[error("target distance must be finite, got {0}")]
    TargetDistance(f64),
    /// A path length that is NaN, infinite or negative.
    #[error("distance must be finite and >= 0, got {0}")]
    Distance(f64),
    /// The end speed cannot be met within the distance while moving forward (v ≥ 0 throughout).
    /// `reachable` is the end speed nearest to the request on the start speed's side: every end
    /// speed between `start` and `reachable` can be met.
    #[error(
        "end speed {requested} cannot be reached from {start} within {distance} \
         (reachable: {reachable})"
    )]
    EndSpeedUnreachable {
        start: f64,
        requested: f64,
        distance: f64,
        reachable: f64,
    },
}

/// Which speed argument was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedKind {
    Start,
    End,
}

impl std::fmt::Display for SpeedKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SpeedKind::Start => "start",
            SpeedKind::End => "end",
        })
    }
}
