//! The motion of a block: G0/G1 (also under G53), G2/G3 arcs and helices, G28/G30 returns.
//!
//! End points are computed in program coordinates as LinuxCNC's `find_ends` does; feeds in
//! inverse time become a rate per move (`F × length`), as LinuxCNC sends them.

use tezgah_geom::{FeedMode, Plane, Pose};

use crate::block::{Block, AXIS_LETTERS};
use crate::canon::{Canon, CanonSink};
use crate::codes::ggroup;
use crate::error::ErrorKind;
use crate::params;

use super::arc::{center_from_offset, center_from_radius, sweep, ArcTolerance, Sense};
use super::comp::{CompError, ProgrammedArc};
use super::execute::{unsupported, Exec};
use super::Interpreter;

impl Interpreter {
    pub(super) fn motion(&mut self, block: &Block, g: u32, sink: &mut impl CanonSink) -> Exec {
        let at = block.g[ggroup::MOTION].map_or(0, |c| c.at);
        if !matches!(g, 730 | 740 | 810..=890) {
            self.state.cycle_initial_level = None;
        }
        // LinuxCNC refuses G5/G5.1 under cutter compensation; tezgah refuses every spline
        // there (LinuxCNC would send a G5.2 NURBS uncompensated, cutting the wrong contour).
        if matches!(g, 50 | 51 | 52 | 62) && self.comp.side.is_some() {
            return Err((CompError::Spline.into(), at));
        }
        match g {
            0 | 10 => self.straight(block, g == 0, at, sink)?,
            20 | 30 => self.arc(block, g == 20, at, sink)?,
            800 => self.comment_call(sink, "motion mode set to none".into()),
            730 | 740 | 810..=890 => self.cycle(block, g, at, sink)?,
            50 | 51 => self.spline(block, g, at, sink)?,
            52 => self.nurbs_point(block, at)?,
            53 => {
                // G5.3 closes the series and leaves no motion mode, as in LinuxCNC.
                self.nurbs_end(at, sink)?;
                self.state.motion = None;
                return Ok(());
            }
            62 => self.g62_line(block, at, sink)?,
            382..=385 => self.probe(block, g, at, sink)?,
            330 | 331 => self.spindle_synced(block, g == 331, at, sink)?,
            _ => return Err(unsupported(g, at)),
        }
        self.state.motion = Some(g);
        Ok(())
    }

    /// End point of the block's axis and polar words, absolute, incremental or (G53) machine
    /// (LinuxCNC's `find_ends`).
    pub(super) fn find_ends(&self, block: &Block) -> Result<Pose, ErrorKind> {
        let s = &self.state;
        if block.g(ggroup::NON_MODAL) == Some(530) {
            if block.polar() {
                return Err(ErrorKind::PolarWithG53);
            }
            let m = block.axes_over(s.to_machine(s.pos) + s.tool_offset);
            return Ok(s.from_machine(m - s.tool_offset));
        }
        // While compensating, axes of the compensation plane not named continue from the
        // programmed point, not from the offset tool (LinuxCNC's `comp && middle`).
        let mut end = s.pos;
        if self.comp.in_progress() {
            let normal = s.plane.map_or(2, |p| p.axes().2);
            for i in 0..3 {
                if i == 0 || (i == 1 && normal == 2) || (i == 2 && normal == 1) {
                    end.0[i] = self.comp.programmed[i];
                }
            }
        }
        for (i, word) in block.axis_words().into_iter().enumerate() {
            if let Some(v) = word {
                end.0[i] = if s.incremental { end.0[i] + v } else { v };
            }
        }
        if block.polar() {
            let (x, y) = polar_end(
                (end.0[0], end.0[1]),
                block.radius.map(|w| w.value),
                block.theta.map(|w| w.value),
                s.incremental,
            )?;
            end.0[0] = x;
            end.0[1] = y;
        }
        Ok(end)
    }

