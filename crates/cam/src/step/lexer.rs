//! Part 21 tokens (ISO 10303-21 §5–6): the first stage of STEP input, turning the exchange
//! structure's text into keywords, numbers, strings, enumerations and references, each with
//! its 1-based line. The lexer works on bytes, so any input (even invalid UTF-8) gives tokens
//! or a syntax error, never a panic.

use super::error::StepError;

/// One token of the exchange structure.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Token {
    /// A standard or user-defined keyword (`B_SPLINE_SURFACE`, `!MY_ENTITY`), also the
    /// section names (`HEADER`, `ISO-10303-21`).
    Keyword(String),
    /// `#123`: an entity instance name.
    Ref(u64),
    Integer(i64),
    Real(f64),
    String(String),
    /// `.T.`, `.MILLI.`: the text between the dots.
    Enum(String),
    /// `"0A1"`: a binary, kept as written.
    Binary(String),
    /// `$`: an unset optional attribute.
    Unset,
    /// `*`: an attribute derived in a subtype.
    Derived,
    Open,
    Close,
    Comma,
    Semicolon,
    Equals,
}

/// A token and the line it starts on.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Lexed {
    pub token: Token,
    pub line: usize,
}

/// Splits `text` into tokens; comments `/* … */` and white space separate them.
pub(crate) fn tokenize(text: &[u8]) -> Result<Vec<Lexed>, StepError> {
    let mut lexer = Lexer {
        s: text,
        i: 0,
        line: 1,
    };
    let mut out = Vec::new();
    while let Some(t) = lexer.next()? {
        out.push(t);
    }
    Ok(out)
}

struct Lexer<'a> {
    s: &'a [u8],
    i: usize,
    line: usize,
}

impl<'a> Lexer<'a> {
    fn peek(&self, k: usize) -> Option<u8> {
        self.s.get(self.i + k).copied()
    }

    fn syntax(&self, line: usize, message: impl Into<String>) -> StepError {
        StepError::Syntax {
            line,
            message: message.into(),
        }
    }

    /// Skips white space and comments, counting lines.
    fn skip(&mut self) -> Result<(), StepError> {
        while let Some(c) = self.peek(0) {
            if c == b'\n' {
                self.line += 1;
                self.i += 1;
            } else if c.is_ascii_whitespace() {
                self.i += 1;
            } else if c == b'/' && self.peek(1) == Some(b'*') {
                let start = self.line;
                self.i += 2;
                loop {
                    match self.peek(0) {
                        None => return Err(self.syntax(start, "comment `/*` is never closed")),
                        Some(b'*') if self.peek(1) == Some(b'/') => {
                            self.i += 2;
                            break;
                        }
                        Some(b'\n') => {
                            self.line += 1;
                            self.i += 1;
                        }
                        Some(_) => self.i += 1,
                    }
                }
            } else {
                break;
            }
        }
        Ok(())
    }

    fn next(&mut self) -> Result<Option<Lexed>, StepError> {
        self.skip()?;
        let line = self.line;
        let Some(c) = self.peek(0) else {
            return Ok(None);
        };
        let token = match c {
            b'(' => self.single(Token::Open),
            b')' => self.single(Token::Close),
            b',' => self.single(Token::Comma),
            b';' => self.single(Token::Semicolon),
            b'=' => self.single(Token::Equals),
            b'$' => self.single(Token::Unset),
            b'*' => self.single(Token::Derived),
            b'#' => {
                self.i += 1;
                let digits = self.run(|c| c.is_ascii_digit());
                if digits.is_empty() {
                    return Err(self.syntax(line, "`#` must be followed by digits"));
                }
                let id = parse_u64(digits)
                    .ok_or_else(|| self.syntax(line, "entity instance name is too large"))?;
                Token::Ref(id)
            }
            b'\'' => self.string(line)?,
            b'"' => {
                self.i += 1;
                let body = self.run(|c| c.is_ascii_hexdigit());
                if self.peek(0) != Some(b'"') {
                    return Err(self.syntax(line, "binary `\"` is never closed"));
                }
                self.i += 1;
                Token::Binary(String::from_utf8_lossy(body).into_owned())
            }
            b'.' if self.peek(1).is_some_and(|c| c.is_ascii_alphabetic()) => {
                self.i += 1;
                let name = self.run(|c| c.is_ascii_alphanumeric() || c == b'_');
                if self.peek(0) != Some(b'.') {
                    return Err(self.syntax(line, "enumeration `.` is never closed"));
                }
                self.i += 1;
                Token::Enum(String::from_utf8_lossy(name).to_ascii_uppercase())
            }
            b'+' | b'-' | b'0'..=b'9' | b'.' => self.number(line)?,
            b'!' | b'A'..=b'Z' | b'a'..=b'z' | b'_' => {
                let word =
                    self.run(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'-' || c == b'!');
                Token::Keyword(String::from_utf8_lossy(word).to_ascii_uppercase())
            }
            other => {
                return Err(self.syntax(
                    line,
                    format!("unexpected character {:?}", char::from(other)),
                ))
            }
        };
        Ok(Some(Lexed { token, line }))
    }

