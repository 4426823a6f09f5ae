//! The rules that tie a block's words together, checked before anything of it is executed:
//! which motion the block makes, and whether every word has a code that uses it
//! (LinuxCNC's `enhance_block`, `check_g_codes`, `check_m_codes`, `check_other_codes`).

use crate::block::{Block, AXIS_LETTERS};
use crate::codes::{ggroup, mgroup};
use crate::error::ErrorKind;

use super::state::State;

/// LinuxCNC allows at most this many M codes in a block.
const MAX_M_CODES: usize = 4;

/// What a checked block will do.
#[derive(Debug, Clone, Copy)]
pub struct Plan {
    /// The motion the block makes (G code ×10), explicit or modal.
    pub motion: Option<u32>,
    /// Fanuc's `G05.1 Q1` / `Q0`: path smoothing switched on or off.
    pub smoothing: Option<bool>,
}

/// `G5.1` with Q and without I or J is Fanuc's smoothing switch (`G05.1 Q1`), not LinuxCNC's
/// quadratic spline (which needs I and J).
fn smoothing_switch(block: &Block) -> Option<f64> {
    (block.g(ggroup::MOTION) == Some(51) && !block.has(b'i') && !block.has(b'j'))
        .then(|| block.get(b'q'))
        .flatten()
}

/// A check failure and the byte offset (in the line) of the word it concerns.
pub type CheckError = (ErrorKind, u32);

fn is_canned_cycle(g: u32) -> bool {
    g == 730 || g == 740 || (810..=890).contains(&g)
}

/// Decide the block's motion and check that its words fit together.
pub fn check(block: &Block, state: &State) -> Result<Plan, CheckError> {
    let at_g = |group: usize| block.g[group].map_or(0, |c| c.at);
    let mode0 = block.g(ggroup::NON_MODAL);
    let polar = block.polar();
    if polar {
        // The plane in force before the block's own G17/G18/G19, as LinuxCNC checks it.
        if state.plane != Some(tezgah_geom::Plane::XY) {
            return Err((ErrorKind::PolarNotXyPlane, block.polar_at()));
        }
        for letter in [b'x', b'y'] {
            if let Some(w) = block.word(letter) {
                let name = letter.to_ascii_uppercase() as char;
                return Err((ErrorKind::PolarWithAxisWord(name), w.at));
            }
        }
    }
    // Only real axis words count where G52/G92 need one.
    let axis_words = block.has_axis_words();
    let axes = axis_words || polar;
    // Codes whose axis words are data, not a move (G43.1 takes its offsets from them too).
    let covets_axes = matches!(mode0, Some(100 | 280 | 300 | 520 | 920))
        || block.g(ggroup::TOOL_LENGTH) == Some(431);
    let smoothing = match smoothing_switch(block) {
        Some(q) if q == 1.0 || q == 0.0 => Some(q == 1.0),
        Some(_) => return Err((ErrorKind::SmoothingQ, at_g(ggroup::MOTION))),
        None => None,
    };
    let explicit_motion = block.g(ggroup::MOTION).filter(|_| smoothing.is_none());
    let motion = match explicit_motion {
        Some(800) => {
            if axes && !covets_axes {
                return Err((ErrorKind::AxisValuesWithG80, at_g(ggroup::MOTION)));
            }
            if polar && mode0 == Some(920) {
                return Err((ErrorKind::PolarWithoutMotion, block.polar_at()));
            }
            Some(800)
        }
        Some(m) => {
            if covets_axes {
                return Err((ErrorKind::TwoGCodesUseAxes, at_g(ggroup::NON_MODAL)));
            }
            if !axes && !matches!(m, 0 | 10 | 20 | 30 | 52 | 53) {
                return Err((ErrorKind::AllAxesMissingWithMotion, at_g(ggroup::MOTION)));
            }
            Some(m)
        }
        None if covets_axes => {
            if polar && mode0 == Some(920) {
                return Err((ErrorKind::PolarWithoutMotion, block.polar_at()));
            }
            if !axis_words && matches!(mode0, Some(520 | 920)) {
                return Err((ErrorKind::AllAxesMissingWithG92, at_g(ggroup::NON_MODAL)));
            }
            None
        }
        None if axes => match state.motion {
            None | Some(800) => {
                let at = first_axis_at(block);
                return Err((ErrorKind::AxisValuesWithoutGCode, at));
            }
            m => m,
        },
        // Fanuc's G6.2: the lines of K alone that close a NURBS carry no axis words.
        None if state.motion == Some(62) && block.has(b'k') => Some(62),
        None => None,
    };
    if polar && motion.is_none() {
        return Err((ErrorKind::PolarWithoutMotion, block.polar_at()));
    }
    check_g_codes(block, state, motion)?;
    if block.m_count > MAX_M_CODES {
        return Err((ErrorKind::TooManyMCodes, 0));
    }
    check_other_words(block, motion, smoothing.is_some())?;
    Ok(Plan { motion, smoothing })
}