    /// The feed checks every feed move makes; in inverse time, the F word of the block.
    fn feed_for_move(&self, block: &Block, arc: bool, at: u32) -> Exec<Option<f64>> {
        let s = &self.state;
        match s.feed_mode {
            FeedMode::UnitsPerMinute | FeedMode::UnitsPerRevolution => {
                if s.feed_rate == 0.0 {
                    let kind = if arc {
                        ErrorKind::ArcZeroFeed
                    } else {
                        ErrorKind::G1ZeroFeed
                    };
                    return Err((kind, at));
                }
                if s.feed_mode == FeedMode::UnitsPerRevolution && s.speed == 0.0 {
                    return Err((ErrorKind::ZeroSpindleFeedPerRev, at));
                }
                Ok(None)
            }
            FeedMode::InverseTime => match block.get(b'f') {
                Some(f) => Ok(Some(f)),
                None => Err((
                    if arc {
                        ErrorKind::InverseTimeArcMissingF
                    } else {
                        ErrorKind::InverseTimeG1MissingF
                    },
                    at,
                )),
            },
        }
    }

    fn straight(&mut self, block: &Block, rapid: bool, at: u32, sink: &mut impl CanonSink) -> Exec {
        self.comp.arc_not_allowed = false;
        let end = self.find_ends(block).map_err(|k| (k, at))?;
        if !rapid {
            // The inverse-time length is the programmed one, also while compensating.
            if let Some(f) = self.feed_for_move(block, false, at)? {
                let length = straight_length(end - self.comp_start());
                self.set_inverse_time_rate(inverse_time_rate(f, length), sink);
            }
        }
        if self.comp.active() {
            if block.g(ggroup::NON_MODAL) == Some(530) {
                return Err((CompError::G53.into(), at));
            }
            return self.straight_comp(rapid, end, sink).map_err(|k| (k, at));
        }
        let call = if rapid {
            Canon::StraightTraverse(end)
        } else {
            Canon::StraightFeed(end)
        };
        self.emit(sink, call);
        self.state.pos = end;
        Ok(())
    }

    /// G38.2 (toward the point until the probe trips, an error if it does not), G38.3 (no
    /// error), G38.4 / G38.5 (until it clears), with LinuxCNC's checks (`convert_probe`);
    /// the answer comes from `cfg.probe`.
    fn probe(&mut self, block: &Block, g: u32, at: u32, sink: &mut impl CanonSink) -> Exec {
        if self.comp.side.is_some() {
            return Err((ErrorKind::ProbeWithComp, at));
        }
        if self.state.feed_rate == 0.0 {
            return Err((ErrorKind::ProbeZeroFeed, at));
        }
        if self.state.feed_mode == FeedMode::UnitsPerRevolution {
            return Err((ErrorKind::ProbeFeedPerRev, at));
        }
        let end = self.find_ends(block).map_err(|k| (k, at))?;
        let start = self.state.pos;
        // G38.3 and G38.5 do not fail, so they may start where they end.
        if matches!(g, 382 | 384) && end == start {
            return Err((ErrorKind::ProbeStartAtTarget, at));
        }
        let name = || format!("{}.{}", g / 10, g % 10);
        let outcome = match &self.cfg.probe {
            super::ProbeModel::Unavailable => {
                return Err((ErrorKind::ProbeUnavailable(name()), at));
            }
            super::ProbeModel::Rs274 => None,
            super::ProbeModel::Answered(answers) => Some(answers.get(self.probes).copied()),
        };
        self.emit(sink, Canon::TurnProbeOn);
        self.emit(sink, Canon::StraightProbe(end));
        self.emit(sink, Canon::TurnProbeOff);
        let Some(outcome) = outcome else {
            self.rs274_probe(start, end);
            return Ok(());
        };
        let Some(outcome) = outcome else {
            self.pending_probe = Some(super::PendingProbe { g, start, end });
            return Err((ErrorKind::ProbeAwaitsAnswer(name()), at));
        };
        self.apply_probe(g, start, end, outcome)
            .map_err(|kind| (kind, at))
    }

