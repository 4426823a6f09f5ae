//! The block: one line of G-code read into its words, as LinuxCNC's `read_items` reads it.
//!
//! Reading checks what can be checked word by word (repeated letters, unknown codes, two codes
//! of one modal group, negative feeds, …); the rules that tie words together are the
//! interpreter's. Every word keeps the byte offset of its letter in the source line.

use tezgah_geom::Pose;

use crate::codes::{g_group, ggroup, m_group, mgroup};
use crate::error::ErrorKind;
use crate::lexer::{NormLine, COMMENT_MARK};
use crate::params::Params;
use crate::reader::{integer_of, ParamRef, ReadResult, Reader};

/// A word's value and where its letter stands in the source line (byte offset).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Word {
    pub value: f64,
    pub at: u32,
}

/// A G or M code of a block: the code (G codes ×10) and where it stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Code {
    pub code: u32,
    pub at: u32,
}

/// A `#…=value` assignment, applied after the whole line has been read.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    pub target: ParamRef,
    pub value: f64,
    pub at: u32,
}

/// The label of an O-word: `o100` or `o<name>` (lower case, blanks removed).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum OLabel {
    Number(i64),
    Name(String),
}

impl std::fmt::Display for OLabel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OLabel::Number(n) => write!(f, "{n}"),
            OLabel::Name(s) => write!(f, "<{s}>"),
        }
    }
}

/// What an O-word line does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OKeyword {
    Sub,
    EndSub,
    Call,
    Return,
    Do,
    While,
    EndWhile,
    If,
    ElseIf,
    Else,
    EndIf,
    Break,
    Continue,
    Repeat,
    EndRepeat,
    /// A bare `O<n>` line: the start of a Fanuc-style subprogram (ended by M99), or the
    /// program number on the first line.
    Program,
}

impl OKeyword {
    const NAMES: [(&'static [u8], OKeyword); 15] = [
        (b"sub", OKeyword::Sub),
        (b"endsub", OKeyword::EndSub),
        (b"call", OKeyword::Call),
        (b"return", OKeyword::Return),
        (b"do", OKeyword::Do),
        (b"while", OKeyword::While),
        (b"endwhile", OKeyword::EndWhile),
        (b"if", OKeyword::If),
        (b"elseif", OKeyword::ElseIf),
        (b"else", OKeyword::Else),
        (b"endif", OKeyword::EndIf),
        (b"break", OKeyword::Break),
        (b"continue", OKeyword::Continue),
        (b"repeat", OKeyword::Repeat),
        (b"endrepeat", OKeyword::EndRepeat),
    ];

    pub fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, k)| *k == self)
            .and_then(|(name, _)| std::str::from_utf8(name).ok())
            .unwrap_or("program")
    }
}

/// An O-word: label, keyword and the bracketed values that follow (call arguments, the
/// condition of `if`/`elseif`/`while`, the count of `repeat`, the value of `return`/`endsub`).
#[derive(Debug, Clone, PartialEq)]
pub struct OWord {
    pub label: OLabel,
    pub keyword: OKeyword,
    pub args: Vec<f64>,
    pub at: u32,
}

/// One block. Letters other than G, M, N and O are kept by their position in the alphabet.
#[derive(Debug, Clone, Default)]
pub struct Block {
    /// The N word's number (its integer part), if any.
    pub n: Option<i64>,
    /// The words of the letters other than G, M, N and O by position in the alphabet; only
    /// those whose bit is set in `present` are in the block (a bit mask to clear per line
    /// instead of 26 options: clearing the block was a tenth of reading it).
    words: [Word; 26],
    present: u32,
    pub g: [Option<Code>; ggroup::COUNT],
    pub m: [Option<Code>; mgroup::COUNT],
    pub m_count: usize,
    /// Index into the line's comments of the comment that counts (the last one, as LinuxCNC).
    pub comment: Option<usize>,
    pub assignments: Vec<Assignment>,
    /// The O-word, on a control-flow line (which holds nothing else but comments).
    pub o: Option<OWord>,
    /// LinuxCNC's polar words: `@` the radius and `^` the angle (degrees) of the end point
    /// in the XY plane. A second one on a line replaces the first, as in LinuxCNC.
    pub radius: Option<Word>,
    pub theta: Option<Word>,
}

