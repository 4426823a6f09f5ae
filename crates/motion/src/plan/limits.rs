//! Speed limits of one segment and of the junction between two: from the programmed feed, the
//! rapid speed, curvature (centripetal acceleration and jerk), chord error at the period, and
//! every joint's velocity, acceleration and jerk limit.
//!
//! A joint q(σ) along the path coordinate σ (arc length, or degrees for a rotary-only move) at
//! path speed v, acceleration a, jerk j moves with
//!   q̇ = q'v,  q̈ = q''v² + q'a,  q⃛ = q'''v³ + 3q''va + q'j            (chain rule)
//! so the profile limits (V, A, J) chosen below keep every joint inside its limits at every
//! point of the segment ([`Geometry::cells`]); this is Kelekçi's (2021, §3.3.1) v ≤ √(A/κ),
//! v ≤ (J/κ²)^⅓ per joint for the speed, with no fixed share of a joint's budget set aside for
//! one term: the split between speed, path acceleration and jerk is chosen per segment (see
//! [`segment_limits`]).

use tezgah_geom::{ArcLengthMap, Curve, Vec3};
use tezgah_kinematics::Joints;

use super::joints::{JointMap, PlanMachine};
use super::PlanError;
use crate::path::{Segment, SegmentFeed};
use crate::profile::Limits;

/// Most joints a machine has (as `tezgah_kinematics::Joints`).
pub const MAX_JOINTS: usize = 6;

/// Planner settings; every tolerance is explicit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanOptions {
    /// Interpolation period Ts, s.
    pub period: f64,
    /// Share of a segment's tolerance given to the chord error at the period (the rest is for
    /// smoothing); the chord limit is v ≤ (2/Ts)·√(2ρδ − δ²) with δ = share·tolerance. By
    /// default what the smoother leaves ([`crate::path::smooth::CHORD_SHARE`]), so that the
    /// two never add up to more than the tolerance.
    pub chord_share: f64,
    /// Share of each joint's acceleration and jerk kept back on segments next to a junction
    /// where the tangent or curvature jumps; the jump is then bounded by that share as seen by
    /// finite differences at the period (Δv/Ts² + Δa/Ts for the jerk).
    pub junction_reserve: f64,
    /// A junction whose cap is below this share of the slower neighbour's speed limit is
    /// passed at rest instead (cheaper than keeping the reserve on both sides).
    pub min_junction_share: f64,
    /// Groups of segments held in the look-ahead window.
    pub window: usize,
    /// Most segments timed by one profile.
    pub max_group: usize,
    /// Segments join one group only while their speed limits are within this ratio (0–1].
    pub group_ratio: f64,
    /// Rotary-only moves on a machine where no joint follows them (a 3-axis mill given A/B/C):
    /// rapid speed in deg/s, and A, J in deg/s², deg/s³ for timing them.
    pub idle_rotary: [f64; 3],
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            period: 0.001,
            chord_share: crate::path::smooth::CHORD_SHARE,
            junction_reserve: 0.25,
            min_junction_share: 0.05,
            window: 64,
            max_group: 256,
            group_ratio: 0.8,
            idle_rotary: [3600.0, 36_000.0, 360_000.0],
        }
    }
}

impl PlanOptions {
    /// The share of each joint's acceleration and jerk a segment may use: all of it, or what
    /// the junction reserve leaves where one is `kept`.
    pub fn budget(&self, kept: bool) -> f64 {
        if kept {
            1.0 - self.junction_reserve
        } else {
            1.0
        }
    }

    /// Checks every option; the error names the bad one.
    pub fn validate(&self) -> Result<(), PlanError> {
        let unit = |name, v: f64, open_low: bool| {
            let ok = if open_low {
                v > 0.0 && v <= 1.0
            } else {
                (0.0..1.0).contains(&v)
            };
            if ok {
                Ok(())
            } else {
                Err(PlanError::Option { name, value: v })
            }
        };
        if !(self.period > 0.0 && self.period.is_finite()) {
            return Err(PlanError::Option {
                name: "period",
                value: self.period,
            });
        }
        unit("chord_share", self.chord_share, true)?;
        unit("junction_reserve", self.junction_reserve, false)?;
        unit("group_ratio", self.group_ratio, true)?;
        unit("min_junction_share", self.min_junction_share, false)?;
        if self.window == 0 || self.max_group == 0 {
            return Err(PlanError::Option {
                name: "window/max_group",
                value: 0.0,
            });
        }
        Ok(())
    }
}

/// The joints' derivatives along one segment (internal units per unit of σ).
#[derive(Debug, Clone, Copy, Default)]
pub struct Geometry {
    /// Path coordinate length: arc length (mm), or rotary travel (deg) for a rotary-only move.
    pub length: f64,
    pub rotary_only: bool,
    /// Largest |q'|, |q''|, |q'''| per joint over the segment.
    pub g1: [f64; MAX_JOINTS],
    pub g2: [f64; MAX_JOINTS],
    pub g3: [f64; MAX_JOINTS],
    /// q' and q'' per joint at the start and at the end.
    pub d1_start: [f64; MAX_JOINTS],
    pub d1_end: [f64; MAX_JOINTS],
    pub d2_start: [f64; MAX_JOINTS],
    pub d2_end: [f64; MAX_JOINTS],
    /// Largest curvature of the tip path, 1/mm.
    pub kappa_max: f64,
    /// The same maxima in each of [`CELLS`] equal stretches of the segment's parameter:
    /// `cells[c][i]` = (|q'|, |q''|, |q'''|) of joint i over stretch c (and one sample spacing
    /// either side). The joint limits are then met point by point along the segment, not by
    /// the worst of each derivative taken at different places (see [`segment_limits`]).
    pub cells: Cells,
}

/// Per stretch of a segment and per joint, the largest (|q'|, |q''|, |q'''|).
pub type Cells = [[[f64; 3]; MAX_JOINTS]; CELLS];

/// Stretches a segment's derivative maxima are kept in ([`Geometry::cells`]).
pub const CELLS: usize = 16;

/// Raises the (|q'|, |q''|, |q'''|) maxima of joint `i` in the cells a sample at `f` ∈ [0, 1]
/// along the segment bounds: its own and those within `df` (one sample spacing), since between
/// two samples a derivative is bounded by theirs with a margin, on either side.
fn raise(cells: &mut Cells, i: usize, f: f64, df: f64, d: [f64; 3]) {
    raise_in(cells, reach(f, df), i, d);
}

/// The cells a sample at `f` ∈ [0, 1] bounds, with `df` either side ([`raise`]).
fn reach(f: f64, df: f64) -> std::ops::RangeInclusive<usize> {
    let cell = |x: f64| ((x * CELLS as f64).floor().max(0.0) as usize).min(CELLS - 1);
    cell(f - df)..=cell(f + df)
}

