//! `tezgah run` of G33/G33.1: each spindle-synchronised move is played against the machine
//! file's simulated spindle (`tezgah_executor::synced`) before the program is played, so that
//! the verifier's reference knows where a rigid tap turned; `run_probe::play` then cuts the
//! program at these moves as at probe moves and plays their samples between the parts. The
//! spindle is taken at its programmed speed, half a turn before its index, when each such move
//! starts (`run` does not simulate it between them).

use miette::Result;
use tezgah_executor::probe_moves::{part, position_before};
use tezgah_executor::synced::{run_synced, SyncError, SyncRun};
use tezgah_geom::{FeedMode, Move, MoveKind, PathMode, Pose, SyncedMove, Vec3};
use tezgah_kinematics::{Joints, Machine};
use tezgah_motion::plan::PlanOptions;
use tezgah_motion::PathItem;

use crate::diagnostics::report_line;
use crate::run::build_path;
use crate::run_probe::Probed;

/// Where the spindle stands when a synchronised move starts, revolutions past its index.
const START_ANGLE: f64 = 0.5;

/// One synchronised move as it ran.
pub struct SyncStep {
    /// Index of the move in [`Probed::moves`], its plain line and G-code.
    pub index: usize,
    pub line: u32,
    pub code: &'static str,
    pub mv: SyncedMove,
    pub run: SyncRun,
    /// Where the machine came to rest: a thread's end, a tap's start.
    pub stopped: Pose,
}

/// Runs every synchronised move of the program on the simulated spindle.
pub fn run_synced_moves(
    probed: &Probed,
    machine: &Machine,
    tolerance: f64,
    options: &PlanOptions,
) -> Result<Vec<SyncStep>> {
    let (moves, sources, keys) = (&probed.moves, &probed.done.sources, &probed.done.keys);
    let mut steps = Vec::new();
    for (index, m) in moves.iter().enumerate() {
        let MoveKind::Synced(mv) = m.kind else {
            continue;
        };
        let at = |message: &str| report_line(sources, keys.source(m.line), message);
        let start = position_before(moves, index);
        let code = if mv.tap.is_some() { "G33.1" } else { "G33" };
        let stopped = if mv.tap.is_some() { start } else { mv.end };
        let line = keys.plain(m.line);
        if Vec3::from(start.xyz()) == Vec3::from(mv.end.xyz()) {
            if start != mv.end {
                return Err(at(&SyncError::NoLinearTravel.to_string()));
            }
            // Nothing to follow (LinuxCNC's motion finishes such a move at once).
            let run = SyncRun {
                samples: Vec::new(),
                figures: Default::default(),
            };
            steps.push(SyncStep {
                index,
                line,
                code,
                mv,
                run,
                stopped,
            });
            continue;
        }
        let rpm = moves[..index]
            .iter()
            .rev()
            .find_map(|m| match m.kind {
                MoveKind::SpindleSpeed { rpm } => Some(rpm),
                _ => None,
            })
            .unwrap_or(0.0);
        // The line as a feed no slower than the joints allow: its geometry, pre-flight and
        // path limits; the spindle sets the speed.
        // The line as feeds no slower than the joints allow, through `points` and back to the
        // start: its geometry, pre-flight and path limits; the spindle sets the speed.
        let lines = |points: &[Pose]| {
            let mut alone = part(moves, index, index + 1, start);
            alone.pop();
            let kinds = [
                MoveKind::FeedMode(FeedMode::UnitsPerMinute),
                MoveKind::FeedRate { value: 1.0e9 },
                MoveKind::PathMode(PathMode::ExactStop),
            ];
            let feeds = points
                .iter()
                .chain([&start])
                .map(|&end| MoveKind::Feed { end });
            for kind in kinds.into_iter().chain(feeds) {
                alone.push(Move { line: m.line, kind });
            }
            let built = build_path(sources, keys, alone, machine, tolerance, start)?;
            let segments: Vec<_> = built
                .items
                .into_iter()
                .filter_map(|i| match i {
                    PathItem::Segment(s) => Some(std::sync::Arc::new(s)),
                    _ => None,
                })
                .collect();
            if segments.len() != points.len() + 1 {
                return Err(at("the synchronised move has no path"));
            }
            Ok((segments, built.pm))
        };
        let (segments, pm) = lines(&[mv.end])?;
        let (seg, back) = (&segments[0], &segments[1]);
        let tip = Vec3::from(start.xyz());
        let rotary = [start.0[3], start.0[4], start.0[5]];
        let joints = pm
            .joints(seg.control, &tip, &rotary, &Joints::zeros(pm.joint_count()))
            .map_err(|e| at(&e.to_string()))?;
        let mut run = run_synced(
            (seg, back),
            &mv,
            start,
            rpm,
            START_ANGLE,
            machine.spindle,
            &pm,
            options,
            joints,
        )
        .map_err(|e| at(&e.to_string()))?;
        // A tap went past its depth, and past its start on the way back: its samples lie on
        // the lines to the deepest point, up to the highest and down to the start (the same
        // line's limits, which the run obeyed).
        if let (Some(past), Some(back)) = (run.figures.overshoot, run.figures.overshoot_back) {
            let turns = tap_points(start, &mv, past, back);
            let (segments, _) = lines(&turns[..2])?;
            // Along the line from the start toward the hole: the turning points are the
            // sample furthest in and, after it, the one furthest out.
            let along = |p: &Vec3| {
                let a = Vec3::from(start.xyz());
                (p - a).dot(&(Vec3::from(mv.end.xyz()) - a))
            };
            let turn = |from: usize, sign: f64| {
                (from..run.samples.len())
                    .max_by(|&i, &j| {
                        let (x, y) = (&run.samples[i].0.tip, &run.samples[j].0.tip);
                        (sign * along(x)).total_cmp(&(sign * along(y)))
                    })
                    .unwrap_or(from)
            };
            let deep = turn(0, 1.0);
            let high = turn(deep, -1.0);
            for (k, (_, segs)) in run.samples.iter_mut().enumerate() {
                let on = if k <= deep {
                    0
                } else if k <= high {
                    1
                } else {
                    2
                };
                *segs = vec![segments[on].clone()];
            }
        }
        steps.push(SyncStep {
            index,
            line,
            code,
            mv,
            run,
            stopped,
        });
    }
    Ok(steps)
}

