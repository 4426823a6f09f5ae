//! Rear gouge: the whole cutting end against the surface. 001 §2.11b scans the shadow of a
//! flat tool's bottom behind the contact (Lo 1999, extended to the full bottom); here every
//! indexed surface sample near the tool is tested against the solid of revolution of the
//! cutting end — the flat, torus or ball bottom and the flutes up to two tool radii — so the
//! heel, the middle of the bottom and the sides are all covered, for every cutter shape.

use nalgebra::Unit;
use tezgah_geom::Vec3;

use super::index::PointGrid;
use crate::cutter::CutterShape;

/// Height of the checked cutting end above the tip, in tool radii.
pub const CUTTING_END_RADII: f64 = 2.0;

/// How deep `p` lies inside the cutting end (mm; ≤ 0 outside) standing at `tip` along `axis`:
/// the distance to the nearest of the bottom (flat `z`, or the corner torus `r − |q − c|` with
/// `c` the corner-circle point) and the side `R − ρ`, in tool coordinates (axial `z`, radial
/// `ρ`).
pub fn penetration(shape: &CutterShape, tip: &Vec3, axis: &Unit<Vec3>, p: &Vec3) -> f64 {
    let (big_r, r) = (shape.radius(), shape.corner_radius());
    let r0 = big_r - r;
    let d = p - tip;
    let z = d.dot(axis);
    let height = CUTTING_END_RADII * big_r;
    if z <= 0.0 || z >= height {
        return z.min(height - z).min(0.0);
    }
    let rho = (d - axis.into_inner() * z).norm();
    let side = big_r - rho;
    if side <= 0.0 {
        return side;
    }
    let bottom = if rho <= r0 || z >= r {
        // Over the flat part, or above the corner: the bottom plane (or nothing) is nearest.
        if rho <= r0 {
            z
        } else {
            f64::INFINITY
        }
    } else {
        r - (rho - r0).hypot(z - r)
    };
    bottom.min(side)
}

/// A surface sample inside the cutting end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// How deep, mm.
    pub depth: f64,
    pub point: Vec3,
}

/// The first surface sample found more than `tolerance` inside the cutting end; `None` if
/// there is none (the scan stops at the first: a gouge is a gouge, its depth is reported).
pub fn first_penetration(
    grid: &PointGrid,
    shape: &CutterShape,
    tip: &Vec3,
    axis: &Unit<Vec3>,
    tolerance: f64,
) -> Option<Penetration> {
    let big_r = shape.radius();
    let top = tip + axis.into_inner() * (CUTTING_END_RADII * big_r);
    let (lo, hi) = (
        tip.inf(&top) - Vec3::repeat(big_r),
        tip.sup(&top) + Vec3::repeat(big_r),
    );
    let mut hit = None;
    grid.visit_box(&lo, &hi, |p| {
        let depth = penetration(shape, tip, axis, p);
        if depth > tolerance {
            hit = Some(Penetration { depth, point: *p });
            false
        } else {
            true
        }
    });
    hit
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn penetration_of_simple_points() {
        let z = Vec3::z_axis();
        let tip = Vec3::zeros();
        let ball = CutterShape::Ball { radius: 3.0 };
        assert!((penetration(&ball, &tip, &z, &Vec3::new(0.0, 0.0, 1.0)) - 1.0).abs() < 1e-12);
        // On the sphere: zero; below the tip: outside.
        let on = Vec3::new(3.0 * 0.6, 0.0, 3.0 - 3.0 * 0.8);
        assert!(penetration(&ball, &tip, &z, &on).abs() < 1e-12);
        assert!(penetration(&ball, &tip, &z, &Vec3::new(0.0, 0.0, -0.1)) < 0.0);
        let flat = CutterShape::Flat { radius: 5.0 };
        assert!((penetration(&flat, &tip, &z, &Vec3::new(4.0, 0.0, 0.5)) - 0.5).abs() < 1e-12);
        assert!((penetration(&flat, &tip, &z, &Vec3::new(4.9, 0.0, 2.0)) - 0.1).abs() < 1e-12);
        let bull = CutterShape::BullNose {
            radius: 6.0,
            corner_radius: 2.0,
        };
        // Corner point at 45° on the torus, moved 0.1 inward.
        let c = Vec3::new(4.0, 0.0, 2.0);
        let dir = Vec3::new(1.0, 0.0, -1.0).normalize();
        let p = c + dir * 1.9;
        assert!((penetration(&bull, &tip, &z, &p) - 0.1).abs() < 1e-12);
    }
}