/// [`raise`] over the cells `range` (found once for a sample's three axes).
fn raise_in(cells: &mut Cells, range: std::ops::RangeInclusive<usize>, i: usize, d: [f64; 3]) {
    for cell in &mut cells[range] {
        for (m, x) in cell[i].iter_mut().zip(d) {
            *m = m.max(x);
        }
    }
}

impl Geometry {
    pub fn curved(&self) -> bool {
        self.g2.iter().any(|&g| g > 0.0)
    }
}

/// The tip's derivatives by arc length at `u`: unit tangent q_s, curvature vector q_ss and its
/// rate q_sss, by the chain rule with s_u = |C'|, s_uu = C'·C''/s_u,
/// s_uuu = (|C''|² + C'·C''' − s_uu²)/s_u:
///   q_s = C'/s_u,  q_ss = (C'' − q_s·s_uu)/s_u²,  q_sss = (C''' − 3q_ss·s_u·s_uu − q_s·s_uuu)/s_u³.
/// Exact at the point, whatever the parametrisation (blends and splines are not u ∝ s).
fn frame(curve: &dyn Curve, u: f64) -> [Vec3; 3] {
    frame_and_speed(curve, u).0
}

/// [`frame`] and the parametric speed s_u = |C'| at `u` (one evaluation of the curve).
fn frame_and_speed(curve: &dyn Curve, u: f64) -> ([Vec3; 3], f64) {
    let [_, c1, c2, c3] = curve.derivs(u);
    let su = c1.norm();
    if su <= 0.0 {
        return ([Vec3::zeros(); 3], 0.0);
    }
    let suu = c1.dot(&c2) / su;
    let suuu = (c2.dot(&c2) + c1.dot(&c3) - suu * suu) / su;
    let q1 = c1 / su;
    let q2 = (c2 - q1 * suu) / (su * su);
    let q3 = (c3 - q2 * (3.0 * su * suu) - q1 * suuu) / (su * su * su);
    ([q1, q2, q3], su)
}

