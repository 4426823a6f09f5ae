//! Interpolation at the servo period: planned pieces in, one [`Sample`] every Ts out — time,
//! source line, tool tip (workpiece frame, mm), rotary axes and joints (through the machine's
//! inverse kinematics). Sits between the planner and the sinks (file, `verify`, executor).
//!
//! Sample k is at t = k·Ts exactly; a piece starts where the previous one ended (durations are
//! summed, never rounded to the grid, so time does not drift), and the final sample, at the
//! first grid time at or after the end, holds the final position. Dwells hold the position.

use std::sync::Arc;

use tezgah_geom::{ArcLengthCursor, ArcLengthMap, Curve, Vec3};
use tezgah_kinematics::{Joints, KinematicsError};

use crate::path::Segment;
use crate::plan::{PlanMachine, Planned};
use crate::takeup::TakeUp;

/// Why interpolation failed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum InterpolateError {
    #[error("line {line}: kinematics: {source}")]
    Kinematics { line: u32, source: KinematicsError },
}

/// One set-point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Sample index k; t = k·Ts.
    pub index: u64,
    pub t: f64,
    /// 1-based source line of the block being executed.
    pub line: u32,
    /// Tool tip, workpiece frame, mm.
    pub tip: Vec3,
    /// A B C, degrees.
    pub rotary: [f64; 3],
    /// Joints in internal units (mm, rad), machine-file order.
    pub joints: Joints,
    /// Path speed (mm/s, or deg/s on a rotary-only move).
    pub feed: f64,
}

/// s → u on one segment: identity for arc-length parametrised curves (lines), otherwise an
/// arc-length map built once per segment with a forward cursor on it (samples move forward, so
/// each one starts from the last: [`ArcLengthMap::advance`]).
pub(crate) struct Param {
    map: Option<(Inverse, ArcLengthCursor)>,
    scale: f64,
    /// The curve's domain (a virtual call per sample otherwise).
    domain: (f64, f64),
}

/// Where a segment's `s → u` map is.
enum Inverse {
    /// Built here, over the segment's curve.
    Own(ArcLengthMap),
    /// The one the path builder built over the whole curve the segment is a part of
    /// (`Curve::prebuilt_arc_length`), at this arc length of the segment's start: the
    /// smoother's map at its tolerance (1e-9 mm, at least as tight as the one built here),
    /// with points taken on the whole curve, a layer less per sample.
    Prebuilt { start: f64 },
}

impl Param {
    pub(crate) fn new(seg: &Segment) -> Param {
        let (a, b) = seg.curve.domain();
        if seg.rotary_only() || (a == 0.0 && b == seg.length) {
            return Param {
                map: None,
                scale: 1.0,
                domain: (a, b),
            };
        }
        // Constant parametric speed (lines, circular arcs and helices): u is proportional
        // to s, no map needed.
        let sp = |f: f64| seg.curve.speed(a + (b - a) * f);
        let s0 = sp(0.0);
        if [0.25, 0.5, 0.75, 1.0]
            .iter()
            .all(|&f| (sp(f) - s0).abs() <= 1e-12 * s0)
        {
            return Param {
                map: None,
                scale: (b - a) / seg.length,
                domain: (a, b),
            };
        }
        if let Some(pre) = seg.curve.prebuilt_arc_length() {
            return Param {
                map: Some((
                    Inverse::Prebuilt { start: pre.start },
                    pre.map.cursor_at(pre.start),
                )),
                scale: 1.0,
                domain: (a, b),
            };
        }
        match ArcLengthMap::new(&*seg.curve, 1e-9 * seg.length.max(1.0)) {
            Ok(m) => {
                let scale = m.length() / seg.length;
                let cursor = m.cursor();
                Param {
                    map: Some((Inverse::Own(m), cursor)),
                    scale,
                    domain: (a, b),
                }
            }
            // Fall back to a parameter proportional to length (exact for constant-speed arcs).
            Err(_) => Param {
                map: None,
                scale: (b - a) / seg.length,
                domain: (a, b),
            },
        }
    }

    /// The parameter and point at distance `s` along `seg`.
    pub(crate) fn at(&mut self, seg: &Segment, s: f64) -> (f64, Vec3) {
        match &mut self.map {
            Some((Inverse::Own(m), cursor)) => {
                let at = m.advance(&*seg.curve, cursor, s * self.scale);
                (at.u, at.point)
            }
            Some((Inverse::Prebuilt { start }, cursor)) => {
                match seg.curve.prebuilt_arc_length() {
                    Some(pre) => {
                        let at = pre.map.advance(pre.curve, cursor, *start + s);
                        (at.u, at.point)
                    }
                    // Not reached: the map came from this segment's curve.
                    None => {
                        let u = self.domain.0 + s * (self.domain.1 - self.domain.0) / seg.length;
                        (u, seg.curve.point(u))
                    }
                }
            }
            None => {
                let u = self.domain.0 + s * self.scale;
                (u, seg.curve.point(u))
            }
        }
    }
}

