//! JOG, INC and HOME through the executor on a virtual clock (mill3): the set-point stream
//! they produce (limits by finite differences, the velocity/acceleration contract, no jump),
//! their distances against closed forms, the homing offsets, refusals while busy, and the
//! pre-flight refusing a program out of reach at load, with the file, line and column of the
//! error also inside a subroutine file.

mod support;

use std::sync::Arc;

use support::*;
use tezgah_executor::command::{Command, Direction, Mode, RunState};
use tezgah_executor::error::ExecError;
use tezgah_executor::executor::{ExecOptions, Executor, Produced};
use tezgah_executor::manual::SimulatedSwitches;
use tezgah_gcode::interp::SubroutineLibrary;
use tezgah_gcode::sources::Located;
use tezgah_gcode::Span;
use tezgah_geom::Pose;
use tezgah_kinematics::{Joints, Machine};

/// Steps until the executor produces nothing more; `each(k, exec)` runs before period k.
fn play(
    exec: &mut Executor,
    max: usize,
    mut each: impl FnMut(usize, &mut Executor),
) -> Vec<Produced> {
    let mut out = Vec::new();
    for k in 0..max {
        each(k, exec);
        match exec.step().unwrap() {
            Some(p) => out.push(p),
            None => return out,
        }
    }
    panic!("still moving after {max} periods");
}

/// Every joint's finite differences within its limits (0.5 % for velocity and acceleration
/// as the executor's other tests, 1e-6 relative on jerk: manual motion is not re-timed), the
/// stream led by `start` at rest; indices consecutive; velocity the motion's own at the
/// set-point's instant; the last set-point at rest.
fn check_stream(exec: &Executor, start: &Joints, out: &[Produced]) {
    let pm = exec.machine();
    let ts = exec.period();
    let first = out[0].setpoint.index;
    for (k, p) in out.iter().enumerate() {
        assert_eq!(p.setpoint.index, first + k as u64, "indices consecutive");
        assert_eq!(p.setpoint.line, 0, "manual motion is outside a program");
    }
    let last = &out[out.len() - 1].setpoint;
    assert!(
        last.velocity.as_slice().iter().all(|v| *v == 0.0),
        "ends at rest"
    );
    assert!(last.acceleration.as_slice().iter().all(|v| *v == 0.0));
    for j in 0..start.len() {
        let mut x = vec![start[j]; 3];
        x.extend(out.iter().map(|p| p.setpoint.position[j]));
        x.extend([x[x.len() - 1]; 3]);
        let d1: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
        let d2: Vec<f64> = d1.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
        let d3: Vec<f64> = d2.windows(2).map(|w| (w[1] - w[0]) / ts).collect();
        let vmax = d1.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let amax = d2.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let jmax = d3.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        // rounding of positions ~1e-13 mm amplified by 8/Ts³
        let slack = 8.0 * 1e-13 / ts.powi(3);
        assert!(vmax <= pm.max_velocity[j] * 1.005, "joint {j}: v {vmax}");
        assert!(
            amax <= pm.max_acceleration[j] * 1.005,
            "joint {j}: a {amax}"
        );
        assert!(
            jmax <= pm.max_jerk[j] * (1.0 + 1e-6) + slack,
            "joint {j}: j {jmax} / {}",
            pm.max_jerk[j]
        );
        // The set-point's velocity is the motion's own at its instant: the central difference
        // (x has 3 rest values first) differs from it by at most J·Ts²/6 for any motion with
        // |jerk| ≤ J (Taylor with the remainder's bound; a backward difference would be
        // half a period late, a·Ts/2 off).
        for (k, p) in out[..out.len() - 1].iter().enumerate() {
            let v = (x[k + 4] - x[k + 2]) / (2.0 * ts);
            let bound = pm.max_jerk[j] * ts * ts / 6.0 * (1.0 + 1e-6) + slack * ts * ts;
            assert!(
                (p.setpoint.velocity[j] - v).abs() <= bound,
                "joint {j} period {k}: velocity {} vs {v}",
                p.setpoint.velocity[j]
            );
        }
    }
}

fn joints(exec: &Executor) -> Joints {
    Joints::from_slice(&exec.status().joints).unwrap()
}

fn mill3_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../machines/mill3.toml"
    ))
    .unwrap()
}

