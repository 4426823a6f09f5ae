//! `verify`: replays the samples after planning and measures what the machine would see — per
//! joint the peak velocity, acceleration and jerk by finite differences at the period, the
//! largest deviation of the tip (and of the chord between two samples) from the programmed
//! path ([`program`]) and from the smoothed path the planner followed ([`follow`]), the time
//! below the feed with no joint near a limit ([`slack`]), the cycle time, and the worst lines.
//! `check` is the pre-flight; this is the post-run.
//!
//! Finite differences: v = ∇q/Ts, a = ∇²q/Ts², j = ∇³q/Ts³ (backward); the machine is at rest
//! before the first and after the last sample, so both ends are padded with copies.

mod follow;
pub mod program;
pub mod slack;

use std::collections::HashMap;
use std::sync::Arc;

use tezgah_geom::deviation::point_segment_distance_squared;
use tezgah_geom::{ToolControl, Vec3};
use tezgah_kinematics::{Joints, Kinematics, Model, Tool};

use crate::interpolate::Sample;
use crate::path::{Junction, Segment, SegmentFeed};
use crate::plan::PlanMachine;

use follow::Follow;
use program::{Nearest, ProgramPath, TIE_DISTANCE_MM};
use slack::Slack;

/// Peaks of one joint (internal units: mm or rad).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointPeaks {
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
    pub max_velocity: f64,
    pub max_acceleration: f64,
    pub max_jerk: f64,
    /// Lines where each peak was reached.
    pub velocity_line: u32,
    pub acceleration_line: u32,
    pub jerk_line: u32,
}

impl JointPeaks {
    /// The largest of peak/limit over v, a, j.
    pub fn worst_ratio(&self) -> f64 {
        (self.velocity / self.max_velocity)
            .max(self.acceleration / self.max_acceleration)
            .max(self.jerk / self.max_jerk)
    }
}

/// What the replay found.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub samples: u64,
    /// Time of the last sample (the duration rounded up to the grid), s.
    pub cycle_time: f64,
    pub joints: Vec<JointPeaks>,
    /// Largest distance of a sample's tip, or of the midpoint of the chord between two
    /// samples, from the programmed path near it, or of a programmed vertex (a move's end)
    /// from the sampled path near it (mm; [`Verifier::against`]); without a program, from
    /// the smoothed path (as `max_deviation_smoothed`).
    pub max_deviation: f64,
    pub max_deviation_line: u32,
    /// The same from the smoothed path the planner followed (mm): the chord error alone.
    pub max_deviation_smoothed: f64,
    pub max_deviation_smoothed_line: u32,
    /// The largest of `max_deviation`'s distances over the tolerance in force at its sample
    /// (G64 P or the machine's): within tolerance when ≤ 1.
    pub deviation_ratio: f64,
    pub deviation_ratio_line: u32,
    /// Samples not measured against the program: on the take-up moves at a tool-control
    /// switch, which the program does not contain (they are measured against the smoothed
    /// path).
    pub unmeasured: u64,
    /// Time below the feed with no joint near a limit, and time at each fraction of the feed.
    pub slack: Slack,
    /// Lines by their worst joint peak/limit ratio, worst first (at most 5).
    pub worst_lines: Vec<(u32, f64)>,
}

/// The largest distance seen and where.
#[derive(Debug, Clone, Copy, Default)]
struct Peak {
    distance: f64,
    line: u32,
    ratio: f64,
    ratio_line: u32,
}

impl Peak {
    fn push(&mut self, d: f64, tolerance: f64, line: u32) {
        if d > self.distance {
            self.distance = d;
            self.line = line;
        }
        let r = d / tolerance;
        if r > self.ratio {
            self.ratio = r;
            self.ratio_line = line;
        }
    }
}

/// A programmed vertex the samples are passing: the nearest the sampled path (tips and the
/// chords between them) has come to it, with the tolerance and line of the sample there.
#[derive(Debug, Clone, Copy)]
struct Pending {
    point: Vec3,
    sigma: f64,
    distance: f64,
    tolerance: f64,
    line: u32,
}

/// Following the programmed path: the program, a cursor on it (arc length `sigma` and a
/// piece index), and the last sample measured. Both directions are measured: every sample
/// (and chord midpoint) to the program near it, and every programmed vertex to the sampled
/// path near it — a smoothing that cuts a corner or skips a feature shows in the second.
struct Against {
    program: ProgramPath,
    model: Model,
    hint: usize,
    sigma: f64,
    last_tip: Option<Vec3>,
    last_distance: f64,
    peak: Peak,
    unmeasured: u64,
    /// The next vertex to enter the window, and those in it.
    next_vertex: usize,
    pending: std::collections::VecDeque<Pending>,
}

