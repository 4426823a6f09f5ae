//! NURBS surfaces against closed forms and properties: exact quadrics (quarter cylinder, sphere
//! octant, torus patch) keep every point on the shape with radial normals and the textbook
//! principal curvatures; a bilinear patch matches its closed-form derivatives; random rational
//! surfaces match finite differences; iso curves equal the surface along their iso line; bad
//! input gives typed errors.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use proptest::prelude::*;
use tezgah_geom::{Curve, CurveError, NurbsSurface, SurfaceError, Vec3};

/// Control points and weights of the rational quadratic quarter circle (P&T §7.3).
const QUARTER: [(f64, f64, f64); 3] = [(1.0, 0.0, 1.0), (1.0, 1.0, FRAC_1_SQRT_2), (0.0, 1.0, 1.0)];
const QUAD_KNOTS: [f64; 6] = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];

/// The surface of revolution (P&T A8.1, a quarter turn about z) of a rational quadratic profile
/// in the xz half-plane given as `(x, z, w)`: u turns about z, v runs along the profile, and
/// `P_ij = (x_j·c_i, z_j)`, `w_ij = w_i·w_j` with `c_i`, `w_i` the quarter circle's.
fn revolve(profile: [(f64, f64, f64); 3]) -> NurbsSurface {
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for (cx, cy, cw) in QUARTER {
        for (x, z, pw) in profile {
            pts.push(Vec3::new(x * cx, x * cy, z));
            w.push(cw * pw);
        }
    }
    NurbsSurface::new(2, 2, &pts, &w, QUAD_KNOTS.to_vec(), QUAD_KNOTS.to_vec()).unwrap()
}

/// A `n × n` grid of parameters covering `[0, 1]²`, ends included.
fn grid(n: usize) -> impl Iterator<Item = (f64, f64)> {
    (0..=n).flat_map(move |i| (0..=n).map(move |j| (i as f64 / n as f64, j as f64 / n as f64)))
}

#[test]
fn quarter_cylinder_is_exact_with_radial_normals() {
    let (r, h) = (5.0, 10.0);
    let mut pts = Vec::new();
    let mut w = Vec::new();
    for (cx, cy, cw) in QUARTER {
        for z in [0.0, h] {
            pts.push(Vec3::new(r * cx, r * cy, z));
            w.push(cw);
        }
    }
    let knots_v = vec![0.0, 0.0, 1.0, 1.0];
    let s = NurbsSurface::new(2, 1, &pts, &w, QUAD_KNOTS.to_vec(), knots_v).unwrap();
    assert_eq!(s.grid_size(), (3, 2));
    for (u, v) in grid(40) {
        let p = s.point(u, v);
        assert!((p.xy().norm() - r).abs() < 1e-12, "u={u} v={v} p={p}");
        assert!((p.z - h * v).abs() < 1e-12);
        let n = s.normal(u, v).unwrap();
        let radial = Vec3::new(p.x, p.y, 0.0) / r;
        assert!((n.into_inner() - radial).norm() < 1e-12, "u={u} v={v}");
        // Bends away from the outward normal across the axis, straight along it.
        let (k1, k2) = s.fundamental_forms(u, v).unwrap().principal_curvatures();
        assert!(
            k1.abs() < 1e-12 && (k2 + 1.0 / r).abs() < 1e-12,
            "{k1} {k2}"
        );
    }
    // The u-iso curve is the quarter circle: the curve layer's arc length sees π r / 2.
    let arc = s.u_iso(0.3);
    assert!((arc.length() - PI * r / 2.0).abs() < 1e-9);
    assert!((s.v_iso(0.0).length() - h).abs() < 1e-12);
}

#[test]
fn sphere_octant_points_on_sphere_normals_radial() {
    let r = 7.0;
    let s = revolve([(r, 0.0, 1.0), (r, r, FRAC_1_SQRT_2), (0.0, r, 1.0)]);
    for (u, v) in grid(40) {
        let p = s.point(u, v);
        assert!((p.norm() - r).abs() < 1e-12, "u={u} v={v} |p|={}", p.norm());
        assert!(p.iter().all(|&c| c >= -1e-12), "stays in the first octant");
        if v == 1.0 {
            // The pole: the whole row collapses, S_u = 0 and the normal is undefined.
            assert!(s.normal(u, v).is_none());
            assert!((p - Vec3::new(0.0, 0.0, r)).norm() < 1e-12);
            continue;
        }
        let n = s.normal(u, v).unwrap();
        assert!((n.into_inner() - p / r).norm() < 1e-12, "u={u} v={v}");
        let ff = s.fundamental_forms(u, v).unwrap();
        let (k1, k2) = ff.principal_curvatures();
        assert!(
            (k1 + 1.0 / r).abs() < 1e-9 && (k2 + 1.0 / r).abs() < 1e-9,
            "{k1} {k2}"
        );
        assert!((ff.gaussian_curvature() - 1.0 / (r * r)).abs() < 1e-9);
    }
}

