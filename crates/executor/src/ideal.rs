//! The ideal drive: measured = commanded, no following error. The executor's own tests run
//! on it; the simulated servo drive (`drive/`) stands in for a real one.

use tezgah_kinematics::Joints;

use crate::drive::{Drive, DriveStatus};
use crate::setpoint::SetPoint;

/// A drive that is exactly where it is told to be.
#[derive(Debug, Clone, Copy, Default)]
pub struct IdealDrive;

impl Drive for IdealDrive {
    fn apply(&mut self, setpoint: &SetPoint) -> DriveStatus {
        DriveStatus {
            position: setpoint.position,
            following_error: Joints::zeros(setpoint.position.len()),
            fault: None,
        }
    }
}
