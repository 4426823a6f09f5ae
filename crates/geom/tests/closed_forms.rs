//! Closed forms: line, arc and helix lengths and curvature (1/r, r/(r²+c²)), arcs in every plane
//! with the right sense of rotation (Kelekçi, 2021, examples (2.21), (3.25), (2.24)), the exact
//! NURBS quarter circle, Bézier = clamped B-spline, and the values of Kahraman et al.'s quintic
//! blend (§3), worked out by hand.

use std::f64::consts::{FRAC_PI_2, PI, SQRT_2};

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{
    Arc, ArcLengthMap, ArcMove, Bezier, Curve, Line, Nurbs, Plane, Pose, Quintic, State, Vec3,
};

fn close(got: f64, want: f64, decimals: i32) -> bool {
    (got - want).abs() <= 0.5 * 10f64.powi(-decimals)
}

fn assert_close(got: f64, want: f64, decimals: i32, what: &str) {
    assert!(close(got, want, decimals), "{what}: got {got}, want {want}");
}

#[test]
fn line_is_arc_length_parameterised() {
    let l = Line::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 6.0, 15.0)).unwrap();
    assert_eq!(l.length(), 13.0);
    assert_eq!(l.domain(), (0.0, 13.0));
    assert_eq!(l.point(13.0), Vec3::new(4.0, 6.0, 15.0));
    assert_eq!(l.curvature(5.0), 0.0);
    let m = ArcLengthMap::new(&l, 1e-12).unwrap();
    assert!((m.length() - 13.0).abs() < 1e-12);
    assert!((m.u_at(&l, 6.5) - 6.5).abs() < 1e-12);
    // Kelekçi (2021), §2.1 examples.
    let l = Line::new(Vec3::new(2.0, -1.0, 3.0), Vec3::new(12.0, 7.0, -2.0)).unwrap();
    assert_close(l.length(), 13.7477, 4, "G01 X12 Y7 Z-2");
}

/// Centre of an R-form arc (Kelekçi, 2021, §2.2, vector form): right of the chord for CW with
/// R > 0, left for CCW; R < 0 flips the side.
fn r_centre(p0: (f64, f64), p1: (f64, f64), r: f64, cw: bool) -> [f64; 2] {
    let (dx, dy) = (p1.0 - p0.0, p1.1 - p0.1);
    let rho = dx.hypot(dy);
    let d = (r * r - rho * rho / 4.0).sqrt();
    let left = (-dy / rho, dx / rho);
    let side = if cw { -1.0 } else { 1.0 } * r.signum();
    [
        0.5 * (p0.0 + p1.0) + side * d * left.0,
        0.5 * (p0.1 + p1.1) + side * d * left.1,
    ]
}

fn xy_arc(start: Pose, end: (f64, f64, f64), r: f64, cw: bool) -> Arc {
    let center = r_centre((start.x(), start.y()), (end.0, end.1), r, cw);
    let mv = ArcMove {
        plane: Plane::XY,
        end: Pose::new(end.0, end.1, end.2, 0.0, 0.0, 0.0),
        center,
        turn: if cw { -1 } else { 1 },
    };
    Arc::from_move(&start, &mv).unwrap()
}

#[test]
fn arc_2_21_g02_r5_and_major_arc() {
    let s = Pose::new(0.24, 1.53, 0.0, 0.0, 0.0, 0.0);
    let a = xy_arc(s, (9.019, 2.975, 0.0), 5.0, true);
    assert_close(a.center().x, 5.0, 3, "cx");
    assert_close(a.center().y, 0.0, 3, "cy");
    assert_close(-a.sweep().to_degrees(), 125.674, 3, "sweep");
    assert_close(a.length(), 10.9672, 4, "length");
    assert_close(a.point(1.0).x, 9.019, 12, "end x");
    let a = xy_arc(s, (9.019, 2.975, 0.0), -5.0, true);
    assert_close(a.center().x, 4.2588, 4, "cx");
    assert_close(a.center().y, 4.5048, 4, "cy");
    assert_close(-a.sweep().to_degrees(), 234.326, 3, "major sweep");
    assert_close(a.length(), 20.4488, 4, "major length");
}

