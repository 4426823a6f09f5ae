//! Local gouge: curvature interference at the contact point. To second order the cutter
//! clears the surface around the contact iff it is at least as curved in every tangent
//! direction, i.e. `K_cutter − K_surface` is positive semi-definite (both in the tangent plane,
//! curvature positive toward the tool; Can, 2010, §3.4.7.2.2; Lo 1999; and its generalisation
//! to all directions). A flat end's rim is infinitely curved along the meridian, leaving the single
//! condition along the parallel.

use nalgebra::Unit;
use tezgah_geom::{SurfaceDerivs, Vec3};

use crate::cutter::CutterShape;
use crate::orientation::ContactFrame;

/// A symmetric 2×2 curvature matrix in the (feed, cross-feed) frame, 1/mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curvature2 {
    pub ff: f64,
    pub ft: f64,
    pub tt: f64,
}

/// The surface's second fundamental form in the contact frame, along the frame's normal
/// (positive where the surface bends toward it, i.e. concave seen from the tool): `II(x, y)`
/// with the tangent vectors expressed in `(du, dv)` by solving `[S_u S_v] x = f` (normal
/// equations of the 3×2 system; exact for tangent vectors).
pub fn surface_curvature(d: &SurfaceDerivs, frame: &ContactFrame) -> Option<Curvature2> {
    let n = frame.normal.into_inner();
    let (e, f, g) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
    let det = e * g - f * f;
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    let to_uv = |w: &Vec3| {
        let (a, b) = (d.su.dot(w), d.sv.dot(w));
        ((g * a - f * b) / det, (e * b - f * a) / det)
    };
    let (l, m, nn) = (d.suu.dot(&n), d.suv.dot(&n), d.svv.dot(&n));
    let ii =
        |x: (f64, f64), y: (f64, f64)| l * x.0 * y.0 + m * (x.0 * y.1 + x.1 * y.0) + nn * x.1 * y.1;
    let (xf, xt) = (to_uv(&frame.feed), to_uv(&frame.cross));
    Some(Curvature2 {
        ff: ii(xf, xf),
        ft: ii(xf, xt),
        tt: ii(xt, xt),
    })
}

/// The cutter's curvature matrix at the contact in the same frame: `κ_m d dᵀ + κ_p p pᵀ` with
/// `d` the meridian direction (the axis projected into the tangent plane) and `p` across it.
/// `ff`/`ft`/`tt` are infinite for a flat end (use [`local_margin`]).
fn cutter_frame(
    shape: &CutterShape,
    frame: &ContactFrame,
    axis: &Unit<Vec3>,
) -> (f64, f64, (f64, f64)) {
    let n = frame.normal.into_inner();
    let an = axis.dot(&n).clamp(-1.0, 1.0);
    let inclination = an.acos();
    let k = shape.contact_curvatures(inclination);
    let proj = axis.into_inner() - n * an;
    let (c, s) = if proj.norm() > 1e-12 {
        let d = proj.normalize();
        (d.dot(&frame.feed), d.dot(&frame.cross))
    } else {
        (1.0, 0.0)
    };
    (k.meridian, k.parallel, (c, s))
}

/// The smallest eigenvalue of `K_cutter − K_surface` (1/mm): negative means local gouge.
pub fn local_margin(
    shape: &CutterShape,
    frame: &ContactFrame,
    axis: &Unit<Vec3>,
    surface: &Curvature2,
) -> f64 {
    let (km, kp, (c, s)) = cutter_frame(shape, frame, axis);
    // Surface curvature along the parallel direction p = (−s, c).
    let s_pp = surface.ff * s * s - 2.0 * surface.ft * s * c + surface.tt * c * c;
    if km.is_infinite() {
        return kp - s_pp;
    }
    let a = km * c * c + kp * s * s - surface.ff;
    let b = (km - kp) * c * s - surface.ft;
    let d = km * s * s + kp * c * c - surface.tt;
    0.5 * (a + d) - (0.5 * (a - d)).hypot(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effective_radius::LeadTilt;
    use crate::testing;

    #[test]
    fn trough_tighter_than_the_ball_gouges() {
        // Inside a trough of radius 20 (concave across the feed along y): a ball R 25 gouges,
        // R 15 does not; a flat R 5 gouges untilted and clears at the matching lead.
        let s = testing::cylinder(20.0, 50.0, false);
        let d = s.derivs(0.5, 0.5);
        let n = s.normal(0.5, 0.5).unwrap();
        let frame = ContactFrame::new(n, d.sv).unwrap();
        let k = surface_curvature(&d, &frame).unwrap();
        assert!(
            (k.tt - 1.0 / 20.0).abs() < 1e-9 && k.ff.abs() < 1e-9,
            "{k:?}"
        );
        let a = frame.axis(LeadTilt::default());
        let m = |shape: CutterShape, a| local_margin(&shape, &frame, &a, &k);
        assert!(m(CutterShape::Ball { radius: 25.0 }, a) < 0.0);
        assert!(m(CutterShape::Ball { radius: 15.0 }, a) > 0.0);
        let flat = CutterShape::Flat { radius: 5.0 };
        assert!(m(flat, a) < 0.0);
        let lead = flat.matching_lead(19.0).unwrap();
        assert!(m(flat, frame.axis(LeadTilt::new(lead, 0.0))) > 0.0);
        // Feeding across the trough instead: the concavity is along the feed, where a flat
        // rim is infinitely curved, so no local gouge even untilted… but a ball R 25 still.
        let frame2 = ContactFrame::new(n, d.su).unwrap();
        let k2 = surface_curvature(&d, &frame2).unwrap();
        let a2 = frame2.axis(LeadTilt::default());
        assert!(local_margin(&CutterShape::Ball { radius: 25.0 }, &frame2, &a2, &k2) < 0.0);
        let lead_only = frame2.axis(LeadTilt::new(0.2, 0.0));
        assert!(local_margin(&flat, &frame2, &lead_only, &k2) > 0.0);
    }
}
