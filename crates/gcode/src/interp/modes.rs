//! M70–M73: saving and restoring the modal state, as LinuxCNC 2.9 does.
//!
//! M70 saves the modes of the current call level, M71 forgets them, M72 restores them, M73
//! saves them to be restored when the subroutine returns. LinuxCNC keeps the modes as its
//! `active_g_codes` / `active_m_codes` / `active_settings` arrays; a restore compares the saved
//! arrays with the current ones and executes G-code text for the difference, so that the
//! canonical calls are those of the codes themselves: first `G20`/`G21` alone, then one line
//! with ` F… S…` and the G codes followed by the first M code, then each further M code on a
//! line of its own. The same text is built and executed here, which gives rs274's calls in
//! rs274's order.

use std::fmt::Write;

use tezgah_geom::{FeedMode, Plane, Pose};

use crate::canon::{CanonSink, ControlMode, SpindleDir, Units};
use crate::error::ErrorKind;

use super::execute::Exec;
use super::{Interpreter, LineRef};

/// G-code slots of LinuxCNC's `active_g_codes` that a restore sets (ten times the code; -1
/// none), in its order: plane, cutter compensation, units, distance, feed mode, coordinate
/// system, tool length, retract, path control, arc distance, lathe diameter, and whether the
/// G92/G52 offsets are applied (G92.3) or not (G92.2), which rs274 2.9 restores too.
const G_SLOTS: usize = 12;
const UNITS: usize = 2;
const PATH_CONTROL: usize = 8;

/// The modes M70/M73 saved at one call level.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct SavedModes {
    g: [i32; G_SLOTS],
    /// Spindle, mist, flood, overrides, adaptive feed, feed hold (`active_m_codes` 2, 4–8).
    m: [i32; 6],
    feed: f64,
    speed: f64,
    /// G64's P and Q.
    tolerance: f64,
    naivecam: f64,
    /// M73: restored when the subroutine of this level returns.
    restore_on_return: bool,
}

/// The saved modes of each call level (0: the program), LinuxCNC's `sub_context[…]` with
/// `CONTEXT_VALID`.
#[derive(Debug, Clone, Default)]
pub(super) struct ModeStack(Vec<Option<SavedModes>>);

impl ModeStack {
    fn slot(&mut self, level: usize) -> &mut Option<SavedModes> {
        if self.0.len() <= level {
            self.0.resize(level + 1, None);
        }
        &mut self.0[level]
    }

    /// A call enters `level`: nothing is saved there yet.
    pub(super) fn enter(&mut self, level: usize) {
        *self.slot(level) = None;
    }

    /// The modes to restore when the call of `level` returns (M73), forgetting them.
    pub(super) fn leave(&mut self, level: usize) -> Option<SavedModes> {
        self.slot(level)
            .take()
            .filter(|saved| saved.restore_on_return)
    }
}

impl Interpreter {
    /// The modes as LinuxCNC's `write_g_codes`, `write_m_codes` and `write_settings` see them.
    fn modes(&self) -> SavedModes {
        let s = &self.state;
        let g = [
            match s.plane {
                Some(Plane::XY) => 170,
                Some(Plane::ZX) => 180,
                Some(Plane::YZ) => 190,
                None => -1,
            },
            match self.comp.side {
                None => 400,
                Some(super::comp::Side::Left) => 410,
                Some(super::comp::Side::Right) => 420,
            },
            if s.units == Units::Inches { 200 } else { 210 },
            if s.incremental { 910 } else { 900 },
            match s.feed_mode {
                FeedMode::InverseTime => 930,
                FeedMode::UnitsPerMinute => 940,
                FeedMode::UnitsPerRevolution => 950,
            },
            match s.origin_index {
                i @ 1..=6 => 530 + 10 * i as i32,
                i => 584 + i as i32,
            },
            if s.tool_offset != Pose::ZERO {
                430
            } else {
                490
            },
            if s.retract_r_plane { 990 } else { 980 },
            match s.control {
                ControlMode::Continuous(_) => 640,
                ControlMode::ExactPath => 610,
                ControlMode::ExactStop => 611,
            },
            if s.ijk_incremental { 911 } else { 901 },
            if s.lathe_diameter { 70 } else { 80 },
            if self.params.get(crate::params::G92_ENABLED) != 0.0 {
                923
            } else {
                922
            },
        ];
        let w = &s.switches;
        let m = [
            match s.spindle {
                None => 5,
                Some(SpindleDir::Clockwise) => 3,
                Some(SpindleDir::CounterClockwise) => 4,
            },
            if s.mist {
                7
            } else if s.flood {
                -1
            } else {
                9
            },
            if s.flood { 8 } else { -1 },
            // rs274 2.9 looks at the feed override alone here.
            if w.feed_override { 48 } else { 49 },
            if w.adaptive_feed { 52 } else { -1 },
            if w.feed_hold { 53 } else { -1 },
        ];
        SavedModes {
            g,
            m,
            feed: s.feed_rate,
            speed: s.speed,
            tolerance: s.path_tolerance,
            naivecam: s.naivecam_tolerance,
            restore_on_return: false,
        }
    }