#[test]
fn arc_3_25_g02_r14_976() {
    let s = Pose::new(0.2407, 1.533, 0.0, 0.0, 0.0, 0.0);
    let a = xy_arc(s, (9.019, 2.975, 0.0), 14.976, true);
    assert_close(a.center().x, 6.9479, 4, "cx");
    assert_close(a.center().y, -11.8571, 4, "cy");
    assert_close(-a.sweep().to_degrees(), 34.5558, 4, "sweep");
    assert_close(a.length(), 9.03222, 5, "length");
}

#[test]
fn helix_2_24_g03_and_curvature() {
    let s = Pose::new(14.32, 5.66, 0.0, 0.0, 0.0, 0.0);
    let a = xy_arc(s, (14.94, 1.749, 2.0), 14.976, false);
    assert_close(a.center().x, 29.2915, 4, "cx");
    assert_close(a.center().y, 6.0287, 4, "cy");
    assert_close(a.sweep().to_degrees(), 15.194, 3, "sweep");
    let planar = a.radius() * a.sweep();
    assert_close(planar, 3.9715, 4, "planar length");
    // The helix's own length includes the lead (F is along the helix, pitch included).
    assert!((a.length() - planar.hypot(2.0)).abs() < 1e-12);
    let numeric = ArcLengthMap::new(&a, 1e-12).unwrap().length();
    assert!((numeric - a.length()).abs() < 1e-11);
    // κ = r / (r² + c²), c = lead per radian.
    let (r, c) = (a.radius(), a.rise() / a.sweep());
    for u in [0.0, 0.3, 1.0] {
        assert!((a.curvature(u) - r / (r * r + c * c)).abs() < 1e-12);
    }
    assert!((a.point(1.0) - Vec3::new(14.94, 1.749, 2.0)).norm() < 1e-9);
    let a = xy_arc(s, (14.94, 1.749, 2.0), -14.976, false);
    assert_close(a.center().x, -0.0315, 4, "cx");
    assert_close(a.sweep().to_degrees(), 344.806, 3, "major sweep");
    assert_close(a.radius() * a.sweep(), 90.1255, 4, "major planar length");
}

fn quarter(plane: Plane, start: [f64; 3], end: [f64; 3], turn: i32) -> Arc {
    let mv = ArcMove {
        plane,
        end: Pose::new(end[0], end[1], end[2], 0.0, 0.0, 0.0),
        center: [0.0, 0.0],
        turn,
    };
    Arc::from_move(&Pose::new(start[0], start[1], start[2], 0., 0., 0.), &mv).unwrap()
}

#[test]
fn every_plane_turns_the_right_way() {
    let h = 0.5f64.sqrt();
    // G17 G3: X toward Y seen from +Z.
    let a = quarter(Plane::XY, [1., 0., 0.], [0., 1., 0.], 1);
    assert!((a.point(0.5) - Vec3::new(h, h, 0.)).norm() < 1e-12);
    // G18 G3: Z toward X seen from +Y (the plane LinuxCNC and Fanuc call ZX).
    let a = quarter(Plane::ZX, [0., 0., 1.], [1., 0., 0.], 1);
    assert!((a.sweep() - FRAC_PI_2).abs() < 1e-12);
    assert!((a.point(0.5) - Vec3::new(h, 0., h)).norm() < 1e-12);
    let a = quarter(Plane::ZX, [0., 0., 1.], [1., 0., 0.], -1);
    assert!((a.sweep() + 3.0 * FRAC_PI_2).abs() < 1e-12);
    assert!((a.point(0.5) - Vec3::new(-h, 0., -h)).norm() < 1e-12);
    // G19 G3: Y toward Z seen from +X.
    let a = quarter(Plane::YZ, [0., 1., 0.], [0., 0., 1.], 1);
    assert!((a.point(0.5) - Vec3::new(0., h, h)).norm() < 1e-12);
    // Helical lead goes along the plane normal: Y for G18.
    let a = quarter(Plane::ZX, [0., 0., 1.], [1., 3., 0.], 1);
    assert!((a.point(0.5).y - 1.5).abs() < 1e-12);
    assert!((a.point(1.0) - Vec3::new(1., 3., 0.)).norm() < 1e-12);
}