impl Against {
    fn new(machine: &PlanMachine, program: ProgramPath) -> Self {
        Against {
            program,
            model: machine.model.clone(),
            hint: 0,
            sigma: 0.0,
            last_tip: None,
            last_distance: 0.0,
            peak: Peak::default(),
            unmeasured: 0,
            next_vertex: 0,
            pending: std::collections::VecDeque::new(),
        }
    }

    /// The vertices in `[lo, hi]` against the sample `tip` and the chord from `previous`;
    /// those left behind `lo` are done.
    fn vertices(
        &mut self,
        (lo, hi): (f64, f64),
        tip: &Vec3,
        previous: Option<&Vec3>,
        seg: &Segment,
        line: u32,
    ) {
        let vs = self.program.vertices();
        while self.next_vertex < vs.len() && vs[self.next_vertex].0 <= hi {
            let (sigma, point) = vs[self.next_vertex];
            self.pending.push_back(Pending {
                point,
                sigma,
                distance: f64::INFINITY,
                tolerance: seg.tolerance,
                line,
            });
            self.next_vertex += 1;
        }
        for v in self.pending.iter_mut() {
            let d2 = match previous {
                Some(p) => point_segment_distance_squared(&v.point, p, tip),
                None => (v.point - tip).norm_squared(),
            };
            // Most samples pass a vertex farther than they already came: the root only for
            // a square that may be nearer (a margin over the rounding of both).
            if d2 > v.distance * v.distance * (1.0 + 1e-9) {
                continue;
            }
            let d = d2.sqrt();
            if d < v.distance {
                v.distance = d;
                v.tolerance = seg.tolerance;
                v.line = line;
            }
        }
        while self.pending.front().is_some_and(|v| v.sigma < lo) {
            if let Some(v) = self.pending.pop_front() {
                self.peak.push(v.distance, v.tolerance, v.line);
            }
        }
    }

    /// A sample standing still off any segment (a dwell, the final row) under `control`:
    /// the vertices in the window are measured against it.
    fn rest(&mut self, s: &Sample, control: ToolControl) {
        if self.last_tip.is_none() {
            return;
        }
        let tip = self.tip(s, control);
        for v in self.pending.iter_mut() {
            let d = (v.point - tip).norm();
            if d < v.distance {
                v.distance = d;
                v.line = s.line;
            }
        }
    }

    /// Every vertex still in the window, at the end of the replay.
    fn finish(&mut self) {
        for v in self.pending.drain(..) {
            if v.distance.is_finite() {
                self.peak.push(v.distance, v.tolerance, v.line);
            }
        }
    }

    /// The tip to measure: under TCP the tool tip in the workpiece frame by forward
    /// kinematics of the sample's joints (what the machine holds, not what the interpolator
    /// aimed at); with TCP off the program point, which the program's X Y Z give there.
    fn tip(&self, s: &Sample, control: ToolControl) -> Vec3 {
        match control {
            ToolControl::CentrePoint { tool_length } => self
                .model
                .forward(&s.joints, &Tool::with_length(tool_length))
                .map_or(s.tip, |p| Vec3::new(p.tip.x, p.tip.y, p.tip.z)),
            ToolControl::Joints { .. } => s.tip,
        }
    }

    /// The chord's midpoint `mid` (and its expected `σ`) against the program over `window`
    /// (`hint` as the tip's search had it), or `None` where its distance cannot change the
    /// report: where the tip's move, or the one before it, already comes within `tip` (the
    /// sample's distance is the larger of the two) or within the peak so far, by more than
    /// the search's tie margin. The peak only grows, so the report is the full search's. A
    /// midpoint is nearly always that near: this saves most of a second search per sample.
    fn midpoint(
        &self,
        (mid, expected): (Vec3, f64),
        tip: f64,
        window: (f64, f64),
        hint: usize,
        seg: &Segment,
    ) -> Option<Nearest> {
        let settles = |i: usize| {
            self.program
                .piece_distance(i, &mid, window)
                .is_some_and(|c| {
                    // The search's answer is at most `c` plus its tie margin.
                    let c = c + 2.0 * TIE_DISTANCE_MM;
                    c <= tip || (c <= self.peak.distance && c / seg.tolerance <= self.peak.ratio)
                })
        };
        // The tip's move, or the one before it where the tip has just passed a vertex.
        let settled = settles(self.hint) || self.hint.checked_sub(1).is_some_and(settles);
        if settled {
            return None;
        }
        Some(
            self.program
                .nearest(&mid, window, expected, &mut hint.clone()),
        )
    }

