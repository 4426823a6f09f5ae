//! Surfaces of revolution about an axis — `CYLINDRICAL_SURFACE`, `CONICAL_SURFACE`,
//! `SPHERICAL_SURFACE`, `TOROIDAL_SURFACE` (ISO 10303-42 §4.4.25–28) — as exact NURBS: the
//! profile (a line or a circular arc in the (radius, height) half-plane) swept by a circular
//! arc (Piegl & Tiller §8.5, A8.1). These surfaces are unbounded or periodic; the face's
//! extent in the surface's own (u, v) comes from its pcurves.
//!
//! The NURBS keeps the directions of ISO's (u, v) — u the angle about the axis, v along the
//! profile — and so the face's orientation, but not the angle parameterisation itself (a
//! rational arc is not uniform in angle): parameters of the file do not carry over, and the
//! face's pcurves, checked against the new surface, are dropped.

use std::f64::consts::{FRAC_PI_2, TAU};

use tezgah_geom::{NurbsSurface, Vec3};

use super::conic::Frame;
use super::entity::Entity;
use super::error::StepError;
use super::geometry::Geometry;
use super::model::{Bound, BoundKind};
use super::pcurve::{self, Axis, EdgeRange, ParamMap};

/// The surface types read here.
pub(crate) const REVOLVED: [&str; 4] = [
    "CYLINDRICAL_SURFACE",
    "CONICAL_SURFACE",
    "SPHERICAL_SURFACE",
    "TOROIDAL_SURFACE",
];

/// The profile in the (ρ, ζ) half-plane as a function of ISO's v.
enum Profile {
    /// ρ = r0 + v·slope, ζ = v (cylinder: slope 0; cone: tan of the semi-angle).
    Line { r0: f64, slope: f64 },
    /// ρ = rho0 + r cos v, ζ = r sin v (sphere: rho0 = 0; torus: the major radius).
    Arc { rho0: f64, r: f64 },
}

