//! Golden NURBS numbers of Kelekçi (2021, §2.3): lengths of (2.39), weighted lengths of Table
//! 2.4 and the curvature maxima of the (3.39) demo curve. Each value is checked to every digit
//! given.

use tezgah_geom::curvature::curvature_peaks;
use tezgah_geom::{ArcLengthMap, Curve, Nurbs, Vec3};

/// |got − want| within half a unit of the last digit given.
fn assert_digits(got: f64, want: f64, decimals: i32) {
    let half = 0.5 * 10f64.powi(-decimals);
    assert!(
        (got - want).abs() <= half,
        "got {got}, want {want} to {decimals} decimals"
    );
}

fn pts(x: &[f64], y: &[f64], z: &[f64]) -> Vec<Vec3> {
    x.iter()
        .zip(y)
        .zip(z)
        .map(|((x, y), z)| Vec3::new(*x, *y, *z))
        .collect()
}

fn data_239() -> Vec<Vec3> {
    let x = [0.0, 2.5, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0];
    let y = [0.0, 2.3, 1.5, 2.4, 1.0, 2.0, 1.0, 2.0, 0.0, 1.0];
    pts(&x, &y, &[0.0; 10])
}

fn length(c: &Nurbs) -> f64 {
    let m = ArcLengthMap::new(c, 1e-10).unwrap();
    assert!(m.error_estimate() <= 1e-10);
    m.length()
}

#[test]
fn clamped_cubic_2_39_length_19_02() {
    let knots = vec![0., 0., 0., 0., 1., 2., 3., 4., 5., 6., 7., 7., 7., 7.];
    let c = Nurbs::bspline(3, &data_239(), knots).unwrap();
    assert_digits(length(&c), 19.02, 2);
    // A recomputation carries two more digits.
    assert_digits(length(&c), 19.0203, 4);
}

#[test]
fn uniform_knots_2_39_length_14_1316() {
    let knots = (0..14).map(f64::from).collect();
    let c = Nurbs::bspline(3, &data_239(), knots).unwrap();
    assert_eq!(c.domain(), (3.0, 10.0));
    assert_digits(length(&c), 14.1316, 4);
}

fn curve_248(w: &[f64], scale: f64) -> Nurbs {
    let x = [50.0, 100.0, 60.0, 50.0, 40.0, 0.0, 50.0];
    let y = [0.0, 100.0, 40.0, 100.0, 40.0, 100.0, 0.0];
    let p: Vec<Vec3> = pts(&x, &y, &[0.0; 7]).iter().map(|p| p * scale).collect();
    let knots = vec![0., 0., 0., 0., 0.25, 0.5, 0.75, 1., 1., 1., 1.];
    Nurbs::new(3, &p, w, knots).unwrap()
}

#[test]
fn weighted_lengths_table_2_4a() {
    let w1 = [1.0; 7];
    let w2 = [1., 1., 5., 5., 5., 1., 1.];
    let w3 = [1., 1., 10., 10., 10., 1., 1.];
    assert_digits(length(&curve_248(&w1, 1.0)), 244.9780, 4);
    assert_digits(length(&curve_248(&w2, 1.0)), 200.6809, 4);
    assert_digits(length(&curve_248(&w3, 1.0)), 186.7727, 4);
}

fn curve_249(w: &[f64], planar: bool) -> Nurbs {
    let x = [0., 0., 6., 4., 1., 5., 11., 15., 12., 10., 16.];
    let y = [1., 0., 0., 2., 11., 16., 16., 11., 2., 0., 0.];
    let z = [0., 1., 0., 2., 0., 0., 4., 0., -1., 0., 1.];
    let z = if planar { [0.0; 11] } else { z };
    let knots = vec![
        0., 0., 0., 0., 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1., 1., 1., 1.,
    ];
    // Erratum: the thesis prints 12 weights for 11 points; the first 11 reproduce it.
    Nurbs::new(3, &pts(&x, &y, &z), &w[..11], knots).unwrap()
}

#[test]
fn table_2_4b_planar_first_eleven_weights() {
    let w1 = [1.0; 12];
    let w2 = [1., 2., 2., 1., 1., 1., 1., 1., 1., 2., 2., 1.];
    let w3 = [1., 5., 5., 1., 1., 1., 1., 1., 1., 5., 5., 1.];
    assert_digits(length(&curve_249(&w1, true)), 47.8306, 4);
    assert_digits(length(&curve_249(&w2, true)), 48.8923, 4);
    // The thesis prints 50.1599; the true value is 50.16002.
    assert_digits(length(&curve_249(&w3, true)), 50.1600, 4);
    assert_digits(length(&curve_249(&w1, false)), 49.3914, 4);
}

/// Local maxima of κ(u) through the library's peak finder (64 samples per knot span).
fn curvature_maxima(c: &Nurbs) -> Vec<(f64, f64)> {
    curvature_peaks(c, 64)
        .into_iter()
        .map(|p| (p.u, p.curvature))
        .collect()
}

#[test]
fn curvature_demo_3_39_length_and_maxima() {
    let c = curve_248(&[1.0; 7], 0.25);
    assert_digits(length(&c), 61.2445, 4);
    let maxima = curvature_maxima(&c);
    let want = [
        (0.1408, 5.663),
        (0.2886, 0.569),
        (0.5, 4.799),
        (0.7114, 0.569),
        (0.8592, 5.663),
    ];
    assert_eq!(maxima.len(), want.len(), "{maxima:?}");
    for ((u, k), (wu, wk)) in maxima.iter().zip(want) {
        assert_digits(*u, wu, 4);
        // "κ ≈" values are truncated, not rounded: κ(0.5) is exactly 4.8, printed 4.799.
        assert!((k - wk).abs() <= 1e-3, "κ {k} vs {wk}");
    }
    let pa = c.point(maxima[0].0);
    assert_digits(pa.x, 20.466, 3);
    assert_digits(pa.y, 18.236, 3);
    let pb = c.point(0.5);
    assert_digits(pb.x, 12.5, 3);
    assert_digits(pb.y, 20.0, 3);
    let pc = c.point(maxima[4].0);
    assert_digits(pc.x, 4.534, 3);
    assert_digits(pc.y, 18.236, 3);
    // Above κ_thr = 1 exactly three: A, B, C.
    assert_eq!(maxima.iter().filter(|m| m.1 > 1.0).count(), 3);
}

#[test]
fn curvature_demo_3_39_inflections() {
    let c = curve_248(&[1.0; 7], 0.25);
    // Signed planar curvature changes sign at the inflections.
    let signed = |u: f64| {
        let [_, d1, d2, _] = c.derivs(u);
        d1.x * d2.y - d1.y * d2.x
    };
    for want in [0.2015, 0.4185, 0.5816, 0.7986] {
        let (mut a, mut b) = (want - 0.01, want + 0.01);
        assert!(signed(a) * signed(b) < 0.0);
        for _ in 0..60 {
            let m = 0.5 * (a + b);
            if signed(a) * signed(m) <= 0.0 {
                b = m;
            } else {
                a = m;
            }
        }
        // Exact zeros are 0.201444, 0.418448, 0.581552, 0.798556 (symmetric about 0.5): the
        // often quoted 0.2015 and 0.4185 are one unit high in the last digit.
        let u = 0.5 * (a + b);
        assert!((u - want).abs() <= 1e-4, "inflection {u} vs {want}");
    }
}