    /// Measures the sample against the program between `σ − w` and `σ + w` around the
    /// cursor: `w` covers the step from the last sample and both samples' distances from the
    /// program (the nearest points are at most that far apart) twice over, and the tolerance.
    fn push(&mut self, s: &Sample, seg: &Segment, chord: bool) {
        let tip = self.tip(s, seg.control);
        let step = self.last_tip.map_or(0.0, |p| (tip - p).norm());
        let w = 2.0 * (step + self.last_distance + seg.tolerance);
        let (lo, hi) = (self.sigma - w, self.sigma + w);
        // With the moves around the cursor's whole: where the program runs ahead of the
        // samples (a feature the path leaves out) the cursor catches up at once.
        let (before, after) = self.program.around(self.hint);
        let (lo, hi) = (lo.min(before), hi.max(after));
        // The tip, then the chord's midpoint over the same window.
        let hint = self.hint;
        let n = self
            .program
            .nearest(&tip, (lo, hi), self.sigma + step, &mut self.hint);
        let m = match (chord, self.last_tip) {
            (true, Some(p)) => {
                let mid = (0.5 * (p + tip), self.sigma + 0.5 * step);
                self.midpoint(mid, n.distance, (lo, hi), hint, seg)
            }
            _ => None,
        };
        // A take-up at a tool-control switch (a rapid straight in joint space, TCP off, ending
        // at rest) runs between two readings of the program point and is not the program's:
        // such a sample off the program at the switch is not measured (one on it, a
        // programmed G0 after G49, is).
        let local = (self.sigma - w, self.sigma + w);
        let take_up = seg.control.is_joints()
            && matches!(seg.feed, SegmentFeed::Rapid)
            && matches!(seg.end, Junction::Stop)
            && self.program.switch_within(local.0, local.1)
            && self
                .program
                .nearest(&tip, local, self.sigma + step, &mut self.hint.clone())
                .distance
                .partial_cmp(&seg.tolerance)
                .is_none_or(|o| o == std::cmp::Ordering::Greater);
        if take_up {
            self.unmeasured += 1;
            self.last_tip = None;
            return;
        }
        let d = m.map_or(n.distance, |m: Nearest| n.distance.max(m.distance));
        if d.is_finite() {
            self.peak.push(d, seg.tolerance, s.line);
        }
        let previous = if chord { self.last_tip } else { None };
        self.vertices((lo, hi), &tip, previous.as_ref(), seg, s.line);
        self.sigma = n.sigma;
        self.last_tip = Some(tip);
        self.last_distance = if n.distance.is_finite() {
            n.distance
        } else {
            0.0
        };
    }
}

/// The streaming replay.
pub struct Verifier {
    period: f64,
    /// The last three samples' joints, a ring with the newest at `newest`.
    history: Option<[Joints; 3]>,
    newest: usize,
    peaks: Vec<JointPeaks>,
    samples: u64,
    /// The last sample's tip and line.
    last: Option<(Vec3, u32)>,
    /// The tool control of the last segment a sample lay on: a dwell's samples lie on none,
    /// and a switch may follow a dwell.
    last_control: Option<ToolControl>,
    cycle_time: f64,
    smoothed: Peak,
    follow: Follow,
    against: Option<Against>,
    slack: Slack,
    per_line: HashMap<u32, f64>,
    line_worst: Option<(u32, f64)>,
}

impl Verifier {
    /// A replay that measures the samples against the smoothed path only; see
    /// [`Verifier::against`].
    pub fn new(machine: &PlanMachine, period: f64) -> Self {
        let peaks = (0..machine.joint_count())
            .map(|i| JointPeaks {
                max_velocity: machine.max_velocity[i],
                max_acceleration: machine.max_acceleration[i],
                max_jerk: machine.max_jerk[i],
                ..JointPeaks::default()
            })
            .collect();
        Verifier {
            period,
            history: None,
            newest: 0,
            peaks,
            samples: 0,
            last: None,
            last_control: None,
            cycle_time: 0.0,
            smoothed: Peak::default(),
            follow: Follow::default(),
            against: None,
            slack: Slack::default(),
            per_line: HashMap::new(),
            line_worst: None,
        }
    }

    /// Measures the samples against `program` too (the moves the path was built from):
    /// the report's `max_deviation` is then the distance from the program.
    pub fn against(mut self, machine: &PlanMachine, program: ProgramPath) -> Self {
        self.against = Some(Against::new(machine, program));
        self
    }

