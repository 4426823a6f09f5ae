//! Table-tilting A/C orientation (DESIGN.md "Kinematic conventions"): A tilts the table
//! about machine X, C turns the table about its own Z. This file holds only the tool-axis ↔
//! (A, C) map; the chain with `pivot` and `c_offset` is shared in [`crate::trunnion`].

use nalgebra::Vector3;

/// Tool axis seen from the part for table angles (A, C), rad:
/// `(sin A·sin C, sin A·cos C, cos A)` = Rz(C)ᵀ·Rx(A)ᵀ·ẑ (DESIGN.md).
#[inline]
pub fn axis(a: f64, c: f64) -> Vector3<f64> {
    let (sa, ca) = a.sin_cos();
    let (sc, cc) = c.sin_cos();
    Vector3::new(sa * sc, sa * cc, ca)
}

/// Both (A, C) solutions for a unit axis away from the pole: (A ≥ 0, C) and (−A, C + π).
///
/// A = atan2(√(i²+j²), k) rather than acos(k): acos loses half the digits near the pole.
#[inline]
pub fn solutions(k: &Vector3<f64>) -> [(f64, f64); 2] {
    let h = k.x.hypot(k.y);
    let a = h.atan2(k.z);
    [(a, k.x.atan2(k.y)), (-a, (-k.x).atan2(-k.y))]
}

/// At the pole C is free: keep `c` and choose the A that brings the axis closest,
/// A = atan2(i·sin C + j·cos C, k) (the axis component in the plane A sweeps).
#[inline]
pub fn tilt_keeping_c(k: &Vector3<f64>, c: f64) -> f64 {
    let (sc, cc) = c.sin_cos();
    (k.x * sc + k.y * cc).atan2(k.z)
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
