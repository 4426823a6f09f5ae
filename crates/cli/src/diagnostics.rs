//! Rendering interpreter errors for people: file, line and column, the line, a caret.
//!
//! The library's errors carry a `Span`; here they become `miette` reports with the source.

use miette::{miette, LabeledSpan, NamedSource, Report};
use tezgah_gcode::sources::{Source, SourceLine, Sources};
use tezgah_gcode::{Canon, CanonSink, GcodeError, Origin, Span};

/// A report naming `file:line:col` and underlining the place in the file the error is in (the
/// program, or a subroutine file it called).
pub fn report(sources: &Sources, e: &GcodeError) -> Report {
    let error = sources.error_at(e);
    match error.source {
        Some(source) => located(source, e.span, 0, &error.message),
        // Not loaded (cannot happen for an error inside it): name it without its text.
        None => miette!("{}: {}", error.at, error.message),
    }
}

/// A report for an error known only by its line (the path and the kinematics keep lines, not
/// columns): `file:line:col` of the line's first word, the line's words underlined.
pub fn report_line(sources: &Sources, at: SourceLine, message: &str) -> Report {
    let line = sources.line_at(at);
    located(line.source, line.span, line.width, message)
}

/// `file:line:col: message`, with `width` bytes from the span underlined (a point for 0).
fn located(source: &Source, span: Span, width: usize, message: &str) -> Report {
    let len = source.text.len();
    let from = span.offset.min(len);
    let label = match width {
        0 => LabeledSpan::at_offset(from, "here"),
        _ => LabeledSpan::at(from..(from + width).min(len), "here"),
    };
    miette!(labels = vec![label], "{}:{span}: {message}", source.name)
        .with_source_code(NamedSource::new(&source.name, source.text.to_string()))
}

/// Counts of what a program does, for `check`'s summary line.
#[derive(Default)]
pub struct Counts {
    lines: u32,
    rapids: usize,
    feeds: usize,
    arcs: usize,
    nurbs: usize,
    dwells: usize,
}

impl CanonSink for Counts {
    fn call(&mut self, origin: Origin, call: Canon) {
        if origin.file == 0 {
            self.lines = self.lines.max(origin.line);
        }
        match call {
            Canon::StraightTraverse(_) => self.rapids += 1,
            Canon::StraightFeed(_) => self.feeds += 1,
            Canon::ArcFeed { .. } => self.arcs += 1,
            Canon::NurbsFeed(_) => self.nurbs += 1,
            Canon::Dwell(_) => self.dwells += 1,
            _ => {}
        }
    }
}

impl std::fmt::Display for Counts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} lines, {} rapid, {} feed, {} arc, {} NURBS moves, {} dwells",
            self.lines, self.rapids, self.feeds, self.arcs, self.nurbs, self.dwells
        )
    }
}
