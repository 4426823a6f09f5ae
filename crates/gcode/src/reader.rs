//! Reading values from a normalised line: numbers, parameters, `[ … ]` expressions and the
//! unary functions, with LinuxCNC's precedence and its degree-based trigonometry.
//!
//! As in LinuxCNC, values are evaluated while the line is read, against the parameter values as
//! they stood before the line (a block's own assignments take effect after it is read).

use crate::error::ErrorKind;
use crate::params::Params;

/// Equality tolerance of `EQ`/`NE`: LinuxCNC 2.9's `TOLERANCE_EQUAL` (interp_internal.hh),
/// 0.0001, so `[EXP[-9.2104] EQ 0]` is true there and here.
pub(crate) const TOLERANCE_EQUAL: f64 = 1e-4;

/// An error and the index in the normalised text where it was found.
pub type ReadError = (ErrorKind, usize);
pub type ReadResult<T> = Result<T, ReadError>;

/// A cursor over one normalised line.
pub struct Reader<'a> {
    pub text: &'a [u8],
    pub pos: usize,
    pub params: &'a Params,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum BinOp {
    Power,
    Times,
    Divide,
    Modulo,
    Plus,
    Minus,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    Xor,
}

impl BinOp {
    /// LinuxCNC's precedence: `**` > `* / MOD` > `+ -` > comparisons > logic; all left-assoc.
    fn precedence(self) -> u8 {
        use BinOp::*;
        match self {
            Power => 6,
            Times | Divide | Modulo => 5,
            Plus | Minus => 4,
            Eq | Ne | Gt | Ge | Lt | Le => 3,
            And | Or | Xor => 2,
        }
    }

    fn apply(self, l: f64, r: f64) -> Result<f64, ErrorKind> {
        use BinOp::*;
        let truth = |b: bool| if b { 1.0 } else { 0.0 };
        Ok(match self {
            Power => {
                if l < 0.0 && r.floor() != r {
                    return Err(ErrorKind::NegativePower);
                }
                l.powf(r)
            }
            Times => l * r,
            Divide => {
                if r == 0.0 {
                    return Err(ErrorKind::DivisionByZero);
                }
                l / r
            }
            Modulo => {
                let m = l % r;
                if m < 0.0 {
                    m + r.abs()
                } else {
                    m
                }
            }
            Plus => l + r,
            Minus => l - r,
            Eq => truth((l - r).abs() < TOLERANCE_EQUAL),
            Ne => truth((l - r).abs() >= TOLERANCE_EQUAL),
            Gt => truth(l > r),
            Ge => truth(l >= r),
            Lt => truth(l < r),
            Le => truth(l <= r),
            And => truth(l != 0.0 && r != 0.0),
            Or => truth(l != 0.0 || r != 0.0),
            Xor => truth((l != 0.0) != (r != 0.0)),
        })
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Unary {
    Abs,
    Acos,
    Asin,
    Atan,
    Cos,
    Exp,
    Exists,
    Fix,
    Fup,
    Ln,
    Round,
    Sin,
    Sqrt,
    Tan,
}

const UNARY_NAMES: [(&[u8], Unary); 14] = [
    (b"abs", Unary::Abs),
    (b"acos", Unary::Acos),
    (b"asin", Unary::Asin),
    (b"atan", Unary::Atan),
    (b"cos", Unary::Cos),
    (b"exp", Unary::Exp),
    (b"exists", Unary::Exists),
    (b"fix", Unary::Fix),
    (b"fup", Unary::Fup),
    (b"ln", Unary::Ln),
    (b"round", Unary::Round),
    (b"sin", Unary::Sin),
    (b"sqrt", Unary::Sqrt),
    (b"tan", Unary::Tan),
];

impl Unary {
    fn apply(self, x: f64) -> Result<f64, ErrorKind> {
        use Unary::*;
        let rad = x.to_radians();
        Ok(match self {
            Abs => x.abs(),
            Acos => {
                if !(-1.0..=1.0).contains(&x) {
                    return Err(ErrorKind::AcosOutOfRange);
                }
                x.acos().to_degrees()
            }
            Asin => {
                if !(-1.0..=1.0).contains(&x) {
                    return Err(ErrorKind::AsinOutOfRange);
                }
                x.asin().to_degrees()
            }
            Cos => rad.cos(),
            Sin => rad.sin(),
            Tan => rad.tan(),
            Exp => x.exp(),
            Fix => x.floor(),
            Fup => x.ceil(),
            Ln => {
                if x <= 0.0 {
                    return Err(ErrorKind::LogOfNonPositive);
                }
                x.ln()
            }
            // C's (int)(x ± 0.5): rounds half away from zero.
            // LinuxCNC rounds through an integer, so −0.4 gives +0, never −0 (which would
            // turn ATAN[0]/[ROUND[−0.4]] into 180°).
            Round => (x + if x < 0.0 { -0.5 } else { 0.5 }).trunc() + 0.0,
            Sqrt => {
                if x < 0.0 {
                    return Err(ErrorKind::SqrtOfNegative);
                }
                x.sqrt()
            }
            Atan | Exists => unreachable!("two-argument and parameter functions are read apart"),
        })
    }
}

/// Where a parameter lives.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamRef {
    Numbered(usize),
    Named(String),
}

impl<'a> Reader<'a> {
    pub fn new(text: &'a [u8], pos: usize, params: &'a Params) -> Self {
        Reader { text, pos, params }
    }

