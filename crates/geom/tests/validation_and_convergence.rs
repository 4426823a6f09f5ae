//! Constructors reject bad input with typed errors (no panic reachable from a G-code block or a
//! fit request), and the arc-length map converges to 1e-9 mm and below under refinement.

use tezgah_geom::fit::{approximate, interpolate, Parameterisation};
use tezgah_geom::{ArcLengthMap, Curve, CurveError, Nurbs, Vec3};

fn pts(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| Vec3::new(i as f64, (i * i % 7) as f64, 0.0))
        .collect()
}

#[test]
fn nurbs_validation() {
    let p = pts(4);
    let k = vec![0., 0., 0., 0., 1., 1., 1., 1.];
    assert!(Nurbs::bspline(3, &p, k.clone()).is_ok());
    assert!(matches!(
        Nurbs::bspline(0, &p, k.clone()),
        Err(CurveError::Degree { .. })
    ));
    assert!(matches!(
        Nurbs::bspline(3, &p[..3], k.clone()),
        Err(CurveError::TooFewPoints { .. })
    ));
    assert!(matches!(
        Nurbs::bspline(3, &p, k[..7].to_vec()),
        Err(CurveError::KnotCount { .. })
    ));
    assert!(matches!(
        Nurbs::bspline(3, &p, vec![0., 0., 0., 0., 1., 1., 0.5, 1.]),
        Err(CurveError::KnotsDecreasing { index: 6, .. })
    ));
    assert!(matches!(
        Nurbs::new(3, &p, &[1., 0., 1., 1.], k.clone()),
        Err(CurveError::Weight { index: 1, .. })
    ));
    assert!(matches!(
        Nurbs::new(3, &p, &[1., -2., 1., 1.], k.clone()),
        Err(CurveError::Weight { .. })
    ));
    assert!(matches!(
        Nurbs::new(3, &p, &[1., 1., 1.], k.clone()),
        Err(CurveError::WeightCount { .. })
    ));
    assert!(matches!(
        Nurbs::bspline(3, &p, vec![0.; 8]),
        Err(CurveError::EmptyDomain) | Err(CurveError::KnotMultiplicity { .. })
    ));
    let p8 = pts(8);
    // An interior knot of multiplicity 4 > degree 3 breaks the curve apart.
    let k8 = vec![0., 0., 0., 0., 0.5, 0.5, 0.5, 0.5, 1., 1., 1., 1.];
    assert!(matches!(
        Nurbs::bspline(3, &p8, k8),
        Err(CurveError::KnotMultiplicity {
            multiplicity: 4,
            ..
        })
    ));
    let mut bad = p.clone();
    bad[2].y = f64::INFINITY;
    assert_eq!(
        Nurbs::bspline(3, &bad, k.clone()),
        Err(CurveError::NotFinite)
    );
    assert!(Nurbs::bspline(3, &p, vec![0., 0., 0., 0., f64::NAN, 1., 1., 1.]).is_err());
    assert!(matches!(
        Nurbs::bspline(16, &pts(17), (0..34).map(f64::from).collect()),
        Err(CurveError::Degree { .. })
    ));
}

#[test]
fn evaluation_outside_the_domain_clamps_and_never_nans() {
    let c = Nurbs::bspline(3, &pts(6), (0..10).map(f64::from).collect()).unwrap();
    assert_eq!(c.domain(), (3.0, 6.0));
    for u in [f64::NAN, f64::NEG_INFINITY, -1e300, 1e300, f64::INFINITY] {
        let d = c.derivs(u);
        assert!(d.iter().all(|v| v.iter().all(|x| x.is_finite())), "{u}");
        assert!(!c.curvature(u).is_nan());
    }
    assert_eq!(c.point(f64::NAN), c.point(3.0));
    assert_eq!(c.point(100.0), c.point(6.0));
}

#[test]
fn fit_validation() {
    let p = pts(6);
    assert!(matches!(
        interpolate(&p[..3], 3, Parameterisation::Centripetal),
        Err(CurveError::TooFewPoints { .. })
    ));
    let mut dup = p.clone();
    dup[3] = dup[2];
    assert!(matches!(
        interpolate(&dup, 3, Parameterisation::ChordLength),
        Err(CurveError::DuplicatePoints { index: 2, next: 3 })
    ));
    assert!(matches!(
        approximate(&dup, 3, 0.01, Parameterisation::Centripetal),
        Err(CurveError::DuplicatePoints { .. })
    ));
    for tol in [0.0, -1.0, f64::NAN] {
        assert!(matches!(
            approximate(&p, 3, tol, Parameterisation::Centripetal),
            Err(CurveError::Tolerance(_))
        ));
    }
    assert!(ArcLengthMap::new(
        &Nurbs::bspline(1, &p, (0..8).map(f64::from).collect()).unwrap(),
        0.0
    )
    .is_err());
    // Two points are enough for an approximation: the line itself.
    let a = approximate(&p[..2], 3, 1e-6, Parameterisation::Centripetal).unwrap();
    assert!(a.max_deviation < 1e-9);
}

fn weighted() -> Nurbs {
    let x = [50.0, 100.0, 60.0, 50.0, 40.0, 0.0, 50.0];
    let y = [0.0, 100.0, 40.0, 100.0, 40.0, 100.0, 0.0];
    let p: Vec<Vec3> = x
        .iter()
        .zip(y)
        .map(|(x, y)| Vec3::new(*x, y, 0.0))
        .collect();
    let knots = vec![0., 0., 0., 0., 0.25, 0.5, 0.75, 1., 1., 1., 1.];
    Nurbs::new(3, &p, &[1., 1., 10., 10., 10., 1., 1.], knots).unwrap()
}

#[test]
fn arc_length_converges_under_refinement() {
    let c = weighted();
    let reference = ArcLengthMap::new(&c, 1e-13).unwrap().length();
    let mut panels = 0;
    for tol in [1e-3, 1e-5, 1e-7, 1e-9, 1e-11] {
        let m = ArcLengthMap::new(&c, tol).unwrap();
        assert!(
            m.error_estimate() <= tol,
            "estimate {} > {tol}",
            m.error_estimate()
        );
        assert!(
            (m.length() - reference).abs() <= tol,
            "tol {tol}: {} vs {reference}",
            m.length()
        );
        assert!(m.panels() >= panels);
        panels = m.panels();
    }
    // Same map inverted: s(u(s)) = s to the Newton tolerance.
    let m = ArcLengthMap::new(&c, 1e-9).unwrap();
    for i in 0..=100 {
        let s = m.length() * i as f64 / 100.0;
        let u = m.u_at(&c, s);
        assert!((m.s_at(&c, u) - s).abs() <= 1e-11, "s={s}");
    }
    // A cusp (zero first derivative) still terminates and is accurate: y = x^(2/3)-like
    // B-spline with a doubled control point.
    let p = [
        Vec3::new(0., 0., 0.),
        Vec3::new(1., 1., 0.),
        Vec3::new(1., 1., 0.),
        Vec3::new(2., 0., 0.),
    ];
    let cusp = Nurbs::bspline(2, &p, vec![0., 0., 0., 0.5, 1., 1., 1.]).unwrap();
    let a = ArcLengthMap::new(&cusp, 1e-9).unwrap();
    let b = ArcLengthMap::new(&cusp, 1e-12).unwrap();
    assert!((a.length() - b.length()).abs() <= 1e-9);
    assert!((b.length() - 2.0 * 2f64.sqrt()).abs() < 1e-9);
}
