//! Topology entities (ISO 10303-42 §5) down to faces: `MANIFOLD_SOLID_BREP`,
//! `BREP_WITH_VOIDS`, `SHELL_BASED_SURFACE_MODEL` → `OPEN_SHELL`/`CLOSED_SHELL` (and their
//! oriented forms) → `ADVANCED_FACE`/`FACE_SURFACE` (and `ORIENTED_FACE`) → `FACE_BOUND`s →
//! `EDGE_LOOP` of `ORIENTED_EDGE`s on `EDGE_CURVE`s, or `VERTEX_LOOP`.

use std::collections::HashSet;

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Curve, Nurbs, NurbsSurface, Trimmed, Vec3};

use super::conic;
use super::entity::{Entity, Resolve};
use super::error::StepError;
use super::geometry::{is_bspline, Geometry, BSPLINE_SURFACES};
use super::model::{Bound, BoundEdge, BoundKind, Face};
use super::pcurve::{self, EdgeRange, ParamMap};
use super::revolved;
use super::swept;

/// The entities that hold a shape; their shells' faces are the model's faces.
const BODIES: [&str; 3] = [
    "MANIFOLD_SOLID_BREP",
    "BREP_WITH_VOIDS",
    "SHELL_BASED_SURFACE_MODEL",
];
const SHELLS: [&str; 2] = ["OPEN_SHELL", "CLOSED_SHELL"];

/// A vertex within this distance (mm) of a curve end is at that end.
const VERTEX_AT_END_MM: f64 = 1e-6;
/// Samples per knot span for locating a vertex inside an edge curve.
const LOCATE_SAMPLES_PER_SPAN: usize = 16;

/// Faces of every body in the file (in `#id` order), or of every shell when the file has no
/// body entity; a face reached twice is read once. With `skip_unsupported`, a face that needs
/// an entity tezgah does not map is left out and its error returned beside the faces read.
pub(crate) fn faces(
    g: &Geometry<'_>,
    skip_unsupported: bool,
) -> Result<(Vec<Face>, Vec<StepError>), StepError> {
    let ids = g.ex.ids();
    let is = |id: &u64, names: &[&str]| {
        g.ex.entity(*id)
            .is_some_and(|e| names.contains(&e.name()) && !e.instance.complex)
    };
    let mut walker = Walker {
        g,
        seen: HashSet::new(),
        out: Vec::new(),
        skip_unsupported,
        skipped: Vec::new(),
    };
    let bodies: Vec<u64> = ids.iter().copied().filter(|id| is(id, &BODIES)).collect();
    if bodies.is_empty() {
        let shells: Vec<u64> = ids.iter().copied().filter(|id| is(id, &SHELLS)).collect();
        if shells.is_empty() {
            return Err(StepError::NoShape);
        }
        for id in shells {
            if let Some(e) = g.ex.entity(id) {
                walker.shell(&e, true, 0)?;
            }
        }
    } else {
        for id in bodies {
            if let Some(e) = g.ex.entity(id) {
                walker.body(&e)?;
            }
        }
    }
    Ok((walker.out, walker.skipped))
}

struct Walker<'g, 'a> {
    g: &'g Geometry<'a>,
    seen: HashSet<u64>,
    out: Vec<Face>,
    skip_unsupported: bool,
    skipped: Vec<StepError>,
}

impl Walker<'_, '_> {
    fn body(&mut self, b: &Entity<'_>) -> Result<(), StepError> {
        let shells = match b.name() {
            "SHELL_BASED_SURFACE_MODEL" => b.refs(1, "sbsm_boundary")?,
            "MANIFOLD_SOLID_BREP" => vec![b.reference(1, "outer")?],
            _ => {
                let mut s = vec![b.reference(1, "outer")?];
                s.extend(b.refs(2, "voids")?);
                s
            }
        };
        for id in shells {
            let s = self.g.ex.get(id, b)?;
            self.shell(&s, true, 0)?;
        }
        Ok(())
    }