/// The tool at distance `s` along `seg` (mm, or degrees on a rotary-only segment; clamped):
/// tip, A B C (degrees) and joints nearest `previous`, through
/// [`PlanMachine::segment_joints`]. The block end is the curve's end point bit for bit. The one
/// pose lookup of the interpolator and the executor's re-timed cursor.
pub(crate) fn segment_pose(
    machine: &PlanMachine,
    seg: &Segment,
    param: &mut Param,
    s: f64,
    previous: &Joints,
) -> Result<(Vec3, [f64; 3], Joints), InterpolateError> {
    let len = seg.path_length();
    let s = s.clamp(0.0, len);
    let f = if len > 0.0 { s / len } else { 1.0 };
    let (tip, u) = if s >= len {
        // From the segment, not `param`: the piece's end is asked with the last segment's
        // param possibly not built yet.
        let (_, b) = seg.curve.domain();
        (seg.curve.point(b), b)
    } else {
        let (u, tip) = param.at(seg, s);
        (tip, u)
    };
    let (q, rotary) = machine
        .segment_joints(seg, u, f, &tip, previous)
        .map_err(|source| InterpolateError::Kinematics {
            line: seg.line,
            source,
        })?;
    Ok((tip, rotary, q))
}

/// The interpolator: feed it planned items, it calls the sink for every sample.
pub struct Interpolator {
    /// The machine: joints from the program point under each segment's tool control.
    machine: PlanMachine,
    period: f64,
    /// Next sample index.
    k: u64,
    /// Time at which the next item starts.
    t0: f64,
    last: Option<Sample>,
    joints: Joints,
    /// The segments the path has entered since the last sample, starting with that sample's
    /// own: at speed, short segments and blends can be entered and left within one period,
    /// and the chord between two samples then runs past them.
    passed: Vec<Arc<Segment>>,
}

impl Interpolator {
    /// `start` are the joints before the program (internal units), a guess for continuity.
    pub fn new(machine: &PlanMachine, period: f64, start: Joints) -> Self {
        Interpolator {
            machine: machine.clone(),
            period,
            k: 0,
            t0: 0.0,
            last: None,
            joints: start,
            passed: Vec::new(),
        }
    }

    /// Program time so far (unrounded), s.
    pub fn duration(&self) -> f64 {
        self.t0
    }

    fn pose(
        &mut self,
        seg: &Segment,
        param: &mut Param,
        s: f64,
    ) -> Result<(Vec3, [f64; 3], Joints), InterpolateError> {
        let pose = segment_pose(&self.machine, seg, param, s, &self.joints)?;
        self.joints = pose.2;
        Ok(pose)
    }

    /// Hands one sample to the sink with the path it lies on: the segments passed since the
    /// previous sample, ending with the sample's own (none while standing still).
    fn emit(&mut self, mut s: Sample, sink: &mut impl FnMut(&Sample, &[Arc<Segment>])) {
        s.index = self.k;
        s.t = self.k as f64 * self.period;
        sink(&s, &self.passed);
        // `last` is not updated here: a piece stores its exact end pose when it is done, and
        // dwells and the final row repeat it (a copy per sample was ~10 % of sampling lines).
        self.k += 1;
        // The next chord starts on this sample's segment.
        if self.passed.len() > 1 {
            self.passed.drain(..self.passed.len() - 1);
        }
    }

