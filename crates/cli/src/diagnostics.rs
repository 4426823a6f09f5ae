//! Rendering interpreter errors for people: file, line and column, the line, a caret.
//!
//! The library's errors carry a `Span`; here they become `miette` reports with the source.

use std::path::Path;

use miette::{miette, LabeledSpan, NamedSource, Report};
use tezgah_gcode::{Canon, CanonSink, GcodeError, Origin};

/// A report naming `file:line:col` and underlining the place in the source.
pub fn report(path: &Path, text: &str, e: &GcodeError) -> Report {
    let name = path.display().to_string();
    let span = e.span;
    if let Some(file) = &e.file {
        // In a subroutine file: name it; its text is not at hand here.
        return miette!(
            "{file}:{}:{}: {} (in a subroutine called from {name})",
            span.line,
            span.column,
            e.kind
        );
    }
    let label = LabeledSpan::at_offset(span.offset.min(text.len()), "here");
    miette!(
        labels = vec![label],
        "{name}:{}:{}: {}",
        span.line,
        span.column,
        e.kind
    )
    .with_source_code(NamedSource::new(name, text.to_string()))
}

/// A report for an error known only by its 1-based line (the path and the kinematics keep
/// lines, not columns): `file:line:col` of the line's first word, underlined.
pub fn report_line(path: &Path, text: &str, line: u32, message: &str) -> Report {
    let name = path.display().to_string();
    let start: usize = text
        .split_inclusive('\n')
        .take((line as usize).saturating_sub(1))
        .map(str::len)
        .sum();
    let body = text[start.min(text.len())..].lines().next().unwrap_or("");
    let indent = body.len() - body.trim_start().len();
    let width = body.trim().len().max(1);
    let label = LabeledSpan::at(
        (start + indent).min(text.len())..(start + indent + width).min(text.len()),
        "here",
    );
    miette!(
        labels = vec![label],
        "{name}:{line}:{}: {message}",
        indent + 1
    )
    .with_source_code(NamedSource::new(name, text.to_string()))
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
        self.lines = self.lines.max(origin.line);
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