fn first_axis_at(block: &Block) -> u32 {
    AXIS_LETTERS
        .iter()
        .filter_map(|&c| block.word(c))
        .chain(block.radius)
        .chain(block.theta)
        .map(|w| w.at)
        .min()
        .unwrap_or(0)
}

fn check_g_codes(block: &Block, state: &State, motion: Option<u32>) -> Result<(), CheckError> {
    let Some(code) = block.g[ggroup::NON_MODAL] else {
        return Ok(());
    };
    let at = code.at;
    match code.code {
        40 if block.get(b'p').is_none_or(|p| p < 0.0) => {
            return Err((ErrorKind::DwellTimeMissing, at));
        }
        100 => {
            let l = block.get(b'l');
            if !matches!(l.map(|l| l as i64), Some(0 | 1 | 2 | 10 | 11 | 20)) {
                return Err((ErrorKind::G10MissingL, at));
            }
            let l = l.unwrap_or(0.0) as i64;
            // LinuxCNC's test is one-sided: P2.6 passes (and means 2), P2.4 does not.
            let p = block.get(b'p').unwrap_or(-1.0);
            let rounded = p.round();
            if (p + 0.0001) - rounded > 0.0002 {
                return Err((ErrorKind::G10PNotInteger, at));
            }
            if (l == 2 || l == 20) && !(0.0..=9.0).contains(&rounded) {
                return Err((ErrorKind::G10POutOfRange(l), at));
            }
            if matches!(l, 1 | 10 | 11) && rounded < 1.0 {
                return Err((ErrorKind::G10PToolOutOfRange(l), at));
            }
        }
        530 => {
            if !matches!(motion, Some(0 | 10)) {
                return Err((ErrorKind::G53NeedsG0OrG1, at));
            }
            let incremental = match block.g(ggroup::DISTANCE) {
                Some(910) => true,
                Some(_) => false,
                None => state.incremental,
            };
            if incremental {
                return Err((ErrorKind::G53Incremental, at));
            }
        }
        _ => {}
    }
    Ok(())
}

/// Letters whose use `check_other_words` restricts to certain codes.
const RULED_LETTERS: [u8; 10] = [b'd', b'e', b'h', b'i', b'j', b'k', b'l', b'p', b'q', b'r'];