    /// `sense` accumulates `ORIENTED_*_SHELL` flips; `depth` bounds oriented-shell chains.
    fn shell(&mut self, s: &Entity<'_>, sense: bool, depth: usize) -> Result<(), StepError> {
        match s.name() {
            "OPEN_SHELL" | "CLOSED_SHELL" => {
                for id in s.refs(1, "cfs_faces")? {
                    let f = self.g.ex.get(id, s)?;
                    self.face(&f, sense, 0)?;
                }
                Ok(())
            }
            "ORIENTED_OPEN_SHELL" | "ORIENTED_CLOSED_SHELL" if depth < 4 => {
                let inner = self.g.ex.get(s.reference(2, "shell element")?, s)?;
                let flip = s.boolean(3, "orientation")?;
                self.shell(&inner, sense == flip, depth + 1)
            }
            _ => Err(StepError::Unsupported {
                at: s.at(),
                role: "a shell".to_string(),
            }),
        }
    }

    fn face(&mut self, f: &Entity<'_>, sense: bool, depth: usize) -> Result<(), StepError> {
        match f.name() {
            "ADVANCED_FACE" | "FACE_SURFACE" => {
                if !self.seen.insert(f.id) {
                    return Ok(());
                }
                match read_face(self.g, f, sense) {
                    Ok(face) => self.out.push(face),
                    Err(e @ StepError::Unsupported { .. }) if self.skip_unsupported => {
                        self.skipped.push(e)
                    }
                    Err(e) => return Err(e),
                }
                Ok(())
            }
            "ORIENTED_FACE" if depth < 4 => {
                let inner = self.g.ex.get(f.reference(2, "face element")?, f)?;
                let flip = f.boolean(3, "orientation")?;
                self.face(&inner, sense == flip, depth + 1)
            }
            _ => Err(StepError::Unsupported {
                at: f.at(),
                role: "a face".to_string(),
            }),
        }
    }
}

fn read_face(g: &Geometry<'_>, f: &Entity<'_>, sense: bool) -> Result<Face, StepError> {
    let same_sense = f.boolean(3, "same_sense")?;
    let mut bounds = Vec::new();
    // One entry per edge of the loops, in order.
    let mut ranges = Vec::new();
    for id in f.refs(1, "bounds")? {
        let b = g.ex.get(id, f)?;
        bounds.push(read_bound(g, &b, &mut ranges)?);
    }
    let s = g.ex.get(f.reference(2, "face_geometry")?, f)?;
    let mut plane_frame = None;
    // The surface, and how the pcurves' coordinates become its parameters (a plane's are
    // lengths: the unit's scale; revolved and swept surfaces: a map).
    let (surface, map) = if is_bspline(s.instance, &BSPLINE_SURFACES) {
        (g.bspline_surface(&s)?, ParamMap::scale(1.0))
    } else if s.name() == "PLANE" && !s.instance.complex {
        let surface = plane(g, &s, &bounds)?;
        plane_frame = Some(g.placement(s.reference(1, "position")?, &s)?);
        (surface, ParamMap::scale(g.mm))
    } else if revolved::REVOLVED.contains(&s.name()) && !s.instance.complex {
        revolved::surface(g, &s, &ranges, &bounds)?
    } else if swept::SWEPT.contains(&s.name()) && !s.instance.complex {
        swept::surface(g, &s, &bounds)?
    } else {
        return Err(StepError::Unsupported {
            at: s.at(),
            role: format!("the surface of {}", f.at()),
        });
    };
    // The pcurves, loop by loop (`ranges` holds one entry per edge, in loop order).
    let mut ranges = ranges.iter();
    for b in &mut bounds {
        let BoundKind::Edges(edges) = &mut b.kind else {
            continue;
        };
        let candidates = edges
            .iter()
            .map(|e| {
                let from_file = match ranges.next() {
                    Some(Some(range)) => pcurve::candidates(g, s.id, &map, range),
                    _ => Vec::new(),
                };
                // A plane is an affine image of its parameters, so an edge without a pcurve
                // gets an exact one by projection (writers such as Parasolid give none).
                match (&plane_frame, from_file.is_empty()) {
                    (Some(frame), true) => pcurve::project_to_plane(&e.curve, frame)
                        .into_iter()
                        .collect(),
                    _ => from_file,
                }
            })
            .collect();
        pcurve::attach_loop(&surface, edges, candidates);
    }
    Ok(Face {
        id: f.id,
        surface,
        same_sense: same_sense == sense,
        bounds,
    })
}

