//! `tezgah run --drive servo`: every planned sample goes, as the executor would send it
//! (position, and velocity and acceleration by backward differences), through the simulated
//! servo drive of the machine file (`tezgah_executor::drive::servo`); the report gives the
//! tracking errors as Kelekçi (2021, eq. 5.1) does: per joint RMSE and largest following
//! error, and the contour error (distance of the actual tip from the commanded path).

use tezgah_executor::drive::{ContourError, ContourStats, Drive, JointTracking, ServoDrive};
use tezgah_executor::{DriveFault, SetPoint};
use tezgah_kinematics::{Joints, Kinematics, Machine, Model, Tool};
use tezgah_motion::interpolate::Sample;

/// Which drive the samples go to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum DriveKind {
    /// Measured = commanded: no tracking figures.
    #[default]
    Ideal,
    /// The machine file's `[joint.servo]` model.
    Servo,
}

/// The servo drive and its metrics, fed one sample at a time.
pub struct Tracker {
    drive: ServoDrive,
    model: Model,
    period: f64,
    joints: JointTracking,
    contour: ContourError,
    prev: Joints,
    prev_velocity: Joints,
    fault: Option<TrackingFault>,
}

/// The drive's first fault.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackingFault {
    pub t: f64,
    pub line: u32,
    pub fault: DriveFault,
}

/// What the report shows (internal units: mm or rad per joint).
#[derive(Debug, Clone, PartialEq)]
pub struct Tracking {
    pub rmse: Vec<f64>,
    pub max: Vec<f64>,
    pub contour: ContourStats,
    pub fault: Option<TrackingFault>,
}

impl Tracker {
    /// A servo drive for `machine` standing at `start` (the first sample's joints) and taking
    /// a set-point every `period` s.
    pub fn new(
        machine: &Machine,
        model: Model,
        period: f64,
        start: Joints,
    ) -> Result<Self, String> {
        let params: Vec<_> = machine
            .joints
            .iter()
            .map(|j| tezgah_executor::drive::ServoParams::from_settings(&j.servo, j.kind))
            .collect();
        let drive = ServoDrive::new(&params, period, &start).map_err(|e| e.to_string())?;
        let n = start.len();
        Ok(Tracker {
            drive,
            model,
            period,
            joints: JointTracking::new(n),
            contour: ContourError::default(),
            prev: start,
            prev_velocity: Joints::zeros(n),
            fault: None,
        })
    }

    /// One sample (the interpolator's row 0, the start at rest, included: it sets nothing
    /// moving and is measured like the others).
    pub fn push(&mut self, s: &Sample) {
        let q = s.joints;
        let mut velocity = q;
        let mut acceleration = q;
        for i in 0..q.len() {
            velocity[i] = (q[i] - self.prev[i]) / self.period;
            acceleration[i] = (velocity[i] - self.prev_velocity[i]) / self.period;
        }
        self.prev = q;
        self.prev_velocity = velocity;
        let sp = SetPoint {
            index: s.index,
            line: s.line,
            position: q,
            velocity,
            acceleration,
        };
        let status = self.drive.apply(&sp);
        if let (None, Some(fault)) = (self.fault, status.fault) {
            self.fault = Some(TrackingFault {
                t: s.t,
                line: s.line,
                fault,
            });
        }
        self.joints.record(&status);
        let tool = Tool::default();
        if let (Ok(c), Ok(a)) = (
            self.model.forward(&q, &tool),
            self.model.forward(&status.position, &tool),
        ) {
            self.contour.push(c.tip, a.tip);
        }
    }

    pub fn finish(mut self) -> Tracking {
        let n = self.prev.len();
        Tracking {
            rmse: (0..n).map(|i| self.joints.rmse(i)).collect(),
            max: (0..n).map(|i| self.joints.max(i)).collect(),
            contour: self.contour.finish(),
            fault: self.fault,
        }
    }
}
