//! A program as the executor loads it: interpreted once through the same pass as `tezgah run`
//! and `tezgah check` (`tezgah_gcode::sources`), so its moves number the lines of subroutine
//! files apart from the program's, and every error of the load and of the pre-flight names
//! the file, line and column it is at. The jobs then run on plain line numbers.

use std::sync::Arc;

use tezgah_gcode::error::ErrorKind;
use tezgah_gcode::sources::{self, LineKeys, Located, Pass, Sources};
use tezgah_gcode::{canon::Discard, Config};
use tezgah_geom::Move;
use tezgah_motion::path::smooth::PathError;
use tezgah_motion::preflight::PreflightError;

use crate::error::ExecError;

/// How errors name a loaded program: it arrives as text (a `load` command), not as a file.
pub const PROGRAM_NAME: &str = "program";

/// How errors name an MDI block.
pub const MDI_NAME: &str = "MDI";

/// The texts a job's moves came from and what their line numbers stand for.
#[derive(Debug)]
pub struct Origins {
    keys: LineKeys,
    sources: Sources,
}

impl Origins {
    /// One MDI block: its moves carry its own line numbers.
    pub fn mdi(block: &str) -> Origins {
        Origins {
            keys: LineKeys::default(),
            sources: Sources::new(MDI_NAME, block.to_owned()),
        }
    }

    /// The file, line and column a move's line number stands for (the line's first word).
    pub fn at(&self, key: u32) -> Located {
        self.sources.line_at(self.keys.source(key)).located()
    }

    pub fn keys(&self) -> &LineKeys {
        &self.keys
    }

    /// A path builder's error at its move's place (an option's error as it is).
    pub fn path_error(&self, e: PathError) -> ExecError {
        match e.line() {
            Some(line) => ExecError::At {
                at: self.at(line),
                message: format!("path: {}", e.detail()),
            },
            None => ExecError::Path(e),
        }
    }

    /// A pose out of reach or past a limit, at its move's place.
    pub fn preflight_error(&self, e: &PreflightError) -> ExecError {
        ExecError::Preflight {
            at: self.at(e.line),
            message: e.source.to_string(),
        }
    }
}

/// A loaded program: its moves (lines keyed) and where they came from.
#[derive(Debug, Clone)]
pub struct Program {
    pub moves: Vec<Move>,
    pub origins: Arc<Origins>,
    /// The interpretation's warnings (a missing program end, run as M2).
    pub warnings: Vec<String>,
    /// The G-code (`38.2` …) of the probe move the pass stopped at, waiting for the machine's
    /// answer (`config.probe` is `Answered`): the moves end with that probe move.
    pub awaits: Option<String>,
}

impl Program {
    /// Interprets `text` as a controller does (stopping at the first error, which names its
    /// file, line and column); subroutine files come from `config`'s library. A probe move
    /// without an answer ends the moves there ([`Program::awaits`]).
    pub fn interpret(text: String, config: &Config) -> Result<Program, ExecError> {
        let library = config.subroutines.clone();
        let done = sources::interpret(
            Sources::new(PROGRAM_NAME, text),
            config.clone(),
            Pass::Run,
            |name| library.as_ref().and_then(|l| l.path(name)),
            &mut Discard,
        );
        let awaits = match done.errors.first().map(|e| &e.kind) {
            Some(ErrorKind::ProbeAwaitsAnswer(code)) => Some(code.clone()),
            _ => None,
        };
        if let Some(e) = done.errors.first().filter(|_| awaits.is_none()) {
            let error = done.sources.error_at(e);
            return Err(ExecError::At {
                at: error.at,
                message: error.message,
            });
        }
        Ok(Program {
            awaits,
            warnings: done.warnings,
            moves: done.moves,
            origins: Arc::new(Origins {
                keys: done.keys,
                sources: done.sources,
            }),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_gcode::interp::SubroutineLibrary;
    use tezgah_geom::MoveKind;

    /// One subroutine file, `far.ngc`.
    #[derive(Debug)]
    struct Far;

    impl SubroutineLibrary for Far {
        fn source(&self, name: &str) -> Option<String> {
            (name == "far").then(|| "o<far> sub\n  G1 X10\no<far> endsub\nM2\n".to_owned())
        }
    }

    #[test]
    fn path_errors_are_placed_in_the_file_of_their_move() {
        let config = Config {
            subroutines: Some(Arc::new(Far)),
            ..Config::default()
        };
        let program =
            Program::interpret("G21 G90\nF1000\no<far> call\nG1 Y5\nM2\n".into(), &config).unwrap();
        let feeds: Vec<u32> = program
            .moves
            .iter()
            .filter(|m| matches!(m.kind, MoveKind::Feed { .. }))
            .map(|m| m.line)
            .collect();
        let error = |line| {
            program
                .origins
                .path_error(PathError::FeedPerRevolution { line })
                .to_string()
        };
        // The interpreter refuses G95 without S, so the path builder's own check is met here
        // by its error alone: at the subroutine file's line 2, then the program's line 4.
        assert_eq!(
            error(feeds[0]),
            "far.ngc:2:3: path: feed per revolution (G95) with no spindle speed (S)"
        );
        assert_eq!(
            error(feeds[1]),
            "program:4:1: path: feed per revolution (G95) with no spindle speed (S)"
        );
        let option = PathError::Option {
            name: "tolerance",
            value: -1.0,
        };
        assert_eq!(
            program.origins.path_error(option.clone()),
            ExecError::Path(option)
        );
    }
}
