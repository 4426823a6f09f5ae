//! One probe move (G38.2–G38.5) on the simulated probe: the move is planned and sampled to its
//! end as any feed, then replayed period by period against the probe model; at the first
//! sample where the input has changed the trip position is taken and the machine stops along
//! the line with the jerk-limited path stop ([`path_stop`]) under the move's path limits, so
//! every joint stays within its limits. The answer goes back to the interpreter as fractions
//! of the move ([`ProbeOutcome`]), which then reads on from where the machine came to rest.

use std::sync::Arc;

use tezgah_gcode::ProbeOutcome;
use tezgah_geom::Vec3;
use tezgah_kinematics::probe::ProbeModel;
use tezgah_kinematics::KinematicsError;
use tezgah_motion::interpolate::Sample;
use tezgah_motion::plan::{limits, PlanMachine, PlanOptions};
use tezgah_motion::tool_pose::SampleTool;
use tezgah_motion::{Profile, Segment, State};

use crate::stop::path_stop;

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
    pub fn found(self, model: &ProbeModel, p: &Vec3) -> bool {
        model.touches(p) == (self == Seek::Contact)
    }
}

/// A probe move as run: its samples (up to rest) and the answer.
#[derive(Debug, Clone)]
pub struct ProbeRun {
    pub samples: Vec<Sampled>,
    pub outcome: ProbeOutcome,
    /// Where the input changed (the tool tip, workpiece frame, mm), when it did.
    pub trip: Option<Vec3>,
}

