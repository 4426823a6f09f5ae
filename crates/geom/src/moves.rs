//! The typed moves that flow from any program source (G-code, CAM, MDI) into path planning.
//!
//! Positions are absolute, in mm and degrees, in the workpiece frame seen by the machine (work
//! offsets and tool length already applied). Each move carries the 1-based source line it came
//! from so that samples, reports and errors can point back at the program.

use std::sync::Arc;

use crate::nurbs::Nurbs;
use crate::pose::Pose;

/// The plane of an arc: G17 (XY), G18 (ZX) or G19 (YZ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    #[default]
    XY,
    ZX,
    YZ,
}

impl Plane {
    /// Indices of (first in-plane axis, second in-plane axis, normal axis), ordered so that a
    /// positive rotation from first to second is counter-clockwise seen from the normal's + side.
    pub const fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::XY => (0, 1, 2),
            Plane::ZX => (2, 0, 1),
            Plane::YZ => (1, 2, 0),
        }
    }
}

/// Sense and number of turns of an arc: `+n` counter-clockwise, `-n` clockwise, as LinuxCNC's
/// `ARC_FEED` rotation argument (1 = less than one full turn, 2 = one extra full turn, …).
pub type Turn = i32;

/// G33 / G33.1: a straight move whose position along the line follows the spindle's angle,
/// `pitch` mm per revolution (the thread's lead), instead of a feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyncedMove {
    pub end: Pose,
    /// mm along the line per spindle revolution.
    pub pitch: f64,
    /// G33.1: rigid tapping — the spindle reverses at `end` and the tool follows it back to the
    /// start (where the move leaves the machine); the spindle speed on the way back is
    /// multiplied by this (LinuxCNC's I word, 1 without it).
    pub tap: Option<f64>,
}

/// A circular or helical feed move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcMove {
    pub plane: Plane,
    /// End of the move (all six axes).
    pub end: Pose,
    /// Centre in the two in-plane coordinates (first, second axis of `plane`).
    pub center: [f64; 2],
    pub turn: Turn,
}

/// A NURBS feed move (G5, G5.1, G5.2/G5.3, G06.2): the whole curve is one move.
///
/// The curve's control points are tool-tip positions in mm, in the same frame as every other
/// move's end (work offsets, XY rotation and tool length applied: all three are affine maps, and
/// a NURBS mapped point by point through an affine map is the mapped curve). The curve starts at
/// the position before the move. Rotary axes run from their start values to `end`'s in
/// proportion to arc length, as along an arc.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsMove {
    /// Shared, so that copying a move never copies its control points.
    pub curve: Arc<Nurbs>,
    /// End of the move (all six axes); its X Y Z is the curve's last point.
    pub end: Pose,
}

/// What a move does.
#[derive(Debug, Clone, PartialEq)]
pub enum MoveKind {
    /// G0: straight line at the machine's rapid speed.
    Rapid { end: Pose },
    /// G1: straight line at the programmed feed.
    Feed { end: Pose },
    /// G2/G3: arc or helix at the programmed feed.
    Arc(ArcMove),
    /// G5, G5.1, G5.2/G5.3, G06.2: a NURBS curve at the programmed feed.
    Nurbs(NurbsMove),
    /// G33 / G33.1: a straight move following the spindle (`tezgah run` simulates the
    /// spindle; the path builder takes it as a feed at pitch × programmed speed).
    Synced(SyncedMove),
    /// G4: wait, motion stopped.
    Dwell { seconds: f64 },
    /// The feed in force from here on, mm/min (or 1/min in inverse time, mm/rev with G95).
    FeedRate { value: f64 },
    /// G93/G94/G95.
    FeedMode(FeedMode),
    /// S: the spindle speed from here on, rev/min. Under G95 the feed (mm/rev) times it is the
    /// feed along the path; the spindle is taken to run at the programmed speed.
    SpindleSpeed { rpm: f64 },
    /// G61 / G61.1 / G64 P Q.
    PathMode(PathMode),
    /// Fanuc's `G05.1 Q1` (true) / `Q0`: runs of short moves may be compressed into splines.
    Smoothing(bool),
    /// Whether the operator's feed override acts on the moves from here on: M48 and M50 turn
    /// it on, M49 and `M50 P0` off (the feed is then the programmed one, whatever the dial
    /// says), as do the tapping cycles G74/G84 around their feed in and out.
    FeedOverride(bool),
    /// Tool-centre-point control switched (G43.4 on, G49 off) or, under it, a new tool length.
    /// `at` is the current point in the coordinates of the new control (nothing moves here: the
    /// next move starts from `at`; a machine whose joints differ between the two readings of
    /// the point takes them up before that move).
    ToolControl { control: ToolControl, at: Pose },
    /// M0/M1/M60 pauses and M2/M30 program end.
    Stop(StopKind),
}

