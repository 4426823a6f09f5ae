//! Cutter radius compensation (G40, G41, G42, G41.1, G42.1) as LinuxCNC's interpreter does it:
//! the tool centre runs one tool radius to the left or right of the programmed contour, in the
//! XY plane (G17) or the XZ plane (G18), and the interpreter emits the offset path.
//!
//! A compensated move cannot be sent when it is read: where it ends depends on the next move
//! (a concave corner pulls its end back, a convex one adds an arc round the corner). So each
//! compensated move waits in a queue, together with the feed, spindle, coolant and comment calls
//! issued after it, until the next move or G40 fixes its end point ([`queue`]). The geometry of
//! the entry move and of later lines and arcs is in [`straight`] and [`arc`].
//!
//! Coordinates here are the compensation plane's (first, second, normal) axes — X Y Z in G17,
//! Z X Y in G18, as LinuxCNC's `comp_get_current` orders them — in program units.

mod arc;
mod queue;
mod straight;

pub(super) use arc::ProgrammedArc;
pub(super) use queue::Held;

use tezgah_geom::{Plane, Pose};

use crate::block::Block;
use crate::canon::CanonSink;
use crate::error::ErrorKind;

use super::execute::Exec;
use super::Interpreter;

/// Angle (rad) within which two directions count as the same at a corner: below it no corner
/// arc is added, beyond it the other way a corner is concave (LinuxCNC
/// `TOLERANCE_CONCAVE_CORNER`).
const CORNER_TOLERANCE: f64 = 0.05;

/// Which side of the programmed path, seen in the direction of travel, the tool runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Side {
    /// G41, G41.1.
    Left,
    /// G42, G42.1.
    Right,
}

impl Side {
    fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// Whether the tool is on the inside of an arc of turn `turn` (+ counter-clockwise).
    fn inside_arc(self, turn: i32) -> bool {
        (self == Side::Left && turn > 0) || (self == Side::Right && turn < 0)
    }

    /// The normal pointing from the path to the tool, as an angle added to the direction of
    /// travel.
    fn normal_angle(self) -> f64 {
        match self {
            Side::Left => std::f64::consts::FRAC_PI_2,
            Side::Right => -std::f64::consts::FRAC_PI_2,
        }
    }

    /// Turn of an arc that goes round a convex corner on this side.
    fn corner_turn(self) -> i32 {
        match self {
            Side::Left => -1,
            Side::Right => 1,
        }
    }
}

/// The compensation state of a running program (LinuxCNC's `cutter_comp_*`, `program_*` and
/// the interp queue).
#[derive(Debug, Clone)]
pub(super) struct CutterComp {
    /// `None` while G40 is in force.
    pub side: Option<Side>,
    /// Tool radius, program units, never negative (a negative table diameter swaps sides).
    pub radius: f64,
    /// No compensated move has been made since compensation was turned on.
    pub first_move: bool,
    /// The move after G40 turned compensation off must be a straight line.
    pub arc_not_allowed: bool,
    /// The last programmed (uncompensated) point, X Y Z in program coordinates; the current
    /// point of the state is the compensated one.
    pub programmed: [f64; 3],
    /// Moves and calls waiting for their end point to be fixed.
    pub queue: Vec<Held>,
    /// Where the queued moves start (their end points are moved relative to it), once known.
    pub endpoint: Option<[f64; 2]>,
}

impl Default for CutterComp {
    fn default() -> Self {
        CutterComp {
            side: None,
            radius: 0.0,
            first_move: true,
            arc_not_allowed: false,
            programmed: [0.0; 3],
            queue: Vec::new(),
            endpoint: None,
        }
    }
}

impl CutterComp {
    /// Compensation changes the path: it is on with a radius above zero.
    pub fn active(&self) -> bool {
        self.side.is_some() && self.radius > 0.0
    }

    /// Compensation has begun: the programmed point, not the current one, is where the
    /// program is (LinuxCNC's `comp && middle` in `find_ends`).
    pub fn in_progress(&self) -> bool {
        self.side.is_some() && !self.first_move
    }

    /// G20/G21 while compensating: everything held in program units is rescaled.
    pub fn scale(&mut self, k: f64) {
        self.radius *= k;
        for v in &mut self.programmed {
            *v *= k;
        }
        if let Some(e) = &mut self.endpoint {
            e[0] *= k;
            e[1] *= k;
        }
        for held in &mut self.queue {
            held.scale(k);
        }
    }
}

