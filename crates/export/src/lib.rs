//! tezgah-export: joint-space G-code for controllers that know no kinematics (a grbl, grblHAL
//! or Mach3 board on a delta, a trunnion table without tool-centre-point control).
//!
//! The program's moves are built into the path `tezgah run` follows (arcs, splines, blends;
//! the program's own geometry under G61), then [`convert`] writes each segment as G1 moves in
//! joint coordinates, split so a joint-linear controller keeps the tip within the tolerance
//! and timed in inverse time (G93) so the tip keeps the programmed feed; [`words`] carries
//! spindle, coolant and tool words through; [`mod@write`] prints the program.
//!
//! ```text
//! moves ──motion::path::smooth──► segments ──convert (chords, kinematics::segment)──► Blocks
//!       ──write──► .ngc (joint letters, G93 F, N = source line)
//! ```

pub mod convert;
pub mod letters;
pub mod words;
pub mod write;

use tezgah_geom::{Move, MoveKind, Pose, StopKind, Vec3};
use tezgah_kinematics::{Joints, KinematicsError, Machine};
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::PathItem;

pub use convert::{Block, Piece};
pub use letters::AxisLetters;
pub use words::{PassThrough, Word};

/// Why a program could not be exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// The machine cannot be written for (or planned on).
    #[error("machine: {0}")]
    Machine(String),
    /// The path builder refused a move (`line`: the move's line as given to [`export`]).
    #[error("{message}")]
    Path { line: Option<u32>, message: String },
    /// A point of the path has no joints within reach and limits, or a piece cannot be kept
    /// within the tolerance (a pass through a singularity).
    #[error("{source}")]
    Kinematics {
        line: u32,
        #[source]
        source: KinematicsError,
    },
}

impl ExportError {
    /// The line (as the moves carried it) the error is about.
    pub fn line(&self) -> Option<u32> {
        match self {
            ExportError::Machine(_) => None,
            ExportError::Path { line, .. } => *line,
            ExportError::Kinematics { line, .. } => Some(*line),
        }
    }
}

/// The figures `tezgah export` prints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Motion blocks of the program (rapids, feeds, arcs, splines, dwells).
    pub blocks_in: usize,
    /// Motion blocks written (G0, G1, G4).
    pub blocks_out: usize,
    /// The largest distance of the joint-linear tip from the built path, mm, and its line.
    pub worst_deviation: f64,
    pub worst_line: u32,
    /// The written blocks' share of the tolerance (the largest in the program), mm.
    pub budget: f64,
    /// Where the path carries a tool axis (five-axis under TCP): the largest angle of the
    /// joint-linear tool axis from it and the blocks' share of the angular tolerance,
    /// degrees; `None` without.
    pub axis: Option<(f64, f64)>,
    /// The longest written move along the tip path, mm, and its line.
    pub longest: f64,
    pub longest_line: u32,
}

/// The written program before printing.
#[derive(Debug)]
pub struct Exported {
    pub blocks: Vec<Block>,
    /// The built path the blocks realise ([`Piece::segment`] indexes it).
    pub path: Vec<PathItem>,
    pub summary: Summary,
}

