//! Table-tilting B/C orientation: as `table-ac` with B about machine Y (DESIGN.md). This file
//! holds only the tool-axis ↔ (B, C) map; the chain with `pivot` and `c_offset` is shared in
//! [`crate::trunnion`].

use nalgebra::Vector3;

/// Tool axis seen from the part for table angles (B, C), rad: Rz(C)ᵀ·Ry(B)ᵀ·ẑ =
/// `(−sin B·cos C, sin B·sin C, cos B)`. (DESIGN.md gives only the A/C form; this is the
/// same derivation with Ry, right-handed.)
#[inline]
pub fn axis(b: f64, c: f64) -> Vector3<f64> {
    let (sb, cb) = b.sin_cos();
    let (sc, cc) = c.sin_cos();
    Vector3::new(-sb * cc, sb * sc, cb)
}

/// Both (B, C) solutions for a unit axis away from the pole: (B ≥ 0, C) and (−B, C + π).
#[inline]
pub fn solutions(k: &Vector3<f64>) -> [(f64, f64); 2] {
    let h = k.x.hypot(k.y);
    let b = h.atan2(k.z);
    [(b, k.y.atan2(-k.x)), (-b, (-k.y).atan2(k.x))]
}

/// At the pole C is free: keep `c` and choose B = atan2(−i·cos C + j·sin C, k).
#[inline]
pub fn tilt_keeping_c(k: &Vector3<f64>, c: f64) -> f64 {
    let (sc, cc) = c.sin_cos();
    (-k.x * cc + k.y * sc).atan2(k.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both solutions give back the axis, and keeping C at the exact pole gives tilt 0.
    #[test]
    fn solutions_reproduce_the_axis() {
        for (t, c) in [
            (0.3, 0.2),
            (1.2, -2.5),
            (-0.7, 3.0),
            (2.0, 1.0),
            (0.01, -0.01),
        ] {
            let k = axis(t, c);
            for (ts, cs) in solutions(&k) {
                assert!((axis(ts, cs) - k).norm() < 1e-14, "{t} {c} → {ts} {cs}");
            }
            let (t0, c0) = solutions(&k)[0];
            assert!(t0 >= 0.0 && ((t0 - t.abs()).abs() < 1e-14));
            // the tilt that keeps a given C reproduces the axis when C is one of the solutions
            assert!((axis(tilt_keeping_c(&k, c0), c0) - k).norm() < 1e-14);
        }
        assert_eq!(tilt_keeping_c(&Vector3::z(), 1.234), 0.0);
    }
}
