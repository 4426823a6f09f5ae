//! Canonical machining calls: what the interpreter tells the machine, in LinuxCNC's vocabulary.
//!
//! Positions are in the program's current length units and in program coordinates (the active
//! work offsets are announced by their own calls), exactly as LinuxCNC's canonical interface
//! receives them. `Display` prints a call the way LinuxCNC's standalone `rs274` prints it, so
//! the `canon` command can be diffed against it; [`crate::moves`] turns the calls into moves.

use std::fmt;
use std::sync::Arc;

use tezgah_geom::{Nurbs, Plane, Pose};

/// Length units of the program.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Units {
    Inches,
    #[default]
    Millimeters,
}

impl Units {
    /// Millimetres per unit.
    pub fn mm(self) -> f64 {
        match self {
            Units::Inches => 25.4,
            Units::Millimeters => 1.0,
        }
    }
}

/// `SET_MOTION_CONTROL_MODE` argument.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ControlMode {
    ExactStop,
    ExactPath,
    Continuous(f64),
}

/// Sense of spindle rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpindleDir {
    Clockwise,
    CounterClockwise,
}

/// Which program dialect a NURBS feed came from: it decides how `canon` prints it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NurbsDialect {
    /// LinuxCNC's G5, G5.1 and G5.2/G5.3: printed as `rs274` prints `NURBS_FEED`.
    LinuxCnc,
    /// Fanuc's G06.2: printed as tezgah's own `NURBS_G6_FEED` (LinuxCNC 2.9 has no G6.2).
    Fanuc,
}

/// A NURBS feed, in program coordinates and units (A B C in degrees).
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsFeed {
    pub dialect: NurbsDialect,
    /// The curve, built (and so validated) once by the interpreter; its first control point
    /// is the current point. [`crate::moves`] maps it to the machine frame.
    pub curve: Arc<Nurbs>,
    /// Where the move ends, all six axes (X Y Z = the last control point).
    pub end: Pose,
}

/// One canonical call.
#[derive(Debug, Clone, PartialEq)]
pub enum Canon {
    UseLengthUnits(Units),
    SetG5xOffset {
        index: u8,
        offset: Pose,
    },
    SetG92Offset(Pose),
    SetXyRotation(f64),
    SetFeedReference,
    OnReset,
    /// `None` for the planes of the U V W axes (G17.1 …), which tezgah does not drive.
    SelectPlane(Option<Plane>),
    SetMotionControlMode(ControlMode),
    SetNaivecamTolerance(f64),
    /// LinuxCNC's `G64 P… R…` (newer than 2.9): the trajectory planner's kind and its peak
    /// scale. `R` > 0 selects kind 1 with the scale clamped to 0.1–1; `R0` kind 0 (scale −1).
    /// tezgah's planner takes its limits from the machine file; the call is carried for `canon`.
    SetPlannerMode {
        kind: u8,
        peak_scale: f64,
    },
    /// Fanuc's `G05.1 Q1`/`Q0` (tezgah's own call; LinuxCNC has none): compression of short
    /// moves into splines on or off.
    SetSmoothing(bool),
    /// Fanuc's `G43.4 H<n>` / `G49` (tezgah's own call; LinuxCNC 2.9 has no G43.4):
    /// tool-centre-point control on with the tool length (program units), or off (`None`).
    SetToolCentrePoint(Option<f64>),
    /// G93 = 1, G94 = 0, G95 = 2 (LinuxCNC's `SET_FEED_MODE(spindle, mode)`).
    SetFeedMode(i32),
    SetFeedRate(f64),
    SetSpindleSpeed(f64),
    StartSpindle(SpindleDir),
    StopSpindle,
    /// Stop the spindle at orientation 0 (G87), turning the given way before.
    OrientSpindle(SpindleDir),
    SetSpindleMode(f64),
    StraightTraverse(Pose),
    StraightFeed(Pose),
    /// G38.2–G38.5: move toward the point until the probe input changes (LinuxCNC's
    /// `STRAIGHT_PROBE`), between `TURN_PROBE_ON` and `TURN_PROBE_OFF`.
    StraightProbe(Pose),
    TurnProbeOn,
    TurnProbeOff,
    /// G33/G33.1: the moves up to `StopSpeedFeedSync` follow the spindle's angle, advancing
    /// `feed_per_rev` (program units) per revolution (LinuxCNC's `START_SPEED_FEED_SYNCH` in
    /// position mode).
    StartSpeedFeedSync {
        feed_per_rev: f64,
    },
    StopSpeedFeedSync,
    /// G33.1: tap to X Y Z following the spindle, reverse it at depth and come back to the start
    /// (LinuxCNC's `RIGID_TAP`); the current point does not change.
    /// `end` is X Y Z of the bottom with the current A B C; `retract_scale` the spindle speed
    /// factor for the way back (the I word, 1 without it; `rs274` does not print it).
    RigidTap {
        end: Pose,
        retract_scale: f64,
    },
    ArcFeed {
        first_end: f64,
        second_end: f64,
        first_axis: f64,
        second_axis: f64,
        rotation: i32,
        axis_end: f64,
        abc: [f64; 3],
    },
    /// A NURBS curve (G5, G5.1, G5.2/G5.3, G06.2). Boxed: control points make it large.
    NurbsFeed(Box<NurbsFeed>),
    Dwell(f64),
    Comment(String),
    Message(String),
    /// `(PRINT,…)`: text for the operator's console, printed bare by `rs274`.
    Print(String),
    SelectTool(i64),
    StartChange,
    /// Load the tool of the given pocket (LinuxCNC's pocket = 1-based row of the tool table).
    ChangeTool(usize),
    /// M61: tell the machine which pocket's tool is in the spindle without a change.
    ChangeToolNumber(usize),
    /// G10 L1/L10/L11 wrote the tool table: `index` is the tool's pocket index (0 = the
    /// spindle), the offsets are in the machine's units.
    SetToolTableEntry {
        index: usize,
        tool: i64,
        offset: Pose,
        diameter: f64,
        front_angle: f64,
        back_angle: f64,
        orientation: i32,
    },
    /// X Y Z A B C offsets (U V W are always zero here).
    UseToolLengthOffset(Pose),
    FloodOn,
    FloodOff,
    MistOn,
    MistOff,
    EnableFeedOverride,
    DisableFeedOverride,
    EnableSpeedOverride,
    DisableSpeedOverride,
    /// M52 (P1): the feed follows the adaptive-feed input.
    EnableAdaptiveFeed,
    DisableAdaptiveFeed,
    /// M53 (P1): the feed-hold input is honoured; `M53 P0` ignores it.
    EnableFeedHold,
    DisableFeedHold,
    ProgramStop,
    OptionalProgramStop,
    PalletShuttle,
    ProgramEnd,
    Finish,
}

