//! The machine file's `[drive]` table: which drives the bus must hold, in bus order, and how
//! each maps to a joint. The kinematics crate lets the table through; this module reads it
//! from the same text (unknown fields refused, errors with line and column) and checks it
//! against the machine's joints. The master (`crate::master`) checks the scanned bus against it.
//!
//! ```toml
//! [[drive.slave]]                  # one per drive, in the order they sit on the cable
//! joint = "x"                      # the joint it moves (each joint exactly one drive)
//! vendor_id = 0x0000006A           # from the drive's ESI file / its SII EEPROM
//! product_code = 0x00414B44
//! counts_per_unit = 10000.0        # encoder counts per mm (linear) or per degree (rotary)
//! following_error_limit = 0.5      # mm or degrees; beyond it the machine stops
//! ```

use serde::Deserialize;
use tezgah_kinematics::{JointKind, Machine};
use thiserror::Error;

/// Why the `[drive]` table cannot be used.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SectionError {
    /// Not TOML, a wrong type, a missing or unknown field (the message has line and column).
    #[error("machine file [drive]: {0}")]
    Toml(String),
    /// A field's value cannot be used.
    #[error("{field}: {reason}")]
    Invalid { field: String, reason: String },
    /// The file has no `[drive]` table but an EtherCAT bus was asked for.
    #[error("the machine file has no [drive] table (see README: wiring EtherCAT drives)")]
    Missing,
}

fn invalid(field: String, reason: impl Into<String>) -> SectionError {
    SectionError::Invalid {
        field,
        reason: reason.into(),
    }
}

/// One drive of `[drive]`, validated; scaling in internal units (mm or rad).
#[derive(Debug, Clone, PartialEq)]
pub struct DriveSlave {
    /// Index of the joint it moves (machine order).
    pub joint: usize,
    /// The joint's name, for messages.
    pub joint_name: String,
    pub vendor_id: u32,
    pub product_code: u32,
    /// Encoder counts per internal unit (mm, or rad for a rotary joint).
    pub counts_per_unit: f64,
    /// Largest |following error|, internal units.
    pub following_error_limit: f64,
    /// The same, counts (for the drive's own window, object 0x6065).
    pub following_error_counts: u32,
}

impl DriveSlave {
    /// A joint position (internal units) in counts, or `None` beyond the i32 range.
    pub fn to_counts(&self, q: f64) -> Option<i32> {
        let c = (q * self.counts_per_unit).round();
        (c.is_finite() && c >= i32::MIN as f64 && c <= i32::MAX as f64).then_some(c as i32)
    }

    /// Counts in internal units.
    pub fn from_counts(&self, c: i32) -> f64 {
        c as f64 / self.counts_per_unit
    }
}

/// `[drive]`, validated against the machine.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveSection {
    /// In bus order.
    pub slaves: Vec<DriveSlave>,
}

