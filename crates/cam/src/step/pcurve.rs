//! Trimming curves in the surface's parameter plane: the `PCURVE`s of an edge's
//! `SURFACE_CURVE`/`SEAM_CURVE` (ISO 10303-42 §4.4.48), read for the face they lie on and cut
//! to the edge's piece, so a strategy can classify (u, v) against a face's loops directly.
//!
//! The piece is the 3-D edge's parameter range on the pcurve: ISO 10303-42 makes a surface
//! curve's 3-D curve and pcurves representations of one curve, and OpenCascade writes them
//! with one parameter. Writers that do not are caught by a check — the pcurve, mapped through
//! the surface, must meet the 3-D edge at its ends and middle — and the pcurve is then dropped
//! (`None`), never guessed.

use std::f64::consts::TAU;

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Curve, Nurbs, NurbsSurface, Trimmed, Vec3};

use super::conic::{radii, Frame};
use super::entity::{Entity, Resolve};
use super::exchange::Param;
use super::geometry::{is_bspline, Geometry, BSPLINE_CURVES};
use super::model::{BoundEdge, PCurve};

/// How far (mm) the pcurve mapped through the surface may be from the 3-D edge.
pub const PCURVE_TOLERANCE_MM: f64 = 1e-4;

/// What the 3-D side of an edge leaves for its pcurve: the `EDGE_CURVE`'s geometry entity, the
/// edge's range on the 3-D curve's own parameter (`lo < hi`), and the oriented edge's sense.
pub(crate) struct EdgeRange {
    pub geometry: u64,
    pub lo: f64,
    pub hi: f64,
    /// The loop runs along increasing parameter.
    pub forward: bool,
    pub orientation: bool,
}

/// Sets `edge.pcurve` from its surface curve's pcurve on `surface_id` when there is one and it
/// agrees with the 3-D edge. `scale` converts the pcurve's coordinates to the surface's
/// parameters (mm per file unit on a plane, whose parameters are lengths; 1 on a B-spline).
pub(crate) fn attach(
    g: &Geometry<'_>,
    surface_id: u64,
    scale: f64,
    surface: &NurbsSurface,
    edge: &mut BoundEdge,
    range: &EdgeRange,
) {
    edge.pcurve = find(g, surface_id, scale, range)
        .filter(|p| agrees(surface, edge, p))
        .map(|curve| PCurve {
            curve,
            forward: range.forward,
        });
}

/// The pcurve on `surface_id` cut to `range`. A seam lies twice on one surface; OpenCascade
/// lists first the pcurve the edge follows in its forward use.
pub(crate) fn find(
    g: &Geometry<'_>,
    surface_id: u64,
    scale: f64,
    range: &EdgeRange,
) -> Option<Trimmed<Nurbs>> {
    let sc = g.ex.entity(range.geometry)?;
    if !matches!(sc.name(), "SURFACE_CURVE" | "SEAM_CURVE") {
        return None;
    }
    let mut on_surface = Vec::new();
    for p in sc.list(2, "associated_geometry").ok()? {
        let Param::Ref(id) = p else { continue };
        let pc = g.ex.entity(*id)?;
        if pc.name() == "PCURVE" && pc.reference(1, "basis_surface").ok() == Some(surface_id) {
            on_surface.push(pc);
        }
    }
    let pc = match on_surface.len() {
        1 => on_surface[0],
        2 => on_surface[usize::from(!range.orientation)],
        _ => return None,
    };
    let rep = g.ex.entity(pc.reference(2, "reference_to_curve").ok()?)?;
    let item = match rep.list(1, "items").ok()?.first()? {
        Param::Ref(id) => g.ex.entity(*id)?,
        _ => return None,
    };
    curve_2d(g, &item, scale, range.lo, range.hi)
}