/// Samples the tip path (tangent, curvature vector and its rate, exact at each sample, see
/// [`frame`]) and maps it onto the joints.
pub fn analyse(seg: &Segment, machine: &PlanMachine) -> Result<Geometry, PlanError> {
    machine.check_axes(seg)?;
    let n = machine.joint_count().min(MAX_JOINTS);
    let rotary_only = seg.rotary_only();
    let length = seg.path_length();
    let mut g = Geometry {
        length,
        rotary_only,
        ..Geometry::default()
    };
    if length <= 0.0 {
        return Ok(g);
    }
    let rot_rate = |k: usize| (seg.rotary[1][k] - seg.rotary[0][k]).to_radians() / length;
    // Tip samples.
    let (ua, ub) = seg.curve.domain();
    let mut tip_d1_start = Vec3::zeros();
    let mut tip_d1_end = Vec3::zeros();
    let mut tip_d2_start = Vec3::zeros();
    let mut tip_d2_end = Vec3::zeros();
    let mut g1 = [0.0f64; 3];
    let mut g2 = [0.0f64; 3];
    let mut g3 = [0.0f64; 3];
    let mut tip_cells: Cells = Default::default();
    if !rotary_only {
        let curve: &dyn Curve = &*seg.curve;
        let [t0, k0, _] = frame(curve, ua);
        let [t1, k1, _] = frame(curve, ub);
        let [tm, km, _] = frame(curve, 0.5 * (ua + ub));
        tip_d1_start = t0;
        tip_d1_end = t1;
        tip_d2_start = k0;
        tip_d2_end = k1;
        let straight = k0.norm() == 0.0 && k1.norm() == 0.0 && km.norm() == 0.0;
        if straight {
            for i in 0..3 {
                g1[i] = t0[i].abs().max(t1[i].abs()).max(tm[i].abs());
                for cell in tip_cells.iter_mut() {
                    cell[i][0] = g1[i];
                }
            }
        } else {
            // Enough samples that the turning between two is small (≤ ~0.1 rad on arcs):
            // a sampled sinusoid then misses its peak by < 0.1 % (|q'| by ~(0.1)²/8 = 0.13 %);
            // the 1.005 and 1.05 below cover it and the change between samples.
            // The turning is estimated on a first coarse pass too: a curvature spike away
            // from the ends and the middle (a tight bend inside a spline) needs the samples.
            // (Lines, arcs and helices turn evenly: the ends and the middle tell it.)
            const COARSE: usize = 16;
            let dc = (ub - ua) / COARSE as f64;
            let constant = constant_speed(curve);
            let coarse: f64 = if constant {
                0.0
            } else {
                (0..COARSE)
                    .map(|c| {
                        let u = ua + dc * (c as f64 + 0.5);
                        let ([_, k, _], su) = frame_and_speed(curve, u);
                        k.norm() * su * dc
                    })
                    .sum()
            };
            let turning = (k0.norm().max(k1.norm()).max(km.norm()) * seg.length).max(coarse);
            // The margins cover more than sampling: on an arc at its curvature limit an
            // underrun stop brakes along the curve with the acceleration the plan kept, and a
            // 0.2 % margin there (enough for the sampling alone on arcs) let such a stop
            // overdraw a joint by 0.9 % (executor's `rt` test, seed 940400): kept at 5 %.
            let (margin, vertex_margin) = ([1.005, 1.05, 1.05], [1.01, 1.06, 1.06]);
            let samples = ((turning / 0.1).ceil() as usize).clamp(32, 4096);
            let du = (ub - ua) / samples as f64;
            // Per axis, the sample where |q''| and where |q'''| peak: the peak between samples
            // is looked for around it, on a finer grid (a narrow curvature spike of a spline
            // or blend can fall between coarse samples).
            let mut peaks = [[0usize; 3]; 2];
            let mut best = [[0.0f64; 3]; 2];
            let df = 1.0 / samples as f64;
            let take = |u: f64,
                        g1: &mut [f64; 3],
                        g2: &mut [f64; 3],
                        g3: &mut [f64; 3],
                        cells: &mut Cells| {
                let ([t, k, dk], su) = frame_and_speed(curve, u);
                let f = (u - ua) / (ub - ua);
                // Half a sample spacing in arc length: between samples a derivative strays
                // from its sampled value by at most that times the next derivative (the
                // whole segment's maxima have the peak refinement below; a cell does not).
                let h = 0.5 * su * du;
                let range = reach(f, df);
                for i in 0..3 {
                    let d = [
                        t[i].abs() * margin[0],
                        k[i].abs() * margin[1],
                        dk[i].abs() * margin[2],
                    ];
                    g1[i] = g1[i].max(d[0]);
                    g2[i] = g2[i].max(d[1]);
                    g3[i] = g3[i].max(d[2]);
                    let local = [
                        (t[i].abs() + h * k[i].abs()) * margin[0],
                        (k[i].abs() + h * dk[i].abs()) * margin[1],
                        d[2],
                    ];
                    raise_in(cells, range.clone(), i, local);
                }
                (t, k, dk)
            };
            // |q'|, |q''|, |q'''| per axis at every sample, for the peaks between them.
            let mut rows: Vec<[[f64; 3]; 3]> = Vec::with_capacity(samples + 1);
            for s in 0..=samples {
                let (t, k, dk) = take(
                    ua + du * s as f64,
                    &mut g1,
                    &mut g2,
                    &mut g3,
                    &mut tip_cells,
                );
                rows.push([0, 1, 2].map(|i| [t[i].abs(), k[i].abs(), dk[i].abs()]));
                g.kappa_max = g.kappa_max.max(k.norm());
                for i in 0..3 {
                    for (d, x) in [k[i].abs(), dk[i].abs()].into_iter().enumerate() {
                        if x > best[d][i] {
                            best[d][i] = x;
                            peaks[d][i] = s;
                        }
                    }
                }
            }
            // A cell's peak between two samples: the vertex of the parabola through a local
            // maximum and its neighbours (the whole segment's peak is refined below too).
            for s in 1..samples {
                let (before, here, after) = (&rows[s - 1], &rows[s], &rows[s + 1]);
                let range = reach(s as f64 * df, df);
                for i in 0..3 {
                    let mut d = [0.0; 3];
                    for (o, x) in d.iter_mut().enumerate() {
                        let (a, b, c) = (before[i][o], here[i][o], after[i][o]);
                        let bend = 2.0 * b - a - c;
                        if b >= a && b >= c && bend > 0.0 {
                            *x = (b + (c - a) * (c - a) / (8.0 * bend)) * vertex_margin[o];
                        }
                    }
                    raise_in(&mut tip_cells, range.clone(), i, d);
                }
            }
            const FINE: usize = 8;
            // Axes often peak at the same sample: refine each sample once.
            let mut around: Vec<usize> = (0..2)
                .flat_map(|d| {
                    (0..3)
                        .filter(move |&i| best[d][i] > 0.0)
                        .map(move |i| (d, i))
                })
                .map(|(d, i)| peaks[d][i])
                .collect();
            // And every other local peak of |q''| or |q'''| within half of the largest: a
            // narrow spike sampled off its top may hide a higher peak than the one sampled
            // highest.
            for s in 1..samples {
                for i in 0..3 {
                    for o in 1..3 {
                        let (a, b, c) = (rows[s - 1][i][o], rows[s][i][o], rows[s + 1][i][o]);
                        if b >= a && b >= c && b >= 0.7 * best[o - 1][i] && b > 0.0 {
                            around.push(s);
                        }
                    }
                }
            }
            around.sort_unstable();
            around.dedup();
            // Each window is narrowed around its highest |q'''| (relative to the largest
            // sampled) a few times over: a spike narrower than a fine step is still found.
            const NARROWINGS: usize = 3;
            for s in &around {
                let mut lo = ua + du * (*s as f64 - 1.0).max(0.0);
                let mut hi = (ua + du * (*s as f64 + 1.0)).min(ub);
                for _ in 0..NARROWINGS {
                    let mut top = (f64::NEG_INFINITY, lo);
                    for f in 1..FINE {
                        let u = lo + (hi - lo) * f as f64 / FINE as f64;
                        let (_, k, dk) = take(u, &mut g1, &mut g2, &mut g3, &mut tip_cells);
                        g.kappa_max = g.kappa_max.max(k.norm());
                        let level = (0..3)
                            .map(|i| dk[i].abs() / best[1][i].max(1e-300))
                            .fold(0.0, f64::max);
                        if level > top.0 {
                            top = (level, u);
                        }
                    }
                    let step = (hi - lo) / FINE as f64;
                    (lo, hi) = ((top.1 - step).max(ua), (top.1 + step).min(ub));
                }
            }
        }
    }
    let Some(map) = machine.map_for(seg.control) else {
        numeric_joints(seg, machine, n, &mut g)?;
        return Ok(g);
    };
    for (j, m) in map.iter().take(n).enumerate() {
        match *m {
            JointMap::Tip(i) => {
                g.g1[j] = g1[i];
                g.g2[j] = g2[i];
                g.g3[j] = g3[i];
                g.d1_start[j] = tip_d1_start[i];
                g.d1_end[j] = tip_d1_end[i];
                g.d2_start[j] = tip_d2_start[i];
                g.d2_end[j] = tip_d2_end[i];
                for (cell, tip) in g.cells.iter_mut().zip(&tip_cells) {
                    cell[j] = tip[i];
                }
            }
            JointMap::Rotary(k) => {
                let r = rot_rate(k);
                g.g1[j] = r.abs();
                for cell in g.cells.iter_mut() {
                    cell[j] = [r.abs(), 0.0, 0.0];
                }
                g.d1_start[j] = r;
                g.d1_end[j] = r;
            }
        }
    }
    Ok(g)
}

/// Most inverse-kinematics samples along one segment.
const MAX_STEPS: usize = 8192;

/// Whether the curve's parametric speed is constant (u ∝ s), checked at five parameters.
fn constant_speed(curve: &dyn Curve) -> bool {
    let (a, b) = curve.domain();
    let s0 = curve.speed(a);
    [0.25, 0.5, 0.75, 1.0]
        .iter()
        .all(|&f| (curve.speed(a + (b - a) * f) - s0).abs() <= 1e-12 * s0)
}

