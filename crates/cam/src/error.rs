//! Why planning a tool path failed: bad settings or cutter, a surface the strategies cannot
//! work on, or a search that did not converge. Gouges are not errors: they are corrected or
//! listed in the plan's report (see `strategy::Plan`).

use thiserror::Error;

#[derive(Debug, Clone, PartialEq, Error)]
pub enum CamError {
    #[error("setting `{name}` must be {want}, got {got}")]
    Setting {
        name: &'static str,
        want: &'static str,
        got: f64,
    },
    #[error("the cutter is invalid: {0}")]
    Cutter(String),
    #[error("the surface has no normal at (u, v) = ({u}, {v}) (degenerate point)")]
    Degenerate { u: f64, v: f64 },
    #[error("the forward step did not converge at parameter {at} (chord error {error} mm)")]
    StepStalled { at: f64, error: f64 },
    #[error("the plan needs more than {limit} {what}; loosen the scallop height or tolerance")]
    TooLarge { what: &'static str, limit: usize },
    #[error("no cutter of the standard set fits: {0}")]
    NoCutter(String),
}

/// Checks a setting is finite and > 0.
pub(crate) fn positive(name: &'static str, x: f64) -> Result<f64, CamError> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(CamError::Setting {
            name,
            want: "finite and > 0",
            got: x,
        })
    }
}
