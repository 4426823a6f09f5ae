//! The unit the feed planner times: one piece of the tool-tip path with its feed, the rotary
//! axes that move along it, and what happens at its end.
//!
//! This is the contract between path building (compression, corner blending) and feed
//! planning (look-ahead, interpolation): the builder emits [`PathItem`]s in program order, the
//! planner consumes them as a stream.

use tezgah_geom::{Curve, ToolControl, Vec3};

use crate::path::orient::AxisPath;

/// How fast a segment is to be run, before the machine's limits lower it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegmentFeed {
    /// G0: the machine's rapid speed (limited per joint by the machine file).
    Rapid,
    /// Programmed feed along the path, mm/s (tip speed; a segment that turns only rotary axes
    /// carries its rotary speed in deg/s here, see [`Segment::rotary_only`]).
    Feed(f64),
    /// G93: the segment takes this long, seconds (or longer if a limit forbids).
    InverseTime(f64),
}

impl SegmentFeed {
    /// The feed of a programmed (non-rapid) move: `value` is the F in force (mm/min, deg/min
    /// for rotary-only moves; 1/min under G93; mm/rev under G95, turned into mm/min by the
    /// spindle speed `rpm`, the spindle taken to run at its programmed speed). `None` when the
    /// numbers cannot time a move (F or, under G95, S not positive and finite).
    pub fn programmed(mode: tezgah_geom::FeedMode, value: f64, rpm: f64) -> Option<SegmentFeed> {
        use tezgah_geom::FeedMode;
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(value) {
            return None;
        }
        Some(match mode {
            FeedMode::UnitsPerMinute => SegmentFeed::Feed(value / 60.0),
            FeedMode::InverseTime => SegmentFeed::InverseTime(60.0 / value),
            FeedMode::UnitsPerRevolution if positive(rpm) => SegmentFeed::Feed(value * rpm / 60.0),
            FeedMode::UnitsPerRevolution => return None,
        })
    }
}

/// What joins a segment to the next one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Junction {
    /// Position, tangent and curvature continue (a blend or spline joint): no junction limit
    /// beyond the curvature limits of the two segments.
    Smooth,
    /// Position and tangent continue, curvature may jump (line into tangent arc).
    Tangent,
    /// A corner: the path turns. The planner must pass it at zero speed (G61 corners, or a
    /// corner the blender was not allowed to round).
    Corner,
    /// Exact stop at the end of this segment (G61.1, before a dwell, a pause or program end).
    Stop,
}

/// One piece of the tool-tip path.
pub struct Segment {
    /// The tool tip, mm, in the frame of the moves (work offsets and tool length applied).
    pub curve: Box<dyn Curve + Send + Sync>,
    /// Arc length of `curve`, mm.
    pub length: f64,
    /// A B C at the start and end of the segment, degrees; they move in proportion to the
    /// arc length travelled (or to time, for a segment with no tip motion).
    pub rotary: [[f64; 3]; 2],
    /// 1-based source line.
    pub line: u32,
    pub feed: SegmentFeed,
    /// What joins this segment to the next.
    pub end: Junction,
    /// The path tolerance in force (mm): chord error and smoothing stay within it.
    pub tolerance: f64,
    /// How the program axes reach the joints along this segment (TCP on or off).
    pub control: ToolControl,
    /// Whether the operator's feed override may re-time this segment (M48/M50); `false` runs
    /// it at the planned speed whatever the override (M49, `M50 P0`, tapping).
    pub feed_override: bool,
    /// Under tool-centre-point control, the angle (degrees) the tool axis turns through on a
    /// segment that only turns it, which times the segment (F is then degrees per minute of
    /// that rotation; docs/path-and-feed.md). Set by the planner, which knows the machine; `None`
    /// times a rotary-only segment by its largest axis travel.
    pub tool_axis_travel: Option<f64>,
    /// Under tool-centre-point control on a machine whose rotaries orient the tool, the tool
    /// axis along the segment (workpiece frame): the joints then follow tip + axis, and the
    /// rotary angles are read back from them. `None` runs `rotary` linearly (TCP off, or a
    /// machine whose rotaries do not orient the tool).
    pub axis: Option<AxisPath>,
}

impl Segment {
    /// Whether only rotary axes move (the tip stands still): such a segment is timed by its
    /// rotary travel, and `feed` is in deg/s.
    pub fn rotary_only(&self) -> bool {
        self.length <= f64::EPSILON
    }

    /// The coordinate the planner times the segment along: its length (mm), or for a
    /// rotary-only segment its rotary travel (degrees).
    pub fn path_length(&self) -> f64 {
        if self.rotary_only() {
            self.rotary_travel()
        } else {
            self.length
        }
    }

    /// The travel (degrees) that times a rotary-only segment: the tool axis's turn where the
    /// planner set it, else the largest rotary axis travel.
    pub fn rotary_travel(&self) -> f64 {
        self.tool_axis_travel.unwrap_or_else(|| self.axis_travel())
    }

    /// The largest rotary axis travel of the segment, degrees.
    pub fn axis_travel(&self) -> f64 {
        let [a, b] = self.rotary;
        (0..3).map(|i| (b[i] - a[i]).abs()).fold(0.0, f64::max)
    }

    /// Tip position at parameter `u` of the curve.
    pub fn point(&self, u: f64) -> Vec3 {
        self.curve.point(u)
    }
}

impl std::fmt::Debug for Segment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Segment")
            .field("length", &self.length)
            .field("rotary", &self.rotary)
            .field("line", &self.line)
            .field("feed", &self.feed)
            .field("end", &self.end)
            .field("tolerance", &self.tolerance)
            .field("control", &self.control)
            .field("axis", &self.axis)
            .finish_non_exhaustive()
    }
}

/// What the path stage emits, in program order.
// Nearly every item is a segment, so boxing it would cost an allocation per segment to save
// space only on the rare dwells and stops.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum PathItem {
    Segment(Segment),
    /// G4: stand still this long, seconds (the segment before ends with [`Junction::Stop`]).
    Dwell {
        seconds: f64,
        line: u32,
    },
    /// M0/M1/M60 or program end: the machine stands still.
    Stop {
        line: u32,
    },
}

impl PathItem {
    /// The source line the item carries, to renumber (a caller that keyed its moves' lines
    /// gives the built path its plain numbers back).
    pub fn line_mut(&mut self) -> &mut u32 {
        match self {
            PathItem::Segment(s) => &mut s.line,
            PathItem::Dwell { line, .. } | PathItem::Stop { line } => line,
        }
    }
}
