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
    /// Tip path length the move covers, mm (0 when only rotary axes move the tool).
    pub length: f64,
    /// Largest distance of the joint-linear tip from the programmed piece, mm (measured at
    /// [`DENSE_CHECKS`] points, closer than the splitter checks).
    pub deviation: f64,
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
/// checks [`SPLIT_CHECKS`] and aims at [`SPLIT_MARGIN`] of its share, so the peak between its
/// checks stays inside the share).
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
                    axis_tolerance_rad: None,
                    checks_per_piece: SPLIT_CHECKS,
                    max_depth: 40,
                };
                segment_line_by(&pm.model, &tool, &a, &b, &self.last, &options, &target)?.points
            };
            self.take_up(&points[0].1, line);
            for w in points.windows(2) {
                let ((f0, q0), (f1, q1)) = (&w[0], &w[1]);
                let length = (s1 - s0) * (f1 - f0);
                let deviation = if direct {
                    chord_deviation
                } else {
                    let shape = if straight {
                        Programmed::Line(a, b)
                    } else {
                        Programmed::Curve(u0, u1)
                    };
                    self.dense_deviation(curve, shape, &tool, q0, q1)?
                };
                let piece = Piece {
                    segment: index,
                    u: (u0, u1),
                    length,
                    deviation,
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
    /// `q0` to `q1`, at [`DENSE_CHECKS`] interior points.
    fn dense_deviation<C: Curve + ?Sized>(
        &self,
        curve: &C,
        shape: Programmed,
        tool: &Tool,
        q0: &Joints,
        q1: &Joints,
    ) -> Result<f64, KinematicsError> {
        let mut worst: f64 = 0.0;
        for k in 1..DENSE_CHECKS {
            let t = k as f64 / DENSE_CHECKS as f64;
            let tip = self.pm.model.forward(&q0.lerp(q1, t), tool)?.tip;
            let d = match shape {
                Programmed::Line(a, b) => point_segment_distance(&tip, &a, &b),
                Programmed::Curve(u0, u1) => closest_point(curve, &tip, u0, u1, 8).distance,
            };
            worst = worst.max(d);
        }
        Ok(worst)
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
