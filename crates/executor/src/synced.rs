//! A spindle-synchronised move (G33 threading, G33.1 rigid tapping) played period by period
//! against a simulated spindle with inertia, as LinuxCNC's trajectory planner runs it in
//! position mode (`tpSyncPositionMode`, `tp.c`): the move waits for the spindle's index,
//! accelerates until its speed matches pitch × spindle speed, then locks its position to the
//! spindle's angle — the offset taken at the lock is the same on every pass, so repeated
//! passes cut the same thread. Locked, the path speed is the spindle's speed times the pitch
//! plus a correction of the position error; every step is the jerk-limited velocity change of
//! the one profile solver under the line's path limits, so the joints stay within theirs and
//! the error is what following a spindle that changes speed costs. A thread leaves the spindle
//! where the stop still fits before its end and stops there; a rigid tap reverses the spindle
//! at depth and follows it back (LinuxCNC's TAPPING → REVERSING → RETRACTION →
//! FINAL_REVERSAL → FINAL_PLACEMENT), overshooting the depth by what the spindle turns while
//! it reverses.

use std::sync::Arc;

use tezgah_geom::{Pose, SyncedMove, Vec3};
use tezgah_kinematics::spindle::SpindleModel;
use tezgah_kinematics::Joints;
use tezgah_motion::interpolate::Sample;
use tezgah_motion::plan::{limits, PlanMachine, PlanOptions};
use tezgah_motion::profile::{reach_velocity, solve_from, stopping_displacement};
use tezgah_motion::{Limits, Profile, Segment, State};

use crate::probe::Sampled;

/// The spindle: its angle (revolutions), speed (rev/s) and the speed it is told to run at.
#[derive(Debug, Clone, Copy)]
pub struct Spindle {
    pub angle: f64,
    pub speed: f64,
    pub command: f64,
    model: SpindleModel,
}

impl Spindle {
    /// Turning steadily at `speed` rev/s, at `angle`.
    pub fn steady(model: SpindleModel, speed: f64, angle: f64) -> Spindle {
        Spindle {
            angle,
            speed,
            command: speed,
            model,
        }
    }

    /// One step of `dt` s: the speed approaches the command as a first-order lag, at most
    /// `max_acceleration` (the drive's torque over the rotor's inertia); the angle integrates
    /// the speed exactly over the step (constant acceleration in it).
    pub fn step(&mut self, dt: f64) {
        let m = &self.model;
        let wanted = (self.command - self.speed) / m.time_constant;
        let mut acc = wanted.clamp(-m.max_acceleration, m.max_acceleration);
        // The lag never carries the speed past the command within a step.
        if (self.command - self.speed).abs() <= (acc * dt).abs() {
            acc = (self.command - self.speed) / dt;
        }
        self.angle += self.speed * dt + 0.5 * acc * dt * dt;
        self.speed += acc * dt;
    }
}

/// What the run of a synchronised move measured.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SyncFigures {
    /// The largest |tool position − pitch × spindle angle − offset| while locked, mm.
    pub max_error: f64,
    /// The lead measured over the locked stretch going in (mm run / revolutions turned),
    /// mm/rev.
    pub lead: f64,
    /// Waiting for the spindle's index, s.
    pub index_wait: f64,
    /// From the index to the lock (matching speeds), s.
    pub lock_after: f64,
    /// Rigid tap: how far past the programmed depth the tool went while the spindle reversed, mm.
    pub overshoot: Option<f64>,
    /// Rigid tap: how far past the start (away from the hole) the tool went while the spindle
    /// turned forward again, before the final placement, mm.
    pub overshoot_back: Option<f64>,
    /// The whole move, s.
    pub duration: f64,
}

/// A synchronised move as run: its samples (from the first period to rest) and figures.
#[derive(Debug, Clone)]
pub struct SyncRun {
    pub samples: Vec<Sampled>,
    pub figures: SyncFigures,
}

/// Why a synchronised move could not be run (the caller knows which move it was).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SyncError {
    #[error("G33/G33.1 need a K (pitch) above 0, not {0} mm/rev")]
    Pitch(f64),
    #[error("G33/G33.1 need the spindle turning (S above 0)")]
    SpindleStopped,
    #[error("G33/G33.1 must move X, Y or Z")]
    NoLinearTravel,
    #[error("the move's limits: {0}")]
    Limits(String),
    #[error("the spindle never carried the move to its end within {0} s")]
    Unfinished(f64),
    #[error("kinematics: {0}")]
    Kinematics(String),
}

