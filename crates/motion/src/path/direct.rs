//! The direct path builder: moves → [`PathItem`]s without smoothing (the G61 reference).
//!
//! G0/G1 become [`Line`]s, G2/G3 helices, each with its feed; the junction kind comes from the
//! angle between the end and start tangents. The smoothing builder (`path::smooth`) replaces
//! this for G64; tests and `tezgah run` use it as the exact-path reference.

use tezgah_geom::{
    Arc, Curve, FeedMode, Line, Move, MoveKind, PathMode, Pose, StopKind, ToolControl, Vec3,
};

use super::segment::{Junction, PathItem, Segment, SegmentFeed};

/// Why a move could not become a segment.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum DirectError {
    #[error("line {line}: feed move with no feed rate (F0 or no F)")]
    NoFeed { line: u32 },
    #[error("line {line}: feed per revolution (G95) with no spindle speed (S)")]
    FeedPerRevolution { line: u32 },
    #[error("line {line}: bad arc: {reason}")]
    BadArc { line: u32, reason: String },
    #[error("line {line}: dwell of {seconds} s is not a finite, non-negative time")]
    BadDwell { line: u32, seconds: f64 },
    #[error("line {line}: position is not finite")]
    NotFinite { line: u32 },
    #[error("line {line}: G33/G33.1 follow the spindle; only `tezgah run` simulates that")]
    Synced { line: u32 },
}

/// Thresholds of the direct builder (explicit, never buried literals).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectOptions {
    /// Path tolerance (mm) when the program gives no `G64 P` (the machine's `tolerance_mm`).
    pub tolerance: f64,
    /// G61: junctions whose tangents differ by less than this (rad) are [`Junction::Tangent`].
    pub exact_tangent_angle: f64,
    /// G64: the same threshold; larger, since the planner still bounds the velocity step at a
    /// kink by the jerk budget (plan::junction), so a small kink costs speed, not accuracy.
    pub continuous_tangent_angle: f64,
    /// Tool control before the program switches it (the machine file's `tcp`).
    pub control: ToolControl,
}

impl Default for DirectOptions {
    fn default() -> Self {
        DirectOptions {
            tolerance: 0.01,
            exact_tangent_angle: 1e-6,
            continuous_tangent_angle: 0.05,
            control: ToolControl::OFF,
        }
    }
}

/// Streams moves into path items; one segment is held back until the next move decides its
/// junction.
#[derive(Debug)]
pub struct Direct {
    options: DirectOptions,
    position: Pose,
    feed_rate: f64,
    feed_mode: FeedMode,
    /// Programmed spindle speed (rev/min), for G95.
    spindle_rpm: f64,
    path_mode: PathMode,
    pending: Option<Segment>,
    control: ToolControl,
    /// M48/M50 on, M49/`M50 P0` off.
    feed_override: bool,
}

fn end_tangent(seg: &Segment) -> Option<Vec3> {
    if seg.rotary_only() {
        return None;
    }
    let (_, b) = seg.curve.domain();
    let d = seg.curve.d1(b);
    let n = d.norm();
    (n > 0.0).then(|| d / n)
}

fn start_tangent(seg: &Segment) -> Option<Vec3> {
    if seg.rotary_only() {
        return None;
    }
    let (a, _) = seg.curve.domain();
    let d = seg.curve.d1(a);
    let n = d.norm();
    (n > 0.0).then(|| d / n)
}

impl Direct {
    /// Starts at `start` (machine position before the program), G94, G64 (LinuxCNC's defaults).
    pub fn new(start: Pose, options: DirectOptions) -> Self {
        Direct {
            options,
            position: start,
            feed_rate: 0.0,
            feed_mode: FeedMode::UnitsPerMinute,
            spindle_rpm: 0.0,
            path_mode: PathMode::default(),
            pending: None,
            control: options.control,
            feed_override: true,
        }
    }

    /// The position after the moves pushed so far.
    pub fn position(&self) -> Pose {
        self.position
    }

    fn tolerance(&self) -> f64 {
        match self.path_mode {
            PathMode::Continuous { tolerance: Some(p) } if p > 0.0 => p,
            _ => self.options.tolerance,
        }
    }

    fn tangent_angle(&self) -> f64 {
        match self.path_mode {
            PathMode::Continuous { .. } => self.options.continuous_tangent_angle,
            _ => self.options.exact_tangent_angle,
        }
    }

    /// Ends the held segment with `end` and hands it out.
    fn flush(&mut self, end: Junction, out: &mut Vec<PathItem>) {
        if let Some(mut seg) = self.pending.take() {
            seg.end = end;
            out.push(PathItem::Segment(seg));
        }
    }

    fn feed(&self, line: u32, rapid: bool) -> Result<SegmentFeed, DirectError> {
        if rapid {
            return Ok(SegmentFeed::Rapid);
        }
        SegmentFeed::programmed(self.feed_mode, self.feed_rate, self.spindle_rpm).ok_or(
            if self.feed_mode == FeedMode::UnitsPerRevolution && self.feed_rate > 0.0 {
                DirectError::FeedPerRevolution { line }
            } else {
                DirectError::NoFeed { line }
            },
        )
    }

