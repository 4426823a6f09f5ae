//! The speed override an operator sets — feed override in AUTO and MDI, jog override in JOG:
//! a percent of the programmed (or set) speed, 0–200 %, the limits still capping the speed
//! reached. Checked once, where a command brings it in; past that the type says it is valid.

use thiserror::Error;

/// An override percent known to lie in 0–[`Override::MAX_PERCENT`].
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd)]
pub struct Override(f64);

/// An override percent outside the range (or not a number).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error("override {percent} % is outside 0–{max} %", max = Override::MAX_PERCENT)]
pub struct OverrideError {
    pub percent: f64,
}

impl Override {
    /// Largest override accepted, percent.
    pub const MAX_PERCENT: f64 = 200.0;

    /// As programmed.
    pub const FULL: Override = Override(100.0);

    /// `percent` if it lies in 0–200 (NaN does not).
    pub fn new(percent: f64) -> Result<Override, OverrideError> {
        if (0.0..=Self::MAX_PERCENT).contains(&percent) {
            Ok(Override(percent))
        } else {
            Err(OverrideError { percent })
        }
    }

    pub fn percent(self) -> f64 {
        self.0
    }

    /// The factor on speed (1 at 100 %).
    pub fn factor(self) -> f64 {
        self.0 / 100.0
    }
}

impl Default for Override {
    fn default() -> Self {
        Override::FULL
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_is_checked() {
        for ok in [0.0, 37.5, 100.0, 200.0] {
            assert_eq!(Override::new(ok).map(Override::percent), Ok(ok));
        }
        assert_eq!(Override::new(150.0).unwrap().factor(), 1.5);
        for bad in [-0.1, 200.01, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = Override::new(bad).unwrap_err();
            assert!(e.percent.is_nan() || e.percent == bad);
            assert!(e.to_string().contains("outside 0–200 %"), "{e}");
        }
    }
}