    fn peek(&self) -> Option<u8> {
        self.text.get(self.pos).copied()
    }

    fn err<T>(&self, kind: ErrorKind) -> ReadResult<T> {
        Err((kind, self.pos))
    }

    /// A real value: a number, a parameter, a bracketed expression, a unary function, or one of
    /// these after a sign.
    pub fn real_value(&mut self) -> ReadResult<f64> {
        match self.peek() {
            None => self.err(ErrorKind::NoCharactersInRealValue),
            Some(b'[') => self.expression(),
            Some(b'#') => self.parameter_value(),
            Some(c @ (b'+' | b'-'))
                if !matches!(self.text.get(self.pos + 1), Some(b'0'..=b'9' | b'.')) =>
            {
                self.pos += 1;
                let v = self.real_value()?;
                Ok(if c == b'-' { -v } else { v })
            }
            Some(b'a'..=b'z') => self.unary(),
            Some(_) => self.number(),
        }
    }

    /// [`Reader::real_value`], with the plain number (most words of most programs) read
    /// inline first: [`quick_number`] accepts only text that `real_value` would hand to
    /// [`Reader::number`], which reads it the same way, so the value is the same.
    #[inline]
    pub fn word_value(&mut self) -> ReadResult<f64> {
        match quick_number(self.text, self.pos) {
            Some(quick) => {
                self.pos = quick.end;
                Ok(quick.value)
            }
            None => self.real_value(),
        }
    }

    /// A value that must be an integer (within 1e-4), rounded to it.
    pub fn integer_value(&mut self) -> ReadResult<i64> {
        let start = self.pos;
        let v = self.real_value()?;
        integer_of(v).ok_or((ErrorKind::NonIntegerValue, start))
    }

    /// A literal number: signs, then digits and dots, read exactly as C++ streams read them.
    pub fn number(&mut self) -> ReadResult<f64> {
        let start = self.pos;
        let t = self.text;
        if let Some(quick) = quick_number(t, start) {
            self.pos = quick.end;
            return Ok(quick.value);
        }
        let mut i = start;
        while i < t.len() && matches!(t[i], b'+' | b'-') {
            i += 1;
        }
        let signs = i - start;
        // One pass gathers the digits as an integer (while they fit) for the quick path.
        let mut digits = Digits::default();
        let mut dots = 0;
        while let Some(&b) = t.get(i) {
            match b {
                b'0'..=b'9' if dots < 2 => digits.push(b - b'0', dots == 1),
                b'0'..=b'9' => {}
                b'.' => dots += 1,
                _ => break,
            }
            i += 1;
        }
        let whole = || String::from_utf8_lossy(&t[start..i]).into_owned();
        if signs > 1 || digits.count == 0 {
            return Err((ErrorKind::BadNumberFormat(whole()), start));
        }
        if dots > 1 {
            return Err((ErrorKind::TrailingCharacters(whole()), start));
        }
        let v = match digits.exact_value() {
            Some(v) if t[start] == b'-' => -v,
            Some(v) => v,
            // The slice holds ASCII signs, digits and at most one dot, with a digit: valid
            // UTF-8 and valid for Rust's correctly rounded float parser (C's strtod grammar).
            None => std::str::from_utf8(&t[start..i])
                .ok()
                .and_then(|s| s.parse().ok())
                .ok_or_else(|| (ErrorKind::BadNumberFormat(whole()), start))?,
        };
        self.pos = i;
        Ok(v)
    }