/// The face on surface `s` whose edges' ranges are `ranges`, as a NURBS surface over the
/// extent of the face's pcurves on `s`.
pub(crate) fn surface(
    g: &Geometry<'_>,
    s: &Entity<'_>,
    ranges: &[Option<EdgeRange>],
    bounds: &[Bound],
) -> Result<(NurbsSurface, ParamMap), StepError> {
    let (centre, x, y) = g.placement(s.reference(1, "position")?, s)?;
    let z = x.cross(&y);
    let length = |i: usize, what: &str| -> Result<f64, StepError> {
        let v = s.real(i, what)? * g.mm;
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(s.invalid(format!("{what} must be > 0")))
        }
    };
    let sphere = s.name() == "SPHERICAL_SURFACE";
    let profile = match s.name() {
        "CYLINDRICAL_SURFACE" => Profile::Line {
            r0: length(2, "radius")?,
            slope: 0.0,
        },
        "CONICAL_SURFACE" => {
            let r0 = s.real(2, "radius")? * g.mm;
            let angle = s.real(3, "semi_angle")? * g.angle;
            if !(r0.is_finite() && r0 >= 0.0 && angle.abs() < FRAC_PI_2 && angle != 0.0) {
                return Err(s.invalid("a cone needs radius ≥ 0 and 0 < |semi_angle| < 90°"));
            }
            Profile::Line {
                r0,
                slope: angle.tan(),
            }
        }
        "SPHERICAL_SURFACE" => Profile::Arc {
            rho0: 0.0,
            r: length(2, "radius")?,
        },
        _ => Profile::Arc {
            rho0: length(2, "major_radius")?,
            r: length(3, "minor_radius")?,
        },
    };
    // The face's extent in ISO's (u, v): the box of its pcurves' control points (the pcurves
    // are in the file's angle unit and length unit).
    let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let v_scale = match profile {
        Profile::Line { .. } => g.mm,
        Profile::Arc { .. } => g.angle,
    };
    // Every edge must give its pcurve, or the box could miss part of the face.
    let mut complete = !ranges.is_empty();
    for range in ranges {
        let Some(pc) = range.as_ref().and_then(|r| pcurve::find(g, s.id, 1.0, r)) else {
            complete = false;
            break;
        };
        for p in pc.inner().control_points() {
            let (u, v) = (p.x * g.angle, p.y * v_scale);
            u0 = u0.min(u);
            u1 = u1.max(u);
            v0 = v0.min(v);
            v1 = v1.max(v);
        }
    }
    if !complete {
        // Without (all) pcurves, the extent comes from the 3-D loops (writers such as
        // Parasolid give none); a closed surface without loops is whole.
        let frame = Axes { centre, x, y, z };
        match loop_extent(&frame, &profile, sphere, bounds) {
            Some(e) => (u0, u1, v0, v1) = e,
            None => match profile {
                Profile::Arc { .. } => {
                    (u0, u1) = (0.0, TAU);
                    (v0, v1) = if sphere {
                        (-FRAC_PI_2, FRAC_PI_2)
                    } else {
                        (0.0, TAU)
                    };
                }
                Profile::Line { .. } => {
                    return Err(s.invalid("a face on an unbounded surface needs bounds"))
                }
            },
        }
    }
    let u1 = u1.min(u0 + TAU);
    let (v0, v1) = match profile {
        Profile::Arc { .. } if sphere => (v0.max(-FRAC_PI_2), v1.min(FRAC_PI_2)),
        Profile::Arc { .. } => (v0, v1.min(v0 + TAU)),
        Profile::Line { .. } => (v0, v1),
    };
    if !(u0 < u1 && v0 < v1) {
        return Err(s.invalid("the face's bounds do not span an area on it"));
    }
    // The profile as (ρ, ζ) control points with weights, and its knots.
    let (rz, knots_v) = match profile {
        Profile::Line { r0, slope } => (
            vec![
                (Vec3::new(r0 + v0 * slope, v0, 0.0), 1.0),
                (Vec3::new(r0 + v1 * slope, v1, 0.0), 1.0),
            ],
            vec![0.0, 0.0, 1.0, 1.0],
        ),
        Profile::Arc { rho0, r } => {
            let arc = Frame {
                centre: Vec3::new(rho0, 0.0, 0.0),
                x: Vec3::new(r, 0.0, 0.0),
                y: Vec3::new(0.0, r, 0.0),
            }
            .arc(v0, v1 - v0)
            .map_err(|e| s.invalid(e.to_string()))?;
            let pts = arc
                .control_points()
                .into_iter()
                .zip(arc.weights())
                .collect();
            (pts, arc.knots().to_vec())
        }
    };
    let sweep = Frame {
        centre: Vec3::zeros(),
        x: Vec3::x(),
        y: Vec3::y(),
    }
    .arc(u0, u1 - u0)
    .map_err(|e| s.invalid(e.to_string()))?;
    // P_ij = C + ρ_j·(a_i.x·x + a_i.y·y) + ζ_j·z, w_ij = w_i·w_j: the product of the two
    // rational curves is the revolved surface exactly (P&T A8.1).
    let (a, wa) = (sweep.control_points(), sweep.weights());
    let (mut points, mut weights) = (Vec::new(), Vec::new());
    for (ai, wi) in a.iter().zip(&wa) {
        for (p, wj) in &rz {
            points.push(centre + (x * ai.x + y * ai.y) * p.x + z * p.y);
            weights.push(wi * wj);
        }
    }
    let degree_v = if rz.len() == 2 { 1 } else { 2 };
    let knots_u = sweep.knots().to_vec();
    let surface = NurbsSurface::new(2, degree_v, &points, &weights, knots_u, knots_v)
        .map_err(|e| s.invalid(e.to_string()))?;
    let map = ParamMap {
        u: Axis::Arc {
            start: u0,
            sweep: u1 - u0,
        },
        v: match profile {
            Profile::Line { .. } => Axis::Affine { from: v0, to: v1 },
            Profile::Arc { .. } => Axis::Arc {
                start: v0,
                sweep: v1 - v0,
            },
        },
        u_scale: g.angle,
        v_scale,
    };
    Ok((surface, map))
}

/// The surface's frame: origin and axes (z the axis of revolution).
struct Axes {
    centre: Vec3,
    x: Vec3,
    y: Vec3,
    z: Vec3,
}

/// Angles closer than this on either side of the loops' largest angular gap make the face a
/// full turn (the extent then holds the face all the same: a superset is always safe).
const FULL_TURN_GAP: f64 = 0.5;
/// Points per edge, beside its control points, that the loop extent looks at.
pub(crate) const EXTENT_SAMPLES_PER_EDGE: usize = 32;

