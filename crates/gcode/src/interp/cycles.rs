//! Canned cycles (G73, G74, G81–G89) expanded into ordinary moves exactly as LinuxCNC's
//! `convert_cycle` does: in any plane, absolute or incremental, with L repeats and the G98/G99
//! retract, under exact-path mode for the cycle's duration.
//!
//! The cycle is written for the plane's first, second and normal axes (LinuxCNC's aa, bb, cc):
//! G17 is X Y Z, G18 is Z X Y, G19 is Y Z X.

use tezgah_geom::{FeedMode, Plane, Pose};

use crate::block::{Block, AXIS_LETTERS};
use crate::canon::{Canon, CanonSink, ControlMode, SpindleDir, Units};
use crate::error::ErrorKind;

use super::execute::Exec;
use super::Interpreter;

/// How far G73 and G83 back off above the last peck, in inches (LinuxCNC's G83_RAPID_DELTA).
const PECK_CLEARANCE_INCH: f64 = 0.010;

/// The words of a cycle that stay in force from block to block (LinuxCNC's `cycle_*`).
#[derive(Debug, Clone, Copy, Default)]
pub struct CycleMemory {
    /// R as last programmed (an increment under G91).
    pub r: f64,
    /// The normal-axis word (Z in G17) as last programmed.
    pub bottom: f64,
    pub p: f64,
    pub q: f64,
    /// I J K of G87, in X Y Z order.
    pub ijk: [f64; 3],
}

/// One cycle's geometry on the plane's axes.
struct Hole {
    plane: (usize, usize, usize),
    /// The point in the plane.
    a: f64,
    b: f64,
    /// R plane, bottom and retract height along the normal.
    r: f64,
    bottom: f64,
    clear: f64,
}