/// A 2-D curve (x = u, y = v, z = 0) between its own parameters `lo` and `hi`.
fn curve_2d(
    g: &Geometry<'_>,
    c: &Entity<'_>,
    scale: f64,
    lo: f64,
    hi: f64,
) -> Option<Trimmed<Nurbs>> {
    let simple = |name: &str| c.name() == name && !c.instance.complex;
    if simple("LINE") {
        // λ(t) = pnt + t·vector (ISO 10303-42 line).
        let p = point_2d(g, c.reference(1, "pnt").ok()?, scale)?;
        let v = g.ex.entity(c.reference(2, "dir").ok()?)?;
        let d = direction_2d(g, v.reference(1, "orientation").ok()?)?
            * (v.real(2, "magnitude").ok()? * scale);
        let seg = Nurbs::bspline(1, &[p + d * lo, p + d * hi], vec![0.0, 0.0, 1.0, 1.0]).ok()?;
        return Trimmed::new(seg, 0.0, 1.0).ok();
    }
    if simple("CIRCLE") || simple("ELLIPSE") {
        let a = g.ex.entity(c.reference(1, "position").ok()?)?;
        if a.name() != "AXIS2_PLACEMENT_2D" {
            return None;
        }
        let centre = point_2d(g, a.reference(1, "location").ok()?, scale)?;
        let x = match a.param(2, "ref_direction").ok()? {
            Param::Unset => Vec3::x(),
            Param::Ref(id) => direction_2d(g, *id)?,
            _ => return None,
        };
        let y = Vec3::new(-x.y, x.x, 0.0);
        let (r1, r2) = radii(c, scale).ok()?;
        let frame = Frame {
            centre,
            x: x * r1,
            y: y * r2,
        };
        // The range is in the file's plane angle unit.
        let arc = frame
            .arc(lo * g.angle, ((hi - lo) * g.angle).min(TAU))
            .ok()?;
        return Trimmed::new(arc, 0.0, 1.0).ok();
    }
    if is_bspline(c.instance, &BSPLINE_CURVES) {
        let flat = Geometry {
            ex: g.ex,
            mm: scale,
            angle: g.angle,
        };
        let curve = flat.bspline_curve_2d(c).ok()?;
        return Trimmed::new(curve, lo, hi).ok();
    }
    None
}

fn point_2d(g: &Geometry<'_>, id: u64, scale: f64) -> Option<Vec3> {
    let p = g.ex.entity(id)?;
    match p.reals(1, "coordinates").ok()?.as_slice() {
        [x, y] if p.name() == "CARTESIAN_POINT" => Some(Vec3::new(*x, *y, 0.0) * scale),
        _ => None,
    }
}

fn direction_2d(g: &Geometry<'_>, id: u64) -> Option<Vec3> {
    let d = g.ex.entity(id)?;
    match d.reals(1, "direction_ratios").ok()?.as_slice() {
        [x, y] if d.name() == "DIRECTION" => {
            let v = Vec3::new(*x, *y, 0.0);
            let n = v.norm();
            (n.is_finite() && n > 0.0).then(|| v / n)
        }
        _ => None,
    }
}

/// The pcurve through the surface meets the 3-D edge at both ends and lies on it midway.
fn agrees(surface: &NurbsSurface, edge: &BoundEdge, uv: &Trimmed<Nurbs>) -> bool {
    let (a, b) = uv.domain();
    let on_surface = |t: f64| {
        let p = uv.point(t);
        surface.point(p.x, p.y)
    };
    let (e0, e1) = edge.curve.domain();
    let (start, end) = (edge.curve.point(e0), edge.curve.point(e1));
    let ends = (on_surface(a) - start).norm() <= PCURVE_TOLERANCE_MM
        && (on_surface(b) - end).norm() <= PCURVE_TOLERANCE_MM;
    let spans = edge.curve.breakpoints().len().max(2) - 1;
    ends && closest_point(&edge.curve, &on_surface(0.5 * (a + b)), e0, e1, 16 * spans).distance
        <= PCURVE_TOLERANCE_MM
}

impl Geometry<'_> {
    /// A B-spline pcurve: its control points are `CARTESIAN_POINT`s with two coordinates.
    fn bspline_curve_2d(&self, c: &Entity<'_>) -> Result<Nurbs, super::error::StepError> {
        self.bspline_curve_with(c, |id, from| {
            point_2d(self, id, self.mm).ok_or_else(|| from.invalid("a pcurve point must be 2-D"))
        })
    }
}
