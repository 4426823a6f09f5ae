//! The servo and homing fields of machine files (`[joint.servo]`, `[joint.home]`): defaults,
//! the default homing order (Z first), and errors that name the field.

use tezgah_kinematics::machine::{
    DEFAULT_FORCE_MARGIN, DEFAULT_SERVO_BANDWIDTH_HZ, DEFAULT_SERVO_LOOP_PERIOD_S,
};
use tezgah_kinematics::{Machine, MachineError};

fn field_error(text: &str) -> (String, String) {
    match Machine::from_toml_str(text) {
        Err(MachineError::Invalid { field, reason }) => (field, reason),
        other => panic!("expected a field error, got {other:?}"),
    }
}

/// A 3-joint Cartesian machine; `extra[i]` is appended after joint i's limits.
fn mill(extra: [&str; 3]) -> String {
    let mut s = String::from(
        "name = \"t\"\n[kinematics]\ntype = \"cartesian\"\n[motion]\nperiod_s = 0.001\ntolerance_mm = 0.01\n",
    );
    for (name, e) in ["x", "y", "z"].iter().zip(extra) {
        s += &format!(
            "[[joint]]\nname = \"{name}\"\nkind = \"linear\"\nmin = -100.0\nmax = 100.0\n\
             max_velocity = 100.0\nmax_acceleration = 1000.0\nmax_jerk = 20000.0\n{e}\n"
        );
    }
    s
}

#[test]
fn defaults_are_filled_in() {
    let m = Machine::from_toml_str(&mill(["", "", ""])).unwrap();
    let s = &m.joints[0].servo;
    assert_eq!(s.bandwidth_hz, DEFAULT_SERVO_BANDWIDTH_HZ);
    assert_eq!(s.inertia, 100.0);
    assert_eq!(s.friction, 0.0);
    // 3 × (100 kg · 1 m/s²)
    assert!((s.max_force - DEFAULT_FORCE_MARGIN * 100.0).abs() < 1e-9);
    assert_eq!(
        (s.velocity_feed_forward, s.acceleration_feed_forward),
        (1.0, 1.0)
    );
    assert_eq!(s.loop_period_s, DEFAULT_SERVO_LOOP_PERIOD_S);
    assert_eq!(s.following_error_limit, None);
    let h = &m.joints[0].home;
    assert_eq!(
        (h.switch, h.search_velocity, h.latch_velocity, h.position),
        (100.0, 10.0, 1.0, 0.0)
    );
    // Z first, then x and y one after another.
    let seq: Vec<u32> = m.joints.iter().map(|j| j.home.sequence).collect();
    assert_eq!(seq, [1, 2, 0]);
}

#[test]
fn builtin_mill3_homes_z_first() {
    let m = Machine::builtin("mill3").unwrap();
    let seq: Vec<u32> = m.joints.iter().map(|j| j.home.sequence).collect();
    assert_eq!(seq, [1, 2, 0]);
    assert_eq!(m.joints[0].servo.following_error_limit, Some(1.0));
    for name in tezgah_kinematics::builtin_names() {
        let m = Machine::builtin(name).unwrap();
        let mut seq: Vec<u32> = m.joints.iter().map(|j| j.home.sequence).collect();
        seq.sort_unstable();
        assert_eq!(
            seq,
            (0..m.joints.len() as u32).collect::<Vec<_>>(),
            "{name}"
        );
    }
}

