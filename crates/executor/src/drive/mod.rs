//! The drive interface: the sink of set-points and the source of feedback, one call per period.
//! A real drive bus (EtherCAT, a step generator) implements it later; the simulated servo
//! drive implements it now so the executor can be tested end to end here.

use tezgah_kinematics::Joints;

use crate::setpoint::SetPoint;

/// What a drive reports back each period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveStatus {
    /// Measured joint positions (internal units).
    pub position: Joints,
    /// Commanded minus measured position per joint.
    pub following_error: Joints,
    /// A drive fault stops the machine; the executor reports it.
    pub fault: Option<DriveFault>,
}

/// Why a drive refused to go on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriveFault {
    /// A joint's following error exceeded its limit.
    FollowingError { joint: usize },
    /// The drive lost its link or power.
    Offline,
}

/// A set-point sink called from the real-time thread: implementations must not allocate,
/// lock or block.
pub trait Drive {
    /// Apply one period's set-point and return the status after it.
    fn apply(&mut self, setpoint: &SetPoint) -> DriveStatus;
}

pub mod ideal;
pub mod metrics;
pub mod servo;

pub use ideal::IdealDrive;
pub use metrics::{ContourError, ContourStats, JointTracking};
pub use servo::{ServoAxis, ServoDrive, ServoError, ServoParams};
