//! Manual motion: JOG (continuous, velocity mode), INC (fixed small steps) and HOME (the
//! homing sequence of the machine file). Each is a generator the executor's mode machine polls
//! once per period for the next [`SetPoint`](crate::SetPoint): jerk-limited, exact at every
//! period, no allocation per period. Set-points carry line 0 (outside a program).
//!
//! As in Kelekçi (2021, §4.1): JOG and HND run in velocity control, INC/HOME/REF in position
//! control; JOG defaults to 50 mm/s (linear) and 20 °/s (rotary); INC steps are 0.0001–0.1 mm; HOME
//! moves Z first.
//!
//! ```
//! use tezgah_executor::drive::{Drive, JointTracking, ServoDrive};
//! use tezgah_executor::manual::{jog::Direction, Jog};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let m = tezgah_kinematics::Machine::builtin("mill3")?;
//! let start = m.home();
//! let mut drive = ServoDrive::from_machine(&m, &start)?;
//! let mut jog = Jog::new(&m, 0, &start, Direction::Plus, 50.0, 0)?; // X+ at 50 mm/s
//! jog.set_override(tezgah_executor::Override::new(25.0)?);
//! let mut errors = JointTracking::new(3);
//! for sp in jog.by_ref().take(500) {
//!     errors.record(&drive.apply(&sp));
//! }
//! jog.stop(); // comes to rest in the jerk-limited minimum distance
//! let rest = jog.last().expect("a final set-point at rest");
//! assert_eq!(rest.velocity[0], 0.0);
//! # Ok(())
//! # }
//! ```

pub mod active;
pub mod home;
pub mod inc;
pub mod jog;

use std::f64::consts::PI;

use tezgah_kinematics::{JointKind, Machine};
use tezgah_motion::profile::Limits;
use thiserror::Error;

pub use home::{Home, HomeSwitches, SimulatedSwitches};
pub use inc::{Inc, IncStep};
pub use jog::Jog;

/// Why a manual move was refused or failed. Joints are 0-based machine-file indices; values
/// are in file units (mm or degrees).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ManualError {
    #[error("no joint {joint} (the machine has {count})")]
    NoSuchJoint { joint: usize, count: usize },
    #[error("start position has {given} joints, the machine {expected}")]
    JointCount { given: usize, expected: usize },
    #[error("start position of joint {joint} is {value}")]
    NotFinite { joint: usize, value: f64 },
    #[error("joint `{name}`: speed {value} must be > 0 and finite")]
    Speed { name: String, value: f64 },
    #[error("INC step {value} is outside {min}–{max} (file units)", min = inc::MIN_STEP, max = inc::MAX_STEP)]
    Step { value: f64 },
    #[error("joint `{name}`: {target} is beyond its soft limit {limit}")]
    BeyondLimit {
        name: String,
        target: f64,
        limit: f64,
    },
    #[error("joint `{name}`: the home switch was not found within {travel} of travel")]
    SwitchNotFound { name: String, travel: f64 },
    #[error("joint `{name}`: {reason}")]
    Motion { name: String, reason: String },
}

/// Default JOG speed of Kelekçi (2021, §4.1): 50 mm/s linear, 20 °/s rotary (file units).
pub fn default_jog_speed(kind: JointKind) -> f64 {
    match kind {
        JointKind::Linear => 50.0,
        JointKind::Rotary => 20.0,
    }
}

/// One joint as manual motion sees it, in internal units (mm or rad).
#[derive(Debug, Clone, PartialEq)]
pub struct JointAxis {
    pub name: String,
    pub kind: JointKind,
    /// Soft limits (±∞ for an endless rotary).
    pub min: f64,
    pub max: f64,
    pub max_velocity: f64,
    pub max_acceleration: f64,
    pub max_jerk: f64,
    /// File units per internal unit (1, or 180/π for a rotary joint).
    pub to_file: f64,
}