    /// The machine's answer to the probe move G`g` from `start` to `end`: `#5061`… and the
    /// position where the machine came to rest, or LinuxCNC's error for the outcome.
    pub(super) fn apply_probe(
        &mut self,
        g: u32,
        start: Pose,
        end: Pose,
        outcome: super::ProbeOutcome,
    ) -> Result<(), ErrorKind> {
        self.probes += 1;
        let toward = matches!(g, 382 | 383);
        let point = |f: f64| {
            let mut p = start;
            for i in 0..6 {
                p.0[i] += f * (end.0[i] - start.0[i]);
            }
            p
        };
        let (probed, stopped, tripped) = match outcome {
            super::ProbeOutcome::Tripped { at: f, stopped } => (point(f), point(stopped), true),
            super::ProbeOutcome::Completed if matches!(g, 382) => {
                return Err(ErrorKind::ProbeNoContact)
            }
            super::ProbeOutcome::Completed if matches!(g, 384) => {
                return Err(ErrorKind::ProbeStillInContact)
            }
            // G38.3 and G38.5 go on untripped from the end of the move.
            super::ProbeOutcome::Completed => (end, end, false),
            super::ProbeOutcome::AlreadyThere if toward => {
                return Err(ErrorKind::ProbeAlreadyTripped)
            }
            super::ProbeOutcome::AlreadyThere => return Err(ErrorKind::ProbeAlreadyClear),
        };
        self.set_probe_parameters(probed, tripped);
        self.state.pos = stopped;
        Ok(())
    }

    /// G33 (a straight move whose axes follow the spindle, K program units per revolution)
    /// and G33.1 (rigid tapping: to the point and back following the spindle, which reverses
    /// at depth; the current point stays), as LinuxCNC's `convert_straight` sends them.
    fn spindle_synced(
        &mut self,
        block: &Block,
        tap: bool,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        if self.state.spindle.is_none() {
            let name = if tap { "G33.1" } else { "G33" };
            return Err((ErrorKind::SyncSpindleStopped(name), at));
        }
        if self.comp.side.is_some() {
            return Err((ErrorKind::SyncWithComp, at));
        }
        let feed_per_rev = block.get(b'k').unwrap_or(0.0);
        let end = self.find_ends(block).map_err(|k| (k, at))?;
        self.emit(sink, Canon::StartSpeedFeedSync { feed_per_rev });
        if tap {
            let mut bottom = self.state.pos;
            bottom.0[..3].copy_from_slice(&end.0[..3]);
            let retract_scale = block.get(b'i').unwrap_or(1.0);
            self.emit(
                sink,
                Canon::RigidTap {
                    end: bottom,
                    retract_scale,
                },
            );
        } else {
            self.emit(sink, Canon::StraightFeed(end));
            self.state.pos = end;
        }
        self.emit(sink, Canon::StopSpeedFeedSync);
        Ok(())
    }

    /// rs274's canon: never tripped, the target as the probe position, and the machine
    /// 0.01 in short of it along the XYZ direction of the move.
    fn rs274_probe(&mut self, start: Pose, end: Pose) {
        let d = [
            start.0[0] - end.0[0],
            start.0[1] - end.0[1],
            start.0[2] - end.0[2],
        ];
        let distance = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let mut stop = end;
        if distance != 0.0 {
            let backoff = if self.state.inches() { 0.01 } else { 0.254 };
            for (i, di) in d.iter().enumerate() {
                stop.0[i] = end.0[i] + backoff * (di / distance);
            }
        }
        self.set_probe_parameters(end, false);
        self.state.pos = stop;
    }

    /// `#5061`…`#5066` the probed point (program coordinates), `#5067`…`#5069` (U V W) zero,
    /// `#5070` whether it tripped.
    fn set_probe_parameters(&mut self, probed: Pose, tripped: bool) {
        for (i, v) in probed.0.iter().enumerate() {
            self.params.set(params::PROBE_POSITION + i, *v);
        }
        for i in 6..9 {
            self.params.set(params::PROBE_POSITION + i, 0.0);
        }
        self.params
            .set(params::PROBE_TRIPPED, if tripped { 1.0 } else { 0.0 });
    }

    /// An inverse-time move's rate becomes the feed rate in force, as in LinuxCNC.
    fn set_inverse_time_rate(&mut self, rate: f64, sink: &mut impl CanonSink) {
        self.state.feed_rate = rate;
        self.emit(sink, Canon::SetFeedRate(rate));
    }

