//! What STEP input yields: the faces to machine, each a NURBS surface with its orientation
//! and its boundary loops as 3-D edge curves, plus the file's length unit. Everything is in
//! mm, whatever unit the file used.

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Curve, Nurbs, NurbsSurface, Trimmed, Vec3};

use super::error::StepError;
pub use super::units::LengthUnit;

/// A STEP file's free-form faces, in the order of the file's shells (solids and
/// shell-based surface models in increasing `#id`, faces in each shell's order).
#[derive(Debug, Clone, PartialEq)]
pub struct StepModel {
    pub faces: Vec<Face>,
    pub unit: LengthUnit,
    /// `FILE_SCHEMA` of the header (`AUTOMOTIVE_DESIGN` for AP214, `CONFIG_CONTROL_DESIGN` for
    /// AP203), as written.
    pub schemas: Vec<String>,
    /// Faces left out by [`ReadOptions::skip_unsupported_faces`], each with the error that
    /// names what tezgah does not map (always empty otherwise).
    pub skipped: Vec<StepError>,
}

/// How lenient reading is.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Leave out faces whose surface, loop or edge curves use entities tezgah does not map
    /// (a cylinder, a hyperbola …) instead of refusing the file; a malformed file (syntax,
    /// dangling references, bad attributes) is still refused.
    pub skip_unsupported_faces: bool,
}

/// One `ADVANCED_FACE` (or `FACE_SURFACE`).
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The face's `#id` in the file.
    pub id: u64,
    /// The face's surface in mm, with the file's own parameters (knots as written). A
    /// `PLANE` becomes the bilinear patch over its bounds' extent, parametrised as
    /// `origin + u·x_axis + v·y_axis` (u, v in mm), as ISO 10303-42 parametrises a plane.
    pub surface: NurbsSurface,
    /// True when the face's outward normal (toward the material's outside, for a solid) is
    /// `S_u × S_v`; the face's `same_sense` combined with any `ORIENTED_FACE` and
    /// `ORIENTED_*_SHELL` flips on the way to it.
    pub same_sense: bool,
    /// The face's boundary loops. The surface's own domain is always a bound too: the face
    /// is the part of `S(domain)` inside these loops.
    pub bounds: Vec<Bound>,
}

/// Points per edge that [`Face::is_untrimmed`] checks.
pub const UNTRIMMED_SAMPLES_PER_EDGE: usize = 32;

impl Face {
    /// True when the face is its whole surface: every loop runs along the boundary of the
    /// surface's domain (each edge, sampled at [`UNTRIMMED_SAMPLES_PER_EDGE`]` + 1` points, lies
    /// within `tolerance` mm of one of the four boundary iso-curves; a vertex loop, such as a
    /// sphere's pole, on one of them). A strategy can then work on the domain alone; otherwise
    /// it must keep to the loops. A face without bounds is its whole surface.
    pub fn is_untrimmed(&self, tolerance: f64) -> bool {
        let (u0, u1) = self.surface.domain_u();
        let (v0, v1) = self.surface.domain_v();
        let sides = [
            self.surface.u_iso(v0),
            self.surface.u_iso(v1),
            self.surface.v_iso(u0),
            self.surface.v_iso(u1),
        ];
        let on_side = |p: &Vec3| {
            sides.iter().any(|c| {
                let (a, b) = c.domain();
                let spans = c.breakpoints().len().max(2) - 1;
                closest_point(c, p, a, b, 8 * spans).distance <= tolerance
            })
        };
        self.bounds.iter().all(|b| match &b.kind {
            BoundKind::Vertex(p) => on_side(p),
            BoundKind::Edges(edges) => edges
                .iter()
                .all(|e| e.polyline(UNTRIMMED_SAMPLES_PER_EDGE).iter().all(on_side)),
        })
    }
}

/// A `FACE_BOUND` or `FACE_OUTER_BOUND`.
#[derive(Debug, Clone, PartialEq)]
pub struct Bound {
    pub id: u64,
    /// Declared `FACE_OUTER_BOUND`. Writers that only use `FACE_BOUND` (OpenCascade) leave
    /// this false for every loop; the outer loop is then the one enclosing the others.
    pub outer: bool,
    /// The bound's `orientation`: false means the loop is used reversed.
    pub orientation: bool,
    pub kind: BoundKind,
}

