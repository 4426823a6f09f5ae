//! Machine files: the built-in files parse and build their models; every bad field is
//! refused with an error that names it; random damage never panics.

use proptest::prelude::*;
use tezgah_kinematics::{builtin_names, JointKind, Kinematics, Machine, MachineError, Model};

#[test]
fn builtins_parse() {
    let names: Vec<_> = builtin_names().collect();
    assert_eq!(
        names,
        ["mill3", "yzca", "table-ac", "table-bc", "linear-delta"]
    );
    for name in names {
        let m = Machine::builtin(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.name, name);
        assert_eq!(
            m.kinematics.type_name(),
            if name == "mill3" { "cartesian" } else { name }
        );
        assert_eq!(m.kinematics.joint_count(), m.joints.len());
        assert!((m.motion.period_s - 0.001).abs() < 1e-15);
        // the home joints are valid and map to a pose and back
        let home = m.home();
        m.kinematics.check_joints(&home).unwrap();
        let tool = tezgah_kinematics::Tool::default();
        let p = m.kinematics.forward(&home, &tool).unwrap();
        let q = m.kinematics.inverse(&p, &tool, &home).unwrap();
        assert!(
            q.as_slice()
                .iter()
                .zip(home.as_slice())
                .all(|(a, b)| (a - b).abs() < 1e-9),
            "{name}"
        );
    }
    assert_eq!(Machine::default_machine().name, "mill3");
    assert!(matches!(
        Machine::builtin("hexapod"),
        Err(MachineError::UnknownBuiltin { .. })
    ));
}

#[test]
fn tcp_is_switched_by_the_program_unless_the_file_says_always() {
    use tezgah_kinematics::TcpSwitch;
    for name in builtin_names() {
        assert_eq!(
            Machine::builtin(name).unwrap().tcp,
            TcpSwitch::Program,
            "{name}"
        );
    }
    let ac = Machine::builtin_text("table-ac").unwrap();
    let always = edit(ac, "[kinematics]", "tcp", "tcp = \"always\"");
    assert_eq!(
        Machine::from_toml_str(&always).unwrap().tcp,
        TcpSwitch::Always
    );
}

#[test]
fn machine_files_on_disk_match_builtins() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines");
    for name in builtin_names() {
        let m = Machine::from_file(format!("{dir}/{name}.toml")).unwrap();
        assert_eq!(m.name, name);
    }
    assert!(matches!(
        Machine::from_file(format!("{dir}/nope.toml")),
        Err(MachineError::Io { .. })
    ));
}