#[test]
fn torus_patch_points_on_torus_and_curvatures_textbook() {
    // Tube radius r about a centre circle of radius R in the xy plane; the quarter of the tube
    // from the outer equator (φ = 0) to the top (φ = π/2).
    let (big, r) = (20.0, 4.0);
    let s = revolve([
        (big + r, 0.0, 1.0),
        (big + r, r, FRAC_1_SQRT_2),
        (big, r, 1.0),
    ]);
    for (u, v) in grid(40) {
        let p = s.point(u, v);
        let rho = p.xy().norm();
        let tube = ((rho - big).powi(2) + p.z * p.z).sqrt();
        assert!((tube - r).abs() < 1e-12, "u={u} v={v} distance={tube}");
        let centre = Vec3::new(p.x, p.y, 0.0) * (big / rho);
        let n = s.normal(u, v).unwrap().into_inner();
        assert!((n - (p - centre) / r).norm() < 1e-12, "u={u} v={v}");
        // Meridian: −1/r; parallel: −cos φ / ρ (Meusnier), both away from the outward normal.
        let cos_phi = (rho - big) / r;
        let (k1, k2) = s.fundamental_forms(u, v).unwrap().principal_curvatures();
        assert!((k1 + cos_phi / rho).abs() < 1e-9, "u={u} v={v} k1={k1}");
        assert!((k2 + 1.0 / r).abs() < 1e-9, "u={u} v={v} k2={k2}");
        // κ₁ along the parallel (horizontal, tangent to the circle about z), κ₂ along the
        // meridian (in the plane of p and z).
        let pc = s.principal_curvatures(u, v).unwrap();
        let parallel = Vec3::new(-p.y, p.x, 0.0) / rho;
        assert!(
            (pc.d1.dot(&parallel).abs() - 1.0).abs() < 1e-9,
            "u={u} v={v}"
        );
        assert!(pc.d2.dot(&parallel).abs() < 1e-9);
        assert!((pc.k1 - k1).abs() < 1e-15 && (pc.k2 - k2).abs() < 1e-15);
    }
}

#[test]
fn bilinear_patch_matches_closed_form_derivatives() {
    // The hyperbolic paraboloid S(u, v) = (u, v, uv) on [0, 1]².
    let pts = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let k = vec![0.0, 0.0, 1.0, 1.0];
    let s = NurbsSurface::bspline(1, 1, &pts, k.clone(), k).unwrap();
    for (u, v) in grid(16) {
        let d = s.derivs(u, v);
        let close = |a: Vec3, b: Vec3| (a - b).norm() < 1e-15;
        assert!(close(d.point, Vec3::new(u, v, u * v)));
        assert!(close(d.su, Vec3::new(1.0, 0.0, v)));
        assert!(close(d.sv, Vec3::new(0.0, 1.0, u)));
        assert!(close(d.suu, Vec3::zeros()) && close(d.svv, Vec3::zeros()));
        assert!(close(d.suv, Vec3::new(0.0, 0.0, 1.0)));
        // z = xy: K = −1/(1+x²+y²)², H = −xy/(1+x²+y²)^{3/2}.
        let q = 1.0 + u * u + v * v;
        let ff = s.fundamental_forms(u, v).unwrap();
        assert!((ff.gaussian_curvature() + 1.0 / (q * q)).abs() < 1e-14);
        assert!((ff.mean_curvature() + u * v / q.powf(1.5)).abs() < 1e-14);
        let n = s.normal(u, v).unwrap().into_inner();
        assert!((n - Vec3::new(-v, -u, 1.0) / q.sqrt()).norm() < 1e-15);
    }
}

