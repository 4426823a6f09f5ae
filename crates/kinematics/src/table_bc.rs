//! Table-tilting B/C orientation: as `table-ac` with B about machine Y. This file
//! holds only the tool-axis ↔ (B, C) map; the chain with `pivot` and `c_offset` is shared in
//! [`crate::trunnion`].

use nalgebra::Vector3;

/// Tool axis seen from the part for table angles (B, C), rad: Rz(C)ᵀ·Ry(B)ᵀ·ẑ =
/// `(−sin B·cos C, sin B·sin C, cos B)`. (The A/C form's derivation with Ry,
/// right-handed.)
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
