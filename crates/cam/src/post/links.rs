//! The stations of a posted program: every cutter location of every pass, and the links
//! between passes — retract along the tool axis to the safe plane, move there to the next
//! pass, plunge back along its axis. First step of the post-processor, before the angles.
//!
//! The safe plane lies a clearance plus the cutter radius above the highest point of the part
//! (or of the tool path): a tool whose axis points upward (`k > 0`) has no point lower than
//! its radius below the tip, so a link at that height cannot touch the part.

use tezgah_geom::Vec3;

use super::PostError;
use crate::toolpath::ToolPath;

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

/// Smallest upward component of a tool axis that can still be retracted to the safe plane.
const MIN_AXIS_Z: f64 = 1e-3;

/// The safe plane's height: `clearance` plus the cutter radius above `part_top` or above the
/// highest tip and contact point of the path, whichever is higher.
pub fn safe_height(path: &ToolPath, part_top: Option<f64>, clearance: f64) -> f64 {
    let top = path
        .passes
        .iter()
        .flat_map(|p| &p.points)
        .map(|c| c.tip.z.max(c.contact.z))
        .fold(part_top.unwrap_or(f64::NEG_INFINITY), f64::max);
    top + clearance + path.cutter.shape.radius()
}

/// The point where the line from `tip` along `axis` meets the plane `z = safe`.
fn lifted(tip: Vec3, axis: Vec3, safe: f64, at: (usize, usize)) -> Result<Vec3, PostError> {
    if axis.z < MIN_AXIS_Z {
        return Err(PostError::NoRetract {
            pass: at.0,
            point: at.1,
        });
    }
    let lambda = ((safe - tip.z) / axis.z).max(0.0);
    Ok(tip + axis * lambda)
}

/// Every station in order: above the first pass with the tool vertical, then for each pass
/// its approach (rapid), plunge, cuts and retract, and last the tool vertical again above the
/// final retract. Cutter locations repeated in place (same tip and axis) are dropped.
pub fn stations(path: &ToolPath, safe: f64) -> Result<Vec<Station>, PostError> {
    let mut out: Vec<Station> = Vec::new();
    for (p, pass) in path.passes.iter().enumerate() {
        let Some(first) = pass.points.first() else {
            continue;
        };
        let above = lifted(first.tip, first.axis, safe, (p, 0))?;
        if out.is_empty() {
            out.push(Station {
                tip: Vec3::new(above.x, above.y, safe),
                axis: Vec3::z(),
                motion: Motion::Rapid,
                source: None,
                place: None,
            });
        }
        out.push(Station {
            tip: above,
            axis: first.axis,
            motion: Motion::Rapid,
            source: None,
            place: Some((p, 0)),
        });
        let mut last = first;
        out.push(Station {
            tip: first.tip,
            axis: first.axis,
            motion: Motion::Plunge,
            source: Some((p, 0)),
            place: Some((p, 0)),
        });
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
        let at = (p, pass.points.len() - 1);
        let up = lifted(last.tip, last.axis, safe, at)?;
        out.push(Station {
            tip: up,
            axis: last.axis,
            motion: Motion::Rapid,
            source: None,
            place: Some(at),
        });
    }
    if let Some(end) = out.last().copied() {
        out.push(Station {
            tip: end.tip,
            axis: Vec3::z(),
            motion: Motion::Rapid,
            source: None,
            place: None,
        });
    }
    Ok(out)
}
