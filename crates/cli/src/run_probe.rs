//! `tezgah run` of a program that probes (G38.2–G38.5) on the simulated probe: the hand-off
//! between the interpreter and the machine. The interpreter stops at each probe move it has no
//! answer for; the probe move is run on the probe model (`tezgah_executor::probe`) and the
//! program interpreted again with one answer more, until it runs through. The moves are then
//! played in parts cut at the probe moves, each part pre-flighted as it is reached, each probe
//! move replayed as it ran (trip, then the stop).

use std::sync::Arc;

use miette::{miette, Result};
use tezgah_executor::probe::{run_probe_move, ProbeRun, Sampled, Seek};
use tezgah_executor::probe_moves::{part, point_at, position_before, with_stops};
use tezgah_gcode::error::ErrorKind;
use tezgah_gcode::sources::{interpret, Interpreted, Pass, Sources};
use tezgah_gcode::{Config, ProbeModel as Answers, ProbeOutcome};
use tezgah_geom::{Move, MoveKind, Pose, Vec3};
use tezgah_kinematics::probe::ProbeModel;
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::{run as run_items, Sample};
use tezgah_motion::plan::PlanOptions;
use tezgah_motion::Segment;

use crate::diagnostics::report_line;
use crate::run::{build_path, AxisFigures, BuiltPath};
use crate::run_synced::SyncStep;

/// One probe move as it ran.
pub struct ProbeStep {
    /// Index of the probe move in [`Probed::moves`].
    pub index: usize,
    /// Its G-code (`38.2` …) and plain line number.
    pub code: String,
    pub line: u32,
    pub run: ProbeRun,
    /// Where the machine came to rest (moves' coordinates, mm and degrees).
    pub stopped: Pose,
}

/// A program interpreted to its end with every probe answered.
pub struct Probed {
    pub done: Interpreted,
    /// The moves, each probe move ending where the machine stopped.
    pub moves: Vec<Move>,
    pub steps: Vec<ProbeStep>,
}

/// Interprets the program, answering its probe moves from `model` (none: probing is refused).
/// `Err(done)` when the interpretation fails: `done.errors` says where.
pub fn interpret_probing(
    sources: impl Fn() -> Sources,
    mut config: Config,
    locate: impl Fn(&str) -> Option<std::path::PathBuf>,
    model: Option<&ProbeModel>,
    machine: &Machine,
    tolerance: f64,
    options: &PlanOptions,
) -> Result<std::result::Result<Probed, Interpreted>> {
    let mut steps: Vec<ProbeStep> = Vec::new();
    let mut answers: Vec<ProbeOutcome> = Vec::new();
    loop {
        if model.is_some() {
            config.probe = Answers::Answered(Arc::from(answers.as_slice()));
        }
        let mut done = interpret(
            sources(),
            config.clone(),
            Pass::Run,
            &locate,
            &mut tezgah_gcode::canon::Discard,
        );
        let stops: Vec<(usize, Pose)> = steps.iter().map(|s| (s.index, s.stopped)).collect();
        let moves = with_stops(std::mem::take(&mut done.moves), &stops);
        let code = match done.errors.first().map(|e| &e.kind) {
            None => {
                return Ok(Ok(Probed { done, moves, steps }));
            }
            Some(ErrorKind::ProbeAwaitsAnswer(code)) => code.clone(),
            Some(_) => {
                done.moves = moves;
                return Ok(Err(done));
            }
        };
        let (Some(model), Some(seek)) = (model, Seek::of(&code)) else {
            return Err(miette!("G{code}: no probe to answer"));
        };
        // The probe move is the last move of the pass that stopped at it.
        let Some((
            index,
            &Move {
                line: key,
                kind: MoveKind::Feed { end },
            },
        )) = moves.iter().enumerate().next_back()
        else {
            return Err(miette!("G{code}: the probe move is not a straight feed"));
        };
        let at = |message: &str| report_line(&done.sources, done.keys.source(key), message);
        let line = done.keys.plain(key);
        let start = position_before(&moves, index);
        let alone = part(&moves, index, index + 1, start);
        let built = build_path(&done.sources, &done.keys, alone, machine, tolerance, start)?;
        let pm = built.pm.clone();
        let mut samples: Vec<Sampled> = Vec::new();
        let tip = Vec3::from(start.xyz());
        run_items(
            built.items,
            built.pm,
            *options,
            (tip, [start.0[3], start.0[4], start.0[5]]),
            |s: &Sample, seg: &[Arc<Segment>]| samples.push((*s, seg.to_vec())),
        )
        .map_err(|e| miette!("{e}"))?;
        let run =
            run_probe_move(samples, model, seek, &pm, options).map_err(|e| at(&e.to_string()))?;
        let stopped = match run.outcome {
            ProbeOutcome::Tripped { stopped, .. } => point_at(start, end, stopped),
            ProbeOutcome::Completed => end,
            ProbeOutcome::AlreadyThere => start,
        };
        answers.push(run.outcome);
        steps.push(ProbeStep {
            index,
            code,
            line,
            run,
            stopped,
        });
    }
}

/// Where the program is cut: a probe move or a synchronised move, its samples as it ran and
/// where the machine came to rest.
struct Cut<'a> {
    index: usize,
    samples: &'a [Sampled],
    stopped: Pose,
}