#[test]
fn full_circles_and_extra_turns() {
    let a = quarter(Plane::XY, [2., 0., 0.], [2., 0., 0.], -1);
    assert!((a.sweep() + 2.0 * PI).abs() < 1e-12);
    assert!((a.length() - 4.0 * PI).abs() < 1e-12);
    let a = quarter(Plane::XY, [2., 0., 0.], [0., 2., 5.], 3);
    assert!((a.sweep() - (FRAC_PI_2 + 4.0 * PI)).abs() < 1e-12);
    for u in [0.1, 0.5, 0.9] {
        assert!(
            (a.curvature(u) - {
                let (r, c) = (2.0, 5.0 / a.sweep());
                r / (r * r + c * c)
            })
            .abs()
                < 1e-12
        );
    }
}

#[test]
fn arc_rejects_bad_moves() {
    let mv = ArcMove {
        plane: Plane::XY,
        end: Pose::new(1., 0., 0., 0., 0., 0.),
        center: [0.0, 0.0],
        turn: 0,
    };
    assert!(Arc::from_move(&Pose::new(0., 1., 0., 0., 0., 0.), &mv).is_err());
    let mv = ArcMove { turn: 1, ..mv };
    assert!(Arc::from_move(&Pose::ZERO, &mv).is_err());
    let bad = Pose::new(f64::NAN, 1., 0., 0., 0., 0.);
    assert!(Arc::from_move(&bad, &mv).is_err());
}

#[test]
fn nurbs_quarter_circle_is_exact() {
    let r = 7.5;
    let pts = [
        Vec3::new(r, 0., 0.),
        Vec3::new(r, r, 0.),
        Vec3::new(0., r, 0.),
    ];
    let w = [1.0, SQRT_2 / 2.0, 1.0];
    let c = Nurbs::new(2, &pts, &w, vec![0., 0., 0., 1., 1., 1.]).unwrap();
    for i in 0..=20 {
        let u = i as f64 / 20.0;
        assert!((c.point(u).norm() - r).abs() < 1e-13);
        assert!((c.curvature(u) - 1.0 / r).abs() < 1e-13);
        // The tangent is perpendicular to the radius.
        assert!(c.point(u).dot(&c.d1(u)).abs() < 1e-11);
    }
    assert!((c.point(0.5) - Vec3::new(r, r, 0.) * (SQRT_2 / 2.0)).norm() < 1e-14);
    let m = ArcLengthMap::new(&c, 1e-12).unwrap();
    assert!((m.length() - FRAC_PI_2 * r).abs() < 1e-11);
    // Equal arc length means equal angle.
    let u = m.u_at(&c, FRAC_PI_2 * r / 3.0);
    let p = c.point(u);
    assert!((p.y.atan2(p.x) - PI / 6.0).abs() < 1e-11);
}

#[test]
fn bezier_equals_clamped_bspline() {
    let pts = vec![
        Vec3::new(0., 0., 0.),
        Vec3::new(1., 3., -1.),
        Vec3::new(4., -2., 2.),
        Vec3::new(6., 1., 0.5),
    ];
    let b = Bezier::new(pts.clone()).unwrap();
    let n = Nurbs::bspline(3, &pts, vec![0., 0., 0., 0., 1., 1., 1., 1.]).unwrap();
    for i in 0..=10 {
        let u = i as f64 / 10.0;
        let (x, y) = (b.derivs(u), n.derivs(u));
        for k in 0..4 {
            assert!((x[k] - y[k]).norm() < 1e-11, "k={k} u={u}");
        }
    }
    assert!(Bezier::new(vec![Vec3::zeros()]).is_err());
}

