//! Comments that do something (LinuxCNC's `convert_comment`): `(MSG,…)` shows a message,
//! `(DEBUG,…)` and `(PRINT,…)` show one with parameter values filled in, `(ABORT,…)` stops the
//! program with its (filled-in) text as the error; any other comment is passed on.
//!
//! Values are filled in as LinuxCNC's `convert_param_comment` does: `#n` and `#<name>` become
//! the value with `%.6f`, or in the format of the last `%d` (`%.0f`), `%f` (`%.4f`) or `%.Nf`
//! written before them; a name that is not defined prints as `######`.

use crate::canon::{Canon, CanonSink};
use crate::error::ErrorKind;
use crate::params::Params;

use super::execute::Exec;
use super::Interpreter;

/// Text printed for a parameter that has no value.
const NO_VALUE: &str = "######";

impl Interpreter {
    /// Act on the block's comment.
    pub(super) fn comment(&mut self, text: &str, at: u32, sink: &mut impl CanonSink) -> Exec {
        let lower = text.get(..6).unwrap_or(text).to_ascii_lowercase();
        if lower.starts_with("msg,") {
            self.emit(sink, Canon::Message(text[4..].to_string()));
        } else if lower.starts_with("debug,") {
            let expanded = self.expand(&text[6..]).map_err(|k| (k, at))?;
            self.emit(sink, Canon::Message(expanded));
        } else if lower.starts_with("print,") {
            let expanded = self.expand(&text[6..]).map_err(|k| (k, at))?;
            self.emit(sink, Canon::Print(expanded));
        } else if lower.starts_with("abort,") {
            let expanded = self.expand(&text[6..]).map_err(|k| (k, at))?;
            return Err((ErrorKind::Abort(expanded), at));
        } else {
            self.emit(sink, Canon::Comment(text.to_string()));
        }
        Ok(())
    }

    /// `text` with its parameters replaced by their values.
    fn expand(&self, text: &str) -> Result<String, ErrorKind> {
        expand_parameters(text, &self.params)
    }
}

/// The value of a parameter written in a comment: `#` then digits, or `#<name>` (blanks inside
/// the name ignored, lower-cased). `None` if the text after `#` is neither.
enum CommentParam {
    Number(usize),
    Name(String),
}

/// Port of LinuxCNC's `convert_param_comment`.
pub(super) fn expand_parameters(text: &str, params: &Params) -> Result<String, ErrorKind> {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut precision = 6;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'%' => {
                i += 1;
                match (b.get(i), b.get(i + 1), b.get(i + 2)) {
                    (Some(b'd'), ..) => {
                        precision = 0;
                        i += 1;
                    }
                    (Some(b'f'), ..) => {
                        precision = 4;
                        i += 1;
                    }
                    (Some(b'.'), Some(d), Some(b'f')) if d.is_ascii_digit() => {
                        precision = usize::from(d - b'0');
                        i += 3;
                    }
                    (Some(b'.'), ..) => {
                        out.push('.');
                        i += 1;
                    }
                    _ => out.push('%'),
                }
            }
            b'#' => {
                i += 1;
                if i >= b.len() {
                    return Err(ErrorKind::NamedParameterNotTerminated);
                }
                let param = if b[i].is_ascii_digit() {
                    let digits = b[i..].iter().take_while(|c| c.is_ascii_digit()).count();
                    let n = text[i..i + digits].parse::<usize>().ok();
                    i += digits;
                    n.map(CommentParam::Number)
                } else if b[i] == b'<' {
                    i += 1;
                    let mut name = String::new();
                    while i < b.len() && b[i] != b'>' && b[i] != b')' {
                        if !b[i].is_ascii_whitespace() {
                            name.push(char::from(b[i].to_ascii_lowercase()));
                        }
                        i += 1;
                    }
                    if b.get(i) != Some(&b'>') {
                        return Err(ErrorKind::NamedParameterNotTerminated);
                    }
                    i += 1;
                    Some(CommentParam::Name(name))
                } else {
                    out.push('#');
                    continue;
                };
                let value = match param {
                    Some(CommentParam::Number(n)) if Params::in_range(n as i64) => {
                        Some(params.get(n))
                    }
                    Some(CommentParam::Name(name)) => params.named(&name),
                    _ => None,
                };
                match value {
                    // LinuxCNC prints values within 1e-4 of zero as zero (no "-0.000000").
                    Some(v) => {
                        let v = if v.abs() < 1e-4 { 0.0 } else { v };
                        out.push_str(&format!("{v:.precision$}"));
                    }
                    None => out.push_str(NO_VALUE),
                }
            }
            _ => {
                let ch = text[i..].chars().next().unwrap_or(' ');
                out.push(ch);
                i += ch.len_utf8();
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> Params {
        let mut p = Params::default();
        p.set(42, 20.0);
        p.set_named("value", 1.123456789);
        p.set(7, -0.00001);
        p
    }

    #[test]
    fn formats_follow_linuxcnc() {
        let p = params();
        let cases = [
            ("v=#<value>", "v=1.123457"),
            ("%d#<value>", "1"),
            ("%f#<value>", "1.1235"),
            ("%f the value is: #<value>", " the value is: 1.1235"),
            ("%.7f#<value>", "1.1234568"),
            ("#42 #< v a l u e >", "20.000000 1.123457"),
            ("#7", "0.000000"),
            ("#<nosuch> # 5%x 1.5%.x", "###### # 5%x 1.5.x"),
        ];
        for (text, want) in cases {
            assert_eq!(expand_parameters(text, &p).unwrap(), want, "{text}");
        }
    }

    #[test]
    fn unterminated_names_are_errors() {
        let p = params();
        for text in ["#<value", "a #", "#<value)"] {
            assert_eq!(
                expand_parameters(text, &p),
                Err(ErrorKind::NamedParameterNotTerminated),
                "{text}"
            );
        }
    }
}
