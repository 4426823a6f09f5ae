//! Test surfaces built in code, shared by the unit tests, the integration tests and the
//! benchmark: a plane, the complete boundary curve of the STEP excerpt in Can (2010,
//! Appendix A), a free-form bicubic patch, cylinder and sphere patches as rational NURBS, a
//! saddle, and random bicubic patches for property tests. Not part of the planning API.

use tezgah_geom::{NurbsSurface, Vec3};

fn clamped(degree: usize, interior: &[f64]) -> Vec<f64> {
    let mut k = vec![0.0; degree + 1];
    k.extend_from_slice(interior);
    k.extend(std::iter::repeat_n(1.0, degree + 1));
    k
}

/// The bilinear square `[0, size]² × {0}`, normal +z.
pub fn plane(size: f64) -> NurbsSurface {
    let p = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, size, 0.0),
        Vec3::new(size, 0.0, 0.0),
        Vec3::new(size, size, 0.0),
    ];
    NurbsSurface::bspline(1, 1, &p, clamped(1, &[]), clamped(1, &[])).expect("valid plane")
}

/// Row 1 of Can's (2010, Appendix A) STEP excerpt (entities #3, #2, #4, #10, #5, #12, #11, #9, #8,
/// #7, #6 with the v knot vector corrected to 15 knots) as the `u = 0` edge of a ruled strip
/// (the second row is the first moved 10 mm along −y), so `S(0, v)` is the boundary curve
/// whose golden values `forward_step`'s tests list.
// The coordinates and knots keep every digit the STEP file prints.
#[allow(clippy::excessive_precision)]
pub fn boundary_curve_001() -> NurbsSurface {
    let row = [
        [0.0, 160.0, -2.997_117_026_008_431_9e-15],
        [5.780_162_769_084_116_2, 160.0, 0.143_359_701_523_636_72],
        [
            15.412_752_970_865_741,
            159.999_999_999_999_97,
            0.382_267_377_897_906_38,
        ],
        [
            28.740_121_433_138_093,
            159.999_999_999_999_97,
            0.123_591_468_700_825_7,
        ],
        [
            43.441_784_141_532_48,
            159.999_999_999_999_97,
            -1.016_527_956_225_229_8,
        ],
        [
            63.219_382_141_396_053,
            159.999_999_999_999_97,
            -3.043_989_460_204_696,
        ],
        [
            81.669_793_487_437_602,
            159.999_999_999_999_94,
            -2.702_595_296_722_309_5,
        ],
        [
            98.715_241_851_284_574,
            159.999_999_999_999_97,
            -1.900_988_741_244_382_9,
        ],
        [
            112.427_797_880_894_7,
            159.999_999_999_999_97,
            -1.111_010_497_271_683,
        ],
        [
            123.843_147_633_201_06,
            159.999_999_999_999_97,
            -0.367_482_398_730_768_43,
        ],
        [129.475_449_391_902_06, 160.0, 4.577_700_871_035_874_6e-15],
    ];
    let mut pts: Vec<Vec3> = row.iter().map(|p| Vec3::from(*p)).collect();
    pts.extend(row.iter().map(|p| Vec3::new(p[0], p[1] - 10.0, p[2])));
    let kv = clamped(
        3,
        &[
            0.133_634_983_203_784_75,
            0.222_701_519_187_148_64,
            0.308_663_567_273_193_88,
            0.474_911_176_233_495_66,
            0.682_212_779_437_162_96,
            0.735_158_994_880_887_87,
            0.869_326_056_995_079_25,
        ],
    );
    NurbsSurface::bspline(1, 3, &pts, clamped(1, &[]), kv).expect("valid 001 strip")
}

