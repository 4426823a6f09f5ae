//! `CIRCLE` and `ELLIPSE` edges (ISO 10303-42 §4.4.13–14) as exact rational quadratic NURBS
//! arcs between the edge's vertices (Piegl & Tiller A7.1, MakeNurbsCircle; an ellipse is the
//! affine image of the circle construction, which rational quadratics keep exact).

use std::f64::consts::{FRAC_PI_2, TAU};

use tezgah_geom::{Nurbs, Vec3};

use super::entity::{Entity, Resolve};
use super::error::StepError;
use super::geometry::Geometry;

/// The arc of the conic `c` from vertex `v0` to `v1` when `same_sense`, else from `v1` to
/// `v0`, always in the conic's own (counter-clockwise about its axis) direction; equal
/// vertices give the whole conic. Also the arc's start angle and sweep (rad): the conic's own
/// parameter range (ISO 10303-42 parametrises a circle and an ellipse by the angle).
pub(crate) fn arc(
    g: &Geometry<'_>,
    c: &Entity<'_>,
    v0: Vec3,
    v1: Vec3,
    same_sense: bool,
) -> Result<(Nurbs, f64, f64), StepError> {
    let (centre, x, y) = g.placement(c.reference(1, "position")?, c)?;
    let (r1, r2) = radii(c, g.mm)?;
    let angle = |p: Vec3| {
        let d = p - centre;
        (d.dot(&y) / r2).atan2(d.dot(&x) / r1)
    };
    let (from, to) = if same_sense { (v0, v1) } else { (v1, v0) };
    let start = angle(from);
    let mut sweep = (angle(to) - start).rem_euclid(TAU);
    // Equal vertices (a closed edge), or angles equal to rounding: the whole conic.
    if sweep < 1e-12 || (from - to).norm() < 1e-9 * r1.max(r2) {
        sweep = TAU;
    }
    let frame = Frame {
        centre,
        x: x * r1,
        y: y * r2,
    };
    let curve = frame
        .arc(start, sweep)
        .map_err(|e| c.invalid(e.to_string()))?;
    Ok((curve, start, sweep))
}

/// `radius` of a `CIRCLE`, the semi-axes of an `ELLIPSE`, times `scale`.
pub(crate) fn radii(c: &Entity<'_>, scale: f64) -> Result<(f64, f64), StepError> {
    let (r1, r2) = if c.name() == "CIRCLE" {
        let r = c.real(2, "radius")? * scale;
        (r, r)
    } else {
        (
            c.real(2, "semi_axis_1")? * scale,
            c.real(3, "semi_axis_2")? * scale,
        )
    };
    if !(r1.is_finite() && r1 > 0.0 && r2.is_finite() && r2 > 0.0) {
        return Err(c.invalid("radii must be finite and > 0"));
    }
    Ok((r1, r2))
}

/// A conic as `centre + cos t · x + sin t · y` (x, y the semi-axis vectors).
pub(crate) struct Frame {
    pub centre: Vec3,
    pub x: Vec3,
    pub y: Vec3,
}

impl Frame {
    /// The arc `t` in `[start, start + sweep]`, `0 < sweep ≤ 2π`, as a rational quadratic
    /// NURBS of one to four pieces (A7.1: each piece's middle point on the bisector at
    /// `1 / cos(Δ/2)`, weight `cos(Δ/2)`).
    pub fn arc(&self, start: f64, sweep: f64) -> Result<Nurbs, tezgah_geom::CurveError> {
        let at = |t: f64, scale: f64| self.centre + (self.x * t.cos() + self.y * t.sin()) * scale;
        let sweep = sweep.clamp(1e-12, TAU);
        let arcs = ((sweep / FRAC_PI_2) - 1e-9).ceil().max(1.0) as usize;
        let d = sweep / arcs as f64;
        let w = (d / 2.0).cos();
        let mut points = vec![at(start, 1.0)];
        let mut weights = vec![1.0];
        let mut knots = vec![0.0; 3];
        for k in 0..arcs {
            let t0 = start + d * k as f64;
            points.push(at(t0 + d / 2.0, 1.0 / w));
            points.push(at(t0 + d, 1.0));
            weights.extend([w, 1.0]);
            let knot = (k + 1) as f64 / arcs as f64;
            knots.extend(if k + 1 == arcs {
                vec![1.0; 3]
            } else {
                vec![knot; 2]
            });
        }
        Nurbs::new(2, &points, &weights, knots)
    }
}

impl Geometry<'_> {
    /// An `AXIS2_PLACEMENT_3D`: origin (mm) and its orthonormal x and y axes.
    pub fn placement(&self, id: u64, from: &Entity<'_>) -> Result<(Vec3, Vec3, Vec3), StepError> {
        let a = self.ex.get(id, from)?;
        if a.name() != "AXIS2_PLACEMENT_3D" {
            return Err(StepError::Unsupported {
                at: a.at(),
                role: format!("the position of {}", from.at()),
            });
        }
        let origin = self.point(a.reference(1, "location")?, &a)?;
        let z = self.direction(&a, 2)?.unwrap_or_else(Vec3::z);
        let r = self.direction(&a, 3)?.unwrap_or_else(Vec3::x);
        // ISO 10303-42 build_axes: x is ref_direction made perpendicular to the axis.
        let x = r - z * r.dot(&z);
        if x.norm() < 1e-12 {
            return Err(a.invalid("ref_direction is parallel to axis"));
        }
        let x = x.normalize();
        Ok((origin, x, z.cross(&x)))
    }

    /// An optional `DIRECTION` attribute, normalised.
    fn direction(&self, a: &Entity<'_>, i: usize) -> Result<Option<Vec3>, StepError> {
        if matches!(a.param(i, "direction")?, super::exchange::Param::Unset) {
            return Ok(None);
        }
        let d = self.ex.get(a.reference(i, "direction")?, a)?;
        if d.name() != "DIRECTION" {
            return Err(StepError::Unsupported {
                at: d.at(),
                role: format!("a direction of {}", a.at()),
            });
        }
        let c = d.reals(1, "direction_ratios")?;
        let v = match c.as_slice() {
            [x, y, z] => Vec3::new(*x, *y, *z),
            _ => return Err(d.invalid("a 3-D direction needs 3 ratios")),
        };
        let n = v.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(d.invalid("direction has zero length"));
        }
        Ok(Some(v / n))
    }
}