    /// G28/G30: rapid to the point the axis words give, then to the stored home position of
    /// those axes (all axes when none is given).
    pub(super) fn go_home(&mut self, block: &Block, g: u32, sink: &mut impl CanonSink) -> Exec {
        // Polar words never reach here (`checks`: not a motion), so this cannot fail.
        let intermediate = self.find_ends(block).map_err(|k| (k, block.polar_at()))?;
        self.emit(sink, Canon::StraightTraverse(intermediate));
        self.state.pos = intermediate;
        let base = if g == 280 {
            params::G28_HOME
        } else {
            params::G30_HOME
        };
        // The stored point is the spindle's; the tool tip ends a tool length below it.
        let home_machine = self.offset_params(base);
        let home = self
            .state
            .from_machine(home_machine - self.state.tool_offset);
        let words = block.axis_words();
        let any = words.iter().any(Option::is_some);
        let mut end = intermediate;
        for (i, word) in words.iter().enumerate() {
            if !any || word.is_some() {
                end.0[i] = home.0[i];
            }
        }
        self.emit(sink, Canon::StraightTraverse(end));
        self.state.pos = end;
        Ok(())
    }

    fn arc(&mut self, block: &Block, clockwise: bool, at: u32, sink: &mut impl CanonSink) -> Exec {
        if self.comp.arc_not_allowed {
            return Err((CompError::ArcAfterExit.into(), at));
        }
        let Some(plane) = self.state.plane else {
            return Err((
                ErrorKind::Unsupported("arcs in the U V W planes".into()),
                at,
            ));
        };
        let ijk = block.has(b'i') || block.has(b'j') || block.has(b'k');
        let radius = block.get(b'r');
        if radius.is_none() && !ijk {
            return Err((ErrorKind::ArcMissingRIJK, at));
        }
        if radius.is_some() && ijk {
            return Err((ErrorKind::ArcMixedFormat, at));
        }
        let inverse_feed = self.feed_for_move(block, true, at)?;
        let (first, second, normal) = plane.axes();
        let (name, offsets, forbidden, missing_ends) = match plane {
            Plane::XY => ("xy", [b'i', b'j'], b'k', ('X', 'y')),
            Plane::ZX => ("xz", [b'k', b'i'], b'j', ('X', 'z')),
            Plane::YZ => ("yz", [b'j', b'k'], b'i', ('Y', 'z')),
        };
        if ijk && block.has(forbidden) {
            let letter = (forbidden as char).to_ascii_uppercase();
            return Err((ErrorKind::ArcWrongOffsetWord(letter, name), at));
        }
        let in_plane_end = block.has(AXIS_LETTERS[first])
            || block.has(AXIS_LETTERS[second])
            || (plane == Plane::XY && block.polar());
        if radius.is_some() && !in_plane_end {
            return Err((
                ErrorKind::ArcMissingEndWords(missing_ends.0, missing_ends.1, name),
                at,
            ));
        }
        // `checks` has made sure P is a whole number of at least 1.
        let turns = block.get(b'p').map_or(1, |p| p.round() as i32);
        let start = self.comp_start();
        let end = self.find_ends(block).map_err(|k| (k, at))?;
        let s2 = [start.0[first], start.0[second]];
        let e2 = [end.0[first], end.0[second]];
        let tol = ArcTolerance::for_units(self.state.inches());
        let sense = if clockwise {
            Sense::Clockwise
        } else {
            Sense::CounterClockwise
        };
        let letters = (
            (AXIS_LETTERS[first] as char).to_ascii_uppercase(),
            (AXIS_LETTERS[second] as char).to_ascii_uppercase(),
        );
        let turn = sense.turn(turns);
        self.check_entry_arc(end, radius, turn)
            .map_err(|k| (k, at))?;
        let center = match radius {
            Some(r) => center_from_radius(s2, e2, r, sense, tol),
            None => {
                let mut c = [0.0; 2];
                for (k, &letter) in offsets.iter().enumerate() {
                    let v = block.get(letter);
                    c[k] = if self.state.ijk_incremental {
                        s2[k] + v.unwrap_or(0.0)
                    } else {
                        v.ok_or_else(|| {
                            (
                                ErrorKind::ArcAbsoluteCenterMissing(
                                    (letter as char).to_ascii_uppercase(),
                                ),
                                at,
                            )
                        })?
                    };
                }
                center_from_offset(s2, e2, c, tol, letters)
            }
        }
        .map_err(|kind| (kind, at))?;
        if radius.is_none() {
            self.check_entry_arc_center(s2, center, turn)
                .map_err(|k| (k, at))?;
        }
        if let Some(f) = inverse_feed {
            let radius = (s2[0] - center[0]).hypot(s2[1] - center[1]);
            let planar = radius * sweep(s2, e2, center, sense, turns as u32);
            let length = planar.hypot(end.0[normal] - start.0[normal]);
            self.set_inverse_time_rate(inverse_time_rate(f, length), sink);
        }
        if self.comp.active() {
            let arc = ProgrammedArc::new(plane.axes(), end, center, turn);
            return self.arc_comp(arc, sink).map_err(|k| (k, at));
        }
        self.emit(
            sink,
            Canon::ArcFeed {
                first_end: e2[0],
                second_end: e2[1],
                first_axis: center[0],
                second_axis: center[1],
                rotation: turn,
                axis_end: end.0[normal],
                abc: [end.0[3], end.0[4], end.0[5]],
            },
        );
        self.state.pos = end;
        Ok(())
    }
}

