//! Swept surfaces (ISO 10303-42 §4.4.31–33): `SURFACE_OF_LINEAR_EXTRUSION` (a curve moved
//! along a vector — how CAD systems write extruded B-spline profiles) and
//! `SURFACE_OF_REVOLUTION` (a curve turned about an axis), as exact NURBS: the swept curve's
//! control net times a line or a circular arc (Piegl & Tiller §8.3, §8.5). Both are unbounded
//! in the sweep direction; the face's extent there comes from its 3-D loops.

use std::f64::consts::TAU;

use tezgah_geom::{Nurbs, NurbsSurface, Vec3};

use super::conic::{radii, Frame};
use super::entity::{Entity, Resolve};
use super::error::StepError;
use super::geometry::{is_bspline, Geometry, BSPLINE_CURVES};
use super::model::{Bound, BoundKind};
use super::pcurve::{Axis, ParamMap};
use super::revolved::{arc_extent, EXTENT_SAMPLES_PER_EDGE};

/// The swept surface types read here.
pub(crate) const SWEPT: [&str; 2] = ["SURFACE_OF_LINEAR_EXTRUSION", "SURFACE_OF_REVOLUTION"];

/// The face on the swept surface `s`, bounded by `bounds`.
pub(crate) fn surface(
    g: &Geometry<'_>,
    s: &Entity<'_>,
    bounds: &[Bound],
) -> Result<(NurbsSurface, ParamMap), StepError> {
    let c = g.basis_curve(g.ex.get(s.reference(1, "swept_curve")?, s)?)?;
    let profile = swept_curve(g, &c, s)?;
    let pts = loop_points(bounds);
    if pts.is_empty() {
        return Err(s.invalid("a face on a swept surface needs edge loops for its extent"));
    }
    let no_area = || s.invalid("the face's bounds do not span an area on it");
    // The swept curve's parameter: a B-spline's own; a conic's angle, which its NURBS maps.
    let conic = matches!(c.name(), "CIRCLE" | "ELLIPSE") && !c.instance.complex;
    let (curve_axis, curve_scale) = if conic {
        (
            Axis::Arc {
                start: 0.0,
                sweep: TAU,
            },
            g.angle,
        )
    } else {
        (Axis::Identity, 1.0)
    };
    if s.name() == "SURFACE_OF_LINEAR_EXTRUSION" {
        let surface = extrusion(g, s, &profile, &pts)?.ok_or_else(no_area)?;
        let map = ParamMap {
            u: curve_axis,
            v: Axis::Identity,
            u_scale: curve_scale,
            v_scale: 1.0,
        };
        Ok((surface, map))
    } else {
        let (surface, u0, u1) = revolution(g, s, &profile, &pts)?.ok_or_else(no_area)?;
        let map = ParamMap {
            u: Axis::Arc {
                start: u0,
                sweep: u1 - u0,
            },
            v: curve_axis,
            u_scale: g.angle,
            v_scale: curve_scale,
        };
        Ok((surface, map))
    }
}

/// The swept curve as a NURBS: a B-spline as written, a circle or ellipse as the whole conic.
fn swept_curve(g: &Geometry<'_>, c: &Entity<'_>, s: &Entity<'_>) -> Result<Nurbs, StepError> {
    if matches!(c.name(), "CIRCLE" | "ELLIPSE") && !c.instance.complex {
        let (centre, x, y) = g.placement(c.reference(1, "position")?, c)?;
        let (r1, r2) = radii(c, g.mm)?;
        let frame = Frame {
            centre,
            x: x * r1,
            y: y * r2,
        };
        return frame.arc(0.0, TAU).map_err(|e| c.invalid(e.to_string()));
    }
    if is_bspline(c.instance, &BSPLINE_CURVES) {
        return g.curve(c, 0);
    }
    Err(StepError::Unsupported {
        at: c.at(),
        role: format!("the swept curve of {}", s.at()),
    })
}

/// Samples and control points of the face's edges: a superset's worth of the face.
fn loop_points(bounds: &[Bound]) -> Vec<Vec3> {
    let mut pts = Vec::new();
    for b in bounds {
        if let BoundKind::Edges(edges) = &b.kind {
            for e in edges {
                pts.extend(e.polyline(EXTENT_SAMPLES_PER_EDGE));
                pts.extend(e.curve.inner().control_points());
            }
        }
    }
    pts
}