    /// Samples one planned item.
    pub fn push(
        &mut self,
        item: &Planned,
        sink: &mut impl FnMut(&Sample, &[Arc<Segment>]),
    ) -> Result<(), InterpolateError> {
        match item {
            Planned::Motion(piece) => {
                let duration = piece.profile.duration();
                let end = self.t0 + duration;
                let mut idx = 0;
                let mut param = Param::new(&piece.segments[0]);
                self.passed.push(piece.segments[0].clone());
                while (self.k as f64) * self.period < end {
                    let tau = (self.k as f64 * self.period - self.t0).max(0.0);
                    let st = piece.profile.state_at(tau);
                    let s = st.s.clamp(0.0, piece.length());
                    // Several segments may pass within one period: build the s → u map only
                    // for the one the sample lands on.
                    let before = idx;
                    while idx + 1 < piece.segments.len() && s > piece.offsets[idx + 1] {
                        idx += 1;
                        self.passed.push(piece.segments[idx].clone());
                    }
                    if idx != before {
                        param = Param::new(&piece.segments[idx]);
                    }
                    let seg = &piece.segments[idx];
                    let (tip, rotary, joints) =
                        self.pose(seg, &mut param, s - piece.offsets[idx])?;
                    let sample = Sample {
                        index: 0,
                        t: 0.0,
                        line: seg.line,
                        tip,
                        rotary,
                        joints,
                        feed: st.v,
                    };
                    self.emit(sample, sink);
                }
                // Segments after the last sample are passed before the next one.
                self.passed
                    .extend(piece.segments[idx + 1..].iter().cloned());
                // The piece's end, exactly (held for the final row and for dwells).
                let seg = piece.segments.last().expect("a piece has segments");
                let len = *piece.lengths.last().unwrap_or(&0.0);
                let (tip, rotary, joints) = self.pose(seg, &mut param, len)?;
                self.last = Some(Sample {
                    index: self.k,
                    t: end,
                    line: seg.line,
                    tip,
                    rotary,
                    joints,
                    feed: 0.0,
                });
                self.t0 = end;
            }
            Planned::Dwell { seconds, line } => {
                // Standing still: no chord.
                self.passed.clear();
                let end = self.t0 + seconds;
                while (self.k as f64) * self.period < end {
                    if let Some(mut s) = self.last {
                        s.line = *line;
                        s.feed = 0.0;
                        self.emit(s, sink);
                    } else {
                        break;
                    }
                }
                self.t0 = end;
            }
            Planned::Stop { .. } => {}
        }
        Ok(())
    }

    /// Emits the start row (before any motion), given the start pose under the machine's
    /// initial tool control.
    pub fn start(
        &mut self,
        tip: Vec3,
        rotary: [f64; 3],
        line: u32,
    ) -> Result<(), InterpolateError> {
        let q = self
            .machine
            .joints(self.machine.initial, &tip, &rotary, &self.joints)
            .map_err(|source| InterpolateError::Kinematics { line, source })?;
        self.joints = q;
        self.last = Some(Sample {
            index: 0,
            t: 0.0,
            line,
            tip,
            rotary,
            joints: q,
            feed: 0.0,
        });
        Ok(())
    }

    /// The final row: the final position at rest, at the first grid time at or after the end.
    pub fn finish(&mut self, sink: &mut impl FnMut(&Sample, &[Arc<Segment>])) {
        if let Some(mut s) = self.last {
            s.feed = 0.0;
            self.passed.clear();
            self.emit(s, sink);
        }
    }
}

/// Why a run (plan + interpolate) failed.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum RunError {
    #[error(transparent)]
    Plan(#[from] crate::plan::PlanError),
    #[error(transparent)]
    Interpolate(#[from] InterpolateError),
}

impl From<crate::takeup::TakeUpError> for RunError {
    fn from(e: crate::takeup::TakeUpError) -> Self {
        RunError::Interpolate(InterpolateError::Kinematics {
            line: e.line,
            source: e.source,
        })
    }
}

/// Plans and samples a stream of path items from the start pose (tip, A B C, under the
/// machine's initial tool control), calling `sink` for every sample; returns the unrounded
/// duration. Where the tool control switches and the joints of the current point differ
/// between the two readings, a take-up move ([`crate::takeup`]) is run first, from the joints
/// the interpolator reached. Memory stays
/// bounded by the planner's window: items are planned and sampled as they come.
pub fn run(
    items: impl IntoIterator<Item = crate::path::PathItem>,
    machine: PlanMachine,
    options: crate::plan::PlanOptions,
    start: (Vec3, [f64; 3]),
    mut sink: impl FnMut(&Sample, &[Arc<Segment>]),
) -> Result<f64, RunError> {
    let period = options.period;
    let mut interp = Interpolator::new(&machine, period, Joints::zeros(machine.joint_count()));
    interp.start(start.0, start.1, 1)?;
    let mut takeup = TakeUp::new(&machine, start, interp.joints);
    let mut planner = crate::plan::Planner::new(machine, options)?;
    for item in items {
        if takeup.switches(&item) {
            // The machine stops before a switch anyway: run everything up to it, so that the
            // take-up starts from the joints reached (an endless C following the tip may have
            // turned any number of times since the last switch).
            planner.finish()?;
            while let Some(p) = planner.pop() {
                interp.push(&p, &mut sink)?;
            }
        }
        if let Some(t) = takeup.before_from(&item, &interp.joints)? {
            planner.push(t)?;
        }
        planner.push(item)?;
        while let Some(p) = planner.pop() {
            interp.push(&p, &mut sink)?;
        }
    }
    planner.finish()?;
    while let Some(p) = planner.pop() {
        interp.push(&p, &mut sink)?;
    }
    interp.finish(&mut sink);
    Ok(interp.duration())
}