/// A 100 × 100 mm bicubic patch with a hill and a valley (principal radii down to ≈ 46 mm
/// convex and ≈ 60 mm concave), on a 7 × 7 control grid. The control points stand at the
/// Greville abscissae of the knot vector, so with `warp = 0` the parametrisation is linear in
/// x and y (B-spline linear precision) and only the slopes and curvature vary; `warp` > 0
/// moves the columns to `x = 100·g^(1+warp)`, a distorted parametrisation as CAD often makes.
pub fn freeform(warp: f64) -> NurbsSurface {
    let n = 7;
    let k = clamped(3, &[0.25, 0.5, 0.75]);
    let greville: Vec<f64> = (0..n)
        .map(|i| (k[i + 1] + k[i + 2] + k[i + 3]) / 3.0)
        .collect();
    let mut pts = Vec::with_capacity(n * n);
    for &gx in &greville {
        let x = 100.0 * gx.powf(1.0 + warp);
        for &gy in &greville {
            let y = 100.0 * gy;
            let z = 9.0 * (std::f64::consts::PI * x / 60.0).sin() * (y / 45.0).cos()
                + 6.0 * (-((x - 65.0).powi(2) + (y - 60.0).powi(2)) / 500.0).exp();
            pts.push(Vec3::new(x, y, z));
        }
    }
    NurbsSurface::bspline(3, 3, &pts, k.clone(), k).expect("valid freeform")
}

/// A rational quadratic circular arc in the xz-plane from angle `a0` to `a1` (radians from
/// +x toward +z, span < π) on a circle of radius `r` about the origin: `(points, weights)`.
fn arc(r: f64, a0: f64, a1: f64) -> ([[f64; 2]; 3], [f64; 3]) {
    let half = 0.5 * (a1 - a0);
    let mid = 0.5 * (a0 + a1);
    let w = half.cos();
    (
        [
            [r * a0.cos(), r * a0.sin()],
            [r * mid.cos() / w, r * mid.sin() / w],
            [r * a1.cos(), r * a1.sin()],
        ],
        [1.0, w, 1.0],
    )
}

/// A cylinder patch of `radius` about the y axis, angles 45°…135° from +x toward +z (a
/// 90° arc across the top), `length` along y; rational quadratic × linear. `outside`:
/// the normal points away from the axis (convex, a roller); otherwise toward it (concave, a
/// trough).
pub fn cylinder(radius: f64, length: f64, outside: bool) -> NurbsSurface {
    let q = std::f64::consts::FRAC_PI_4;
    let (mut p, mut w) = arc(radius, q, 3.0 * q);
    if outside {
        p.reverse();
        w.reverse();
    }
    let mut pts = Vec::new();
    let mut ws = Vec::new();
    for (pp, ww) in p.iter().zip(w) {
        for y in [0.0, length] {
            pts.push(Vec3::new(pp[0], y, pp[1]));
            ws.push(ww);
        }
    }
    // Outside: the arc reversed so S_u runs toward +x over the top; with S_v along +y,
    // S_u × S_v points away from the axis.
    NurbsSurface::new(2, 1, &pts, &ws, clamped(2, &[]), clamped(1, &[])).expect("valid cylinder")
}

/// A trough: the bottom quarter of a cylinder of `radius` about the y axis (angles 225°…315°),
/// `length` along y, normal pointing up toward the axis — concave across x for a tool from
/// above, as a 3-axis machine sees it.
pub fn trough(radius: f64, length: f64) -> NurbsSurface {
    let q = std::f64::consts::FRAC_PI_4;
    let (p, w) = arc(radius, 5.0 * q, 7.0 * q);
    let mut pts = Vec::new();
    let mut ws = Vec::new();
    for (pp, ww) in p.iter().zip(w) {
        for y in [0.0, length] {
            pts.push(Vec3::new(pp[0], y, pp[1]));
            ws.push(ww);
        }
    }
    NurbsSurface::new(2, 1, &pts, &ws, clamped(2, &[]), clamped(1, &[])).expect("valid trough")
}