/// Letters of the six axes, in [`Pose`] order.
pub const AXIS_LETTERS: [u8; 6] = [b'x', b'y', b'z', b'a', b'b', b'c'];

/// The program axes a machine has: LinuxCNC's axis mask (bit 0 X … bit 5 C; U V W are never
/// axes here). A word of an axis the mask lacks is refused as LinuxCNC refuses it, when the
/// line is read: "Bad character 'a' used". The default, all six, is LinuxCNC's `rs274`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct AxisMask(u8);

impl AxisMask {
    /// X Y Z A B C: the standalone `rs274`'s machine.
    pub const XYZABC: AxisMask = AxisMask(0x3f);

    /// The mask of the axes given.
    pub fn of(axes: impl IntoIterator<Item = tezgah_geom::Axis>) -> Self {
        AxisMask(axes.into_iter().fold(0, |m, a| m | 1 << a.index()))
    }

    /// Whether the machine has `axis`.
    pub fn has(self, axis: tezgah_geom::Axis) -> bool {
        self.0 >> axis.index() & 1 == 1
    }

    /// The axis letters the mask lacks, one bit per letter by its place in the alphabet (the
    /// block's `present` layout).
    fn refused_letters(self) -> u32 {
        AXIS_LETTERS
            .iter()
            .enumerate()
            .filter(|&(i, _)| self.0 >> i & 1 == 0)
            .fold(0, |m, (_, &c)| m | 1 << (c - b'a'))
    }
}

impl Default for AxisMask {
    fn default() -> Self {
        AxisMask::XYZABC
    }
}

/// Letters that are words of their own (everything but G, M, N, O).
const fn is_value_letter(c: u8) -> bool {
    matches!(
        c,
        b'a' | b'b'
            | b'c'
            | b'd'
            | b'e'
            | b'f'
            | b'h'
            | b'i'
            | b'j'
            | b'k'
            | b'l'
            | b'p'
            | b'q'
            | b'r'
            | b's'
            | b't'
            | b'x'
            | b'y'
            | b'z'
    )
}

impl Block {
    /// The word of letter `c` (lower case), if the block has one.
    #[inline]
    pub fn word(&self, c: u8) -> Option<Word> {
        let slot = (c - b'a') as usize;
        (self.present >> slot & 1 == 1).then(|| self.words[slot])
    }

    /// Whether the block holds no word of a letter other than G, M, N and O.
    #[inline]
    pub fn has_no_letter_words(&self) -> bool {
        self.present == 0
    }

    /// The value of letter `c`, if present.
    #[inline]
    pub fn get(&self, c: u8) -> Option<f64> {
        self.word(c).map(|w| w.value)
    }

    #[inline]
    pub fn has(&self, c: u8) -> bool {
        self.word(c).is_some()
    }

    /// The G code of a modal group, if the block has one.
    #[inline]
    pub fn g(&self, group: usize) -> Option<u32> {
        self.g[group].map(|c| c.code)
    }

    #[inline]
    pub fn m(&self, group: usize) -> Option<u32> {
        self.m[group].map(|c| c.code)
    }

    /// Whether the block has a polar word (`@` or `^`).
    #[inline]
    pub fn polar(&self) -> bool {
        self.radius.is_some() || self.theta.is_some()
    }

    /// Where the block's first polar word stands.
    pub fn polar_at(&self) -> u32 {
        match (self.radius, self.theta) {
            (Some(r), Some(t)) => r.at.min(t.at),
            (Some(w), None) | (None, Some(w)) => w.at,
            (None, None) => 0,
        }
    }

