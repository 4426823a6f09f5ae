//! Property tests on random curves and polylines: NURBS derivatives agree with finite
//! differences, the arc-length map inverts itself within its bound, interpolation passes
//! through its points, approximation stays within tolerance of every point and segment (checked
//! by an independent dense sampling), and nothing produces NaN.

use proptest::prelude::*;
use tezgah_geom::deviation::point_segment_distance;
use tezgah_geom::fit::{approximate, interpolate, Parameterisation};
use tezgah_geom::{Arc, ArcLengthMap, ArcMove, Curve, Nurbs, Plane, Pose, Vec3};

fn vec3(r: f64) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A random clamped NURBS: degree 1–5, up to 8 extra control points, weights 0.2–5, interior
/// knots from positive increments (distinct, so no knot exceeds the multiplicity rule).
fn nurbs() -> impl Strategy<Value = Nurbs> {
    (1usize..=5, 0usize..=8).prop_flat_map(|(p, extra)| {
        let n = p + 1 + extra;
        (
            prop::collection::vec(vec3(50.0), n),
            prop::collection::vec(0.2f64..5.0, n),
            prop::collection::vec(0.2f64..1.0, extra + 1),
        )
            .prop_map(move |(pts, w, inc)| {
                let mut knots = vec![0.0; p + 1];
                let mut acc = 0.0;
                for d in &inc[..extra] {
                    acc += d;
                    knots.push(acc);
                }
                acc += inc[extra];
                knots.extend(std::iter::repeat_n(acc, p + 1));
                Nurbs::new(p, &pts, &w, knots).expect("generated NURBS is valid")
            })
    })
}

/// A point strictly inside a knot span chosen by `pick` in [0,1) and `frac` in [0.1, 0.9].
fn inside_span(c: &Nurbs, pick: f64, frac: f64) -> (f64, f64) {
    let b = c.breakpoints();
    let i = ((pick * (b.len() - 1) as f64) as usize).min(b.len() - 2);
    (b[i] + (b[i + 1] - b[i]) * frac, b[i + 1] - b[i])
}