/// A sphere patch of `radius` about the origin: latitudes 10°…60°, longitudes 0°…90°, as
/// the revolution of a rational quadratic arc (P&T §8.5), normal pointing outward.
pub fn sphere(radius: f64) -> NurbsSurface {
    let (p, w) = arc(radius, 10f64.to_radians(), 60f64.to_radians());
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let around = [([1.0, 0.0], 1.0), ([1.0, 1.0], s), ([0.0, 1.0], 1.0)];
    let mut pts = Vec::new();
    let mut ws = Vec::new();
    // u runs along longitude, v along latitude (up): S_u × S_v points outward.
    for (q, wq) in around {
        for (pp, wp) in p.iter().zip(w) {
            pts.push(Vec3::new(pp[0] * q[0], pp[0] * q[1], pp[1]));
            ws.push(wq * wp);
        }
    }
    NurbsSurface::new(2, 2, &pts, &ws, clamped(2, &[]), clamped(2, &[])).expect("valid sphere")
}

/// The saddle `z = (x² − y²) / (2c)` over `[−a, a]²`, exactly, as a biquadratic Bézier patch
/// (`x²` has Bernstein coefficients `a², −a², a²` on `[−a, a]`).
pub fn saddle(a: f64, c: f64) -> NurbsSurface {
    let xs = [-a, 0.0, a];
    let sq = [a * a, -a * a, a * a];
    let mut pts = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            pts.push(Vec3::new(xs[i], xs[j], (sq[i] - sq[j]) / (2.0 * c)));
        }
    }
    NurbsSurface::bspline(2, 2, &pts, clamped(2, &[]), clamped(2, &[])).expect("valid saddle")
}

/// A random 100 × 100 mm bicubic patch (6 × 6 control grid, heights within ±`12` mm, random
/// interior knots) from `seed`: wavy, with inflections, for property tests.
pub fn random_bicubic(seed: u64) -> NurbsSurface {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        // xorshift64*: deterministic, dependency-free.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    let n = 6;
    let mut pts = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let x = 100.0 * i as f64 / (n - 1) as f64 + 4.0 * (next() - 0.5);
            let y = 100.0 * j as f64 / (n - 1) as f64 + 4.0 * (next() - 0.5);
            pts.push(Vec3::new(x, y, 24.0 * (next() - 0.5)));
        }
    }
    let mut knots = |_: ()| {
        let a = 0.15 + 0.3 * next();
        let b = a + 0.15 + 0.3 * next() * (0.85 - a - 0.15) / 0.3;
        clamped(3, &[a, b.min(0.9)])
    };
    let (ku, kv) = (knots(()), knots(()));
    NurbsSurface::bspline(3, 3, &pts, ku, kv).expect("valid random patch")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_surfaces_are_what_they_claim() {
        let cyl = cylinder(20.0, 50.0, true);
        let sph = sphere(30.0);
        let sad = saddle(50.0, 40.0);
        for k in 0..=10 {
            for l in 0..=10 {
                let (u, v) = (k as f64 / 10.0, l as f64 / 10.0);
                let p = cyl.point(u, v);
                assert!((p.x.hypot(p.z) - 20.0).abs() < 1e-12);
                let n = cyl.normal(u, v).unwrap();
                assert!((n.into_inner() - Vec3::new(p.x, 0.0, p.z) / 20.0).norm() < 1e-9);
                let p = sph.point(u, v);
                assert!((p.norm() - 30.0).abs() < 1e-12);
                assert!((sph.normal(u, v).unwrap().into_inner() - p / 30.0).norm() < 1e-9);
                let p = sad.point(u, v);
                assert!((p.z - (p.x * p.x - p.y * p.y) / 80.0).abs() < 1e-12);
            }
        }
        let t = trough(20.0, 50.0);
        let p = t.point(0.5, 0.5);
        assert!((p - Vec3::new(0.0, 25.0, -20.0)).norm() < 1e-12);
        assert!((t.normal(0.5, 0.5).unwrap().into_inner() - Vec3::z()).norm() < 1e-12);
        let trough = cylinder(20.0, 50.0, false);
        let p = trough.point(0.3, 0.4);
        let n = trough.normal(0.3, 0.4).unwrap();
        assert!((n.into_inner() + Vec3::new(p.x, 0.0, p.z) / 20.0).norm() < 1e-9);
    }
}