/// How the program axes reach the joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolControl {
    /// TCP off (G49, or no G43.4): program axes are joints. On machines whose rotary joints
    /// orient the tool, X Y Z A B C drive the joints of those names and moves are straight in
    /// joint space; Cartesian and delta machines keep X Y Z as the gauge point. `tool_length`
    /// is G43's offset in force (mm, 0 after G49), already added to the moves' Z: the joints
    /// do not need it, the tool tip read back from them does (forward kinematics).
    Joints { tool_length: f64 },
    /// TCP on (G43.4): X Y Z are the tool tip in the workpiece frame and A B C orient the tool;
    /// the joints follow, with the tip `tool_length` mm from the gauge point along the tool axis.
    CentrePoint { tool_length: f64 },
}

impl Default for ToolControl {
    /// TCP off with no tool length: the state before any G43 or G43.4.
    fn default() -> Self {
        ToolControl::OFF
    }
}

impl ToolControl {
    /// TCP off, no tool length in force.
    pub const OFF: ToolControl = ToolControl::Joints { tool_length: 0.0 };

    /// Whether TCP is off (program axes are joints), whatever the G43 length.
    pub fn is_joints(&self) -> bool {
        matches!(self, ToolControl::Joints { .. })
    }

    /// The tool length in force (mm): G43.4's under TCP, G43's with TCP off.
    pub fn tool_length(&self) -> f64 {
        match *self {
            ToolControl::Joints { tool_length } | ToolControl::CentrePoint { tool_length } => {
                tool_length
            }
        }
    }

    /// Whether the two read program points into the same joints: both TCP off (G43's length
    /// is already in the moves' Z, so it changes nothing), or both TCP on with one length.
    pub fn same_reading(&self, other: &ToolControl) -> bool {
        self.is_joints() && other.is_joints() || self == other
    }
}

/// Feed-rate interpretation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FeedMode {
    /// G93: F is the inverse of the move's duration in minutes.
    InverseTime,
    /// G94: F in length units per minute.
    #[default]
    UnitsPerMinute,
    /// G95: F in length units per spindle revolution.
    UnitsPerRevolution,
}

/// Path-control (tolerance) mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathMode {
    /// G61.1: stop exactly at the end of every block.
    ExactStop,
    /// G61: follow the programmed path exactly; corners are passed at zero speed.
    ExactPath,
    /// G64 [P tolerance]: blend within the tolerance (mm); `None` means "as fast as possible"
    /// (the machine file's tolerance applies). LinuxCNC's Q (naive-CAM collinearity) has no
    /// role here: compressing short moves is the path stage's job, under the same tolerance.
    Continuous { tolerance: Option<f64> },
}

impl Default for PathMode {
    /// LinuxCNC starts in G64 without P: blend as fast as possible.
    fn default() -> Self {
        PathMode::Continuous { tolerance: None }
    }
}

/// Program stops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopKind {
    /// M0.
    Pause,
    /// M1, honoured only when optional stop is on.
    OptionalPause,
    /// M60 pallet change pause.
    PalletPause,
    /// M2 or M30.
    End,
}

/// One move with the source line it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Move {
    pub line: u32,
    pub kind: MoveKind,
}