/// Errors of cutter compensation, worded as LinuxCNC words them.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompError {
    #[error("Cutter radius compensation allowed only in XY, XZ planes")]
    OnlyInXyOrXz,
    #[error("Cannot turn cutter radius comp on when on")]
    AlreadyOn,
    #[error("G{0}.1 with no D word")]
    DynamicWithoutD(u32),
    #[error("G{0}.1 with L word, but plane is not G18")]
    OrientationOutsideG18(u32),
    #[error("G{0} requires D word to be a whole number")]
    DNotInteger(u32),
    #[error("G{0} with lathe tool, but plane is not G18")]
    LatheToolOutsideG18(u32),
    #[error("Cannot use g53 with cutter radius comp")]
    G53,
    #[error("Length of cutter compensation entry move is not greater than the tool radius")]
    EntryMoveTooShort,
    #[error("Radius of cutter compensation entry arc is not greater than the tool radius")]
    EntryArcTooSmall,
    #[error("Tool radius not less than arc radius with comp")]
    ToolNotSmallerThanArc,
    #[error("Bug in tool radius comp")]
    Bug,
    #[error(
        "BUG: cutter compensation has generated an invalid arc with mismatched radii r1 {0:.6} r2 {1:.6}\n"
    )]
    MismatchedRadii(f64, f64),
    #[error("Arc move in concave corner cannot be reached by the tool without gouging")]
    ArcGouge,
    #[error("Straight traverse in concave corner cannot be reached by the tool without gouging")]
    TraverseGouge,
    #[error("Straight feed in concave corner cannot be reached by the tool without gouging")]
    FeedGouge,
    #[error("Arc to arc motion is invalid because the arcs have the same center")]
    ArcArcSameCenter,
    #[error("Arc to arc motion makes a corner the compensated tool can't fit in without gouging")]
    ArcArcGouge,
    #[error(
        "Arc to straight motion makes a corner the compensated tool can't fit in without gouging"
    )]
    ArcLineGouge,
    #[error("Zero degree inside corner is invalid for cutter compensation")]
    ZeroDegreeCorner,
    #[error("The move just after exiting cutter compensation mode must be straight, not an arc")]
    ArcAfterExit,
    #[error("Cannot change planes with cutter radius compensation on")]
    ChangePlane,
    #[error("Cannot change coordinate systems with cutter radius compensation on")]
    ChangeCoordinateSystem,
    #[error("Cannot change the active coordinate system with cutter radius compensation on")]
    ChangeActiveCoordinateSystem,
    #[error("Cannot change control mode with cutter radius compensation on")]
    ChangeControlMode,
    #[error("Cannot change retract mode with cutter radius compensation on")]
    ChangeRetractMode,
    #[error("Cannot change axis offsets with cutter radius comp")]
    ChangeAxisOffsets,
    #[error("Cannot use g28 or g30 with cutter radius comp")]
    Home,
    #[error("Cannot set reference point with cutter compensation in effect")]
    SetHome,
    #[error("Cannot change tools with cutter radius compensation on")]
    ToolChange,
    #[error("Cannot change tool offset with cutter radius compensation on")]
    ToolOffset,
    #[error("Cannot use canned cycles with cutter compensation on")]
    CannedCycle,
    #[error("Cannot convert spline with cutter radius compensation")]
    Spline,
}

/// The (first, second, normal) axis indices of the compensation plane.
fn plane_axes(plane: Option<Plane>) -> (usize, usize, usize) {
    plane.unwrap_or(Plane::XY).axes()
}

impl Interpreter {
    /// G40, G41, G42, G41.1, G42.1 (LinuxCNC's `convert_cutter_compensation`).
    pub(super) fn cutter_compensation(
        &mut self,
        block: &Block,
        g: u32,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        if g == 400 {
            return self.cutter_comp_off(sink).map_err(|k| (k, at));
        }
        let side = if matches!(g, 410 | 411) {
            Side::Left
        } else {
            Side::Right
        };
        self.cutter_comp_on(block, g, side, sink)
            .map_err(|k| (k, at))
    }

    fn cutter_comp_off(&mut self, sink: &mut impl CanonSink) -> Result<(), ErrorKind> {
        self.comment_call(sink, "cutter radius compensation off".into());
        let comp = &self.comp;
        if comp.side.is_some() && comp.radius > 0.0 && !comp.first_move {
            let (a, b, _) = plane_axes(self.state.plane);
            let current = [self.state.pos.0[a], self.state.pos.0[b]];
            self.move_endpoint_and_flush(current, sink)?;
            self.dequeue(sink);
            let p = self.comp.programmed;
            self.state.pos.0[..3].copy_from_slice(&p);
            self.comp.arc_not_allowed = true;
        }
        self.comp.side = None;
        self.comp.first_move = true;
        Ok(())
    }

