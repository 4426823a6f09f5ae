//! The lexer: one source line in, one normalised line out, following LinuxCNC's rules.
//!
//! LinuxCNC removes blanks everywhere and lower-cases everything outside comments before it
//! parses (`G 0 1 X 1 . 5` is `g01x1.5`). We do the same, but keep for every normalised byte
//! the byte it came from, so that words and errors still point at the real source column.
//! Comments are cut out into [`Comment`]s and leave a marker byte in the text, so that a comment
//! still separates what stands on either side of it (`X1(c)2` is an error, as in LinuxCNC).

use crate::error::ErrorKind;

/// Byte that stands in the normalised text where a `( … )` comment was.
pub const COMMENT_MARK: u8 = 0x01;

/// Whether `b` is copied to the normalised text as it is (lower-cased): anything but blanks,
/// comment openers, `%` and the comment marker.
#[inline]
fn is_plain(b: u8) -> bool {
    // All the special bytes are below 64: one shift and mask instead of seven comparisons.
    const SPECIAL: u64 =
        1 << b' ' | 1 << b'\t' | 1 << b'\r' | 1 << b';' | 1 << b'(' | 1 << b'%' | 1 << COMMENT_MARK;
    b >= 64 || SPECIAL >> b & 1 == 0
}

/// A `( … )` comment: its text without the parentheses and leading blanks, and where it began.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Comment {
    pub text: String,
    /// Byte offset of the opening parenthesis in the source line.
    pub at: usize,
}

/// A normalised line. The buffers are reused from line to line so that lexing allocates nothing
/// in the steady state.
#[derive(Debug, Default, Clone)]
pub struct NormLine {
    /// Buffer of the lower-cased text without blanks (each comment replaced by
    /// [`COMMENT_MARK`]) in its first `len` bytes; see [`NormLine::text`].
    text: Vec<u8>,
    /// Buffer of the source offsets in its first `len` entries; see [`NormLine::at`].
    at: Vec<u32>,
    /// Length of the normalised line. The buffers keep the longest line's length so that
    /// lexing neither fills nor cuts them per line.
    len: usize,
    /// The comments, in order; the i-th [`COMMENT_MARK`] stands for the i-th comment.
    pub comments: Vec<Comment>,
    /// Byte offset in the source line of a `%` that no comment precedes. Lexing stops there:
    /// such a line is either a lone `%` (a program delimiter) or an error.
    pub percent: Option<usize>,
    /// Whether the line holds a `#` anywhere (a parameter read or write, also in a DEBUG or
    /// PRINT comment): only then do the interpreter's published values need refreshing.
    pub mentions_parameters: bool,
}

impl NormLine {
    /// Normalise `raw` (one line without its line terminator) into `self`.
    /// On error returns the kind and the byte offset in `raw` where it was found.
    pub fn lex(&mut self, raw: &str) -> Result<(), (ErrorKind, usize)> {
        self.comments.clear();
        self.percent = None;
        let bytes = raw.as_bytes();
        self.mentions_parameters = memchr::memchr(b'#', bytes).is_some();
        // The normalised line is never longer than the source line: with buffers at least
        // that long, write by index with a local length (a `push` per byte stores the length
        // and checks the capacity every time, and was most of the lexer's cost).
        if self.text.len() < bytes.len() {
            self.text.resize(bytes.len(), 0);
            self.at.resize(bytes.len(), 0);
        }
        let mut out = Out {
            text: &mut self.text,
            at: &mut self.at,
            len: 0,
        };
        let result = lex_into(raw, &mut out, &mut self.comments, &mut self.percent);
        self.len = out.len;
        result
    }

    /// Lower-cased text without blanks; each comment replaced by [`COMMENT_MARK`].
    #[inline]
    pub fn text(&self) -> &[u8] {
        &self.text[..self.len]
    }

    /// For each byte of [`NormLine::text`], its byte offset in the source line.
    #[inline]
    pub fn at(&self) -> &[u32] {
        &self.at[..self.len]
    }
}

/// The normalised text being written: the sized buffers and how much of them is written.
struct Out<'a> {
    text: &'a mut [u8],
    at: &'a mut [u32],
    len: usize,
}

impl Out<'_> {
    /// Append byte `b` that came from source offset `at`. Callers write at most one byte per
    /// source byte, so `len` stays within the buffers.
    #[inline]
    fn put(&mut self, b: u8, at: usize) {
        self.text[self.len] = b;
        self.at[self.len] = at as u32;
        self.len += 1;
    }
}

/// The lexer's loop over `raw`, writing into `out` (see [`NormLine::lex`]).
fn lex_into(
    raw: &str,
    out: &mut Out,
    comments: &mut Vec<Comment>,
    percent: &mut Option<usize>,
) -> Result<(), (ErrorKind, usize)> {
    let bytes = raw.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        if is_plain(b) {
            out.put(b.to_ascii_lowercase(), i);
            i += 1;
            continue;
        }
        match b {
            // A semicolon makes the rest of the line a comment that LinuxCNC ignores.
            b';' => break,
            b'(' => {
                let (comment, next) = lex_comment(raw, i)?;
                comments.push(comment);
                out.put(COMMENT_MARK, i);
                i = next;
                continue;
            }
            b'%' if comments.is_empty() => {
                *percent = Some(i);
                break;
            }
            b'%' => out.put(b'%', i),
            // The source may not hold the byte that stands for a comment here.
            COMMENT_MARK => return Err((ErrorKind::BadCharacter(COMMENT_MARK as char), i)),
            // Blanks.
            _ => {}
        }
        i += 1;
    }
    Ok(())
}

/// Read the comment that opens at `open`; return it and the index just past its `)`.
fn lex_comment(raw: &str, open: usize) -> Result<(Comment, usize), (ErrorKind, usize)> {
    let bytes = raw.as_bytes();
    let mut j = open + 1;
    while j < bytes.len() && matches!(bytes[j], b' ' | b'\t') {
        j += 1;
    }
    let start = j;
    loop {
        match bytes.get(j) {
            None => return Err((ErrorKind::UnclosedComment, open)),
            Some(b'(') => return Err((ErrorKind::NestedComment, j)),
            Some(b')') => break,
            Some(_) => j += 1,
        }
    }
    let comment = Comment {
        text: raw[start..j].to_string(),
        at: open,
    };
    Ok((comment, j + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(s: &str) -> NormLine {
        let mut l = NormLine::default();
        l.lex(s).unwrap();
        l
    }

    #[test]
    fn blanks_removed_and_case_folded() {
        let l = lex("G 0 1 X 1 . 5\tY-2");
        assert_eq!(l.text(), b"g01x1.5y-2");
        assert_eq!(l.at()[3], 6); // the 'x'
    }

    #[test]
    fn comments_keep_case_and_leave_a_mark() {
        let l = lex("g0 x1 (  Hello World) y2 ; rest");
        assert_eq!(l.text(), b"g0x1\x01y2");
        assert_eq!(l.comments[0].text, "Hello World");
        assert_eq!(l.comments[0].at, 6);
    }

    #[test]
    fn comment_errors() {
        let mut l = NormLine::default();
        assert_eq!(l.lex("g0 (open"), Err((ErrorKind::UnclosedComment, 3)));
        assert_eq!(l.lex("g0 (a (b) c)"), Err((ErrorKind::NestedComment, 6)));
        // Found by fuzzing: a raw comment-marker byte once reached the comment table.
        assert_eq!(
            l.lex("G0 X1\x01"),
            Err((ErrorKind::BadCharacter('\x01'), 5))
        );
    }
}