    fn single(&mut self, t: Token) -> Token {
        self.i += 1;
        t
    }

    fn run(&mut self, keep: impl Fn(u8) -> bool) -> &'a [u8] {
        let (s, start) = (self.s, self.i);
        while self.peek(0).is_some_and(&keep) {
            self.i += 1;
        }
        &s[start..self.i]
    }

    /// `'…'` with `''` for an apostrophe; control directives (`\X2\…\X0\`) are kept as
    /// written: names and descriptions are only shown, never interpreted.
    fn string(&mut self, line: usize) -> Result<Token, StepError> {
        self.i += 1;
        let mut out = Vec::new();
        loop {
            match self.peek(0) {
                None => return Err(self.syntax(line, "string `'` is never closed")),
                Some(b'\'') if self.peek(1) == Some(b'\'') => {
                    out.push(b'\'');
                    self.i += 2;
                }
                Some(b'\'') => {
                    self.i += 1;
                    break;
                }
                Some(c) => {
                    if c == b'\n' {
                        self.line += 1;
                    }
                    out.push(c);
                    self.i += 1;
                }
            }
        }
        Ok(Token::String(String::from_utf8_lossy(&out).into_owned()))
    }

    /// `[sign] digits [. digits] [E [sign] digits]`; a `.` makes it a real. Writers differ
    /// (`1.`, `1.E-07`, `-0.`, lower-case `e`), so the form is read leniently and the value by
    /// Rust's correctly rounded parser.
    fn number(&mut self, line: usize) -> Result<Token, StepError> {
        let start = self.i;
        if matches!(self.peek(0), Some(b'+' | b'-')) {
            self.i += 1;
        }
        let int_digits = self.run(|c| c.is_ascii_digit()).len();
        let mut real = false;
        let mut frac_digits = 0;
        if self.peek(0) == Some(b'.') {
            real = true;
            self.i += 1;
            frac_digits = self.run(|c| c.is_ascii_digit()).len();
        }
        if int_digits + frac_digits == 0 {
            return Err(self.syntax(line, "a number needs digits"));
        }
        if matches!(self.peek(0), Some(b'E' | b'e')) {
            real = true;
            self.i += 1;
            if matches!(self.peek(0), Some(b'+' | b'-')) {
                self.i += 1;
            }
            if self.run(|c| c.is_ascii_digit()).is_empty() {
                return Err(self.syntax(line, "exponent without digits"));
            }
        }
        let text = std::str::from_utf8(&self.s[start..self.i])
            .map_err(|_| self.syntax(line, "malformed number"))?;
        if real {
            // Rust's parser wants a digit after a sign, `-.5` and `1.E5` are fine for it.
            let value: f64 = text
                .parse()
                .map_err(|_| self.syntax(line, format!("malformed real `{text}`")))?;
            if !value.is_finite() {
                return Err(self.syntax(line, format!("real `{text}` is out of range")));
            }
            Ok(Token::Real(value))
        } else {
            text.parse()
                .map(Token::Integer)
                .map_err(|_| self.syntax(line, format!("integer `{text}` is out of range")))
        }
    }
}

fn parse_u64(digits: &[u8]) -> Option<u64> {
    digits.iter().try_fold(0u64, |acc, &d| {
        acc.checked_mul(10)?.checked_add(u64::from(d - b'0'))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<Token> {
        tokenize(s.as_bytes())
            .unwrap()
            .into_iter()
            .map(|l| l.token)
            .collect()
    }

    #[test]
    fn reads_the_token_kinds() {
        assert_eq!(
            toks("#12 = A_B('it''s', (1, -2.5E-3, .T.), $, *, \"0F\") ; /* c */"),
            vec![
                Token::Ref(12),
                Token::Equals,
                Token::Keyword("A_B".into()),
                Token::Open,
                Token::String("it's".into()),
                Token::Comma,
                Token::Open,
                Token::Integer(1),
                Token::Comma,
                Token::Real(-2.5e-3),
                Token::Comma,
                Token::Enum("T".into()),
                Token::Close,
                Token::Comma,
                Token::Unset,
                Token::Comma,
                Token::Derived,
                Token::Comma,
                Token::Binary("0F".into()),
                Token::Close,
                Token::Semicolon,
            ]
        );
        assert_eq!(
            toks("1. 1.E-07 -0."),
            vec![Token::Real(1.0), Token::Real(1e-7), Token::Real(-0.0)]
        );
    }

    #[test]
    fn counts_lines_through_comments_and_strings() {
        let t = tokenize(b"/* a\nb */ 'x\ny'\n#1").unwrap();
        assert_eq!(t[0].line, 2);
        assert_eq!(t[1].line, 4);
    }

    #[test]
    fn overflow_is_an_error_not_a_panic() {
        let e = tokenize(b"\n99999999999999999999").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2: integer `99999999999999999999` is out of range"
        );
        let e = tokenize(b"1.0E99999999999999999999").unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 1: real `1.0E99999999999999999999` is out of range"
        );
        let e = tokenize(b"#99999999999999999999999").unwrap_err();
        assert_eq!(e.to_string(), "line 1: entity instance name is too large");
    }
}
