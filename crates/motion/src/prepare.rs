//! A program's moves made ready for a machine, as `tezgah run` and `tezgah check --machine`
//! do it: smoothed into path items for the machine, then the pre-flight over the whole path.
//! Comes after the G-code interpreter; [`planned_time`] then plans the result as `run` does
//! (the planner's rule for joint jumps applies on the way), for callers that want the
//! machine's time without the samples (the CAM post-processor's own check).

use tezgah_geom::{Move, Pose, Vec3};
use tezgah_kinematics::{Joints, KinematicsError, Machine};

use crate::path::smooth::{self, PathError, SmoothOptions};
use crate::plan::{PlanError, PlanMachine, PlanOptions, Planned, Planner};
use crate::preflight::{check_path, PreflightError};
use crate::PathItem;

/// The path a machine will follow, checked whole before anything moves.
pub struct Prepared {
    pub items: Vec<PathItem>,
    pub pm: PlanMachine,
    /// The program pose the machine starts from.
    pub start: Pose,
    /// The largest angle between a corner blend's tool axis and the programmed one, degrees.
    pub max_axis_deviation_deg: f64,
    /// The angular tolerance the blends kept to, degrees.
    pub angular_tolerance_deg: f64,
}

/// Why a program's moves cannot be made ready for the machine. Lines are those the moves
/// carry.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PrepareError {
    #[error(transparent)]
    Machine(#[from] PlanError),
    #[error(transparent)]
    Path(#[from] PathError),
    #[error("the start pose: {0}")]
    Start(KinematicsError),
    #[error(transparent)]
    Preflight(#[from] PreflightError),
}

/// The program's moves smoothed for `machine` (G64 compresses and blends within its shares of
/// the tolerance, G61 keeps corners, G61.1 stops at every block end), then the pre-flight:
/// every segment within the machine's reach and joint limits, from the program pose `start`
/// (the joints there found by the inverse kinematics).
pub fn prepare(
    moves: Vec<Move>,
    machine: &Machine,
    tolerance: f64,
    start: Pose,
) -> Result<Prepared, PrepareError> {
    prepare_from(moves, machine, tolerance, start, None)
}

/// [`prepare`] for a machine whose joints stand at `joints` (the executor knows them; where
/// a pose has several inverses, the path is checked on the branch the machine is on), or at
/// the inverse kinematics' answer for `start` when `None`.
pub fn prepare_from(
    moves: Vec<Move>,
    machine: &Machine,
    tolerance: f64,
    start: Pose,
    joints: Option<Joints>,
) -> Result<Prepared, PrepareError> {
    let pm = PlanMachine::from_machine(machine)?;
    let opts = SmoothOptions::for_machine(&machine.path, &pm, tolerance, start);
    let mut smoother = smooth::Smoother::new(moves.into_iter(), opts.clone())?;
    let items = smoother.by_ref().collect::<Result<Vec<_>, _>>()?;
    let start_joints = match joints {
        Some(j) => j,
        None => {
            let (tip, rotary) = start_point(&start);
            pm.joints(pm.initial, &tip, &rotary, &Joints::zeros(pm.joint_count()))
                .map_err(PrepareError::Start)?
        }
    };
    check_path(&items, &pm, start_joints)?;
    Ok(Prepared {
        items,
        pm,
        start,
        max_axis_deviation_deg: smoother.stats().max_axis_deviation,
        angular_tolerance_deg: opts.angular_tolerance,
    })
}

/// The start pose as tip and A B C.
pub fn start_point(start: &Pose) -> (Vec3, [f64; 3]) {
    (
        Vec3::from(start.xyz()),
        [start.0[3], start.0[4], start.0[5]],
    )
}

/// The planner's options `tezgah run` uses at interpolation period `period` (s): the chord
/// error gets what compression and blending leave of the tolerance.
pub fn plan_options(period: f64) -> PlanOptions {
    PlanOptions {
        period,
        chord_share: smooth::CHORD_SHARE,
        ..PlanOptions::default()
    }
}

/// The machine's time for a prepared path by the planner alone, as `tezgah run` plans it
/// (same options, same look-ahead): the sum of the planned pieces' profiles and the dwells.
/// The interpolator then samples exactly these profiles, so `tezgah run`'s cycle differs
/// only by the sampling period per piece and the joint take-up moves at tool-centre-point
/// switches (0.07 % on issue 23's wavy patch); it costs a fraction of the interpolation
/// (joints every 0.5 mm instead of every period).
/// A joint jump (a path through a singular pose) is the planner's error, with its line.
pub fn planned_time(prepared: Prepared, period: f64) -> Result<f64, PlanError> {
    let mut planner = Planner::new(prepared.pm, plan_options(period))?;
    let mut total = 0.0;
    let mut add = |p: Planned| {
        if let Planned::Motion(piece) = p {
            total += piece.profile.duration();
        } else if let Planned::Dwell { seconds, .. } = p {
            total += seconds;
        }
    };
    for item in prepared.items {
        planner.push(item)?;
        while let Some(p) = planner.pop() {
            add(p);
        }
    }
    planner.finish()?;
    while let Some(p) = planner.pop() {
        add(p);
    }
    Ok(total)
}
