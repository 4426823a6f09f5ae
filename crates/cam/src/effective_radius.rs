//! The cutter's curvature at the contact point and its effective cutting radius under lead and
//! tilt: what scallop height (side step), curvature matching and the local gouge check read.
//! Angles in radians, lengths in mm.
//!
//! At a contact whose surface normal makes the angle `α` with the tool axis, the cutter surface
//! has two principal curvatures (Rao, Ismail & Bedi 1997; Can, 2010, §3.3.7): along the
//! meridian (the plane of axis and normal) `κ_m = 1/r` (corner radius `r`; infinite for a flat
//! end, whose rim is a sharp edge), and along the parallel circle, by Meusnier,
//! `κ_p = sin α / (R₀ + r sin α)` with `R₀ = R − r`. The scallop left across the feed is the
//! cutter's silhouette seen along the feed; for the local quadric with curvature matrix `K` in
//! the (feed, cross-feed) frame that silhouette has curvature `det K / K_ff`. With `β` the angle
//! between the feed and the meridian direction, `K_ff = κ_m cos²β + κ_p sin²β`, so the effective
//! radius is `r_e = (κ_m cos²β + κ_p sin²β) / (κ_m κ_p)`. For a pure lead (`β = 0`) this is
//! `1/κ_p = R₀/sin α + r` (Can, 2010, §3.3.7: ball `R`, flat `R/sin S`, torus `R₀/sin α + r`).

use crate::cutter::CutterShape;

/// The cutter's principal curvatures at a contact point (1/mm, ≥ 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactCurvatures {
    /// Along the meridian (in the plane of the tool axis and the surface normal);
    /// `f64::INFINITY` on the sharp rim of a flat end mill.
    pub meridian: f64,
    /// Along the parallel circle through the contact point (perpendicular to the meridian).
    pub parallel: f64,
}

/// The tool axis relative to the surface at the contact: lead (rotation toward the feed) and
/// tilt (rotation toward the cross-feed side), radians. The axis is
/// `a ∝ n + tan(lead)·f + tan(tilt)·t` in the contact frame (feed `f`, cross-feed `t = n × f`,
/// normal `n`), i.e. Can's (2010) Eq. 3.36 with inclination `α = atan √(tan² lead + tan² tilt)` and
/// yaw `β = atan2(tan tilt, tan lead)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LeadTilt {
    pub lead: f64,
    pub tilt: f64,
}

impl LeadTilt {
    pub fn new(lead: f64, tilt: f64) -> LeadTilt {
        LeadTilt { lead, tilt }
    }

    /// Inclination `α` between the axis and the normal, radians.
    pub fn inclination(&self) -> f64 {
        self.lead.tan().hypot(self.tilt.tan()).atan()
    }

    /// `cos² β`, the squared cosine of the angle between the feed and the meridian direction
    /// (1 for a pure lead, and by convention when the axis is along the normal).
    pub fn cos2_yaw(&self) -> f64 {
        let (a, b) = (self.lead.tan(), self.tilt.tan());
        let s = a * a + b * b;
        if s == 0.0 {
            1.0
        } else {
            a * a / s
        }
    }
}

impl CutterShape {
    /// Principal curvatures of the cutter at a contact whose normal is inclined by
    /// `inclination` (radians) to the tool axis.
    pub fn contact_curvatures(&self, inclination: f64) -> ContactCurvatures {
        let (big_r, r) = (self.radius(), self.corner_radius());
        let s = inclination.sin().abs();
        let r0 = big_r - r;
        let meridian = if r > 0.0 { 1.0 / r } else { f64::INFINITY };
        let parallel = if r0 <= 0.0 {
            1.0 / big_r
        } else {
            s / (r0 + r * s)
        };
        ContactCurvatures { meridian, parallel }
    }

    /// Curvature of the cutter's silhouette seen along the feed (1/mm): `det K / K_ff` of the
    /// module comment, with `cos²β` the yaw of [`LeadTilt::cos2_yaw`].
    pub fn silhouette_curvature(&self, inclination: f64, cos2_yaw: f64) -> f64 {
        let k = self.contact_curvatures(inclination);
        let sin2 = 1.0 - cos2_yaw;
        if k.meridian.is_infinite() {
            // Flat end: K_ff → ∞·cos²β; the limit of κ_m κ_p / K_ff is κ_p / cos²β.
            return if cos2_yaw > 0.0 {
                k.parallel / cos2_yaw
            } else {
                f64::INFINITY
            };
        }
        let kff = k.meridian * cos2_yaw + k.parallel * sin2;
        if kff == 0.0 {
            0.0
        } else {
            k.meridian * k.parallel / kff
        }
    }

    /// The effective cutting radius across the feed under `lead` and `tilt` (mm): the radius of
    /// the circle that the cutter's cross-feed profile osculates at the contact. Ball: `R`;
    /// flat with lead `λ`: `R / sin λ` (infinite at `λ = 0`, a flat bottom); bull-nose:
    /// `(R − r)/sin λ + r`. A side tilt bends the meridian's tighter curvature into the
    /// cross-feed profile (a flat end tilted sideways cuts with its sharp rim: `r_e → 0`).
    pub fn effective_radius(&self, angles: LeadTilt) -> f64 {
        let k = self.silhouette_curvature(angles.inclination(), angles.cos2_yaw());
        if k == 0.0 {
            f64::INFINITY
        } else {
            1.0 / k
        }
    }