/// Joint derivatives by differences of the inverse kinematics at equal arc-length steps h
/// along the segment: q' = ∇q/h, q'' = ∇²q/h², q''' = ∇³q/h³, one-sided second-order formulas
/// at the ends. Margins cover the peaks between samples (the step turns the joint map by
/// little). The samples are where the interpolator puts them: tip at u(s), rotary axes linear
/// in s. Lines, arcs and helices have constant parametric speed (u ∝ s); a blend or spline
/// does not, and equal steps in u there would misjudge h (and so q''' by the cube of the
/// speed ratio), which is why an arc-length map is built for them.
// Joint i indexes several parallel arrays (rows of q, g1…g3, ends): a range loop is clearest.
#[allow(clippy::needless_range_loop)]
fn numeric_joints(
    seg: &Segment,
    machine: &PlanMachine,
    n: usize,
    g: &mut Geometry,
) -> Result<(), PlanError> {
    let (ua, ub) = seg.curve.domain();
    let length = g.length;
    // Steps short against the tightest curvature of the tip (g.kappa_max, found exactly
    // above): a tight blend's curvature spike is narrow, and uniform steps coarser than its
    // width miss q'' and q''' by orders of magnitude.
    let by_length = 16 + (length / 0.5).ceil() as usize;
    let by_curvature = (length * g.kappa_max / 0.05).ceil() as usize;
    let steps = by_length.max(by_curvature).min(MAX_STEPS);
    let h = length / steps as f64;
    let map = if g.rotary_only || constant_speed(&*seg.curve) {
        None
    } else {
        // The s → u map's error, divided by h³ in q''', must stay far below the real q'''.
        ArcLengthMap::new(&*seg.curve, 1e-12 * seg.length.clamp(1e-3, 1.0)).ok()
    };
    let at = |f: f64| {
        let u = if g.rotary_only {
            ua
        } else if let Some(m) = &map {
            m.u_at(&*seg.curve, f * m.length())
        } else {
            ua + (ub - ua) * f
        };
        (seg.curve.point(u), u)
    };
    let mut q: Vec<[f64; MAX_JOINTS]> = Vec::with_capacity(steps + 1);
    // The branch the interpolator follows: the one of the programmed angles at the start
    // (where a tool axis is carried, its inverse has two tilt branches; the guess picks the
    // one the path arrives on).
    let (tip0, _) = at(0.0);
    let mut prev = machine
        .joints(seg.control, &tip0, &seg.rotary[0], &Joints::zeros(n))
        .unwrap_or_else(|_| Joints::zeros(n));
    for k in 0..=steps {
        let f = k as f64 / steps as f64;
        let (tip, u) = at(f);
        // Unreachable points are the interpolator's error to report, with the line.
        let Ok((qk, _)) = machine.segment_joints(seg, u, f, &tip, &prev) else {
            return Ok(());
        };
        prev = qk;
        let mut row = [0.0; MAX_JOINTS];
        row[..n].copy_from_slice(&qk.as_slice()[..n]);
        q.push(row);
    }
    let m = q.len() - 1;
    for i in 0..n {
        let x = |k: usize| q[k][i];
        // A joint that jumps (a path through a singular pose, e.g. the C axis centre of a
        // Y-Z-C-A machine) has no speed that keeps it in its limits: halving the step around
        // the largest change must halve it, as for any smooth joint. Changes below the
        // joint's own floor (`PlanMachine::jump_floor`) are rounding, not motion.
        let k = (0..m)
            .max_by(|&a, &b| (x(a + 1) - x(a)).abs().total_cmp(&(x(b + 1) - x(b)).abs()))
            .unwrap_or(0);
        let big = (x(k + 1) - x(k)).abs();
        if big > machine.jump_floor(i) {
            let mut before = Joints::zeros(n);
            before.as_mut_slice().copy_from_slice(&q[k][..n]);
            let fm = (k as f64 + 0.5) / steps as f64;
            let (tip, u) = at(fm);
            if let Ok((mid, _)) = machine.segment_joints(seg, u, fm, &tip, &before) {
                let half = (mid[i] - x(k)).abs().max((x(k + 1) - mid[i]).abs());
                if half > 0.9 * big {
                    return Err(PlanError::JointJump {
                        line: seg.line,
                        joint: i,
                        jump: big,
                    });
                }
            }
        }
        let mut g1: f64 = 0.0;
        let mut g2: f64 = 0.0;
        let mut g3: f64 = 0.0;
        // Each difference also raises the cells of its stretch, with the margins below.
        let df = 1.0 / m as f64;
        let at = |k: f64| k / m as f64;
        let cells = &mut g.cells;
        // Second differences at every inner step (the ends take their neighbour's): they
        // bound how far q' strays from a first difference within its step, h/2·|q''|.
        let second = |k: usize| {
            let k = k.clamp(1, m - 1);
            ((x(k + 1) - 2.0 * x(k) + x(k - 1)) / (h * h)).abs()
        };
        // The third differences likewise bound how far q'' strays from a second difference.
        let third = |k: usize| {
            let k = k.clamp(1, m.saturating_sub(2).max(1));
            ((x(k + 2) - 3.0 * x(k + 1) + 3.0 * x(k) - x(k - 1)) / (h * h * h)).abs()
        };
        for k in 0..m {
            let d = ((x(k + 1) - x(k)) / h).abs() + 0.5 * h * second(k).max(second(k + 1));
            g1 = g1.max(d);
            raise(cells, i, at(k as f64 + 0.5), df, [d * 1.01, 0.0, 0.0]);
        }
        for k in 1..m {
            let d = second(k) + 0.5 * h * third(k - 1).max(third(k));
            g2 = g2.max(d);
            raise(cells, i, at(k as f64), df, [0.0, d * 1.1, 0.0]);
        }
        for k in 1..m - 1 {
            let d = ((x(k + 2) - 3.0 * x(k + 1) + 3.0 * x(k) - x(k - 1)) / (h * h * h)).abs();
            g3 = g3.max(d);
            raise(cells, i, at(k as f64 + 0.5), df, [0.0, 0.0, d * 1.2]);
        }
        // q''' is largest at an end of a blend (its curvature rises from the straight line's
        // zero at a finite rate there): one-sided second-order formulas, which the central
        // differences above never reach.
        let d3_start = (-5.0 * x(0) + 18.0 * x(1) - 24.0 * x(2) + 14.0 * x(3) - 3.0 * x(4))
            / (2.0 * h * h * h);
        let d3_end = (5.0 * x(m) - 18.0 * x(m - 1) + 24.0 * x(m - 2) - 14.0 * x(m - 3)
            + 3.0 * x(m - 4))
            / (2.0 * h * h * h);
        g3 = g3.max(d3_start.abs()).max(d3_end.abs());
        g.d1_start[i] = (-3.0 * x(0) + 4.0 * x(1) - x(2)) / (2.0 * h);
        g.d1_end[i] = (3.0 * x(m) - 4.0 * x(m - 1) + x(m - 2)) / (2.0 * h);
        g.d2_start[i] = (2.0 * x(0) - 5.0 * x(1) + 4.0 * x(2) - x(3)) / (h * h);
        g.d2_end[i] = (2.0 * x(m) - 5.0 * x(m - 1) + 4.0 * x(m - 2) - x(m - 3)) / (h * h);
        let ends = [
            (0.0, g.d1_start[i], g.d2_start[i], d3_start),
            (1.0, g.d1_end[i], g.d2_end[i], d3_end),
        ];
        for (f, d1, d2, d3) in ends {
            raise(
                &mut g.cells,
                i,
                f,
                df,
                [d1.abs() * 1.01, d2.abs() * 1.1, d3.abs() * 1.2],
            );
        }
        g.g1[i] = g1.max(g.d1_start[i].abs()).max(g.d1_end[i].abs()) * 1.01;
        g.g2[i] = g2.max(g.d2_start[i].abs()).max(g.d2_end[i].abs()) * 1.1;
        g.g3[i] = g3 * 1.2;
    }
    Ok(())
}