    fn cutter_comp_on(
        &mut self,
        block: &Block,
        g: u32,
        mut side: Side,
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        let plane = self.state.plane;
        if !matches!(plane, Some(Plane::XY | Plane::ZX)) {
            return Err(CompError::OnlyInXyOrXz.into());
        }
        if self.comp.side.is_some() {
            return Err(CompError::AlreadyOn.into());
        }
        let whole = g / 10;
        let d = block.get(b'd');
        let radius = if matches!(g, 411 | 421) {
            let d = d.ok_or(CompError::DynamicWithoutD(whole))?;
            if block.has(b'l') && plane != Some(Plane::ZX) {
                return Err(CompError::OrientationOutsideG18(whole).into());
            }
            d / 2.0
        } else {
            let diameter = match d {
                None => self.state.spindle_slot.diameter,
                Some(d) => {
                    // LinuxCNC rounds by truncating d + 0.5, so a negative D is never near a
                    // whole number and fails here.
                    let tool = (d + 0.5) as i64;
                    if (tool as f64 - d).abs() >= 0.0001 {
                        return Err(CompError::DNotInteger(whole).into());
                    }
                    match self.cfg.tool_table.get(tool) {
                        Some(t) => t.diameter,
                        // D0 is the spindle's entry.
                        None if tool == 0 => self.state.spindle_slot.diameter,
                        None => return Err(ErrorKind::ToolNotFound(tool)),
                    }
                }
            };
            diameter * self.program_per_machine_unit() / 2.0
        };
        if radius < 0.0 {
            side = side.other();
        }
        let what = match side {
            Side::Right => "right",
            Side::Left => "left",
        };
        self.comment_call(sink, format!("cutter radius compensation on {what}"));
        self.comp.radius = radius.abs();
        self.comp.side = Some(side);
        Ok(())
    }

    /// The refusals of LinuxCNC while compensation is on (even with a zero radius).
    pub(super) fn refuse_with_comp(&self, e: CompError) -> Result<(), ErrorKind> {
        if self.comp.side.is_some() {
            Err(e.into())
        } else {
            Ok(())
        }
    }

    /// G17/G18/G19 while compensating: only the plane in force may be named again, and never
    /// G19 (LinuxCNC's `convert_set_plane`).
    pub(super) fn refuse_plane_change(&self, g: u32) -> Result<(), ErrorKind> {
        if self.comp.side.is_none() {
            return Ok(());
        }
        let named = match g {
            170 => Some(Plane::XY),
            180 => Some(Plane::ZX),
            190 => Some(Plane::YZ),
            _ => None,
        };
        if named != self.state.plane {
            return Err(CompError::ChangePlane.into());
        }
        if g == 190 {
            return Err(CompError::OnlyInXyOrXz.into());
        }
        Ok(())
    }

    /// The compensation plane's (first, second, normal) coordinates of the current point.
    fn comp_current(&self) -> [f64; 3] {
        let (a, b, n) = plane_axes(self.state.plane);
        let p = &self.state.pos.0;
        [p[a], p[b], p[n]]
    }

    /// The same of the last programmed point.
    fn comp_programmed(&self) -> [f64; 3] {
        let (a, b, n) = plane_axes(self.state.plane);
        let p = &self.comp.programmed;
        [p[a], p[b], p[n]]
    }

    fn set_comp_programmed(&mut self, q: [f64; 3]) {
        let (a, b, n) = plane_axes(self.state.plane);
        self.comp.programmed[a] = q[0];
        self.comp.programmed[b] = q[1];
        self.comp.programmed[n] = q[2];
    }

    /// The current point becomes `q` (plane coordinates) with rotary axes `abc`.
    fn set_comp_current(&mut self, q: [f64; 3], abc: [f64; 3]) {
        let (a, b, n) = plane_axes(self.state.plane);
        let p = &mut self.state.pos.0;
        p[a] = q[0];
        p[b] = q[1];
        p[n] = q[2];
        p[3..].copy_from_slice(&abc);
    }

    /// Where a compensated move starts from: the last programmed point once compensation is
    /// under way, else the current point (the start of the entry move).
    pub(super) fn comp_start(&self) -> Pose {
        let mut start = self.state.pos;
        if self.comp.active() && !self.comp.first_move {
            start.0[..3].copy_from_slice(&self.comp.programmed);
        }
        start
    }

    /// M0, M1, M2, M30, M60: every held move is sent as it stands.
    pub(super) fn flush_comp(&mut self, sink: &mut impl CanonSink) -> Result<(), ErrorKind> {
        let c = self.comp_current();
        self.move_endpoint_and_flush([c[0], c[1]], sink)?;
        self.dequeue(sink);
        Ok(())
    }
}

/// Direction of `to` seen from `from`, radians.
pub(super) fn angle_to(from: [f64; 2], to: [f64; 2]) -> f64 {
    (to[1] - from[1]).atan2(to[0] - from[0])
}

/// Distance between two points of the plane.
pub(super) fn distance(p: [f64; 2], q: [f64; 2]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// The point `radius` from `center` in direction `angle`.
pub(super) fn polar(center: [f64; 2], radius: f64, angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [center[0] + radius * c, center[1] + radius * s]
}