    /// Whether any axis word (X Y Z A B C) is present.
    pub fn has_axis_words(&self) -> bool {
        self.axis_words().iter().any(Option::is_some)
    }

    /// The values of the axis words X Y Z A B C, in [`Pose`] order.
    pub fn axis_words(&self) -> [Option<f64>; 6] {
        AXIS_LETTERS.map(|c| self.get(c))
    }

    /// `base` with each axis the block names replaced by the block's value.
    pub fn axes_over(&self, base: Pose) -> Pose {
        let mut p = base;
        for (slot, word) in p.0.iter_mut().zip(self.axis_words()) {
            if let Some(v) = word {
                *slot = v;
            }
        }
        p
    }

    fn clear(&mut self) {
        self.n = None;
        self.present = 0;
        self.g = [None; ggroup::COUNT];
        self.m = [None; mgroup::COUNT];
        self.m_count = 0;
        self.comment = None;
        self.assignments.clear();
        self.o = None;
        self.radius = None;
        self.theta = None;
    }

    /// Read the normalised line `line` into `self`; words of axes `axes` lacks are bad
    /// characters. `Ok(false)` means the line is deleted by `/` and holds nothing to execute.
    /// On error, the index into `line.text` is returned.
    pub fn read(&mut self, line: &NormLine, params: &Params, axes: AxisMask) -> ReadResult<bool> {
        self.clear();
        let refused = axes.refused_letters();
        let text = line.text();
        let mut r = Reader::new(text, 0, params);
        if text.first() == Some(&b'/') {
            return Ok(false);
        }
        if text.first() == Some(&b'n') {
            r.pos = 1;
            let v = r.number()?;
            if v < 0.0 {
                return Err((ErrorKind::BadLineNumber, 1));
            }
            self.n = Some(v.trunc() as i64);
        }
        if text.get(r.pos) == Some(&b'o') {
            let at = line.at()[r.pos];
            self.o = Some(read_o_word(&mut r, at, true)?);
            // Only comments may follow (they are not executed on control lines).
            if let Some(i) = text[r.pos..].iter().position(|&c| c != COMMENT_MARK) {
                return Err((ErrorKind::WordsAfterOWord, r.pos + i));
            }
            return Ok(true);
        }
        let mut comment_index = 0;
        while r.pos < text.len() {
            let c = text[r.pos];
            let at = line.at()[r.pos];
            match c {
                COMMENT_MARK => {
                    self.comment = Some(comment_index);
                    comment_index += 1;
                    r.pos += 1;
                }
                b'#' => self.read_assignment(&mut r, at)?,
                b'g' => self.read_g(&mut r, at)?,
                b'm' => self.read_m(&mut r, at)?,
                b'@' | b'^' => {
                    r.pos += 1;
                    let word = Some(Word {
                        value: r.real_value()?,
                        at,
                    });
                    if c == b'@' {
                        self.radius = word;
                    } else {
                        self.theta = word;
                    }
                }
                c if is_value_letter(c) && refused >> (c - b'a') & 1 == 0 => {
                    self.read_letter(&mut r, c, at)?
                }
                _ => return Err((ErrorKind::BadCharacter(c as char), r.pos)),
            }
        }
        Ok(true)
    }

    fn read_assignment(&mut self, r: &mut Reader, at: u32) -> ReadResult<()> {
        let target = r.parameter_ref()?;
        if r.text.get(r.pos) != Some(&b'=') {
            return Err((ErrorKind::EqualSignMissing, r.pos));
        }
        r.pos += 1;
        let value = r.real_value()?;
        self.assignments.push(Assignment { target, value, at });
        Ok(())
    }