/// The profile limits of one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentLimits {
    /// Path speed, acceleration and jerk (σ units).
    pub limits: Limits,
    /// What set the speed limit (for reports).
    pub by: LimitedBy,
    /// The speed at which the segment just fits with no acceleration left (the least of the
    /// maximum-velocity curve over it, the feed, the joints' speeds and the chord error): what
    /// its neighbours may expect to meet it at.
    pub top: f64,
}

/// The binding speed limit of a segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitedBy {
    Feed,
    JointVelocity,
    Curvature,
    ChordError,
    Idle,
}

/// Speed, acceleration and jerk of the path profile on `seg` (see the module doc). `reserve`
/// keeps [`PlanOptions::junction_reserve`] of the joint budgets back for junction jumps.
///
/// The profile's (v, a, j) stay in the box |v| ≤ V, |a| ≤ A, |j| ≤ J, so V, A and J are chosen
/// together such that at every point of the segment (each of its [`Geometry::cells`]) and for
/// every joint i (budget b):
///   |q'|·V ≤ Vᵢ,   |q''|V² + |q'|A ≤ b·Aᵢ,   |q'''|V³ + 3|q''|·V·A + |q'|J ≤ b·Jᵢ.
/// The constraints are met point by point: where a joint's slope peaks its curvature term is
/// usually small, and the other way round, so the budget left for A and J is the least over
/// the points, not the worst slope times the worst curvature.
///
/// On a curved segment the speed at which a = j = 0 just fits, the least over the segment of
/// √(b·Aᵢ/|q''|) and ∛(b·Jᵢ/|q'''|) (Kelekçi, 2021, §3.3.1, v ≤ √(A/κ), v ≤ (J/κ²)^⅓ per joint; the
/// maximum-velocity curve of the phase plane, Bobrow et al. 1985), leaves nothing to change
/// speed with. No fixed share of the budget is set aside: among speeds V = β·V_top (V_top the
/// least of that curve, the feed, the joints' speeds and the chord error), and accelerations up
/// to what is left, [`best_split`] takes the (V, A, J) that would cover the segment
/// fastest, ramps to and from it included. A long arc or helix thus runs close to its
/// curvature limit, and a short stretch between speed changes keeps more for its ramps.
/// The cross term 3|q''|·V·A is paid by the path acceleration, not by the speed: charging it
/// at a fixed A (as a speed cap) made tight corner blends crawl.
pub fn segment_limits(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
) -> Result<SegmentLimits, PlanError> {
    segment_limits_at_feed(seg, geom, machine, options, reserve, 1.0)
}

/// [`segment_limits`] with the programmed feed scaled by `feed_scale` (a feed override above
/// 100 %): the V, A and J returned hold for every speed up to that V, so a re-timing that runs
/// the planned profile faster stays within every joint's limits under them.
pub fn segment_limits_at_feed(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
    feed_scale: f64,
) -> Result<SegmentLimits, PlanError> {
    limits_for_change(seg, geom, machine, options, reserve, feed_scale, |_| {
        Changes::both(REFERENCE_CHANGE)
    })
}

/// [`segment_limits`] for a segment whose neighbours let it be entered at about `ends.0` and
/// left at about `ends.1` (the junction caps and the neighbours' [`SegmentLimits::top`]): the
/// split keeps acceleration for the speed changes those ends ask for, and no more. A segment
/// at a minimum of the maximum-velocity curve, between faster ones, thus runs close to that
/// curve and its neighbours change the speed (the optimum touches the limit curve at its
/// minima; Bobrow, Dubowsky & Gibson 1985, §4).
pub fn segment_limits_between(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
    ends: (f64, f64),
) -> Result<SegmentLimits, PlanError> {
    let change = |top: f64, end: f64| (1.0 - end / top).clamp(MIN_CHANGE, 1.0);
    limits_for_change(seg, geom, machine, options, reserve, 1.0, |top| {
        let (start, end) = (change(top, ends.0), change(top, ends.1));
        Changes {
            start,
            end,
            ramp: start.max(end),
        }
    })
}

/// The limits of the cruise between a curved segment's speed steps ([`ladder`]): the steps
/// climb to 90 % of it, so the cruise's own ramps are a tenth of its speed, and it may run
/// closer to the curvature limit than a segment that must change speed by a quarter.
pub fn cruise_limits(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
) -> Result<SegmentLimits, PlanError> {
    limits_for_change(seg, geom, machine, options, reserve, 1.0, |_| {
        Changes::both(1.0 - LADDER[LADDER.len() - 1])
    })
}

/// [`segment_limits_at_feed`] with the split chosen for ramps of `change(top)`·V at the start
/// and at the end, `top` the speed at which the segment just fits.
fn limits_for_change(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
    feed_scale: f64,
    change: impl Fn(f64) -> Changes,
) -> Result<SegmentLimits, PlanError> {
    let (top, mut a, mut j, by) = top_speed(seg, geom, machine, options, reserve, feed_scale);
    let mut v = top;
    if geom.curved() && v.is_finite() {
        let budgets = Budgets::new(&geom.cells, machine, options, reserve);
        (v, a, j) =
            best_split(v, geom.length, change(v), &budgets).ok_or_else(|| PlanError::NoLimit {
                line: seg.line,
                reason: "no acceleration is left at any speed".into(),
            })?;
    }
    if !a.is_finite() {
        a = options.idle_rotary[1];
    }
    if !j.is_finite() {
        j = options.idle_rotary[2];
    }
    let limits = Limits::new(v, a, j).map_err(|e| PlanError::NoLimit {
        line: seg.line,
        reason: e.to_string(),
    })?;
    Ok(SegmentLimits { limits, by, top })
}

