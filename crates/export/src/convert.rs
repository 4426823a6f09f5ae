//! The built path → joint blocks. Each segment is cut into chords (a curve: arc, helix,
//! spline, blend) and each chord is split by the kinematics crate's deviation-based splitter,
//! so that a controller moving its joints linearly between two written points keeps the tool
//! tip within the tolerance left to it; each block is timed so the tip keeps the programmed
//! feed along the path.
//!
//! The tolerance budget is `tezgah run`'s (ARCHITECTURE.md "One tolerance budget"): the path
//! builder spends up to 0.8 ε on compression and blends, the rest (`CHORD_SHARE`, 0.2 ε) is the
//! written blocks' — half on chords of a curve and half on the joint-linear bow, or all of it
//! on whichever one a segment needs (a line needs no chords; a machine whose joints are the
//! program axes has no bow).

use nalgebra::{Unit, Vector3};
use tezgah_geom::curve::LENGTH_TOLERANCE;
use tezgah_geom::deviation::{closest_point, max_distance_to_segment, point_segment_distance};
use tezgah_geom::{ArcLengthMap, Curve, StopKind, ToolControl, Vec3};
use tezgah_kinematics::segment::{segment_line_by, SegmentOptions};
use tezgah_kinematics::{Joints, Kinematics, KinematicsError, Tool};
use tezgah_motion::path::smooth::CHORD_SHARE;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::{Segment, SegmentFeed};

/// Which programmed piece a written move realises: what the tests and the summary measure the
/// joint-linear tip against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Index of the segment in [`crate::Exported::path`].
    pub segment: usize,
    /// The curve parameters of the chord the move lies along (the whole chord: the tip's
    /// nearest path point may be anywhere on it).
    pub u: (f64, f64),
    /// The fractions of the chord at the move's ends: the joints are the program's at
    /// `u.0 + (u.1 − u.0)·s` for `s` = each end.
    pub s: (f64, f64),
    /// Tip path length the move covers, mm (0 when only rotary axes move the tool).
    pub length: f64,
    /// Largest distance of the joint-linear tip from the programmed piece, mm (measured at
    /// [`DENSE_CHECKS`] points, closer than the splitter checks).
    pub deviation: f64,
    /// Under tool-centre-point control with a tool axis path: the largest angle (rad) of the
    /// joint-linear tool axis from the path's axis at the same fraction of the move (the
    /// tool is where the path puts it when the move is that far through); else 0.
    pub axis_deviation: f64,
}

/// One written block.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// G0 to these joints: a piece of a rapid, or (`piece` `None`) the take-up a
    /// tool-centre-point switch needs where the two readings of the point differ.
    Rapid {
        joints: Joints,
        line: u32,
        piece: Option<Piece>,
    },
    /// G1 to these joints in `minutes` (written as G93 F = 1/minutes).
    Feed {
        joints: Joints,
        minutes: f64,
        line: u32,
        piece: Piece,
    },
    /// G4 P seconds.
    Dwell { seconds: f64, line: u32 },
    /// M0, M1, M60, or the end: M2, M30 (`rewind`, LinuxCNC's pallet shuttle and end).
    Stop {
        kind: StopKind,
        rewind: bool,
        line: u32,
    },
    /// Carried-through words (spindle, coolant, tool, message).
    Words { text: String, line: u32 },
}

/// Joint-linear tip samples per written move for the deviation figure (the splitter itself
/// checks five points and aims at 0.9 of its share, so the peak between its checks stays
/// inside the share).
pub const DENSE_CHECKS: usize = 16;
const SPLIT_CHECKS: usize = 5;
const SPLIT_MARGIN: f64 = 0.9;
/// A chord that far from its curve is the curve: the segment is straight.
const STRAIGHT: f64 = 1e-9;
/// Joints that close (rad or mm) are the same point: no take-up move.
const SAME_JOINTS: f64 = 1e-9;

/// Turns segments into blocks, keeping the joints written last (every inverse continues from
/// them, so rotary joints unwrap and stay on one branch).
pub(crate) struct Converter<'a> {
    pub pm: &'a PlanMachine,
    /// The tool axis's angular tolerance α, degrees; the blocks get [`CHORD_SHARE`] α, as the
    /// planner's samples do (the path's axis blends take the rest).
    pub axis_tolerance_deg: f64,
    pub last: Joints,
    pub blocks: Vec<Block>,
}

