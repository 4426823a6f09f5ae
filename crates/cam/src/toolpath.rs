//! The tool path: what the strategies produce and the post-processor and the verifying
//! simulation consume — passes of cutter locations in the workpiece frame, each with the
//! cutter-contact point it was computed from, so every later stage can check against it.

use tezgah_geom::Vec3;

use crate::cutter::Cutter;

/// One cutter location (CL): where the tool is and how it stands, with the cutter-contact
/// (CC) point on the surface that placed it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterLocation {
    /// The tool tip (the lowest point of the tool on its axis), workpiece frame, mm.
    pub tip: Vec3,
    /// Unit tool axis, from the tip towards the spindle.
    pub axis: Vec3,
    /// The cutter-contact point on the surface.
    pub contact: Vec3,
    /// Unit surface normal at the contact point, pointing out of the material.
    pub normal: Vec3,
    /// Surface parameters of the contact point.
    pub uv: (f64, f64),
}

/// One cutting pass: a run of cutter locations cut in order at the cutting feed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Pass {
    pub points: Vec<CutterLocation>,
}

/// A finishing tool path: the cutter and its passes, in cutting order. Between passes the
/// tool retracts along its axis, moves and plunges back (the post-processor writes those links).
#[derive(Debug, Clone, PartialEq)]
pub struct ToolPath {
    pub cutter: Cutter,
    pub passes: Vec<Pass>,
}

impl Pass {
    /// Length of the tip's polyline, mm.
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|w| (w[1].tip - w[0].tip).norm())
            .sum()
    }
}

impl ToolPath {
    /// Cutting length over all passes (links excluded), mm.
    pub fn cutting_length(&self) -> f64 {
        self.passes.iter().map(Pass::length).sum()
    }

    /// Number of cutter-contact points.
    pub fn contact_count(&self) -> usize {
        self.passes.iter().map(|p| p.points.len()).sum()
    }
}