    /// `#n`, `##n`, `#[expr]` or `#<name>`: the parameter's value.
    fn parameter_value(&mut self) -> ReadResult<f64> {
        let at = self.pos;
        match self.parameter_ref()? {
            ParamRef::Numbered(n) => Ok(self.params.get(n)),
            ParamRef::Named(name) => match self.params.named(&name) {
                Some(v) => Ok(v),
                None => Err((ErrorKind::NamedParameterNotDefined(name), at)),
            },
        }
    }

    /// Read `#…` and say which parameter it names (used for reads and for assignments).
    pub fn parameter_ref(&mut self) -> ReadResult<ParamRef> {
        debug_assert_eq!(self.peek(), Some(b'#'));
        self.pos += 1;
        if self.peek() == Some(b'<') {
            return self.named_parameter().map(ParamRef::Named);
        }
        let at = self.pos;
        let n = self.integer_value()?;
        if !Params::in_range(n) {
            return Err((ErrorKind::ParameterOutOfRange, at));
        }
        Ok(ParamRef::Numbered(n as usize))
    }

    /// `<name>` after `#`; returns the name (already lower case, blanks removed).
    fn named_parameter(&mut self) -> ReadResult<String> {
        let start = self.pos + 1;
        let t = self.text;
        let mut i = start;
        while i < t.len() && t[i] != b'>' {
            i += 1;
        }
        if i >= t.len() {
            return Err((ErrorKind::NamedParameterNotTerminated, self.pos));
        }
        let name = String::from_utf8_lossy(&t[start..i]).into_owned();
        self.pos = i + 1;
        Ok(name)
    }

    /// `[ value { op value } ]`, evaluated by precedence climbing.
    pub fn expression(&mut self) -> ReadResult<f64> {
        debug_assert_eq!(self.peek(), Some(b'['));
        self.pos += 1;
        let v = self.binary(1)?;
        match self.peek() {
            Some(b']') => {
                self.pos += 1;
                // A bracket's value must be a finite number; inside it NaN and infinity may
                // pass through comparisons (`[0 EQ [0 MOD 0]]` is 0), as in LinuxCNC.
                finite(v).map_err(|k| (k, self.pos - 1))
            }
            None => self.err(ErrorKind::UnclosedExpression),
            Some(_) => self.err(ErrorKind::UnknownOperation),
        }
    }

    /// Left-associative precedence climbing over operators binding at least `min`.
    fn binary(&mut self, min: u8) -> ReadResult<f64> {
        let mut left = self.real_value()?;
        loop {
            let save = self.pos;
            let Some(op) = self.operator()? else {
                return Ok(left);
            };
            if op.precedence() < min {
                self.pos = save;
                return Ok(left);
            }
            let at = save;
            let right = self.binary(op.precedence() + 1)?;
            left = op.apply(left, right).map_err(|k| (k, at))?;
        }
    }

    /// The binary operator at the cursor, or `None` at a closing bracket.
    fn operator(&mut self) -> ReadResult<Option<BinOp>> {
        let t = &self.text[self.pos..];
        let (op, len) = match t {
            [] => return self.err(ErrorKind::UnclosedExpression),
            [b']', ..] => return Ok(None),
            [b'*', b'*', ..] => (BinOp::Power, 2),
            [b'*', ..] => (BinOp::Times, 1),
            [b'/', ..] => (BinOp::Divide, 1),
            [b'+', ..] => (BinOp::Plus, 1),
            [b'-', ..] => (BinOp::Minus, 1),
            [b'm', b'o', b'd', ..] => (BinOp::Modulo, 3),
            [b'a', b'n', b'd', ..] => (BinOp::And, 3),
            [b'x', b'o', b'r', ..] => (BinOp::Xor, 3),
            [b'o', b'r', ..] => (BinOp::Or, 2),
            [b'e', b'q', ..] => (BinOp::Eq, 2),
            [b'n', b'e', ..] => (BinOp::Ne, 2),
            [b'g', b't', ..] => (BinOp::Gt, 2),
            [b'g', b'e', ..] => (BinOp::Ge, 2),
            [b'l', b't', ..] => (BinOp::Lt, 2),
            [b'l', b'e', ..] => (BinOp::Le, 2),
            [c @ (b'm' | b'a' | b'x' | b'o' | b'e' | b'n' | b'g' | b'l'), ..] => {
                return self.err(ErrorKind::UnknownOperationName(
                    c.to_ascii_uppercase() as char
                ))
            }
            _ => return self.err(ErrorKind::UnknownOperation),
        };
        self.pos += len;
        Ok(Some(op))
    }