impl Interpreter {
    /// G73, G74 and G81–G89.
    pub(super) fn cycle(
        &mut self,
        block: &Block,
        g: u32,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        let err = |kind| Err((kind, at));
        if self.state.feed_rate == 0.0 {
            return err(ErrorKind::CycleZeroFeed);
        }
        if self.state.feed_mode == FeedMode::InverseTime {
            return err(ErrorKind::CycleInverseTime);
        }
        if self.comp.side.is_some() {
            return err(super::comp::CompError::CannedCycle.into());
        }
        let Some(plane) = self.state.plane else {
            return err(ErrorKind::Unsupported(
                "canned cycles in the U V W planes".into(),
            ));
        };
        let same_cycle = self.state.motion == Some(g);
        let r_word = match block.get(b'r') {
            Some(r) => r,
            None if same_cycle => self.state.cycle.r,
            None => return err(ErrorKind::CycleRMissing),
        };
        let repeats = match block.get(b'l') {
            Some(0.0) => return err(ErrorKind::CycleZeroRepeats),
            Some(l) => l as u32,
            None => 1,
        };
        // The loop guard bounds L as it bounds loops (L2000000000 would drill for ever).
        let limit = self.cfg.limits.max_loop_iterations;
        if u64::from(repeats) > limit {
            return err(ErrorKind::TooManyRepeats(repeats, limit));
        }
        let (first, second, normal) = plane.axes();
        let (plane_name, normal_letter) = match plane {
            Plane::XY => ("xy", 'z'),
            Plane::ZX => ("xz", 'y'),
            Plane::YZ => ("yz", 'x'),
        };
        let normal_word = block.get(AXIS_LETTERS[normal]);
        if !same_cycle && normal_word.is_none() {
            let letter = normal_letter.to_ascii_uppercase();
            return err(ErrorKind::CycleNormalMissing(letter, plane_name));
        }
        let bottom_word = normal_word.unwrap_or(self.state.cycle.bottom);
        let pos = self.state.pos;
        // Where the tool stands along the normal.
        let mut height = pos.0[normal];
        // The initial level: the height when the series of cycles began (LinuxCNC 2.9's
        // `cycle_il`). G98 retracts to it (or to R, if higher) and incremental R counts from it.
        let mut old = *self.state.cycle_initial_level.get_or_insert(height);
        // Polar words (XY plane only, `checks` made sure): in G90 the hole's radius and
        // angle; in G91 added to each hole's radius and angle about the origin, after the X Y
        // steps (LinuxCNC's `CYCLE_MACRO`), so that L repeats go round a circle.
        let (radius, theta) = (block.radius.map(|w| w.value), block.theta.map(|w| w.value));
        let mut polar_step = (0.0, 0.0);
        let (mut a, mut b, step, r, bottom) = if self.state.incremental {
            let step = (
                block.get(AXIS_LETTERS[first]).unwrap_or(0.0),
                block.get(AXIS_LETTERS[second]).unwrap_or(0.0),
            );
            polar_step = (radius.unwrap_or(0.0), theta.unwrap_or(0.0).to_radians());
            let r = r_word + old;
            (pos.0[first], pos.0[second], step, r, r + bottom_word)
        } else if block.polar() {
            let (x, y) = (pos.0[first], pos.0[second]);
            let rad = radius.unwrap_or_else(|| y.hypot(x));
            let t = theta.map_or_else(|| y.atan2(x), f64::to_radians);
            (
                rad * t.cos(),
                rad * t.sin(),
                (0.0, 0.0),
                r_word,
                bottom_word,
            )
        } else {
            (
                block.get(AXIS_LETTERS[first]).unwrap_or(pos.0[first]),
                block.get(AXIS_LETTERS[second]).unwrap_or(pos.0[second]),
                (0.0, 0.0),
                r_word,
                bottom_word,
            )
        };
        if r < bottom {
            return err(ErrorKind::CycleRBelowBottom(normal_letter, plane_name));
        }
        if old < r {
            let mut p = pos;
            p.0[normal] = r;
            self.traverse(p, sink);
            old = r;
            height = r;
        }
        let clear = if self.state.retract_r_plane { r } else { old };
        let saved = self.state.control;
        if saved != ControlMode::ExactPath {
            self.emit(sink, Canon::SetMotionControlMode(ControlMode::ExactPath));
        }
        let words = self.cycle_words(block, g, same_cycle, at)?;
        for repeat in 0..repeats {
            a += step.0;
            b += step.1;
            if polar_step.0 != 0.0 {
                if a == 0.0 && b == 0.0 {
                    return err(ErrorKind::PolarIncrementalAtOrigin);
                }
                let (t, rr) = (b.atan2(a), b.hypot(a) + polar_step.0);
                (a, b) = (rr * t.cos(), rr * t.sin());
            }
            if polar_step.1 != 0.0 {
                if a == 0.0 && b == 0.0 {
                    return err(ErrorKind::PolarIncrementalAtOrigin);
                }
                let (t, rr) = (b.atan2(a) + polar_step.1, b.hypot(a));
                (a, b) = (rr * t.cos(), rr * t.sin());
            }
            let hole = Hole {
                plane: (first, second, normal),
                a,
                b,
                r,
                bottom,
                clear,
            };
            // Over the first hole at the height the tool stands at, if above R; over the
            // others (and when already down at R) at the retract height.
            if repeat == 0 && height > r {
                self.cycle_move(&hole, height, false, sink);
                self.cycle_move(&hole, r, false, sink);
            } else {
                self.cycle_move(&hole, clear, false, sink);
                if clear > r {
                    self.cycle_move(&hole, r, false, sink);
                }
            }
            self.cycle_body(g, &hole, &words, at, sink)?;
        }
        self.state.pos.0[first] = a;
        self.state.pos.0[second] = b;
        self.state.pos.0[normal] = clear;
        self.state.cycle.r = r_word;
        self.state.cycle.bottom = bottom_word;
        if saved != ControlMode::ExactPath {
            self.emit(sink, Canon::SetMotionControlMode(saved));
            if let ControlMode::Continuous(_) = saved {
                self.emit(
                    sink,
                    Canon::SetNaivecamTolerance(self.state.naivecam_tolerance),
                );
            }
        }
        Ok(())
    }