/// Where the move is in LinuxCNC's sequence.
// One value for the whole move, on the stack: the profile's size costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// At rest, waiting for the spindle's index (the angle crossing a whole revolution).
    Index,
    /// Accelerating to pitch × spindle speed; `index` the angle where the index came.
    Match { index: f64 },
    /// Following the spindle's angle: the position wanted is pitch × (angle − index) + offset.
    Locked {
        index: f64,
        offset: f64,
        stage: Stage,
    },
    /// Unsynchronised to rest at the end (a thread's end, a tap's final placement).
    Finish { profile: Profile, t: f64 },
}

/// A rigid tap's stages while locked (a thread has only `Forward`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stage {
    Forward,
    /// Spindle told to reverse at depth; following it through the turn and back to the start.
    Retracting,
    /// Back at the start, the spindle told to turn forward again; following it till it does.
    FinalReversal,
}

/// The longest a synchronised move may take before it is called stuck, s.
const MAX_DURATION: f64 = 3600.0;

/// Runs `mv` from `start` (the machine at rest there with `joints`) along `path.0`, its path
/// (a straight feed to `mv.end`; a tap's way back along `path.1`, the feed back to `start`),
/// with the spindle turning at `rpm` at angle `phase` (rev). Samples are numbered from 1 at
/// `options.period`, each with the segment it lies on.
#[allow(clippy::too_many_arguments)]
pub fn run_synced(
    path: (&Arc<Segment>, &Arc<Segment>),
    mv: &SyncedMove,
    start: Pose,
    rpm: f64,
    phase: f64,
    model: SpindleModel,
    machine: &PlanMachine,
    options: &PlanOptions,
    joints: Joints,
) -> Result<SyncRun, SyncError> {
    let pitch = mv.pitch;
    if !(pitch > 0.0 && pitch.is_finite()) {
        return Err(SyncError::Pitch(pitch));
    }
    let speed = rpm / 60.0;
    if !(speed > 0.0 && speed.is_finite()) {
        return Err(SyncError::SpindleStopped);
    }
    let (a, b) = (Vec3::from(start.xyz()), Vec3::from(mv.end.xyz()));
    let length = (b - a).norm();
    if length <= 0.0 {
        return Err(SyncError::NoLinearTravel);
    }
    // At the spindle's speed the move would outlast the bound: say so before simulating it.
    if length / (pitch * speed) > MAX_DURATION {
        return Err(SyncError::Unfinished(MAX_DURATION));
    }
    let direction = (b - a) / length;
    let (seg, back) = path;
    let path = path_limits(seg, machine, options)?;
    let (a_max, j_max) = (path.max_acceleration(), path.max_jerk());
    // The position loop's gain (1/s): slow enough that the jerk-limited velocity steps settle
    // within it (A/J is the time to build up acceleration).
    let gain = 0.5 * j_max / a_max;
    let period = options.period;
    let mut spindle = Spindle::steady(model, speed, phase);
    let mut x = State {
        s: 0.0,
        v: 0.0,
        a: 0.0,
        j: 0.0,
    };
    let mut phase = Phase::Index;
    let mut figures = SyncFigures::default();
    let mut locked_from: Option<(f64, f64)> = None;
    let mut locked_to = (0.0, 0.0);
    let (mut deepest, mut shallowest) = (0.0f64, 0.0f64);
    let mut samples = Vec::new();
    let mut q = joints;
    let mut k: u64 = 0;
    loop {
        k += 1;
        let t = k as f64 * period;
        if t > MAX_DURATION {
            return Err(SyncError::Unfinished(MAX_DURATION));
        }
        let before = spindle.angle;
        spindle.step(period);
        let mut done = false;
        match phase {
            Phase::Index => {
                figures.index_wait = t;
                if spindle.angle.floor() > before.floor() {
                    phase = Phase::Match {
                        index: spindle.angle.floor(),
                    };
                }
            }
            Phase::Match { index } => {
                let profile = velocity_step(&x, pitch * spindle.speed, &path)?;
                x = at(&profile, period);
                figures.lock_after = t - figures.index_wait;
                if profile.duration() <= period {
                    let offset = x.s - pitch * (spindle.angle - index);
                    locked_from = Some((x.s, spindle.angle));
                    phase = Phase::Locked {
                        index,
                        offset,
                        stage: Stage::Forward,
                    };
                }
            }
            Phase::Locked {
                index,
                offset,
                stage,
            } => {
                let wanted = |angle: f64| pitch * (angle - index) + offset;
                // Both at the start of the step.
                let error = wanted(before) - x.s;
                // LinuxCNC corrects with √(2A|e|); the gain keeps the jerk-limited loop calm
                // for small errors.
                let correction =
                    error.signum() * (gain * error.abs()).min((a_max * error.abs()).sqrt());
                let target = (pitch * spindle.speed + correction)
                    .clamp(-path.max_velocity(), path.max_velocity());
                let profile = velocity_step(&x, target, &path)?;
                x = at(&profile, period);
                figures.max_error = figures.max_error.max((wanted(spindle.angle) - x.s).abs());
                // The lead is measured going in (a tap's way back has its own speed).
                if stage == Stage::Forward {
                    locked_to = (x.s, spindle.angle);
                }
                deepest = deepest.max(x.s);
                shallowest = shallowest.min(x.s);
                let next = match (mv.tap, stage) {
                    (None, _) => {
                        // A thread leaves the spindle where the stop still fits before its end.
                        let stop = stopping_displacement(x, &path).unwrap_or(0.0);
                        (x.s + stop + x.v.abs() * period >= length)
                            .then(|| finish(&x, length, &path))
                    }
                    (Some(scale), Stage::Forward) if x.s >= length => {
                        spindle.command = -speed * scale;
                        Some(Ok(Phase::Locked {
                            index,
                            offset,
                            stage: Stage::Retracting,
                        }))
                    }
                    (Some(_), Stage::Retracting) if x.s <= 0.0 && spindle.speed < 0.0 => {
                        spindle.command = speed;
                        Some(Ok(Phase::Locked {
                            index,
                            offset,
                            stage: Stage::FinalReversal,
                        }))
                    }
                    (Some(_), Stage::FinalReversal) if spindle.speed >= 0.0 => {
                        Some(finish(&x, 0.0, &path))
                    }
                    _ => None,
                };
                if let Some(next) = next {
                    phase = next?;
                }
            }
            Phase::Finish { profile, t: tp } => {
                let tp = tp + period;
                let st = profile.state_at(tp);
                x = State { j: 0.0, ..st };
                if tp >= profile.duration() {
                    done = true;
                } else {
                    phase = Phase::Finish { profile, t: tp };
                }
            }
        }
        let f = x.s / length;
        let tip = a + direction * x.s;
        let rotary =
            std::array::from_fn(|r| start.0[3 + r] + f * (mv.end.0[3 + r] - start.0[3 + r]));
        q = machine
            .joints(seg.control, &tip, &rotary, &q)
            .map_err(|e| SyncError::Kinematics(e.to_string()))?;
        // A tap's way back lies on the feed back (the same line, run the other way).
        let on = match phase {
            Phase::Locked {
                stage: Stage::Forward,
                ..
            }
            | Phase::Index
            | Phase::Match { .. } => seg,
            _ if mv.tap.is_some() => back,
            _ => seg,
        };
        samples.push((
            Sample {
                index: k,
                t,
                line: seg.line,
                tip,
                rotary,
                joints: q,
                feed: if done { 0.0 } else { x.v.abs() },
            },
            vec![on.clone()],
        ));
        if done {
            figures.duration = t;
            break;
        }
    }
    if let Some((s0, angle0)) = locked_from {
        let turned = locked_to.1 - angle0;
        if turned.abs() > 0.0 {
            figures.lead = (locked_to.0 - s0) / turned;
        }
    }
    if mv.tap.is_some() {
        figures.overshoot = Some(deepest - length);
        figures.overshoot_back = Some(-shallowest);
    }
    Ok(SyncRun { samples, figures })
}

