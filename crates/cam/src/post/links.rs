//! The stations of a posted program: every cutter location of every pass, and the links
//! between passes — retract along the tool axis to the clearance sphere, turn the table
//! there, move on the sphere to the next pass, turn, come down its axis and plunge. First
//! step of the post-processor, before the angles.
//!
//! The sphere ([`Clearance`]) holds the part and the tool's widest radius with a clearance
//! to spare; on it, with the link axes [`Clearance::link_axis`] gives, the whole tool stands
//! outside the part's ball, so the table turns only where it cannot touch the part. The
//! retract and the approach keep the tool axis fixed (no rotary motion), along the line the
//! tool itself occupies while it cuts, for any tilt the machine reaches.

use nalgebra::Unit;
use tezgah_geom::Vec3;

use super::clearance::Clearance;
use crate::toolpath::{CutterLocation, ToolPath};

/// How the tool gets to a station.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// G0, off the part.
    Rapid,
    /// G1 at the feed, along the tool axis into the first point of a pass.
    Plunge,
    /// G1 at the feed, cutting.
    Cut,
}

/// Where the tool goes next and how, in the part frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Station {
    pub tip: Vec3,
    /// Unit tool axis.
    pub axis: Vec3,
    pub motion: Motion,
    /// The (pass, point) of the tool path this station is, if it is one.
    pub source: Option<(usize, usize)>,
    /// The (pass, point) this station is, approaches or leaves: where errors are reported.
    pub place: Option<(usize, usize)>,
}

/// Where the tool is between passes: on the sphere, with its axis.
#[derive(Clone, Copy)]
struct Pose {
    tip: Vec3,
    axis: Vec3,
}

fn tilt(axis: &Vec3) -> f64 {
    axis.z.clamp(-1.0, 1.0).acos()
}

/// Every station in order: the top of the sphere with the tool vertical, then for each pass
/// the link to it, its approach and plunge, its cuts and the retract, and last the link back
/// to the top with the tool vertical. Cutter locations repeated in place are dropped.
/// `approach` is the distance above the first point where the rapid approach ends and the
/// plunge at the feed begins, mm.
pub fn stations(path: &ToolPath, sphere: &Clearance, approach: f64) -> Vec<Station> {
    let mut out: Vec<Station> = Vec::new();
    let start = Pose {
        tip: sphere.top(),
        axis: Vec3::z(),
    };
    out.push(Station {
        tip: start.tip,
        axis: start.axis,
        motion: Motion::Rapid,
        source: None,
        place: None,
    });
    let mut here = start;
    for (p, pass) in path.passes.iter().enumerate() {
        let Some(first) = pass.points.first() else {
            continue;
        };
        let last_index = pass.points.len() - 1;
        let entry = Pose {
            tip: sphere.exit(&first.tip, &first.axis),
            axis: first.axis,
        };
        link(&mut out, sphere, here, entry, Some((p, 0)));
        let depth = (first.tip - entry.tip).norm();
        if depth > approach {
            push(
                &mut out,
                first.tip + first.axis * approach,
                first.axis,
                Motion::Rapid,
                Some((p, 0)),
            );
        }
        out.push(Station {
            tip: first.tip,
            axis: first.axis,
            motion: Motion::Plunge,
            source: Some((p, 0)),
            place: Some((p, 0)),
        });
        let mut last: &CutterLocation = first;
        for (i, cl) in pass.points.iter().enumerate().skip(1) {
            if (cl.tip - last.tip).norm() <= 1e-9 && (cl.axis - last.axis).norm() <= 1e-12 {
                continue;
            }
            out.push(Station {
                tip: cl.tip,
                axis: cl.axis,
                motion: Motion::Cut,
                source: Some((p, i)),
                place: Some((p, i)),
            });
            last = cl;
        }
        here = Pose {
            tip: sphere.exit(&last.tip, &last.axis),
            axis: last.axis,
        };
        push(
            &mut out,
            here.tip,
            here.axis,
            Motion::Rapid,
            Some((p, last_index)),
        );
    }
    link(&mut out, sphere, here, start, None);
    out
}

/// A rapid station, unless it repeats the last one.
fn push(
    out: &mut Vec<Station>,
    tip: Vec3,
    axis: Vec3,
    motion: Motion,
    place: Option<(usize, usize)>,
) {
    if let Some(l) = out.last() {
        if (l.tip - tip).norm() <= 1e-9 && (l.axis - axis).norm() <= 1e-12 {
            return;
        }
    }
    out.push(Station {
        tip,
        axis,
        motion,
        source: None,
        place,
    });
}

/// Samples per link move where [`link`] tests the tool's clearance.
const LINK_SAMPLES: usize = 8;

/// From `from` to `to`, both on the sphere, as [`Clearance::traverse`] runs. The tool axis
/// turns from one pass's axis to the other's along the way when that keeps the whole tool
/// clear of the part's ball at every station and between them (the table then turns no more
/// than the passes need — none between parallel passes); otherwise it turns on the spot to
/// the link axes, which are always clear, and back at the end. Those lean no further than
/// the larger of the two axes' tilts, so a link asks no more of the tilt axis than the
/// cutting on either side of it.
fn link(
    out: &mut Vec<Station>,
    sphere: &Clearance,
    from: Pose,
    to: Pose,
    place: Option<(usize, usize)>,
) {
    let route = sphere.traverse(&from.tip, &to.tip);
    if let Some(axes) = turning(sphere, &from, &to, &route) {
        for (q, a) in route.iter().zip(axes) {
            push(out, *q, a, Motion::Rapid, place);
        }
        return;
    }
    let cap = tilt(&from.axis).max(tilt(&to.axis));
    push(
        out,
        from.tip,
        sphere.link_axis(&from.tip, cap),
        Motion::Rapid,
        place,
    );
    for q in &route {
        push(out, *q, sphere.link_axis(q, cap), Motion::Rapid, place);
    }
    push(out, to.tip, to.axis, Motion::Rapid, place);
}

/// The axes turning evenly from `from`'s to `to`'s over `route` (one per point), if the tool
/// stays clear, with half the clearance to spare, all the way: at every point and at [`LINK_SAMPLES`] places between points
/// (tip on the chord, axis between the two), and no axis tilts further than both ends do.
fn turning(sphere: &Clearance, from: &Pose, to: &Pose, route: &[Vec3]) -> Option<Vec<Vec3>> {
    let (ua, ub) = (Unit::new_normalize(from.axis), Unit::new_normalize(to.axis));
    let n = route.len();
    let cap = tilt(&from.axis).max(tilt(&to.axis)) + 1e-9;
    let mut axes = Vec::with_capacity(n);
    for k in 1..=n {
        let a = ua.try_slerp(&ub, k as f64 / n as f64, 1e-9)?.into_inner();
        if tilt(&a) > cap {
            return None;
        }
        axes.push(a);
    }
    // Half the clearance to spare: the machine's motion between stations may stray from
    // this blend by the linearisation tolerance, and the check after posting allows none.
    let margin = 0.5 * (sphere.radius - sphere.part_radius - sphere.tool_radius);
    let mut before = (from.tip, from.axis);
    for (q, a) in route.iter().zip(&axes) {
        for k in 1..=LINK_SAMPLES {
            let t = k as f64 / LINK_SAMPLES as f64;
            let tip = before.0 + (q - before.0) * t;
            let axis = (before.1 * (1.0 - t) + a * t).normalize();
            if !sphere.clear_by(&tip, &axis, margin) {
                return None;
            }
        }
        before = (*q, *a);
    }
    Some(axes)
}
