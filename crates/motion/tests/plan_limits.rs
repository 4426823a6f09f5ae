//! The planner's per-segment limits (V, A, J) against the chain rule along the path:
//! q̇ = q'v, q̈ = q''v² + q'a, q⃛ = q'''v³ + 3q''va + q'j. On random Bézier segments (curved,
//! not arc-length parametrised, like corner blends) q', q'', q''' are computed at 2 000 points
//! independently of the planner's formulas (the unit tangent differenced in arc length, see
//! [`arc_length_derivs`]), and every joint must stay inside its velocity,
//! acceleration and jerk limit at (V, A, J) — each term at its worst at once. Tight corner
//! blends must get the speed that curvature alone allows (the cross term 3q''va is paid by a
//! lower A, not by a lower V). End to end, the five-axis example with its corner blends holds
//! every joint of `table-ac` (numeric joint derivatives on blends, which are not u ∝ s).

#[path = "../benches/common/mod.rs"]
mod common;

use tezgah_geom::arclen::gauss_legendre;
use tezgah_geom::{ArcLengthMap, Bezier, Curve, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::limits::{analyse, segment_limits};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::Verifier;
use tezgah_motion::{Junction, Segment, SegmentFeed};

/// xorshift64* (Vigna 2016), reproducible test cases.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.unit() * (hi.ln() - lo.ln())).exp()
    }
}

fn segment(curve: Bezier, feed: f64) -> Segment {
    let length = ArcLengthMap::new(&curve, 1e-12).unwrap().length();
    Segment {
        curve: Box::new(curve),
        length,
        rotary: [[0.0; 3]; 2],
        line: 1,
        feed: SegmentFeed::Feed(feed),
        end: Junction::Smooth,
        tolerance: 0.01,
        control: Default::default(),
        feed_override: true,
        tool_axis_travel: None,
        axis: None,
    }
}

/// Relative error allowed for the finite-difference reference below (of a limit's use):
/// after Richardson extrapolation its error is O(du⁴) with du = 1e-4 of the parameter range,
/// measured ≤ 2e-7 of the largest |q_ss|, |q_sss| over these cases; a wrong term in the
/// planner's formulas shows at ≥ 10 % (one of the three q_ss·s_u·s_uu of q_sss dropped).
const REFERENCE_RTOL: f64 = 1e-6;

/// q_s, q_ss, q_sss of the tip by arc length at u, independent of the planner's chain rule
/// (`limits::frame`): q_s is the unit tangent T = C'/|C'| by its definition, and q_ss, q_sss
/// are divided differences of T over arc length (see [`tangent_differences`]), Richardson-
/// extrapolated from steps du and du/2 (the estimates are even in du: steps ±du give the
/// same three nodes).
fn arc_length_derivs(curve: &dyn Curve, u: f64, du: f64) -> [Vec3; 3] {
    let [t, a2, a3] = tangent_differences(curve, u, du);
    let [_, b2, b3] = tangent_differences(curve, u, 0.5 * du);
    [t, (b2 * 4.0 - a2) / 3.0, (b3 * 4.0 - a3) / 3.0]
}

/// T at u, and the first and second derivatives of T in arc length from T at u − du, u,
/// u + du: three-point formulas on the uneven grid of arc lengths (Fornberg 1988), each arc
/// length the Gauss–Legendre integral of |C'| over [u − du, u] or [u, u + du] (exact to
/// rounding on such short panels).
fn tangent_differences(curve: &dyn Curve, u: f64, du: f64) -> [Vec3; 3] {
    let tangent = |u: f64| {
        let d = curve.d1(u);
        d / d.norm()
    };
    let (tm, t0, tp) = (tangent(u - du), tangent(u), tangent(u + du));
    let h1 = gauss_legendre(curve, u - du, u);
    let h2 = gauss_legendre(curve, u, u + du);
    let q2 = ((tp - t0) * (h1 * h1) + (t0 - tm) * (h2 * h2)) / (h1 * h2 * (h1 + h2));
    let q3 = ((tp - t0) / h2 - (t0 - tm) / h1) * (2.0 / (h1 + h2));
    [t0, q2, q3]
}