/// Exports `moves` (one interpretation, with its carried-through `words` placed by
/// [`PassThrough::placed`]) for `machine` within `tolerance` (mm, the path builder's ε;
/// `G64 P` overrides it per move). `label` turns a move's line into the N word written.
pub fn export(
    moves: Vec<Move>,
    words: &[(usize, Word)],
    machine: &Machine,
    tolerance: f64,
    label: &dyn Fn(u32) -> u32,
) -> Result<Exported, ExportError> {
    let pm = PlanMachine::from_machine(machine).map_err(|e| ExportError::Machine(e.to_string()))?;
    let start = Pose::ZERO;
    let start_joints = pm
        .joints(
            pm.initial,
            &Vec3::from(start.xyz()),
            &[start.0[3], start.0[4], start.0[5]],
            &Joints::zeros(pm.joint_count()),
        )
        .map_err(|e| ExportError::Machine(format!("the start pose: {e}")))?;
    // Each move's line becomes its index + 1, so every path item names the move it came
    // from and the carried words go back between the same two moves.
    let lines: Vec<u32> = moves.iter().map(|m| m.line).collect();
    let kinds: Vec<MoveKind> = moves.iter().map(|m| m.kind.clone()).collect();
    let blocks_in = kinds
        .iter()
        .filter(|k| {
            matches!(
                k,
                MoveKind::Rapid { .. }
                    | MoveKind::Feed { .. }
                    | MoveKind::Arc(_)
                    | MoveKind::Nurbs(_)
                    | MoveKind::Dwell { .. }
            )
        })
        .count();
    let numbered = moves.into_iter().enumerate().map(|(i, m)| Move {
        line: i as u32 + 1,
        ..m
    });
    let original = |n: u32| {
        lines
            .get((n as usize).wrapping_sub(1))
            .copied()
            .unwrap_or(0)
    };
    let opts = SmoothOptions::for_machine(&machine.path, &pm, tolerance, start);
    let path = smooth::Smoother::new(numbered, opts.clone())
        .map_err(|e| ExportError::Path {
            line: None,
            message: e.to_string(),
        })?
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| ExportError::Path {
            line: e.line().map(original),
            message: e.detail(),
        })?;

    let mut conv = convert::Converter {
        pm: &pm,
        axis_tolerance_deg: opts.angular_tolerance,
        last: start_joints,
        blocks: Vec::new(),
    };
    let mut pending = words.iter().peekable();
    let mut ended = false;
    for (index, item) in path.iter().enumerate() {
        let n = match item {
            PathItem::Segment(s) => s.line,
            PathItem::Dwell { line, .. } | PathItem::Stop { line } => *line,
        };
        let at = n as usize - 1;
        while let Some((_, w)) = pending.next_if(|(p, _)| *p <= at) {
            conv.blocks.push(Block::Words {
                text: w.text.clone(),
                line: w.line,
            });
        }
        let line = label(original(n));
        match item {
            PathItem::Segment(seg) => {
                conv.segment(index, seg, line)
                    .map_err(|source| ExportError::Kinematics {
                        line: original(n),
                        source,
                    })?
            }
            PathItem::Dwell { seconds, .. } => conv.blocks.push(Block::Dwell {
                seconds: *seconds,
                line,
            }),
            PathItem::Stop { .. } => {
                let kind = match kinds[at] {
                    MoveKind::Stop(kind) => kind,
                    _ => StopKind::Pause,
                };
                // M30 reaches the moves as a pallet shuttle and the end, on one line.
                let rewind = kind == StopKind::PalletPause
                    && matches!(kinds.get(at + 1), Some(MoveKind::Stop(StopKind::End)))
                    && lines.get(at + 1) == lines.get(at);
                let kind = if rewind { StopKind::End } else { kind };
                if !ended {
                    conv.blocks.push(Block::Stop { kind, rewind, line });
                }
                ended |= kind == StopKind::End;
            }
        }
    }
    for (_, w) in pending {
        conv.blocks.push(Block::Words {
            text: w.text.clone(),
            line: w.line,
        });
    }
    let axis_budget = smooth::CHORD_SHARE * opts.angular_tolerance;
    let summary = summarise(&conv.blocks, blocks_in, tolerance, axis_budget, &path);
    Ok(Exported {
        blocks: conv.blocks,
        path,
        summary,
    })
}

fn summarise(
    blocks: &[Block],
    blocks_in: usize,
    tolerance: f64,
    axis_budget: f64,
    path: &[PathItem],
) -> Summary {
    let mut s = Summary {
        blocks_in,
        blocks_out: 0,
        worst_deviation: 0.0,
        worst_line: 0,
        budget: smooth::CHORD_SHARE * tolerance,
        longest: 0.0,
        longest_line: 0,
        axis: None,
    };
    for item in path {
        if let PathItem::Segment(seg) = item {
            s.budget = s.budget.max(smooth::CHORD_SHARE * seg.tolerance);
            if seg.axis.is_some() && s.axis.is_none() {
                s.axis = Some((0.0, axis_budget));
            }
        }
    }
    for b in blocks {
        let (piece, line) = match b {
            Block::Rapid { piece, line, .. } => (*piece, *line),
            Block::Feed { piece, line, .. } => (Some(*piece), *line),
            Block::Dwell { .. } => (None, 0),
            Block::Stop { .. } | Block::Words { .. } => continue,
        };
        s.blocks_out += 1;
        if let Some(p) = piece {
            if p.deviation > s.worst_deviation {
                (s.worst_deviation, s.worst_line) = (p.deviation, line);
            }
            if let Some((worst, _)) = &mut s.axis {
                *worst = worst.max(p.axis_deviation.to_degrees());
            }
            if p.length > s.longest {
                (s.longest, s.longest_line) = (p.length, line);
            }
        }
    }
    s
}
