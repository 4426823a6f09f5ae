//! Trimming curves in the surface's parameter plane: the `PCURVE`s of an edge's
//! `SURFACE_CURVE`/`SEAM_CURVE` (ISO 10303-42 §4.4.48), read for the face they lie on and cut
//! to the edge's piece, so a strategy can classify (u, v) against a face's loops directly.
//!
//! The piece is the 3-D edge's parameter range on the pcurve: ISO 10303-42 makes a surface
//! curve's 3-D curve and pcurves representations of one curve, and OpenCascade writes them
//! with one parameter. Writers that do not are caught by a check — the pcurve, mapped through
//! the surface, must meet the 3-D edge at its ends and middle — and the pcurve is then dropped
//! (`None`), never guessed.

use std::f64::consts::{FRAC_PI_2, TAU};

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Curve, Nurbs, NurbsSurface, Trimmed, Vec3};

use super::conic::{radii, Frame};
use super::entity::{Entity, Resolve};
use super::exchange::Param;
use super::geometry::{is_bspline, Geometry, BSPLINE_CURVES};
use super::model::{BoundEdge, PCurve};

/// How far (mm) the pcurve mapped through the surface may be from the 3-D edge.
pub const PCURVE_TOLERANCE_MM: f64 = 1e-4;

/// What the 3-D side of an edge leaves for its pcurve: the `EDGE_CURVE`'s geometry entity and
/// the edge's range on the 3-D curve's own parameter (`lo < hi`).
pub(crate) struct EdgeRange {
    pub geometry: u64,
    pub lo: f64,
    pub hi: f64,
}

/// How the file's (u, v) of a surface become the parameters of tezgah's NURBS for it: per
/// direction a scale (the file's angle or length unit) then an `Axis` map.
pub(crate) struct ParamMap {
    pub u: Axis,
    pub v: Axis,
    pub u_scale: f64,
    pub v_scale: f64,
}

/// One direction's map from the file's parameter (scaled) to the NURBS parameter.
pub(crate) enum Axis {
    Identity,
    /// `[from, to]` onto `[0, 1]`.
    Affine {
        from: f64,
        to: f64,
    },
    /// An angle onto the parameter of `conic::Frame::arc(start, sweep)` (in `[0, 1]`).
    Arc {
        start: f64,
        sweep: f64,
    },
}

impl ParamMap {
    /// The pcurves' coordinates times `scale` are the surface's parameters.
    pub fn scale(scale: f64) -> Self {
        ParamMap {
            u: Axis::Identity,
            v: Axis::Identity,
            u_scale: scale,
            v_scale: scale,
        }
    }
}

impl Axis {
    fn map(&self, x: f64) -> f64 {
        match *self {
            Axis::Identity => x,
            Axis::Affine { from, to } => (x - from) / (to - from),
            Axis::Arc { start, sweep } => arc_param(start, sweep, x),
        }
    }
}

/// The parameter at angle `angle` of the rational arc `Frame::arc(start, sweep)`: its `n` equal
/// pieces of `d = sweep / n` each take `1/n` of `[0, 1]`, and within a piece, whose middle is
/// at angle `m`, `tan((angle − m)/2) = (2t − 1)·tan(d/4)` (t the piece's own parameter: the
/// rational quadratic circle's stereographic parametrisation, P&T §7.2).
fn arc_param(start: f64, sweep: f64, angle: f64) -> f64 {
    let n = ((sweep / FRAC_PI_2) - 1e-9).ceil().max(1.0);
    let d = sweep / n;
    // The angle within [start, start + sweep], turns added or taken away.
    let mut rel = angle - start;
    if rel < -1e-9 {
        rel += TAU * (-rel / TAU).ceil();
    }
    if rel > sweep + 1e-9 {
        rel -= TAU * ((rel - sweep) / TAU).ceil();
    }
    let rel = rel.clamp(0.0, sweep);
    let k = (rel / d).floor().min(n - 1.0).max(0.0);
    let psi = rel - k * d - d / 2.0;
    let s = (psi / 2.0).tan() / (d / 4.0).tan();
    (k + (1.0 + s) / 2.0) / n
}

