//! The kinematic limits of a 1-D motion along the path: speed, acceleration and jerk.
//!
//! Validated once, at construction, so that the solver never sees a NaN or a non-positive limit
//! (Ruckig's `validate_input`): every later computation may divide by them.

use thiserror::Error;

/// Speed (mm/s), acceleration (mm/s²) and jerk (mm/s³) limits, all finite and > 0.
///
/// The fields are private so that an invalid value cannot be built; read them with the getters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    max_velocity: f64,
    max_acceleration: f64,
    max_jerk: f64,
}

/// Which limit was rejected by [`Limits::new`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitKind {
    Velocity,
    Acceleration,
    Jerk,
}

impl std::fmt::Display for LimitKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LimitKind::Velocity => "max_velocity",
            LimitKind::Acceleration => "max_acceleration",
            LimitKind::Jerk => "max_jerk",
        })
    }
}

/// A limit that is NaN, infinite, zero or negative.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error("{kind} must be finite and > 0, got {value}")]
pub struct LimitsError {
    pub kind: LimitKind,
    pub value: f64,
}

impl Limits {
    /// Checks each limit; the first bad one is named in the error.
    pub fn new(
        max_velocity: f64,
        max_acceleration: f64,
        max_jerk: f64,
    ) -> Result<Self, LimitsError> {
        for (kind, value) in [
            (LimitKind::Velocity, max_velocity),
            (LimitKind::Acceleration, max_acceleration),
            (LimitKind::Jerk, max_jerk),
        ] {
            // `!(value > 0.0)` also rejects NaN.
            if !(value.is_finite() && value > 0.0) {
                return Err(LimitsError { kind, value });
            }
        }
        Ok(Limits {
            max_velocity,
            max_acceleration,
            max_jerk,
        })
    }

    pub fn max_velocity(&self) -> f64 {
        self.max_velocity
    }

    pub fn max_acceleration(&self) -> f64 {
        self.max_acceleration
    }

    pub fn max_jerk(&self) -> f64 {
        self.max_jerk
    }

    /// The speed change A²/J above which a zero-to-zero-acceleration speed change reaches the
    /// acceleration limit (the two jerk ramps alone then give exactly A).
    pub(crate) fn full_ramp_speed_change(&self) -> f64 {
        self.max_acceleration * self.max_acceleration / self.max_jerk
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_limits_by_name() {
        assert!(Limits::new(1.0, 2.0, 3.0).is_ok());
        let e = Limits::new(f64::NAN, 2.0, 3.0).unwrap_err();
        assert_eq!(e.kind, LimitKind::Velocity);
        let e = Limits::new(1.0, -2.0, 3.0).unwrap_err();
        assert_eq!(e.kind, LimitKind::Acceleration);
        let e = Limits::new(1.0, 2.0, 0.0).unwrap_err();
        assert_eq!(e.kind, LimitKind::Jerk);
        let e = Limits::new(1.0, 2.0, f64::INFINITY).unwrap_err();
        assert_eq!(e.kind, LimitKind::Jerk);
        assert_eq!(e.to_string(), "max_jerk must be finite and > 0, got inf");
    }
}