    /// Takes the sample's finite differences; returns the worst peak/limit ratio over every
    /// joint and v, a, j, and the largest velocity ratio.
    fn differences(&mut self, q: &Joints, line: u32) -> (f64, f64) {
        // At rest before the first sample.
        let history = self.history.get_or_insert([*q; 3]);
        let n = self.newest;
        let (q1, q2, q3) = (
            history[n].as_slice(),
            history[(n + 2) % 3].as_slice(),
            history[(n + 1) % 3].as_slice(),
        );
        let q = q.as_slice();
        let ts = self.period;
        let mut worst: f64 = 0.0;
        let mut worst_v: f64 = 0.0;
        let (ts2, ts3) = (ts * ts, ts * ts * ts);
        let joints = q.iter().zip(q1).zip(q2).zip(q3);
        for (p, (((q, q1), q2), q3)) in self.peaks.iter_mut().zip(joints) {
            let v = (q - q1).abs() / ts;
            let a = (q - 2.0 * q1 + q2).abs() / ts2;
            let j = (q - 3.0 * q1 + 3.0 * q2 - q3).abs() / ts3;
            if v > p.velocity {
                p.velocity = v;
                p.velocity_line = line;
            }
            if a > p.acceleration {
                p.acceleration = a;
                p.acceleration_line = line;
            }
            if j > p.jerk {
                p.jerk = j;
                p.jerk_line = line;
            }
            worst_v = worst_v.max(v / p.max_velocity);
            worst = worst.max(a / p.max_acceleration).max(j / p.max_jerk);
        }
        worst = worst.max(worst_v);
        // The worst of the current line is kept aside and filed when the line changes.
        match &mut self.line_worst {
            Some((l, w)) if *l == line => *w = w.max(worst),
            other => {
                if let Some((l, w)) = other.take() {
                    let e = self.per_line.entry(l).or_insert(0.0);
                    *e = e.max(w);
                }
                *other = Some((line, worst));
            }
        }
        // The oldest slot takes the new sample.
        let oldest = (n + 1) % 3;
        history[oldest].as_mut_slice().copy_from_slice(q);
        self.newest = oldest;
        (worst, worst_v)
    }

    /// Takes one sample and the path it lies on: the segments passed since the previous
    /// sample, ending with the sample's own (empty while standing still).
    pub fn push(&mut self, s: &Sample, path: &[Arc<Segment>]) {
        let (worst, velocity) = self.differences(&s.joints, s.line);
        let seg = path.last();
        self.slack
            .push(self.period, seg.map(|g| &**g), s.feed, worst, velocity);
        if let (None, Some(a), Some(c)) = (seg, self.against.as_mut(), self.last_control) {
            a.rest(s, c);
        }
        if let Some(seg) = seg {
            // Across a tool-control switch (at rest) the tip is read two ways: no chord there.
            let same_reading = self
                .last_control
                .is_none_or(|c| c.same_reading(&seg.control));
            self.last_control = Some(seg.control);
            // The chord to the previous sample: its midpoint against the path between the two
            // samples — every segment passed, not only the two ends: at speed, short segments
            // and blends are entered and left within one period and the chord runs past them.
            let previous = self.last.map(|(tip, _)| tip);
            if let Some(d) = self
                .follow
                .push(&s.tip, previous.as_ref(), path, same_reading)
            {
                self.smoothed.push(d, seg.tolerance, s.line);
            }
            if let Some(a) = self.against.as_mut() {
                if !same_reading {
                    a.last_tip = None;
                }
                a.push(s, seg, same_reading);
            }
        }
        self.samples += 1;
        self.cycle_time = s.t;
        self.last = Some((s.tip, s.line));
    }

    /// Ends the replay (at rest after the last sample) and returns the report.
    pub fn finish(mut self) -> Report {
        if let (Some((_, line)), Some(h)) = (self.last.take(), self.history) {
            let q = h[self.newest];
            for _ in 0..3 {
                self.differences(&q, line);
            }
        }
        if let Some((l, w)) = self.line_worst.take() {
            let e = self.per_line.entry(l).or_insert(0.0);
            *e = e.max(w);
        }
        let mut worst: Vec<(u32, f64)> = self.per_line.into_iter().collect();
        worst.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        worst.truncate(5);
        if let Some(a) = self.against.as_mut() {
            a.finish();
        }
        let (main, unmeasured) = match &self.against {
            Some(a) => (a.peak, a.unmeasured),
            None => (self.smoothed, 0),
        };
        Report {
            samples: self.samples,
            cycle_time: self.cycle_time,
            joints: self.peaks,
            max_deviation: main.distance,
            max_deviation_line: main.line,
            max_deviation_smoothed: self.smoothed.distance,
            max_deviation_smoothed_line: self.smoothed.line,
            deviation_ratio: main.ratio,
            deviation_ratio_line: main.ratio_line,
            unmeasured,
            slack: self.slack,
            worst_lines: worst,
        }
    }
}