/// `%.4f` of a pose's six values joined by ", ".
struct Six<'a>(&'a Pose);

impl fmt::Display for Six<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = &self.0 .0;
        write!(
            f,
            "{:.4}, {:.4}, {:.4}, {:.4}, {:.4}, {:.4}",
            p[0], p[1], p[2], p[3], p[4], p[5]
        )
    }
}

impl fmt::Display for Canon {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use Canon::*;
        match self {
            UseLengthUnits(u) => write!(
                f,
                "USE_LENGTH_UNITS({})",
                match u {
                    Units::Inches => "CANON_UNITS_INCHES",
                    Units::Millimeters => "CANON_UNITS_MM",
                }
            ),
            SetG5xOffset { index, offset } => {
                write!(f, "SET_G5X_OFFSET({index}, {})", Six(offset))
            }
            SetG92Offset(p) => write!(f, "SET_G92_OFFSET({})", Six(p)),
            SetXyRotation(r) => write!(f, "SET_XY_ROTATION({r:.4})"),
            SetFeedReference => f.write_str("SET_FEED_REFERENCE(CANON_XYZ)"),
            OnReset => f.write_str("ON_RESET()"),
            SetSmoothing(on) => write!(f, "SET_SMOOTHING({})", if *on { "ON" } else { "OFF" }),
            SetToolCentrePoint(Some(length)) => write!(f, "SET_TOOL_CENTRE_POINT(ON, {length:.4})"),
            SetToolCentrePoint(None) => f.write_str("SET_TOOL_CENTRE_POINT(OFF)"),
            SelectPlane(p) => write!(
                f,
                "SELECT_PLANE({})",
                match p {
                    Some(Plane::XY) => "CANON_PLANE_XY",
                    Some(Plane::ZX) => "CANON_PLANE_XZ",
                    Some(Plane::YZ) => "CANON_PLANE_YZ",
                    None => "CANON_PLANE_UNKNOWN",
                }
            ),
            SetMotionControlMode(m) => match m {
                ControlMode::ExactStop => f.write_str("SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)"),
                ControlMode::ExactPath => f.write_str("SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)"),
                ControlMode::Continuous(t) => {
                    write!(f, "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, {t:.6})")
                }
            },
            SetNaivecamTolerance(t) => write!(f, "SET_NAIVECAM_TOLERANCE({t:.4})"),
            SetPlannerMode { kind, peak_scale } => {
                write!(f, "SET_PLANNER_MODE(type={kind}, peak_scale={peak_scale:.6})")
            }
            SetFeedMode(m) => write!(f, "SET_FEED_MODE(0, {m})"),
            SetFeedRate(v) => write!(f, "SET_FEED_RATE({v:.4})"),
            SetSpindleSpeed(s) => write!(f, "SET_SPINDLE_SPEED(0, {s:.4})"),
            StartSpindle(SpindleDir::Clockwise) => f.write_str("START_SPINDLE_CLOCKWISE(0)"),
            StartSpindle(SpindleDir::CounterClockwise) => {
                f.write_str("START_SPINDLE_COUNTERCLOCKWISE(0)")
            }
            StopSpindle => f.write_str("STOP_SPINDLE_TURNING(0)"),
            // LinuxCNC's CANON_DIRECTION: 2 clockwise, 3 counterclockwise.
            OrientSpindle(dir) => write!(
                f,
                "ORIENT_SPINDLE(0, 0.0000, {})",
                match dir {
                    SpindleDir::Clockwise => 2,
                    SpindleDir::CounterClockwise => 3,
                }
            ),
            SetSpindleMode(v) => write!(f, "SET_SPINDLE_MODE(0 {v:.4})"),
            StraightTraverse(p) => write!(f, "STRAIGHT_TRAVERSE({})", Six(p)),
            StraightFeed(p) => write!(f, "STRAIGHT_FEED({})", Six(p)),
            StraightProbe(p) => write!(f, "STRAIGHT_PROBE({})", Six(p)),
            TurnProbeOn => f.write_str("TURN_PROBE_ON()"),
            TurnProbeOff => f.write_str("TURN_PROBE_OFF()"),
            StartSpeedFeedSync { feed_per_rev } => {
                write!(f, "START_SPEED_FEED_SYNC({feed_per_rev:.6},0)")
            }
            StopSpeedFeedSync => f.write_str("STOP_SPEED_FEED_SYNCH()"),
            RigidTap { end, .. } => {
                let [x, y, z] = [end.0[0], end.0[1], end.0[2]];
                write!(f, "RIGID_TAP({x:.4}, {y:.4}, {z:.4})")
            }
            ArcFeed {
                first_end,
                second_end,
                first_axis,
                second_axis,
                rotation,
                axis_end,
                abc,
            } => write!(
                f,
                "ARC_FEED({first_end:.4}, {second_end:.4}, {first_axis:.4}, {second_axis:.4}, {rotation}, {axis_end:.4}, {:.4}, {:.4}, {:.4})",
                abc[0], abc[1], abc[2]
            ),
            NurbsFeed(n) => match n.dialect {
                // rs274 2.9's saicanon prints only the number of control points.
                NurbsDialect::LinuxCnc => {
                    write!(f, "NURBS_FEED({}, ...)", n.curve.weights().len())
                }
                NurbsDialect::Fanuc => write_nurbs_g6(f, n),
            },
            Dwell(s) => write!(f, "DWELL({s:.4})"),
            Comment(s) => write!(f, "COMMENT(\"{s}\")"),
            Message(s) => write!(f, "MESSAGE(\"{s}\")"),
            Print(s) => f.write_str(s),
            SelectTool(t) => write!(f, "SELECT_TOOL({t})"),
            StartChange => f.write_str("START_CHANGE()"),
            ChangeTool(p) => write!(f, "CHANGE_TOOL({p})"),
            ChangeToolNumber(p) => write!(f, "CHANGE_TOOL_NUMBER({p})"),
            // rs274 prints the offsets (U V W zero) and the lathe fields, not the diameter.
            SetToolTableEntry {
                index,
                tool,
                offset: o,
                front_angle,
                back_angle,
                orientation,
                ..
            } => write!(
                f,
                "SET_TOOL_TABLE_ENTRY({index}, {tool}, {:.4} {:.4} {:.4} {:.4} {:.4} {:.4} 0.0000 \
                 0.0000 0.0000, {front_angle:.4}, {back_angle:.4}, {orientation})",
                o.0[0], o.0[1], o.0[2], o.0[3], o.0[4], o.0[5]
            ),
            UseToolLengthOffset(p) => {
                let o = &p.0;
                write!(
                    f,
                    "USE_TOOL_LENGTH_OFFSET({:.4} {:.4} {:.4}, {:.4} {:.4} {:.4}, 0.0000 0.0000 0.0000)",
                    o[0], o[1], o[2], o[3], o[4], o[5]
                )
            }
            FloodOn => f.write_str("FLOOD_ON()"),
            FloodOff => f.write_str("FLOOD_OFF()"),
            MistOn => f.write_str("MIST_ON()"),
            MistOff => f.write_str("MIST_OFF()"),
            EnableFeedOverride => f.write_str("ENABLE_FEED_OVERRIDE()"),
            DisableFeedOverride => f.write_str("DISABLE_FEED_OVERRIDE()"),
            EnableSpeedOverride => f.write_str("ENABLE_SPEED_OVERRIDE(0)"),
            DisableSpeedOverride => f.write_str("DISABLE_SPEED_OVERRIDE(0)"),
            EnableAdaptiveFeed => f.write_str("ENABLE_ADAPTIVE_FEED()"),
            DisableAdaptiveFeed => f.write_str("DISABLE_ADAPTIVE_FEED()"),
            EnableFeedHold => f.write_str("ENABLE_FEED_HOLD()"),
            DisableFeedHold => f.write_str("DISABLE_FEED_HOLD()"),
            ProgramStop => f.write_str("PROGRAM_STOP()"),
            OptionalProgramStop => f.write_str("OPTIONAL_PROGRAM_STOP()"),
            PalletShuttle => f.write_str("PALLET_SHUTTLE()"),
            ProgramEnd => f.write_str("PROGRAM_END()"),
            Finish => f.write_str("FINISH()"),
        }
    }
}