#[test]
fn bad_servo_and_home_fields_are_named() {
    let cases: Vec<([&str; 3], &str, &str)> = vec![
        (
            ["[joint.servo]\nbandwidth_hz = 0.0", "", ""],
            "joint[0].servo.bandwidth_hz",
            "must be > 0",
        ),
        (
            ["", "[joint.servo]\nbandwidth_hz = 500.0", ""],
            "joint[1].servo.bandwidth_hz",
            "too high",
        ),
        (
            ["[joint.servo]\nfriction = -1.0", "", ""],
            "joint[0].servo.friction",
            ">= 0",
        ),
        (
            ["[joint.servo]\nvelocity_feed_forward = 2.5", "", ""],
            "joint[0].servo.velocity_feed_forward",
            "[0, 2]",
        ),
        (
            ["[joint.servo]\nmax_force = 50.0", "", ""],
            "joint[0].servo.max_force",
            "cannot give",
        ),
        (
            [
                "[joint.servo]\nloop_period_s = 0.002\nbandwidth_hz = 5.0",
                "",
                "",
            ],
            "joint[0].servo.loop_period_s",
            "motion.period_s",
        ),
        (
            ["", "", "[joint.home]\nswitch = 120.0"],
            "joint[2].home.switch",
            "outside",
        ),
        (
            ["[joint.home]\nsearch_velocity = 0.0", "", ""],
            "joint[0].home.search_velocity",
            "non-zero",
        ),
        (
            [
                "[joint.home]\nsearch_velocity = -5.0\nlatch_velocity = 6.0",
                "",
                "",
            ],
            "joint[0].home.latch_velocity",
            "at most",
        ),
        (
            ["[joint.home]\nposition = -101.0", "", ""],
            "joint[0].home.position",
            "outside",
        ),
        (
            ["[joint.home]\nsequence = 4294967295", "", ""],
            "joint[0].home.sequence",
            "too large",
        ),
    ];
    for (extra, field, reason) in cases {
        let (f, r) = field_error(&mill(extra));
        assert_eq!(f, field, "{extra:?}");
        assert!(r.contains(reason), "{field}: {r}");
    }
    // unknown fields are refused by the TOML reader
    assert!(matches!(
        Machine::from_toml_str(&mill(["[joint.servo]\nbandwith_hz = 3.0", "", ""])),
        Err(MachineError::Toml { .. })
    ));
}

#[test]
fn joints_without_a_sequence_follow_the_given_ones() {
    let m = Machine::from_toml_str(&mill(["[joint.home]\nsequence = 3", "", ""])).unwrap();
    let seq: Vec<u32> = m.joints.iter().map(|j| j.home.sequence).collect();
    assert_eq!(seq, [3, 4, 5]);
}

#[test]
fn explicit_sequence_allows_joints_together() {
    let m = Machine::from_toml_str(&mill([
        "[joint.home]\nsequence = 1",
        "[joint.home]\nsequence = 1",
        "[joint.home]\nsequence = 0\nsearch_velocity = -5.0\nswitch = -90.0",
    ]))
    .unwrap();
    let seq: Vec<u32> = m.joints.iter().map(|j| j.home.sequence).collect();
    assert_eq!(seq, [1, 1, 0]);
    assert_eq!(m.joints[2].home.search_velocity, -5.0);
    assert_eq!(m.joints[2].home.latch_velocity, 0.5);
}

/// Z is found by the model's joint-to-axis map, not by a joint's name: Y-Z-C-A's joint 1 and a
/// table's joint 2 home first whatever they are called; a delta's carriages carry no axis and
/// home in file order.
#[test]
fn the_joint_that_carries_z_homes_first_whatever_its_name() {
    let seq = |text: &str| -> Vec<u32> {
        let m = Machine::from_toml_str(text).unwrap();
        m.joints.iter().map(|j| j.home.sequence).collect()
    };
    let rename = |name: &str, names: &[(&str, &str)]| {
        let mut text = Machine::builtin_text(name).unwrap().to_owned();
        for (from, to) in names {
            text = text.replace(&format!("name = \"{from}\""), &format!("name = \"{to}\""));
        }
        text
    };
    let yzca = rename(
        "yzca",
        &[("y", "radial"), ("z", "vertical"), ("c", "table")],
    );
    assert_eq!(seq(&yzca), [1, 0, 2, 3]);
    let ac = rename("table-ac", &[("z", "spindle"), ("x", "z")]);
    assert_eq!(seq(&ac), [1, 2, 0, 3, 4]);
    let delta = rename("linear-delta", &[("q2", "z")]);
    assert_eq!(seq(&delta), [0, 1, 2]);
}
