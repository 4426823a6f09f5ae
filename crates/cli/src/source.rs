//! Where a program's moves and errors come from: the program and the subroutine files it
//! loaded, so that every error names the file, line and column of its block. `check` and `run`
//! interpret a program once, here, and hand the moves on to the path and its pre-flight.
//!
//! A move keeps only a line number (`tezgah_geom::Move::line`), so a line of a subroutine file
//! would read as the program's line of the same number. Until the motion stages carry the file,
//! the moves given to them number the lines of subroutine files past the program's last line
//! ([`LineKeys`]); a pre-flight error is turned back into its (file, line), and the built path
//! into plain line numbers, before anything is reported or run.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use tezgah_gcode::{Canon, CanonSink, Config, GcodeError, Interpreter, MoveBuilder, Origin};
use tezgah_geom::Move;
use tezgah_motion::PathItem;

/// A line of the program (`file` 0) or of the `file`-th subroutine file it loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SourceLine {
    pub file: u16,
    pub line: u32,
}

/// The line numbers the moves carry: the program's own lines unchanged, each line of a
/// subroutine file a number past the program's last line.
#[derive(Debug, Default)]
pub struct LineKeys {
    program_lines: u32,
    keys: HashMap<SourceLine, u32>,
    lines: Vec<SourceLine>,
}

impl LineKeys {
    fn new(program: &str) -> Self {
        let newlines = memchr_count(program.as_bytes());
        LineKeys {
            program_lines: u32::try_from(newlines + 1).unwrap_or(u32::MAX),
            ..LineKeys::default()
        }
    }

    /// The number a move from `at` carries.
    fn key(&mut self, at: SourceLine) -> u32 {
        if at.file == 0 {
            return at.line;
        }
        let next = self
            .program_lines
            .saturating_add(1)
            .saturating_add(u32::try_from(self.lines.len()).unwrap_or(u32::MAX));
        *self.keys.entry(at).or_insert_with(|| {
            self.lines.push(at);
            next
        })
    }

    /// The line a move's number stands for.
    pub fn source(&self, key: u32) -> SourceLine {
        let sub = key
            .checked_sub(self.program_lines.saturating_add(1))
            .and_then(|k| self.lines.get(k as usize));
        match sub {
            Some(&at) => at,
            None => SourceLine { file: 0, line: key },
        }
    }

    /// Back to plain line numbers (each in its own file), as samples and reports print them.
    pub fn unkey(&self, items: &mut [PathItem]) {
        if self.lines.is_empty() {
            return;
        }
        for item in items {
            let line = match item {
                PathItem::Segment(s) => &mut s.line,
                PathItem::Dwell { line, .. } | PathItem::Stop { line } => line,
            };
            *line = self.source(*line).line;
        }
    }
}

fn memchr_count(bytes: &[u8]) -> usize {
    bytes.iter().filter(|&&b| b == b'\n').count()
}

/// One text errors may point into.
#[derive(Debug, Clone)]
pub struct Source {
    /// How reports name it: the path it was read from.
    pub name: String,
    pub text: Arc<str>,
}

/// The program and the subroutine files it loaded (file k of a [`SourceLine`] is `subs[k-1]`).
#[derive(Debug, Clone)]
pub struct Sources {
    pub program: Source,
    subs: Vec<(String, Source)>,
}

impl Sources {
    /// A program with no subroutine file loaded yet (an owned `String` is moved, not copied
    /// twice).
    pub fn new(path: &Path, text: impl Into<Arc<str>>) -> Self {
        Sources {
            program: Source {
                name: path.display().to_string(),
                text: text.into(),
            },
            subs: Vec::new(),
        }
    }

    /// Adds the subroutine files `interp` loaded; `locate` finds the path a file was read from.
    pub fn with_subroutines(
        mut self,
        interp: &Interpreter,
        locate: impl Fn(&str) -> Option<PathBuf>,
    ) -> Self {
        let mut k = u16::try_from(self.subs.len() + 1).unwrap_or(u16::MAX);
        while let Some(f) = interp.subroutine_file(k) {
            let file_name = f.file_name();
            let name = locate(&f.name).map_or(file_name.clone(), |p| p.display().to_string());
            let text = f.text.clone();
            self.subs.push((file_name, Source { name, text }));
            k = k.saturating_add(1);
        }
        self
    }