fn st(p: [f64; 3], v: [f64; 3], a: [f64; 3]) -> State {
    State {
        p: p.into(),
        v: v.into(),
        a: a.into(),
    }
}

#[test]
fn quintic_coefficients() {
    let q = Quintic::hermite(
        st([1., 0., 0.], [2., 0., 0.], [3., 0., 0.]),
        st([5., 0., 0.], [-1., 0., 0.], [0.5, 0., 0.]),
        0.7,
    )
    .unwrap();
    let c = q.coefficients();
    let want = [1.0, 2.0, 1.5, 94.220117, -215.493544, 126.658535];
    for (k, w) in want.iter().enumerate() {
        assert_close(c[k].x, *w, 6, "coefficient");
    }
    let [p, v, a, _] = q.derivs(0.7);
    assert!((p.x - 5.0).abs() < 1e-12 && (v.x + 1.0).abs() < 1e-11 && (a.x - 0.5).abs() < 1e-9);
    // A pure line stays a line.
    let q = Quintic::hermite(
        st([0., 0., 0.], [10., 0., 0.], [0.; 3]),
        st([1., 0., 0.], [10., 0., 0.], [0.; 3]),
        0.1,
    )
    .unwrap();
    let c = q.coefficients();
    assert!(c[2..].iter().all(|v| v.norm() < 1e-9) && (c[1].x - 10.0).abs() < 1e-12);
    assert!(Quintic::hermite(
        st([0.; 3], [0.; 3], [0.; 3]),
        st([0.; 3], [0.; 3], [0.; 3]),
        0.0
    )
    .is_err());
}

/// Line–line corner blend of Kahraman et al. (§3): legs `ell`, speed `v`, turn `phi`.
fn corner(ell: f64, v: f64, phi: f64) -> (Quintic, Vec3) {
    let t0 = Vec3::new(1.0, 0.0, 0.0);
    let t1 = Vec3::new(phi.cos(), phi.sin(), 0.0);
    let c = Vec3::zeros();
    let q = Quintic::hermite(
        State {
            p: c - t0 * ell,
            v: t0 * v,
            a: Vec3::zeros(),
        },
        State {
            p: c + t1 * ell,
            v: t1 * v,
            a: Vec3::zeros(),
        },
        2.0 * ell / v,
    )
    .unwrap();
    (q, c)
}

fn peaks(q: &Quintic) -> (f64, f64, f64) {
    let n = 2000;
    let (mut amax, mut jmax, mut vmin) = (0.0f64, 0.0f64, f64::INFINITY);
    for i in 0..=n {
        let [_, v, a, j] = q.derivs(q.duration() * i as f64 / n as f64);
        amax = amax.max(a.norm());
        jmax = jmax.max(j.norm());
        vmin = vmin.min(v.norm());
    }
    (amax, jmax, vmin)
}