/// How the segment is timed: total minutes, or none (rapid).
fn minutes_of(pm: &PlanMachine, seg: &Segment) -> Option<f64> {
    match seg.feed {
        SegmentFeed::Rapid => None,
        SegmentFeed::InverseTime(seconds) => Some(seconds / 60.0),
        // mm/s along the tip; a rotary-only segment's deg/s along its rotary travel (under
        // TCP the tool axis's turn, as the planner times it).
        SegmentFeed::Feed(v) if seg.rotary_only() => {
            let travel = seg
                .tool_axis_travel
                .or_else(|| pm.tool_axis_sweep(seg))
                .unwrap_or_else(|| seg.axis_travel());
            Some(travel / v / 60.0)
        }
        SegmentFeed::Feed(v) => Some(seg.length / v / 60.0),
    }
}

/// Chords of `curve` over `[u0, u1]`, each within `tolerance` of it: halved until they are.
/// Returns (u0, u1, deviation) per chord.
fn chords<C: Curve + ?Sized>(
    curve: &C,
    u0: f64,
    u1: f64,
    tolerance: f64,
) -> Result<Vec<(f64, f64, f64)>, KinematicsError> {
    const MAX_DEPTH: u32 = 40;
    let mut out = Vec::new();
    let mut stack = vec![(u0, u1, 0u32)];
    while let Some((a, b, depth)) = stack.pop() {
        let d = max_distance_to_segment(curve, a, b, &curve.point(a), &curve.point(b), 16);
        if d.distance <= tolerance {
            out.push((a, b, d.distance));
        } else if depth >= MAX_DEPTH {
            return Err(KinematicsError::Unreachable {
                reason: format!("cannot chord the curve within {tolerance} mm"),
            });
        } else {
            let m = 0.5 * (a + b);
            // Right half first onto the stack, so the left is taken next: program order.
            stack.push((m, b, depth + 1));
            stack.push((a, m, depth + 1));
        }
    }
    Ok(out)
}