/// `NURBS_G6_FEED(order, n, X Y Z W; …, K k0 k1 …, A, B, C)`: tezgah's own call for G06.2,
/// every number in `%.4f` as rs274 prints positions.
fn write_nurbs_g6(f: &mut fmt::Formatter<'_>, n: &NurbsFeed) -> fmt::Result {
    let c = &n.curve;
    let points = c.control_points();
    write!(f, "NURBS_G6_FEED({}, {}, ", c.degree() + 1, points.len())?;
    for (k, (p, w)) in points.iter().zip(c.weights()).enumerate() {
        let sep = if k == 0 { "" } else { "; " };
        write!(f, "{sep}{:.4} {:.4} {:.4} {:.4}", p.x, p.y, p.z, w)?;
    }
    f.write_str(", K")?;
    for k in c.knots() {
        write!(f, " {k:.4}")?;
    }
    let e = &n.end.0;
    write!(f, ", {:.4}, {:.4}, {:.4})", e[3], e[4], e[5])
}

impl Canon {
    /// Whether this call moves the machine or sets the feed in force: the calls that the
    /// differential tests compare numerically.
    pub fn is_motion(&self) -> bool {
        matches!(
            self,
            Canon::StraightTraverse(_)
                | Canon::StraightFeed(_)
                | Canon::StraightProbe(_)
                | Canon::StartSpeedFeedSync { .. }
                | Canon::StopSpeedFeedSync
                | Canon::RigidTap { .. }
                | Canon::ArcFeed { .. }
                | Canon::NurbsFeed(_)
                | Canon::Dwell(_)
                | Canon::SetFeedRate(_)
        )
    }
}