/// Why a probe move could not be run (the caller knows which move it was).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ProbeError {
    #[error("a probe move must move X, Y or Z")]
    NoLinearTravel,
    #[error("the probe move's limits: {0}")]
    Limits(String),
    #[error("stopping after the trip: {0}")]
    Kinematics(KinematicsError),
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
        return Err(ProbeError::NoLinearTravel);
    };
    let start = first.tip;
    let end = samples.last().map_or(start, |s| s.0.tip);
    let length = (end - start).norm();
    if length <= 0.0 {
        return Err(ProbeError::NoLinearTravel);
    }
    // The probe touches with the tool as the joints hold it (with G43's length taken off the
    // gauge point the moves carry), not with the program point.
    let mut tool = SampleTool::new(machine);
    let mut tip = |s: &Sampled| tool.pose(&s.0, &s.1).map(|p| p.tip);
    if seek.found(model, &tip(&samples[0]).map_err(ProbeError::Kinematics)?) {
        return Ok(ProbeRun {
            samples: Vec::new(),
            outcome: ProbeOutcome::AlreadyThere,
            trip: None,
        });
    }
    // The input is read once a period, as a servo thread reads it.
    let mut found = None;
    for (i, s) in samples.iter().enumerate() {
        let p = tip(s).map_err(ProbeError::Kinematics)?;
        if seek.found(model, &p) {
            found = Some((i, p));
            break;
        }
    }
    let Some((k, tool_tip)) = found else {
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
    let stop = stop_at(&samples, k, &seg, machine, options)?;
    let mut out: Vec<Sampled> = samples[..=k].to_vec();
    let (rotary_start, rotary_end) = (first.rotary, samples[samples.len() - 1].0.rotary);
    let mut joints = trip.joints;
    let steps = (stop.duration() / options.period).ceil() as u64;
    let mut s_rest = s_trip;
    for i in 1..=steps {
        let t = i as f64 * options.period;
        let state = stop.state_at(t);
        let s = (s_trip + state.s).min(length);
        let f = s / length;
        let tip = start + direction * s;
        let rotary =
            std::array::from_fn(|r| rotary_start[r] + f * (rotary_end[r] - rotary_start[r]));
        joints = machine
            .joints(seg.control, &tip, &rotary, &joints)
            .map_err(ProbeError::Kinematics)?;
        out.push((
            Sample {
                index: trip.index + i,
                t: trip.t + t,
                line,
                tip,
                rotary,
                joints,
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
        trip: Some(tool_tip),
    })
}

/// The fastest jerk-limited stop from the path state at sample `k`, under the limits that
/// keep every joint within its own on this segment ([`limits::segment_limits`]). The
/// acceleration at `k` is the central difference of the sampled speed (exact on the planned
/// profile's constant-jerk phases).
fn stop_at(
    samples: &[Sampled],
    k: usize,
    seg: &Segment,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> Result<Profile, ProbeError> {
    let error = ProbeError::Limits;
    let geometry = limits::analyse(seg, machine).map_err(|e| error(e.to_string()))?;
    let path = limits::segment_limits(seg, &geometry, machine, options, false)
        .map_err(|e| error(e.to_string()))?
        .limits;
    let a_max = path.max_acceleration();
    let feed = |i: usize| samples[i].0.feed;
    let (before, after) = (k.saturating_sub(1), (k + 1).min(samples.len() - 1));
    let a0 = if after > before {
        (feed(after) - feed(before)) / ((after - before) as f64 * options.period)
    } else {
        0.0
    };
    let v0 = feed(k);
    let from = |a: f64| State {
        s: 0.0,
        v: v0,
        a,
        j: 0.0,
    };
    path_stop(&from(a0.clamp(-a_max, a_max)), &path)
        .or_else(|| path_stop(&from(0.0), &path))
        .ok_or_else(|| error(format!("no stop from {v0} mm/s")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use tezgah_geom::{Move, MoveKind, Pose};
    use tezgah_kinematics::probe::Solid;
    use tezgah_kinematics::Machine;
    use tezgah_motion::path::smooth::{self, SmoothOptions};

    /// A straight feed from `start` to `end` at `feed` mm/min on mill3, planned and sampled
    /// whole at 1 ms, then run against `model`.
    fn probe_on_mill3(
        start: Vec3,
        end: Vec3,
        feed: f64,
        model: &ProbeModel,
        seek: Seek,
    ) -> (ProbeRun, Machine) {
        let machine = Machine::default_machine();
        let pm = PlanMachine::from_machine(&machine).unwrap();
        let pose = |p: Vec3| Pose([p.x, p.y, p.z, 0.0, 0.0, 0.0]);
        let opts = SmoothOptions::for_machine(&machine.path, &pm, 0.01, pose(start));
        let moves = [
            Move {
                line: 1,
                kind: MoveKind::FeedRate { value: feed },
            },
            Move {
                line: 2,
                kind: MoveKind::Feed { end: pose(end) },
            },
        ];
        let items = smooth::build(moves, &opts).unwrap();
        let options = PlanOptions {
            period: 0.001,
            ..PlanOptions::default()
        };
        let mut samples = Vec::new();
        tezgah_motion::interpolate::run(items, pm.clone(), options, (start, [0.0; 3]), |s, seg| {
            samples.push((*s, seg.to_vec()))
        })
        .unwrap();
        let run = run_probe_move(samples, model, seek, &pm, &options).unwrap();
        (run, machine)
    }

    /// Every joint's speed, acceleration and jerk by finite differences of the samples at the
    /// period (the run's verifier, `tezgah_motion::verify::Verifier`) within 0.5 % of its
    /// limits.
    fn assert_within_limits(run: &ProbeRun, machine: &Machine) {
        let pm = PlanMachine::from_machine(machine).unwrap();
        let mut verifier = tezgah_motion::verify::Verifier::new(&pm, 0.001);
        for (s, _) in &run.samples {
            verifier.push(s, &[]);
        }
        for (joint, peaks) in machine.joints.iter().zip(verifier.finish().joints) {
            assert!(peaks.worst_ratio() <= 1.005, "{} {peaks:?}", joint.name);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Down onto the plane z = h with a ball of radius r: the trip is the first sample at
        /// or below z = h + r (so at most one period's travel past it), the machine comes to
        /// rest below it within the joints' limits, and the fractions place both on the move.
        #[test]
        fn a_z_probe_trips_within_a_period_of_the_contact(
            h in -40.0..0.0f64,
            r in 0.0..5.0f64,
            above in 0.05..15.0f64,
            feed in 30.0..3000.0f64,
        ) {
            let model = ProbeModel {
                tool_radius: r,
                solids: vec![Solid::HalfSpace {
                    point: Vec3::new(0.0, 0.0, h),
                    normal: Vec3::z(),
                }],
            };
            let start = Vec3::new(5.0, -3.0, h + r + above);
            let end = Vec3::new(5.0, -3.0, h - 10.0);
            let (run, machine) = probe_on_mill3(start, end, feed, &model, Seek::Contact);
            let trip = run.trip.unwrap();
            let contact = h + r;
            prop_assert!(trip.z <= contact + 1e-12);
            prop_assert!(trip.z > contact - feed / 60.0 * 0.001 - 1e-9, "{} vs {contact}", trip.z);
            let ProbeOutcome::Tripped { at, stopped } = run.outcome else {
                panic!("{:?}", run.outcome)
            };
            let length = start.z - end.z;
            prop_assert!((start.z - at * length - trip.z).abs() < 1e-9);
            let rest = run.samples.last().unwrap().0;
            prop_assert!((start.z - stopped * length - rest.tip.z).abs() < 1e-9);
            prop_assert!(rest.tip.z < trip.z && rest.feed == 0.0);
            assert_within_limits(&run, &machine);
        }
    }

    /// Off a box's −X face (x = 20, ball 3): G38.4 from inside the contact trips as the ball
    /// leaves it, at x < 17 within a period's travel; a move that never changes the input
    /// completes; one that starts in the sought state is answered at once.
    #[test]
    fn release_completion_and_a_probe_already_there() {
        let model = ProbeModel {
            tool_radius: 3.0,
            solids: vec![Solid::Box {
                min: Vec3::new(20.0, -10.0, -30.0),
                max: Vec3::new(40.0, 10.0, 0.0),
            }],
        };
        let z = -5.0;
        let (run, machine) = probe_on_mill3(
            Vec3::new(18.0, 0.0, z),
            Vec3::new(0.0, 0.0, z),
            100.0,
            &model,
            Seek::Release,
        );
        let trip = run.trip.unwrap();
        assert!(
            trip.x < 17.0 && trip.x >= 17.0 - 100.0 / 60.0 * 0.001,
            "{trip:?}"
        );
        assert_within_limits(&run, &machine);
        let (run, _) = probe_on_mill3(
            Vec3::new(0.0, 0.0, z),
            Vec3::new(10.0, 0.0, z),
            300.0,
            &model,
            Seek::Contact,
        );
        assert_eq!((run.outcome, run.trip), (ProbeOutcome::Completed, None));
        assert_eq!(run.samples.last().unwrap().0.tip, Vec3::new(10.0, 0.0, z));
        let (run, _) = probe_on_mill3(
            Vec3::new(0.0, 0.0, z),
            Vec3::new(10.0, 0.0, z),
            300.0,
            &model,
            Seek::Release,
        );
        assert_eq!(run.outcome, ProbeOutcome::AlreadyThere);
        assert!(run.samples.is_empty());
    }
}