/// The path speed, acceleration and jerk that keep every joint within its limits on `seg`.
fn path_limits(
    seg: &Segment,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> Result<Limits, SyncError> {
    let error = |e: tezgah_motion::plan::PlanError| SyncError::Limits(e.to_string());
    let geometry = limits::analyse(seg, machine).map_err(error)?;
    Ok(
        limits::segment_limits(seg, &geometry, machine, options, false)
            .map_err(error)?
            .limits,
    )
}

/// The jerk-limited change from `x` toward path speed `target` (the solver's velocity
/// interface).
fn velocity_step(x: &State, target: f64, path: &Limits) -> Result<Profile, SyncError> {
    reach_velocity(*x, target, path).map_err(|e| SyncError::Limits(e.to_string()))
}

/// The state `dt` into `profile` (jerk left out: the next step starts a profile of its own).
fn at(profile: &Profile, dt: f64) -> State {
    State {
        j: 0.0,
        ..profile.state_at(dt)
    }
}

/// Leaves the spindle: the time-optimal move from `x` to rest at path coordinate `to`.
fn finish(x: &State, to: f64, path: &Limits) -> Result<Phase, SyncError> {
    let profile =
        solve_from(*x, to - x.s, 0.0, path).map_err(|e| SyncError::Limits(e.to_string()))?;
    Ok(Phase::Finish { profile, t: 0.0 })
}
