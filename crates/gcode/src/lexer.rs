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
    !matches!(b, b' ' | b'\t' | b'\r' | b';' | b'(' | b'%' | COMMENT_MARK)
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
    /// Lower-cased text without blanks; each comment replaced by [`COMMENT_MARK`].
    pub text: Vec<u8>,
    /// For each byte of `text`, its byte offset in the source line.
    pub at: Vec<u32>,
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
        self.text.clear();
        self.at.clear();
        self.comments.clear();
        self.percent = None;
        let bytes = raw.as_bytes();
        self.mentions_parameters = memchr::memchr(b'#', bytes).is_some();
        self.text.reserve(bytes.len());
        self.at.reserve(bytes.len());
        let mut i = 0;
        while i < bytes.len() {
            // Copy a run of ordinary bytes at once: it is most of every line.
            let run = bytes[i..].iter().take_while(|&&b| is_plain(b)).count();
            if run > 0 {
                let end = i + run;
                self.text
                    .extend(bytes[i..end].iter().map(u8::to_ascii_lowercase));
                self.at.extend(i as u32..end as u32);
                i = end;
                continue;
            }
            match bytes[i] {
                // A semicolon makes the rest of the line a comment that LinuxCNC ignores.
                b';' => break,
                b'(' => {
                    i = self.lex_comment(raw, i)?;
                    continue;
                }
                b'%' if self.comments.is_empty() => {
                    self.percent = Some(i);
                    break;
                }
                b'%' => {
                    self.text.push(b'%');
                    self.at.push(i as u32);
                }
                // The source may not hold the byte that stands for a comment here.
                COMMENT_MARK => return Err((ErrorKind::BadCharacter(COMMENT_MARK as char), i)),
                // Blanks.
                _ => {}
            }
            i += 1;
        }
        Ok(())
    }

    /// Read the comment that opens at `open`; return the index just past its `)`.
    fn lex_comment(&mut self, raw: &str, open: usize) -> Result<usize, (ErrorKind, usize)> {
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
        self.comments.push(Comment {
            text: raw[start..j].to_string(),
            at: open,
        });
        self.text.push(COMMENT_MARK);
        self.at.push(open as u32);
        Ok(j + 1)
    }
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
        assert_eq!(l.text, b"g01x1.5y-2");
        assert_eq!(l.at[3], 6); // the 'x'
    }

    #[test]
    fn comments_keep_case_and_leave_a_mark() {
        let l = lex("g0 x1 (  Hello World) y2 ; rest");
        assert_eq!(l.text, b"g0x1\x01y2");
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