/// `S(u, v) = C(u) + v·V` over the curve's domain and the loops' range of v: a point
/// `C(u) + v·V` has `p·V̂ = C(u)·V̂ + v|V|`, so v lies between the loop points' extremes of
/// `p·V̂` less the curve's (its control points bound it).
fn extrusion(
    g: &Geometry<'_>,
    s: &Entity<'_>,
    curve: &Nurbs,
    pts: &[Vec3],
) -> Result<Option<NurbsSurface>, StepError> {
    let vector = g.ex.get(s.reference(2, "extrusion_axis")?, s)?;
    let d = g.ex.get(vector.reference(1, "orientation")?, &vector)?;
    let ratios = d.reals(1, "direction_ratios")?;
    let [dx, dy, dz] = ratios.as_slice() else {
        return Err(d.invalid("a 3-D direction needs 3 ratios"));
    };
    let dir = Vec3::new(*dx, *dy, *dz);
    let len = vector.real(2, "magnitude")? * g.mm;
    let n = dir.norm();
    if !(n.is_finite() && n > 0.0 && len.is_finite() && len > 0.0) {
        return Err(vector.invalid("the extrusion vector must be non-zero"));
    }
    let axis = dir.normalize();
    let v = axis * len;
    let (cp, w) = (curve.control_points(), curve.weights());
    let along = |p: &Vec3| p.dot(&axis);
    let (pmin, pmax) = extremes(pts.iter().map(along));
    let (cmin, cmax) = extremes(cp.iter().map(along));
    let (v0, v1) = ((pmin - cmax) / len, (pmax - cmin) / len);
    if !(v0 < v1 && v0.is_finite() && v1.is_finite()) {
        return Ok(None);
    }
    let mut points = Vec::with_capacity(2 * cp.len());
    let mut weights = Vec::with_capacity(2 * cp.len());
    for (c, wi) in cp.iter().zip(&w) {
        points.extend([c + v * v0, c + v * v1]);
        weights.extend([*wi, *wi]);
    }
    NurbsSurface::new(
        curve.degree(),
        1,
        &points,
        &weights,
        curve.knots().to_vec(),
        vec![v0, v0, v1, v1],
    )
    .map(Some)
    .map_err(|e| s.invalid(e.to_string()))
}

/// The curve turned about `AXIS1_PLACEMENT(location, axis)` through the loops' range of
/// angles, measured from the curve's own half-plane (the first control point off the axis):
/// `P_ij = C + h_j·z + ρ_j·(a_i.x·e_j + a_i.y·(z × e_j))`, `w_ij = w_i·w_j` (P&T A8.1), with
/// `a_i, w_i` the arc's control points and weights and `q_j = C + h_j·z + ρ_j·e_j` the curve's.
/// u is the angle, v the curve's parameter, as ISO 10303-42 orders them.
fn revolution(
    g: &Geometry<'_>,
    s: &Entity<'_>,
    curve: &Nurbs,
    pts: &[Vec3],
) -> Result<Option<(NurbsSurface, f64, f64)>, StepError> {
    let a = g.ex.get(s.reference(2, "axis_position")?, s)?;
    if a.name() != "AXIS1_PLACEMENT" {
        return Err(StepError::Unsupported {
            at: a.at(),
            role: format!("the axis of {}", s.at()),
        });
    }
    let centre = g.point(a.reference(1, "location")?, &a)?;
    let z = match a.param(2, "axis")? {
        super::exchange::Param::Unset => Vec3::z(),
        _ => {
            let d = g.ex.get(a.reference(2, "axis")?, &a)?;
            let r = d.reals(1, "direction_ratios")?;
            let [x, y, zz] = r.as_slice() else {
                return Err(d.invalid("a 3-D direction needs 3 ratios"));
            };
            let v = Vec3::new(*x, *y, *zz);
            let n = v.norm();
            if !(n.is_finite() && n > 0.0) {
                return Err(d.invalid("direction has zero length"));
            }
            v.normalize()
        }
    };
    let (cp, w) = (curve.control_points(), curve.weights());
    let radial = |p: &Vec3| {
        let d = p - centre;
        d - z * d.dot(&z)
    };
    let Some(e0) = cp
        .iter()
        .map(radial)
        .find(|r| r.norm() > 1e-9)
        .map(|r| r.normalize())
    else {
        return Err(s.invalid("the swept curve lies on the axis"));
    };
    let f0 = z.cross(&e0);
    let angles: Vec<f64> = pts
        .iter()
        .map(radial)
        .filter(|r| r.norm() > 1e-9)
        .map(|r| r.dot(&f0).atan2(r.dot(&e0)))
        .collect();
    let Some((u0, u1)) = arc_extent(&angles, None) else {
        return Ok(None);
    };
    let arc = Frame {
        centre: Vec3::zeros(),
        x: Vec3::x(),
        y: Vec3::y(),
    }
    .arc(u0, u1 - u0)
    .map_err(|e| s.invalid(e.to_string()))?;
    let (ac, aw) = (arc.control_points(), arc.weights());
    let mut points = Vec::with_capacity(ac.len() * cp.len());
    let mut weights = Vec::with_capacity(ac.len() * cp.len());
    for (ai, wi) in ac.iter().zip(&aw) {
        for (q, wj) in cp.iter().zip(&w) {
            let d = q - centre;
            let h = d.dot(&z);
            let r = d - z * h;
            let rho = r.norm();
            let e = if rho > 1e-12 { r / rho } else { e0 };
            points.push(centre + z * h + (e * ai.x + z.cross(&e) * ai.y) * rho);
            weights.push(wi * wj);
        }
    }
    NurbsSurface::new(
        2,
        curve.degree(),
        &points,
        &weights,
        arc.knots().to_vec(),
        curve.knots().to_vec(),
    )
    .map(|surface| Some((surface, u0, u1)))
    .map_err(|e| s.invalid(e.to_string()))
}

fn extremes(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)))
}
