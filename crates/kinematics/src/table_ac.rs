//! Table-tilting A/C orientation (docs/machine-files.md, "Kinematic conventions"): A tilts the
//! table about machine X, C turns the table about its own Z. This file holds only the tool-axis ↔
//! (A, C) map; the chain with `pivot` and `c_offset` is shared in [`crate::trunnion`].

use nalgebra::Vector3;

/// Tool axis seen from the part for table angles (A, C), rad:
/// `(sin A·sin C, sin A·cos C, cos A)` = Rz(C)ᵀ·Rx(A)ᵀ·ẑ.
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
