//! Source positions: every word, comment and error keeps the line and column it came from.
//!
//! Columns count characters (not bytes) from 1, as editors do; `offset` is the byte offset of the
//! position in the whole program text, for renderers that underline the source.

/// A position in a program's text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct Span {
    /// 1-based line number.
    pub line: u32,
    /// 1-based column, in characters.
    pub column: u32,
    /// Byte offset from the start of the program text.
    pub offset: usize,
}

impl Span {
    /// The span of byte `byte_in_line` of a line that starts at byte `line_start` of the program.
    pub fn in_line(line: u32, line_text: &str, line_start: usize, byte_in_line: usize) -> Span {
        let byte = byte_in_line.min(line_text.len());
        let column = line_text
            .get(..byte)
            .map_or(byte, |prefix| prefix.chars().count()) as u32
            + 1;
        Span {
            line,
            column,
            offset: line_start + byte,
        }
    }
}

impl std::fmt::Display for Span {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}