#[test]
fn parameters_outside_the_domain_are_clamped_never_nan() {
    let s = revolve([(3.0, 0.0, 1.0), (3.0, 3.0, FRAC_1_SQRT_2), (0.0, 3.0, 1.0)]);
    assert_eq!(s.point(-1.0, f64::NAN), s.point(0.0, 0.0));
    assert_eq!(s.point(f64::INFINITY, 2.0), s.point(1.0, 1.0));
    let d = s.derivs(f64::NAN, f64::NEG_INFINITY);
    assert!([d.point, d.su, d.sv, d.suu, d.suv, d.svv]
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite())));
}

#[test]
fn constructor_rejects_bad_input_with_typed_errors() {
    let pts = vec![Vec3::zeros(); 4];
    let k = || vec![0.0, 0.0, 1.0, 1.0];
    let new = |pts: &[Vec3], w: &[f64], ku: Vec<f64>, kv: Vec<f64>| {
        NurbsSurface::new(1, 1, pts, w, ku, kv)
    };
    let w = [1.0; 4];
    assert_eq!(
        NurbsSurface::new(0, 1, &pts, &w, k(), k()),
        Err(SurfaceError::U(CurveError::Degree { degree: 0, max: 15 }))
    );
    assert_eq!(
        new(&pts, &w, k(), vec![0.0, 1.0, 0.5, 2.0]),
        Err(SurfaceError::V(CurveError::KnotsDecreasing {
            index: 2,
            value: 0.5
        }))
    );
    assert_eq!(
        new(&pts, &w, vec![1.0, 1.0, 1.0, 1.0], k()),
        Err(SurfaceError::U(CurveError::EmptyDomain))
    );
    assert_eq!(
        new(&pts, &w, k(), vec![0.0, 0.0, 1.0]),
        Err(SurfaceError::V(CurveError::TooFewPoints {
            points: 1,
            degree: 1,
            need: 2
        }))
    );
    assert_eq!(
        new(&pts, &w, k(), vec![0.0, 0.0, f64::NAN, 1.0, 1.0]),
        Err(SurfaceError::V(CurveError::NotFinite))
    );
    assert_eq!(
        new(&pts[..3], &w[..3], k(), k()),
        Err(SurfaceError::GridSize {
            got: 3,
            rows: 2,
            cols: 2
        })
    );
    assert_eq!(
        new(&pts, &w[..3], k(), k()),
        Err(SurfaceError::WeightCount {
            weights: 3,
            points: 4
        })
    );
    let mut bad = pts.clone();
    bad[2].y = f64::INFINITY;
    assert_eq!(
        new(&bad, &w, k(), k()),
        Err(SurfaceError::NotFinite { index: 2 })
    );
    for value in [0.0, -1.0, f64::NAN] {
        let mut ww = w;
        ww[3] = value;
        match new(&pts, &ww, k(), k()) {
            Err(SurfaceError::Weight { index: 3, .. }) => {}
            other => panic!("weight {value}: {other:?}"),
        }
    }
    // An interior knot repeated beyond the degree would tear the surface apart.
    let pts8 = vec![Vec3::zeros(); 8];
    assert_eq!(
        NurbsSurface::bspline(1, 1, &pts8, vec![0.0, 0.0, 0.5, 0.5, 1.0, 1.0], k()),
        Err(SurfaceError::U(CurveError::KnotMultiplicity {
            value: 0.5,
            multiplicity: 2,
            degree: 1
        }))
    );
}

fn vec3(r: f64) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A clamped knot vector of degree `p` with `extra` distinct interior knots from increments.
fn knots(p: usize, inc: &[f64]) -> Vec<f64> {
    let mut k = vec![0.0; p + 1];
    let mut acc = 0.0;
    for d in &inc[..inc.len() - 1] {
        acc += d;
        k.push(acc);
    }
    acc += inc[inc.len() - 1];
    k.extend(std::iter::repeat_n(acc, p + 1));
    k
}

/// A random rational surface: degrees 1–4 each, up to 3 extra control points per direction,
/// weights 0.3–3, interior knots at least 0.2 apart.
fn surface() -> impl Strategy<Value = NurbsSurface> {
    (1usize..=4, 1usize..=4, 0usize..=3, 0usize..=3).prop_flat_map(|(p, q, eu, ev)| {
        let (rows, cols) = (p + 1 + eu, q + 1 + ev);
        (
            prop::collection::vec(vec3(20.0), rows * cols),
            prop::collection::vec(0.3f64..3.0, rows * cols),
            prop::collection::vec(0.2f64..1.0, eu + 1),
            prop::collection::vec(0.2f64..1.0, ev + 1),
        )
            .prop_map(move |(pts, w, iu, iv)| {
                NurbsSurface::new(p, q, &pts, &w, knots(p, &iu), knots(q, &iv))
                    .expect("generated surface is valid")
            })
    })
}