    /// The P, Q and I J K a cycle needs, from the block or, for the same cycle again, from
    /// memory. LinuxCNC takes a word of −1 for a missing one; so does tezgah.
    fn cycle_words(&mut self, block: &Block, g: u32, same: bool, at: u32) -> Exec<CycleMemory> {
        let given = |c: u8| block.get(c).filter(|&v| v != -1.0);
        let mut m = self.state.cycle;
        match g {
            820 | 860 | 880 | 890 => {
                m.p = match given(b'p') {
                    Some(p) => p,
                    None if same => m.p,
                    None => return Err((ErrorKind::CycleDwellMissing(g / 10), at)),
                };
            }
            730 | 830 => {
                m.q = match given(b'q') {
                    Some(q) => q,
                    None if same => m.q,
                    None => return Err((ErrorKind::CycleQMissing(g / 10), at)),
                };
            }
            870 => {
                for (k, letter) in [b'i', b'j', b'k'].into_iter().enumerate() {
                    m.ijk[k] = match block.get(letter) {
                        Some(v) => v,
                        None if same => m.ijk[k],
                        None => {
                            let c = (letter as char).to_ascii_uppercase();
                            return Err((ErrorKind::CycleG87WordMissing(c), at));
                        }
                    };
                }
            }
            // G74/G84 dwell at the bottom for P seconds, P being optional.
            740 | 840 => m.p = given(b'p').unwrap_or(m.p),
            _ => {}
        }
        self.state.cycle.p = m.p;
        self.state.cycle.q = m.q;
        self.state.cycle.ijk = m.ijk;
        Ok(m)
    }

    /// What a cycle does once the tool stands at the R plane over the hole.
    fn cycle_body(
        &mut self,
        g: u32,
        h: &Hole,
        w: &CycleMemory,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        match g {
            810 => {
                self.cycle_move(h, h.bottom, true, sink);
                self.cycle_move(h, h.clear, false, sink);
            }
            820 => {
                self.cycle_move(h, h.bottom, true, sink);
                self.emit(sink, Canon::Dwell(w.p));
                self.cycle_move(h, h.clear, false, sink);
            }
            730 | 830 => self.peck(g == 830, h, w.q, at, sink)?,
            740 | 840 => self.tap(g, h, w.p, at, sink)?,
            // G85 feeds back out to R, then rapids to the retract height.
            850 => {
                self.cycle_move(h, h.bottom, true, sink);
                self.cycle_move(h, h.r, true, sink);
                self.cycle_move(h, h.clear, false, sink);
            }
            860 => {
                let dir = self.cycle_spindle(86, at)?;
                self.cycle_move(h, h.bottom, true, sink);
                self.emit(sink, Canon::Dwell(w.p));
                self.emit(sink, Canon::StopSpindle);
                self.cycle_move(h, h.clear, false, sink);
                self.emit(sink, Canon::StartSpindle(dir));
            }
            870 => self.back_bore(h, w, at, sink)?,
            880 => {
                let dir = self.cycle_spindle(88, at)?;
                self.cycle_move(h, h.bottom, true, sink);
                self.emit(sink, Canon::Dwell(w.p));
                self.emit(sink, Canon::StopSpindle);
                self.emit(sink, Canon::ProgramStop);
                self.emit(sink, Canon::StartSpindle(dir));
            }
            890 => {
                self.cycle_move(h, h.bottom, true, sink);
                self.emit(sink, Canon::Dwell(w.p));
                self.cycle_move(h, h.clear, true, sink);
            }
            _ => return Err(super::execute::unsupported(g, at)),
        }
        Ok(())
    }

    /// G83 (full retract between pecks) and G73 (chip break: a short back-off).
    fn peck(&mut self, full: bool, h: &Hole, q: f64, at: u32, sink: &mut impl CanonSink) -> Exec {
        if q <= 0.0 {
            return Err((ErrorKind::CycleQNotPositive, at));
        }
        let back_off = match self.state.units {
            Units::Inches => PECK_CLEARANCE_INCH,
            Units::Millimeters => PECK_CLEARANCE_INCH * 25.4,
        };
        // A Q far below the depth makes pecks without end (in LinuxCNC too: once Q is below
        // the depth's last bit, the depth stops changing): the loop guard bounds their number.
        let pecks = ((h.r - h.bottom) / q).ceil();
        let limit = self.cfg.limits.max_loop_iterations;
        if pecks.is_nan() || pecks > limit as f64 {
            let code = if full { 83 } else { 73 };
            return Err((ErrorKind::TooManyPecks(code, q, limit), at));
        }
        let mut depth = h.r - q;
        while depth > h.bottom {
            self.cycle_move(h, depth, true, sink);
            if full {
                // Out of the hole to R to clear the chips, then back down.
                self.cycle_move(h, h.r, false, sink);
            }
            self.cycle_move(h, depth + back_off, false, sink);
            depth -= q;
        }
        self.cycle_move(h, h.bottom, true, sink);
        self.cycle_move(h, h.clear, false, sink);
        Ok(())
    }

