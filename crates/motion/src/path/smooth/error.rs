//! Typed errors of the smoothing path builder: a move that cannot become a segment (a bad arc,
//! a feed it cannot time, an invalid tolerance) is reported with its source line, never a panic.

use thiserror::Error;

use tezgah_geom::CurveError;

/// Why the path builder could not turn a move into segments.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PathError {
    /// The move's geometry is invalid (arc with zero radius, non-finite coordinates, …).
    #[error("line {line}: {source}")]
    Curve {
        line: u32,
        #[source]
        source: CurveError,
    },
    /// A feed move with a feed that is not finite and positive.
    #[error("line {line}: feed {value} is not a positive finite number")]
    Feed { line: u32, value: f64 },
    /// G95 (feed per revolution) with no spindle speed to turn it into a feed.
    #[error("line {line}: feed per revolution (G95) with no spindle speed (S)")]
    FeedPerRevolution { line: u32 },
    /// A tolerance (options or `G64 P`) that is not finite and positive.
    #[error("line {line}: path tolerance {value} mm is not a positive finite number")]
    Tolerance { line: u32, value: f64 },
    /// G33/G33.1 follow the spindle, not a feed: only a caller that simulates the spindle
    /// (`tezgah run`) plays them, cutting the program at them.
    #[error(
        "line {line}: G33/G33.1 follow the spindle; only `tezgah run` simulates that (the \
         executor, `check --machine` and `export` do not)"
    )]
    Synced { line: u32 },
    /// An option of [`super::SmoothOptions`] out of its range.
    #[error("smoothing option {name} = {value} is out of range")]
    Option { name: &'static str, value: f64 },
}

impl PathError {
    /// The source line of the move the error is about (an option's error has none).
    pub fn line(&self) -> Option<u32> {
        match self {
            PathError::Curve { line, .. }
            | PathError::Feed { line, .. }
            | PathError::FeedPerRevolution { line }
            | PathError::Synced { line }
            | PathError::Tolerance { line, .. } => Some(*line),
            PathError::Option { .. } => None,
        }
    }

    /// The message without its `line N: `, for reports that name the place themselves.
    pub fn detail(&self) -> String {
        let text = self.to_string();
        match self.line() {
            Some(line) => text
                .strip_prefix(&format!("line {line}: "))
                .map_or_else(|| text.clone(), str::to_owned),
            None => text,
        }
    }
}