#[test]
fn units_at_the_boundary() {
    let m = Machine::builtin("table-ac").unwrap();
    assert_eq!(m.joints[3].kind, JointKind::Rotary);
    let q = m.from_file_units(&[1.0, 2.0, 3.0, 90.0, -720.0]).unwrap();
    assert!((q[3] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!((q[4] + 4.0 * std::f64::consts::PI).abs() < 1e-12);
    // rotary joints stay continuous (never wrapped) on the way out
    assert_eq!(m.to_file_units(&q)[4].round(), -720.0);
    // limits are converted: A in [−30°, 120°]
    let l = &m.kinematics.joint_limits()[3];
    assert!((l.max - 120f64.to_radians()).abs() < 1e-15);
    let err = m
        .kinematics
        .check_joints(&m.from_file_units(&[0.0, 0.0, 0.0, 130.0, 0.0]).unwrap())
        .unwrap_err();
    assert!(
        err.to_string().contains("`a`") && err.to_string().contains("130"),
        "{err}"
    );
    assert!(matches!(m.kinematics, Model::TableAc(_)));
}

/// Replaces the first line starting with `key =` after the first occurrence of `anchor`.
fn edit(text: &str, anchor: &str, key: &str, new_line: &str) -> String {
    let start = text
        .find(anchor)
        .unwrap_or_else(|| panic!("anchor {anchor}"));
    let rel = text[start..]
        .lines()
        .scan(0usize, |off, l| {
            let here = *off;
            *off += l.len() + 1;
            Some((here, l))
        })
        .find(|(_, l)| l.trim_start().starts_with(&format!("{key} =")))
        .unwrap_or_else(|| panic!("key {key} after {anchor}"))
        .0;
    let at = start + rel;
    let end = at + text[at..].find('\n').unwrap();
    format!("{}{}{}", &text[..at], new_line, &text[end..])
}

fn field_error(text: &str) -> (String, String) {
    match Machine::from_toml_str(text) {
        Err(MachineError::Invalid { field, reason }) => (field, reason),
        other => panic!("expected a field error, got {other:?}"),
    }
}

fn toml_error(text: &str) -> String {
    match Machine::from_toml_str(text) {
        Err(MachineError::Toml { message }) => message,
        other => panic!("expected a TOML error, got {other:?}"),
    }
}

#[test]
fn bad_fields_are_named() {
    let mill = Machine::builtin_text("mill3").unwrap();
    let delta = Machine::builtin_text("linear-delta").unwrap();
    let ac = Machine::builtin_text("table-ac").unwrap();
    let yzca = Machine::builtin_text("yzca").unwrap();
    let third = "name = \"z\"";
    let cases: Vec<(String, &str, &str)> = vec![
        (
            edit(mill, third, "max_jerk", "max_jerk = 0.0"),
            "joint[2].max_jerk",
            "must be > 0",
        ),
        (
            edit(mill, third, "max_velocity", "max_velocity = -1.0"),
            "joint[2].max_velocity",
            "must be > 0",
        ),
        (
            edit(
                mill,
                "name = \"x\"",
                "max_acceleration",
                "max_acceleration = nan",
            ),
            "joint[0].max_acceleration",
            "must be > 0",
        ),
        (
            edit(mill, "name = \"y\"", "max", "max = -150.0"),
            "joint[1].max",
            "greater than min",
        ),
        (
            edit(mill, "name = \"y\"", "min", "min = inf"),
            "joint[1].min",
            "finite",
        ),
        (
            edit(mill, "name = \"y\"", "name", "name = \"x\""),
            "joint[1].name",
            "already the name of joint[0]",
        ),
        (
            edit(mill, "name = \"y\"", "name", "name = \" \""),
            "joint[1].name",
            "empty",
        ),
        (
            edit(mill, "name = \"x\"", "kind", "kind = \"spline\""),
            "joint[0].kind",
            "linear",
        ),
        (
            edit(mill, "name = \"x\"", "kind", "kind = \"rotary\""),
            "joint[0].kind",
            "linear joint",
        ),
        (
            edit(mill, "name = \"x\"", "min", "endless = true"),
            "joint[0].endless",
            "rotary",
        ),
        (
            edit(mill, "[motion]", "period_s", "period_s = 0.0"),
            "motion.period_s",
            "must be > 0",
        ),
        (
            edit(mill, "[motion]", "tolerance_mm", "tolerance_mm = -0.01"),
            "motion.tolerance_mm",
            "must be > 0",
        ),
        (
            edit(mill, "[kinematics]", "type", "type = \"scara\""),
            "kinematics.type",
            "not one of",
        ),
        (
            edit(
                mill,
                "[kinematics]",
                "axis_tolerance_deg",
                "axis_tolerance_deg = 0.0",
            ),
            "kinematics.axis_tolerance_deg",
            "must be > 0",
        ),
        (
            edit(mill, "name = \"mill3\"", "name", "name = \"\""),
            "name",
            "empty",
        ),
        (
            edit(delta, "[kinematics]", "rod_length", "rod_length = 100.0"),
            "kinematics.rod_length",
            "greater than radius",
        ),
        (
            edit(delta, "[kinematics]", "radius", "radius = -1.0"),
            "kinematics.radius",
            "must be > 0",
        ),
        (
            edit(delta, "[kinematics]", "rod_length", "# no rod"),
            "kinematics.rod_length",
            "missing",
        ),
        (
            edit(
                delta,
                "[kinematics]",
                "min_rod_angle_deg",
                "min_rod_angle_deg = 90.0",
            ),
            "kinematics.min_rod_angle_deg",
            "[0, 90)",
        ),
        (
            edit(
                delta,
                "[kinematics]",
                "tower_angles",
                "tower_angles = [0.0, 0.0, 180.0]",
            ),
            "kinematics.tower_angles",
            "one line",
        ),
        (
            edit(
                delta,
                "[kinematics]",
                "carriage_offsets",
                "carriage_offsets = [0.0, inf, 0.0]",
            ),
            "kinematics.carriage_offsets[1]",
            "finite",
        ),
        (
            edit(ac, "[kinematics]", "pivot", "# no pivot"),
            "kinematics.pivot",
            "missing",
        ),
        (
            edit(ac, "[kinematics]", "tcp", "tcp = \"sometimes\""),
            "kinematics.tcp",
            "`sometimes` is not `program` or `always`",
        ),
        (
            edit(ac, "name = \"a\"", "kind", "kind = \"linear\""),
            "joint[3].kind",
            "rotary joint",
        ),
        (
            edit(ac, "name = \"c\"", "endless", "endless = true\nmin = 1.0"),
            "joint[4].min",
            "endless joint has no limits",
        ),
        (
            edit(ac, "name = \"c\"", "endless", "min = 1.0"),
            "joint[4].max",
            "missing",
        ),
        (
            edit(yzca, "[kinematics]", "pivot_to_gauge", "# none"),
            "kinematics.pivot_to_gauge",
            "missing",
        ),
        (
            edit(
                yzca,
                "[kinematics]",
                "pole_cone_deg",
                "pole_cone_deg = -1.0",
            ),
            "kinematics.pole_cone_deg",
            "must be > 0",
        ),
        (
            edit(
                yzca,
                "[kinematics]",
                "centre_tolerance_mm",
                "centre_tolerance_mm = 0.0",
            ),
            "kinematics.centre_tolerance_mm",
            "must be > 0",
        ),
        (
            edit(yzca, "name = \"a\"", "min", "# no min"),
            "joint[3].min",
            "missing",
        ),
    ];
    for (text, field, reason) in &cases {
        let (f, r) = field_error(text);
        assert_eq!(&f, field, "reason was: {r}");
        assert!(r.contains(reason), "{f}: `{r}` lacks `{reason}`");
        // The rendered message leads with the field.
        let msg = Machine::from_toml_str(text).unwrap_err().to_string();
        assert!(msg.starts_with(&format!("{field}: ")), "{msg}");
    }
    let (f, r) =
        field_error(&delta.replace("# max_joint_angle_deg = 22.0", "max_joint_angle_deg = 0.0"));
    assert_eq!(
        (f.as_str(), r.as_str()),
        ("kinematics.max_joint_angle_deg", "must be in (0, 180)")
    );
    // Joint count per model.
    let (f, r) = field_error(&mill[..mill.rfind("[[joint]]").unwrap()]);
    assert_eq!(f, "joint");
    assert!(
        r.contains("cartesian needs 3 to 6 joints, the file has 2"),
        "{r}"
    );
    let (f, r) = field_error(&delta[..delta.rfind("[[joint]]").unwrap()]);
    assert_eq!(
        (f.as_str(), r.as_str()),
        ("joint", "linear-delta needs 3 joints, the file has 2")
    );
}

#[test]
fn toml_level_errors_name_the_field() {
    let mill = Machine::builtin_text("mill3").unwrap();
    // unknown field, in every table
    let m = toml_error(&mill.replace("[motion]\n", "[motion]\nspeed = 3\n"));
    assert!(m.contains("speed"), "{m}");
    let m = toml_error(&mill.replace("max_jerk = 25000.0", "max_jerk = 25000.0\nmax_snap = 1.0"));
    assert!(m.contains("max_snap"), "{m}");
    let m = toml_error(&mill.replace("[kinematics]\n", "[kinematics]\npivott = [0.0, 0.0, 0.0]\n"));
    assert!(m.contains("pivott"), "{m}");
    let m = toml_error(&format!("colour = \"red\"\n{mill}"));
    assert!(m.contains("colour"), "{m}");
    // missing required field
    let m = toml_error(&mill.replace("period_s = 0.001", ""));
    assert!(m.contains("period_s"), "{m}");
    // wrong type
    let m = toml_error(&mill.replace("max_jerk = 25000.0", "max_jerk = \"fast\""));
    assert!(m.contains("max_jerk") || m.contains("line"), "{m}");
    // wrong array length
    let ac = Machine::builtin_text("table-ac").unwrap();
    let m = toml_error(&ac.replace("pivot = [0.0, 0.0, -150.0]", "pivot = [0.0, -150.0]"));
    assert!(m.contains("pivot") || m.contains("3"), "{m}");
    // not TOML at all
    toml_error("this is not toml = = =");
}

/// The 1-based line of `[kinematics]` in a built-in file (where a section error points).
fn kinematics_line(text: &str) -> usize {
    1 + text.lines().position(|l| l == "[kinematics]").unwrap()
}

/// Each model reads its own `[kinematics]` fields: a typo, or a field of another model, is
/// refused with its name, the model's own fields, the model and the line of the section.
#[test]
fn each_model_refuses_an_unknown_field_of_its_section() {
    // (machine, a field of another model, one of its own fields serde lists)
    let cases = [
        ("mill3", "radius = 5.0", "axis_tolerance_deg"),
        ("mill3", "max_joint_angle_deg = 20.0", "axis_tolerance_deg"),
        ("yzca", "pivot = [0.0, 0.0, 0.0]", "pivot_to_gauge"),
        ("table-ac", "pivot_to_gauge = 1.0", "c_offset"),
        ("table-bc", "centre_tolerance_mm = 1.0", "c_offset"),
        ("linear-delta", "pole_cone_deg = 1.0", "rod_length"),
    ];
    for (name, line, own) in cases {
        let text = Machine::builtin_text(name).unwrap();
        let kind = Machine::builtin(name).unwrap().kinematics.type_name();
        let field = line.split(' ').next().unwrap();
        for bad in [line.to_owned(), format!("{field}x = 1.0")] {
            let m = toml_error(&text.replace("[kinematics]\n", &format!("[kinematics]\n{bad}\n")));
            let key = bad.split(' ').next().unwrap();
            assert!(m.contains(&format!("unknown field `{key}`")), "{name}: {m}");
            assert!(m.contains(&format!("`{own}`")), "{name}: {m}");
            assert!(m.contains(&format!("(for type `{kind}`)")), "{name}: {m}");
            assert!(
                m.contains(&format!("line {}", kinematics_line(text))),
                "{name}: {m}"
            );
        }
    }
}

/// `type` and `tcp` are the machine's keys: every model's section lets them through.
#[test]
fn every_model_accepts_the_machine_keys_of_kinematics() {
    use tezgah_kinematics::TcpSwitch;
    for name in builtin_names() {
        let text = Machine::builtin_text(name)
            .unwrap()
            .replace("[kinematics]\n", "[kinematics]\ntcp = \"always\"\n");
        // table-ac already has a `tcp` line: keep one.
        let text = text.replace("tcp = \"program\"", "");
        let m = Machine::from_toml_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.tcp, TcpSwitch::Always, "{name}");
    }
}

/// A field a model needs, left out, is named with the section and the model.
#[test]
fn each_model_names_a_missing_required_field() {
    let cases = [
        ("yzca", "pivot_to_gauge"),
        ("table-ac", "pivot"),
        ("table-bc", "pivot"),
        ("linear-delta", "radius"),
        ("linear-delta", "rod_length"),
    ];
    for (name, key) in cases {
        let text = Machine::builtin_text(name).unwrap();
        let (f, r) = field_error(&edit(text, "[kinematics]", key, "# left out"));
        assert_eq!(f, format!("kinematics.{key}"), "{name}");
        assert_eq!(r, format!("missing (required by {name})"));
    }
}

/// Each model's joint-to-axis map and the joints TCP control takes from the program: the map
/// gives the program axes, and `tcp_angles` returns exactly the joints `tcp_joints` names.
#[test]
fn models_declare_their_joint_axes_and_tcp_joints() {
    use tezgah_geom::Axis::{self, *};
    let some = |a: &[Axis]| a.iter().copied().map(Some).collect::<Vec<_>>();
    let cases = [
        ("mill3", some(&[X, Y, Z]), Vec::<usize>::new()),
        ("yzca", some(&[Y, Z, C, A]), vec![2, 3]),
        ("table-ac", some(&[X, Y, Z, A, C]), vec![3, 4]),
        ("table-bc", some(&[X, Y, Z, B, C]), vec![3, 4]),
        ("linear-delta", vec![None; 3], vec![]),
    ];
    for (name, axes, tcp) in cases {
        let m = Machine::builtin(name).unwrap();
        assert_eq!(m.kinematics.joint_axes(), axes, "{name}");
        assert_eq!(m.kinematics.tcp_joints(), tcp, "{name}");
        let q = m
            .from_file_units(&[1.5, -2.0, 3.25, 40.0, -50.0][..m.joints.len()])
            .unwrap();
        let want: Vec<f64> = tcp.iter().map(|&i| q[i]).collect();
        assert_eq!(m.kinematics.tcp_angles(&q).as_slice(), want, "{name}");
    }
    // A Cartesian machine's extra joints carry the axis their names give, or none.
    let mill = Machine::builtin_text("mill3").unwrap();
    let extra = |name: &str| {
        format!(
            "{mill}\n[[joint]]\nname = \"{name}\"\nkind = \"rotary\"\nendless = true\n\
             max_velocity = 90.0\nmax_acceleration = 900.0\nmax_jerk = 9000.0\n"
        )
    };
    let m = Machine::from_toml_str(&extra("B")).unwrap();
    assert_eq!(m.kinematics.joint_axes(), some(&[X, Y, Z, B]));
    assert_eq!(m.tcp_axes().unwrap(), [B]);
    assert_eq!(m.program_axes(), [X, Y, Z, B]);
    let m = Machine::from_toml_str(&extra("spindle")).unwrap();
    assert_eq!(m.kinematics.joint_axes()[3], None);
    match m.tcp_axes() {
        Err(MachineError::Invalid { field, reason }) => {
            assert_eq!(field, "joint[3].name");
            assert!(reason.contains("no program axis"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(m.program_axes(), [X, Y, Z]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Random damage to a good file: an error or a machine, never a panic.
    #[test]
    fn damaged_files_do_not_panic(name in proptest::sample::select(vec!["mill3", "yzca", "table-ac", "table-bc", "linear-delta"]),
                                  at in 0usize..4000, len in 0usize..20, junk in "[ -~\n]{0,12}") {
        let text = Machine::builtin_text(name).unwrap();
        let mut bytes: Vec<char> = text.chars().collect();
        let at = at.min(bytes.len());
        let end = (at + len).min(bytes.len());
        bytes.splice(at..end, junk.chars());
        let damaged: String = bytes.into_iter().collect();
        let _ = Machine::from_toml_str(&damaged);
    }
}
