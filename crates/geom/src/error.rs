//! Typed errors of the curve layer: every constructor and fitter validates its input and says
//! what is wrong instead of panicking, so bad G-code (a G06.2 block, an arc) never crashes.

use thiserror::Error;

/// Why a curve could not be built or fitted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CurveError {
    #[error("degree {degree} is not supported (1..={max})")]
    Degree { degree: usize, max: usize },
    #[error("{points} control points are too few for degree {degree} (need at least {need})")]
    TooFewPoints {
        points: usize,
        degree: usize,
        need: usize,
    },
    #[error("knot vector has {got} knots, expected {expected} (control points + degree + 1)")]
    KnotCount { got: usize, expected: usize },
    #[error("knot {index} ({value}) is smaller than the knot before it")]
    KnotsDecreasing { index: usize, value: f64 },
    #[error("interior knot {value} repeats {multiplicity} times (at most the degree, {degree})")]
    KnotMultiplicity {
        value: f64,
        multiplicity: usize,
        degree: usize,
    },
    #[error("the curve's parameter domain is empty")]
    EmptyDomain,
    #[error("weight {index} is {value}; weights must be finite and > 0")]
    Weight { index: usize, value: f64 },
    #[error("weights ({weights}) and control points ({points}) differ in number")]
    WeightCount { weights: usize, points: usize },
    #[error("a coordinate or parameter is not finite")]
    NotFinite,
    #[error("arc radius is zero or the start is on the centre")]
    ZeroRadius,
    #[error("arc turn count must not be 0")]
    ZeroTurn,
    #[error("duration must be finite and > 0, got {0}")]
    Duration(f64),
    #[error("tolerance must be finite and > 0, got {0}")]
    Tolerance(f64),
    #[error("consecutive data points {index} and {next} coincide")]
    DuplicatePoints { index: usize, next: usize },
    #[error("the linear system of the fit is singular")]
    Singular,
    #[error(
        "fit did not reach tolerance {tolerance} (best {achieved}) within {iterations} rounds"
    )]
    NotConverged {
        tolerance: f64,
        achieved: f64,
        iterations: usize,
    },
}