/// The speed a segment is passed at most (see [`SegmentLimits::top`]), what set it, and on a
/// straight segment the path acceleration and jerk (∞ where no joint moves).
pub fn segment_top(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> f64 {
    top_speed(seg, geom, machine, options, false, 1.0).0
}

/// [`segment_top`] with the budget of `reserve` and the feed scaled by `feed_scale`: (V, A,
/// J, what set V), A and J only for a straight segment.
fn top_speed(
    seg: &Segment,
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
    feed_scale: f64,
) -> (f64, f64, f64, LimitedBy) {
    let n = machine.joint_count().min(MAX_JOINTS);
    let budget = options.budget(reserve);
    let curved = geom.curved();
    let (mut v, mut a, mut j) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut by = LimitedBy::JointVelocity;
    for i in 0..n {
        if geom.g1[i] > 0.0 {
            v = v.min(machine.max_velocity[i] / geom.g1[i]);
            if !curved {
                a = a.min(budget * machine.max_acceleration[i] / geom.g1[i]);
                j = j.min(budget * machine.max_jerk[i] / geom.g1[i]);
            }
        }
    }
    if curved {
        let mut vc = f64::INFINITY;
        for i in 0..n {
            let (g2, g3) = (geom.g2[i], geom.g3[i]);
            if g2 > 0.0 {
                vc = vc.min((budget * machine.max_acceleration[i] / g2).sqrt());
            }
            if g3 > 0.0 {
                vc = vc.min((budget * machine.max_jerk[i] / g3).cbrt());
            }
        }
        if vc < v {
            v = vc;
            by = LimitedBy::Curvature;
        }
        // Chord error at the period: the chord of a circle of radius ρ through two samples
        // v·Ts apart sags δ when v = (2/Ts)·√(2ρδ − δ²) (Kelekçi, 2021, §3.3.1).
        if geom.kappa_max > 0.0 {
            let rho = 1.0 / geom.kappa_max;
            let delta = (options.chord_share * seg.tolerance).min(rho);
            let vch = 2.0 / options.period * (2.0 * rho * delta - delta * delta).max(0.0).sqrt();
            if vch < v {
                v = vch;
                by = LimitedBy::ChordError;
            }
        }
    }
    let feed = feed_scale
        * match seg.feed {
            SegmentFeed::Rapid => f64::INFINITY,
            SegmentFeed::Feed(f) => f,
            SegmentFeed::InverseTime(t) if t > 0.0 => geom.length / t,
            SegmentFeed::InverseTime(_) => f64::INFINITY,
        };
    if feed < v {
        v = feed;
        by = LimitedBy::Feed;
    }
    if !v.is_finite() {
        // Nothing on this machine follows the move (A/B/C on a 3-axis mill).
        v = options.idle_rotary[0].min(feed);
        by = LimitedBy::Idle;
    }
    (v, a, j, by)
}

/// The joint budgets of a curved segment, point by point.
///
/// Of the (|q'|, |q''|, |q'''|) of one joint in its cells only those no other cell exceeds in
/// all three are kept (the Pareto front, usually a few of the sixteen): every limit below
/// tightens as each of the three grows (at any speed and acceleration: the acceleration left
/// falls with |q''|, the jerk left with |q'''|, and both are divided among |q'| and |q''|), so
/// a cell bounded by another in all three is never the binding one.
struct Budgets<'a> {
    cells: &'a Cells,
    /// (cell, joint) of the cells on each joint's front; `front[..m]` hold.
    front: [(u8, u8); CELLS * MAX_JOINTS],
    m: usize,
    /// b·Aᵢ and b·Jᵢ per joint.
    acceleration: [f64; MAX_JOINTS],
    jerk: [f64; MAX_JOINTS],
}

impl<'a> Budgets<'a> {
    /// The joints' acceleration and jerk, less the junction reserve where one is `kept`.
    fn new(cells: &'a Cells, machine: &PlanMachine, options: &PlanOptions, kept: bool) -> Self {
        let b = options.budget(kept);
        let scaled =
            |limits: &[f64]| std::array::from_fn(|i| b * limits.get(i).copied().unwrap_or(0.0));
        let mut front = [(0, 0); CELLS * MAX_JOINTS];
        let mut m = 0;
        let below = |x: &[f64; 3], y: &[f64; 3]| x[0] <= y[0] && x[1] <= y[1] && x[2] <= y[2];
        for i in 0..machine.joint_count().min(MAX_JOINTS) {
            for (c, cell) in cells.iter().enumerate() {
                let d = &cell[i];
                // Bounded by another cell (among equal ones, the first is kept).
                let covered = cells.iter().enumerate().any(|(o, other)| {
                    let e = &other[i];
                    o != c && below(d, e) && (o < c || !below(e, d))
                });
                if !covered {
                    front[m] = (c as u8, i as u8);
                    m += 1;
                }
            }
        }
        Budgets {
            cells,
            front,
            m,
            acceleration: scaled(&machine.max_acceleration),
            jerk: scaled(&machine.max_jerk),
        }
    }

    /// Each kept cell's joint and (|q'|, |q''|, |q'''|).
    fn rows(&self) -> impl Iterator<Item = (usize, [f64; 3])> + '_ {
        self.front[..self.m]
            .iter()
            .map(|&(c, i)| (i as usize, self.cells[c as usize][i as usize]))
    }
}

/// The speed changes a segment's split is chosen for, as shares of its speed: at its start,
/// at its end, and the one its acceleration and jerk are shared for (a cruise between speed
/// steps keeps them for a stop that may follow).
#[derive(Debug, Clone, Copy)]
struct Changes {
    start: f64,
    end: f64,
    ramp: f64,
}

impl Changes {
    /// A change of `c` at both ends, acceleration and jerk kept for a ramp through the whole
    /// speed (a stop may follow where the neighbours are not known).
    fn both(c: f64) -> Changes {
        Changes {
            start: c,
            end: c,
            ramp: 1.0,
        }
    }
}

/// Fractions of the top speed [`best_split`] tries (a speed just under the curvature limit
/// leaves almost no acceleration; the finest steps are near 1, where a long arc runs).
const SPEED_FRACTIONS: [f64; 12] = [
    1.0, 0.99, 0.97, 0.95, 0.92, 0.89, 0.85, 0.8, 0.74, 0.66, 0.5, 0.33,
];
/// Fractions of the acceleration left at a speed that [`best_split`] tries (the rest of the
/// jerk budget then goes to the path jerk through the cross term 3|q''|·V·A).
const ACCEL_FRACTIONS: [f64; 5] = [1.0, 0.7, 0.45, 0.25, 0.1];
/// Speed change, as a share of the speed, assumed at each end of a segment whose neighbours
/// are not known.
const REFERENCE_CHANGE: f64 = 0.25;
/// The least speed change, as a share of the speed, a segment keeps acceleration for (the
/// profile's own rounding, and a neighbour that turns out a little slower than expected).
const MIN_CHANGE: f64 = 0.05;

