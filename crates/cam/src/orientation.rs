//! The tool's stance at a cutter-contact point: the local frame (feed `f`, cross-feed
//! `t = n × f`, normal `n`), the tool axis from lead and tilt angles, curvature matching for
//! flat and bull-nose cutters, and CC → CL (the tool tip for a contact). Strategies call this
//! for every contact point; the gouge checks then test the placed cutter.

use nalgebra::Unit;
use tezgah_geom::Vec3;

use crate::cutter::CutterShape;
use crate::effective_radius::LeadTilt;

/// Orthonormal frame at a contact point: `feed` along the path, `normal` out of the material
/// (toward the tool), `cross = normal × feed`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    pub feed: Unit<Vec3>,
    pub cross: Unit<Vec3>,
    pub normal: Unit<Vec3>,
}

impl ContactFrame {
    /// The frame from the surface normal and the path tangent (projected into the tangent
    /// plane); `None` when the tangent is (nearly) along the normal or not finite.
    pub fn new(normal: Unit<Vec3>, tangent: Vec3) -> Option<ContactFrame> {
        let along = tangent - normal.into_inner() * tangent.dot(&normal);
        let len = along.norm();
        if !(len.is_finite() && len > 1e-12 * tangent.norm()) {
            return None;
        }
        let feed = Unit::new_unchecked(along / len);
        let cross = Unit::new_normalize(normal.cross(&feed));
        Some(ContactFrame {
            feed,
            cross,
            normal,
        })
    }

    /// The tool axis `a ∝ n + tan(lead)·f + tan(tilt)·t` (Can, 2010, Eq. 3.36, with `β` the yaw
    /// toward the cross-feed side; lead tilts the tool's top toward the feed, so the tool
    /// centre trails the contact and the heel clears the cut surface).
    pub fn axis(&self, angles: LeadTilt) -> Unit<Vec3> {
        Unit::new_normalize(
            self.normal.into_inner()
                + self.feed.into_inner() * angles.lead.tan()
                + self.cross.into_inner() * angles.tilt.tan(),
        )
    }

    /// Lead and tilt of a given axis in this frame; `None` when the axis does not point to the
    /// normal's side (`a·n ≤ 0`: the cutter cannot touch here from above).
    pub fn lead_tilt(&self, axis: &Unit<Vec3>) -> Option<LeadTilt> {
        let an = axis.dot(&self.normal);
        (an > 1e-9).then(|| LeadTilt {
            lead: (axis.dot(&self.feed) / an).atan(),
            tilt: (axis.dot(&self.cross) / an).atan(),
        })
    }
}

impl CutterShape {
    /// CC → CL: the tool tip for a contact at `contact` with surface normal `n` and tool axis
    /// `a`. The corner-circle centre is `c = CC + r·n + (R − r)·m` with `m` the unit of
    /// `n − (a·n)a` (Choi 1998; Can, 2010, Eq. 3.11, sign fixed so the corner touches at CC: the
    /// cutter's outward normal there is `−n`); the tip is `c − r·a`. When `a ∥ n` the flat part
    /// lies on the tangent plane and the contact is taken on the front of the rim: `m = −f`
    /// (Can, 2010, §3.4.5, "TK = TT − r·f"). Ball: `tip = CC + R n − R a`.
    pub fn tip_for_contact(&self, contact: &Vec3, frame: &ContactFrame, axis: &Unit<Vec3>) -> Vec3 {
        let (big_r, r) = (self.radius(), self.corner_radius());
        let n = frame.normal.into_inner();
        let a = axis.into_inner();
        let horizontal = n - a * a.dot(&n);
        let len = horizontal.norm();
        let m = if len > 1e-12 {
            horizontal / len
        } else {
            -frame.feed.into_inner()
        };
        contact + n * r + m * (big_r - r) - a * r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame_z() -> ContactFrame {
        ContactFrame::new(Vec3::z_axis(), Vec3::x()).unwrap()
    }

    #[test]
    fn frame_and_angles_round_trip() {
        let f = frame_z();
        assert!((f.cross.into_inner() - Vec3::y()).norm() < 1e-15);
        let lt = LeadTilt::new(0.3, -0.2);
        let a = f.axis(lt);
        let back = f.lead_tilt(&a).unwrap();
        assert!((back.lead - 0.3).abs() < 1e-12 && (back.tilt + 0.2).abs() < 1e-12);
        assert!(f.lead_tilt(&-a).is_none());
    }

    #[test]
    fn tips_on_a_plane() {
        let f = frame_z();
        let cc = Vec3::new(1.0, 2.0, 3.0);
        // Axis along the normal: ball tip at the contact, flat tip trails by R along −feed.
        let a = f.axis(LeadTilt::default());
        let ball = CutterShape::Ball { radius: 3.0 };
        assert!((ball.tip_for_contact(&cc, &f, &a) - cc).norm() < 1e-12);
        let flat = CutterShape::Flat { radius: 5.0 };
        let tip = flat.tip_for_contact(&cc, &f, &a);
        assert!((tip - (cc - Vec3::x() * 5.0)).norm() < 1e-12);
        // Flat with lead λ (from Can, 2010, §3.4.5: p_CL = CC + R(sin λ n − cos λ f)): the tip is
        // the bottom centre, and the contact lies on the rim, R from the tip in the bottom plane.
        let lead = 0.25f64;
        let a = f.axis(LeadTilt::new(lead, 0.0));
        let tip = flat.tip_for_contact(&cc, &f, &a);
        let want = cc + (Vec3::z() * lead.sin() - Vec3::x() * lead.cos()) * 5.0;
        assert!((tip - want).norm() < 1e-12);
        assert!((cc - tip).dot(&a).abs() < 1e-12);
        // Bull-nose on a plane, untilted: tip = CC − (R − r)·f.
        let bull = CutterShape::BullNose {
            radius: 6.0,
            corner_radius: 2.0,
        };
        let a = f.axis(LeadTilt::default());
        assert!((bull.tip_for_contact(&cc, &f, &a) - (cc - Vec3::x() * 4.0)).norm() < 1e-12);
    }
}
