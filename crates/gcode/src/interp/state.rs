//! The interpreter's modal state and the frames between program and machine coordinates.
//!
//! Positions are kept as LinuxCNC keeps them: in program coordinates and the current length
//! units. The machine position (without tool length) is `g5x + R(p + g92)` where R is the XY
//! rotation of the active coordinate system (LinuxCNC's `rotate_and_offset_pos`).

use tezgah_geom::{FeedMode, Plane, Pose};

use crate::canon::{ControlMode, SpindleDir, Units};

/// The modal state of a running program.
#[derive(Debug, Clone)]
pub struct State {
    /// Current point, program coordinates, current units (degrees for A B C).
    pub pos: Pose,
    pub units: Units,
    /// `None` while a U V W plane (G17.1 …) is selected.
    pub plane: Option<Plane>,
    pub incremental: bool,
    pub ijk_incremental: bool,
    pub feed_mode: FeedMode,
    pub feed_rate: f64,
    pub speed: f64,
    pub spindle: Option<SpindleDir>,
    /// Active motion mode (G code ×10), `None` after G80 or at start.
    pub motion: Option<u32>,
    pub control: ControlMode,
    /// Active coordinate system, 1 (G54) … 9 (G59.3).
    pub origin_index: usize,
    /// Its offsets and XY rotation (degrees).
    pub origin: Pose,
    pub rotation: f64,
    /// G92/G52 offsets in force.
    pub axis_offset: Pose,
    pub tool_offset: Pose,
    /// G43.4 in force: tool-centre-point control with `tool_offset`'s Z as the tool length.
    pub tool_centre_point: bool,
    /// Tool number chosen by the last T word (`None` before any).
    pub selected_tool: Option<i64>,
    /// Pocket index (table row) of the tool in the spindle: G10 writes to it reach the spindle.
    pub current_pocket: usize,
    /// LinuxCNC's table entry 0: the spindle's copy of its tool, made at M6 (machine units).
    /// G43 without H takes its offsets, G41/G42 without D its diameter.
    pub spindle_slot: crate::tooltable::Tool,
    pub mist: bool,
    pub flood: bool,
    /// The operator's switches the program may lock (M48–M53): feed and spindle-speed
    /// override, adaptive feed, feed hold.
    pub switches: Switches,
    pub lathe_diameter: bool,
    /// G99 (retract to the R plane, LinuxCNC's default) or G98 (to the height before).
    pub retract_r_plane: bool,
    /// Canned-cycle words in force.
    pub cycle: super::cycles::CycleMemory,
    /// Height along the plane's normal when the current series of cycles began.
    pub cycle_initial_level: Option<f64>,
    /// Tolerance of G64 Q (naive CAM detector), program units.
    pub naivecam_tolerance: f64,
    /// The last G64's P (LinuxCNC's `tolerance`), kept while G61 or G61.1 is in force.
    pub path_tolerance: f64,
}

impl Default for State {
    fn default() -> Self {
        State {
            pos: Pose::ZERO,
            units: Units::Millimeters,
            plane: Some(Plane::XY),
            incremental: false,
            ijk_incremental: true,
            feed_mode: FeedMode::UnitsPerMinute,
            feed_rate: 0.0,
            speed: 0.0,
            spindle: None,
            motion: None,
            control: ControlMode::Continuous(0.0),
            origin_index: 1,
            origin: Pose::ZERO,
            rotation: 0.0,
            axis_offset: Pose::ZERO,
            tool_offset: Pose::ZERO,
            tool_centre_point: false,
            selected_tool: None,
            current_pocket: 0,
            spindle_slot: Default::default(),
            mist: false,
            flood: false,
            switches: Switches::default(),
            lathe_diameter: false,
            retract_r_plane: true,
            cycle: Default::default(),
            cycle_initial_level: None,
            naivecam_tolerance: 0.0,
            path_tolerance: 0.0,
        }
    }
}

/// Which operator inputs the program lets act on the motion (M48–M53). At start, as in
/// LinuxCNC: both overrides and feed hold on, adaptive feed off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Switches {
    pub feed_override: bool,
    pub speed_override: bool,
    pub adaptive_feed: bool,
    pub feed_hold: bool,
}

impl Default for Switches {
    fn default() -> Self {
        Switches {
            feed_override: true,
            speed_override: true,
            adaptive_feed: false,
            feed_hold: true,
        }
    }
}

/// Rotate the XY part of `p` by `deg` degrees about the origin.
pub fn rotate_xy(p: Pose, deg: f64) -> Pose {
    if deg == 0.0 {
        return p;
    }
    let (s, c) = deg.to_radians().sin_cos();
    let mut q = p;
    q.0[0] = p.0[0] * c - p.0[1] * s;
    q.0[1] = p.0[0] * s + p.0[1] * c;
    q
}

impl State {
    /// Machine position (without tool length) of program point `p`.
    pub fn to_machine(&self, p: Pose) -> Pose {
        self.origin + rotate_xy(p + self.axis_offset, self.rotation)
    }

    /// Program point of machine position `m` (without tool length).
    pub fn from_machine(&self, m: Pose) -> Pose {
        rotate_xy(m - self.origin, -self.rotation) - self.axis_offset
    }

    /// The current point in the frame of another coordinate system (origin and rotation),
    /// with the G92 offsets in force (LinuxCNC's `find_current_in_system`).
    pub fn current_in(&self, origin: Pose, rotation: f64) -> Pose {
        rotate_xy(self.to_machine(self.pos) - origin, -rotation) - self.axis_offset
    }

    /// The current point after the active system's origin and rotation change in place (G10
    /// on the active system, M2). LinuxCNC re-expresses it as `R(−r')(R(r)·p + o − o')`,
    /// which leaves the G92 offsets out of the rotation, unlike `current_in`; the two agree
    /// unless a rotation changes while G92 offsets are in force. tezgah keeps LinuxCNC's
    /// arithmetic so that the same program ends at the same place.
    pub fn reframed(&self, origin: Pose, rotation: f64) -> Pose {
        rotate_xy(
            rotate_xy(self.pos, self.rotation) + self.origin - origin,
            -rotation,
        )
    }

    pub fn inches(&self) -> bool {
        self.units == Units::Inches
    }
}