/// The (V, A, J) that covers the segment fastest: V ≤ `top`, and for V and A every
/// point and joint within its budgets (see [`segment_limits`]). The time is the cruise L/V
/// plus, at each end, what a jerk-limited ramp of `change`·V (start, end) costs over cruising
/// (half its duration times the change's share of V). `None` if no speed leaves room for
/// acceleration.
fn best_split(
    top: f64,
    length: f64,
    change: Changes,
    budgets: &Budgets<'_>,
) -> Option<(f64, f64, f64)> {
    // The segment's own length: a short one alone between others of other limits (a tight
    // spot, the pole of a 5-axis pass) is all ramps, and a floor of a few millimetres once
    // left it creeping with a tenth of the acceleration it could use.
    let reference = length.max(1e-9);
    let mut best: Option<(f64, (f64, f64, f64))> = None;
    // Slower speeds leave more for the ramps; once two in a row cost more than the best, the
    // rest (slower still, their cruise longer) do not pay either.
    let mut worse = 0;
    for beta in SPEED_FRACTIONS {
        let v = beta * top;
        if let Some((a, j, _)) = at_speed(v, change.ramp * v, budgets) {
            let ramp = |c: f64| 0.5 * c * ramp_time(c * v, a, j);
            let time = reference / v + ramp(change.start) + ramp(change.end);
            if best.is_none_or(|(t, _)| time < t) {
                best = Some((time, (v, a, j)));
                worse = 0;
            } else {
                worse += 1;
                if worse == 2 {
                    break;
                }
            }
        }
    }
    best.map(|(_, x)| x)
}

/// At path speed `v`, the (A, J) within every point's budgets that changes the speed by `dv`
/// fastest, with that ramp's duration: A takes a share of what the acceleration leaves, J the
/// most the jerk then leaves (see [`jerk_left`]). `None` if nothing is left.
fn at_speed(v: f64, dv: f64, budgets: &Budgets<'_>) -> Option<(f64, f64, f64)> {
    let v3 = v * v * v;
    // The most acceleration the acceleration budget leaves, and the most that leaves jerk
    // with the cross term paid at V (a profile's acceleration peaks below V, so this leaves
    // some jerk: shares of it are tried).
    let mut a_cap = f64::INFINITY;
    let mut a_low = f64::INFINITY;
    for (i, [g1, g2, g3]) in budgets.rows() {
        let rest_a = budgets.acceleration[i] - g2 * v * v;
        let rest_j = budgets.jerk[i] - g3 * v3;
        if rest_a < 0.0 || rest_j < 0.0 {
            return None;
        }
        if g1 > 0.0 {
            a_cap = a_cap.min(rest_a / g1);
        }
        if g2 > 0.0 {
            a_low = a_low.min(rest_j / (3.0 * g2 * v));
        }
    }
    if !(a_cap > 0.0 && a_cap.is_finite()) {
        return None;
    }
    // The least over points and joints of what each allows (see [`jerk_left`]), from |q'|,
    // 3|q''| and the jerk left after the curvature's rate |q'''|v³, recomputed per share of
    // the acceleration: cheaper than storing them.
    let jerk = |a: f64| {
        let mut j = f64::INFINITY;
        for (i, [g1, g2, g3]) in budgets.rows() {
            if g1 > 0.0 || g2 > 0.0 {
                let rest_j = budgets.jerk[i] - g3 * v3;
                j = j.min(jerk_left(g1, 3.0 * g2, rest_j, v, a));
            }
        }
        j
    };
    let mut best: Option<(f64, f64, f64)> = None;
    let a_cap = a_low.min(a_cap);
    for a in ACCEL_FRACTIONS.map(|alpha| alpha * a_cap) {
        let j = jerk(a);
        if !(j > 0.0 && j.is_finite()) {
            continue;
        }
        let ramp = ramp_time(dv, a, j);
        if best.is_none_or(|(_, _, t)| ramp < t) {
            best = Some((a, j, ramp));
        }
    }
    best
}

/// The largest path jerk J one joint at one point allows at path speed `v` and acceleration
/// `a`: |q'|·J + 3|q''|·P ≤ `rest` (its jerk left after |q'''|v³), `g2x3` = 3|q''|, with P
/// the largest speed × acceleration a jerk-limited motion under (V, A, J) reaches, its
/// acceleration zero where it starts and ends. Where |a| = α the speed is at most
/// V − α²/(2J): the acceleration must return to zero, at jerk J at most, before the speed
/// passes V (or left zero that much earlier on the way down). So the cross term 3|q''|·v·a
/// is paid at P = max (V − α²/2J)·α over α ≤ A, which peaks at α = √(2JV/3), not at the
/// corner (V, A) of the box, which no profile reaches. The left side grows with J, so the
/// bound is where it equals `rest`, in closed form on either side of that knee.
fn jerk_left(g1: f64, g2x3: f64, rest: f64, v: f64, a: f64) -> f64 {
    if g2x3 <= 0.0 {
        return if g1 > 0.0 { rest / g1 } else { f64::INFINITY };
    }
    // Where the knee is at `a`: J = 3a²/(2V); above it the peak is (V − a²/2J)·a.
    let knee = 1.5 * a * a / v;
    if g1 > 0.0 {
        // g1·J + g2x3·(V − a²/2J)·a = rest: g1·J² − c·J − g2x3·a³/2 = 0.
        let c = rest - g2x3 * v * a;
        let j = (c + (c * c + 2.0 * g1 * g2x3 * a * a * a).sqrt()) / (2.0 * g1);
        if j >= knee {
            return j;
        }
        // Below the knee: g1·x² + b·x − rest = 0 with x = √J, b = g2x3·(2/3)V·√(2V/3).
        let b = g2x3 * (2.0 / 3.0) * v * (2.0 * v / 3.0).sqrt();
        let x = (-b + (b * b + 4.0 * g1 * rest).sqrt()) / (2.0 * g1);
        x * x
    } else {
        // Only the cross term: the peak itself must stay within `rest`.
        let peak = rest / g2x3;
        if v * a <= peak {
            return f64::INFINITY;
        }
        let j = a * a / (2.0 * (v - peak / a));
        if j >= knee {
            return j;
        }
        // (2/3)V·√(2JV/3) = peak.
        let x = 1.5 * peak / v;
        1.5 / v * x * x
    }
}

/// The duration of a jerk-limited speed change `dv` from rest acceleration to rest
/// acceleration under (A, J): dv/A + A/J, or 2√(dv/J) where A is not reached.
fn ramp_time(dv: f64, a: f64, j: f64) -> f64 {
    if dv * j >= a * a {
        dv / a + a / j
    } else {
        2.0 * (dv / j).sqrt()
    }
}

/// Speeds, as shares of a curved segment's cruise speed, of the steps [`ladder`] climbs by.
const LADDER: [f64; 4] = [0.55, 0.75, 0.9, 0.97];
/// A step is kept only where it accelerates at least this many times faster than the cruise.
const LADDER_GAIN: f64 = 2.0;
/// A step must rise at least this share above the speed it starts from.
const LADDER_STEP: f64 = 0.05;
/// The steps at both ends together take at most this share of the segment.
const LADDER_SHARE: f64 = 0.5;