    fn read_g(&mut self, r: &mut Reader, at: u32) -> ReadResult<()> {
        let start = r.pos;
        r.pos += 1;
        let value = r.word_value()?;
        // LinuxCNC keeps G codes as ten times their number and allows 0.001 of slack.
        let tenfold = 10.0 * value;
        let mut code = tenfold.floor();
        if tenfold - code > 0.999 {
            code = tenfold.ceil();
        } else if tenfold - code > 0.001 {
            return Err((ErrorKind::GCodeOutOfRange, start));
        }
        if code > 999.0 {
            return Err((ErrorKind::GCodeOutOfRange, start));
        }
        if code < 0.0 {
            return Err((ErrorKind::NegativeGCode, start));
        }
        let code = code as u32;
        let group = g_group(code).ok_or((ErrorKind::UnknownGCode, start))?;
        if self.g[group].is_some() {
            return Err((ErrorKind::TwoGCodesSameGroup, start));
        }
        self.g[group] = Some(Code { code, at });
        Ok(())
    }

    fn read_m(&mut self, r: &mut Reader, at: u32) -> ReadResult<()> {
        let start = r.pos;
        r.pos += 1;
        let value = r.integer_value()?;
        if value < 0 {
            return Err((ErrorKind::NegativeMCode, start));
        }
        if value > 199 {
            return Err((ErrorKind::MCodeTooBig(value), start));
        }
        let group = m_group(value).ok_or((ErrorKind::UnknownMCode(value), start))?;
        if self.m[group].is_some() {
            return Err((ErrorKind::TwoMCodesSameGroup, start));
        }
        self.m[group] = Some(Code {
            code: value as u32,
            at,
        });
        self.m_count += 1;
        Ok(())
    }

    fn read_letter(&mut self, r: &mut Reader, c: u8, at: u32) -> ReadResult<()> {
        let start = r.pos;
        let slot = (c - b'a') as usize;
        if self.present >> slot & 1 == 1 {
            return Err((ErrorKind::MultipleWords(c as char), start));
        }
        r.pos += 1;
        let value = match c {
            // Words whose value must be an integer.
            b'h' | b'l' | b't' => r.integer_value()? as f64,
            _ => r.word_value()?,
        };
        let negative = value < 0.0;
        let kind = match c {
            b'f' if negative => Some(ErrorKind::NegativeFeed),
            b's' if negative => Some(ErrorKind::NegativeSpindleSpeed),
            b't' if negative => Some(ErrorKind::NegativeTool),
            b'l' if negative => Some(ErrorKind::NegativeL),
            _ => None,
        };
        if let Some(kind) = kind {
            return Err((kind, start));
        }
        self.words[slot] = Word { value, at };
        self.present |= 1 << slot;
        Ok(())
    }
}

/// Read an O-word from `r` (at its `o`): label, keyword and, when `evaluate`, the bracketed
/// values after it (control flow that is being skipped reads only label and keyword).
pub fn read_o_word(r: &mut Reader, at: u32, evaluate: bool) -> ReadResult<OWord> {
    let start = r.pos;
    r.pos += 1;
    let label = match r.text.get(r.pos) {
        Some(b'<') => {
            let close = r.text[r.pos..]
                .iter()
                .position(|&c| c == b'>')
                .ok_or((ErrorKind::NamedParameterNotTerminated, r.pos))?;
            let name = String::from_utf8_lossy(&r.text[r.pos + 1..r.pos + close]).into_owned();
            r.pos += close + 1;
            OLabel::Name(name)
        }
        Some(c) if c.is_ascii_digit() || matches!(c, b'[' | b'#' | b'+' | b'.') => {
            OLabel::Number(r.integer_value()?)
        }
        _ => return Err((ErrorKind::OLabelMissing, start)),
    };
    let word_start = r.pos;
    let letters = r.text[r.pos..]
        .iter()
        .take_while(|c| c.is_ascii_lowercase())
        .count();
    let word = &r.text[r.pos..r.pos + letters];
    let keyword = OKeyword::NAMES
        .iter()
        .find(|(name, _)| *name == word)
        .map(|&(_, k)| k)
        .or(word.is_empty().then_some(OKeyword::Program))
        .ok_or_else(|| {
            let text = String::from_utf8_lossy(word).into_owned();
            (ErrorKind::UnknownOKeyword(text), word_start)
        })?;
    r.pos += letters;
    let mut args = Vec::new();
    // Values in brackets, with comments allowed between them.
    loop {
        let comments = r.text[r.pos..]
            .iter()
            .take_while(|&&c| c == COMMENT_MARK)
            .count();
        if r.text.get(r.pos + comments) != Some(&b'[') {
            break;
        }
        r.pos += comments;
        if evaluate {
            args.push(r.expression()?);
        } else {
            skip_brackets(r);
        }
    }
    Ok(OWord {
        label,
        keyword,
        args,
        at,
    })
}

