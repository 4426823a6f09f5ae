//! A trimmed face's loops mapped into its surface's parameter plane ([`FaceRegion`]): the step
//! between reading a face (`model`) and machining only what lies inside its bounds.
//!
//! Each edge becomes a polyline in (u, v) from its pcurve when the file gives one, else from
//! its 3-D points inverted on the surface (closest point). The polyline is refined until the
//! surface image of every chord's midpoint lies within the tolerance of the edge's own point
//! there, the 3-D chord error of a boundary followed in the parameter plane. A loop that will
//! not refine (a jump across a seam with no pcurve to say which side) is refused.

use tezgah_geom::{Curve, Vec3};

use super::model::{BoundEdge, BoundKind, Face};
use crate::region::{FaceRegion, RegionError};

/// Segments each edge starts with before refinement.
const START_SEGMENTS: usize = 8;
/// Halvings of a segment before a loop is declared unmappable (2⁻¹⁶ of an edge).
const MAX_DEPTH: usize = 16;
/// How far an edge without a pcurve may lie from the face's surface, mm.
const OFF_SURFACE_MM: f64 = 1e-3;

/// Why a face's loops could not be mapped into its parameter plane.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FaceRegionError {
    #[error("edge #{edge} lies {distance:.3e} mm off face #{face}'s surface")]
    OffSurface { face: u64, edge: u64, distance: f64 },
    #[error("edge #{edge} of face #{face} cannot be followed in the surface's parameters within {tolerance} mm (it jumps, e.g. across a seam without a pcurve)")]
    Unresolved {
        face: u64,
        edge: u64,
        tolerance: f64,
    },
    #[error("face #{face}: {source}")]
    Region { face: u64, source: RegionError },
}

impl Face {
    /// The face's region in (u, v), its loops followed within `tolerance` mm; `None` when
    /// the face is its whole surface ([`Face::is_untrimmed`] at that tolerance). A vertex
    /// loop (a pole) bounds nothing and is left out. A face of several loops none of which
    /// encloses another has the surface's domain as its outer bound (the loops are holes).
    pub fn uv_region(&self, tolerance: f64) -> Result<Option<FaceRegion>, FaceRegionError> {
        if self.is_untrimmed(tolerance) {
            return Ok(None);
        }
        let mut loops = Vec::new();
        for bound in &self.bounds {
            let BoundKind::Edges(edges) = &bound.kind else {
                continue;
            };
            let mut poly = Vec::new();
            for e in edges {
                let pts = self.edge_uv(e, tolerance)?;
                poly.extend_from_slice(&pts[..pts.len() - 1]);
            }
            if !bound.orientation {
                poly.reverse();
            }
            loops.push(poly);
        }
        if loops.len() > 1 && !any_nested(&loops) {
            let (u0, u1) = self.surface.domain_u();
            let (v0, v1) = self.surface.domain_v();
            loops.push(vec![(u0, v0), (u1, v0), (u1, v1), (u0, v1)]);
        }
        FaceRegion::new(loops)
            .map(Some)
            .map_err(|source| FaceRegionError::Region {
                face: self.id,
                source,
            })
    }

    /// One edge as a (u, v) polyline in loop order, refined to `tolerance` in 3-D.
    fn edge_uv(&self, e: &BoundEdge, tolerance: f64) -> Result<Vec<(f64, f64)>, FaceRegionError> {
        let at = |s: f64| self.edge_point(e, s);
        let mut out = vec![at(0.0)?];
        for k in 0..START_SEGMENTS {
            let (sa, sb) = (
                k as f64 / START_SEGMENTS as f64,
                (k + 1) as f64 / START_SEGMENTS as f64,
            );
            let b = at(sb)?;
            self.refine(
                e,
                (sa, *out.last().expect("started")),
                (sb, b),
                tolerance,
                0,
                &mut out,
            )?;
        }
        Ok(out.into_iter().map(|p| p.uv).collect())
    }

    /// Pushes the points after `a` up to `b` so that every chord's midpoint maps within
    /// `tolerance` of the edge.
    fn refine(
        &self,
        e: &BoundEdge,
        a: (f64, EdgePoint),
        b: (f64, EdgePoint),
        tolerance: f64,
        depth: usize,
        out: &mut Vec<EdgePoint>,
    ) -> Result<(), FaceRegionError> {
        let sm = 0.5 * (a.0 + b.0);
        let mid = self.edge_point(e, sm)?;
        let chord = ((a.1.uv.0 + b.1.uv.0) / 2.0, (a.1.uv.1 + b.1.uv.1) / 2.0);
        let error = (self.surface.point(chord.0, chord.1) - mid.at).norm();
        if error <= tolerance {
            out.push(b.1);
            return Ok(());
        }
        if depth >= MAX_DEPTH {
            return Err(FaceRegionError::Unresolved {
                face: self.id,
                edge: e.id,
                tolerance,
            });
        }
        self.refine(e, a, (sm, mid), tolerance, depth + 1, out)?;
        let m = *out.last().expect("pushed");
        self.refine(e, (sm, m), b, tolerance, depth + 1, out)
    }

    /// The edge's point at the fraction `s` of its run (loop order): where it is in 3-D and
    /// in (u, v).
    fn edge_point(&self, e: &BoundEdge, s: f64) -> Result<EdgePoint, FaceRegionError> {
        if let Some(pc) = &e.pcurve {
            let (a, b) = pc.curve.domain();
            let t = if pc.forward {
                a + (b - a) * s
            } else {
                b - (b - a) * s
            };
            let q = Curve::point(&pc.curve, t);
            return Ok(EdgePoint {
                at: self.surface.point(q.x, q.y),
                uv: (q.x, q.y),
            });
        }
        let (a, b) = e.curve.domain();
        let t = if e.forward {
            a + (b - a) * s
        } else {
            b - (b - a) * s
        };
        let p = Curve::point(&e.curve, t);
        let off = |distance| FaceRegionError::OffSurface {
            face: self.id,
            edge: e.id,
            distance,
        };
        let c = self
            .surface
            .closest_point(&p, 1e-9)
            .map_err(|_| off(f64::INFINITY))?;
        if c.distance > OFF_SURFACE_MM {
            return Err(off(c.distance));
        }
        Ok(EdgePoint {
            at: p,
            uv: (c.u, c.v),
        })
    }
}

/// A boundary point: in space and in the surface's parameters.
#[derive(Debug, Clone, Copy)]
struct EdgePoint {
    at: Vec3,
    uv: (f64, f64),
}

/// True when some loop lies inside another (its first point does).
fn any_nested(loops: &[Vec<(f64, f64)>]) -> bool {
    loops.iter().enumerate().any(|(k, l)| {
        loops.iter().enumerate().any(|(j, other)| {
            j != k && FaceRegion::new(vec![other.clone()]).is_ok_and(|r| r.contains(l[0].0, l[0].1))
        })
    })
}