fn read_bound(
    g: &Geometry<'_>,
    b: &Entity<'_>,
    ranges: &mut Vec<Option<EdgeRange>>,
) -> Result<Bound, StepError> {
    let outer = match b.name() {
        "FACE_OUTER_BOUND" => true,
        "FACE_BOUND" => false,
        _ => {
            return Err(StepError::Unsupported {
                at: b.at(),
                role: "a face bound".to_string(),
            })
        }
    };
    let orientation = b.boolean(2, "orientation")?;
    let l = g.ex.get(b.reference(1, "bound")?, b)?;
    let kind = match l.name() {
        "VERTEX_LOOP" => BoundKind::Vertex(g.vertex(l.reference(1, "loop_vertex")?, &l)?),
        "EDGE_LOOP" => {
            let mut edges = Vec::new();
            for id in l.refs(1, "edge_list")? {
                let oe = g.ex.get(id, &l)?;
                let (edge, range) = read_edge(g, &oe)?;
                edges.push(edge);
                ranges.push(range);
            }
            BoundKind::Edges(edges)
        }
        _ => {
            return Err(StepError::Unsupported {
                at: l.at(),
                role: format!("the loop of {}", b.at()),
            })
        }
    };
    Ok(Bound {
        id: b.id,
        outer,
        orientation,
        kind,
    })
}

/// `ORIENTED_EDGE('', *, *, #edge_curve, orientation)` → the edge curve's piece between its
/// vertices (in the curve's parameter direction) and the loop's direction along it, plus the
/// piece's range on the curve's own parameter for the pcurve.
fn read_edge(
    g: &Geometry<'_>,
    oe: &Entity<'_>,
) -> Result<(BoundEdge, Option<EdgeRange>), StepError> {
    if oe.name() != "ORIENTED_EDGE" {
        return Err(StepError::Unsupported {
            at: oe.at(),
            role: "an edge of a loop".to_string(),
        });
    }
    let orientation = oe.boolean(4, "orientation")?;
    let e = g.ex.get(oe.reference(3, "edge_element")?, oe)?;
    if e.name() != "EDGE_CURVE" {
        return Err(StepError::Unsupported {
            at: e.at(),
            role: format!("the edge of {}", oe.at()),
        });
    }
    let v0 = g.vertex(e.reference(1, "edge_start")?, &e)?;
    let v1 = g.vertex(e.reference(2, "edge_end")?, &e)?;
    let geometry = e.reference(3, "edge_geometry")?;
    let c = g.basis_curve(g.ex.get(geometry, &e)?)?;
    let same_sense = e.boolean(4, "same_sense")?;
    // The edge runs from `from` to `to` along the curve's parameter.
    let (from, to) = if same_sense { (v0, v1) } else { (v1, v0) };
    let simple = |name: &str| c.name() == name && !c.instance.complex;
    let (curve, lo, hi) = if simple("LINE") {
        // An edge on a (infinite) line is the segment between its vertices; the line's own
        // parameter (pnt + t·vector) is kept for the pcurve.
        let seg = Nurbs::bspline(1, &[from, to], vec![0.0, 0.0, 1.0, 1.0])
            .map_err(|err| e.invalid(err.to_string()))?;
        let (lo, hi) = line_params(g, &c, from, to).unwrap_or((f64::NAN, f64::NAN));
        let (a, b) = seg.domain();
        (Trimmed::new(seg, a, b), lo, hi)
    } else if simple("CIRCLE") || simple("ELLIPSE") {
        let (arc, start, sweep) = conic::arc(g, &c, v0, v1, same_sense)?;
        let (a, b) = arc.domain();
        // A conic's parameter is its angle in the file's plane angle unit.
        (
            Trimmed::new(arc, a, b),
            start / g.angle,
            (start + sweep) / g.angle,
        )
    } else {
        let curve = g.curve(&c, 0)?;
        let lo = locate(&curve, &from, true);
        let hi = locate(&curve, &to, false);
        if hi <= lo {
            return Err(e.invalid(
                "its vertices do not bound a piece of its curve in the curve's direction",
            ));
        }
        (Trimmed::new(curve, lo, hi), lo, hi)
    };
    let curve = curve.map_err(|err| e.invalid(err.to_string()))?;
    let forward = orientation == same_sense;
    let range = (lo < hi).then_some(EdgeRange { geometry, lo, hi });
    let edge = BoundEdge {
        id: oe.id,
        edge: e.id,
        curve,
        forward,
        pcurve: None,
    };
    Ok((edge, range))
}

