//! Pre-flight of a built path: before anything moves, every segment is turned into joints at
//! its ends and at points at most [`PREFLIGHT_STEP_MM`] apart, through the same kinematics the
//! interpolator uses ([`PlanMachine::segment_joints`]), so a pose out of reach or a joint past
//! its limit is reported with its source line instead of stopping a run half-way: a program
//! file is checked whole before motion starts.
//!
//! Sampling bounds what it can miss: between two checked points a curve of radius ρ bulges at
//! most h²/(8ρ) beyond their chord (h ≤ the step), so a limit crossed by less than that on a
//! tight arc is left to the interpolator, which checks every sample and stops with the line.

use tezgah_geom::Vec3;
use tezgah_kinematics::{Joints, KinematicsError};

use crate::path::{PathItem, Segment};
use crate::plan::PlanMachine;

/// Longest tip travel between two checked points of a segment, mm.
pub const PREFLIGHT_STEP_MM: f64 = 0.5;
/// Largest rotary travel between two checked points of a rotary-only segment, degrees.
pub const PREFLIGHT_STEP_DEG: f64 = 1.0;

/// A segment the machine cannot follow.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: {source}")]
pub struct PreflightError {
    /// 1-based source line of the segment.
    pub line: u32,
    #[source]
    pub source: KinematicsError,
}

/// Checks every segment of `items`, starting from joints `start`.
pub fn check_path<'a>(
    items: impl IntoIterator<Item = &'a PathItem>,
    machine: &PlanMachine,
    start: Joints,
) -> Result<(), PreflightError> {
    let mut previous = start;
    for item in items {
        if let PathItem::Segment(seg) = item {
            previous = check_segment(seg, machine, previous)?;
        }
    }
    Ok(())
}

/// The joints along one segment; returns those at its end.
fn check_segment(
    seg: &Segment,
    machine: &PlanMachine,
    mut previous: Joints,
) -> Result<Joints, PreflightError> {
    let steps = if seg.rotary_only() {
        (seg.rotary_travel() / PREFLIGHT_STEP_DEG).ceil()
    } else {
        (seg.length / PREFLIGHT_STEP_MM).ceil()
    }
    .clamp(1.0, 1e6) as usize;
    let (a, b) = seg.curve.domain();
    // Tips at equal steps of the parameter, and the fraction of the length at each (by the
    // chord polygon): the pairs (u, f) the interpolator passes through, to O(h²).
    let tips: Vec<Vec3> = (0..=steps)
        .map(|k| {
            if k == steps {
                seg.curve.point(b)
            } else {
                seg.curve.point(a + (b - a) * k as f64 / steps as f64)
            }
        })
        .collect();
    let mut run = vec![0.0; steps + 1];
    for k in 1..=steps {
        run[k] = run[k - 1] + (tips[k] - tips[k - 1]).norm();
    }
    let total = run[steps];
    for (k, tip) in tips.iter().enumerate() {
        let u = if k == steps {
            b
        } else {
            a + (b - a) * k as f64 / steps as f64
        };
        let f = if total > 0.0 {
            run[k] / total
        } else {
            k as f64 / steps as f64
        };
        let (q, _) = machine
            .segment_joints(seg, u, f, tip, &previous)
            .map_err(|source| PreflightError {
                line: seg.line,
                source,
            })?;
        previous = q;
    }
    Ok(previous)
}