/// The candidate pcurves of an edge in the surface's parameters: the file's pcurves on
/// `surface_id` through `map`. Affine maps carry any pcurve over exactly; through an angle map
/// only iso-parametric pcurves (a constant u or v, such as seams and the circles of a revolved
/// surface) stay straight, so only those are kept.
pub(crate) fn candidates(
    g: &Geometry<'_>,
    surface_id: u64,
    map: &ParamMap,
    range: &EdgeRange,
) -> Vec<Trimmed<Nurbs>> {
    if matches!(map.u, Axis::Identity) && matches!(map.v, Axis::Identity) {
        // Plain scale: built scaled (B-spline surfaces, planes).
        return find_all(g, surface_id, map.u_scale, range);
    }
    find_all(g, surface_id, 1.0, range)
        .iter()
        .filter_map(|pc| remap(pc, map))
        .collect()
}

/// The edge's piece in the parameters of the plane `origin + u·x + v·y` (x, y orthonormal):
/// the projection is affine, so mapping the control points gives the exact 2-D NURBS.
pub(crate) fn project_to_plane(
    curve: &Trimmed<Nurbs>,
    (origin, x, y): &(Vec3, Vec3, Vec3),
) -> Option<Trimmed<Nurbs>> {
    let inner = curve.inner();
    let points: Vec<Vec3> = inner
        .control_points()
        .into_iter()
        .map(|p| {
            let d = p - origin;
            Vec3::new(d.dot(x), d.dot(y), 0.0)
        })
        .collect();
    let flat = Nurbs::new(
        inner.degree(),
        &points,
        &inner.weights(),
        inner.knots().to_vec(),
    )
    .ok()?;
    let (a, b) = curve.domain();
    Trimmed::new(flat, a, b).ok()
}

fn remap(pc: &Trimmed<Nurbs>, m: &ParamMap) -> Option<Trimmed<Nurbs>> {
    let at = |p: Vec3| Vec3::new(m.u.map(p.x * m.u_scale), m.v.map(p.y * m.v_scale), 0.0);
    let affine = |a: &Axis| !matches!(a, Axis::Arc { .. });
    let (a, b) = pc.domain();
    if affine(&m.u) && affine(&m.v) {
        let inner = pc.inner();
        let points: Vec<Vec3> = inner.control_points().into_iter().map(at).collect();
        let curve = Nurbs::new(
            inner.degree(),
            &points,
            &inner.weights(),
            inner.knots().to_vec(),
        )
        .ok()?;
        return Trimmed::new(curve, a, b).ok();
    }
    let (p0, pm, p1) = (pc.point(a), pc.point(0.5 * (a + b)), pc.point(b));
    let flat = |x: f64, y: f64, z: f64| {
        (x - y).abs() <= 1e-9 * (1.0 + x.abs()) && (x - z).abs() <= 1e-9 * (1.0 + x.abs())
    };
    if !(flat(p0.x, pm.x, p1.x) || flat(p0.y, pm.y, p1.y)) {
        return None;
    }
    let seg = Nurbs::bspline(1, &[at(p0), at(p1)], vec![0.0, 0.0, 1.0, 1.0]).ok()?;
    Trimmed::new(seg, 0.0, 1.0).ok()
}