    /// A unary function: `name[expr]`, `atan[y]/[x]` or `exists[#param]`.
    fn unary(&mut self) -> ReadResult<f64> {
        let at = self.pos;
        let rest = &self.text[self.pos..];
        let Some(&(name, op)) = UNARY_NAMES
            .iter()
            .filter(|(name, _)| rest.starts_with(name))
            .max_by_key(|(name, _)| name.len())
        else {
            return self.err(ErrorKind::UnknownWord(rest[0] as char));
        };
        self.pos += name.len();
        if self.peek() != Some(b'[') {
            return self.err(ErrorKind::UnaryMissingBracket);
        }
        match op {
            Unary::Exists => self.exists(),
            Unary::Atan => {
                let y = self.expression()?;
                if self.peek() != Some(b'/') {
                    return self.err(ErrorKind::AtanMissingSlash);
                }
                self.pos += 1;
                if self.peek() != Some(b'[') {
                    return self.err(ErrorKind::AtanMissingBracket);
                }
                let x = self.expression()?;
                Ok(y.atan2(x).to_degrees())
            }
            _ => {
                // A function's value is refused at once when not finite (`0 * EXP[1000]` is
                // 'infinity', not 'not a number'), unlike an operator's.
                let x = self.expression()?;
                op.apply(x).and_then(finite).map_err(|k| (k, at))
            }
        }
    }

    /// `exists[#<name>]`: 1 if the named parameter is defined (numbered ones exist when their
    /// number is in range).
    fn exists(&mut self) -> ReadResult<f64> {
        self.pos += 1; // '['
        if self.peek() != Some(b'#') {
            return self.err(ErrorKind::ExpectedHash);
        }
        // A numbered parameter exists when its number is in range (an out-of-range number is
        // an error only where it is read, as in `EXISTS[###2]`).
        let found = if self.text.get(self.pos + 1) == Some(&b'<') {
            match self.parameter_ref()? {
                ParamRef::Named(name) => self.params.named(&name).is_some(),
                ParamRef::Numbered(_) => true,
            }
        } else {
            self.pos += 1;
            Params::in_range(self.integer_value()?)
        };
        if self.peek() != Some(b']') {
            return self.err(ErrorKind::ExpectedCloseBracket);
        }
        self.pos += 1;
        Ok(if found { 1.0 } else { 0.0 })
    }
}

/// An operation's result, refused when it is not a finite number, as LinuxCNC refuses it.
fn finite(v: f64) -> Result<f64, ErrorKind> {
    if v.is_nan() {
        Err(ErrorKind::NotANumber)
    } else if v.is_infinite() {
        Err(ErrorKind::Infinity)
    } else {
        Ok(v)
    }
}

/// The integer `v` stands for, if it is within 1e-4 of one (LinuxCNC's `read_integer_value`).
pub fn integer_of(v: f64) -> Option<i64> {
    let r = v.round();
    ((v - r).abs() < 1e-4 && r.abs() < 9.0e15).then_some(r as i64)
}

/// Exact powers of ten up to 10²² (every one is an `f64` without rounding).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A number read by [`quick_number`]: its value and the index just past it.
struct QuickNumber {
    value: f64,
    end: usize,
}

/// The common number, `[sign]digits[.digits]` with at most 19 digits whose integer is at most
/// 2⁵³ and at most 22 decimals, read in one tight pass; `None` for anything else (more signs or
/// dots, no digit, too many digits), which [`Reader::number`] then reads the general way. The
/// value is the same correctly rounded one (see [`Digits::exact_value`]); 19 digits always
/// fit a `u64`, so the wrapping arithmetic never wraps on a number this path accepts.
#[inline]
fn quick_number(t: &[u8], start: usize) -> Option<QuickNumber> {
    let sign = t.get(start).filter(|&&b| matches!(b, b'+' | b'-'));
    let negative = sign == Some(&b'-');
    let mut i = start + usize::from(sign.is_some());
    let digit = |i: usize| t.get(i).map(|b| b.wrapping_sub(b'0')).filter(|&d| d <= 9);
    let mut mantissa: u64 = 0;
    let int_start = i;
    while let Some(d) = digit(i) {
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        i += 1;
    }
    let mut count = i - int_start;
    let mut decimals = 0;
    if t.get(i) == Some(&b'.') {
        i += 1;
        let frac_start = i;
        while let Some(d) = digit(i) {
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
            i += 1;
        }
        decimals = i - frac_start;
        count += decimals;
    }
    if count == 0 || count > 19 || mantissa > EXACT_MANTISSA {
        return None;
    }
    if matches!(t.get(i), Some(b'.' | b'+' | b'-')) {
        return None;
    }
    let magnitude = mantissa as f64 / *POW10.get(decimals)?;
    Some(QuickNumber {
        value: if negative { -magnitude } else { magnitude },
        end: i,
    })
}

/// The digits of a decimal number read so far, as one integer while it fits.
#[derive(Default)]
struct Digits {
    count: usize,
    /// All digits as an integer while it is at most 2⁵³; once above, it stops growing and so
    /// stays above (nothing larger is exact, and 2⁵³·10 + 9 cannot overflow a `u64`).
    mantissa: u64,
    /// Digits after the decimal point.
    decimals: usize,
}

/// Largest integer of digits the quick path takes (every integer up to it is an exact `f64`).
const EXACT_MANTISSA: u64 = 1 << 53;

impl Digits {
    #[inline]
    fn push(&mut self, digit: u8, after_point: bool) {
        if self.mantissa <= EXACT_MANTISSA {
            self.mantissa = self.mantissa * 10 + u64::from(digit);
        }
        self.count += 1;
        self.decimals += usize::from(after_point);
    }