impl Converter<'_> {
    /// The blocks of one segment (`index` in the built path, written with `line`).
    pub fn segment(
        &mut self,
        index: usize,
        seg: &Segment,
        line: u32,
    ) -> Result<(), KinematicsError> {
        let pm = self.pm;
        let budget = seg.tolerance * CHORD_SHARE;
        // The tool axis is checked where the path carries one (five-axis under TCP).
        let axis_budget = seg
            .axis
            .map(|_| CHORD_SHARE * self.axis_tolerance_deg.to_radians());
        let tool = match seg.control {
            ToolControl::CentrePoint { tool_length } => Tool::with_length(tool_length),
            // TCP off: the moves' X Y Z are the gauge point (G43's length already in Z).
            ToolControl::Joints { .. } => Tool::default(),
        };
        // Joints that are the program axes themselves move the tip along the chord exactly.
        let direct = pm.map_for(seg.control).is_some();
        let minutes = minutes_of(pm, seg);
        if minutes == Some(0.0) {
            return Ok(()); // nothing moves
        }
        let curve = &*seg.curve;
        let (d0, d1) = curve.domain();
        let rotary_only = seg.rotary_only();
        let map = if rotary_only {
            None
        } else {
            Some(ArcLengthMap::new(curve, LENGTH_TOLERANCE).map_err(|e| {
                KinematicsError::BadInput {
                    reason: format!("path length: {e}"),
                }
            })?)
        };
        let total = map.as_ref().map_or(0.0, |m| m.length());
        let sigma = |u: f64| map.as_ref().map_or(0.0, |m| m.s_at(curve, u));
        let whole = max_distance_to_segment(curve, d0, d1, &curve.point(d0), &curve.point(d1), 16);
        let straight = rotary_only || whole.distance <= STRAIGHT;
        let (pieces, bow) = if straight {
            (vec![(d0, d1, whole.distance)], budget)
        } else {
            let share = if direct { budget } else { 0.5 * budget };
            (chords(curve, d0, d1, share)?, budget - share)
        };
        for (u0, u1, chord_deviation) in pieces {
            let (a, b) = (curve.point(u0), curve.point(u1));
            let (s0, s1) = (sigma(u0), sigma(u1));
            let target =
                |s: f64, prev: &Joints| -> Result<(Joints, Unit<Vector3<f64>>), KinematicsError> {
                    let u = u0 + (u1 - u0) * s;
                    let f = if rotary_only {
                        s
                    } else {
                        (s0 + (s1 - s0) * s) / total
                    };
                    let tip = a + (b - a) * s;
                    let (q, _) = pm.segment_joints(seg, u, f.min(1.0), &tip, prev)?;
                    Ok((q, pm.model.forward(&q, &tool)?.axis))
                };
            let points = if direct {
                let (q0, _) = target(0.0, &self.last)?;
                let (q1, _) = target(1.0, &q0)?;
                vec![(0.0, q0), (1.0, q1)]
            } else {
                let options = SegmentOptions {
                    tolerance_mm: SPLIT_MARGIN * bow,
                    axis_tolerance_rad: axis_budget.map(|b| SPLIT_MARGIN * b),
                    checks_per_piece: SPLIT_CHECKS,
                    max_depth: 40,
                };
                segment_line_by(&pm.model, &tool, &a, &b, &self.last, &options, &target)?.points
            };
            self.take_up(&points[0].1, line);
            for w in points.windows(2) {
                let ((f0, q0), (f1, q1)) = (&w[0], &w[1]);
                let length = (s1 - s0) * (f1 - f0);
                let (deviation, axis_deviation) = if direct {
                    (chord_deviation, 0.0)
                } else {
                    let shape = if straight {
                        Programmed::Line(a, b)
                    } else {
                        Programmed::Curve(u0, u1)
                    };
                    // The programmed axis at chord fraction s, where the path carries one.
                    let axis_at = |s: f64| -> Option<Vec3> {
                        let path = seg.axis?;
                        let f = if rotary_only {
                            s
                        } else {
                            (s0 + (s1 - s0) * s) / total
                        };
                        Some(path.at(u0 + (u1 - u0) * s, f.min(1.0)))
                    };
                    self.dense_deviation(curve, shape, &tool, (*f0, q0), (*f1, q1), &axis_at)?
                };
                let piece = Piece {
                    segment: index,
                    u: (u0, u1),
                    s: (*f0, *f1),
                    length,
                    deviation,
                    axis_deviation,
                };
                let joints = *q1;
                if !moves(q0, q1) {
                    continue; // nothing to write: no joint moves (so neither does the tip)
                }
                self.blocks.push(match minutes {
                    None => Block::Rapid {
                        joints,
                        line,
                        piece: Some(piece),
                    },
                    Some(m) => Block::Feed {
                        joints,
                        // The block's share of the segment: its length, or its part of the
                        // rotary travel.
                        minutes: m * if rotary_only { f1 - f0 } else { length / total },
                        line,
                        piece,
                    },
                });
                self.last = joints;
            }
        }
        Ok(())
    }

    /// A joint-space rapid to `start` when the joints written last are elsewhere (the two
    /// readings of one point across a tool-centre-point switch).
    fn take_up(&mut self, start: &Joints, line: u32) {
        if moves(&self.last, start) {
            self.blocks.push(Block::Rapid {
                joints: *start,
                line,
                piece: None,
            });
            self.last = *start;
        }
    }

    /// The largest distance from the programmed piece of the tip moved joint-linearly from
    /// `q0` (at chord fraction `f0`) to `q1` (at `f1`), at [`DENSE_CHECKS`] interior points,
    /// and the largest angle of its tool axis from `axis_at` the same fraction (0 without).
    fn dense_deviation<C: Curve + ?Sized>(
        &self,
        curve: &C,
        shape: Programmed,
        tool: &Tool,
        (f0, q0): (f64, &Joints),
        (f1, q1): (f64, &Joints),
        axis_at: &dyn Fn(f64) -> Option<Vec3>,
    ) -> Result<(f64, f64), KinematicsError> {
        let (mut worst, mut worst_axis): (f64, f64) = (0.0, 0.0);
        for k in 1..DENSE_CHECKS {
            let t = k as f64 / DENSE_CHECKS as f64;
            let pose = self.pm.model.forward(&q0.lerp(q1, t), tool)?;
            let d = match shape {
                Programmed::Line(a, b) => point_segment_distance(&pose.tip, &a, &b),
                // A chord's stretch of curve is within the tolerance of a straight line:
                // one minimum, which a few samples bracket.
                Programmed::Curve(u0, u1) => closest_point(curve, &pose.tip, u0, u1, 4).distance,
            };
            worst = worst.max(d);
            if let Some(want) = axis_at(f0 + (f1 - f0) * t) {
                worst_axis = worst_axis.max(pose.axis.angle(&want));
            }
        }
        Ok((worst, worst_axis))
    }
}

/// Whether any joint differs between `a` and `b` by more than [`SAME_JOINTS`].
fn moves(a: &Joints, b: &Joints) -> bool {
    a.as_slice()
        .iter()
        .zip(b.as_slice())
        .any(|(x, y)| (x - y).abs() > SAME_JOINTS)
}

/// What a written move is measured against: the segment itself where it is straight (or a
/// point, the tip standing still), else its curve between the chord's parameters.
#[derive(Clone, Copy)]
enum Programmed {
    Line(Vec3, Vec3),
    Curve(f64, f64),
}