/// Where a canonical call came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Origin {
    /// 1-based source line; 0 for the calls made before the first line and after the last.
    pub line: u32,
    /// The block's N word, if any.
    pub n: Option<i64>,
    /// The text the line is in: 0 the program, k the k-th subroutine file the interpreter
    /// loaded ([`crate::Interpreter::subroutine_file`]).
    pub file: u16,
}

/// Receiver of canonical calls.
pub trait CanonSink {
    fn call(&mut self, origin: Origin, call: Canon);
}

impl CanonSink for Vec<(Origin, Canon)> {
    fn call(&mut self, origin: Origin, call: Canon) {
        self.push((origin, call));
    }
}

/// A sink that drops every call (for pre-flight checks and benchmarks).
#[derive(Debug, Default, Clone, Copy)]
pub struct Discard;

impl CanonSink for Discard {
    fn call(&mut self, _: Origin, _: Canon) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_match_rs274() {
        let arc = Canon::ArcFeed {
            first_end: 50.0,
            second_end: 0.0,
            first_axis: 24.986,
            second_axis: 0.0,
            rotation: -1,
            axis_end: 0.0,
            abc: [0.0; 3],
        };
        assert_eq!(
            arc.to_string(),
            "ARC_FEED(50.0000, 0.0000, 24.9860, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)"
        );
        assert_eq!(
            Canon::SetMotionControlMode(ControlMode::Continuous(1.0)).to_string(),
            "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 1.000000)"
        );
        assert_eq!(
            Canon::SetSpindleMode(0.0).to_string(),
            "SET_SPINDLE_MODE(0 0.0000)"
        );
        assert_eq!(
            Canon::UseToolLengthOffset(Pose::new(0.0, 0.0, 2.54, 0.0, 0.0, 0.0)).to_string(),
            "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 2.5400, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)"
        );
    }
}
