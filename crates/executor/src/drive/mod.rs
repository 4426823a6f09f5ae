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
    /// A drive on a bus reported a fault: its error code (CiA 402 object 0x603F) and the
    /// code's text.
    Drive {
        joint: usize,
        code: u16,
        text: &'static str,
    },
    /// A bus cycle got no answer in time: a frame lost or the link down.
    LostFrame,
    /// A bus cycle's working counter was wrong: a drive did not take part.
    WorkingCounter { expected: u16, got: u16 },
}

impl std::fmt::Display for DriveFault {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            DriveFault::FollowingError { joint } => {
                write!(f, "joint {joint}: following error beyond its limit")
            }
            DriveFault::Offline => f.write_str("drive offline (link or power lost)"),
            DriveFault::Drive { joint, code, text } => {
                write!(f, "joint {joint}: drive error {code:#06x}: {text}")
            }
            DriveFault::LostFrame => f.write_str("bus frame lost (no answer within the cycle)"),
            DriveFault::WorkingCounter { expected, got } => write!(
                f,
                "bus working counter {got}, expected {expected}: a drive did not answer"
            ),
        }
    }
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
