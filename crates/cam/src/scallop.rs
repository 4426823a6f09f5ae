//! Scallop height ↔ side step: how far apart adjacent passes may run for a target scallop
//! height `h`, given the cutter's effective radius `r_e` across the feed and the surface's
//! normal curvature `κ` there (1/mm, positive where the surface bends toward its normal, i.e.
//! concave seen from the tool). The strategies size every side step here.
//!
//! Two models: Can's (2010) Eq. 3.69/3.70 (Lo 1999, second order), kept for the thesis's
//! worked examples; and the exact circle–circle cusp used for planning. In the plane normal to the
//! feed the surface is a circle of radius `ρ = 1/|κ|` about `O` and each pass's cutter profile
//! a circle of radius `r_e` about `C`, tangent to it; the cusp `P` between two passes lies on
//! the bisector at `|OP| = ρ ± h`. The triangle `O, C, P` (sides `|OC| = ρ ± r_e`, `|OP|`,
//! `|CP| = r_e`) gives the half angle between the contact points by the half-angle law of
//! cosines, `sin²(θ/2) = h (2 r_e − h) / (4 |OC| |OP|)` (convex and concave alike; the plane is
//! its limit `ω = 2√(2 r_e h − h²)`, Can, 2010, Eq. 3.61), free of the cancellation of `cos θ` for
//! large `ρ`. The side step `ω` is the chord `2ρ sin θ` between the contact points.

/// Can (2010), Eq. 3.69/3.70 (Lo 1999): `ω = √(8 |ρ| r h / (|ρ| + r·sign))`, `sign = +1` convex, −1
/// concave, `ρ = None` for a plane (`ω = √(8 r h)`). `None` where the denominator is not
/// positive (a concave radius at or below the cutter's: local gouge).
pub fn stepover_lo(r: f64, radius: Option<Convexity>, h: f64) -> Option<f64> {
    match radius {
        None => Some((8.0 * r * h).sqrt()),
        Some(c) => {
            let (rho, sign) = match c {
                Convexity::Convex(rho) => (rho, 1.0),
                Convexity::Concave(rho) => (rho, -1.0),
            };
            let den = rho + r * sign;
            (den > 0.0).then(|| (8.0 * rho * r * h / den).sqrt())
        }
    }
}

/// The inverse of Can's Eq. 3.69: the scallop `h = ω² (|ρ| + r·sign) / (8 |ρ| r)`.
pub fn scallop_lo(r: f64, radius: Option<Convexity>, omega: f64) -> f64 {
    match radius {
        None => omega * omega / (8.0 * r),
        Some(Convexity::Convex(rho)) => omega * omega * (rho + r) / (8.0 * rho * r),
        Some(Convexity::Concave(rho)) => omega * omega * (rho - r) / (8.0 * rho * r),
    }
}

/// A curved cross-section, by its radius (mm, > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Convexity {
    Convex(f64),
    Concave(f64),
}

/// Curvatures below this (1/mm) count as a plane: `ρ` beyond 10¹² mm.
const PLANE: f64 = 1e-12;

/// The exact side step (chord between the contact points, mm) that leaves a cusp of height
/// `h` between two passes of a cutter profile of radius `r_e` on a cross-section of curvature
/// `kappa` (module comment). `None` where `h ≥ r_e` or the concave section is tighter than the
/// cutter (`κ r_e ≥ 1`: local gouge); `Some(f64::INFINITY)` where the cusp never reaches `h`
/// (a concave section matched closely by the cutter) — the caller caps it.
pub fn stepover_exact(r_e: f64, kappa: f64, h: f64) -> Option<f64> {
    if !(h > 0.0 && h < r_e && kappa.is_finite()) {
        return None;
    }
    if r_e.is_infinite() {
        // An untilted flat bottom: on a plane it leaves no cusp, on a concave section it
        // gouges, on a convex one the limit r_e → ∞ of the half-angle law, sin²(θ/2) =
        // h / (2(ρ + h)).
        return match kappa {
            k if k.abs() < PLANE => Some(f64::INFINITY),
            k if k > 0.0 => None,
            k => {
                let rho = -1.0 / k;
                let theta = 2.0 * (h / (2.0 * (rho + h))).sqrt().asin();
                Some(2.0 * rho * theta.sin())
            }
        };
    }
    if kappa.abs() < PLANE {
        return Some(2.0 * (2.0 * r_e * h - h * h).sqrt());
    }
    let rho = 1.0 / kappa.abs();
    let (oc, op) = if kappa < 0.0 {
        (rho + r_e, rho + h)
    } else {
        if kappa * r_e >= 1.0 {
            return None;
        }
        (rho - r_e, rho - h)
    };
    let s2 = h * (2.0 * r_e - h) / (4.0 * oc * op);
    if s2 >= 0.5 {
        // θ/2 ≥ 45°: the cusp never reaches h within a quarter turn of the section.
        return Some(f64::INFINITY);
    }
    let theta = 2.0 * s2.sqrt().asin();
    Some(2.0 * rho * theta.sin())
}

