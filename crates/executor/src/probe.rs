//! One probe move (G38.2–G38.5) on the simulated probe: the move is planned and sampled to its
//! end as any feed, then replayed period by period against the probe model; at the first
//! sample where the input has changed the trip position is taken and the machine stops along
//! the line with the jerk-limited path stop ([`PathStop`]) under the move's path limits, so
//! every joint stays within its limits. The answer goes back to the interpreter as fractions
//! of the move ([`ProbeOutcome`]), which then reads on from where the machine came to rest.

use std::sync::Arc;

use tezgah_gcode::ProbeOutcome;
use tezgah_geom::Vec3;
use tezgah_kinematics::probe::ProbeModel;
use tezgah_kinematics::KinematicsError;
use tezgah_motion::interpolate::Sample;
use tezgah_motion::plan::{limits, PlanMachine, PlanOptions};
use tezgah_motion::Segment;

use crate::path_stop::PathStop;

/// A sample and the segments it belongs to, as the interpolator hands them out.
pub type Sampled = (Sample, Vec<Arc<Segment>>);

/// What the probe move waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seek {
    /// G38.2 / G38.3: the input turning on (contact).
    Contact,
    /// G38.4 / G38.5: the input turning off (contact lost).
    Release,
}

impl Seek {
    /// From the G-code number the interpreter names (`"38.2"` … `"38.5"`).
    pub fn of(code: &str) -> Option<Seek> {
        match code {
            "38.2" | "38.3" => Some(Seek::Contact),
            "38.4" | "38.5" => Some(Seek::Release),
            _ => None,
        }
    }

    /// Whether the input with the ball at `p` is what the move waits for.
    fn found(self, model: &ProbeModel, p: &Vec3) -> bool {
        model.touches(p) == (self == Seek::Contact)
    }
}

/// A probe move as run: its samples (up to rest) and the answer.
#[derive(Debug, Clone)]
pub struct ProbeRun {
    pub samples: Vec<Sampled>,
    pub outcome: ProbeOutcome,
    /// Where the input changed (tip, mm), when it did.
    pub trip: Option<Vec3>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ProbeError {
    #[error("line {line}: a probe move must move X, Y or Z")]
    NoLinearTravel { line: u32 },
    #[error("line {line}: the probe move's limits: {message}")]
    Limits { line: u32, message: String },
    #[error("line {line}: stopping after the trip: {source}")]
    Kinematics { line: u32, source: KinematicsError },
}

/// Runs a probe move whose planned `samples` (start to end, the machine at rest at both)
/// were taken at `period` s: cut where the probe input changes, then the stop.
pub fn run_probe_move(
    samples: Vec<Sampled>,
    model: &ProbeModel,
    seek: Seek,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> Result<ProbeRun, ProbeError> {
    let Some((first, segs)) = samples.first() else {
        return Ok(ProbeRun {
            samples,
            outcome: ProbeOutcome::Completed,
            trip: None,
        });
    };
    let line = first.line;
    let Some(seg) = segs.first().cloned() else {
        return Err(ProbeError::NoLinearTravel { line });
    };
    let start = first.tip;
    let end = samples.last().map_or(start, |s| s.0.tip);
    let length = (end - start).norm();
    if length <= 0.0 {
        return Err(ProbeError::NoLinearTravel { line });
    }
    if seek.found(model, &start) {
        return Ok(ProbeRun {
            samples: Vec::new(),
            outcome: ProbeOutcome::AlreadyThere,
            trip: None,
        });
    }
    // The input is read once a period, as a servo thread reads it.
    let Some(k) = samples.iter().position(|s| seek.found(model, &s.0.tip)) else {
        return Ok(ProbeRun {
            samples,
            outcome: ProbeOutcome::Completed,
            trip: None,
        });
    };
    let direction = (end - start) / length;
    let along = |p: &Vec3| (p - start).dot(&direction);
    let trip = samples[k].0;
    let s_trip = along(&trip.tip);
    let stop = path_stop(&samples, k, &seg, machine, options)?;
    let mut out: Vec<Sampled> = samples[..=k].to_vec();
    let (rotary_start, rotary_end) = (first.rotary, samples[samples.len() - 1].0.rotary);
    let mut joints = trip.joints.clone();
    let steps = (stop.duration() / options.period).ceil() as u64;
    let mut s_rest = s_trip;
    for i in 1..=steps {
        let t = i as f64 * options.period;
        let state = stop.at(t);
        let s = (s_trip + state.s).min(length);
        let f = s / length;
        let tip = start + direction * s;
        let rotary =
            std::array::from_fn(|r| rotary_start[r] + f * (rotary_end[r] - rotary_start[r]));
        joints = machine
            .joints(seg.control, &tip, &rotary, &joints)
            .map_err(|source| ProbeError::Kinematics { line, source })?;
        out.push((
            Sample {
                index: trip.index + i,
                t: trip.t + t,
                line,
                tip,
                rotary,
                joints: joints.clone(),
                feed: state.v,
            },
            vec![seg.clone()],
        ));
        s_rest = s;
    }
    Ok(ProbeRun {
        samples: out,
        outcome: ProbeOutcome::Tripped {
            at: s_trip / length,
            stopped: s_rest / length,
        },
        trip: Some(trip.tip),
    })
}

/// The fastest jerk-limited stop from the path state at sample `k`, under the limits that
/// keep every joint within its own on this segment ([`limits::segment_limits`]). The
/// acceleration at `k` is the central difference of the sampled speed (exact on the planned
/// profile's constant-jerk phases).
fn path_stop(
    samples: &[Sampled],
    k: usize,
    seg: &Segment,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> Result<PathStop, ProbeError> {
    let line = seg.line;
    let error = |message: String| ProbeError::Limits { line, message };
    let geometry = limits::analyse(seg, machine).map_err(|e| error(e.to_string()))?;
    let path = limits::segment_limits(seg, &geometry, machine, options, false)
        .map_err(|e| error(e.to_string()))?
        .limits;
    let (a_max, j_max) = (path.max_acceleration(), path.max_jerk());
    let feed = |i: usize| samples[i].0.feed;
    let (before, after) = (k.saturating_sub(1), (k + 1).min(samples.len() - 1));
    let a0 = if after > before {
        (feed(after) - feed(before)) / ((after - before) as f64 * options.period)
    } else {
        0.0
    };
    let v0 = feed(k);
    PathStop::new(v0, a0.clamp(-a_max, a_max), a_max, j_max)
        .or_else(|| PathStop::new(v0, 0.0, a_max, j_max))
        .ok_or_else(|| error(format!("no stop from {v0} mm/s")))
}
