//! `verify`: replays the samples after planning and measures what the machine would see — per
//! joint the peak velocity, acceleration and jerk by finite differences at the period, the
//! largest deviation of the tip (and of the chord between two samples) from the programmed
//! path, the cycle time, and the worst lines. `check` is the pre-flight; this is the post-run.
//!
//! Finite differences: v = ∇q/Ts, a = ∇²q/Ts², j = ∇³q/Ts³ (backward); the machine is at rest
//! before the first and after the last sample, so both ends are padded with copies.

use std::collections::HashMap;
use std::sync::Arc;

use tezgah_geom::deviation::{closest_point, point_segment_distance};
use tezgah_geom::{Curve, ToolControl, Vec3};
use tezgah_kinematics::Joints;

use crate::interpolate::Sample;
use crate::path::Segment;
use crate::plan::PlanMachine;

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
    pub max_deviation: f64,
    pub max_deviation_line: u32,
    /// Lines by their worst joint peak/limit ratio, worst first (at most 5).
    pub worst_lines: Vec<(u32, f64)>,
}

/// The streaming replay.
pub struct Verifier {
    period: f64,
    history: Vec<Joints>,
    peaks: Vec<JointPeaks>,
    samples: u64,
    last: Option<(Sample, Option<Arc<Segment>>)>,
    /// The tool control of the last segment a sample lay on: a dwell's samples lie on none,
    /// and a switch may follow a dwell.
    last_control: Option<ToolControl>,
    cycle_time: f64,
    max_deviation: f64,
    max_deviation_line: u32,
    per_line: HashMap<u32, f64>,
}

/// Distance from `p` to the segment's curve.
pub fn distance_to(seg: &Segment, p: &Vec3) -> f64 {
    let (a, b) = seg.curve.domain();
    if seg.rotary_only() {
        return (seg.curve.point(a) - p).norm();
    }
    let [_, _, d2a, _] = seg.curve.derivs(a);
    if a == 0.0 && b == seg.length && d2a.norm() == 0.0 {
        return point_segment_distance(p, &seg.curve.point(a), &seg.curve.point(b));
    }
    closest_point(&*seg.curve, p, a, b, 64).distance
}

impl Verifier {
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
            history: Vec::with_capacity(4),
            peaks,
            samples: 0,
            last: None,
            last_control: None,
            cycle_time: 0.0,
            max_deviation: 0.0,
            max_deviation_line: 0,
            per_line: HashMap::new(),
        }
    }

    fn differences(&mut self, q: Joints, line: u32) {
        if self.history.is_empty() {
            // At rest before the first sample.
            self.history = vec![q; 3];
        }
        let h = &self.history;
        let n = h.len();
        let (q1, q2, q3) = (h[n - 1], h[n - 2], h[n - 3]);
        let ts = self.period;
        let mut worst: f64 = 0.0;
        for (i, p) in self.peaks.iter_mut().enumerate() {
            let v = (q[i] - q1[i]).abs() / ts;
            let a = (q[i] - 2.0 * q1[i] + q2[i]).abs() / (ts * ts);
            let j = (q[i] - 3.0 * q1[i] + 3.0 * q2[i] - q3[i]).abs() / (ts * ts * ts);
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
            worst = worst
                .max(v / p.max_velocity)
                .max(a / p.max_acceleration)
                .max(j / p.max_jerk);
        }
        let e = self.per_line.entry(line).or_insert(0.0);
        *e = e.max(worst);
        self.history.remove(0);
        self.history.push(q);
    }

    fn deviation(&mut self, d: f64, line: u32) {
        if d > self.max_deviation {
            self.max_deviation = d;
            self.max_deviation_line = line;
        }
    }

    /// Takes one sample and the path it lies on: the segments passed since the previous
    /// sample, ending with the sample's own (empty while standing still).
    pub fn push(&mut self, s: &Sample, path: &[Arc<Segment>]) {
        self.differences(s.joints, s.line);
        let seg = path.last();
        if let Some(seg) = seg {
            let d = distance_to(seg, &s.tip);
            self.deviation(d, s.line);
            // The chord to the previous sample: its midpoint against the path between the two
            // samples — every segment passed, not only the two ends: at speed, short segments
            // and blends are entered and left within one period and the chord runs past them.
            // Across a tool-control switch (at rest) the tip is read two ways: no chord there.
            let same_reading = self
                .last_control
                .is_none_or(|c| c.same_reading(&seg.control));
            self.last_control = Some(seg.control);
            if let (Some((p, pseg)), true) = (&self.last, same_reading) {
                let mid = 0.5 * (p.tip + s.tip);
                let mut dm = path
                    .iter()
                    .map(|g| distance_to(g, &mid))
                    .fold(f64::INFINITY, f64::min);
                if let Some(ps) = pseg {
                    if !path.iter().any(|g| Arc::ptr_eq(g, ps)) {
                        dm = dm.min(distance_to(ps, &mid));
                    }
                }
                self.deviation(dm, s.line);
            }
        }
        self.samples += 1;
        self.cycle_time = s.t;
        self.last = Some((*s, seg.cloned()));
    }

    /// Ends the replay (at rest after the last sample) and returns the report.
    pub fn finish(mut self) -> Report {
        if let Some((s, _)) = self.last.take() {
            for _ in 0..3 {
                self.differences(s.joints, s.line);
            }
        }
        let mut worst: Vec<(u32, f64)> = self.per_line.into_iter().collect();
        worst.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        worst.truncate(5);
        Report {
            samples: self.samples,
            cycle_time: self.cycle_time,
            joints: self.peaks,
            max_deviation: self.max_deviation,
            max_deviation_line: self.max_deviation_line,
            worst_lines: worst,
        }
    }
}