#[test]
fn quintic_corner_blends() {
    let (q, c) = corner(1.0, 10.0, FRAC_PI_2);
    let k = q.coefficients();
    // x(τ) = −1 + 10τ − 250τ³ + 625τ⁴, y(τ) = 250τ³ − 625τ⁴.
    for (got, want) in k
        .iter()
        .map(|v| v.x)
        .zip([-1.0, 10.0, 0.0, -250.0, 625.0, 0.0])
    {
        assert!((got - want).abs() < 1e-9, "{k:?}");
    }
    let dev = closest_point(&q, &c, 0.0, q.duration(), 64).distance;
    assert_close(dev, 0.265165, 6, "corner deviation");
    let (a, j, v) = peaks(&q);
    assert_close(a, 106.066, 3, "peak acceleration");
    assert_close(j, 2121.32, 2, "peak jerk");
    assert_close(v, 7.0711, 4, "minimum speed");
    let (q, c) = corner(0.5, 10.0, PI / 4.0);
    assert_close(
        closest_point(&q, &c, 0.0, q.duration(), 64).distance,
        0.071753,
        6,
        "δ 45°",
    );
    let (a, j, v) = peaks(&q);
    assert_close(a, 114.805, 3, "a 45°");
    assert_close(j, 4592.20, 2, "j 45°");
    assert_close(v, 9.2388, 4, "v 45°");
    // The Bézier form is the same curve.
    let b = q.to_bezier();
    assert_eq!(b.degree(), 5);
    for i in 0..=10 {
        let u = i as f64 / 10.0;
        assert!((b.point(u) - q.point(u * q.duration())).norm() < 1e-13);
    }
}

#[test]
fn knot_insertion_and_split_keep_the_curve() {
    let pts: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new(i as f64, ((i * 3) % 5) as f64, (i % 3) as f64))
        .collect();
    let w = [1.0, 2.0, 0.5, 1.0, 3.0, 1.0, 0.7, 1.0];
    let knots = vec![0., 0., 0., 0., 0.2, 0.4, 0.4, 0.7, 1., 1., 1., 1.];
    let c = Nurbs::new(3, &pts, &w, knots).unwrap();
    let grid: Vec<f64> = (0..=50).map(|i| i as f64 / 50.0).collect();
    for (u, times) in [(0.3, 1), (0.3, 3), (0.4, 1), (0.55, 2)] {
        let d = c.insert_knot(u, times).unwrap();
        assert_eq!(d.control_points().len(), 8 + times);
        for &x in &grid {
            assert!((d.point(x) - c.point(x)).norm() < 1e-12, "u={u} x={x}");
        }
    }
    // 0.4 already appears twice: a third and fourth copy would exceed the degree.
    assert!(c.insert_knot(0.4, 2).is_err());
    assert!(c.insert_knot(0.0, 1).is_err());
    for u in [0.1, 0.4, 0.63] {
        let (l, r) = c.split(u).unwrap();
        assert_eq!(l.domain(), (0.0, u));
        assert_eq!(r.domain(), (u, 1.0));
        for &x in &grid {
            let part = if x <= u { &l } else { &r };
            assert!(
                (part.point(x) - c.point(x)).norm() < 1e-12,
                "split {u} at {x}"
            );
        }
        assert!((l.point(u) - r.point(u)).norm() < 1e-13);
        assert!((l.length() + r.length() - c.length()).abs() < 1e-9);
    }
}

#[test]
fn arc_length_derivatives_of_a_helix_and_a_nurbs() {
    // Helix r = 2, lead 3 over one turn: |dC/ds| = 1, |d²C/ds²| = κ = r/(r²+c²), and
    // d³C/ds³ = −κ² T + κτ B, so |d³C/ds³| = κ·sqrt(κ² + τ²) with τ = c/(r²+c²).
    let a = Arc::new(
        Vec3::zeros(),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::z(),
        2.0 * PI,
        3.0,
    )
    .unwrap();
    let m = ArcLengthMap::new(&a, 1e-12).unwrap();
    let (r, c) = (2.0, 3.0 / (2.0 * PI));
    let (k, tau) = (r / (r * r + c * c), c / (r * r + c * c));
    for s in [0.0, 1.0, 5.5, m.length()] {
        let [_, t, n, j] = m.derivs_at(&a, s);
        assert!((t.norm() - 1.0).abs() < 1e-12);
        assert!((n.norm() - k).abs() < 1e-12);
        assert!((j.norm() - k * (k * k + tau * tau).sqrt()).abs() < 1e-12);
    }
    // A rational curve against finite differences of C(u(s)).
    let pts = [
        Vec3::new(0., 0., 0.),
        Vec3::new(1., 2., 0.),
        Vec3::new(3., 2., 1.),
        Vec3::new(4., 0., 2.),
    ];
    let n = Nurbs::new(
        3,
        &pts,
        &[1.0, 3.0, 0.5, 1.0],
        vec![0., 0., 0., 0., 1., 1., 1., 1.],
    )
    .unwrap();
    let m = ArcLengthMap::new(&n, 1e-13).unwrap();
    let s = 0.4 * m.length();
    let h = 1e-3;
    let d = m.derivs_at(&n, s);
    let at = |x: f64| m.derivs_at(&n, x);
    let (up, down) = (at(s + h), at(s - h));
    for (k, dk) in d.iter().enumerate().skip(1) {
        let fd = (up[k - 1] - down[k - 1]) / (2.0 * h);
        assert!((fd - dk).norm() < 1e-5 * (1.0 + dk.norm()), "k={k}");
    }
    assert!((m.point_at(&n, s) - d[0]).norm() < 1e-15);
}