/// The speed steps of one end of a long curved segment entered or left at `from` (the cap
/// of its junction there), slowest first, as (length, limits): the
/// phase-plane's acceleration limit falls as the speed rises (what the curvature leaves,
/// |q''|v², is less at low speed), and one profile's constant A is what is left at its top
/// speed. A segment entered or left slowly (a helix after a corner) would climb to its cruise
/// at that smallest A; instead its ends are cut into steps, each timed with the acceleration
/// its own top speed leaves: a staircase under the maximum-acceleration curve of Bobrow,
/// Dubowsky & Gibson (1985) and Shin & McKay (1985), each stair a jerk-limited profile. The
/// look-ahead passes the steps like any segments. Empty where the steps do not pay.
pub fn ladder(
    geom: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
    reserve: bool,
    cruise: &Limits,
    from: f64,
) -> Vec<(f64, Limits)> {
    if !geom.curved() || geom.rotary_only {
        return vec![];
    }
    let budgets = Budgets::new(&geom.cells, machine, options, reserve);
    let top = cruise.max_velocity();
    let mut steps = vec![];
    let mut from = from.max(0.0);
    let mut used = 0.0;
    for share in LADDER {
        let v = share * top;
        if v <= from * (1.0 + LADDER_STEP) {
            continue;
        }
        let Some((a, j, _)) = at_speed(v, v - from, &budgets) else {
            continue;
        };
        if a < LADDER_GAIN * cruise.max_acceleration() {
            continue;
        }
        let Ok(limits) = Limits::new(v, a, j) else {
            continue;
        };
        let Ok(d) = crate::profile::speed_change_distance(from, v, &limits) else {
            continue;
        };
        used += d;
        steps.push((d, limits));
        from = v;
    }
    if steps.is_empty() || used > 0.5 * LADDER_SHARE * geom.length {
        return vec![];
    }
    steps
}

/// The highest speed at a junction where the joints' path derivatives jump from `a` (end of the
/// segment before) to `b` (start of the next): a velocity step Δq'·v and an acceleration step
/// Δq''·v², seen by third differences at the period as Δq'v/Ts² + Δq''v²/Ts, must stay within
/// half the reserve of each joint's jerk (the other half covers the path acceleration's step,
/// see [`inside_group`]); the velocity step's Δq'v/Ts within the reserve of the acceleration.
pub fn junction_cap(
    a: &Geometry,
    b: &Geometry,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> f64 {
    let ts = options.period;
    let r = options.junction_reserve;
    let mut cap = f64::INFINITY;
    for i in 0..machine.joint_count().min(MAX_JOINTS) {
        let dv = (b.d1_start[i] - a.d1_end[i]).abs();
        let dk = (b.d2_start[i] - a.d2_end[i]).abs();
        let jb = 0.5 * r * machine.max_jerk[i];
        // dk/Ts·v² + dv/Ts²·v − jb ≤ 0.
        let (qa, qb) = (dk / ts, dv / (ts * ts));
        let v = if qa > 0.0 {
            (-qb + (qb * qb + 4.0 * qa * jb).sqrt()) / (2.0 * qa)
        } else if qb > 0.0 {
            jb / qb
        } else {
            f64::INFINITY
        };
        cap = cap.min(v);
        if dv > 0.0 {
            cap = cap.min(r * machine.max_acceleration[i] * ts / dv);
        }
    }
    cap
}

/// Whether a junction with a tangent jump may lie inside one profile (where the path
/// acceleration `accel` is not zero): the joint acceleration then steps by Δq'·a, seen as
/// Δq'·a/Ts in the jerk, which must fit in the other half of the reserve.
pub fn inside_group(
    a: &Geometry,
    b: &Geometry,
    accel: f64,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> bool {
    (0..machine.joint_count().min(MAX_JOINTS)).all(|i| {
        let dv = (b.d1_start[i] - a.d1_end[i]).abs();
        dv * accel / options.period <= 0.5 * options.junction_reserve * machine.max_jerk[i]
    })
}

/// Whether any joint's path derivatives jump at the junction (it needs the reserve).
pub fn has_jump(a: &Geometry, b: &Geometry, machine: &PlanMachine) -> bool {
    (0..machine.joint_count().min(MAX_JOINTS)).any(|i| {
        (b.d1_start[i] - a.d1_end[i]).abs() > 1e-12 || (b.d2_start[i] - a.d2_end[i]).abs() > 1e-12
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::solve;
    use proptest::prelude::*;

    /// The peak of (V − α²/2J)·α over α ≤ A, by brute force (it is negative beyond √(2JV)).
    fn peak(v: f64, a: f64, j: f64) -> f64 {
        let top = a.min((2.0 * j * v).sqrt());
        (0..=20_000)
            .map(|k| {
                let alpha = top * k as f64 / 20_000.0;
                (v - alpha * alpha / (2.0 * j)) * alpha
            })
            .fold(0.0, f64::max)
    }

    proptest! {
        /// A profile never reaches speed V and acceleration A together: where |a| = α its
        /// speed is at most V − α²/(2J), the envelope [`jerk_left`] charges the cross term at.
        #[test]
        fn profiles_stay_under_the_envelope(
            v in 1.0f64..300.0, a in 10.0f64..5000.0, j in 100.0f64..100_000.0,
            f0 in 0.0f64..1.0, f1 in 0.0f64..1.0, len in 0.01f64..200.0,
        ) {
            let limits = Limits::new(v, a, j).unwrap();
            let Ok(p) = solve(len, f0 * v, f1 * v, &limits) else { return Ok(()) };
            let n = 2000;
            for k in 0..=n {
                let s = p.state_at(p.duration() * k as f64 / n as f64);
                let bound = v - s.a * s.a / (2.0 * j);
                prop_assert!(s.v <= bound + 1e-9 * v, "v {} > {} at a {}", s.v, bound, s.a);
            }
        }

        /// The jerk found is the largest that keeps the joint's jerk within what is left.
        #[test]
        fn jerk_left_meets_the_budget(
            g1 in 0.0f64..2.0, g2 in 0.0f64..2.0, rest in 1.0f64..100_000.0,
            v in 1.0f64..300.0, a in 1.0f64..5000.0,
        ) {
            let j = jerk_left(g1, 3.0 * g2, rest, v, a);
            if j.is_finite() {
                prop_assert!(j > 0.0);
                let used = g1 * j + 3.0 * g2 * peak(v, a, j);
                prop_assert!((used - rest).abs() <= 1e-6 * rest, "used {used} of {rest}");
            } else {
                prop_assert!(g1 == 0.0 && 3.0 * g2 * v * a <= rest * (1.0 + 1e-12));
            }
        }
    }
}