/// The parameters of `from` and `to` on `LINE('', pnt, VECTOR('', dir, magnitude))`,
/// `λ(t) = pnt + t·magnitude·dir`.
fn line_params(g: &Geometry<'_>, c: &Entity<'_>, from: Vec3, to: Vec3) -> Option<(f64, f64)> {
    let p = g.point(c.reference(1, "pnt").ok()?, c).ok()?;
    let v = g.ex.entity(c.reference(2, "dir").ok()?)?;
    let d = g.ex.entity(v.reference(1, "orientation").ok()?)?;
    let r = d.reals(1, "direction_ratios").ok()?;
    let [x, y, z] = r.as_slice() else { return None };
    let dir = Vec3::new(*x, *y, *z);
    let step = dir.normalize() * (v.real(2, "magnitude").ok()? * g.mm);
    let t = |q: Vec3| (q - p).dot(&step) / step.norm_squared();
    let (lo, hi) = (t(from), t(to));
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// The parameter of `q` on `curve`: a domain end when `q` is there (`prefer_start` says which
/// end wins on a closed curve), else the closest point.
fn locate(curve: &Nurbs, q: &Vec3, prefer_start: bool) -> f64 {
    let (a, b) = curve.domain();
    let at = |t: f64| (curve.point(t) - q).norm() <= VERTEX_AT_END_MM;
    let ends = if prefer_start { [a, b] } else { [b, a] };
    for t in ends {
        if at(t) {
            return t;
        }
    }
    let spans = curve.breakpoints().len().max(2) - 1;
    closest_point(curve, q, a, b, LOCATE_SAMPLES_PER_SPAN * spans).u
}

/// A `PLANE` face as the bilinear patch over a rectangle, in the plane's axes, that holds
/// its bounds (their edge curves' control points).
fn plane(g: &Geometry<'_>, s: &Entity<'_>, bounds: &[Bound]) -> Result<NurbsSurface, StepError> {
    let (origin, x, y) = g.placement(s.reference(1, "position")?, s)?;
    let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for b in bounds {
        let pts = match &b.kind {
            BoundKind::Vertex(p) => vec![*p],
            // Control points bound their curve (positive weights: convex hull property),
            // so the rectangle holds the whole face; it is exact for straight edges.
            BoundKind::Edges(edges) => edges
                .iter()
                .flat_map(|e| e.curve.inner().control_points())
                .collect(),
        };
        for p in pts {
            let d = p - origin;
            let (u, v) = (d.dot(&x), d.dot(&y));
            u0 = u0.min(u);
            u1 = u1.max(u);
            v0 = v0.min(v);
            v1 = v1.max(v);
        }
    }
    if !(u0 < u1 && v0 < v1) {
        return Err(s.invalid("a plane face needs bounds that enclose an area"));
    }
    let corner = |u: f64, v: f64| origin + x * u + y * v;
    let pts = [
        corner(u0, v0),
        corner(u0, v1),
        corner(u1, v0),
        corner(u1, v1),
    ];
    NurbsSurface::bspline(1, 1, &pts, vec![u0, u0, u1, u1], vec![v0, v0, v1, v1])
        .map_err(|e| s.invalid(e.to_string()))
}
