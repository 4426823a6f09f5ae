//! The spindle as the machine file's optional `[spindle]` describes it, for spindle-synchronised
//! motion (G33, G33.1): how fast its speed can change. A spindle is a heavy rotor on a drive of
//! limited torque, so its speed follows a command with a lag and at most a given acceleration —
//! which the axes following its angle must track.

use serde::Deserialize;

use crate::machine::check::positive;
use crate::machine::MachineError;

/// How the spindle's speed responds to a speed command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpindleModel {
    /// The most the speed changes per second, rev/s² (the drive's torque over the rotor's
    /// inertia).
    pub max_acceleration: f64,
    /// Time constant of the speed loop, s: below the acceleration limit the speed approaches
    /// the command as a first-order lag.
    pub time_constant: f64,
}

impl Default for SpindleModel {
    /// A mid-size milling spindle: 0 → 6 000 rev/min in about 2 s.
    fn default() -> Self {
        SpindleModel {
            max_acceleration: 50.0,
            time_constant: 0.02,
        }
    }
}

/// `[spindle]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSpindle {
    max_acceleration_rev_s2: Option<f64>,
    time_constant_s: Option<f64>,
}

impl RawSpindle {
    pub(crate) fn build(self) -> Result<SpindleModel, MachineError> {
        let d = SpindleModel::default();
        Ok(SpindleModel {
            max_acceleration: match self.max_acceleration_rev_s2 {
                Some(a) => positive("spindle.max_acceleration_rev_s2", a)?,
                None => d.max_acceleration,
            },
            time_constant: match self.time_constant_s {
                Some(t) => positive("spindle.time_constant_s", t)?,
                None => d.time_constant,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::Machine;

    fn with_spindle(section: &str) -> Result<Machine, String> {
        let text = Machine::builtin_text("mill3").unwrap().to_owned() + "\n[spindle]\n" + section;
        Machine::from_toml_str(&text).map_err(|e| e.to_string())
    }

    #[test]
    fn the_spindle_section_is_read_with_defaults_and_checked_by_field() {
        let m = with_spindle("max_acceleration_rev_s2 = 20.0\n").unwrap();
        assert_eq!(m.spindle.max_acceleration, 20.0);
        assert_eq!(m.spindle.time_constant, 0.02);
        let e = with_spindle("time_constant_s = -1.0\n").unwrap_err();
        assert!(e.contains("spindle.time_constant_s"), "{e}");
        let e = with_spindle("inertia = 1.0\n").unwrap_err();
        assert!(e.contains("inertia"), "{e}");
        assert_eq!(
            Machine::default_machine().spindle,
            super::SpindleModel::default()
        );
    }
}