/// The cuts of the program, in order.
fn cuts<'a>(probed: &'a Probed, synced: &'a [SyncStep]) -> Vec<Cut<'a>> {
    let probes = probed.steps.iter().map(|s| Cut {
        index: s.index,
        samples: &s.run.samples,
        stopped: s.stopped,
    });
    let synced = synced.iter().map(|s| Cut {
        index: s.index,
        samples: &s.run.samples,
        stopped: s.stopped,
    });
    let mut cuts: Vec<Cut> = probes.chain(synced).collect();
    cuts.sort_by_key(|c| c.index);
    cuts
}

/// The path of the part before the first probe or synchronised move (the whole program when
/// it has none), pre-flighted: built before anything is written or moves.
pub fn first_part(
    probed: &Probed,
    synced: &[SyncStep],
    machine: &Machine,
    tolerance: f64,
) -> Result<BuiltPath> {
    let to = cuts(probed, synced)
        .first()
        .map_or(probed.moves.len(), |c| c.index);
    let (sources, keys) = (&probed.done.sources, &probed.done.keys);
    let moves = part(&probed.moves, 0, to, Pose::ZERO);
    build_path(sources, keys, moves, machine, tolerance, Pose::ZERO)
}

/// Plays the probed program into `sink`: the parts between probe and synchronised moves
/// planned and sampled from rest to rest (the first one is [`first_part`]; each later one is
/// built and pre-flighted when it is reached), each probe or synchronised move as it ran;
/// sample times and indices run on across the parts. Returns the duration, the segments
/// planned and the worst tool-axis figures.
pub fn play(
    probed: &Probed,
    synced: &[SyncStep],
    first: BuiltPath,
    machine: &Machine,
    tolerance: f64,
    options: &PlanOptions,
    sink: &mut impl FnMut(&Sample, &[Arc<Segment>]),
) -> Result<(f64, usize, Option<AxisFigures>)> {
    let moves = &probed.moves;
    let (sources, keys) = (&probed.done.sources, &probed.done.keys);
    // The next sample's index; a part's own indices start at 0 from rest.
    let mut next: u64 = 0;
    let mut emit = |s: &Sample, seg: &[Arc<Segment>], next: &mut u64, base: u64| {
        let mut s = *s;
        s.index += base;
        s.t = s.index as f64 * options.period;
        *next = s.index + 1;
        sink(&s, seg);
    };
    let (mut segments, mut axis) = (0, None::<AxisFigures>);
    let mut from = 0;
    let mut start = Pose::ZERO;
    let cuts = cuts(probed, synced);
    let mut first = Some(first);
    for step in cuts.iter().map(Some).chain([None]) {
        let to = step.map_or(moves.len(), |s| s.index);
        let built = match first.take() {
            Some(built) => built,
            None => build_path(
                sources,
                keys,
                part(moves, from, to, start),
                machine,
                tolerance,
                start,
            )?,
        };
        let BuiltPath {
            items,
            pm,
            axis: figures,
        } = built;
        segments += items
            .iter()
            .filter(|i| matches!(i, tezgah_motion::PathItem::Segment(_)))
            .count();
        if axis.is_none_or(|a| figures.deviation_deg > a.deviation_deg) {
            axis = Some(figures);
        }
        let base = next;
        let tip = Vec3::from(start.xyz());
        run_items(
            items,
            pm,
            *options,
            (tip, [start.0[3], start.0[4], start.0[5]]),
            |s: &Sample, seg: &[Arc<Segment>]| emit(s, seg, &mut next, base),
        )
        .map_err(|e| miette!("{e}"))?;
        let Some(step) = step else { break };
        // A probe move's samples start with its row 0 (at rest where the part ended), a
        // synchronised move's with its first period.
        let base = match step.samples.first() {
            Some((s, _)) if s.index > 0 => next - 1,
            _ => next,
        };
        for (s, seg) in step.samples {
            emit(s, seg, &mut next, base);
        }
        segments += 1;
        from = step.index + 1;
        start = step.stopped;
    }
    Ok((
        next.saturating_sub(1) as f64 * options.period,
        segments,
        axis,
    ))
}

/// The report's `probes`: per probe move its line, code, whether it tripped, the trip point
/// (tip, mm) and where the machine came to rest (X Y Z mm, A B C deg).
pub fn probes_json(probed: &Probed) -> serde_json::Value {
    let steps = probed.steps.iter().map(|s| {
        serde_json::json!({
            "line": s.line,
            "code": format!("G{}", s.code),
            "tripped": s.run.trip.is_some(),
            "trip_mm": s.run.trip.map(|p| [p.x, p.y, p.z]),
            "stopped": s.stopped.0,
        })
    });
    serde_json::Value::Array(steps.collect())
}

/// One line per probe move: where it tripped and how far the stop carried on.
pub fn probe_summary(probed: &Probed) {
    for s in &probed.steps {
        let Some(p) = s.run.trip else {
            println!(
                "probe    G{} line {}: no trip (ran to its end)",
                s.code, s.line
            );
            continue;
        };
        let rest = Vec3::from(s.stopped.xyz());
        println!(
            "probe    G{} line {}: tripped at X{:.4} Y{:.4} Z{:.4} mm, at rest {:.4} mm on",
            s.code,
            s.line,
            p.x,
            p.y,
            p.z,
            (rest - p).norm()
        );
    }
}