    /// The number's magnitude when it can be had exactly the quick way: with at most 2⁵³ as
    /// the integer of its digits and at most 22 decimals, the digits and the power of ten are
    /// both exact `f64`s, so their one correctly rounded quotient is the correctly rounded
    /// value (Clinger, "How to read floating point numbers accurately", 1990). `None` sends the
    /// number to the general parser.
    fn exact_value(&self) -> Option<f64> {
        if self.mantissa > EXACT_MANTISSA {
            return None;
        }
        Some(self.mantissa as f64 / *POW10.get(self.decimals)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval(s: &str) -> ReadResult<f64> {
        let p = Params::default();
        let mut r = Reader::new(s.as_bytes(), 0, &p);
        r.real_value()
    }

    #[test]
    fn numbers_read_exactly() {
        assert_eq!(eval("95."), Ok(95.0));
        assert_eq!(eval("-.5"), Ok(-0.5));
        assert_eq!(eval("+3"), Ok(3.0));
        assert_eq!(eval("0.1"), Ok(0.1));
        assert_eq!(eval("."), Err((ErrorKind::BadNumberFormat(".".into()), 0)));
        assert_eq!(
            eval("1.2.3"),
            Err((ErrorKind::TrailingCharacters("1.2.3".into()), 0))
        );
        assert_eq!(
            eval("-."),
            Err((ErrorKind::BadNumberFormat("-.".into()), 0))
        );
    }

    /// The quick path's edges: where it hands over to the general reader (20 digits, an integer
    /// of digits above 2⁵³, 23 decimals, a second sign or dot) the value and the end are still
    /// the general reader's, and `word_value` agrees with `real_value` everywhere.
    #[test]
    fn quick_path_edges_read_as_the_general_reader() {
        let cases = [
            "9007199254740992",     // 2⁵³: quick
            "9007199254740993",     // 2⁵³ + 1: general (rounds to even)
            "9007199254740992.5",   // integer of digits above 2⁵³
            "1234567890123456789",  // 19 digits
            "12345678901234567890", // 20 digits
            "00000000000000000000001.5",
            "0.0000000000000000000001",  // 22 decimals
            "0.00000000000000000000001", // 23 decimals
            "-0",
            "+.5",
            "5.",
            "-7.25",
            "18446744073709551616", // 2⁶⁴: would wrap a u64
            "99999999999999999999999.9",
        ];
        for text in cases {
            let general: f64 = text.parse().unwrap();
            assert_eq!(
                eval(text).map(f64::to_bits),
                Ok(general.to_bits()),
                "{text}"
            );
            let p = Params::default();
            let mut quick = Reader::new(text.as_bytes(), 0, &p);
            assert_eq!(
                quick.word_value().map(f64::to_bits),
                Ok(general.to_bits()),
                "{text}"
            );
            assert_eq!(quick.pos, text.len(), "{text}");
        }
        // What follows a number is left for the block: a sign, a letter, a second number.
        for (text, value, end) in [("1.5-2", 1.5, 3), ("12x", 12.0, 2), ("-3+", -3.0, 2)] {
            let p = Params::default();
            let mut r = Reader::new(text.as_bytes(), 0, &p);
            assert_eq!(r.word_value(), Ok(value), "{text}");
            assert_eq!(r.pos, end, "{text}");
        }
        // Not numbers for the quick path; the general reader's verdicts stand.
        for text in ["1.2.3", "--1", "-.", ".", "+-1", "-[1]", "#1", "sin[0]"] {
            let p = Params::default();
            let mut quick = Reader::new(text.as_bytes(), 0, &p);
            let mut general = Reader::new(text.as_bytes(), 0, &p);
            assert_eq!(quick.word_value(), general.real_value(), "{text}");
            assert_eq!(quick.pos, general.pos, "{text}");
        }
    }

    /// Numbers read bit for bit as the general (correctly rounded) parser reads them, on the
    /// quick path and off it.
    #[test]
    fn numbers_match_the_general_parser() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..200_000 {
            let int = next() % 10u64.pow((next() % 20) as u32);
            let decimals = (next() % 25) as usize;
            let frac = next() % 10u64.pow(decimals.min(19) as u32);
            let sign = ["", "-", "+"][(next() % 3) as usize];
            let text = if decimals == 0 {
                format!("{sign}{int}.")
            } else {
                format!("{sign}{int}.{frac:0decimals$}")
            };
            let general: f64 = text.parse().unwrap();
            assert_eq!(
                eval(&text).map(f64::to_bits),
                Ok(general.to_bits()),
                "{text}"
            );
        }
        assert_eq!(eval("-0.0").map(f64::to_bits), Ok((-0.0f64).to_bits()));
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(eval("[1+2*3]"), Ok(7.0));
        assert_eq!(eval("[2**3**2]"), Ok(64.0));
        assert_eq!(eval("[10-4-3]"), Ok(3.0));
        assert_eq!(eval("[1+2eq3]"), Ok(1.0));
        assert_eq!(eval("[1lt2and3gt4]"), Ok(0.0));
        assert_eq!(eval("[-7mod3]"), Ok(2.0));
        assert_eq!(eval("[2*[3+4]]"), Ok(14.0));
    }

    #[test]
    fn functions_in_degrees() {
        assert!((eval("sin[30]").unwrap() - 0.5).abs() < 1e-15);
        assert!((eval("atan[1]/[1]").unwrap() - 45.0).abs() < 1e-12);
        assert_eq!(eval("sqrt[16]"), Ok(4.0));
        assert_eq!(eval("round[-2.5]"), Ok(-3.0));
        assert_eq!(eval("fix[-2.5]"), Ok(-3.0));
        assert_eq!(eval("fup[2.1]"), Ok(3.0));
        assert_eq!(eval("-sqrt[4]"), Ok(-2.0));
        assert_eq!(eval("sqrt[-1]").unwrap_err().0, ErrorKind::SqrtOfNegative);
        assert_eq!(eval("[1/0]").unwrap_err().0, ErrorKind::DivisionByZero);
    }

    /// Where rs274 says 'infinity' and where 'not a number': a function's value is checked at
    /// once, an operator's only when its bracket closes (the verdicts are rs274's, 2.9).
    #[test]
    fn non_finite_values_are_refused_as_rs274_refuses_them() {
        let kind = |s: &str| eval(s).unwrap_err().0;
        assert_eq!(kind("[0*exp[1000]]"), ErrorKind::Infinity);
        assert_eq!(kind("[0eqexp[1000]]"), ErrorKind::Infinity);
        assert_eq!(kind("[exp[1000]-exp[1000]]"), ErrorKind::Infinity);
        assert_eq!(kind("[0*[10**1000]]"), ErrorKind::Infinity);
        assert_eq!(kind("[0eq[10**400*0]]"), ErrorKind::NotANumber);
    }

    #[test]
    fn exists_errors_match_linuxcnc() {
        assert_eq!(eval("exists[1]").unwrap_err().0, ErrorKind::ExpectedHash);
        assert_eq!(
            eval("exists[#1+#2]").unwrap_err().0,
            ErrorKind::ExpectedCloseBracket
        );
        assert_eq!(
            eval("exists[#<foo]").unwrap_err().0,
            ErrorKind::NamedParameterNotTerminated
        );
        assert_eq!(
            eval("exists[#foo]").unwrap_err().0,
            ErrorKind::UnknownWord('f')
        );
        assert_eq!(eval("exists[#<foo>]"), Ok(0.0));
    }
}
