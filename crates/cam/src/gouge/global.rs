//! Global gouge (collision): the flutes above the cutting end, the shank and the holder —
//! cylinders along the tool axis — against the whole surface, through the coarse index.
//! Can (2010) collects the holder's size but never checks it; this does.

use nalgebra::Unit;
use tezgah_geom::Vec3;

use super::index::PointGrid;
use super::rear::checked_height;
use super::ToolPart;
use crate::cutter::{Cutter, Cylinder};

/// A surface sample inside (or within the clearance of) a part of the tool.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    pub part: ToolPart,
    /// How far inside the part's cylinder, clearance included (mm).
    pub depth: f64,
    pub point: Vec3,
}

/// The tool's cylinders above what the rear check covers ([`checked_height`]), each with
/// its part.
pub fn cylinders(cutter: &Cutter) -> Vec<(ToolPart, Cylinder)> {
    let big_r = cutter.shape.radius();
    let end = checked_height(cutter);
    let mut parts = Vec::new();
    if cutter.flute_length > end {
        parts.push((
            ToolPart::Flutes,
            Cylinder {
                radius: big_r,
                from: end,
                length: cutter.flute_length - end,
            },
        ));
    }
    for (part, c) in [
        (ToolPart::Shank, cutter.shank),
        (ToolPart::Holder, cutter.holder),
    ] {
        // A shank of the tool's radius within the checked solid is covered exactly there.
        let covered = c.radius <= big_r && c.from + c.length <= end;
        // Otherwise whole, even where it overlaps the checked solid: a holder wider than the
        // tool can sit lower than two radii on a stubby tool.
        if c.length > 0.0 && c.radius > 0.0 && !covered {
            parts.push((part, c));
        }
    }
    parts
}

/// The first surface sample within `clearance` of a cylinder of the tool standing at `tip`
/// along `axis`.
pub fn collision(
    grid: &PointGrid,
    cutter: &Cutter,
    tip: &Vec3,
    axis: &Unit<Vec3>,
    clearance: f64,
) -> Option<Collision> {
    let a = axis.into_inner();
    for (part, c) in cylinders(cutter) {
        let (p0, p1) = (tip + a * c.from, tip + a * (c.from + c.length));
        let reach = c.radius + clearance;
        let (lo, hi) = (
            p0.inf(&p1) - Vec3::repeat(reach),
            p0.sup(&p1) + Vec3::repeat(reach),
        );
        let mut hit = None;
        grid.visit_box(&lo, &hi, |s| {
            let p = &s.point;
            let d = p - tip;
            let z = d.dot(&a);
            if z < c.from || z > c.from + c.length {
                return true;
            }
            let rho = (d - a * z).norm();
            if rho < reach {
                hit = Some(Collision {
                    part,
                    depth: reach - rho,
                    point: *p,
                });
                return false;
            }
            true
        });
        if hit.is_some() {
            return hit;
        }
    }
    None
}