#[test]
fn deviation_measures_on_a_circle() {
    use tezgah_geom::deviation::{curve_to_curve, curve_to_polyline, polyline_to_curve};
    // Quarter circle r = 10 as an exact NURBS and as an arc: they coincide.
    let r = 10.0;
    let pts = [
        Vec3::new(r, 0., 0.),
        Vec3::new(r, r, 0.),
        Vec3::new(0., r, 0.),
    ];
    let nurbs = Nurbs::new(
        2,
        &pts,
        &[1.0, SQRT_2 / 2.0, 1.0],
        vec![0., 0., 0., 1., 1., 1.],
    )
    .unwrap();
    let arc = Arc::new(
        Vec3::zeros(),
        Vec3::new(r, 0., 0.),
        Vec3::z(),
        FRAC_PI_2,
        0.0,
    )
    .unwrap();
    assert!(curve_to_curve(&nurbs, &arc, 16).distance < 1e-9);
    // A chordal polyline of n pieces: curve → polyline is the sagitta r(1 − cos(θ/2)), found
    // mid-chord; polyline → curve is the same.
    let n = 6;
    let poly: Vec<Vec3> = (0..=n)
        .map(|i| {
            let a = FRAC_PI_2 * i as f64 / n as f64;
            Vec3::new(r * a.cos(), r * a.sin(), 0.0)
        })
        .collect();
    let sagitta = r * (1.0 - (FRAC_PI_2 / n as f64 / 2.0).cos());
    let d = curve_to_polyline(&arc, &poly, 16);
    assert!(
        (d.distance - sagitta).abs() < 1e-9,
        "{} vs {sagitta}",
        d.distance
    );
    assert!((polyline_to_curve(&arc, &poly, 16) - sagitta).abs() < 1e-9);
}

#[test]
fn programmed_end_points_are_exact() {
    // Joints between path pieces must meet bit for bit, not to rounding.
    let s = Pose::new(0.1, 0.2, 0.3, 0.0, 0.0, 0.0);
    let mv = ArcMove {
        plane: Plane::XY,
        end: Pose::new(7.3, 1.9, 2.2, 0.0, 0.0, 0.0),
        center: [3.7, 1.05],
        turn: -2,
    };
    let a = Arc::from_move(&s, &mv).unwrap();
    assert_eq!(a.point(0.0), Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(a.point(1.0), Vec3::new(7.3, 1.9, 2.2));
    assert_eq!(a.derivs(1.0)[0], Vec3::new(7.3, 1.9, 2.2));
    let l = Line::new(Vec3::new(0.1, 0.2, 0.3), Vec3::new(7.3, 1.9, 2.2)).unwrap();
    assert_eq!(l.point(l.length()), Vec3::new(7.3, 1.9, 2.2));
    assert_eq!(l.point(0.0), Vec3::new(0.1, 0.2, 0.3));
}
