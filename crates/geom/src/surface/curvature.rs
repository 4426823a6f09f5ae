//! Differential geometry of a NURBS surface at a point: unit normal, first and second
//! fundamental forms, Gaussian and mean curvature, principal curvatures and directions — what
//! scallop height, cutter selection and local gouge checks read.

use nalgebra::Unit;

use super::{NurbsSurface, SurfaceDerivs};
use crate::curve::Vec3;

/// Relative size of `|S_u × S_v|` against `(|S_u| + |S_v|)²` below which a point counts as
/// degenerate (tangents parallel, or one of them vanished as at the pole of a sphere patch)
/// and has no normal: the sine of the angle between the tangents, roughly.
pub const DEGENERATE_NORMAL: f64 = 1e-12;

/// The first (`E, F, G`) and second (`L, M, N`) fundamental forms at a point, the second
/// taken along the unit normal `n = S_u × S_v / |S_u × S_v|` (do Carmo §3-3): for a tangent
/// step `(du, dv)`, `I = E du² + 2F du dv + G dv²` is the squared length and `II = L du² +
/// 2M du dv + N dv²` twice the rise of the surface toward `n`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FundamentalForms {
    pub e: f64,
    pub f: f64,
    pub g: f64,
    pub l: f64,
    pub m: f64,
    pub n: f64,
}

impl FundamentalForms {
    /// Gaussian curvature `K = (LN − M²) / (EG − F²)`, 1/mm².
    pub fn gaussian_curvature(&self) -> f64 {
        (self.l * self.n - self.m * self.m) / (self.e * self.g - self.f * self.f)
    }

    /// Mean curvature `H = (EN − 2FM + GL) / (2(EG − F²))`, 1/mm; positive where the surface
    /// bends toward its normal.
    pub fn mean_curvature(&self) -> f64 {
        (self.e * self.n - 2.0 * self.f * self.m + self.g * self.l)
            / (2.0 * (self.e * self.g - self.f * self.f))
    }

    /// Principal curvatures `κ₁ ≥ κ₂` (1/mm, positive where the surface bends toward its
    /// normal): the eigenvalues of the second form in the orthonormal tangent frame of
    /// [`FundamentalForms::orthonormal_second_form`], `(a+c)/2 ± √(((a−c)/2)² + b²)`. The root
    /// of a sum of squares stays accurate at an umbilic (a sphere), where `H ± √(H² − K)`
    /// loses half the digits to cancellation.
    pub fn principal_curvatures(&self) -> (f64, f64) {
        let [a, b, c] = self.orthonormal_second_form();
        let (mid, half) = ((a + c) / 2.0, (a - c) / 2.0);
        let root = half.hypot(b);
        (mid + root, mid - root)
    }

    /// The second form `[a, b, c]` (matrix `[[a, b], [b, c]]`) in the orthonormal tangent
    /// frame `e₁ = S_u/√E`, `e₂ = (S_v − (F/E) S_u)/√((EG − F²)/E)` (Gram–Schmidt).
    pub fn orthonormal_second_form(&self) -> [f64; 3] {
        let (e, f, g) = (self.e, self.f, self.g);
        let d = e * g - f * f;
        // e₁ = α₁ S_u; e₂ = α₂ S_u + β₂ S_v.
        let a1 = 1.0 / e.sqrt();
        let b2 = (e / d).sqrt();
        let a2 = -f / e * b2;
        let a = self.l * a1 * a1;
        let b = (self.l * a2 + self.m * b2) * a1;
        let c = self.l * a2 * a2 + 2.0 * self.m * a2 * b2 + self.n * b2 * b2;
        [a, b, c]
    }
}

/// Principal curvatures `κ₁ ≥ κ₂` (1/mm, positive toward the normal) and their unit directions
/// in space (tangent, orthogonal; arbitrary at an umbilic, where every direction is principal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrincipalCurvatures {
    pub k1: f64,
    pub k2: f64,
    pub d1: Unit<Vec3>,
    pub d2: Unit<Vec3>,
}

impl NurbsSurface {
    /// Unit normal `S_u × S_v / |S_u × S_v|`; `None` where the tangents are parallel or one
    /// vanishes (a degenerate point such as a pole of a sphere patch; see
    /// [`DEGENERATE_NORMAL`]).
    pub fn normal(&self, u: f64, v: f64) -> Option<Unit<Vec3>> {
        self.derivs(u, v).normal()
    }

    /// The first and second fundamental forms at `(u, v)`; `None` where the normal is
    /// undefined.
    pub fn fundamental_forms(&self, u: f64, v: f64) -> Option<FundamentalForms> {
        let d = self.derivs(u, v);
        forms_of(&d, &d.normal()?)
    }

    /// Principal curvatures and directions at `(u, v)`: the symmetric 2×2 second form in the
    /// orthonormal frame `e₁, e₂` is diagonalised by the rotation `θ = ½ atan2(2b, a − c)`
    /// (Jacobi), so `d₁ = cos θ e₁ + sin θ e₂`, `d₂ = n × d₁`. `None` where the normal is
    /// undefined.
    pub fn principal_curvatures(&self, u: f64, v: f64) -> Option<PrincipalCurvatures> {
        let d = self.derivs(u, v);
        let n = d.normal()?;
        let ff = forms_of(&d, &n)?;
        let (k1, k2) = ff.principal_curvatures();
        let [a, b, c] = ff.orthonormal_second_form();
        let e1 = d.su / d.su.norm();
        let e2 = n.cross(&e1);
        let theta = 0.5 * (2.0 * b).atan2(a - c);
        let d1 = Unit::new_normalize(e1 * theta.cos() + e2 * theta.sin());
        let d2 = Unit::new_normalize(n.cross(&d1));
        Some(PrincipalCurvatures { k1, k2, d1, d2 })
    }
}

/// `S_u × S_v` normalised; `None` when it is not finite or at most
/// [`DEGENERATE_NORMAL`]`·(|S_u| + |S_v|)²`: at a collapsed edge (a pole) `S_u` is rounding
/// noise, and so would be the direction of the cross product.
impl SurfaceDerivs {
    /// The unit normal `S_u × S_v / |S_u × S_v|` from derivatives already evaluated; `None`
    /// where it is undefined (a pole or a degenerate edge).
    pub fn normal(&self) -> Option<Unit<Vec3>> {
        let c = self.su.cross(&self.sv);
        let len = c.norm();
        let scale = self.su.norm() + self.sv.norm();
        (len.is_finite() && len > DEGENERATE_NORMAL * scale * scale)
            .then(|| Unit::new_unchecked(c / len))
    }
}

/// The fundamental forms from the derivatives and the unit normal (`None` when `EG − F²`
/// underflows to zero though the normal exists).
fn forms_of(d: &SurfaceDerivs, n: &Unit<Vec3>) -> Option<FundamentalForms> {
    let ff = FundamentalForms {
        e: d.su.dot(&d.su),
        f: d.su.dot(&d.sv),
        g: d.sv.dot(&d.sv),
        l: d.suu.dot(n),
        m: d.suv.dot(n),
        n: d.svv.dot(n),
    };
    (ff.e * ff.g - ff.f * ff.f > 0.0).then_some(ff)
}
