//! The tool axis along the smoothed path under tool-centre-point control (5-axis, Kahraman
//! et al., eqs 1–3 and §3): values computed from their two-curve blend, and properties on
//! thousands of random 5-axis polylines and arc chains on the table-ac and table-bc
//! trunnions — the axis is a unit vector everywhere, continuous at every joint (bit for bit),
//! with continuous first and second derivatives by arc length at every smooth joint
//! (measured, 1e-9), within the blend's share of the angular tolerance of the programmed axis
//! (measured independently), exact at the programmed ends, never NaN.

mod path_support;

use std::f64::consts::PI;
use std::sync::Arc;

use path_support::*;
use proptest::prelude::*;
use tezgah_geom::{Curve, Move, MoveKind, PathMode, Pose, Quintic, State, ToolControl, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::path::orient::{
    angle_between, AxisBlend, AxisEnd, AxisPath, GreatCircle, ToolAxisMap,
};
use tezgah_motion::path::smooth::{build, Orientation, SmoothOptions, CHORD_SHARE};
use tezgah_motion::path::{Junction, PathItem};
use tezgah_motion::plan::PlanMachine;

const TCP: ToolControl = ToolControl::CentrePoint { tool_length: 35.0 };

/// Table-ac's tool axis in closed form (docs/machine-files.md): `(sin A sin C, sin A cos C, cos
/// A)`.
fn table_ac_axis(a_deg: f64, c_deg: f64) -> Vec3 {
    let (a, c) = (a_deg.to_radians(), c_deg.to_radians());
    Vec3::new(a.sin() * c.sin(), a.sin() * c.cos(), a.cos())
}

/// Table-bc's in closed form: `(−sin B cos C, sin B sin C, cos B)`.
fn table_bc_axis(b_deg: f64, c_deg: f64) -> Vec3 {
    let (b, c) = (b_deg.to_radians(), c_deg.to_radians());
    Vec3::new(-b.sin() * c.cos(), b.sin() * c.sin(), b.cos())
}

/// A five-axis trunnion of the property test: its name, the program axis that tilts (A or B,
/// index into A B C) and its tool axis in closed form.
#[derive(Debug, Clone, Copy)]
struct Trunnion {
    name: &'static str,
    tilt: usize,
    axis: fn(f64, f64) -> Vec3,
}

const AC: Trunnion = Trunnion {
    name: "table-ac",
    tilt: 0,
    axis: table_ac_axis,
};
const BC: Trunnion = Trunnion {
    name: "table-bc",
    tilt: 1,
    axis: table_bc_axis,
};

impl Trunnion {
    fn pose(&self, p: Vec3, tilt: f64, c: f64) -> Pose {
        let mut pose = Pose::new(p.x, p.y, p.z, 0.0, 0.0, c);
        pose.0[3 + self.tilt] = tilt;
        pose
    }
    fn rotary(&self, tilt: f64, c: f64) -> [f64; 3] {
        let mut r = [0.0, 0.0, c];
        r[self.tilt] = tilt;
        r
    }
    fn machine(&self) -> PlanMachine {
        PlanMachine::from_machine(&Machine::builtin(self.name).unwrap()).unwrap()
    }
}

fn machine() -> PlanMachine {
    PlanMachine::from_machine(&Machine::builtin("table-ac").unwrap()).unwrap()
}

fn options(pm: &PlanMachine, tolerance: f64, angular: f64) -> SmoothOptions {
    SmoothOptions {
        tolerance,
        angular_tolerance: angular,
        control: TCP,
        orientation: Some(Orientation(Arc::new(pm.clone()))),
        ..SmoothOptions::default()
    }
}

fn g1ac(line: u32, p: Vec3, a: f64, c: f64) -> Move {
    Move {
        line,
        kind: MoveKind::Feed {
            end: Pose::new(p.x, p.y, p.z, a, 0.0, c),
        },
    }
}

#[test]
fn the_machine_gives_the_closed_form_axis() {
    let pm = machine();
    for (a, c) in [(0.0, 0.0), (30.0, 45.0), (-20.0, 300.0), (90.0, -170.0)] {
        let o = pm
            .axis(TCP, &Vec3::new(10.0, -5.0, 3.0), &[a, 0.0, c])
            .unwrap();
        assert!((o - table_ac_axis(a, c)).norm() < 1e-15, "{a} {c}: {o}");
        let bc = BC.machine();
        let o = bc
            .axis(TCP, &Vec3::new(10.0, -5.0, 3.0), &BC.rotary(a, c))
            .unwrap();
        assert!((o - table_bc_axis(a, c)).norm() < 1e-15, "B{a} C{c}: {o}");
    }
    // TCP off: the angles are joints, there is no axis to carry.
    assert_eq!(
        pm.axis(ToolControl::OFF, &Vec3::zeros(), &[30.0, 0.0, 0.0]),
        None
    );
    // Y-Z-C-A: C follows the tip, the axis is not the angles' alone.
    let yzca = PlanMachine::from_machine(&Machine::builtin("yzca").unwrap()).unwrap();
    assert_eq!(
        yzca.axis(TCP, &Vec3::new(50.0, 0.0, 0.0), &[10.0, 0.0, 0.0]),
        None
    );
}

/// Kahraman et al.'s two-curve blend (§3) in physical time: the 90° line–line corner with
/// ℓ = 1 mm at v = 10 mm/s (T = 0.2 s), the axis turning on both legs. The upper curve is the
/// quintic of Step 6 through Step 5's rigid-body end data for a point h along the axis; Eq 7
/// gives the axis. The library's blend must give the same axis for every h.
#[test]
fn two_curve_blend_matches_closed_form() {
    let (v, t_blend) = (10.0, 0.2);
    // Legs: the tool tilts about the path normal on each (θ̇ = 0.2 rad/s and −0.3 rad/s).
    let o0 = table_ac_axis(20.0, 0.0);
    let oc = table_ac_axis(20.0 + 0.2f64.to_degrees() / v, 0.0);
    let k0 = Vec3::x();
    let k1 = Vec3::new(0.6, 0.0, 0.8);
    let (w0, w1) = (0.2, -0.3);
    let o1 = GreatCircle::new(oc, tezgah_motion::path::orient::rotate(&oc, &k1, w1 / v))
        .unwrap()
        .at(1.0);
    // Lower curve: the quintic's x(τ) = −1 + 10τ − 250τ³ + 625τ⁴, y(τ) = 250τ³ − 625τ⁴.
    let p = |tau: f64| {
        Vec3::new(
            -1.0 + 10.0 * tau - 250.0 * tau.powi(3) + 625.0 * tau.powi(4),
            250.0 * tau.powi(3) - 625.0 * tau.powi(4),
            0.0,
        )
    };
    // Step 5: Q̇ = Ṗ + h ω×O, Q̈ = P̈ + h(α×O + ω×(ω×O)), α = 0 at the blend's ends.
    let end_state = |pt: Vec3, pv: Vec3, o: Vec3, omega: Vec3, h: f64| State {
        p: pt + o * h,
        v: pv + omega.cross(&o) * h,
        a: omega.cross(&omega.cross(&o)) * h,
    };
    for h in [1.0, 35.0, 250.0] {
        let q = Quintic::hermite(
            end_state(p(0.0), Vec3::x() * v, o0, k0 * w0, h),
            end_state(p(t_blend), Vec3::y() * v, o1, k1 * w1, h),
            t_blend,
        )
        .unwrap();
        // The library's blend in u = τ/T: O′ = T·ω×O, O″ = T²·ω×(ω×O).
        let end = |o: Vec3, omega: Vec3| AxisEnd {
            axis: o,
            d1: omega.cross(&o) * t_blend,
            d2: omega.cross(&omega.cross(&o)) * (t_blend * t_blend),
        };
        let blend = AxisBlend::new(end(o0, k0 * w0), end(o1, k1 * w1)).unwrap();
        for i in 0..=20 {
            let tau = t_blend * i as f64 / 20.0;
            let eq7 = (q.point(tau) - p(tau)).normalize();
            let ours = blend.at(tau / t_blend);
            assert!(
                angle_between(&eq7, &ours) < 1e-12 * h.max(1.0) * 1e2,
                "h {h} τ {tau}: {eq7} {ours}"
            );
            // And the library's own upper curve is that quintic.
            let upper = blend.upper(&p(tau), h, tau / t_blend);
            assert!((upper - q.point(tau)).norm() < 1e-11 * h, "h {h} τ {tau}");
        }
        assert_eq!(blend.at(0.0), o0);
        assert_eq!(blend.at(1.0), o1);
    }
}

/// One step of a random 5-axis program: turn the heading by `turn` in XY, then go `len` mm
/// straight, or (with `arc`) along an arc of radius `len` and signed sweep `arc` rad (a helix
/// with `dz`), climbing `dz`, turning A by `da`° and C by `dc`°.
#[derive(Debug, Clone)]
struct Step {
    turn: f64,
    len: f64,
    dz: f64,
    da: f64,
    dc: f64,
    arc: Option<f64>,
}

fn step() -> impl Strategy<Value = Step> {
    (
        -2.9f64..2.9,
        0.3f64..15.0,
        -1.0f64..1.0,
        -8.0f64..8.0,
        prop_oneof![-40.0f64..-0.5, 0.5f64..40.0],
        prop_oneof![
            3 => Just(None),
            1 => (-2.5f64..2.5).prop_filter("a real sweep", |s| s.abs() > 0.05).prop_map(Some),
        ],
    )
        .prop_map(|(turn, len, dz, da, dc, arc)| Step {
            turn,
            len,
            dz,
            da,
            dc,
            arc,
        })
}

struct Program {
    kind: Trunnion,
    moves: Vec<Move>,
    /// Programmed points with their A and C (start first).
    points: Vec<(Vec3, f64, f64)>,
    /// For each move ending at `points[i]` that is an arc: its centre (XY, at the start's
    /// height) and signed sweep.
    arcs: Vec<Option<(Vec3, f64)>>,
}

fn rot(v: Vec3, a: f64) -> Vec3 {
    let (s, c) = a.sin_cos();
    Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

fn program(kind: Trunnion, steps: &[Step], tolerance: f64) -> Program {
    let start = (Vec3::new(5.0, -3.0, 2.0), 25.0, 10.0);
    let mut moves = vec![
        feed(1, 1200.0),
        mode(
            2,
            PathMode::Continuous {
                tolerance: Some(tolerance),
            },
        ),
        Move {
            line: 3,
            kind: MoveKind::Rapid {
                end: kind.pose(start.0, start.1, start.2),
            },
        },
    ];
    // The rapid starts from the origin (A 0, C 0).
    let mut points = vec![(Vec3::zeros(), 0.0, 0.0), start];
    let (mut pos, mut a, mut c) = start;
    let mut arcs = vec![None, None];
    let mut heading = Vec3::x();
    for (i, s) in steps.iter().enumerate() {
        heading = rot(heading, s.turn);
        a = (a + s.da).clamp(5.0, 80.0);
        c += s.dc;
        let line = i as u32 + 4;
        match s.arc {
            None => {
                pos += heading * s.len + Vec3::new(0.0, 0.0, s.dz);
                moves.push(Move {
                    line,
                    kind: MoveKind::Feed {
                        end: kind.pose(pos, a, c),
                    },
                });
                arcs.push(None);
            }
            Some(sweep) => {
                let side = if sweep > 0.0 { PI / 2.0 } else { -PI / 2.0 };
                let centre = pos + rot(heading, side) * s.len;
                let end = centre + rot(pos - centre, sweep) + Vec3::new(0.0, 0.0, s.dz);
                moves.push(Move {
                    line,
                    kind: MoveKind::Arc(tezgah_geom::ArcMove {
                        plane: tezgah_geom::Plane::XY,
                        end: kind.pose(end, a, c),
                        center: [centre.x, centre.y],
                        turn: if sweep > 0.0 { 1 } else { -1 },
                    }),
                });
                arcs.push(Some((centre, sweep)));
                heading = rot(heading, sweep);
                pos = end;
            }
        }
        points.push((pos, a, c));
    }
    Program {
        kind,
        moves,
        points,
        arcs,
    }
}

/// The programmed axis at the point of move `m` (from `points[m − 1]` to `points[m]`; the
/// move of source line L is m = L − 2) nearest `q`: the great circle between the closed-form axes
/// of its ends, at the fraction of its length (Kahraman et al., eq. 3). Returns (distance, axis).
fn programmed(prog: &Program, m: usize, q: &Vec3) -> (f64, Vec3) {
    let (p0, a0, c0) = prog.points[m - 1];
    let (p1, a1, c1) = prog.points[m];
    let axis = prog.kind.axis;
    let g = GreatCircle::new(axis(a0, c0), axis(a1, c1)).unwrap();
    let Some((centre, sweep)) = prog.arcs[m] else {
        let d = p1 - p0;
        let t = ((q - p0).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        return ((p0 + d * t - q).norm(), g.at(t));
    };
    // A helix is uniform in its parameter. The nearest point: the best of 64 samples over the
    // whole sweep, refined by golden sections between its neighbours. Seeding from `q`'s angle
    // about the centre (with a ±0.05 window) went wrong on steep helices: where the climb is
    // comparable to the arc's length in XY, the nearest point in 3-D is far from the point at
    // `q`'s XY angle (seed a3e38a55: a 0.16 mm arc climbing 0.71 mm — the window missed the
    // foot, the distance to the arc came out 1.79e-2 mm instead of 1.19e-2, the measure took
    // the axis of the wrong move, and reported 8.388e-2° for a blend whose largest deviation
    // is 7.56e-2°). The blends are within a fraction of a mm of the helix and a sweep is less
    // than π, so the distance has one basin there and the best sample lies in it.
    let at = |t: f64| centre + rot(p0 - centre, sweep * t) + Vec3::new(0.0, 0.0, (p1.z - p0.z) * t);
    let d = |t: f64| (at(t) - q).norm();
    const SAMPLES: usize = 64;
    let best = (0..=SAMPLES)
        .min_by(|&i, &j| d(i as f64 / SAMPLES as f64).total_cmp(&d(j as f64 / SAMPLES as f64)))
        .unwrap_or(0);
    let h = 1.0 / SAMPLES as f64;
    let (mut lo, mut hi) = (
        (best as f64 * h - h).max(0.0),
        (best as f64 * h + h).min(1.0),
    );
    let r = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let (x1, x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
        if d(x1) <= d(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    let t = 0.5 * (lo + hi);
    (d(t), g.at(t))
}

fn check(prog: &Program, items: &[PathItem], pm: &PlanMachine, angular: f64) -> Result<(), String> {
    let segs = segments(items);
    let budget = (1.0 - CHORD_SHARE) * angular.to_radians();
    // A move the axis alone cannot describe keeps linear angles (`ToolAxisMap::follows`: the
    // pole, whole turns, the long way round, a branch change, a reversal); the random walk
    // meets such moves now and then. The properties are those of the axis where it is carried,
    // and most segments carry it.
    let carried = segs.iter().filter(|s| s.axis.is_some()).count();
    if 2 * carried < segs.len() {
        return Err(format!(
            "only {carried} of {} segments carry an axis",
            segs.len()
        ));
    }
    for (i, s) in segs.iter().enumerate() {
        let Some(path) = s.axis else { continue };
        let (u0, u1) = s.curve.domain();
        for k in 0..=16 {
            let f = k as f64 / 16.0;
            let u = u0 + (u1 - u0) * f;
            let o = path.at(u, f);
            if !(o.iter().all(|x| x.is_finite()) && (o.norm() - 1.0).abs() < 1e-12) {
                return Err(format!("segment {i}: axis {o} at {f}"));
            }
        }
        // A blend (its line is the incoming move's) within the blend's share of the angular
        // tolerance of the programmed axis at the nearest point of its two moves.
        if let AxisPath::Blend(b) = path {
            let m = (s.line - 2) as usize;
            for k in 0..=100 {
                let u = k as f64 / 100.0;
                let tip = s.curve.point(u);
                let (da, oa) = programmed(prog, m, &tip);
                let (db, ob) = programmed(prog, m + 1, &tip);
                let reference = if da <= db { oa } else { ob };
                let dev = angle_between(&b.at(u), &reference);
                if dev > budget + 1e-12 {
                    return Err(format!(
                        "segment {i} (line {}): axis {:.3e}° off at u = {u}, budget {:.3e}°",
                        s.line,
                        dev.to_degrees(),
                        budget.to_degrees()
                    ));
                }
            }
        }
    }
    for (i, w) in segs.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let (Some(pa), Some(pb)) = (a.axis, b.axis) else {
            continue;
        };
        let (ea, sb) = (pa.ends()[1], pb.ends()[0]);
        if ea != sb {
            return Err(format!("joint {i}: axis {ea} then {sb}"));
        }
        if a.end == Junction::Smooth {
            let [_, a1, a2] = pa.arc_derivatives(&*a.curve, a.length, a.curve.domain().1, 1.0);
            let [_, b1, b2] = pb.arc_derivatives(&*b.curve, b.length, b.curve.domain().0, 0.0);
            // Within 1e-9 (per mm, per mm²), relative where the values exceed 1.
            let scale1 = a1.norm().max(b1.norm()).max(1.0);
            let scale2 = a2.norm().max(b2.norm()).max(1.0);
            if (a1 - b1).norm() > 1e-9 * scale1 || (a2 - b2).norm() > 1e-9 * scale2 {
                return Err(format!(
                    "joint {i} (line {}): O' {a1} vs {b1}, O'' {a2} vs {b2}",
                    a.line
                ));
            }
        }
    }
    // Programmed ends exactly: the machine's axis of the last programmed angles.
    let last = segs.last().ok_or("no segments")?;
    let &(p, a, c) = prog.points.last().unwrap();
    let want = pm.axis(TCP, &p, &prog.kind.rotary(a, c)).unwrap();
    if let Some(end) = last.axis {
        if end.ends()[1] != want {
            return Err(format!("end axis {:?} vs {want}", end.ends()));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, ..ProptestConfig::default() })]

    #[test]
    fn random_five_axis_polylines_and_arc_chains(
        steps in proptest::collection::vec(step(), 1..12),
        tol in prop_oneof![Just(0.01), Just(0.002), Just(0.1)],
        angular in prop_oneof![Just(0.1), Just(0.01), Just(1.0)],
        kind in prop_oneof![Just(AC), Just(BC)],
    ) {
        let pm = kind.machine();
        let prog = program(kind, &steps, tol);
        let items = build(prog.moves.clone(), &options(&pm, 0.01, angular)).unwrap();
        if let Err(e) = check(&prog, &items, &pm, angular) {
            return Err(TestCaseError::fail(e));
        }
    }
}

#[test]
fn a_blend_is_shortened_to_keep_the_axis_within_tolerance() {
    // A right-angle corner where the axis turns fast on both legs (20° per mm about different
    // normals): with a loose angular tolerance the blend takes its whole tip share, with a
    // tight one its legs shrink until the axis fits.
    let pm = machine();
    let moves = vec![
        feed(1, 600.0),
        g1ac(2, Vec3::new(1.0, 0.0, 0.0), 20.0, 0.0),
        g1ac(3, Vec3::new(1.0, 1.0, 0.0), 20.0, 20.0),
    ];
    let leg = |angular: f64| {
        let items = build(moves.clone(), &options(&pm, 0.05, angular)).unwrap();
        let segs = segments(&items);
        assert_eq!(segs.len(), 3, "line, blend, line");
        assert!(matches!(segs[1].axis, Some(AxisPath::Blend(_))));
        1.0 - segs[0].length
    };
    let loose = leg(5.0);
    let tight = leg(0.05);
    // Tip share only: ℓ = 8·0.4·0.05/(3 sin 45°).
    let tip_leg = 8.0 * 0.4 * 0.05 / (3.0 * (PI / 4.0).sin());
    assert!(
        (loose - tip_leg).abs() < 1e-10 * tip_leg,
        "{loose} {tip_leg}"
    );
    assert!(tight < 0.5 * loose && tight > 0.0, "{tight} {loose}");
}

/// Moves the tool axis alone cannot describe keep their angles linear: a reversal (C 180° at
/// A 90°), a whole turn of C, C turning with the tool along the C axis, the long way round.
/// The others carry the axis, and each move's joints end on the programmed ones.
#[test]
fn moves_the_axis_cannot_describe_keep_linear_angles() {
    let pm = machine();
    // (A, C) of each move, and whether each carries its axis.
    type Case = (&'static [(f64, f64)], &'static [bool]);
    let cases: [Case; 6] = [
        // Reversal at the second move.
        (&[(90.0, 0.0), (90.0, 180.0)], &[true, false]),
        // A whole turn.
        (&[(30.0, 0.0), (30.0, 360.0)], &[true, false]),
        // At the pole C is free: the axis stays while the program turns C (linear); tilting
        // away from the pole then starts from the programmed C (carried); leaving the pole
        // toward another C would make C jump (linear).
        (
            &[(0.0, 0.0), (0.0, 90.0), (30.0, 90.0)],
            &[true, false, true],
        ),
        (
            &[(0.0, 0.0), (30.0, 40.0), (40.0, 50.0)],
            &[true, false, true],
        ),
        // The long way round: C 0 → 350 (the axis would go −10°).
        (&[(30.0, 0.0), (30.0, 350.0)], &[true, false]),
        // The short way: carried.
        (&[(30.0, 0.0), (30.0, 40.0)], &[true, true]),
    ];
    for (angles, carried) in cases {
        let mut moves = vec![feed(1, 600.0)];
        let mut x = 0.0;
        for (i, &(a, c)) in angles.iter().enumerate() {
            x += 5.0;
            moves.push(g1ac(i as u32 + 2, Vec3::new(x, 0.0, 0.0), a, c));
        }
        let items = build(moves, &options(&pm, 0.01, 0.1)).unwrap();
        let segs = segments(&items);
        for (i, &want) in carried.iter().enumerate() {
            let line = i as u32 + 2;
            // Every segment of the move (trimmed pieces and, between carried moves, blends).
            let got = segs
                .iter()
                .filter(|s| s.line == line && !matches!(s.axis, Some(AxisPath::Blend(_))))
                .all(|s| s.axis.is_some() == want);
            assert!(got, "{angles:?}: move {i} carried {want}: {segs:#?}");
        }
    }
}

/// The steps of proptest's minimal case for seed a3e38a55 (see the regressions file): two
/// 0.3 mm moves with A turning +7.6° and −5.8°, a 7.7 mm climb, then a near-reversal (166°)
/// into a 0.16 mm arc of radius 0.4 mm that climbs 0.71 mm, C turning 9.1° on it.
fn steep_helix_steps() -> Vec<Step> {
    let line = |len: f64, dz: f64, da: f64| Step {
        turn: 0.0,
        len,
        dz,
        da,
        dc: -0.5,
        arc: None,
    };
    vec![
        line(0.3, 0.0, 7.6079392465252615),
        line(0.3, 0.0, -5.845072997466244),
        line(7.714835770347208, 0.7767298497238316, 0.0),
        Step {
            turn: -2.898690632201969,
            len: 0.4018260900819374,
            dz: 0.7052198192998504,
            da: 0.0,
            dc: 9.101412549802877,
            arc: Some(0.4050559148335982),
        },
    ]
}

/// Seed a3e38a55 as a named case. The blend of the reversal into the steep helix keeps its
/// axis within its share of the tolerance (7.56e-2° of 8e-2°); the random test reported
/// 8.388e-2° because its own nearest point on the helix was wrong. Checked here against a
/// brute-force nearest point on the helix (100 000 samples), and the builder's reported
/// largest deviation against this independent measure.
#[test]
fn a_reversal_into_a_steep_helix_keeps_the_axis_within_tolerance() {
    let pm = AC.machine();
    let prog = program(AC, &steep_helix_steps(), 0.1);
    let angular = 0.1;
    let mut smoother = tezgah_motion::path::smooth::Smoother::new(
        prog.moves.clone().into_iter(),
        options(&pm, 0.01, angular),
    )
    .unwrap();
    let items: Vec<PathItem> = smoother.by_ref().collect::<Result<_, _>>().unwrap();
    check(&prog, &items, &pm, angular).unwrap();

    // The helix is move 5 (source line 7); the blend before it is line 6's.
    let segs = segments(&items);
    let blend = segs
        .iter()
        .find(|s| s.line == 6 && matches!(s.axis, Some(AxisPath::Blend(_))))
        .expect("the reversal is blended");
    let Some(AxisPath::Blend(b)) = blend.axis else {
        unreachable!()
    };
    // The helix is 0.72 mm long: a sample every 7.2e-6 mm, so brute force is within 3.6e-6 mm
    // of the nearest distance.
    const SAMPLES: usize = 100_000;
    let brute = |m: usize, q: &Vec3| -> (f64, Vec3) {
        let (p0, a0, c0) = prog.points[m - 1];
        let (p1, a1, c1) = prog.points[m];
        let g = GreatCircle::new(table_ac_axis(a0, c0), table_ac_axis(a1, c1)).unwrap();
        let Some((centre, sweep)) = prog.arcs[m] else {
            // A line: the projection in closed form.
            let d = p1 - p0;
            let t = ((q - p0).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            return ((p0 + d * t - q).norm(), g.at(t));
        };
        let at =
            |t: f64| centre + rot(p0 - centre, sweep * t) + Vec3::new(0.0, 0.0, (p1.z - p0.z) * t);
        let (t, d) = (0..=SAMPLES)
            .map(|i| i as f64 / SAMPLES as f64)
            .map(|t| (t, (at(t) - q).norm()))
            .fold((0.0, f64::INFINITY), |x, y| if y.1 < x.1 { y } else { x });
        (d, g.at(t))
    };
    let budget = (1.0 - CHORD_SHARE) * angular.to_radians();
    let mut largest = 0.0f64;
    for k in 0..=400 {
        let u = k as f64 / 400.0;
        let tip = blend.curve.point(u);
        // The oracle's nearest point agrees with brute force (to its sampling).
        let (d, _) = programmed(&prog, 5, &tip);
        let ((da, oa), (db, ob)) = (brute(4, &tip), brute(5, &tip));
        assert!(d <= db + 1e-12 && db - d < 3.6e-6, "u {u}: {d} vs {db}");
        let dev = angle_between(&b.at(u), if da <= db { &oa } else { &ob });
        largest = largest.max(dev);
    }
    assert!(largest <= budget, "{}°", largest.to_degrees());
    // What the builder measured (golden sections up to the switch between the two moves)
    // is the same largest deviation: at least the sampled one, and above it by no more than
    // the axis turns in one sample step (about 4e-4°).
    let reported = smoother.stats().max_axis_deviation;
    assert!(
        reported >= largest.to_degrees() - 1e-9 && reported <= largest.to_degrees() + 1e-3,
        "{reported}° vs {}°",
        largest.to_degrees()
    );
}
