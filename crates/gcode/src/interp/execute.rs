//! Executing a checked block: its words in LinuxCNC's fixed order (comment, feed mode, F, S, T,
//! M6, spindle, coolant, dwell, plane, units, cutter compensation, tool length, coordinate
//! system, path control, distance modes, retract mode, G10/G28/G92 group, motion, stops).

use tezgah_geom::{FeedMode, Plane, Pose};

use crate::block::Block;
use crate::canon::{Canon, CanonSink, ControlMode, SpindleDir, Units};
use crate::codes::{g_name, ggroup, mgroup};
use crate::error::{ErrorKind, GcodeError};
use crate::params::{self, coord_system_base};

use super::comp::CompError;
use super::{checks, state};
use super::{Flow, Interpreter, LineRef};

/// An execution error and the byte offset in the line of the word it concerns.
pub(super) type ExecError = (ErrorKind, u32);
pub(super) type Exec<T = ()> = Result<T, ExecError>;

impl Interpreter {
    pub(super) fn execute_block(
        &mut self,
        block: &Block,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Result<Flow, GcodeError> {
        if let Some(m) = block.m[mgroup::SUBPROGRAM].filter(|_| self.fanuc_subs_disabled()) {
            let kind = ErrorKind::FanucSubsDisabled(m.code);
            return Err(GcodeError::new(kind, line.span(m.at as usize)));
        }
        let plan = checks::check(block, &self.state)
            .map_err(|(kind, at)| GcodeError::new(kind, line.span(at as usize)))?;
        self.g62_guard(block, plan.motion)
            .map_err(|(kind, at)| GcodeError::new(kind, line.span(at as usize)))?;
        self.assign_parameters(block)
            .map_err(|(kind, at)| GcodeError::new(kind, line.span(at as usize)))?;
        self.execute_words(block, plan, line, sink)
            .map_err(|(kind, at)| GcodeError::new(kind, line.span(at as usize)))
    }

    fn execute_words(
        &mut self,
        block: &Block,
        plan: checks::Plan,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Exec<Flow> {
        let motion = plan.motion;
        if let Some(i) = block.comment {
            let comment = &self.norm.comments[i];
            let (text, at) = (comment.text.clone(), comment.at as u32);
            self.comment(&text, at, sink)?;
        }
        if let Some(c) = block.g[ggroup::SPINDLE_MODE] {
            return Err(unsupported(c.code, c.at));
        }
        if let Some(g) = block.g(ggroup::FEED_MODE) {
            self.feed_mode(g, sink);
        }
        if let Some(f) = block.get(b'f') {
            if self.state.feed_mode != FeedMode::InverseTime {
                self.state.feed_rate = f;
                self.emit(sink, Canon::SetFeedRate(f));
            }
        }
        if let Some(s) = block.get(b's') {
            self.state.speed = s;
            self.emit(sink, Canon::SetSpindleSpeed(s));
        }
        if let Some(t) = block.word(b't') {
            self.select_tool(t.value as i64, t.at, sink)?;
        }
        if let Some(m) = block.m[mgroup::TOOL_CHANGE] {
            self.tool_change(block, m.code, m.at, sink)?;
        }
        if let Some(c) = block.m[mgroup::SPINDLE] {
            match c.code {
                3 | 4 => {
                    let dir = if c.code == 3 {
                        SpindleDir::Clockwise
                    } else {
                        SpindleDir::CounterClockwise
                    };
                    self.state.spindle = Some(dir);
                    self.emit(sink, Canon::StartSpindle(dir));
                }
                5 => {
                    self.state.spindle = None;
                    self.emit(sink, Canon::StopSpindle);
                }
                70..=73 => self.modal_state(c.code, c.at, line, sink)?,
                _ => return Err(unsupported_m(block, mgroup::SPINDLE)),
            }
        }
        match block.m(mgroup::COOLANT) {
            Some(7) => {
                self.state.mist = true;
                self.emit(sink, Canon::MistOn);
            }
            Some(8) => {
                self.state.flood = true;
                self.emit(sink, Canon::FloodOn);
            }
            Some(_) => {
                self.state.mist = false;
                self.state.flood = false;
                self.emit(sink, Canon::MistOff);
                self.emit(sink, Canon::FloodOff);
            }
            None => {}
        }
        if let Some(m) = block.m(mgroup::OVERRIDE) {
            self.set_switches(m, block.get(b'p'), sink);
        }
        for group in [mgroup::IO, mgroup::USER] {
            if block.m[group].is_some() {
                return Err(unsupported_m(block, group));
            }
        }
        if block.g(ggroup::NON_MODAL) == Some(40) {
            self.emit(sink, Canon::Dwell(block.get(b'p').unwrap_or(0.0)));
        }
        if let Some(c) = block.g[ggroup::PLANE] {
            self.refuse_plane_change(c.code).map_err(|k| (k, c.at))?;
        }
        if let Some(g) = block.g(ggroup::PLANE) {
            self.state.plane = match g {
                170 => Some(Plane::XY),
                180 => Some(Plane::ZX),
                190 => Some(Plane::YZ),
                _ => None,
            };
            self.emit(sink, Canon::SelectPlane(self.state.plane));
        }
        if let Some(g) = block.g(ggroup::UNITS) {
            let units = if g == 200 {
                Units::Inches
            } else {
                Units::Millimeters
            };
            self.change_units(units);
            self.emit(sink, Canon::UseLengthUnits(units));
        }
        if let Some(g) = block.g(ggroup::LATHE_DIAMETER) {
            let diameter = g == 70;
            if diameter != self.state.lathe_diameter {
                self.state.lathe_diameter = diameter;
                let what = if diameter { "diameter" } else { "radius" };
                // LinuxCNC sends this one at once, even past moves compensation holds.
                let text = format!("interpreter: Lathe diameter mode changed to {what}");
                sink.call(self.origin, Canon::Comment(text));
            }
        }
        if let Some(c) = block.g[ggroup::CUTTER_COMP] {
            self.cutter_compensation(block, c.code, c.at, sink)?;
        }
        if let Some(c) = block.g[ggroup::TOOL_LENGTH] {
            self.refuse_with_comp(CompError::ToolOffset)
                .map_err(|k| (k, c.at))?;
            self.tool_length(block, c.code, c.at, sink)?;
        }
        if let Some(c) = block.g[ggroup::COORD_SYSTEM] {
            self.refuse_with_comp(CompError::ChangeCoordinateSystem)
                .map_err(|k| (k, c.at))?;
            self.select_coordinate_system(coord_index(c.code), sink);
        }
        if let Some(c) = block.g[ggroup::PATH_CONTROL] {
            self.refuse_with_comp(CompError::ChangeControlMode)
                .map_err(|k| (k, c.at))?;
            self.path_control(block, c.code, sink);
        }
        if let Some(on) = plan.smoothing {
            self.emit(sink, Canon::SetSmoothing(on));
        }
        if let Some(g) = block.g(ggroup::DISTANCE) {
            let incremental = g == 910;
            if incremental != self.state.incremental {
                self.state.incremental = incremental;
                let what = if incremental {
                    "incremental"
                } else {
                    "absolute"
                };
                self.comment_call(sink, format!("distance mode changed to {what}"));
            }
        }
        if let Some(g) = block.g(ggroup::ARC_DISTANCE) {
            let incremental = g == 911;
            if incremental != self.state.ijk_incremental {
                self.state.ijk_incremental = incremental;
                let what = if incremental {
                    "incremental"
                } else {
                    "absolute"
                };
                self.comment_call(sink, format!("IJK distance mode changed to {what}"));
            }
        }
        if let Some(c) = block.g[ggroup::RETRACT] {
            self.refuse_with_comp(CompError::ChangeRetractMode)
                .map_err(|k| (k, c.at))?;
        }
        if let Some(g) = block.g(ggroup::RETRACT) {
            self.state.retract_r_plane = g == 990;
            let what = if g == 980 { "old_z" } else { "r_plane" };
            self.comment_call(sink, format!("retract mode set to {what}"));
        }
        if let Some(c) = block.g[ggroup::NON_MODAL] {
            self.non_modal(block, c.code, c.at, sink)?;
        }
        if let Some(m) = motion {
            self.motion(block, m, sink)?;
        }
        if let Some(m) = block.m[mgroup::SUBPROGRAM] {
            return self.subprogram(block, m.code, m.at);
        }
        if let Some(m) = block.m[mgroup::STOP] {
            self.flush_comp(sink).map_err(|k| (k, m.at))?;
            return Ok(self.stop(m.code, sink));
        }
        Ok(Flow::Continue)
    }

    /// `COMMENT("interpreter: …")`, the notes LinuxCNC makes on mode changes.
    pub(super) fn comment_call(&mut self, sink: &mut impl CanonSink, what: String) {
        self.emit(sink, Canon::Comment(format!("interpreter: {what}")));
    }

    fn feed_mode(&mut self, g: u32, sink: &mut impl CanonSink) {
        let (mode, what, code) = match g {
            930 => (FeedMode::InverseTime, "inverse time", 0),
            940 => (FeedMode::UnitsPerMinute, "units per minute", 0),
            _ => (FeedMode::UnitsPerRevolution, "units per revolution", 1),
        };
        self.state.feed_mode = mode;
        self.comment_call(sink, format!("feed mode set to {what}"));
        self.emit(sink, Canon::SetFeedMode(code));
        if mode != FeedMode::InverseTime {
            self.state.feed_rate = 0.0;
            self.emit(sink, Canon::SetFeedRate(0.0));
        }
    }

    /// M48–M53: which operator inputs act on the motion. `P0` turns one off, a missing or other
    /// P on (LinuxCNC's reading); M48/M49 switch both overrides together.
    fn set_switches(&mut self, m: u32, p: Option<f64>, sink: &mut impl CanonSink) {
        let on = match m {
            48 => true,
            49 => false,
            _ => p != Some(0.0),
        };
        let s = &mut self.state.switches;
        let mut calls = Vec::with_capacity(2);
        let mut set = |flag: &mut bool, enable: Canon, disable: Canon| {
            *flag = on;
            calls.push(if on { enable } else { disable });
        };
        use Canon::*;
        if matches!(m, 48..=50) {
            set(
                &mut s.feed_override,
                EnableFeedOverride,
                DisableFeedOverride,
            );
        }
        if matches!(m, 48 | 49 | 51) {
            set(
                &mut s.speed_override,
                EnableSpeedOverride,
                DisableSpeedOverride,
            );
        }
        match m {
            52 => set(
                &mut s.adaptive_feed,
                EnableAdaptiveFeed,
                DisableAdaptiveFeed,
            ),
            53 => set(&mut s.feed_hold, EnableFeedHold, DisableFeedHold),
            _ => {}
        }
        for call in calls {
            self.emit(sink, call);
        }
    }

    fn select_tool(&mut self, t: i64, at: u32, sink: &mut impl CanonSink) -> Exec {
        if t < 0 {
            return Err((ErrorKind::NegativeTool, at));
        }
        if t != 0 && self.cfg.tool_table.get(t).is_none() {
            return Err((ErrorKind::ToolNotFound(t), at));
        }
        self.state.selected_tool = Some(t);
        self.emit(sink, Canon::SelectTool(t));
        Ok(())
    }

    fn pocket_of(&self, tool: i64) -> usize {
        self.cfg.tool_table.get(tool).map_or(0, |t| t.row)
    }

    fn tool_change(&mut self, block: &Block, m: u32, at: u32, sink: &mut impl CanonSink) -> Exec {
        if m == 6 {
            self.refuse_with_comp(CompError::ToolChange)
                .map_err(|k| (k, at))?;
            let tool = self.state.selected_tool.unwrap_or(0);
            self.emit(sink, Canon::StartChange);
            self.state.spindle = None;
            self.emit(sink, Canon::StopSpindle);
            let pocket = self.pocket_of(tool);
            self.emit(sink, Canon::ChangeTool(pocket));
            self.state.current_pocket = pocket;
            // The spindle's entry becomes a copy of the tool's (tool 0 leaves it as it is).
            if let Some(t) = self.cfg.tool_table.get(tool).filter(|_| tool != 0) {
                self.state.spindle_slot = t.clone();
            }
            self.publish_tool_parameters();
            return Ok(());
        }
        // M61 Q: declare the tool in the spindle.
        let q = block.get(b'q').filter(|&q| q >= 0.0);
        let Some(q) = q else {
            return Err((ErrorKind::M61NeedsQ, at));
        };
        let tool = q.round() as i64;
        if tool != 0 && self.cfg.tool_table.get(tool).is_none() {
            return Err((ErrorKind::ToolNotFound(tool), at));
        }
        self.state.current_pocket = self.pocket_of(tool);
        self.emit(sink, Canon::ChangeToolNumber(self.state.current_pocket));
        self.publish_tool_parameters();
        Ok(())
    }

    fn tool_length(&mut self, block: &Block, g: u32, at: u32, sink: &mut impl CanonSink) -> Exec {
        let offset = match g {
            430 => match block.get(b'h').map(|h| h as i64) {
                None | Some(0) => self.to_program_units(self.state.spindle_slot.offset),
                Some(h) => self
                    .table_offset(h)
                    .ok_or((ErrorKind::ToolNotFound(h), at))?,
            },
            // Axes it does not name keep their offsets.
            431 => block.axes_over(self.state.tool_offset),
            434 => self.centre_point_offset(block, at)?,
            490 => Pose::ZERO,
            _ => return Err(unsupported(g, at)),
        };
        // The tip stays where it is: program coordinates shift by the change of offset, which
        // is in the machine's (unrotated) frame.
        let shift = state::rotate_xy(self.state.tool_offset - offset, -self.state.rotation);
        self.state.pos = self.state.pos + shift;
        self.state.tool_offset = offset;
        self.emit(sink, Canon::UseToolLengthOffset(offset));
        self.switch_centre_point(g == 434, sink);
        Ok(())
    }

    /// G20/G21: convert the position and the offsets in force (parameters, in the machine's
    /// units, keep their values).
    fn change_units(&mut self, units: Units) {
        if units == self.state.units {
            return;
        }
        let k = self.state.units.mm() / units.mm();
        let s = &mut self.state;
        s.pos = s.pos.scale_linear(k);
        s.origin = s.origin.scale_linear(k);
        s.axis_offset = s.axis_offset.scale_linear(k);
        s.tool_offset = s.tool_offset.scale_linear(k);
        s.units = units;
        self.comp.scale(k);
    }

    /// G54 … G59.3: the tool stays where it is and its point is re-expressed in the new system.
    pub(super) fn select_coordinate_system(&mut self, index: usize, sink: &mut impl CanonSink) {
        if index == self.state.origin_index {
            self.comment_call(sink, "continuing to use same coordinate system".into());
            return;
        }
        let (origin, rotation) = self.coordinate_system(index);
        let pos = self.state.current_in(origin, rotation);
        self.activate_coordinate_system(index, origin, rotation, pos, sink);
        self.emit(sink, Canon::SetG92Offset(self.state.axis_offset));
        self.emit(sink, Canon::SetXyRotation(self.state.rotation));
    }

    /// Offsets (program units) and XY rotation (degrees) stored for system `index`.
    pub(super) fn coordinate_system(&self, index: usize) -> (Pose, f64) {
        let base = coord_system_base(index);
        (self.offset_params(base), self.params.get(base + 9))
    }

    /// Make system `index` active with `origin` and `rotation`, the current point being `pos`.
    fn activate_coordinate_system(
        &mut self,
        index: usize,
        origin: Pose,
        rotation: f64,
        pos: Pose,
        sink: &mut impl CanonSink,
    ) {
        self.state.origin_index = index;
        self.params.set(params::COORD_SYSTEM, index as f64);
        self.state.origin = origin;
        self.state.rotation = rotation;
        self.state.pos = pos;
        self.emit(
            sink,
            Canon::SetG5xOffset {
                index: index as u8,
                offset: origin,
            },
        );
    }

    fn path_control(&mut self, block: &Block, g: u32, sink: &mut impl CanonSink) {
        let mode = match g {
            610 => ControlMode::ExactPath,
            611 => ControlMode::ExactStop,
            _ => ControlMode::Continuous(block.get(b'p').unwrap_or(0.0).max(0.0)),
        };
        self.state.control = mode;
        // LinuxCNC announces the planner of `G64 … R` before the blending mode itself.
        if let (ControlMode::Continuous(_), Some(r)) = (mode, block.get(b'r')) {
            self.emit(sink, planner_mode(r));
        }
        self.emit(sink, Canon::SetMotionControlMode(mode));
        if let ControlMode::Continuous(p) = mode {
            self.state.path_tolerance = p;
            let q = block.get(b'q').unwrap_or(p);
            self.state.naivecam_tolerance = q;
            self.emit(sink, Canon::SetNaivecamTolerance(q));
        }
    }

    /// G10, G28, G28.1, G30, G30.1, G52, G92, G92.1, G92.2, G92.3 (G4 and G53 are elsewhere).
    fn non_modal(&mut self, block: &Block, g: u32, at: u32, sink: &mut impl CanonSink) -> Exec {
        let refusal = match g {
            280 | 300 => Some(CompError::Home),
            281 | 301 => Some(CompError::SetHome),
            520 | 920..=923 => Some(CompError::ChangeAxisOffsets),
            _ => None,
        };
        if let Some(e) = refusal {
            self.refuse_with_comp(e).map_err(|k| (k, at))?;
        }
        let l = block.get(b'l').unwrap_or(0.0) as i64;
        match g {
            100 if matches!(l, 1 | 10 | 11) => self.write_tool_table(block, l, at, sink)?,
            100 if l == 0 => {
                // LinuxCNC reloads its tool data; tezgah's table is the one it was given.
                if self.state.spindle_slot.number > 0 {
                    return Err((
                        ErrorKind::G10L0ToolLoaded(self.state.spindle_slot.number),
                        at,
                    ));
                }
            }
            100 => self.set_coordinate_system(block, at, sink)?,
            280 | 300 => self.go_home(block, g, sink)?,
            281 | 301 => {
                let base = if g == 281 {
                    params::G28_HOME
                } else {
                    params::G30_HOME
                };
                // The home point is where the spindle (not the tool tip) is.
                let machine = self.state.to_machine(self.state.pos) + self.state.tool_offset;
                self.set_offset_params(base, machine);
            }
            520 | 920 => self.set_axis_offsets(block, g == 520, sink),
            921 | 922 => self.cancel_axis_offsets(g == 921, sink),
            923 => {
                let offset = self.offset_params(params::G92_OFFSET);
                self.state.pos = self.state.pos + self.state.axis_offset - offset;
                self.state.axis_offset = offset;
                self.params.set(params::G92_ENABLED, 1.0);
                self.emit(sink, Canon::SetG92Offset(offset));
            }
            40 | 530 => {}
            _ => return Err(unsupported(g, at)),
        }
        Ok(())
    }

    /// G92.1 (`forget`: the stored offsets too) and G92.2: the G92/G52 offsets stop applying;
    /// the tool stays where it is.
    fn cancel_axis_offsets(&mut self, forget: bool, sink: &mut impl CanonSink) {
        self.state.pos = self.state.pos + self.state.axis_offset;
        self.state.axis_offset = Pose::ZERO;
        if forget {
            self.params.set6(params::G92_OFFSET, [0.0; 6]);
        }
        self.params.set(params::G92_ENABLED, 0.0);
        self.emit(sink, Canon::SetG92Offset(Pose::ZERO));
    }

    /// G10 L2 / L20: set a coordinate system's offsets directly, or so that the current point
    /// reads as the given coordinates in it.
    fn set_coordinate_system(&mut self, block: &Block, at: u32, sink: &mut impl CanonSink) -> Exec {
        let l20 = block.get(b'l').is_some_and(|l| l as i64 == 20);
        if l20 && block.has(b'r') {
            return Err((ErrorKind::G10L20Rotation, at));
        }
        // LinuxCNC checks round(P) but uses the truncated P.
        let p = block.get(b'p').unwrap_or(0.0).trunc() as usize;
        let index = if p == 0 { self.state.origin_index } else { p };
        if index == self.state.origin_index {
            self.refuse_with_comp(CompError::ChangeActiveCoordinateSystem)
                .map_err(|k| (k, at))?;
        }
        let (mut offset, mut rotation) = self.coordinate_system(index);
        if let Some(r) = block.get(b'r') {
            rotation = r;
        }
        if l20 {
            // The offsets move by the difference between where the point is in that system
            // and where it should read, turned into the unrotated frame.
            let current = self.state.current_in(offset, rotation);
            let wanted = block.axes_over(current);
            offset = offset + state::rotate_xy(current - wanted, rotation);
        } else {
            offset = block.axes_over(offset);
        }
        let base = coord_system_base(index);
        self.set_offset_params(base, offset);
        self.params.set(base + 9, rotation);
        if index == self.state.origin_index {
            let pos = self.state.reframed(offset, rotation);
            self.activate_coordinate_system(index, offset, rotation, pos, sink);
            self.emit(sink, Canon::SetXyRotation(rotation));
        } else {
            self.comment_call(sink, "setting coordinate system origin".into());
        }
        Ok(())
    }

    /// G92 (offsets that make the current point the given coordinates) and G52 (local offsets).
    fn set_axis_offsets(&mut self, block: &Block, local: bool, sink: &mut impl CanonSink) {
        for (i, word) in block.axis_words().into_iter().enumerate() {
            if let Some(v) = word {
                let old = self.state.axis_offset.0[i];
                if local {
                    self.state.pos.0[i] += old - v;
                    self.state.axis_offset.0[i] = v;
                } else {
                    // The point reads exactly as programmed (LinuxCNC sets it, rather than
                    // computing it back from the offset and losing digits).
                    self.state.axis_offset.0[i] = self.state.pos.0[i] + old - v;
                    self.state.pos.0[i] = v;
                }
            }
        }
        self.set_offset_params(params::G92_OFFSET, self.state.axis_offset);
        self.params.set(params::G92_ENABLED, 1.0);
        self.emit(sink, Canon::SetG92Offset(self.state.axis_offset));
    }

    /// M0, M1, M60 pause; M2 and M30 end the program with LinuxCNC's resets.
    fn stop(&mut self, m: u32, sink: &mut impl CanonSink) -> Flow {
        match m {
            0 => self.emit(sink, Canon::ProgramStop),
            1 => self.emit(sink, Canon::OptionalProgramStop),
            60 => {
                self.emit(sink, Canon::PalletShuttle);
                self.emit(sink, Canon::ProgramStop);
            }
            _ => {
                self.end_program(m == 30, sink);
                return Flow::End;
            }
        }
        Flow::Continue
    }

    fn end_program(&mut self, pallet: bool, sink: &mut impl CanonSink) {
        // LinuxCNC reloads G54 even when it is already active.
        let (origin, rotation) = self.coordinate_system(1);
        let pos = self.state.reframed(origin, rotation);
        self.activate_coordinate_system(1, origin, rotation, pos, sink);
        self.emit(sink, Canon::SetXyRotation(self.state.rotation));
        if self.state.plane != Some(Plane::XY) {
            self.state.plane = Some(Plane::XY);
            self.emit(sink, Canon::SelectPlane(Some(Plane::XY)));
        }
        self.state.incremental = false;
        self.state.feed_mode = FeedMode::UnitsPerMinute;
        self.emit(sink, Canon::SetFeedMode(0));
        self.state.feed_rate = 0.0;
        self.emit(sink, Canon::SetFeedRate(0.0));
        self.state.spindle = None;
        self.emit(sink, Canon::StopSpindle);
        self.emit(sink, Canon::SetSpindleMode(0.0));
        if self.state.mist {
            self.state.mist = false;
            self.emit(sink, Canon::MistOff);
        }
        if self.state.flood {
            self.state.flood = false;
            self.emit(sink, Canon::FloodOff);
        }
        if self.g92_not_persistent() {
            // G92/G52 offsets last one run (LinuxCNC's DISABLE_G92_PERSISTENCE).
            self.cancel_axis_offsets(true, sink);
        }
        if pallet {
            self.emit(sink, Canon::PalletShuttle);
        }
        self.emit(sink, Canon::ProgramEnd);
        // In a `%` program, LinuxCNC looks past M2/M30 for the closing `%`.
        self.closing_percent_sought = self.percent == super::Percent::Open;
        self.state.motion = Some(10);
        self.ended = true;
    }
}

fn coord_index(g: u32) -> usize {
    match g {
        540..=590 => ((g - 540) / 10 + 1) as usize,
        _ => (g - 591 + 7) as usize,
    }
}

pub(super) fn unsupported(g10: u32, at: u32) -> ExecError {
    (ErrorKind::Unsupported(g_name(g10)), at)
}

fn unsupported_m(block: &Block, group: usize) -> ExecError {
    let c = block.m[group].expect("group present");
    (ErrorKind::Unsupported(format!("M{}", c.code)), c.at)
}

/// `G64 … R<r>`, as LinuxCNC's newer interpreters read it: a positive R picks the planner of
/// kind 1 with its peak scale clamped to 0.1–1; zero (or less) goes back to kind 0.
fn planner_mode(r: f64) -> Canon {
    if r > 0.0 {
        Canon::SetPlannerMode {
            kind: 1,
            peak_scale: r.clamp(0.1, 1.0),
        }
    } else {
        Canon::SetPlannerMode {
            kind: 0,
            peak_scale: -1.0,
        }
    }
}
