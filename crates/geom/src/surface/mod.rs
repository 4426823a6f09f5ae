//! Rational B-spline surfaces (NURBS), the free-form patches that CAM machines: the surface
//! type, its validation, point and partial derivatives to second order (A3.6 on the
//! homogeneous surface, then A4.4 of Piegl & Tiller) and exact iso-parametric curves.
//! `curvature` adds the normal, fundamental forms and principal curvatures; `closest` the
//! point inversion.

// Index loops mirror the book's pseudo-code, so the code can be checked against it line by line.
#![allow(clippy::needless_range_loop)]

mod closest;
mod curvature;

use nalgebra::Vector4;
use thiserror::Error;

use crate::basis::{basis_funs, ders_basis_funs, find_span, MAX_DEGREE, MAX_DER, W};
use crate::curve::{clamp_param, Vec3};
use crate::error::CurveError;
use crate::nurbs::{domain_spans, Nurbs, BIN};

pub use closest::{ClosestPoint, CLOSEST_SEEDS_PER_SPAN};
pub use curvature::{FundamentalForms, PrincipalCurvatures, DEGENERATE_NORMAL};

/// Why a surface could not be built: a fault of one parametric direction's degree or knot
/// vector (the curve rules apply to each), or of the control grid and its weights.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SurfaceError {
    #[error("u direction: {0}")]
    U(CurveError),
    #[error("v direction: {0}")]
    V(CurveError),
    #[error("control grid has {got} points, the knot vectors ask for {rows} × {cols}")]
    GridSize {
        got: usize,
        rows: usize,
        cols: usize,
    },
    #[error("weights ({weights}) and control points ({points}) differ in number")]
    WeightCount { weights: usize, points: usize },
    #[error("control point {index} is not finite")]
    NotFinite { index: usize },
    #[error("weight {index} is {value}; weights must be finite and > 0")]
    Weight { index: usize, value: f64 },
    #[error("tolerance must be finite and > 0, got {0}")]
    Tolerance(f64),
    #[error("the query point is not finite")]
    QueryNotFinite,
}

/// One parametric direction: degree, knot vector and the first/last non-empty span of its
/// domain `[t_p, t_{n+1}]` (as for a curve, the knots need not be clamped).
#[derive(Debug, Clone, PartialEq)]
struct Direction {
    degree: usize,
    knots: Vec<f64>,
    first: usize,
    last: usize,
}

impl Direction {
    /// Validates the degree and the knot vector; `count` is the number of control points
    /// along this direction, `knots.len() - degree - 1`.
    fn new(degree: usize, knots: Vec<f64>) -> Result<Self, CurveError> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(CurveError::Degree {
                degree,
                max: MAX_DEGREE,
            });
        }
        let count = knots.len().saturating_sub(degree + 1);
        if count < degree + 1 {
            return Err(CurveError::TooFewPoints {
                points: count,
                degree,
                need: degree + 1,
            });
        }
        if !knots.iter().all(|k| k.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        let (first, last) = domain_spans(degree, &knots)?;
        Ok(Direction {
            degree,
            knots,
            first,
            last,
        })
    }

    fn count(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.count()])
    }

    /// A2.1 on the clamped parameter: `(span, t)`.
    fn span(&self, t: f64) -> (usize, f64) {
        let (a, b) = self.domain();
        let t = clamp_param(t, a, b);
        (find_span(&self.knots, self.first, self.last, t), t)
    }
}

/// `S` and its partial derivatives to second order at one `(u, v)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceDerivs {
    pub point: Vec3,
    pub su: Vec3,
    pub sv: Vec3,
    pub suu: Vec3,
    pub suv: Vec3,
    pub svv: Vec3,
}

/// `S(u,v) = Σ_i Σ_j N_{i,p}(u) N_{j,q}(v) w_ij P_ij / Σ_i Σ_j N_{i,p}(u) N_{j,q}(v) w_ij`.
///
/// The control grid is row-major: row `i` runs along `v` at u-index `i`, so `P_ij` is
/// `points[i·cols + j]`. Points are stored homogeneous (`w·x, w·y, w·z, w`), as A3.6 and A4.4
/// work on them. Parameters outside the domain are clamped into it; NaN maps to its start.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    u: Direction,
    v: Direction,
    /// `rows × cols` homogeneous control points, row-major.
    cw: Vec<Vector4<f64>>,
}

