//! The ideal drive: the measured position is the commanded one, with no following error. The
//! executor's tests use it where only the set-point stream matters, and it is the baseline the
//! servo model's errors are measured against.

use super::{Drive, DriveStatus};
use crate::setpoint::SetPoint;

/// A drive that is always exactly where it was told to be.
#[derive(Debug, Clone, Copy, Default)]
pub struct IdealDrive;

impl Drive for IdealDrive {
    fn apply(&mut self, setpoint: &SetPoint) -> DriveStatus {
        DriveStatus {
            position: setpoint.position,
            following_error: tezgah_kinematics::Joints::zeros(setpoint.position.len()),
            fault: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_kinematics::Joints;

    #[test]
    fn measured_is_commanded() {
        let s = SetPoint::at_rest(3, 7, Joints::new([1.0, -2.0, 3.5]));
        let st = IdealDrive.apply(&s);
        assert_eq!(st.position, s.position);
        assert!(st.following_error.as_slice().iter().all(|e| *e == 0.0));
        assert_eq!(st.following_error.len(), 3);
    }
}