/// The moves the verifier measures the samples against: each synchronised move as the straight
/// feeds it is — a thread to its end, a tap to its depth and on by the overshoot its spindle's
/// reversal made (reported with it), then back to its start.
pub fn reference_moves(moves: &[Move], steps: &[SyncStep]) -> Vec<Move> {
    let mut out = Vec::with_capacity(moves.len() + steps.len());
    let mut steps = steps.iter().peekable();
    for (index, m) in moves.iter().enumerate() {
        let Some(step) = steps.next_if(|s| s.index == index) else {
            out.push(m.clone());
            continue;
        };
        let feed = |end: Pose| Move {
            line: m.line,
            kind: MoveKind::Feed { end },
        };
        let f = &step.run.figures;
        match (f.overshoot, f.overshoot_back) {
            (Some(past), Some(back)) => {
                for p in tap_points(step.stopped, &step.mv, past, back) {
                    out.push(feed(p));
                }
                out.push(feed(step.stopped));
            }
            _ => out.push(feed(step.mv.end)),
        }
    }
    out
}

/// A tap's turning points from `start`: its end and `past` mm on along the line, then `back`
/// mm beyond the start the other way.
fn tap_points(start: Pose, mv: &SyncedMove, past: f64, back: f64) -> [Pose; 2] {
    let (a, b) = (Vec3::from(start.xyz()), Vec3::from(mv.end.xyz()));
    let length = (b - a).norm();
    let (mut deepest, mut highest) = (mv.end, start);
    if length > 0.0 {
        let d = (b - a) / length;
        for i in 0..3 {
            deepest.0[i] += d[i] * past;
            highest.0[i] -= d[i] * back;
        }
    }
    [deepest, highest]
}

/// The report's `synced`: per move its line, code, pitch and figures.
pub fn synced_json(steps: &[SyncStep]) -> serde_json::Value {
    let steps = steps.iter().map(|s| {
        let f = &s.run.figures;
        serde_json::json!({
            "line": s.line,
            "code": s.code,
            "pitch_mm": s.mv.pitch,
            "lead_mm": f.lead,
            "sync_error_mm": f.max_error,
            "index_wait_s": f.index_wait,
            "lock_after_s": f.lock_after,
            "overshoot_mm": f.overshoot,
            "duration_s": f.duration,
        })
    });
    serde_json::Value::Array(steps.collect())
}

/// One line per synchronised move: the lead held and the synchronisation error.
pub fn synced_summary(steps: &[SyncStep]) {
    for s in steps {
        let f = &s.run.figures;
        let tap = f
            .overshoot
            .map(|o| format!(", {o:.4} mm past the depth while the spindle reversed"))
            .unwrap_or_default();
        println!(
            "sync     {} line {}: lead {:.5} mm/rev (K {:.5}), sync error ≤ {:.4} mm, \
             index after {:.3} s, locked {:.3} s later{tap}",
            s.code, s.line, f.lead, s.mv.pitch, f.max_error, f.index_wait, f.lock_after
        );
    }
}