/// The pcurves on `surface_id` cut to `range`: one, or two for a seam (which lies twice on
/// its surface; which one a use of the seam follows is settled by the loop, in `attach_loop`).
pub(crate) fn find_all(
    g: &Geometry<'_>,
    surface_id: u64,
    scale: f64,
    range: &EdgeRange,
) -> Vec<Trimmed<Nurbs>> {
    let Some(sc) = g.ex.entity(range.geometry) else {
        return Vec::new();
    };
    if !matches!(sc.name(), "SURFACE_CURVE" | "SEAM_CURVE") {
        return Vec::new();
    }
    let Ok(items) = sc.list(2, "associated_geometry") else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for p in items {
        let Param::Ref(id) = p else { continue };
        let Some(pc) = g.ex.entity(*id) else { continue };
        if pc.name() != "PCURVE" || pc.reference(1, "basis_surface").ok() != Some(surface_id) {
            continue;
        }
        let curve = (|| {
            let rep = g.ex.entity(pc.reference(2, "reference_to_curve").ok()?)?;
            let item = match rep.list(1, "items").ok()?.first()? {
                Param::Ref(id) => g.ex.entity(*id)?,
                _ => return None,
            };
            curve_2d(g, &item, scale, range.lo, range.hi)
        })();
        out.extend(curve);
    }
    if out.len() > 2 {
        out.clear();
    }
    out
}

/// The first pcurve on `surface_id` cut to `range` (enough for a face's extent: a seam's two
/// pcurves bound the same box as either with the rest of the loop).
pub(crate) fn find(
    g: &Geometry<'_>,
    surface_id: u64,
    scale: f64,
    range: &EdgeRange,
) -> Option<Trimmed<Nurbs>> {
    find_all(g, surface_id, scale, range).into_iter().next()
}

/// Sets the pcurves of one loop's edges from their candidates (`None` without a range): each
/// candidate must agree with its 3-D edge; where a seam offers two, the loop decides — the
/// one starting where the previous edge's pcurve ends, the first seam's choice being the one
/// that closes the loop best.
pub(crate) fn attach_loop(
    surface: &NurbsSurface,
    edges: &mut [BoundEdge],
    candidates: Vec<Vec<Trimmed<Nurbs>>>,
) {
    let candidates: Vec<Vec<Trimmed<Nurbs>>> = candidates
        .into_iter()
        .zip(edges.iter())
        .map(|(c, e)| c.into_iter().filter(|p| agrees(surface, e, p)).collect())
        .collect();
    let ends = |e: &BoundEdge, p: &Trimmed<Nurbs>| {
        let (a, b) = p.domain();
        let (s, t) = (p.point(a), p.point(b));
        if e.forward {
            (s, t)
        } else {
            (t, s)
        }
    };
    // Walk the loop from edge `first` taking candidate `pick` there; returns the choices and
    // the gap left between the last pcurve's end and the first's start.
    let walk = |first: usize, pick: usize| {
        let n = edges.len();
        let mut choice = vec![None; n];
        let mut prev_end: Option<Vec3> = None;
        let mut first_start = None;
        for step in 0..n {
            let i = (first + step) % n;
            let c = &candidates[i];
            let k = match (c.len(), prev_end) {
                (0, _) => None,
                (1, _) => Some(0),
                (_, _) if step == 0 => Some(pick),
                (_, Some(end)) => (0..c.len()).min_by(|&x, &y| {
                    let dx = (ends(&edges[i], &c[x]).0 - end).norm();
                    let dy = (ends(&edges[i], &c[y]).0 - end).norm();
                    dx.total_cmp(&dy)
                }),
                (_, None) => Some(0),
            };
            choice[i] = k;
            match k {
                Some(k) => {
                    let (s, e) = ends(&edges[i], &c[k]);
                    if step == 0 {
                        first_start = Some(s);
                    }
                    prev_end = Some(e);
                }
                None => prev_end = None,
            }
        }
        let gap = match (first_start, prev_end) {
            (Some(s), Some(e)) => (s - e).norm(),
            _ => f64::INFINITY,
        };
        (choice, gap)
    };
    let first = candidates.iter().position(|c| c.len() == 2).unwrap_or(0);
    let (choice, _) = (0..candidates.get(first).map_or(1, |c| c.len().max(1)))
        .map(|pick| walk(first, pick))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or_else(|| (vec![None; edges.len()], f64::INFINITY));
    for ((edge, mut c), k) in edges.iter_mut().zip(candidates).zip(choice) {
        edge.pcurve = k.map(|k| PCurve {
            curve: c.swap_remove(k),
            forward: edge.forward,
        });
    }
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
