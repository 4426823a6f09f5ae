//! A side step checked against the true surface between two passes. The scallop models
//! (`scallop`, `silhouette::cusp`) take the surface across the feed as its osculating circle at
//! the contact; where the curvature changes over the step (a large ball on a gently concave,
//! varying region) the real ridge stands higher. Here, as in Lin & Koren's iso-scallop check
//! (1996) and Feng & Li's cusp computation (2002): in the cross-feed section of the first
//! contact, both cutters stand at their own contacts with their own axes, the cusp is where
//! their swept sections (`silhouette::envelope`) meet, and its height is its distance to the
//! actual surface (local point inversion, Piegl & Tiller §6.1). The strategies shrink a step
//! until that height fits the target (`Context::fit_true_surface`).

use tezgah_geom::Vec3;

use super::{Context, Local};
use crate::silhouette::envelope;

/// Bisections locating the cusp between the two contacts (bracket shrinks by 2⁻⁶⁰).
const CUSP_BISECTIONS: usize = 60;
/// Samples of the parameter segment between the contacts seeding the point inversion.
const SEED_SAMPLES: usize = 16;
/// Newton steps sliding the second contact abreast of the first.
const ABREAST_STEPS: usize = 6;
/// The most the second contact may stay ahead or behind the first's section (relative to the
/// step) for the check to count: more only at the domain's feed ends, where the pass ends.
const ABREAST_LAG: f64 = 0.02;
/// Gauss–Newton steps of the local point inversion (it converges quadratically near a foot).
const INVERSION_STEPS: usize = 8;
/// Bisections of a side step against the true cusp (the bracket shrinks by 2⁻¹⁴ of the step).
pub(super) const STEP_BISECTIONS: usize = 14;
/// A cusp this far (relative) above the target still passes: the models and this check agree
/// to rounding where the model is exact (a cylinder, a sphere), and the steps stay as they were.
const CUSP_SLACK: f64 = 1e-6;

/// One pass's cutter at a contact: tip and unit axis at the nominal orientation.
pub(super) struct Standing {
    pub(super) tip: Vec3,
    axis: Vec3,
}