impl NurbsSurface {
    /// A NURBS surface of degrees `degree_u`, `degree_v`. The grid size comes from the knot
    /// vectors (`rows = knots_u.len() − degree_u − 1`, likewise `cols`). Validates each
    /// direction by the curve rules of [`Nurbs::new`] (degree 1..=15, at least `degree + 1`
    /// control points, finite non-decreasing knots, a non-empty domain, no interior knot
    /// repeated more than the degree), then the grid size, finite points, one weight per point
    /// and weights finite and > 0.
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        points: &[Vec3],
        weights: &[f64],
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
    ) -> Result<Self, SurfaceError> {
        let u = Direction::new(degree_u, knots_u).map_err(SurfaceError::U)?;
        let v = Direction::new(degree_v, knots_v).map_err(SurfaceError::V)?;
        let (rows, cols) = (u.count(), v.count());
        if points.len() != rows * cols {
            return Err(SurfaceError::GridSize {
                got: points.len(),
                rows,
                cols,
            });
        }
        if weights.len() != points.len() {
            return Err(SurfaceError::WeightCount {
                weights: weights.len(),
                points: points.len(),
            });
        }
        if let Some(index) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(SurfaceError::NotFinite { index });
        }
        for (index, &value) in weights.iter().enumerate() {
            if !(value.is_finite() && value > 0.0) {
                return Err(SurfaceError::Weight { index, value });
            }
        }
        let cw = points
            .iter()
            .zip(weights)
            .map(|(p, &w)| Vector4::new(p.x * w, p.y * w, p.z * w, w))
            .collect();
        Ok(NurbsSurface { u, v, cw })
    }

    /// A non-rational B-spline surface (all weights 1).
    pub fn bspline(
        degree_u: usize,
        degree_v: usize,
        points: &[Vec3],
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
    ) -> Result<Self, SurfaceError> {
        let w = vec![1.0; points.len()];
        NurbsSurface::new(degree_u, degree_v, points, &w, knots_u, knots_v)
    }

    pub fn degrees(&self) -> (usize, usize) {
        (self.u.degree, self.v.degree)
    }
    pub fn knots_u(&self) -> &[f64] {
        &self.u.knots
    }
    pub fn knots_v(&self) -> &[f64] {
        &self.v.knots
    }
    /// `(rows, cols)`: control points along u and along v.
    pub fn grid_size(&self) -> (usize, usize) {
        (self.u.count(), self.v.count())
    }
    /// `(u_start, u_end)`.
    pub fn domain_u(&self) -> (f64, f64) {
        self.u.domain()
    }
    /// `(v_start, v_end)`.
    pub fn domain_v(&self) -> (f64, f64) {
        self.v.domain()
    }

    fn cw(&self, i: usize, j: usize) -> Vector4<f64> {
        self.cw[i * self.v.count() + j]
    }

    /// `S(u, v)`: A4.3 (A3.5 on the homogeneous grid, then the projection).
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        let (su, u) = self.u.span(u);
        let (sv, v) = self.v.span(v);
        self.point_at(su, sv, u, v)
    }

    /// `S(u, v)` on the polynomial piece of knot spans `(su, sv)`, `u, v` in their closure.
    fn point_at(&self, su: usize, sv: usize, u: f64, v: f64) -> Vec3 {
        let (p, q) = (self.u.degree, self.v.degree);
        let (mut nu, mut nv) = ([0.0; W], [0.0; W]);
        basis_funs(&self.u.knots, su, u, p, &mut nu);
        basis_funs(&self.v.knots, sv, v, q, &mut nv);
        let mut h = Vector4::zeros();
        for k in 0..=p {
            let mut row = Vector4::zeros();
            for l in 0..=q {
                row += self.cw(su - p + k, sv - q + l) * nv[l];
            }
            h += row * nu[k];
        }
        Vec3::new(h.x, h.y, h.z) / h.w
    }

    /// `S` and its partial derivatives to second order at `(u, v)`.
    pub fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        let (su, u) = self.u.span(u);
        let (sv, v) = self.v.span(v);
        self.derivs_at(su, sv, u, v)
    }

    /// The partials on the piece of knot spans `(su, sv)`: one-sided at a knot line, which is
    /// what a search confined to one piece needs where the surface has a crease.
    fn derivs_at(&self, su: usize, sv: usize, u: f64, v: f64) -> SurfaceDerivs {
        let (p, q) = (self.u.degree, self.v.degree);
        let mut nu = [[0.0; W]; MAX_DER + 1];
        let mut nv = [[0.0; W]; MAX_DER + 1];
        ders_basis_funs(&self.u.knots, su, u, p, 2, &mut nu);
        ders_basis_funs(&self.v.knots, sv, v, q, 2, &mut nv);
        // A3.6 SurfaceDerivsAlg1 on the 4-D points: aw[k][l] = ∂^{k+l} S^w / ∂u^k ∂v^l for
        // k + l ≤ 2 (derivatives above a degree are zero rows of ders_basis_funs).
        let mut aw = [[Vector4::zeros(); 3]; 3];
        for k in 0..=2 {
            let mut temp = [Vector4::zeros(); W];
            for s in 0..=q {
                for r in 0..=p {
                    temp[s] += self.cw(su - p + r, sv - q + s) * nu[k][r];
                }
            }
            for l in 0..=2 - k {
                for s in 0..=q {
                    aw[k][l] += temp[s] * nv[l][s];
                }
            }
        }
        // A4.4 RatSurfaceDerivs: S_kl = (A_kl − Σ_{j≥1} C(l,j) w_0j S_{k,l−j}
        //   − Σ_{i≥1} C(k,i) (w_i0 S_{k−i,l} + Σ_{j≥1} C(l,j) w_ij S_{k−i,l−j})) / w_00.
        let mut s = [[Vec3::zeros(); 3]; 3];
        let w00 = aw[0][0].w;
        for k in 0..=2 {
            for l in 0..=2 - k {
                let a = aw[k][l];
                let mut val = Vec3::new(a.x, a.y, a.z);
                for j in 1..=l {
                    val -= s[k][l - j] * (BIN[l][j] * aw[0][j].w);
                }
                for i in 1..=k {
                    val -= s[k - i][l] * (BIN[k][i] * aw[i][0].w);
                    let mut v2 = Vec3::zeros();
                    for j in 1..=l {
                        v2 += s[k - i][l - j] * (BIN[l][j] * aw[i][j].w);
                    }
                    val -= v2 * BIN[k][i];
                }
                s[k][l] = val / w00;
            }
        }
        SurfaceDerivs {
            point: s[0][0],
            su: s[1][0],
            sv: s[0][1],
            suu: s[2][0],
            suv: s[1][1],
            svv: s[0][2],
        }
    }

    /// The u-iso-parametric curve `u ↦ S(u, v)` at fixed `v`, exactly, as a [`Nurbs`] of
    /// degree `p` on the u knots: its homogeneous control points are `Q_i^w = Σ_j N_{j,q}(v)
    /// P_ij^w` (P&T §4.4: a tensor-product surface restricted to an iso line).
    pub fn u_iso(&self, v: f64) -> Nurbs {
        let q = self.v.degree;
        let (sv, v) = self.v.span(v);
        let mut nv = [0.0; W];
        basis_funs(&self.v.knots, sv, v, q, &mut nv);
        let qw = (0..self.u.count())
            .map(|i| (0..=q).map(|l| self.cw(i, sv - q + l) * nv[l]).sum())
            .collect();
        let u = &self.u;
        Nurbs::from_valid_homogeneous(u.degree, qw, u.knots.clone(), (u.first, u.last))
    }

    /// The v-iso-parametric curve `v ↦ S(u, v)` at fixed `u`, exactly: `Q_j^w = Σ_i N_{i,p}(u)
    /// P_ij^w` on the v knots.
    pub fn v_iso(&self, u: f64) -> Nurbs {
        let p = self.u.degree;
        let (su, u) = self.u.span(u);
        let mut nu = [0.0; W];
        basis_funs(&self.u.knots, su, u, p, &mut nu);
        let qw = (0..self.v.count())
            .map(|j| (0..=p).map(|k| self.cw(su - p + k, j) * nu[k]).sum())
            .collect();
        let v = &self.v;
        Nurbs::from_valid_homogeneous(v.degree, qw, v.knots.clone(), (v.first, v.last))
    }
}