    /// The text of `file` (0 the program; an unknown file reads as the program).
    pub fn file(&self, file: u16) -> &Source {
        usize::from(file)
            .checked_sub(1)
            .and_then(|k| self.subs.get(k))
            .map_or(&self.program, |(_, s)| s)
    }

    /// The subroutine file an error names (`<name>.ngc`), if it was loaded.
    pub fn named(&self, file_name: &str) -> Option<&Source> {
        self.subs
            .iter()
            .find(|(n, _)| n == file_name)
            .map(|(_, s)| s)
    }
}

/// A program interpreted once: its moves (with [`LineKeys`] numbers), the errors and the texts.
pub struct Interpreted {
    pub moves: Vec<Move>,
    pub keys: LineKeys,
    /// Every error of the pre-flight, or the first one of a run.
    pub errors: Vec<GcodeError>,
    pub sources: Sources,
}

/// What one pass of the interpreter is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pass {
    /// Every error (the pre-flight), no moves.
    Check,
    /// Every error, and the moves for a machine's pre-flight.
    CheckMoves,
    /// Stop at the first error, as a controller; the moves.
    Run,
}

/// Interprets the program once, into moves (unless `pass` wants none) and into `extra` (a
/// summary) too.
pub fn interpret(
    sources: Sources,
    config: Config,
    pass: Pass,
    locate: impl Fn(&str) -> Option<PathBuf>,
    extra: &mut impl CanonSink,
) -> Interpreted {
    let text = sources.program.text.clone();
    let mut keys = LineKeys::new(&text);
    let mut moves = Vec::new();
    let always = config.tool_centre_point_always;
    let mut interp = Interpreter::new(config);
    let errors = {
        let mut builder = MoveBuilder::new(|m| moves.push(m));
        if always {
            builder = builder.centre_point_always();
        }
        let mut sink = Keyed {
            keys: &mut keys,
            moves: (pass != Pass::Check).then_some(builder),
            extra,
        };
        match pass {
            Pass::Check | Pass::CheckMoves => interp.check(&text, &mut sink),
            Pass::Run => interp.run(&text, &mut sink).err().into_iter().collect(),
        }
    };
    Interpreted {
        moves,
        keys,
        errors,
        sources: sources.with_subroutines(&interp, locate),
    }
}

/// Sends each call to the move builder (if any) with its line keyed, and to `extra` as it came.
struct Keyed<'a, M, E> {
    keys: &'a mut LineKeys,
    moves: Option<M>,
    extra: &'a mut E,
}

impl<M: CanonSink, E: CanonSink> CanonSink for Keyed<'_, M, E> {
    fn call(&mut self, origin: Origin, call: Canon) {
        let at = SourceLine {
            file: origin.file,
            line: origin.line,
        };
        let Some(moves) = self.moves.as_mut() else {
            self.extra.call(origin, call);
            return;
        };
        let keyed = Origin {
            line: self.keys.key(at),
            ..origin
        };
        self.extra.call(origin, call.clone());
        moves.call(keyed, call);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_leave_program_lines_and_map_subroutine_lines_back() {
        let mut keys = LineKeys::new("G0 X1\nG1 X2\nM2\n");
        let sub = |line| SourceLine { file: 1, line };
        assert_eq!(keys.key(SourceLine { file: 0, line: 3 }), 3);
        let (a, b) = (keys.key(sub(3)), keys.key(sub(1)));
        assert!(a > 4 && b > 4 && a != b);
        assert_eq!(keys.key(sub(3)), a);
        assert_eq!(keys.source(a), sub(3));
        assert_eq!(keys.source(b), sub(1));
        assert_eq!(keys.source(2), SourceLine { file: 0, line: 2 });
    }
}