fn check_other_words(
    block: &Block,
    motion: Option<u32>,
    smoothing: bool,
) -> Result<(), CheckError> {
    if let Some(c) = block.m[mgroup::SUBPROGRAM] {
        if c.code == 98 && !block.has(b'p') {
            return Err((ErrorKind::M98WithoutP, c.at));
        }
    }
    let mode0 = block.g(ggroup::NON_MODAL);
    let g10 = mode0 == Some(100);
    let arc = matches!(motion, Some(20 | 30));
    let cycle = motion.is_some_and(is_canned_cycle);
    let m = |group| block.m(group);
    if cycle {
        for (letter, kind) in [
            (b'a', ErrorKind::AInCannedCycle),
            (b'b', ErrorKind::BInCannedCycle),
            (b'c', ErrorKind::CInCannedCycle),
        ] {
            if let Some(w) = block.word(letter) {
                return Err((kind, w.at));
            }
        }
    }
    // Most blocks (`G1 X… Y… Z…`) carry none of the words below: no rule to check then.
    if !RULED_LETTERS.iter().any(|&c| block.has(c)) {
        return check_synced(block, motion);
    }
    let rule = |letter: u8, allowed: bool, kind: ErrorKind| -> Result<(), CheckError> {
        match block.word(letter) {
            Some(w) if !allowed => Err((kind, w.at)),
            _ => Ok(()),
        }
    };
    let comp = block.g(ggroup::CUTTER_COMP);
    rule(
        b'd',
        matches!(comp, Some(410 | 411 | 420 | 421)) || block.g(ggroup::SPINDLE_MODE) == Some(960),
        ErrorKind::DWordUnused,
    )?;
    // LinuxCNC lets E ride along on G33/G33.1 (and ignores it).
    rule(
        b'e',
        matches!(motion, Some(330 | 331)),
        ErrorKind::EWordUnused,
    )?;
    rule(
        b'h',
        matches!(block.g(ggroup::TOOL_LENGTH), Some(430 | 432 | 434)),
        ErrorKind::HWordUnused,
    )?;
    let ij_user = arc || g10 || matches!(motion, Some(50 | 51 | 870));
    // G33.1's I: the spindle speed factor of the way back.
    rule(b'i', ij_user || motion == Some(331), ErrorKind::IWordUnused)?;
    rule(b'j', ij_user, ErrorKind::JWordUnused)?;
    rule(
        b'k',
        arc || matches!(motion, Some(330 | 331 | 760 | 870 | 62)),
        ErrorKind::KWordUnused,
    )?;
    rule(
        b'l',
        // G74 takes no L, unlike the other cycles (LinuxCNC's rule).
        g10 || (cycle && motion != Some(740))
            || m(mgroup::SUBPROGRAM) == Some(98)
            || matches!(motion, Some(52 | 760))
            || matches!(m(mgroup::IO), Some(66)),
        ErrorKind::LWordUnused,
    )?;
    let p_user = arc
        || matches!(mode0, Some(40 | 100))
        || block.g(ggroup::PATH_CONTROL) == Some(640)
        || matches!(
            motion,
            Some(50 | 52 | 62 | 740 | 760 | 820 | 840 | 860 | 880 | 890)
        )
        || matches!(m(mgroup::OVERRIDE), Some(50..=53))
        || m(mgroup::SUBPROGRAM) == Some(98)
        || matches!(m(mgroup::IO), Some(62..=66))
        || m(mgroup::USER).is_some();
    rule(b'p', p_user, ErrorKind::PWordUnused)?;
    // The turn count of a G2/G3 is checked here, before the block does anything (F, S, M48…).
    if let (true, Some(w)) = (arc, block.word(b'p')) {
        if (w.value - w.value.round()).abs() > 0.001 {
            return Err((ErrorKind::ArcTurnsNotInteger, w.at));
        }
        if w.value.round() < 1.0 {
            return Err((ErrorKind::ArcTurnsBelowOne, w.at));
        }
    }
    let q_user = g10
        || smoothing
        || block.g(ggroup::PATH_CONTROL) == Some(640)
        || matches!(motion, Some(50 | 730 | 760 | 830))
        || matches!(m(mgroup::SPINDLE), Some(19))
        || matches!(m(mgroup::IO), Some(66..=68))
        || matches!(m(mgroup::TOOL_CHANGE), Some(61))
        || m(mgroup::USER).is_some();
    rule(b'q', q_user, ErrorKind::QWordUnused)?;
    rule(
        b'r',
        arc || g10
            || cycle
            || motion == Some(62)
            || block.g(ggroup::PATH_CONTROL) == Some(640)
            || matches!(m(mgroup::SPINDLE), Some(19)),
        ErrorKind::RWordUnused,
    )?;
    check_synced(block, motion)
}

/// G33 and G33.1 take their pitch from K on every block (K is not modal) and no F: checked
/// after the other words, as LinuxCNC does.
fn check_synced(block: &Block, motion: Option<u32>) -> Result<(), CheckError> {
    if !matches!(motion, Some(330 | 331)) {
        return Ok(());
    }
    let at = block.g[ggroup::MOTION].map_or(0, |c| c.at);
    if !block.has(b'k') {
        return Err((ErrorKind::SyncMissingK, at));
    }
    if let Some(w) = block.word(b'f') {
        return Err((ErrorKind::SyncWithF, w.at));
    }
    Ok(())
}