/// A parameter strictly inside a knot span of `knots`: span picked by `pick` in [0, 1),
/// position `frac` in [0.1, 0.9] of it. Returns the parameter and the span width.
fn inside_span(knots: &[f64], pick: f64, frac: f64) -> (f64, f64) {
    let mut b: Vec<f64> = knots.to_vec();
    b.dedup();
    let i = ((pick * (b.len() - 1) as f64) as usize).min(b.len() - 2);
    (b[i] + (b[i + 1] - b[i]) * frac, b[i + 1] - b[i])
}

/// Richardson-extrapolated central difference of `f` at `t` (error O(h⁴)).
fn diff(f: impl Fn(f64) -> Vec3, t: f64, h: f64) -> Vec3 {
    let d = |h: f64| (f(t + h) - f(t - h)) / (2.0 * h);
    (d(h / 2.0) * 4.0 - d(h)) / 3.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn derivatives_match_finite_differences(
        s in surface(), pu in 0.0f64..1.0, fu in 0.1f64..0.9, pv in 0.0f64..1.0, fv in 0.1f64..0.9
    ) {
        let (u, wu) = inside_span(s.knots_u(), pu, fu);
        let (v, wv) = inside_span(s.knots_v(), pv, fv);
        let (hu, hv) = (1e-3 * wu, 1e-3 * wv);
        let d = s.derivs(u, v);
        prop_assert!((s.point(u, v) - d.point).norm() <= 1e-12 * (1.0 + d.point.norm()));
        // Each check: (analytic, finite difference, scale of the differenced quantity / width).
        let checks = [
            ("su", d.su, diff(|x| s.point(x, v), u, hu), d.point.norm() / wu),
            ("sv", d.sv, diff(|y| s.point(u, y), v, hv), d.point.norm() / wv),
            ("suu", d.suu, diff(|x| s.derivs(x, v).su, u, hu), d.su.norm() / wu),
            ("svv", d.svv, diff(|y| s.derivs(u, y).sv, v, hv), d.sv.norm() / wv),
            ("suv", d.suv, diff(|y| s.derivs(u, y).su, v, hv), d.su.norm() / wv),
            ("svu", d.suv, diff(|x| s.derivs(x, v).sv, u, hu), d.sv.norm() / wu),
        ];
        for (name, analytic, fd, lower) in checks {
            let scale = 1.0 + analytic.norm() + lower;
            let err = (analytic - fd).norm();
            prop_assert!(err <= 1e-6 * scale, "{} err={} scale={} u={} v={}", name, err, scale, u, v);
        }
    }

    #[test]
    fn iso_curves_equal_the_surface_along_their_line(
        s in surface(), u in 0.0f64..=1.0, v in 0.0f64..=1.0, t in 0.0f64..=1.0
    ) {
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        let (u, v) = (u0 + (u1 - u0) * u, v0 + (v1 - v0) * v);
        let (a, b) = (u0 + (u1 - u0) * t, v0 + (v1 - v0) * t);
        let cu = s.u_iso(v);
        let cv = s.v_iso(u);
        prop_assert_eq!(cu.domain(), (u0, u1));
        prop_assert_eq!(cv.domain(), (v0, v1));
        let tol = |p: Vec3| 1e-12 * (1.0 + p.norm());
        let (pa, pb) = (s.point(a, v), s.point(u, b));
        prop_assert!((cu.point(a) - pa).norm() <= tol(pa), "u-iso {} vs {}", cu.point(a), pa);
        prop_assert!((cv.point(b) - pb).norm() <= tol(pb), "v-iso {} vs {}", cv.point(b), pb);
        // The curve's first two derivatives are the surface's along the iso line.
        let (da, db) = (s.derivs(a, v), s.derivs(u, b));
        let [_, c1, c2, _] = cu.derivs(a);
        let [_, e1, e2, _] = cv.derivs(b);
        let close = |x: Vec3, y: Vec3| (x - y).norm() <= 1e-9 * (1.0 + y.norm());
        prop_assert!(close(c1, da.su) && close(c2, da.suu));
        prop_assert!(close(e1, db.sv) && close(e2, db.svv));
    }

    #[test]
    fn normal_is_unit_and_orthogonal_to_the_tangents(
        s in surface(), u in 0.0f64..=1.0, v in 0.0f64..=1.0
    ) {
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        let (u, v) = (u0 + (u1 - u0) * u, v0 + (v1 - v0) * v);
        let d = s.derivs(u, v);
        if let Some(n) = s.normal(u, v) {
            prop_assert!((n.norm() - 1.0).abs() < 1e-14);
            prop_assert!(n.dot(&d.su).abs() <= 1e-9 * d.su.norm());
            prop_assert!(n.dot(&d.sv).abs() <= 1e-9 * d.sv.norm());
            let ff = s.fundamental_forms(u, v).unwrap();
            let (k1, k2) = ff.principal_curvatures();
            prop_assert!(!k1.is_nan() && !k2.is_nan() && k1 >= k2);
        }
    }

    #[test]
    fn principal_directions_obey_euler(
        s in surface(), u in 0.0f64..=1.0, v in 0.0f64..=1.0, phi in 0.0f64..PI
    ) {
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        let (u, v) = (u0 + (u1 - u0) * u, v0 + (v1 - v0) * v);
        let (Some(pc), Some(ff)) = (s.principal_curvatures(u, v), s.fundamental_forms(u, v))
        else {
            return Ok(());
        };
        let d = s.derivs(u, v);
        let n = s.normal(u, v).unwrap();
        // Orthonormal tangent directions.
        prop_assert!(pc.d1.dot(&pc.d2).abs() < 1e-9);
        prop_assert!(pc.d1.dot(&n).abs() < 1e-9 && pc.d2.dot(&n).abs() < 1e-9);
        // Euler: the normal curvature II/I of the tangent t = cos φ d₁ + sin φ d₂, computed
        // from the forms in (u, v) coordinates, is κ₁ cos² φ + κ₂ sin² φ.
        let t = pc.d1.into_inner() * phi.cos() + pc.d2.into_inner() * phi.sin();
        // t = α S_u + β S_v: solve the Gram system [[E F] [F G]] (α β) = (t·S_u, t·S_v).
        let (tu, tv) = (t.dot(&d.su), t.dot(&d.sv));
        let det = ff.e * ff.g - ff.f * ff.f;
        // Ill-conditioned Gram systems (nearly parallel tangents) lose digits: skip them.
        prop_assume!(det > 1e-6 * ff.e * ff.g);
        let (al, be) = ((ff.g * tu - ff.f * tv) / det, (ff.e * tv - ff.f * tu) / det);
        let first = ff.e * al * al + 2.0 * ff.f * al * be + ff.g * be * be;
        let second = ff.l * al * al + 2.0 * ff.m * al * be + ff.n * be * be;
        let euler = pc.k1 * phi.cos().powi(2) + pc.k2 * phi.sin().powi(2);
        let scale = 1.0 + pc.k1.abs() + pc.k2.abs();
        prop_assert!((second / first - euler).abs() <= 1e-7 * scale,
            "II/I={} euler={} k1={} k2={}", second / first, euler, pc.k1, pc.k2);
    }
}