/// A loop of edges, or a single vertex (`VERTEX_LOOP`, e.g. a sphere's degenerate pole).
#[derive(Debug, Clone, PartialEq)]
pub enum BoundKind {
    Edges(Vec<BoundEdge>),
    Vertex(Vec3),
}

/// One `ORIENTED_EDGE` of an `EDGE_LOOP`: the piece of its `EDGE_CURVE`'s 3-D curve between
/// the edge's vertices, exactly (a B-spline as written, a line as the segment), and the
/// direction the loop runs along it.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundEdge {
    /// The `ORIENTED_EDGE`'s `#id`.
    pub id: u64,
    /// The `EDGE_CURVE`'s `#id` (shared by the two faces meeting at the edge).
    pub edge: u64,
    /// The piece `[t0, t1]` of the curve the edge covers.
    pub curve: Trimmed<Nurbs>,
    /// True when the loop runs along increasing curve parameter (the oriented edge's
    /// orientation agreeing with the edge curve's `same_sense`).
    pub forward: bool,
    /// The same piece in the face's parameter plane, when the file gives it (a `PCURVE` on
    /// this face's surface that agrees with the 3-D edge; see [`PCurve`]).
    pub pcurve: Option<PCurve>,
}

/// A point of a surface's parameter plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Uv {
    pub u: f64,
    pub v: f64,
}

/// An edge in the face's (u, v) plane: `curve` holds u in x and v in y (z = 0), over the same
/// piece as the 3-D edge, run in loop order when `forward`. It was checked on reading: mapped
/// through the surface it meets the 3-D edge at both ends and in the middle within
/// `PCURVE_TOLERANCE_MM`.
#[derive(Debug, Clone, PartialEq)]
pub struct PCurve {
    pub curve: Trimmed<Nurbs>,
    pub forward: bool,
}

impl PCurve {
    /// `segments + 1` points along the edge in loop order, at equal parameter steps.
    pub fn polyline(&self, segments: usize) -> Vec<Uv> {
        sample(&self.curve, self.forward, segments)
            .into_iter()
            .map(|p| Uv { u: p.x, v: p.y })
            .collect()
    }
}

fn sample(curve: &Trimmed<Nurbs>, forward: bool, segments: usize) -> Vec<Vec3> {
    let n = segments.max(1);
    let (a, b) = curve.domain();
    (0..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            let s = if forward { s } else { 1.0 - s };
            curve.point(a + (b - a) * s)
        })
        .collect()
}

impl Bound {
    /// The loop as a closed polygon in the face's (u, v) plane, `segments_per_edge` pieces per
    /// edge, without repeating each edge's first point; `None` for a vertex loop or when an
    /// edge has no pcurve. The bound's `orientation` is applied (false: reversed).
    pub fn uv_polygon(&self, segments_per_edge: usize) -> Option<Vec<Uv>> {
        let BoundKind::Edges(edges) = &self.kind else {
            return None;
        };
        let mut out = Vec::new();
        for e in edges {
            let pts = e.pcurve.as_ref()?.polyline(segments_per_edge);
            out.extend_from_slice(&pts[..pts.len() - 1]);
        }
        if !self.orientation {
            out.reverse();
        }
        Some(out)
    }
}

impl BoundEdge {
    /// Where the loop enters the edge.
    pub fn start(&self) -> Vec3 {
        let (a, b) = self.curve.domain();
        self.curve.point(if self.forward { a } else { b })
    }

    /// Where the loop leaves the edge.
    pub fn end(&self) -> Vec3 {
        let (a, b) = self.curve.domain();
        self.curve.point(if self.forward { b } else { a })
    }

    /// `segments + 1` points along the edge in loop order, at equal parameter steps
    /// (a polyline of the boundary for classification or display).
    pub fn polyline(&self, segments: usize) -> Vec<Vec3> {
        sample(&self.curve, self.forward, segments)
    }
}