    /// G84 (right-hand) and G74 (left-hand) tapping: overrides off, feed in, reverse, dwell,
    /// feed out, restore.
    fn tap(&mut self, g: u32, h: &Hole, dwell: f64, at: u32, sink: &mut impl CanonSink) -> Exec {
        let (cutting, code) = if g == 840 {
            (SpindleDir::Clockwise, 84)
        } else {
            (SpindleDir::CounterClockwise, 74)
        };
        match self.state.spindle {
            None => return Err((ErrorKind::CycleSpindleStopped(code), at)),
            Some(dir) if dir != cutting => {
                return Err((ErrorKind::CycleSpindleWrongWay(code, g == 840), at));
            }
            Some(_) => {}
        }
        let reverse = match cutting {
            SpindleDir::Clockwise => SpindleDir::CounterClockwise,
            SpindleDir::CounterClockwise => SpindleDir::Clockwise,
        };
        self.emit(sink, Canon::DisableFeedOverride);
        self.emit(sink, Canon::DisableSpeedOverride);
        self.cycle_move(h, h.bottom, true, sink);
        self.emit(sink, Canon::StopSpindle);
        self.emit(sink, Canon::StartSpindle(reverse));
        self.emit(sink, Canon::Dwell(dwell));
        self.cycle_move(h, h.clear, true, sink);
        self.emit(sink, Canon::StopSpindle);
        self.emit(sink, Canon::StartSpindle(cutting));
        self.emit(sink, Canon::EnableFeedOverride);
        self.emit(sink, Canon::EnableSpeedOverride);
        Ok(())
    }

    /// G87 back boring: in beside the hole with the spindle oriented, under the part, feed up
    /// to the counterbore's top and back, and out the same way.
    fn back_bore(&mut self, h: &Hole, w: &CycleMemory, at: u32, sink: &mut impl CanonSink) -> Exec {
        let dir = self.cycle_spindle(87, at)?;
        let (first, second, normal) = h.plane;
        let offset = Hole {
            a: h.a + w.ijk[first],
            b: h.b + w.ijk[second],
            ..*h
        };
        let mut middle = w.ijk[normal];
        if self.state.incremental {
            middle += h.bottom;
        }
        self.cycle_move(&offset, h.r, false, sink);
        self.emit(sink, Canon::StopSpindle);
        self.emit(sink, Canon::OrientSpindle(dir));
        self.cycle_move(&offset, h.bottom, false, sink);
        self.cycle_move(h, h.bottom, false, sink);
        self.emit(sink, Canon::StartSpindle(dir));
        self.cycle_move(h, middle, true, sink);
        self.cycle_move(h, h.bottom, true, sink);
        self.emit(sink, Canon::StopSpindle);
        self.emit(sink, Canon::OrientSpindle(dir));
        self.cycle_move(&offset, h.bottom, false, sink);
        self.cycle_move(&offset, h.clear, false, sink);
        self.cycle_move(h, h.clear, false, sink);
        self.emit(sink, Canon::StartSpindle(dir));
        Ok(())
    }

    /// The spindle's sense of turning, which G86, G87 and G88 need.
    fn cycle_spindle(&self, code: u32, at: u32) -> Exec<SpindleDir> {
        self.state
            .spindle
            .ok_or((ErrorKind::CycleSpindleNeeded(code), at))
    }

    /// A move of a cycle to height `height` over the hole: feed or traverse.
    fn cycle_move(&mut self, h: &Hole, height: f64, feed: bool, sink: &mut impl CanonSink) {
        let (first, second, normal) = h.plane;
        let mut p: Pose = self.state.pos;
        p.0[first] = h.a;
        p.0[second] = h.b;
        p.0[normal] = height;
        if feed {
            self.emit(sink, Canon::StraightFeed(p));
            self.state.pos = p;
        } else {
            self.traverse(p, sink);
        }
    }

    fn traverse(&mut self, p: Pose, sink: &mut impl CanonSink) {
        self.emit(sink, Canon::StraightTraverse(p));
        self.state.pos = p;
    }
}