#[test]
fn closest_point_on_sphere_and_torus_is_the_radial_foot() {
    let r = 7.0;
    let sphere = revolve([(r, 0.0, 1.0), (r, r, FRAC_1_SQRT_2), (0.0, r, 1.0)]);
    let (big, t) = (20.0, 4.0);
    let torus = revolve([
        (big + t, 0.0, 1.0),
        (big + t, t, FRAC_1_SQRT_2),
        (big, t, 1.0),
    ]);
    for (a, b) in grid(12) {
        // Directions inside the octant, away from the pole (where u is undefined).
        let (theta, phi) = (0.05 + 1.4 * a, 0.05 + 1.3 * b);
        let dir = Vec3::new(phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin());
        for scale in [0.3, 0.9, 1.0, 1.5, 3.0] {
            let q = dir * (r * scale);
            let c = sphere.closest_point(&q, 1e-12).unwrap();
            assert!(
                (c.distance - (r * scale - r).abs()).abs() < 1e-12,
                "{q} {c:?}"
            );
            assert!((c.point - dir * r).norm() < 1e-9, "{q} {c:?}");
        }
        // Torus: q off the tube centre along the outward tube direction.
        let (c_dir, tube) = (
            Vec3::new(theta.cos(), theta.sin(), 0.0),
            Vec3::new(phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin()),
        );
        for off in [0.5, 3.9, 4.0, 6.0] {
            let q = c_dir * big + tube * off;
            let c = torus.closest_point(&q, 1e-12).unwrap();
            assert!((c.distance - (off - t).abs()).abs() < 1e-12, "{q} {c:?}");
            assert!(
                (c.point - (c_dir * big + tube * t)).norm() < 1e-7,
                "{q} {c:?}"
            );
        }
    }
    assert_eq!(
        sphere.closest_point(&Vec3::zeros(), 0.0),
        Err(SurfaceError::Tolerance(0.0))
    );
    assert_eq!(
        sphere.closest_point(&Vec3::new(f64::NAN, 0.0, 0.0), 1e-9),
        Err(SurfaceError::QueryNotFinite)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn closest_point_finds_a_point_just_off_the_surface(
        s in height_field(), u in 0.0f64..=1.0, v in 0.0f64..=1.0, off in -1.0f64..1.0
    ) {
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        let (u, v) = (u0 + (u1 - u0) * u, v0 + (v1 - v0) * v);
        let n = s.normal(u, v).unwrap();
        let q = s.point(u, v) + n.into_inner() * off;
        let c = s.closest_point(&q, 1e-12).unwrap();
        prop_assert!(c.distance <= off.abs() + 1e-12, "{:?} off={}", c, off);
        prop_assert!((c.point - s.point(c.u, c.v)).norm() == 0.0);
        // Strictly inside a knot-span cell the foot is a perpendicular one (on a knot line of a
        // degree-1 field it may sit on a crease instead).
        let d = s.derivs(c.u, c.v);
        let r = c.point - q;
        let inside = |t: f64, knots: &[f64]| knots.iter().all(|&k| k != t);
        if inside(c.u, s.knots_u()) && inside(c.v, s.knots_v()) {
            prop_assert!(r.dot(&d.su).abs() <= 1e-9 * d.su.norm(), "{:?}", c);
            prop_assert!(r.dot(&d.sv).abs() <= 1e-9 * d.sv.norm(), "{:?}", c);
        }
        // No sample of a dense grid is nearer (the search is global, not just local).
        for (a, b) in grid(40) {
            let x = s.point(u0 + (u1 - u0) * a, v0 + (v1 - v0) * b);
            prop_assert!(c.distance <= (x - q).norm() + 1e-12, "{:?} beaten by {} at {}", c, x, (x - q).norm());
        }
    }
}

/// A random rational height field, the shape of a machined free-form patch: control points on
/// a 10 mm grid in x, y with heights within ±3 mm, degrees 1–4, weights 0.5–2.
fn height_field() -> impl Strategy<Value = NurbsSurface> {
    (1usize..=4, 1usize..=4, 0usize..=3, 0usize..=3).prop_flat_map(|(p, q, eu, ev)| {
        let (rows, cols) = (p + 1 + eu, q + 1 + ev);
        (
            prop::collection::vec(-3.0f64..3.0, rows * cols),
            prop::collection::vec(0.5f64..2.0, rows * cols),
            prop::collection::vec(0.2f64..1.0, eu + 1),
            prop::collection::vec(0.2f64..1.0, ev + 1),
        )
            .prop_map(move |(z, w, iu, iv)| {
                let pts: Vec<Vec3> = (0..rows * cols)
                    .map(|k| Vec3::new(10.0 * (k / cols) as f64, 10.0 * (k % cols) as f64, z[k]))
                    .collect();
                NurbsSurface::new(p, q, &pts, &w, knots(p, &iu), knots(q, &iv))
                    .expect("generated surface is valid")
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// On wild surfaces (a degree-4 piece can fold between the seeds) the search is local:
    /// what it returns is a local minimum — no nearby parameter pair is nearer.
    #[test]
    fn closest_point_is_a_local_minimum_on_random_surfaces(s in surface(), q in vec3(30.0)) {
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        let c = s.closest_point(&q, 1e-12).unwrap();
        prop_assert!((c.point - q).norm() == c.distance);
        let (hu, hv) = (1e-4 * (u1 - u0), 1e-4 * (v1 - v0));
        for (a, b) in [(-1.0, -1.0), (-1.0, 0.0), (-1.0, 1.0), (0.0, -1.0), (0.0, 1.0), (1.0, -1.0), (1.0, 0.0), (1.0, 1.0)] {
            let x = s.point((c.u + a * hu).clamp(u0, u1), (c.v + b * hv).clamp(v0, v1));
            prop_assert!(c.distance <= (x - q).norm() + 1e-12, "{:?} beaten by {} at {}", c, x, (x - q).norm());
        }
    }
}