#[derive(Deserialize)]
struct File {
    drive: Option<RawDrive>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDrive {
    #[serde(default)]
    slave: Vec<RawSlave>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSlave {
    joint: String,
    vendor_id: u32,
    product_code: u32,
    counts_per_unit: f64,
    following_error_limit: f64,
}

impl DriveSection {
    /// Reads `[drive]` from the machine file's `text` and checks it against `machine` (the
    /// same file, read by the kinematics crate). `Ok(None)` when the file has no `[drive]`.
    pub fn from_machine_text(
        text: &str,
        machine: &Machine,
    ) -> Result<Option<DriveSection>, SectionError> {
        let file: File =
            toml::from_str(text).map_err(|e| SectionError::Toml(e.to_string().trim().into()))?;
        let Some(raw) = file.drive else {
            return Ok(None);
        };
        if raw.slave.is_empty() {
            return Err(invalid("drive.slave".into(), "lists no drive"));
        }
        let mut slaves = Vec::with_capacity(raw.slave.len());
        let mut driven = vec![false; machine.joints.len()];
        for (i, s) in raw.slave.into_iter().enumerate() {
            let field = |name: &str| format!("drive.slave[{i}].{name}");
            let Some(joint) = machine.joints.iter().position(|j| j.name == s.joint) else {
                let names: Vec<&str> = machine.joints.iter().map(|j| j.name.as_str()).collect();
                return Err(invalid(
                    field("joint"),
                    format!(
                        "`{}` is not a joint of the machine ({})",
                        s.joint,
                        names.join(", ")
                    ),
                ));
            };
            if std::mem::replace(&mut driven[joint], true) {
                return Err(invalid(
                    field("joint"),
                    format!("joint `{}` already has a drive", s.joint),
                ));
            }
            if !(s.counts_per_unit.is_finite() && s.counts_per_unit > 0.0) {
                return Err(invalid(field("counts_per_unit"), "must be > 0"));
            }
            if !(s.following_error_limit.is_finite() && s.following_error_limit > 0.0) {
                return Err(invalid(field("following_error_limit"), "must be > 0"));
            }
            // File units are mm or degrees; internally mm or rad.
            let per_file_unit = match machine.joints[joint].kind {
                JointKind::Linear => 1.0,
                JointKind::Rotary => 180.0 / std::f64::consts::PI,
            };
            let counts = (s.following_error_limit * s.counts_per_unit).round();
            if counts < 1.0 || counts >= u32::MAX as f64 {
                return Err(invalid(
                    field("following_error_limit"),
                    format!("is {counts} counts: must be 1 to 2^32 − 2"),
                ));
            }
            slaves.push(DriveSlave {
                joint,
                joint_name: s.joint,
                vendor_id: s.vendor_id,
                product_code: s.product_code,
                counts_per_unit: s.counts_per_unit * per_file_unit,
                following_error_limit: s.following_error_limit / per_file_unit,
                following_error_counts: counts as u32,
            });
        }
        if let Some(j) = driven.iter().position(|d| !d) {
            return Err(invalid(
                "drive.slave".into(),
                format!("joint `{}` has no drive", machine.joints[j].name),
            ));
        }
        Ok(Some(DriveSection { slaves }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mill_with(drive: &str) -> (String, Machine) {
        let text = format!(
            "{}\n{drive}",
            Machine::builtin_text("mill3").expect("mill3 is built in")
        );
        let m = Machine::from_toml_str(&text).expect("the kinematics crate lets [drive] through");
        (text, m)
    }

    const THREE: &str = r#"
[[drive.slave]]
joint = "x"
vendor_id = 0x6A
product_code = 0x414B44
counts_per_unit = 10000.0
following_error_limit = 0.5
[[drive.slave]]
joint = "z"
vendor_id = 0x6A
product_code = 0x414B44
counts_per_unit = 2000.0
following_error_limit = 1.0
[[drive.slave]]
joint = "y"
vendor_id = 0x83
product_code = 0x1
counts_per_unit = 1000.0
following_error_limit = 0.25
"#;

    #[test]
    fn reads_drives_in_bus_order() {
        let (text, m) = mill_with(THREE);
        let d = DriveSection::from_machine_text(&text, &m).unwrap().unwrap();
        let joints: Vec<usize> = d.slaves.iter().map(|s| s.joint).collect();
        assert_eq!(joints, [0, 2, 1]);
        assert_eq!(d.slaves[0].vendor_id, 0x6A);
        assert_eq!(d.slaves[0].following_error_counts, 5000);
        assert_eq!(d.slaves[1].to_counts(1.25), Some(2500));
        assert_eq!(d.slaves[1].from_counts(-2500), -1.25);
        assert_eq!(d.slaves[2].to_counts(3e6), None);
    }

    #[test]
    fn no_table_is_none() {
        let m = Machine::default_machine();
        let text = Machine::builtin_text("mill3").unwrap();
        assert_eq!(DriveSection::from_machine_text(text, &m), Ok(None));
    }

    #[test]
    fn errors_name_the_field() {
        let bad = |from: &str, to: &str| {
            let (text, m) = mill_with(&THREE.replacen(from, to, 1));
            DriveSection::from_machine_text(&text, &m)
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            bad("joint = \"z\"", "joint = \"q\""),
            "drive.slave[1].joint: `q` is not a joint of the machine (x, y, z)"
        );
        assert_eq!(
            bad("joint = \"z\"", "joint = \"x\""),
            "drive.slave[1].joint: joint `x` already has a drive"
        );
        assert_eq!(
            bad("counts_per_unit = 2000.0", "counts_per_unit = -1.0"),
            "drive.slave[1].counts_per_unit: must be > 0"
        );
        let e = bad("following_error_limit = 1.0", "following_error_limt = 1.0");
        assert!(e.contains("unknown field `following_error_limt`"), "{e}");
        assert!(e.contains("line"), "{e}");
        let (text, m) = mill_with(&THREE[..THREE.rfind("[[drive.slave]]").unwrap()]);
        assert_eq!(
            DriveSection::from_machine_text(&text, &m)
                .unwrap_err()
                .to_string(),
            "drive.slave: joint `y` has no drive"
        );
    }
}