    /// M70–M73 (`code`, its word at `at`) in the line `line`.
    pub(super) fn modal_state(
        &mut self,
        code: u32,
        at: u32,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Exec {
        let level = self.control.call_level();
        match code {
            70 | 73 => {
                let mut saved = self.modes();
                // M73 at the program's level has nothing to return to: kept as M70.
                saved.restore_on_return = code == 73 && level > 0;
                *self.saved_modes.slot(level) = Some(saved);
            }
            71 => *self.saved_modes.slot(level) = None,
            _ => {
                let saved = self
                    .saved_modes
                    .slot(level)
                    .clone()
                    .ok_or((ErrorKind::RestoreWithoutContext, at))?;
                self.restore_modes(&saved, line, sink)
                    .map_err(|kind| (kind, at))?;
            }
        }
        Ok(())
    }

    /// LinuxCNC's `restore_settings`: the G-code text for the difference between the modes in
    /// force and `saved`, executed as part of `line`.
    pub(super) fn restore_modes(
        &mut self,
        saved: &SavedModes,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        let now = self.modes();
        if now.g[UNITS] != saved.g[UNITS] {
            let units = format!("G{}", saved.g[UNITS] / 10);
            self.execute_restore(&units, line, sink)
                .map_err(|_| ErrorKind::RestoreUnitsFailed)?;
        }
        let mut cmd = String::new();
        if saved.feed != now.feed {
            let _ = write!(cmd, " F{:.1}", saved.feed);
        }
        if saved.speed != now.speed {
            let _ = write!(cmd, " S{:.0}", saved.speed);
        }
        for (k, (&was, &is)) in saved.g.iter().zip(&now.g).enumerate() {
            if k == PATH_CONTROL && was == 640 {
                // rs274 2.9 sets G64 again with its tolerances when the mode or either
                // tolerance differs.
                let (p, q) = (saved.tolerance, saved.naivecam);
                if was != is || p != now.tolerance || q != now.naivecam {
                    let _ = write!(cmd, " G64 P{p} Q{q}");
                }
                continue;
            }
            if k == UNITS || was == is || was == -1 {
                continue;
            }
            let _ = match was % 10 {
                0 => write!(cmd, " G{}", was / 10),
                tenth => write!(cmd, " G{}.{tenth}", was / 10),
            };
        }
        for (&was, &is) in saved.m.iter().zip(&now.m) {
            if was != is && was != -1 {
                let _ = writeln!(cmd, "M{was}");
            }
        }
        for piece in cmd.split('\n').filter(|p| !p.is_empty()) {
            self.execute_restore(piece, line, sink)
                .map_err(|message| ErrorKind::RestoreFailed(piece.to_owned(), message))?;
        }
        Ok(())
    }

    /// Execute `text` as if it stood in `line` (its calls carry that line); the error's text.
    fn execute_restore(
        &mut self,
        text: &str,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Result<(), String> {
        let origin = self.origin;
        let next_line = self.control.next_line;
        let result = self.execute_line(LineRef { text, ..line }, sink);
        self.origin = origin;
        self.control.next_line = next_line;
        result.map(|_| ()).map_err(|e| e.kind.to_string())
    }
}