impl Context<'_> {
    pub(super) fn standing(&self, local: &Local) -> Option<Standing> {
        let angles = self.nominal_angles(local)?;
        let axis = self.axis_for(&local.frame, angles);
        Some(Standing {
            tip: self
                .shape()
                .tip_for_contact(&local.d.point, &local.frame, &axis),
            axis: axis.into_inner(),
        })
    }

    /// The height (mm, signed: negative where the two cutters overlap below the surface) of
    /// the cusp between a pass through the contact `from` and one through `to` (both `(u, v)`,
    /// the passes running along `tangent_uv`), measured to the true surface. `None` where
    /// either contact has no frame or orientation, or the cutters do not meet between them.
    pub(super) fn true_cusp(
        &self,
        from: (f64, f64),
        to: (f64, f64),
        tangent_uv: (f64, f64),
    ) -> Option<f64> {
        let first = self.local(from.0, from.1, tangent_uv)?;
        let to = self.abreast(&first, to, tangent_uv)?;
        let second = self.local(to.0, to.1, tangent_uv)?;
        let (c1, c2) = (self.standing(&first)?, self.standing(&second)?);
        let p = first.d.point;
        let n = first.frame.normal.into_inner();
        let mut t = first.frame.cross.into_inner();
        let mut yq = (second.d.point - p).dot(&t);
        if yq < 0.0 {
            t = -t;
            yq = -yq;
        }
        if yq.is_nan() || yq <= 0.0 {
            return None;
        }
        let (shape, len) = (self.shape(), self.cutter.flute_length);
        let (tip1, tip2) = (c1.tip - p, c2.tip - p);
        let env1 = |y: f64| envelope(shape, len, &tip1, &c1.axis, &n, &t, y);
        let env2 = |y: f64| envelope(shape, len, &tip2, &c2.axis, &n, &t, y);
        // env1 − env2 rises from ≤ 0 at the first contact to ≥ 0 at the second.
        let (mut lo, mut hi) = (0.0, yq);
        if !(env1(lo) <= env2(lo) && env1(hi) >= env2(hi)) {
            return None;
        }
        for _ in 0..CUSP_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if env1(mid) <= env2(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let y = 0.5 * (lo + hi);
        let z = env1(y).max(env2(y));
        if !z.is_finite() {
            return None;
        }
        let cusp = p + t * y + n * z;
        let foot = self.foot(&cusp, from, to)?;
        Some((cusp - foot).norm() * (cusp - foot).dot(&n).signum())
    }

    /// `to` slid along its pass (`tangent_uv`) into the cross-feed plane of the first contact:
    /// the section sees the second pass where it runs abreast of the first contact, not the
    /// cutter a little ahead or behind (on a surface curved along the feed that one stands
    /// lower or higher by the curvature times the square of the lag). Newton on
    /// `(S(to + λ·tangent) − p)·f = 0`; `None` where the domain's edge stops it short.
    fn abreast(&self, first: &Local, to: (f64, f64), tangent_uv: (f64, f64)) -> Option<(f64, f64)> {
        let (p, f) = (first.d.point, first.frame.feed.into_inner());
        let (du, dv) = (self.surface.domain_u(), self.surface.domain_v());
        let (mut u, mut v) = to;
        let mut across = 0.0;
        for _ in 0..ABREAST_STEPS {
            let d = self.surface.derivs(u, v);
            let lag = (d.point - p).dot(&f);
            across = (d.point - p - f * lag).norm();
            let slope = (d.su * tangent_uv.0 + d.sv * tangent_uv.1).dot(&f);
            if slope.is_nan() || slope == 0.0 {
                break;
            }
            let lam = -lag / slope;
            u = (u + lam * tangent_uv.0).clamp(du.0, du.1);
            v = (v + lam * tangent_uv.1).clamp(dv.0, dv.1);
        }
        let lag = (self.surface.point(u, v) - p).dot(&f);
        (lag.abs() <= ABREAST_LAG * across.max(f64::MIN_POSITIVE) && u.is_finite() && v.is_finite())
            .then_some((u, v))
    }

    /// The surface point nearest `q` near the parameter segment `from`–`to`: the nearest of
    /// its samples, refined by Gauss–Newton on the tangent plane (P&T eq. 6.6), clamped to
    /// the domain.
    fn foot(&self, q: &Vec3, from: (f64, f64), to: (f64, f64)) -> Option<Vec3> {
        let lerp = |x: f64| (from.0 + (to.0 - from.0) * x, from.1 + (to.1 - from.1) * x);
        let (mut u, mut v) = (0..=SEED_SAMPLES)
            .map(|k| lerp(k as f64 / SEED_SAMPLES as f64))
            .min_by(|a, b| {
                let da = (self.surface.point(a.0, a.1) - q).norm_squared();
                let db = (self.surface.point(b.0, b.1) - q).norm_squared();
                da.total_cmp(&db)
            })?;
        let (du, dv) = (self.surface.domain_u(), self.surface.domain_v());
        for _ in 0..INVERSION_STEPS {
            let d = self.surface.derivs(u, v);
            let r = q - d.point;
            let (e, f, g) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
            let det = e * g - f * f;
            if det.is_nan() || det <= 0.0 {
                break;
            }
            let (a, b) = (d.su.dot(&r), d.sv.dot(&r));
            u = (u + (g * a - f * b) / det).clamp(du.0, du.1);
            v = (v + (e * b - f * a) / det).clamp(dv.0, dv.1);
        }
        let point = self.surface.point(u, v);
        point.iter().all(|c| c.is_finite()).then_some(point)
    }

    /// Whether the cusp between the two contacts is within the target scallop (a pair the
    /// check cannot measure passes: the model's step stands there).
    pub(super) fn cusp_fits(
        &self,
        from: (f64, f64),
        to: (f64, f64),
        tangent_uv: (f64, f64),
    ) -> bool {
        self.true_cusp(from, to, tangent_uv)
            .is_none_or(|c| c <= self.settings.scallop * (1.0 + CUSP_SLACK))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::{Cutter, CutterShape};
    use crate::scallop::stepover_exact;
    use crate::strategy::{Settings, StrategyKind};

    #[test]
    fn cusp_on_a_sphere_and_a_trough_is_the_closed_form() {
        // Where the cross-section is a circle everywhere the true cusp of passes the exact
        // model's chord apart is h: convex sphere R 30 (chord along u, the neighbour slid
        // abreast) and concave trough R 40 (across its arc), ball D6, h 0.02.
        let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
        let h = 0.02;
        let settings = Settings::new(StrategyKind::IsoScallop, h, 0.005);
        for (name, s, kappa) in [
            ("sphere", crate::testing::sphere(30.0), -1.0 / 30.0),
            ("trough", crate::testing::trough(40.0, 50.0), 1.0 / 40.0),
        ] {
            let ctx = Context::new(&s, &cutter, &settings).unwrap();
            let w = stepover_exact(3.0, kappa, h).unwrap();
            let (du, dv) = (s.domain_u(), s.domain_v());
            for (x, y) in [(0.3, 0.5), (0.1, 0.1), (0.7, 0.9), (0.5, 0.2)] {
                let (u, v) = (du.0 + (du.1 - du.0) * x, dv.0 + (dv.1 - dv.0) * y);
                let p = s.point(u, v);
                // The point along u at chord w (bisection on the parameter).
                let (mut lo, mut hi) = (u, du.1);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if (s.point(mid, v) - p).norm() < w {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let c = ctx.true_cusp((u, v), (lo, v), (0.0, 1.0)).unwrap();
                assert!((c - h).abs() < 2e-3 * h, "{name} {x} {y}: {c}");
                // A wider step leaves more, a narrower less.
                let wide = ctx.true_cusp((u, v), (u + 1.2 * (lo - u), v), (0.0, 1.0));
                assert!(wide.unwrap() > 1.3 * h, "{name}: {wide:?}");
            }
        }
    }
}