/// The ISO (u, v) box of the face's 3-D loops: u the angle about the axis and (torus) v the
/// angle about the tube, each the circle minus its largest gap between loop points; v the
/// height (cylinder, cone) or latitude (sphere). Control points join the samples so that the
/// box holds curved edges (convex hull), not only their samples. `None` without edge loops.
fn loop_extent(
    f: &Axes,
    profile: &Profile,
    sphere: bool,
    bounds: &[Bound],
) -> Option<(f64, f64, f64, f64)> {
    let mut pts: Vec<Vec3> = Vec::new();
    for b in bounds {
        match &b.kind {
            BoundKind::Vertex(p) => pts.push(*p),
            BoundKind::Edges(edges) => {
                for e in edges {
                    pts.extend(e.polyline(EXTENT_SAMPLES_PER_EDGE));
                    pts.extend(e.curve.inner().control_points());
                }
            }
        }
    }
    if !bounds.iter().any(|b| matches!(b.kind, BoundKind::Edges(_))) {
        return None;
    }
    let local: Vec<(f64, f64, f64)> = pts
        .iter()
        .map(|p| {
            let d = p - f.centre;
            (d.dot(&f.x), d.dot(&f.y), d.dot(&f.z))
        })
        .collect();
    // Points on the axis (a sphere's pole) have no angle about it.
    let around: Vec<f64> = local
        .iter()
        .filter(|(a, b, _)| a.hypot(*b) > 1e-9)
        .map(|(a, b, _)| b.atan2(*a))
        .collect();
    let axial = |p: &Vec3| {
        let d = p - f.centre;
        let (a, b) = (d.dot(&f.x), d.dot(&f.y));
        (a.hypot(b) > 1e-9).then(|| b.atan2(a))
    };
    let (u0, u1) = arc_extent(&around, seam_angle(bounds, axial))?;
    let (v0, v1) = match *profile {
        Profile::Line { .. } => {
            let h = local.iter().map(|l| l.2);
            (
                h.clone().fold(f64::MAX, f64::min),
                h.fold(f64::MIN, f64::max),
            )
        }
        Profile::Arc { .. } if sphere => {
            let lat = local.iter().map(|(a, b, c)| c.atan2(a.hypot(*b)));
            (
                lat.clone().fold(f64::MAX, f64::min),
                lat.fold(f64::MIN, f64::max),
            )
        }
        Profile::Arc { rho0, .. } => {
            let tube: Vec<f64> = local
                .iter()
                .map(|(a, b, c)| c.atan2(a.hypot(*b) - rho0))
                .collect();
            let tube_angle = |p: &Vec3| {
                let d = p - f.centre;
                let (a, b, c) = (d.dot(&f.x), d.dot(&f.y), d.dot(&f.z));
                Some(c.atan2(a.hypot(b) - rho0))
            };
            arc_extent(&tube, seam_angle(bounds, tube_angle))?
        }
    };
    Some((u0, u1, v0, v1))
}

/// The smallest arc `[a, b]` (b − a ≤ 2π) of the circle holding all `angles`: the circle minus
/// the largest gap between neighbours, or the full turn — from `seam` when the face has one —
/// when no gap reaches `FULL_TURN_GAP`.
pub(crate) fn arc_extent(angles: &[f64], seam: Option<f64>) -> Option<(f64, f64)> {
    let mut a: Vec<f64> = angles
        .iter()
        .map(|t| t.rem_euclid(TAU))
        .filter(|t| t.is_finite())
        .collect();
    a.sort_by(f64::total_cmp);
    let (first, last) = (*a.first()?, *a.last()?);
    // The gap after each angle, the last one wrapping round to the first.
    let mut best = (first + TAU - last, last, first + TAU);
    for w in a.windows(2) {
        if w[1] - w[0] > best.0 {
            best = (w[1] - w[0], w[0], w[1]);
        }
    }
    if best.0 < FULL_TURN_GAP {
        // A full turn starts at the face's seam, so the loops lie on the domain's boundary.
        let start = seam.unwrap_or(0.0);
        return Some((start, start + TAU));
    }
    // The face runs from the gap's end round to its start.
    let start = best.2.rem_euclid(TAU);
    let mut end = best.1;
    while end <= start {
        end += TAU;
    }
    Some((start, end))
}

/// The angle (by `angle_of`) of a seam of the face: an edge its loops use twice, along which
/// that angle is constant (sampled at its ends and middle).
fn seam_angle(bounds: &[Bound], angle_of: impl Fn(&Vec3) -> Option<f64>) -> Option<f64> {
    let edges: Vec<_> = bounds
        .iter()
        .filter_map(|b| match &b.kind {
            BoundKind::Edges(e) => Some(e.iter()),
            BoundKind::Vertex(_) => None,
        })
        .flatten()
        .collect();
    edges.iter().enumerate().find_map(|(i, e)| {
        if !edges[i + 1..].iter().any(|o| o.edge == e.edge) {
            return None;
        }
        let pts = e.polyline(2);
        let a: Vec<f64> = pts.iter().map(&angle_of).collect::<Option<_>>()?;
        let same = |x: f64, y: f64| {
            ((x - y + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI).abs() < 1e-9
        };
        (same(a[0], a[1]) && same(a[1], a[2])).then(|| a[1].rem_euclid(TAU))
    })
}