#[test]
fn jog_starts_cruises_and_stops_in_the_jerk_limited_distance() {
    let mut exec = executor();
    let start = joints(&exec);
    exec.command(Command::Jog {
        joint: 0,
        direction: Direction::Plus,
        speed: Some(50.0),
    })
    .unwrap();
    assert_eq!(exec.status().mode, Mode::Jog);
    let mut at_stop = None;
    let out = play(&mut exec, 10_000, |k, e| {
        if k == 300 {
            at_stop = Some(e.status().joints[0]);
            e.command(Command::JogStop).unwrap();
        }
    });
    check_stream(&exec, &start, &out);
    // Cruise at 50 mm/s before the stop.
    let v = out[298].setpoint.velocity[0];
    assert!((v - 50.0).abs() < 1e-9, "cruise {v}");
    // From cruise at v (no acceleration), the time-optimal stop: a peak of √(vJ) ≤ A is
    // reached, so the distance is v·√(v/J) (J = 50 000 mm/s³ on mill3's x): 1.5811 mm.
    let rest = exec.status().joints[0];
    let d = rest - at_stop.unwrap();
    assert!(
        (d - 50.0 * (50.0_f64 / 50_000.0).sqrt()).abs() < 1e-9,
        "stop {d}"
    );
    // Only x moved; idle afterwards, and the tip follows the joints.
    assert_eq!(exec.status().joints[1..], start.as_slice()[1..]);
    assert_eq!(exec.state(), RunState::Idle);
    assert!((exec.status().tip[0] - rest).abs() < 1e-12);
}

