//! The optional `[path]` table of a machine file (the smoothing builder's options): read when
//! present, absent fields left to the builder's defaults, bad values refused by field name.

use tezgah_kinematics::machine::PathSettings;
use tezgah_kinematics::{Machine, MachineError};

/// mill3's text with its `[path]` table replaced by `path` (empty: no table).
fn with_path(path: &str) -> String {
    let text = Machine::builtin_text("mill3").expect("mill3 is built in");
    let start = text.find("[path]").expect("mill3 shows [path]");
    let end = start + text[start..].find("[[joint]]").expect("joints follow");
    format!("{}{path}\n\n{}", &text[..start], &text[end..])
}

#[test]
fn mill3_shows_every_path_field() {
    let m = Machine::builtin("mill3").unwrap();
    assert_eq!(
        m.path,
        PathSettings {
            compress_corner_angle_deg: Some(30.0),
            short_segment_mm: Some(1.0),
            blend_max_angle_deg: Some(175.0),
            axis_tolerance_deg: None,
        }
    );
}

#[test]
fn five_axis_machines_show_the_axis_tolerance() {
    for name in ["table-ac", "table-bc", "yzca"] {
        let m = Machine::builtin(name).unwrap();
        assert_eq!(m.path.axis_tolerance_deg, Some(0.1), "{name}");
    }
    let m = Machine::from_toml_str(&with_path("[path]\naxis_tolerance_deg = 0.02")).unwrap();
    assert_eq!(m.path.axis_tolerance_deg, Some(0.02));
}

#[test]
fn the_table_and_its_fields_are_optional() {
    let m = Machine::from_toml_str(&with_path("")).unwrap();
    assert_eq!(m.path, PathSettings::default());
    let m = Machine::from_toml_str(&with_path("[path]\nshort_segment_mm = 0.5")).unwrap();
    assert_eq!(m.path.short_segment_mm, Some(0.5));
    assert_eq!(m.path.blend_max_angle_deg, None);
}

#[test]
fn bad_values_name_their_field() {
    for (table, field) in [
        (
            "[path]\ncompress_corner_angle_deg = 0.0",
            "path.compress_corner_angle_deg",
        ),
        (
            "[path]\nblend_max_angle_deg = 181.0",
            "path.blend_max_angle_deg",
        ),
        ("[path]\nshort_segment_mm = -1.0", "path.short_segment_mm"),
        ("[path]\nshort_segment_mm = nan", "path.short_segment_mm"),
        (
            "[path]\naxis_tolerance_deg = 0.0",
            "path.axis_tolerance_deg",
        ),
        (
            "[path]\naxis_tolerance_deg = 200.0",
            "path.axis_tolerance_deg",
        ),
    ] {
        match Machine::from_toml_str(&with_path(table)) {
            Err(MachineError::Invalid { field: f, .. }) => assert_eq!(f, field, "{table}"),
            other => panic!("{table}: {other:?}"),
        }
    }
    // Unknown fields are refused like everywhere else in the file.
    assert!(Machine::from_toml_str(&with_path("[path]\nblend_angle = 3.0")).is_err());
}