/// Move past one bracketed expression without evaluating it.
fn skip_brackets(r: &mut Reader) {
    let mut depth = 0usize;
    while let Some(&c) = r.text.get(r.pos) {
        r.pos += 1;
        match c {
            b'[' => depth += 1,
            b']' => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    return;
                }
            }
            _ => {}
        }
    }
}

/// Whether `v` is an integer within LinuxCNC's slack.
pub fn is_integer(v: f64) -> bool {
    integer_of(v).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(s: &str) -> ReadResult<Block> {
        let mut l = NormLine::default();
        l.lex(s).unwrap();
        let p = Params::default();
        let mut b = Block::default();
        b.read(&l, &p, AxisMask::XYZABC)?;
        Ok(b)
    }

    #[test]
    fn words_and_codes() {
        let b = read("N10 G1 X1.5 Y-2 F100 M3 S1000").unwrap();
        assert_eq!(b.n, Some(10));
        assert_eq!(b.g(ggroup::MOTION), Some(10));
        assert_eq!(b.get(b'x'), Some(1.5));
        assert_eq!(b.word(b'y').unwrap().at, 12);
        assert_eq!(b.m(mgroup::SPINDLE), Some(3));
    }

    #[test]
    fn word_errors() {
        assert_eq!(read("g0x1x2").unwrap_err().0, ErrorKind::MultipleWords('x'));
        assert_eq!(read("g0g1").unwrap_err().0, ErrorKind::TwoGCodesSameGroup);
        assert_eq!(read("g12").unwrap_err().0, ErrorKind::UnknownGCode);
        assert_eq!(read("g1.25").unwrap_err().0, ErrorKind::GCodeOutOfRange);
        assert_eq!(read("g0x1n2").unwrap_err().0, ErrorKind::BadCharacter('n'));
        assert_eq!(read("g1f-1").unwrap_err().0, ErrorKind::NegativeFeed);
    }

    #[test]
    fn axes_the_mask_lacks_are_bad_characters() {
        use tezgah_geom::Axis;
        let mut l = NormLine::default();
        l.lex("G1 X10 A90 F600").unwrap();
        let xyz = AxisMask::of([Axis::X, Axis::Y, Axis::Z]);
        let err = Block::default()
            .read(&l, &Params::default(), xyz)
            .unwrap_err();
        // At the `a`, index 6 of "g1x10a90f600".
        assert_eq!(err, (ErrorKind::BadCharacter('a'), 5));
        assert_eq!(err.0.to_string(), "Bad character 'a' used");
        let xyzc = AxisMask::of([Axis::X, Axis::Y, Axis::Z, Axis::C]);
        assert!(Block::default().read(&l, &Params::default(), xyzc).is_err());
        let xyza = AxisMask::of([Axis::X, Axis::Y, Axis::Z, Axis::A]);
        assert!(Block::default().read(&l, &Params::default(), xyza).is_ok());
        assert!(xyza.has(Axis::A) && !xyza.has(Axis::B));
    }

    #[test]
    fn fractional_line_number() {
        assert_eq!(read("N4567.789 S1200").unwrap().n, Some(4567));
    }
}