/// Richardson-extrapolated central difference of `f` at `u` (error O(h⁴)).
fn diff(f: impl Fn(f64) -> Vec3, u: f64, h: f64) -> Vec3 {
    let d = |h: f64| (f(u + h) - f(u - h)) / (2.0 * h);
    (d(h / 2.0) * 4.0 - d(h)) / 3.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn nurbs_derivatives_match_finite_differences(
        c in nurbs(), pick in 0.0f64..1.0, frac in 0.1f64..0.9
    ) {
        let (u, width) = inside_span(&c, pick, frac);
        let h = 1e-3 * width;
        let d = c.derivs(u);
        prop_assert!(d.iter().all(|v| v.iter().all(|x| x.is_finite())));
        for k in 1..4 {
            let fd = diff(|x| c.derivs(x)[k - 1], u, h);
            // Scale: the derivative itself and the lower one over the span width.
            let scale = 1.0 + d[k].norm() + d[k - 1].norm() / width;
            let err = (fd - d[k]).norm();
            prop_assert!(err <= 1e-6 * scale, "k={} err={} scale={} u={}", k, err, scale, u);
        }
        let k = c.curvature(u);
        prop_assert!(!k.is_nan() && k >= 0.0);
        prop_assert!((c.point(u) - d[0]).norm() <= 1e-12 * (1.0 + d[0].norm()));
    }

    #[test]
    fn arc_length_map_inverts_within_its_bound(
        c in nurbs(), fracs in prop::collection::vec(0.0f64..=1.0, 8)
    ) {
        let tol = 1e-9;
        let m = ArcLengthMap::new(&c, tol).unwrap();
        let fine = ArcLengthMap::new(&c, 1e-12).unwrap();
        prop_assert!(m.length().is_finite() && m.length() > 0.0);
        prop_assert!((m.length() - fine.length()).abs() <= tol, "{} vs {}", m.length(), fine.length());
        let (a, b) = c.domain();
        let mut last_u = a;
        let mut sorted = fracs.clone();
        sorted.sort_by(f64::total_cmp);
        for f in sorted {
            let s = f * m.length();
            let u = m.u_at(&c, s);
            prop_assert!(u >= a && u <= b && u >= last_u);
            last_u = u;
            prop_assert!((m.s_at(&c, u) - s).abs() <= tol, "s={} back={}", s, m.s_at(&c, u));
            // The independent fine map agrees within the coarse map's bound.
            prop_assert!((fine.s_at(&c, u) - s).abs() <= 2.0 * tol);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A NURBS's panel quadrature (one span lookup for the eight nodes) gives the per-node
    /// rule's value bit for bit inside a knot span, and across knots falls back to it.
    #[test]
    fn speed_integral_is_the_per_node_rule(
        c in nurbs(), pick in 0.0f64..1.0, f0 in 0.0f64..1.0, f1 in 0.0f64..1.0
    ) {
        let (lo, hi) = (f0.min(f1), f0.max(f1));
        let (u, width) = inside_span(&c, pick, 0.5);
        let (a, b) = (u - 0.5 * width + lo * width, u - 0.5 * width + hi * width);
        let per_node = tezgah_geom::arclen::gauss_legendre_8(|x| c.speed(x), a, b);
        prop_assert_eq!(c.speed_integral(a, b).to_bits(), per_node.to_bits());
        let (da, db) = c.domain();
        let whole = tezgah_geom::arclen::gauss_legendre_8(|x| c.speed(x), da, db);
        prop_assert_eq!(c.speed_integral(da, db).to_bits(), whole.to_bits());
    }

    /// A NURBS's eight node speeds (one span lookup) are the per-node speeds bit for bit,
    /// inside a span and across knots (the fallback), and they sum to its panel quadrature.
    #[test]
    fn gauss_speeds_are_the_per_node_speeds(
        c in nurbs(), pick in 0.0f64..1.0, f0 in 0.0f64..1.0, f1 in 0.0f64..1.0
    ) {
        let (lo, hi) = (f0.min(f1), f0.max(f1));
        let (u, width) = inside_span(&c, pick, 0.5);
        let (a, b) = (u - 0.5 * width + lo * width, u - 0.5 * width + hi * width);
        let (da, db) = c.domain();
        for (a, b) in [(a, b), (da, db)] {
            let per_node = tezgah_geom::arclen::gauss_nodes_8(|x| c.speed(x), a, b);
            let got = c.gauss_speeds(a, b);
            prop_assert_eq!(got.map(f64::to_bits), per_node.map(f64::to_bits));
            // m ∓ h·x_i pairs: the first pair is nearest the middle, straddling it.
            let m = 0.5 * (a + b);
            if b > a {
                prop_assert!(got.iter().all(|v| v.is_finite()));
            }
            let weights = [0.362_683_783_378_362, 0.313_706_645_877_887_3,
                0.222_381_034_453_374_5, 0.101_228_536_290_376_3];
            let sum: f64 = got.chunks_exact(2).zip(weights).map(|(v, w)| w * (v[0] + v[1])).sum();
            let integral = c.speed_integral(a, b);
            prop_assert!((sum * 0.5 * (b - a) - integral).abs() <= 1e-12 * (1.0 + integral.abs()),
                "{} vs {} at m = {}", sum * 0.5 * (b - a), integral, m);
        }
    }

    /// The forward cursor finds the same u as `u_at` (to the map's bound in arc length) on
    /// sampling runs like the interpolator's — many small forward steps, crossing panels — and
    /// after arbitrary jumps back and forth; its point is C(u).
    #[test]
    fn arc_length_cursor_agrees_with_u_at(
        c in nurbs(), steps in 50usize..400, jumps in prop::collection::vec(0.0f64..=1.0, 6)
    ) {
        let tol = 1e-9;
        let m = ArcLengthMap::new(&c, tol).unwrap();
        let fine = ArcLengthMap::new(&c, 1e-12).unwrap();
        let len = m.length();
        let mut cur = m.cursor();
        let scale = 1.0 + c.point(c.domain().0).norm();
        // Forward steps, then jumps, then the knots' arc lengths: table entries (every span
        // starts a panel), where a Newton root would sit on the bracket's end.
        let ends: Vec<f64> = c.breakpoints().iter().map(|&u| m.s_at(&c, u)).collect();
        let ss = (0..=steps)
            .map(|i| len * i as f64 / steps as f64)
            .chain(jumps.iter().map(|f| f * len))
            .chain(ends);
        for s in ss {
            let at = m.advance(&c, &mut cur, s);
            let u = m.u_at(&c, s);
            let (a, b) = c.domain();
            prop_assert!(at.u >= a && at.u <= b);
            // Both within the bound of the true arc length s (fine map), so within 2·tol of
            // each other along the curve.
            let back = fine.s_at(&c, at.u);
            prop_assert!((back - s).abs() <= 2.0 * tol, "s={} back={}", s, back);
            prop_assert!((fine.s_at(&c, at.u) - fine.s_at(&c, u)).abs() <= 3.0 * tol);
            let exact = c.point(at.u);
            prop_assert!((at.point - exact).norm() <= 1e-12 * scale, "{} vs {}", at.point, exact);
        }
        // At a knot's own table length the cursor returns the knot itself, as `u_at` does.
        for u in c.breakpoints() {
            let s = m.s_at(&c, u);
            prop_assert_eq!(m.advance(&c, &mut cur, s).u, u);
            prop_assert_eq!(m.u_at(&c, s), u);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Knot insertion (A5.1) and splitting never change the curve, whatever the degree, the
    /// weights and the multiplicity already present; impossible insertions are typed errors.
    #[test]
    fn knot_insertion_and_split_keep_random_nurbs(
        c in nurbs(), pick in 0.0f64..1.0, frac in 0.0f64..1.0, times in 1usize..=5, on_knot: bool
    ) {
        let (a, b) = c.domain();
        let bps = c.breakpoints();
        let u = if on_knot && bps.len() > 2 {
            bps[1 + ((pick * (bps.len() - 2) as f64) as usize).min(bps.len() - 3)]
        } else {
            a + (b - a) * (0.01 + 0.98 * frac)
        };
        let grid: Vec<f64> = (0..=40).map(|i| a + (b - a) * i as f64 / 40.0).collect();
        let scale = 1.0 + grid.iter().map(|&x| c.point(x).norm()).fold(0.0, f64::max);
        match c.insert_knot(u, times) {
            Ok(d) => {
                for &x in &grid {
                    prop_assert!((d.point(x) - c.point(x)).norm() <= 1e-11 * scale);
                }
            }
            Err(_) => {
                let s = c.knots().iter().filter(|&&k| k == u).count();
                prop_assert!(s + times > c.degree());
            }
        }
        let (l, r) = c.split(u).unwrap();
        for &x in &grid {
            let part = if x <= u { &l } else { &r };
            prop_assert!((part.point(x) - c.point(x)).norm() <= 1e-11 * scale, "x={} u={}", x, u);
        }
    }
}

fn plane() -> impl Strategy<Value = Plane> {
    prop_oneof![Just(Plane::XY), Just(Plane::ZX), Just(Plane::YZ)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Random G2/G3 moves in any plane: exact end points, closed-form length equal to the
    /// quadrature, helix curvature r/(r²+c²), derivatives against finite differences.
    #[test]
    fn random_arcs_and_helices(
        pl in plane(), c in vec3(20.0), r in 0.1f64..30.0, a0 in -3.2f64..3.2, a1 in -3.2f64..3.2,
        turn in prop_oneof![-3i32..=-1, 1i32..=3], rise in -10.0f64..10.0, at in 0.05f64..0.95
    ) {
        let (i, j, k) = pl.axes();
        let mut s = [c.x, c.y, c.z, 0.0, 0.0, 0.0];
        s[i] = c[i] + r * a0.cos();
        s[j] = c[j] + r * a0.sin();
        let mut e = s;
        e[i] = c[i] + r * a1.cos();
        e[j] = c[j] + r * a1.sin();
        e[k] += rise;
        let mv = ArcMove { plane: pl, end: Pose(e), center: [c[i], c[j]], turn };
        let arc = Arc::from_move(&Pose(s), &mv).unwrap();
        prop_assert_eq!(arc.point(0.0), Vec3::new(s[0], s[1], s[2]));
        prop_assert_eq!(arc.point(1.0), Vec3::new(e[0], e[1], e[2]));
        prop_assert!(arc.sweep().signum() == f64::from(turn.signum()));
        prop_assert!(arc.sweep().abs() <= f64::from(turn.abs()) * std::f64::consts::TAU + 1e-9);
        let numeric = ArcLengthMap::new(&arc, 1e-10).unwrap().length();
        prop_assert!((numeric - arc.length()).abs() <= 1e-9 * (1.0 + arc.length()));
        let rad = arc.radius();
        let pitch = arc.rise() / arc.sweep();
        // The interpreter's centre makes start and end radii equal up to rounding here.
        prop_assert!((arc.end_radius() - rad).abs() < 1e-9);
        let kappa = rad / (rad * rad + pitch * pitch);
        prop_assert!((arc.curvature(at) - kappa).abs() <= 1e-6 * kappa);
        let d = arc.derivs(at);
        let h = 1e-4;
        for n in 1..4 {
            let fd = (arc.derivs(at + h)[n - 1] - arc.derivs(at - h)[n - 1]) / (2.0 * h);
            prop_assert!((fd - d[n]).norm() <= 1e-5 * (1.0 + d[n].norm() + d[n - 1].norm()));
        }
    }
}

/// A random polyline: segment lengths and turn angles bounded, as the compression stage will
/// hand over runs of short moves between sharp corners.
fn polyline(
    n: std::ops::RangeInclusive<usize>,
    len: (f64, f64),
    max_turn: f64,
) -> impl Strategy<Value = Vec<Vec3>> {
    let turn = move || -max_turn..max_turn;
    prop::collection::vec((len.0..len.1, turn(), turn()), n).prop_map(|steps| {
        let mut p = Vec3::zeros();
        let (mut heading, mut pitch, mut out) = (0.0f64, 0.0f64, vec![Vec3::zeros()]);
        for (l, dh, dp) in steps {
            heading += dh;
            pitch = (pitch + dp).clamp(-0.5, 0.5);
            let dir = Vec3::new(
                pitch.cos() * heading.cos(),
                pitch.cos() * heading.sin(),
                pitch.sin(),
            );
            p += dir * l;
            out.push(p);
        }
        out
    })
}

fn method() -> impl Strategy<Value = Parameterisation> {
    prop_oneof![
        Just(Parameterisation::Uniform),
        Just(Parameterisation::ChordLength),
        Just(Parameterisation::Centripetal),
        Just(Parameterisation::Universal),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn interpolation_passes_through_points(
        q in polyline(3..=40, (0.05, 5.0), 1.2), m in method(), p in 1usize..=5
    ) {
        prop_assume!(q.len() > p);
        let (c, t) = interpolate(&q, p, m).unwrap();
        prop_assert_eq!(t.len(), q.len());
        prop_assert!(t.windows(2).all(|w| w[0] < w[1]));
        for (k, qk) in q.iter().enumerate() {
            let e = (c.point(t[k]) - qk).norm();
            prop_assert!(e <= 1e-9, "point {} off by {}", k, e);
        }
        prop_assert!(c.length().is_finite());
    }

    #[test]
    fn approximation_stays_within_tolerance(
        q in polyline(2..=60, (0.05, 0.3), 0.6),
        tol in 0.001f64..0.05,
        m in prop_oneof![Just(Parameterisation::ChordLength), Just(Parameterisation::Centripetal)],
        p in 2usize..=5,
    ) {
        let a = approximate(&q, p, tol, m).unwrap();
        let c = &a.curve;
        prop_assert!(a.max_deviation <= tol);
        // Ends are exact.
        prop_assert_eq!(c.point(0.0), q[0]);
        prop_assert_eq!(c.point(1.0), *q.last().unwrap());
        // Independent check: dense sampling of every piece against its segment, and of the
        // curve near every point (slack for the sampling's own resolution only).
        let slack = 1e-9;
        for k in 0..q.len() - 1 {
            let (u0, u1) = (a.params[k], a.params[k + 1]);
            for i in 0..=64 {
                let pt = c.point(u0 + (u1 - u0) * i as f64 / 64.0);
                prop_assert!(pt.iter().all(|x| x.is_finite()));
                // Piece k against its segment and the neighbouring ones (the fitter's contract).
                let lo = k.saturating_sub(1);
                let hi = (k + 2).min(q.len() - 1);
                let d = (lo..hi)
                    .map(|j| point_segment_distance(&pt, &q[j], &q[j + 1]))
                    .fold(f64::INFINITY, f64::min);
                prop_assert!(d <= tol + slack, "segment {} piece off by {} > {}", k, d, tol);
            }
        }
        for (k, qk) in q.iter().enumerate().take(q.len() - 1).skip(1) {
            let (u0, u1) = (a.params[k - 1], a.params[k + 1]);
            let dist = |u: f64| (c.point(u) - qk).norm();
            let h = (u1 - u0) / 400.0;
            let i = (0..=400)
                .min_by(|&i, &j| dist(u0 + h * i as f64).total_cmp(&dist(u0 + h * j as f64)))
                .unwrap();
            // Ternary search between the neighbouring samples (distance is unimodal there).
            let (mut lo, mut hi) = ((u0 + h * (i as f64 - 1.0)).max(u0), (u0 + h * (i as f64 + 1.0)).min(u1));
            for _ in 0..100 {
                let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                if dist(m1) < dist(m2) { hi = m2 } else { lo = m1 }
            }
            let best = dist(0.5 * (lo + hi)).min(dist(u0 + h * i as f64));
            prop_assert!(best <= tol + slack, "point {} off by {} > {}", k, best, tol);
        }

    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// CAM output samples a smooth surface curve with short chords; on such runs (segments
    /// 0.05–0.3 mm, radius of curvature ≥ 3 mm so the chords themselves are within a few µm,
    /// tolerance 10 µm) the fit must need less than half as many control points as points
    /// (typically a tenth to a thirtieth; tight bends on short runs approach a third).
    #[test]
    fn approximation_compresses_sampled_smooth_curves(
        steps in prop::collection::vec(0.05f64..0.3, 40..=200),
        amp in 0.5f64..3.0, wave in 20.0f64..60.0, rise in -0.2f64..0.2,
    ) {
        let mut s = 0.0;
        let mut q = vec![Vec3::new(0.0, 0.0, amp)];
        for d in steps {
            s += d; // arc length along x is close enough to the chord for this purpose
            let w = std::f64::consts::TAU * s / wave;
            q.push(Vec3::new(s, amp * w.sin(), amp * w.cos() + rise * s));
        }
        let a = approximate(&q, 3, 0.01, Parameterisation::Centripetal).unwrap();
        prop_assert!(a.max_deviation <= 0.01);
        let n = a.curve.control_points().len();
        prop_assert!(2 * n < q.len(), "{} control points for {} points", n, q.len());
    }
}