/// A corner blend of size `h` mm turning by `angle` rad: a quintic Bézier whose first and
/// last three control points are collinear with the corner's legs (G2 at both ends).
fn corner_blend(h: f64, angle: f64) -> Bezier {
    let a = Vec3::new(-1.0, 0.0, 0.0);
    let b = Vec3::new(angle.cos(), angle.sin(), 0.0);
    let p = |k: f64, d: Vec3| d * (h * k);
    Bezier::new(vec![
        p(1.0, a),
        p(2.0 / 3.0, a),
        p(1.0 / 3.0, a),
        p(1.0 / 3.0, b),
        p(2.0 / 3.0, b),
        p(1.0, b),
    ])
    .unwrap()
}

#[test]
fn limits_hold_every_cartesian_joint_on_random_curved_segments() {
    let machine = Machine::default_machine();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let options = PlanOptions::default();
    let mut rng = Rng(0x5eed_0105);
    let mut worst: f64 = 0.0;
    for case in 0..300 {
        let scale = rng.log_uniform(0.005, 50.0);
        let degree = 2 + case % 4;
        let points: Vec<Vec3> = (0..=degree)
            .map(|_| Vec3::new(rng.unit(), rng.unit(), rng.unit() * 0.3) * scale)
            .collect();
        let Ok(curve) = Bezier::new(points) else {
            continue;
        };
        // Skip curves with a cusp (speed near zero), which no feed can follow.
        let (ua, ub) = curve.domain();
        let min_speed = (0..=200)
            .map(|k| curve.speed(ua + (ub - ua) * k as f64 / 200.0))
            .fold(f64::INFINITY, f64::min);
        if min_speed < 0.05 * scale {
            continue;
        }
        let feed = rng.log_uniform(1.0, 500.0);
        let seg = segment(curve, feed);
        let geom = analyse(&seg, &pm).unwrap();
        // 2 001 points, kept a step inside the ends for the difference stencil.
        let du = 1e-4 * (ub - ua);
        let at = |k: usize| ua + 2.0 * du + (ub - ua - 4.0 * du) * k as f64 / 2000.0;
        let reference: Vec<[Vec3; 3]> = (0..=2000)
            .map(|k| arc_length_derivs(&*seg.curve, at(k), du))
            .collect();
        for reserve in [false, true] {
            let l = segment_limits(&seg, &geom, &pm, &options, reserve)
                .unwrap()
                .limits;
            let (v, a, j) = (l.max_velocity(), l.max_acceleration(), l.max_jerk());
            let p = speed_times_acceleration(v, a, j);
            assert!(v <= feed * (1.0 + 1e-12));
            let budget = if reserve {
                1.0 - options.junction_reserve
            } else {
                1.0
            };
            for (k, &[q1, q2, q3]) in reference.iter().enumerate() {
                let u = at(k);
                for i in 0..3 {
                    let vel = q1[i].abs() * v / pm.max_velocity[i];
                    let acc =
                        (q2[i].abs() * v * v + q1[i].abs() * a) / (budget * pm.max_acceleration[i]);
                    let jerk = (q3[i].abs() * v * v * v + 3.0 * q2[i].abs() * p + q1[i].abs() * j)
                        / (budget * pm.max_jerk[i]);
                    worst = worst.max(vel).max(acc).max(jerk);
                    assert!(
                        vel <= 1.0 + 1e-9
                            && acc <= 1.0 + REFERENCE_RTOL
                            && jerk <= 1.0 + REFERENCE_RTOL,
                        "case {case} joint {i} at u {u}: v {vel} a {acc} j {jerk} of limit \
                         (V {v}, A {a}, J {j})"
                    );
                }
            }
        }
    }
    // The bound is not slack everywhere: some case uses most of a limit.
    assert!(worst > 0.9, "worst use of a limit {worst}");
}

/// The largest v·|a| of a jerk-limited profile under (V, A, J) that starts and ends at zero
/// acceleration: where |a| = α its speed is at most V − α²/(2J) (the acceleration must return
/// to zero before the speed passes V, or left zero that much earlier on the way down). Found
/// here by sampling α, the planner's closed form being what is checked.
fn speed_times_acceleration(v: f64, a: f64, j: f64) -> f64 {
    let top = a.min((2.0 * j * v).sqrt());
    (0..=10_000)
        .map(|k| {
            let alpha = top * k as f64 / 10_000.0;
            (v - alpha * alpha / (2.0 * j)) * alpha
        })
        .fold(0.0, f64::max)
}

