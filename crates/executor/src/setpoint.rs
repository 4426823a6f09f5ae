//! The set-point: what the executor hands the drives once per period (reference 000 §1.4's
//! 1 ms stream). Position, velocity and acceleration per joint, so a drive can feed forward;
//! internal units (mm, rad), machine-file joint order. Fixed size: it crosses the lock-free
//! ring into the real-time thread, which never allocates.

use tezgah_kinematics::Joints;

/// One period's command to every joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetPoint {
    /// Period index k; the set-point is due at t = k·Ts.
    pub index: u64,
    /// 1-based source line of the block being executed (0 outside a program: jog, home).
    pub line: u32,
    pub position: Joints,
    pub velocity: Joints,
    pub acceleration: Joints,
}

impl SetPoint {
    /// At rest at `position`.
    pub fn at_rest(index: u64, line: u32, position: Joints) -> SetPoint {
        let zero = Joints::zeros(position.len());
        SetPoint {
            index,
            line,
            position,
            velocity: zero,
            acceleration: zero,
        }
    }
}
