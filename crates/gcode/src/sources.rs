//! Where a program's moves and errors come from: the program and the subroutine files it
//! loaded, so that every error names the file, line and column of its block. `tezgah check`,
//! `tezgah run` and the executor's load interpret a program once, here, and hand the moves on
//! to the path and its pre-flight; their reports locate errors through [`Sources`].
//!
//! A move keeps only a line number (`tezgah_geom::Move::line`), so a line of a subroutine file
//! would read as the program's line of the same number. Until the motion stages carry the file,
//! the moves given to them number the lines of subroutine files past the program's last line
//! ([`LineKeys`]); a pre-flight error is turned back into its (file, line), and the built path
//! into plain line numbers ([`LineKeys::plain`]), before anything is reported or run.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use tezgah_geom::Move;

use crate::{Canon, CanonSink, Config, GcodeError, Interpreter, MoveBuilder, Origin, Span};

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

    /// The plain line number (in its own file) of a move's number, as samples and reports
    /// print it.
    pub fn plain(&self, key: u32) -> u32 {
        self.source(key).line
    }

    /// Whether every number is already plain (no subroutine file gave a move).
    pub fn is_plain(&self) -> bool {
        self.lines.is_empty()
    }
}

fn memchr_count(bytes: &[u8]) -> usize {
    memchr::memchr_iter(b'\n', bytes).count()
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
    /// A program named `name` (the path it was read from) with no subroutine file loaded yet
    /// (an owned `String` is moved, not copied twice).
    pub fn new(name: impl Into<String>, text: impl Into<Arc<str>>) -> Self {
        Sources {
            program: Source {
                name: name.into(),
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

    /// Where an error known only by its line is reported (the path and the kinematics keep
    /// lines, not columns): the line's first word, with the line's words as its width. The
    /// one column rule of every such report.
    pub fn line_at(&self, at: SourceLine) -> LineAt<'_> {
        let source = self.file(at.file);
        let text = &source.text;
        let start: usize = text
            .split_inclusive('\n')
            .take((at.line as usize).saturating_sub(1))
            .map(str::len)
            .sum();
        let body = text[start.min(text.len())..].lines().next().unwrap_or("");
        let indent = body.len() - body.trim_start().len();
        LineAt {
            source,
            span: Span::in_line(at.line, body, start, indent),
            width: body.trim().len().max(1),
        }
    }

    /// Where an interpreter error is and what it says: in the program, or in the subroutine
    /// file it names, whose message then says which program called it.
    pub fn error_at(&self, e: &GcodeError) -> ErrorAt<'_> {
        let Some(file) = &e.file else {
            return ErrorAt {
                source: Some(&self.program),
                at: Located {
                    file: self.program.name.clone(),
                    span: e.span,
                },
                message: e.kind.to_string(),
            };
        };
        let source = self.named(file);
        ErrorAt {
            source,
            at: Located {
                file: source.map_or_else(|| file.clone(), |s| s.name.clone()),
                span: e.span,
            },
            message: format!(
                "{} (in a subroutine called from {})",
                e.kind, self.program.name
            ),
        }
    }
}

/// An interpreter error for people: its place, the text it is in (`None` for a subroutine
/// file that was not loaded, which an error inside it cannot be) and its message.
#[derive(Debug, Clone)]
pub struct ErrorAt<'a> {
    pub source: Option<&'a Source>,
    pub at: Located,
    pub message: String,
}

/// A line's place in its file: the text, the span of its first word, and the bytes its words
/// take.
#[derive(Debug, Clone, Copy)]
pub struct LineAt<'a> {
    pub source: &'a Source,
    pub span: Span,
    pub width: usize,
}

impl LineAt<'_> {
    /// `file:line:col`, as every report starts.
    pub fn located(&self) -> Located {
        Located {
            file: self.source.name.clone(),
            span: self.span,
        }
    }
}

/// A place named for people: the file and the line and column in it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Located {
    /// How the file is named: the path it was read from, `<name>.ngc` for a subroutine file
    /// whose folder is not known, or the name the caller gave the program.
    pub file: String,
    pub span: Span,
}

impl std::fmt::Display for Located {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file, self.span)
    }
}

/// A program interpreted once: its moves (with [`LineKeys`] numbers), the errors and the texts.
pub struct Interpreted {
    pub moves: Vec<Move>,
    pub keys: LineKeys,
    /// Every error of the pre-flight, or the first one of a run.
    pub errors: Vec<GcodeError>,
    /// What ran but deserves a word: a text that ended without M2, M30 or `%` (run as if it
    /// ended with M2), placed as `file:line:col: text`.
    pub warnings: Vec<String>,
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
    let sources = sources.with_subroutines(&interp, locate);
    let warnings = interp
        .missing_end()
        .map(|e| {
            let at = sources.error_at(e);
            format!("{}: {}; run as if it ended with M2", at.at, at.message)
        })
        .into_iter()
        .collect();
    Interpreted {
        moves,
        keys,
        errors,
        warnings,
        sources,
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

    #[test]
    fn a_line_is_placed_at_its_first_word_in_its_own_file() {
        let sources = Sources::new("main.ngc", "G0 X1\n\u{e9}  G1 X2\n");
        // Line 2 starts at byte 6 with a word (the two-byte é): column 1, the whole line wide.
        let at = sources.line_at(SourceLine { file: 0, line: 2 });
        assert_eq!(
            at.located(),
            Located {
                file: "main.ngc".into(),
                span: Span {
                    line: 2,
                    column: 1,
                    offset: 6
                }
            }
        );
        assert_eq!(at.width, "\u{e9}  G1 X2".len());
        let indented = Sources::new("main.ngc", "G0 X1\n   G1 X2\n");
        let at = indented.line_at(SourceLine { file: 0, line: 2 });
        assert_eq!((at.span.column, at.span.offset, at.width), (4, 9, 5));
        assert_eq!(at.located().to_string(), "main.ngc:2:4");
        // A line past the end is placed at the end, never out of the text.
        let at = indented.line_at(SourceLine { file: 0, line: 9 });
        assert_eq!((at.span.line, at.span.offset), (9, 15));
    }
}
