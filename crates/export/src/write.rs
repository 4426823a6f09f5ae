//! The blocks printed as a program a controller without kinematics runs: every joint
//! absolute on every move, G93 feeds, each block numbered with the source line it came from.

use std::fmt::Write as _;

use tezgah_geom::StopKind;
use tezgah_kinematics::Joints;

use crate::convert::Block;
use crate::letters::AxisLetters;

/// Decimals written for joints in mm (10 nm) and in degrees (1e-6°, 3.5 nm at 200 mm).
const MM_DECIMALS: usize = 5;
const DEG_DECIMALS: usize = 6;
/// Significant digits of a G93 F: the block time to 1e-9 of itself.
const FEED_DIGITS: i32 = 10;

/// What the header comment says about the program.
pub struct Header<'a> {
    pub program: &'a str,
    pub machine: &'a str,
    /// `q1=X q2=Y …`
    pub mapping: String,
    /// The written blocks' share of the tolerance, mm.
    pub budget: f64,
}

/// `v` with `decimals` decimals, trailing zeros dropped, never `-0`.
pub fn number(v: f64, decimals: usize) -> String {
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.truncate(s.trim_end_matches('0').trim_end_matches('.').len());
    }
    if s == "-0" {
        s = "0".to_owned();
    }
    s
}

/// Text safe inside a G-code comment: no parentheses (they would close it), ASCII only.
pub fn comment_text(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '(' | ')' => ' ',
            c if c.is_ascii() && !c.is_ascii_control() => c,
            _ => '?',
        })
        .collect()
}

/// LinuxCNC refuses N words past 99999 ("Line number greater than 99999").
const LARGEST_N: u32 = 99_999;

/// The source line a block starts with: its N word, or past [`LARGEST_N`] a comment.
fn source(line: u32) -> String {
    if line <= LARGEST_N {
        format!("N{line} ")
    } else {
        format!("(line {line}) ")
    }
}

/// A G93 F for a block of `minutes`: 1/minutes to 10 significant digits.
pub fn inverse_time(minutes: f64) -> String {
    let f = 1.0 / minutes;
    let magnitude = f.abs().log10().floor() as i32;
    let decimals = (FEED_DIGITS - 1 - magnitude).clamp(0, 15) as usize;
    number(f, decimals)
}

fn joints_words(out: &mut String, q: &Joints, letters: &AxisLetters) {
    for ((v, l), k) in q
        .as_slice()
        .iter()
        .zip(&letters.letters)
        .zip(&letters.scale)
    {
        let decimals = if *k == 1.0 { MM_DECIMALS } else { DEG_DECIMALS };
        let _ = write!(out, " {l}{}", number(v * k, decimals));
    }
}

/// The whole program text.
pub fn program(blocks: &[Block], letters: &AxisLetters, header: &Header<'_>) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "(tezgah export of {} for machine {})",
        comment_text(header.program),
        comment_text(header.machine)
    );
    let _ = writeln!(
        out,
        "(joint coordinates, mm and degrees, no offsets: {})",
        comment_text(&header.mapping)
    );
    let _ = writeln!(
        out,
        "(G93: F is 1/minutes of its block; joint-linear moves within {} mm of the path)",
        number(header.budget, 6)
    );
    // G61: blocks are met exactly (a controller blending them would cut the bow we split).
    out.push_str("G21 G90 G17 G40 G49 G61\nG93\n");
    let mut ended = false;
    for b in blocks {
        if ended {
            break; // a controller reads nothing after M2
        }
        match b {
            Block::Rapid { joints, line, .. } => {
                let _ = write!(out, "{}G0", source(*line));
                joints_words(&mut out, joints, letters);
            }
            Block::Feed {
                joints,
                minutes,
                line,
                ..
            } => {
                let _ = write!(out, "{}G1", source(*line));
                joints_words(&mut out, joints, letters);
                let _ = write!(out, " F{}", inverse_time(*minutes));
            }
            Block::Dwell { seconds, line } => {
                let _ = write!(out, "{}G4 P{}", source(*line), number(*seconds, 4));
            }
            Block::Stop { kind, rewind, line } => {
                let word = match kind {
                    StopKind::Pause => "M0",
                    StopKind::OptionalPause => "M1",
                    StopKind::PalletPause => "M60",
                    StopKind::End if *rewind => "M30",
                    StopKind::End => "M2",
                };
                ended |= *kind == StopKind::End;
                let _ = write!(out, "{}{word}", source(*line));
            }
            Block::Words { text, line } => {
                let _ = write!(out, "{}{text}", source(*line));
            }
        }
        out.push('\n');
    }
    if !ended {
        out.push_str("M2\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_source_lines() {
        assert_eq!(number(-0.000001, 5), "0");
        assert_eq!(number(12.5, 5), "12.5");
        assert_eq!(number(-3.0, 6), "-3");
        assert_eq!(inverse_time(0.1), "10");
        assert_eq!(inverse_time(1.0 / 640.0717411), "640.0717411");
        assert_eq!(source(99_999), "N99999 ");
        assert_eq!(source(100_000), "(line 100000) ");
        assert_eq!(comment_text("a(b)c→"), "a b c?");
    }
}