/// The exact cusp height left between contact points a chord `omega` apart (inverse of
/// [`stepover_exact`]): Can's (2010, §3.3.14) closed forms, convex `h = (ρ+r)cos θ − √(r² − (ρ+r)²
/// sin²θ) − ρ`, concave `h = ρ − (ρ−r)cos θ − √(r² − (ρ−r)² sin²θ)`, `sin θ = ω/(2ρ)`. `None` where
/// the geometry has no cusp (`ω ≥ 2r` on a plane, a gouging concave section).
pub fn scallop_exact(r: f64, kappa: f64, omega: f64) -> Option<f64> {
    if kappa.abs() < PLANE {
        let half = omega / 2.0;
        return (half < r).then(|| r - (r * r - half * half).sqrt());
    }
    let rho = 1.0 / kappa.abs();
    let sin = omega / (2.0 * rho);
    if sin >= 1.0 {
        return None;
    }
    let cos = (1.0 - sin * sin).sqrt();
    if kappa < 0.0 {
        let a = rho + r;
        let d = r * r - a * a * sin * sin;
        (d >= 0.0).then(|| a * cos - d.sqrt() - rho)
    } else {
        let b = rho - r;
        let d = r * r - b * b * sin * sin;
        (b > 0.0 && d >= 0.0).then(|| rho - b * cos - d.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn reference_001_worked_examples() {
        // T4: r = 5, h = 0.2, convex ρ = 26.0544985814386 → ω = 2.5907 (Table 4.3: 2.591).
        let w = stepover_lo(5.0, Some(Convexity::Convex(26.054_498_581_438_6)), 0.2).unwrap();
        assert!((w - 2.5907).abs() < 5e-5, "{w}");
        // T5: concave → 3.1464.
        let w = stepover_lo(5.0, Some(Convexity::Concave(26.0545)), 0.2).unwrap();
        assert!((w - 3.1464).abs() < 5e-5, "{w}");
        // T6: plane √8 = 2.8284, exact 2√(2rh − h²) = 2.8000.
        assert!((stepover_lo(5.0, None, 0.2).unwrap() - 8f64.sqrt()).abs() < 1e-12);
        assert!((stepover_exact(5.0, 0.0, 0.2).unwrap() - 2.8).abs() < 1e-12);
        // T7: r = 3, h = 0.2, ω = 1.62 ↔ ρ_convex = 3.619.
        let h = scallop_lo(3.0, Some(Convexity::Convex(3.619)), 1.62);
        assert!((h - 0.2).abs() < 1e-4, "{h}");
        // T9: ball D = 40, ω = 4 → 0.1003 exact (0.1 in Lo's model); flat D = 40 at 25° → 0.0423.
        assert!((scallop_exact(20.0, 0.0, 4.0).unwrap() - 0.100_25).abs() < 1e-5);
        assert!((scallop_lo(20.0, None, 4.0) - 0.1).abs() < 1e-12);
        let re = 20.0 / 25f64.to_radians().sin();
        assert!((scallop_lo(re, None, 4.0) - 0.0423).abs() < 5e-5);
        // Caveat: the exact cusp at the step of Can's Table 4.3 (h = 0.2) is 0.206, not 0.200.
        let h = scallop_exact(5.0, -1.0 / 26.054_498_581_438_6, 2.5907).unwrap();
        assert!((h - 0.206).abs() < 5e-4, "{h}");
        // …and for T7 0.223 (+12 %).
        let h = scallop_exact(3.0, -1.0 / 3.619, 1.62).unwrap();
        assert!((h - 0.223).abs() < 5e-4, "{h}");
    }

    #[test]
    fn cylinder_closed_form() {
        // A ball r = 3 inside a cylinder bore of radius 20 (concave) and on its outside
        // (convex): the cusp between contact points at angles ±θ, from plane geometry.
        let (r, rho, h) = (3.0, 20.0, 0.01);
        for (kappa, oc, op) in [
            (1.0 / rho, rho - r, rho - h),
            (-1.0 / rho, rho + r, rho + h),
        ] {
            let w = stepover_exact(r, kappa, h).unwrap();
            let theta = (w / (2.0 * rho)).asin();
            // Law of cosines in O, C, P: |CP|² = |OC|² + |OP|² − 2|OC||OP| cos θ.
            let cp2 = oc * oc + op * op - 2.0 * oc * op * theta.cos();
            assert!((cp2.sqrt() - r).abs() < 1e-9, "{kappa}: {}", cp2.sqrt());
        }
        // Concave sections allow a wider step than the plane, convex a narrower one.
        let plane = stepover_exact(r, 0.0, h).unwrap();
        assert!(stepover_exact(r, 1.0 / rho, h).unwrap() > plane);
        assert!(stepover_exact(r, -1.0 / rho, h).unwrap() < plane);
        // Tighter than the cutter: gouge.
        assert_eq!(stepover_exact(r, 1.0 / 2.0, h), None);
    }

    proptest! {
        #[test]
        fn exact_forms_invert_each_other(r in 0.5f64..20.0, rho in 0.5f64..1e4,
                                          convex in any::<bool>(), hf in 1e-4f64..0.2) {
            let h = hf * r;
            let kappa = if convex { -1.0 / rho } else { 1.0 / rho };
            prop_assume!(convex || rho > 1.05 * r);
            if let Some(w) = stepover_exact(r, kappa, h) {
                prop_assume!(w.is_finite() && w < 1.9 * rho.min(r));
                let back = scallop_exact(r, kappa, w).unwrap();
                prop_assert!((back - h).abs() < 1e-7 * r, "{} vs {}", back, h);
            }
        }
    }
}
