//! Which G-code letter carries which joint in the written program, and in which unit.
//!
//! A controller without kinematics knows only its axis letters. Joints named by one axis
//! letter (a trunnion's `x y z a c`) keep their names; any other machine (a delta's `q1 q2 q3`)
//! gets letters by joint order as grblHAL assigns its axes: X Y Z, then A B C, then U V W.

use tezgah_kinematics::{JointKind, Machine};

use crate::ExportError;

/// grblHAL's axis order (`N_AXIS` up to 9).
pub const GRBLHAL_ORDER: [char; 9] = ['X', 'Y', 'Z', 'A', 'B', 'C', 'U', 'V', 'W'];

/// The letter and unit of each joint, in the machine's joint order.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisLetters {
    /// One upper-case letter per joint.
    pub letters: Vec<char>,
    /// Internal value (mm, rad) × this = the written value (mm, degrees).
    pub scale: Vec<f64>,
}

impl AxisLetters {
    /// The joint names as letters when every name is one distinct axis letter, else grblHAL's
    /// order; more joints than nine letters is an error.
    pub fn for_machine(machine: &Machine) -> Result<Self, ExportError> {
        let n = machine.joints.len();
        if n > GRBLHAL_ORDER.len() {
            return Err(ExportError::Machine(format!(
                "{n} joints: a G-code program has at most {} axis letters",
                GRBLHAL_ORDER.len()
            )));
        }
        let named: Vec<char> = machine
            .joints
            .iter()
            .filter_map(|j| {
                let mut chars = j.name.chars();
                match (chars.next(), chars.next()) {
                    (Some(c), None) => Some(c.to_ascii_uppercase()),
                    _ => None,
                }
            })
            .filter(|c| GRBLHAL_ORDER.contains(c))
            .collect();
        let distinct = named
            .iter()
            .enumerate()
            .all(|(i, c)| !named[..i].contains(c));
        let letters = if named.len() == n && distinct {
            named
        } else {
            GRBLHAL_ORDER[..n].to_vec()
        };
        let scale = machine
            .joints
            .iter()
            .map(|j| match j.kind {
                JointKind::Linear => 1.0,
                JointKind::Rotary => 1.0 / j.to_internal(),
            })
            .collect();
        Ok(AxisLetters { letters, scale })
    }

    /// `q1=X q2=Y q3=Z` for the header comment.
    pub fn describe(&self, machine: &Machine) -> String {
        machine
            .joints
            .iter()
            .zip(&self.letters)
            .map(|(j, l)| format!("{}={l}", j.name))
            .collect::<Vec<_>>()
            .join(" ")
    }
}