    /// The smallest inclination (pure lead, radians) at which the effective radius is at most
    /// `radius` — curvature matching for flat and bull-nose cutters (Can, 2010, §3.4.7.2.2, `S =
    /// asin(r/ρ)` for a flat end; `sin α = R₀/(ρ − r)` for a torus). `Some(0)` when even the
    /// untilted cutter fits; `None` when no inclination below 90° does (a ball or a torus corner
    /// wider than `radius`).
    pub fn matching_lead(&self, radius: f64) -> Option<f64> {
        let (big_r, r) = (self.radius(), self.corner_radius());
        let r0 = big_r - r;
        if radius.is_nan() || radius <= r {
            return None;
        }
        if r0 <= 0.0 {
            // A ball: r_e = R at every lead, and R < radius here.
            return Some(0.0);
        }
        let s = r0 / (radius - r);
        (s <= 1.0).then(|| s.asin())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn deg(x: f64) -> f64 {
        x * PI / 180.0
    }

    #[test]
    fn closed_forms_under_lead() {
        let ball = CutterShape::Ball { radius: 3.0 };
        let flat = CutterShape::Flat { radius: 5.0 };
        let bull = CutterShape::BullNose {
            radius: 6.0,
            corner_radius: 2.0,
        };
        for lead_deg in [1.0, 5.0, 14.4775, 20.0, 45.0, 80.0] {
            let lt = LeadTilt::new(deg(lead_deg), 0.0);
            let s = deg(lead_deg).sin();
            assert!((ball.effective_radius(lt) - 3.0).abs() < 1e-12);
            assert!((flat.effective_radius(lt) - 5.0 / s).abs() < 1e-9 * (5.0 / s));
            assert!((bull.effective_radius(lt) - (4.0 / s + 2.0)).abs() < 1e-9 * (4.0 / s));
        }
        // Can (2010, §3.3): flat D = 40 at S = 25° → r_e = 47.32 mm.
        let flat40 = CutterShape::Flat { radius: 20.0 };
        let re = flat40.effective_radius(LeadTilt::new(deg(25.0), 0.0));
        assert!((re - 47.324).abs() < 1e-3, "{re}");
        assert!(flat.effective_radius(LeadTilt::default()).is_infinite());
    }

    #[test]
    fn ball_is_isotropic_and_side_tilt_sharpens_a_flat_end() {
        let ball = CutterShape::Ball { radius: 4.0 };
        let flat = CutterShape::Flat { radius: 5.0 };
        for (l, t) in [(10.0, 10.0), (0.0, 30.0), (40.0, -20.0)] {
            let lt = LeadTilt::new(deg(l), deg(t));
            assert!((ball.effective_radius(lt) - 4.0).abs() < 1e-12);
        }
        // Pure side tilt: the rim's sharp edge is the cross-feed profile.
        let side = flat.effective_radius(LeadTilt::new(0.0, deg(10.0)));
        assert!(side < 1e-9, "{side}");
        // Lead and tilt: R cos²β / sin α.
        let lt = LeadTilt::new(deg(20.0), deg(10.0));
        let (a, b) = (deg(20.0).tan(), deg(10.0).tan());
        let alpha = a.hypot(b).atan();
        let cos2b = a * a / (a * a + b * b);
        let want = 5.0 * cos2b / alpha.sin();
        assert!((flat.effective_radius(lt) - want).abs() < 1e-9);
    }

    #[test]
    fn matching_lead_reproduces_the_thesis_sturz_angles() {
        // Can (2010, §3.4.7.2): D = 10 on ρ = 20 → S = asin(5/20) = 14.4775°.
        let flat = CutterShape::Flat { radius: 5.0 };
        let s = flat.matching_lead(20.0).unwrap();
        assert!((s.to_degrees() - 14.477_512_185_929_92).abs() < 1e-9);
        // T3: D = 16 on ρ = 26.0544985816258 → 17.8814613349°.
        let flat16 = CutterShape::Flat { radius: 8.0 };
        let s = flat16.matching_lead(26.054_498_581_625_8).unwrap();
        assert!((s.to_degrees() - 17.881_461_334_9).abs() < 1e-8);
        // At the matched lead the effective radius equals the surface radius.
        let re = flat16.effective_radius(LeadTilt::new(s, 0.0));
        assert!((re - 26.054_498_581_625_8).abs() < 1e-9);
        let bull = CutterShape::BullNose {
            radius: 6.0,
            corner_radius: 2.0,
        };
        let s = bull.matching_lead(30.0).unwrap();
        assert!((bull.effective_radius(LeadTilt::new(s, 0.0)) - 30.0).abs() < 1e-9);
        assert_eq!(bull.matching_lead(1.5), None);
        assert_eq!(CutterShape::Ball { radius: 3.0 }.matching_lead(2.0), None);
    }
}