#[test]
fn jog_to_the_soft_limit_stops_on_it_and_further_jogs_that_way_are_refused() {
    let m = Machine::default_machine();
    let mut exec = Executor::new(
        &m,
        ExecOptions::for_machine(&m),
        Pose::new(190.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    )
    .unwrap();
    let start = joints(&exec);
    exec.command(Command::JogOverride { percent: 200.0 })
        .unwrap();
    exec.command(Command::Jog {
        joint: 0,
        direction: Direction::Plus,
        speed: None,
    })
    .unwrap();
    let out = play(&mut exec, 10_000, |_, _| {});
    check_stream(&exec, &start, &out);
    // Default 50 mm/s at 200 %: 100 mm/s reached before braking.
    let top = out
        .iter()
        .fold(0.0_f64, |m, p| m.max(p.setpoint.velocity[0]));
    assert!((top - 100.0).abs() < 1e-6, "top speed {top}");
    assert!(out.iter().all(|p| p.setpoint.position[0] <= 200.0));
    assert!((exec.status().joints[0] - 200.0).abs() < 1e-9);
    // The stop at the limit ends the jog; releasing the key afterwards is harmless.
    exec.command(Command::JogStop).unwrap();
    let e = exec
        .command(Command::Jog {
            joint: 0,
            direction: Direction::Plus,
            speed: None,
        })
        .unwrap_err();
    assert!(e.to_string().contains("soft limit"), "{e}");
    // Either override out of 0–200 % is refused by the one check and changes nothing.
    let before = exec.status();
    let e = exec
        .command(Command::JogOverride { percent: 250.0 })
        .unwrap_err();
    assert!(matches!(e, ExecError::Override(_)), "{e}");
    let e = exec
        .command(Command::FeedOverride { percent: f64::NAN })
        .unwrap_err();
    assert!(e.to_string().contains("outside 0–200 %"), "{e}");
    let after = exec.status();
    assert_eq!(
        (after.jog_override_percent, after.feed_override_percent),
        (before.jog_override_percent, before.feed_override_percent)
    );
}

#[test]
fn increments_land_exactly() {
    let mut exec = executor();
    let start = joints(&exec);
    let mut expected = start[1];
    let mut all = Vec::new();
    for (dir, step) in [
        (Direction::Plus, 0.1),
        (Direction::Plus, 0.1),
        (Direction::Plus, 0.1),
        (Direction::Minus, 0.0001),
        (Direction::Minus, 0.01),
        (Direction::Plus, 0.001),
    ] {
        exec.command(Command::Increment {
            joint: 1,
            direction: dir,
            step,
        })
        .unwrap();
        let out = play(&mut exec, 1000, |_, _| {});
        expected += dir.sign() * step;
        assert_eq!(exec.status().joints[1], expected, "after {step}");
        assert_eq!(out.last().unwrap().setpoint.position[1], expected);
        if step == 0.1 {
            // Rest to rest in 4·(d/2J)^{1/3} = 40 ms for 0.1 mm at J = 50 000 (no plateau):
            // 40 moving periods and the rest set-point.
            assert_eq!(out.len(), 41);
        }
        all.extend(out);
    }
    check_stream(&exec, &start, &all);
    assert_eq!(exec.status().mode, Mode::Inc);
    for bad in [0.00005, 0.2, -0.1, f64::NAN] {
        exec.command(Command::Increment {
            joint: 1,
            direction: Direction::Plus,
            step: bad,
        })
        .unwrap_err();
    }
    assert!(matches!(
        exec.command(Command::Increment {
            joint: 7,
            direction: Direction::Plus,
            step: 0.1,
        }),
        Err(ExecError::Manual(_))
    ));
    assert_eq!(exec.state(), RunState::Idle);
}

/// mill3 powered on with its drives reading machine position plus `offset`.
fn homing(offset: [f64; 3]) -> (Executor, Vec<Produced>, Joints) {
    let m = Machine::default_machine();
    let mut exec = executor();
    let offset = Joints::from_slice(&offset).unwrap();
    exec.set_switches(Box::new(SimulatedSwitches::new(&m, &offset).unwrap()));
    let start = exec.drive_joints();
    assert!(!exec.status().homed);
    exec.command(Command::Home).unwrap();
    let out = play(&mut exec, 200_000, |_, _| {});
    (exec, out, start)
}

#[test]
fn homing_runs_z_first_and_applies_the_offsets_without_a_jump() {
    let (mut exec, out, start) = homing([12.3, -4.5, 7.0]);
    check_stream(&exec, &start, &out);
    let st = exec.status();
    assert!(st.homed && st.error.is_none() && st.state == RunState::Idle);
    // The offsets found: latched once per period at 2 mm/s, late by at most 2e-3 mm.
    let found = exec.homing_offsets();
    eprintln!(
        "homing: {} periods, offsets found {:?}",
        out.len(),
        found.as_slice()
    );
    for (i, want) in [12.3, -4.5, 7.0].iter().enumerate() {
        assert!((found[i] - want).abs() <= 2e-3, "joint {i}: {}", found[i]);
    }
    // The machine stands at the home positions (machine frame), the drives at home + offset:
    // the last set-point equals the one before (homing ended there at rest).
    let home = [0.0, 0.0, 0.0];
    for (i, h) in home.iter().enumerate() {
        assert!(
            (st.joints[i] - h).abs() < 1e-9,
            "joint {i}: {}",
            st.joints[i]
        );
    }
    let n = out.len();
    assert_eq!(out[n - 1].setpoint.position, out[n - 2].setpoint.position);
    for i in 0..3 {
        assert!((out[n - 1].setpoint.position[i] - found[i]).abs() < 1e-9);
    }
    // Order: z moves alone first, then x, then y (mill3's sequence; z by default first).
    let first_move = |j: usize| {
        out.iter()
            .position(|p| p.setpoint.position[j] != start[j])
            .unwrap()
    };
    let last_move = |j: usize| {
        out.iter()
            .rposition(|p| p.setpoint.velocity[j] != 0.0)
            .unwrap()
    };
    assert!(last_move(2) < first_move(0), "z before x");
    assert!(last_move(0) < first_move(1), "x before y");
    // After homing, manual moves and programs run in the machine frame; the drives get the
    // offset added.
    exec.command(Command::Increment {
        joint: 0,
        direction: Direction::Plus,
        step: 0.1,
    })
    .unwrap();
    let inc = play(&mut exec, 1000, |_, _| {});
    assert_eq!(exec.status().joints[0], st.joints[0] + 0.1);
    let drive = inc.last().unwrap().setpoint.position[0];
    assert!((drive - (st.joints[0] + 0.1 + found[0])).abs() < 1e-12);
    exec.command(Command::Mdi {
        block: "G0 X10 Y5".into(),
    })
    .unwrap();
    let mdi = play(&mut exec, 10_000, |_, _| {});
    let end = mdi.last().unwrap();
    assert!((end.tip - tezgah_geom::Vec3::new(10.0, 5.0, 0.0)).norm() < 1e-6);
    assert!((end.setpoint.position[0] - (10.0 + found[0])).abs() < 1e-6);
    assert!((exec.status().joints[0] - 10.0).abs() < 1e-6);
}

#[test]
fn a_hold_or_abort_during_homing_stops_jerk_limited_and_leaves_it_unhomed() {
    for command in [Command::FeedHold, Command::Abort] {
        let m = Machine::default_machine();
        let mut exec = executor();
        let offset = Joints::from_slice(&[3.0, 2.0, 1.0]).unwrap();
        exec.set_switches(Box::new(SimulatedSwitches::new(&m, &offset).unwrap()));
        let start = exec.drive_joints();
        exec.command(Command::Home).unwrap();
        // z searches at its speed: stop it mid-way.
        let out = play(&mut exec, 200_000, |k, e| {
            if k == 2000 {
                e.command(command.clone()).unwrap();
            }
        });
        check_stream(&exec, &start, &out);
        assert!(
            out.len() < 2100,
            "stopped within a few periods: {}",
            out.len()
        );
        let st = exec.status();
        assert!(!st.homed && st.state == RunState::Idle);
        assert_eq!(exec.homing_offsets().as_slice(), &[0.0; 3]);
    }
}

#[test]
fn a_missing_switch_stops_homing_with_the_joint_named() {
    // z's switch beyond its travel: the search gives up after 1.1 × the travel.
    let text = mill3_text();
    let m = Machine::from_toml_str(&text).unwrap();
    let mut exec = Executor::new(&m, ExecOptions::for_machine(&m), Pose::ZERO).unwrap();
    let offset = Joints::from_slice(&[0.0, 0.0, 1000.0]).unwrap();
    exec.set_switches(Box::new(SimulatedSwitches::new(&m, &offset).unwrap()));
    let start = exec.drive_joints();
    exec.command(Command::Home).unwrap();
    let out = play(&mut exec, 400_000, |_, _| {});
    check_stream(&exec, &start, &out);
    let st = exec.status();
    assert!(!st.homed && st.state == RunState::Idle);
    let err = st.error.expect("the error stays shown");
    assert!(err.contains("`z`") && err.contains("switch"), "{err}");
}

#[test]
fn commands_are_refused_while_moving() {
    let mut exec = executor();
    exec.command(Command::Load {
        program: "G1 X20 F600\nM2\n".into(),
    })
    .unwrap();
    exec.command(Command::CycleStart).unwrap();
    exec.step().unwrap();
    let jog = Command::Jog {
        joint: 0,
        direction: Direction::Plus,
        speed: None,
    };
    let inc = Command::Increment {
        joint: 0,
        direction: Direction::Plus,
        step: 0.1,
    };
    for c in [jog.clone(), inc.clone(), Command::Home] {
        let e = exec.command(c).unwrap_err();
        assert!(e.to_string().ends_with("while running"), "{e}");
    }
    assert_eq!(
        exec.command(Command::JogStop).unwrap_err(),
        ExecError::NotJogging
    );
    exec.command(Command::Abort).unwrap();
    play(&mut exec, 10_000, |_, _| {});

    exec.command(jog).unwrap();
    exec.step().unwrap();
    for c in [
        Command::Load {
            program: "G0 X1\n".into(),
        },
        Command::CycleStart,
        Command::Mdi {
            block: "G0 X1".into(),
        },
        Command::RestartFrom { line: 1 },
        inc,
        Command::Home,
    ] {
        let e = exec.command(c).unwrap_err();
        assert!(e.to_string().ends_with("while jogging"), "{e}");
    }
    assert_eq!(exec.state(), RunState::Running);
    exec.command(Command::FeedHold).unwrap();
    play(&mut exec, 10_000, |_, _| {});
    assert_eq!(exec.state(), RunState::Idle);
}

#[test]
fn auto_waits_for_homing_only_if_the_machine_file_asks() {
    let text = mill3_text().replace("home_required = false", "home_required = true");
    let m = Machine::from_toml_str(&text).unwrap();
    assert!(m.motion.home_required);
    let mut exec = Executor::new(&m, ExecOptions::for_machine(&m), Pose::ZERO).unwrap();
    exec.command(Command::Load {
        program: "G0 X1\nM2\n".into(),
    })
    .unwrap();
    for c in [
        Command::CycleStart,
        Command::RestartFrom { line: 1 },
        Command::Mdi {
            block: "G0 X1".into(),
        },
    ] {
        let e = exec.command(c).unwrap_err();
        assert!(matches!(e, ExecError::NotHomed { .. }), "{e}");
    }
    // Manual motion is allowed before homing.
    exec.command(Command::Increment {
        joint: 0,
        direction: Direction::Plus,
        step: 0.1,
    })
    .unwrap();
    play(&mut exec, 1000, |_, _| {});
    exec.command(Command::Home).unwrap();
    play(&mut exec, 200_000, |_, _| {});
    assert!(exec.status().homed);
    exec.command(Command::CycleStart).unwrap();
    play(&mut exec, 10_000, |_, _| {});
    assert!((exec.status().tip[0] - 1.0).abs() < 1e-9);
    // The default machine file does not ask.
    assert!(!Machine::default_machine().motion.home_required);
}

#[test]
fn a_program_past_a_limit_is_refused_at_load_and_nothing_moves() {
    let mut exec = executor();
    let before = exec.status();
    let e = exec
        .command(Command::Load {
            program: "G1 X50 F1000\nG1 Y20\nG1 X250\nM2\n".into(),
        })
        .unwrap_err();
    match &e {
        ExecError::Preflight { at, message } => {
            assert_eq!((at.file.as_str(), at.span.line), ("program", 3));
            assert!(
                message.contains('x') || message.contains("limit"),
                "{message}"
            );
        }
        other => panic!("{other}"),
    }
    let after = exec.status();
    assert!(!after.program_loaded);
    assert_eq!(after.index, before.index);
    assert_eq!(after.joints, before.joints);
    assert_eq!(
        exec.command(Command::CycleStart).unwrap_err(),
        ExecError::NoProgram
    );
    assert!(exec.step().unwrap().is_none());
    // MDI too, before it moves.
    let e = exec
        .command(Command::Mdi {
            block: "G0 X300".into(),
        })
        .unwrap_err();
    assert!(matches!(e, ExecError::Preflight { .. }), "{e}");
    assert!(exec.step().unwrap().is_none());
    assert_eq!(exec.state(), RunState::Idle);
    // A reachable program still runs.
    let mut trace = Trace::new(&exec);
    run_program(&mut exec, &mut trace, "G1 X50 F1000\nG1 Y20\nM2\n");
    let (_, report) = trace.report();
    assert_within_limits(&report);
}

/// Subroutine files held in memory: (name, text).
#[derive(Debug)]
struct Files(Vec<(&'static str, String)>);

impl SubroutineLibrary for Files {
    fn source(&self, name: &str) -> Option<String> {
        self.0
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, t)| t.clone())
    }
}

/// Loads a program whose line 4 calls subroutine `far`, with `body` as the file's lines 2 on;
/// the program's line 3 is blank, so an error that took the file's line 3 for the program's
/// would show. The load must be refused and leave nothing loaded.
fn load_with_sub(body: &str) -> ExecError {
    let file = format!("o<far> sub\n{body}o<far> endsub\nM2\n");
    let mut exec = executor().with_subroutines(Arc::new(Files(vec![("far", file)])));
    let e = exec
        .command(Command::Load {
            program: "G21 G90\nF1000\n\no<far> call\nM2\n".into(),
        })
        .unwrap_err();
    assert!(!exec.status().program_loaded, "{e}");
    e
}

#[test]
fn load_errors_inside_a_subroutine_file_name_that_file_line_and_column() {
    // The pre-flight: line 3 of far.ngc leaves mill3's X range [-200, 200]; its first word is
    // in column 3, byte 2 of the line, which starts at byte 11 + 7 of the file.
    let e = load_with_sub("G1 X10\n  G1 X5000\n");
    let ExecError::Preflight { at, message } = &e else {
        panic!("{e}");
    };
    let span = Span {
        line: 3,
        column: 3,
        offset: 20,
    };
    assert_eq!(
        at,
        &Located {
            file: "far.ngc".into(),
            span
        }
    );
    assert!(message.contains("outside its limits [-200, 200]"), "{e}");
    assert!(
        e.to_string()
            .starts_with("far.ngc:3:3: out of reach before anything moves: joint 0 (`x`)"),
        "{e}"
    );
    // The interpreter: `Y` without a value on the file's line 3, column 8.
    let e = load_with_sub("G1 X10\nG1 X5 Y\n");
    assert_eq!(
        e.to_string(),
        "far.ngc:3:8: No characters found in reading real value \
         (in a subroutine called from program)"
    );
}

#[test]
fn manual_commands_round_trip_as_json() {
    let c = Command::Jog {
        joint: 2,
        direction: Direction::Minus,
        speed: None,
    };
    let text = serde_json::to_string(&c).unwrap();
    assert_eq!(
        text,
        r#"{"command":"jog","joint":2,"direction":"minus","speed":null}"#
    );
    let back: Command =
        serde_json::from_str(r#"{"command":"jog","joint":2,"direction":"minus"}"#).unwrap();
    assert_eq!(back, c);
    let inc: Command =
        serde_json::from_str(r#"{"command":"increment","joint":0,"direction":"plus","step":0.01}"#)
            .unwrap();
    assert_eq!(
        inc,
        Command::Increment {
            joint: 0,
            direction: Direction::Plus,
            step: 0.01
        }
    );
    let home: Command = serde_json::from_str(r#"{"command":"home"}"#).unwrap();
    assert_eq!(home, Command::Home);
}

/// One step of a random manual session.
#[derive(Debug, Clone)]
enum Press {
    /// Jog `joint` one way at `speed`, override changes at chosen periods, stop after `hold`.
    Jog {
        joint: usize,
        plus: bool,
        speed: f64,
        overrides: Vec<(usize, f64)>,
        hold: usize,
    },
    Inc {
        joint: usize,
        plus: bool,
        step: f64,
    },
}

fn press() -> impl Strategy<Value = Press> {
    prop_oneof![
        (
            0usize..3,
            any::<bool>(),
            1.0..250.0f64,
            proptest::collection::vec((0usize..400, 0.0..200.0f64), 0..4),
            0usize..600
        )
            .prop_map(|(joint, plus, speed, overrides, hold)| Press::Jog {
                joint,
                plus,
                speed,
                overrides,
                hold
            }),
        (0usize..3, any::<bool>(), 0.0001..0.1f64).prop_map(|(joint, plus, step)| Press::Inc {
            joint,
            plus,
            step
        }),
    ]
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random jogs (speeds, override steps, stops, soft limits met on the way) and increments
    /// from a random start: every joint within its limits at every period, never past a soft
    /// limit, the stream consecutive, idle after every press, increments exact.
    #[test]
    fn random_manual_sessions_keep_the_limits(
        start in (-150.0..150.0f64, -100.0..100.0f64, -60.0..60.0f64),
        presses in proptest::collection::vec(press(), 1..6),
    ) {
        let m = Machine::default_machine();
        let mut exec = Executor::new(
            &m,
            ExecOptions::for_machine(&m),
            Pose::new(start.0, start.1, start.2, 0.0, 0.0, 0.0),
        )
        .unwrap();
        let first = joints(&exec);
        let mut all = Vec::new();
        for p in presses {
            let dir = |plus: bool| if plus { Direction::Plus } else { Direction::Minus };
            match p {
                Press::Jog { joint, plus, speed, overrides, hold } => {
                    if exec.command(Command::Jog { joint, direction: dir(plus), speed: Some(speed) }).is_err() {
                        continue; // on the limit already
                    }
                    all.extend(play(&mut exec, 1_000_000, |k, e| {
                        for &(at, pct) in &overrides {
                            if k == at {
                                e.command(Command::JogOverride { percent: pct }).unwrap();
                            }
                        }
                        if k == hold {
                            e.command(Command::JogStop).unwrap();
                        }
                    }));
                    exec.command(Command::JogOverride { percent: 100.0 }).unwrap();
                }
                Press::Inc { joint, plus, step } => {
                    let before = exec.status().joints[joint];
                    if exec.command(Command::Increment { joint, direction: dir(plus), step }).is_err() {
                        continue; // past a soft limit
                    }
                    all.extend(play(&mut exec, 10_000, |_, _| {}));
                    let want = before + if plus { step } else { -step };
                    prop_assert_eq!(exec.status().joints[joint], want);
                }
            }
            prop_assert_eq!(exec.state(), RunState::Idle);
        }
        if !all.is_empty() {
            check_stream(&exec, &first, &all);
        }
        for p in &all {
            for (j, q) in p.setpoint.position.as_slice().iter().enumerate() {
                let joint = &m.joints[j];
                prop_assert!(*q >= joint.min && *q <= joint.max, "joint {} at {}", j, q);
            }
        }
    }
}