#[test]
fn tight_corner_blends_get_the_pure_curvature_speed() {
    let machine = Machine::default_machine();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let options = PlanOptions::default();
    for (h, deg) in [
        (0.01, 90.0),
        (0.02, 120.0),
        (0.005, 150.0),
        (0.05, 45.0),
        (0.2, 90.0),
    ] {
        let seg = segment(corner_blend(h, f64::to_radians(deg)), 1000.0);
        let geom = analyse(&seg, &pm).unwrap();
        let sl = segment_limits(&seg, &geom, &pm, &options, false).unwrap();
        // The pure-curvature cap (a = j = 0): V = minᵢ √(Aᵢ/g2ᵢ), ∛(Jᵢ/g3ᵢ); the plan stays
        // under it and, with no fixed share set aside, close to it.
        let mut cap = f64::INFINITY;
        for i in 0..3 {
            if geom.g2[i] > 0.0 {
                cap = cap.min((pm.max_acceleration[i] / geom.g2[i]).sqrt());
            }
            if geom.g3[i] > 0.0 {
                cap = cap.min((pm.max_jerk[i] / geom.g3[i]).cbrt());
            }
        }
        let (v, a, j) = (
            sl.limits.max_velocity(),
            sl.limits.max_acceleration(),
            sl.limits.max_jerk(),
        );
        assert!(
            v <= cap * (1.0 + 1e-12) && v >= 0.75 * cap,
            "h {h} turn {deg}°: V {v} against the curvature cap {cap}"
        );
        // Point by point, every joint within its acceleration and jerk where a profile under
        // (V, A, J) is fastest with the most acceleration.
        let p = speed_times_acceleration(v, a, j);
        for cell in &geom.cells {
            for (i, &[g1, g2, g3]) in cell.iter().enumerate().take(3) {
                let acc = g2 * v * v + g1 * a;
                let jerk = g3 * v * v * v + 3.0 * g2 * p + g1 * j;
                assert!(acc <= pm.max_acceleration[i] * (1.0 + 1e-12), "a {acc}");
                // (The sampled peak is within ~1e-8 of the true one.)
                assert!(jerk <= pm.max_jerk[i] * (1.0 + 1e-7), "j {jerk}");
            }
        }
    }
    // The blend of the old report: a 90° corner 0.01 mm in size was capped at ~0.07 mm/s by
    // the cross term at full acceleration; curvature alone allows > 1 mm/s.
    let seg = segment(corner_blend(0.01, std::f64::consts::FRAC_PI_2), 1000.0);
    let geom = analyse(&seg, &pm).unwrap();
    let v = segment_limits(&seg, &geom, &pm, &options, false)
        .unwrap()
        .limits
        .max_velocity();
    assert!(v > 0.5, "V {v}");
}

#[test]
fn five_axis_example_with_blends_holds_table_ac_limits() {
    let text = include_str!("../../../examples/five-axis.ngc");
    let machine = Machine::builtin("table-ac").unwrap();
    // The example asks for tool-centre-point control with tool 1 (G43.4 H1).
    let config = tezgah_gcode::Config {
        tool_table: tezgah_gcode::ToolTable::parse(include_str!("../../../examples/tools.tbl"))
            .unwrap(),
        ..tezgah_gcode::Config::default()
    };
    let moves = tezgah_gcode::program_moves(text, config).unwrap();
    let items = smooth::build(
        moves,
        &SmoothOptions {
            tolerance: machine.motion.tolerance_mm,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    )
    .unwrap();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let mut verifier = Verifier::new(&pm, machine.motion.period_s);
    run(
        items,
        pm,
        PlanOptions {
            chord_share: smooth::CHORD_SHARE,
            ..PlanOptions::default()
        },
        (Vec3::zeros(), [0.0; 3]),
        |s, seg| verifier.push(s, seg),
    )
    .unwrap();
    let report = verifier.finish();
    common::assert_joints_within(&report);
    assert!(report.max_deviation <= machine.motion.tolerance_mm);
}