impl JointAxis {
    /// Joint `joint` of `machine`.
    pub fn from_machine(machine: &Machine, joint: usize) -> Result<JointAxis, ManualError> {
        let j = machine.joints.get(joint).ok_or(ManualError::NoSuchJoint {
            joint,
            count: machine.joints.len(),
        })?;
        let s = j.to_internal();
        Ok(JointAxis {
            name: j.name.clone(),
            kind: j.kind,
            min: j.min * s,
            max: j.max * s,
            max_velocity: j.max_velocity * s,
            max_acceleration: j.max_acceleration * s,
            max_jerk: j.max_jerk * s,
            to_file: match j.kind {
                JointKind::Linear => 1.0,
                JointKind::Rotary => 180.0 / PI,
            },
        })
    }

    /// The joint's limits for the profile solver (JOG, homing, stops).
    pub fn limits(&self) -> Result<Limits, ManualError> {
        Limits::new(self.max_velocity, self.max_acceleration, self.max_jerk).map_err(|e| {
            ManualError::Motion {
                name: self.name.clone(),
                reason: e.to_string(),
            }
        })
    }

    /// A speed given in file units, checked and capped at the joint's limit (internal units).
    pub fn speed(&self, file_units: f64) -> Result<f64, ManualError> {
        if !(file_units.is_finite() && file_units > 0.0) {
            return Err(ManualError::Speed {
                name: self.name.clone(),
                value: file_units,
            });
        }
        Ok((file_units / self.to_file).min(self.max_velocity))
    }

    fn beyond(&self, target: f64, limit: f64) -> ManualError {
        ManualError::BeyondLimit {
            name: self.name.clone(),
            target: target * self.to_file,
            limit: limit * self.to_file,
        }
    }
}

/// A start position with one finite value per joint of `machine`.
fn check_start(machine: &Machine, start: &tezgah_kinematics::Joints) -> Result<(), ManualError> {
    if start.len() != machine.joints.len() {
        return Err(ManualError::JointCount {
            given: start.len(),
            expected: machine.joints.len(),
        });
    }
    match start.as_slice().iter().position(|v| !v.is_finite()) {
        Some(joint) => Err(ManualError::NotFinite {
            joint,
            value: start[joint],
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use tezgah_kinematics::Joints;

    use crate::setpoint::SetPoint;

    /// Joint `joint`'s positions, led by the start at rest (and the rest before it).
    pub fn positions(start: &Joints, sps: &[SetPoint], joint: usize) -> Vec<f64> {
        let mut x = vec![start[joint]; 3];
        x.extend(sps.iter().map(|s| s.position[joint]));
        let last = *x.last().unwrap_or(&start[joint]);
        x.extend([last; 3]);
        x
    }

    /// Backward differences at the period against the limits. For a piecewise-cubic motion
    /// sampled exactly, the k-th difference over Ts^k is a B-spline-weighted mean of the k-th
    /// derivative over k periods, so it can never exceed the derivative's bound.
    pub fn check_limits(x: &[f64], ts: f64, v: f64, a: f64, j: f64) -> Result<(), String> {
        let d1: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
        let d2: Vec<f64> = d1.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
        let d3: Vec<f64> = d2.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
        // Rounding of the positions (a few ulps) is amplified 2^k/Ts^k by the k-th difference;
        // the solvers meet their limits to ~1e-10 relative.
        let ulps = 16.0 * f64::EPSILON * x.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
        for (k, (name, d, lim)) in [
            ("velocity", &d1, v),
            ("acceleration", &d2, a),
            ("jerk", &d3, j),
        ]
        .into_iter()
        .enumerate()
        {
            let slack = lim * 1e-9 + ulps * (2.0 / ts).powi(k as i32 + 1);
            if let Some((i, val)) = d.iter().enumerate().find(|(_, x)| x.abs() > lim + slack) {
                return Err(format!("{name} {val} > {lim} at difference {i}"));
            }
        }
        Ok(())
    }
}
