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

#[cfg(test)]
mod tests {
    use super::*;

    fn letters(machine: &Machine) -> String {
        AxisLetters::for_machine(machine)
            .unwrap()
            .letters
            .iter()
            .collect()
    }

    #[test]
    fn own_letters_else_grblhal_order() {
        let table_ac = Machine::builtin("table-ac").unwrap();
        assert_eq!(letters(&table_ac), "XYZAC");
        assert_eq!(letters(&Machine::builtin("table-bc").unwrap()), "XYZBC");
        assert_eq!(letters(&Machine::builtin("yzca").unwrap()), "YZCA");
        assert_eq!(letters(&Machine::builtin("linear-delta").unwrap()), "XYZ");
        // Five joints not named by letters: grblHAL's X Y Z A B, degrees for the rotaries.
        let text = Machine::builtin_text("table-ac")
            .unwrap()
            .replace("name = \"a\"", "name = \"tilt\"")
            .replace("name = \"c\"", "name = \"turn\"");
        let renamed = Machine::from_toml_str(&text).unwrap();
        let l = AxisLetters::for_machine(&renamed).unwrap();
        assert_eq!(l.letters.iter().collect::<String>(), "XYZAB");
        assert_eq!(l.scale[0], 1.0);
        assert!((l.scale[3] - 180.0 / std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(l.describe(&renamed), "x=X y=Y z=Z tilt=A turn=B");
    }
}