    /// Takes one move; finished items are appended to `out`.
    pub fn push(&mut self, m: &Move, out: &mut Vec<PathItem>) -> Result<(), DirectError> {
        let line = m.line;
        let (curve, end, rapid): (Box<dyn Curve + Send + Sync>, Pose, bool) = match &m.kind {
            &MoveKind::FeedRate { value } => {
                self.feed_rate = value;
                return Ok(());
            }
            &MoveKind::FeedMode(mode) => {
                self.feed_mode = mode;
                return Ok(());
            }
            &MoveKind::SpindleSpeed { rpm } => {
                self.spindle_rpm = rpm;
                return Ok(());
            }
            &MoveKind::PathMode(mode) => {
                self.path_mode = mode;
                return Ok(());
            }
            // The direct builder never compresses: G05.1 changes nothing here.
            MoveKind::Smoothing(_) => return Ok(()),
            // The planner never groups across the switch: the machine stops there.
            &MoveKind::FeedOverride(on) => {
                if on != self.feed_override {
                    self.flush(Junction::Stop, out);
                    self.feed_override = on;
                }
                return Ok(());
            }
            // TCP switched: stop; the next move starts from the same point read the new way.
            &MoveKind::ToolControl { control, at } => {
                if !at.0.iter().all(|v| v.is_finite()) {
                    return Err(DirectError::NotFinite { line });
                }
                self.flush(Junction::Stop, out);
                self.control = control;
                self.position = at;
                return Ok(());
            }
            &MoveKind::Dwell { seconds } => {
                if !(seconds.is_finite() && seconds >= 0.0) {
                    return Err(DirectError::BadDwell { line, seconds });
                }
                self.flush(Junction::Stop, out);
                out.push(PathItem::Dwell { seconds, line });
                return Ok(());
            }
            MoveKind::Synced(_) => return Err(DirectError::Synced { line }),
            &MoveKind::Stop(kind) => {
                // M1 is honoured only with optional stop on, which `run` does not set.
                if kind != StopKind::OptionalPause {
                    self.flush(Junction::Stop, out);
                    out.push(PathItem::Stop { line });
                }
                return Ok(());
            }
            &MoveKind::Rapid { end } | &MoveKind::Feed { end } => {
                let a = Vec3::from(self.position.xyz());
                let b = Vec3::from(end.xyz());
                let l = Line::new(a, b).map_err(|_| DirectError::NotFinite { line })?;
                (Box::new(l), end, matches!(m.kind, MoveKind::Rapid { .. }))
            }
            MoveKind::Arc(arc) => {
                let c = Arc::from_move(&self.position, arc).map_err(|e| DirectError::BadArc {
                    line,
                    reason: e.to_string(),
                })?;
                (Box::new(c), arc.end, false)
            }
            // One curve segment, never split: a corner or tangent junction at each end as for
            // an arc.
            MoveKind::Nurbs(n) => (Box::new((*n.curve).clone()), n.end, false),
        };
        if !end.0.iter().all(|v| v.is_finite()) {
            return Err(DirectError::NotFinite { line });
        }
        let start = self.position;
        let length = curve.length();
        let rotary = [
            [start.0[3], start.0[4], start.0[5]],
            [end.0[3], end.0[4], end.0[5]],
        ];
        let seg = Segment {
            curve,
            length: if length.is_finite() { length } else { 0.0 },
            rotary,
            line,
            feed: self.feed(line, rapid)?,
            end: Junction::Stop,
            tolerance: self.tolerance(),
            control: self.control,
            feed_override: self.feed_override,
            tool_axis_travel: None,
            axis: None,
        };
        if seg.rotary_only() && seg.rotary_travel() <= 0.0 {
            // Nothing moves: a repeated point.
            return Ok(());
        }
        self.position = end;
        let junction = match (&self.pending, self.path_mode) {
            (None, _) => Junction::Stop,
            (Some(_), PathMode::ExactStop) => Junction::Stop,
            (Some(prev), _) => match (end_tangent(prev), start_tangent(&seg)) {
                (Some(t0), Some(t1)) => {
                    let angle = t0.dot(&t1).clamp(-1.0, 1.0).acos();
                    if angle < self.tangent_angle() {
                        Junction::Tangent
                    } else {
                        Junction::Corner
                    }
                }
                // Into or out of a rotary-only move: stop (the tip stands still there).
                _ => Junction::Stop,
            },
        };
        self.flush(junction, out);
        // G61.1 stops at the end of every block.
        let mut seg = seg;
        if self.path_mode == PathMode::ExactStop {
            seg.end = Junction::Stop;
            out.push(PathItem::Segment(seg));
        } else {
            self.pending = Some(seg);
        }
        Ok(())
    }

    /// Program end: the held segment ends with a stop.
    pub fn finish(&mut self, out: &mut Vec<PathItem>) {
        self.flush(Junction::Stop, out);
    }
}

/// All moves of a program to path items, starting from `start`.
pub fn build(
    moves: &[Move],
    start: Pose,
    options: DirectOptions,
) -> Result<Vec<PathItem>, DirectError> {
    let mut d = Direct::new(start, options);
    let mut out = Vec::with_capacity(moves.len());
    for m in moves {
        d.push(m, &mut out)?;
    }
    d.finish(&mut out);
    Ok(out)
}