/// Below this (program units) an axis does not count as moving when a straight move's length
/// is measured (LinuxCNC's `find_straight_length`).
const STILL: f64 = 1e-7;

/// Length of a straight move for its inverse-time rate: the XYZ distance if X, Y or Z moves,
/// else the rotary distance in degrees (LinuxCNC's `find_straight_length`).
/// LinuxCNC's polar end point in XY: from `(x, y)` (where the axis words left it), `@ radius`
/// and `^ angle` (degrees) absolute, or in G91 added to the current point's radius and angle.
pub(super) fn polar_end(
    (x, y): (f64, f64),
    radius: Option<f64>,
    theta: Option<f64>,
    incremental: bool,
) -> Result<(f64, f64), ErrorKind> {
    let at_origin = x == 0.0 && y == 0.0;
    if !incremental {
        let (r, t) = match (radius, theta) {
            (Some(r), Some(t)) => (r, t.to_radians()),
            (Some(_), None) if at_origin => return Err(ErrorKind::PolarAngleAtOrigin),
            (Some(r), None) => (r, y.atan2(x)),
            (None, Some(t)) => (y.hypot(x), t.to_radians()),
            (None, None) => return Ok((x, y)),
        };
        return Ok((r * t.cos(), r * t.sin()));
    }
    let (mut x, mut y) = (x, y);
    if let Some(dr) = radius {
        if x == 0.0 && y == 0.0 {
            return Err(ErrorKind::PolarIncrementalAtOrigin);
        }
        let (t, r) = (y.atan2(x), y.hypot(x) + dr);
        (x, y) = (r * t.cos(), r * t.sin());
    }
    if let Some(dt) = theta {
        if x == 0.0 && y == 0.0 {
            return Err(ErrorKind::PolarG91AtOrigin);
        }
        let (t, r) = (y.atan2(x) + dt.to_radians(), y.hypot(x));
        (x, y) = (r * t.cos(), r * t.sin());
    }
    Ok((x, y))
}

fn straight_length(d: Pose) -> f64 {
    if d.0[..3].iter().any(|v| v.abs() > STILL) {
        d.linear_norm()
    } else {
        d.rotary_norm()
    }
}

/// The feed rate an inverse-time move is sent with: its length over its time `1/F`. LinuxCNC
/// floors it at 0.1 units per minute (`inverse_time_rate_straight`/`_arc`), so a tiny move never
/// gets a near-zero feed; tezgah does the same to run the same programs at the same speed.
pub(super) fn inverse_time_rate(f: f64, length: f64) -> f64 {
    (length * f).max(0.1)
}
