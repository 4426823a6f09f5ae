//! Words of the Fanuc dialect that LinuxCNC lacks: the `G05.1` smoothing switch.

use tezgah_gcode::{program_moves, Config, ErrorKind};
use tezgah_geom::MoveKind;

#[test]
fn g05_1_q_switches_smoothing_and_keeps_the_motion_mode() {
    let moves = program_moves(
        "G21 G1 X1 F100\nG05.1 Q1\nX2\nG5.1 Q0\nX3\nM2\n",
        Config::default(),
    )
    .unwrap();
    let kinds: Vec<_> = moves
        .iter()
        .filter_map(|m| match m.kind {
            MoveKind::Smoothing(on) => Some(("smoothing", on as u8 as f64, m.line)),
            MoveKind::Feed { end } => Some(("feed", end.0[0], m.line)),
            _ => None,
        })
        .collect();
    assert_eq!(
        kinds,
        vec![
            ("feed", 1.0, 1),
            ("smoothing", 1.0, 2),
            // G1 stays in force across the switch.
            ("feed", 2.0, 3),
            ("smoothing", 0.0, 4),
            ("feed", 3.0, 5),
        ]
    );
}

#[test]
fn g05_1_needs_q0_or_q1_and_g5_1_with_ij_is_the_spline() {
    let err = program_moves("G05.1 Q2\nM2\n", Config::default()).unwrap_err();
    assert_eq!(err.kind, ErrorKind::SmoothingQ);
    // With I and J it is LinuxCNC's quadratic spline: one NURBS move of degree 2.
    let moves = program_moves("G21 F10\nG5.1 X1 Y1 I1 J0\nM2\n", Config::default()).unwrap();
    let spline = moves.iter().find_map(|m| match &m.kind {
        MoveKind::Nurbs(n) => Some(n.curve.degree()),
        _ => None,
    });
    assert_eq!(spline, Some(2));
}

#[test]
fn splines_are_refused_under_cutter_compensation() {
    for spline in [
        "G5 I1 J0 P-1 Q0 X10 Y0",
        "G5.1 I1 J1 X10 Y0",
        "G5.2 X1 Y1 P1\nX2 Y0 P1\nX3 Y1 P1\nG5.3",
        "G6.2 P3 K0 X0 Y0 Z0\nK0 X1 Y1 Z0\nK0 X2 Y0 Z0\nK1\nK1\nK1",
    ] {
        let program = format!("G21 G0 X0 Y0\nG41.1 D1\nF100\n{spline}\nM2\n");
        let err = tezgah_gcode::Interpreter::new(tezgah_gcode::Config::default())
            .run(
                &program,
                &mut Vec::<(tezgah_gcode::Origin, tezgah_gcode::Canon)>::new(),
            )
            .expect_err(spline);
        assert_eq!(
            err.kind.to_string(),
            "Cannot convert spline with cutter radius compensation",
            "{spline}"
        );
        assert_eq!(err.span.line, 4, "{spline}");
    }
}

/// `EQ` and `NE` compare within LinuxCNC 2.9's `TOLERANCE_EQUAL`, 0.0001 (rs274 found
/// `EXP[-9.2104] EQ SIN[0]` true, e^−9.2104 being 0.99994e-4).
#[test]
fn eq_and_ne_compare_within_a_ten_thousandth() {
    let cases = [
        ("[EXP[-9.2104] EQ SIN[0]]", 1.0),
        ("[0.0002 EQ 0]", 0.0),
        ("[0.00009 NE 0]", 0.0),
        ("[0.0001 NE 0]", 1.0),
        ("[-0.00005 EQ 0.00004]", 1.0),
    ];
    for (expr, want) in cases {
        let program = format!("#1 = {expr}\n(DEBUG,#1)\nM2\n");
        let mut calls: Vec<(tezgah_gcode::Origin, tezgah_gcode::Canon)> = Vec::new();
        tezgah_gcode::Interpreter::new(tezgah_gcode::Config::default())
            .run(&program, &mut calls)
            .unwrap();
        let shown = calls
            .iter()
            .find_map(|(_, c)| match c {
                tezgah_gcode::Canon::Message(m) => Some(m.clone()),
                _ => None,
            })
            .unwrap();
        assert_eq!(shown, format!("{want:.6}"), "{expr}");
    }
}

/// A text that ends without M2, M30 or `%` runs every move and ends as if `M2` followed its
/// last line (LinuxCNC's milltask runs the moves, then reports); `rs274`'s behaviour, the
/// error, stays with `MissingEnd::Error` (`Config::linuxcnc`, what `canon` uses).
#[test]
fn a_missing_program_end_runs_as_m2() {
    use tezgah_gcode::{Canon, GcodeError, Interpreter, MissingEnd, Origin};
    let program = "G21 G90 M3 S1000\nG1 X10 F100\nG1 Y5\n";
    let mut calls: Vec<(Origin, Canon)> = Vec::new();
    let mut interp = Interpreter::new(Config::default());
    interp.run(program, &mut calls).unwrap();
    // The moves, then M2's resets: spindle stopped, feed zeroed, program end.
    let tail: Vec<&Canon> = calls.iter().rev().take(4).map(|(_, c)| c).collect();
    assert!(matches!(tail[0], Canon::ProgramEnd), "{tail:?}");
    assert!(calls.iter().any(|(_, c)| matches!(c, Canon::StopSpindle)));
    let feeds = calls
        .iter()
        .filter(|(_, c)| matches!(c, Canon::StraightFeed(_)))
        .count();
    assert_eq!(feeds, 2);
    // The end's calls come from the last line.
    assert_eq!(calls.last().unwrap().0.line, 3);
    let missing: &GcodeError = interp.missing_end().unwrap();
    assert_eq!(missing.kind, ErrorKind::NoProgramEnd);
    assert_eq!((missing.span.line, missing.span.column), (3, 6));
    // With M2 there is nothing to say.
    let mut interp = Interpreter::new(Config::default());
    interp
        .run("G0 X1\nM2\n", &mut Vec::<(Origin, Canon)>::new())
        .unwrap();
    assert!(interp.missing_end().is_none());
    // rs274's behaviour.
    let cfg = Config {
        missing_end: MissingEnd::Error,
        ..Config::default()
    };
    let err = Interpreter::new(cfg)
        .run(program, &mut Vec::<(Origin, Canon)>::new())
        .unwrap_err();
    assert_eq!(
        err.kind.to_string(),
        "File ended with no percent sign or program end"
    );
    // An unclosed subroutine is still an error, M2 or not.
    let err = Interpreter::new(Config::default())
        .run("o100 sub\nG0 X1\n", &mut Vec::<(Origin, Canon)>::new())
        .unwrap_err();
    assert_ne!(err.kind, ErrorKind::NoProgramEnd);
}

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Every call tezgah makes for `data/<name>.ngc` with the tool table `<name>.tbl`, printed as
/// rs274 prints them (with its driver's two closing resets), and the error, if any.
fn our_rs274_calls(name: &str) -> (Vec<String>, Option<String>) {
    use tezgah_gcode::{Canon, Interpreter, Origin, ToolTable};
    let program = std::fs::read_to_string(data(&format!("{name}.ngc"))).unwrap();
    let table = std::fs::read_to_string(data(&format!("{name}.tbl"))).unwrap();
    let config = Config::linuxcnc(ToolTable::parse(&table).unwrap());
    let mut calls = Vec::<(Origin, Canon)>::new();
    let result = Interpreter::new(config).run(&program, &mut calls);
    let mut printed: Vec<String> = calls.iter().map(|(_, c)| c.to_string()).collect();
    printed.extend(["ON_RESET()".to_owned(), "ON_RESET()".to_owned()]);
    (printed, result.err().map(|e| e.kind.to_string()))
}

/// `data/<name>.expected`: what LinuxCNC 2.9's `rs274` printed for the program (call number
/// and N field dropped). With `TEZGAH_RS274` set, rs274 runs again and must still print it.
fn rs274_expected(name: &str) -> Vec<String> {
    let expected: Vec<String> = std::fs::read_to_string(data(&format!("{name}.expected")))
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect();
    if let Some(rs274) = std::env::var_os("TEZGAH_RS274") {
        // One rs274 at a time: its tool data lives in memory shared between its processes.
        static RS274: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let _one = RS274.lock().unwrap_or_else(|e| e.into_inner());
        // rs274 writes its parameter file where it runs: a folder of its own per program.
        let dir =
            std::env::temp_dir().join(format!("tezgah-dialect-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = std::process::Command::new(rs274)
            .current_dir(&dir)
            .arg("-t")
            .arg(data(&format!("{name}.tbl")))
            .arg("-g")
            .arg(data(&format!("{name}.ngc")))
            .stdin(std::process::Stdio::null())
            .output()
            .expect("run rs274");
        let _ = std::fs::remove_dir_all(&dir);
        let theirs: Vec<String> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter_map(|l| l.find(" N..... ").map(|i| l[i + 8..].to_owned()))
            .collect();
        assert_eq!(theirs, expected, "rs274 no longer prints {name}.expected");
    }
    expected
}

/// M70 saves, M71 forgets, M72 restores the modal state and M73 restores it when the
/// subroutine returns: every canonical call (the restoring codes in rs274's order, F restored
/// as LinuxCNC prints it, `F10.2` for 10.25) and the `#<_…>` parameters read after each
/// restore agree with rs274 call for call.
#[test]
fn m70_to_m73_match_rs274_call_for_call() {
    let expected = rs274_expected("modal_state");
    assert_eq!(expected.len(), 107, "the expected file is whole");
    let (ours, error) = our_rs274_calls("modal_state");
    assert_eq!(error, None);
    for (k, (a, b)) in expected.iter().zip(&ours).enumerate() {
        assert_eq!(b, a, "call {}", k + 1);
    }
    assert_eq!(ours.len(), expected.len());
}

/// M72 also restores whether the G92/G52 offsets are applied (G92.2 / G92.3, as rs274 2.9
/// does): `data/m7_g92.ngc` agrees with rs274's 30 calls and its `#5210`, `#5211`.
#[test]
fn m72_restores_the_g92_state_as_rs274() {
    let expected = rs274_expected("m7_g92");
    assert_eq!(expected.len(), 30, "the expected file is whole");
    let (ours, error) = our_rs274_calls("m7_g92");
    assert_eq!(error, None);
    assert_eq!(ours, expected);
}

/// M72 with nothing saved at its call level, M71's invalidation, and M70 in the spindle's
/// modal group: LinuxCNC's errors, at the M word.
#[test]
fn m72_without_a_saved_state_fails_as_linuxcnc() {
    use tezgah_gcode::{Canon, Interpreter, Origin};
    let run = |program: &str| {
        Interpreter::new(Config::linuxcnc(Default::default()))
            .run(program, &mut Vec::<(Origin, Canon)>::new())
            .unwrap_err()
    };
    let none = "Cannot restore context from invalid stack frame - missing M70/M73?";
    let err = run("G21\nF10 M72\nM2\n");
    assert_eq!(
        (
            err.kind.to_string().as_str(),
            err.span.line,
            err.span.column
        ),
        (none, 2, 5)
    );
    assert_eq!(run("M70\nM71\nM72\nM2\n").kind.to_string(), none);
    // Saved in the caller, not at the subroutine's level.
    let sub = "o1 sub\nM72\no1 endsub\nM70\no1 call\nM2\n";
    assert_eq!(run(sub).kind.to_string(), none);
    assert_eq!(
        run("M3 M70\nM2\n").kind.to_string(),
        "Two m codes used from same modal group"
    );
}

/// Polar coordinates (`@` radius, `^` angle): absolute and G91 lines, R and I J arcs, G81
/// and G83 in G90 and G91 with L repeats going round a circle. Every call agrees with
/// rs274's 147.
#[test]
fn polar_coordinates_match_rs274_call_for_call() {
    let expected = rs274_expected("polar");
    assert_eq!(expected.len(), 147, "the expected file is whole");
    let (ours, error) = our_rs274_calls("polar");
    assert_eq!(error, None);
    for (k, (a, b)) in expected.iter().zip(&ours).enumerate() {
        assert_eq!(b, a, "call {}", k + 1);
    }
    assert_eq!(ours.len(), expected.len());
}

/// Each polar-coordinate refusal with LinuxCNC's text (as rs274 printed it).
#[test]
fn polar_coordinate_errors_are_linuxcnc_s() {
    use tezgah_gcode::{Canon, Interpreter, Origin};
    let cases = [
        (
            "G18\nG1 @1 F10",
            "Cannot use polar coordinate except in G17 plane",
        ),
        (
            "G1 X1 @1 F10",
            "Cannot specify both polar coordinate and X word",
        ),
        (
            "G1 Y1 ^1 F10",
            "Cannot specify both polar coordinate and Y word",
        ),
        ("G92 @1", "Polar coordinates can only be used for motion"),
        (
            "G10 L2 P1 @1",
            "Polar coordinates can only be used for motion",
        ),
        (
            "@1",
            "Cannot use axis values without a g code that uses them",
        ),
        ("G80 @1", "Cannot use axis values with g80"),
        ("G53 G0 @1 ^3", "Cannot use polar coordinates with G53"),
        (
            "G1 @1 F10",
            "Must specify angle in polar coordinate if at the origin",
        ),
        (
            "G91 G1 @1 F10",
            "Incremental motion with polar coordinates is indeterminate when at the origin",
        ),
        (
            "G91 G1 ^1 F10",
            "G91 motion with polar coordinates is indeterminate when at the origin",
        ),
        (
            "G0 Z2\nG91 G81 @1 R1 Z-1 F10",
            "Incremental motion with polar coordinates is indeterminate when at the origin",
        ),
    ];
    for (program, text) in cases {
        let err = Interpreter::new(Config::linuxcnc(Default::default()))
            .run(
                &format!("{program}\nM2\n"),
                &mut Vec::<(Origin, Canon)>::new(),
            )
            .expect_err(program);
        assert_eq!(err.kind.to_string(), text, "{program}");
    }
    // The place of the error: the `@` word, line 2 column 4.
    let err = Interpreter::new(Config::default())
        .run("G18\nG1 @1 F10\nM2\n", &mut Vec::<(Origin, Canon)>::new())
        .unwrap_err();
    assert_eq!((err.span.line, err.span.column), (2, 4));
}

/// A cutter-compensation entry move (or entry arc) exactly one tool radius long is accepted,
/// as rs274 2.9 accepts it in LinuxCNC's `useful-subroutines.ngc` (`g41 g0` onto the edge of
/// a hole the size of the tool): the tool centre ends on the contour's normal, and every
/// call agrees with rs274's 48. A shorter one is still refused.
#[test]
fn comp_entry_one_radius_long_is_accepted_as_rs274() {
    use tezgah_gcode::{Canon, Interpreter, Origin, ToolTable};
    let expected = rs274_expected("comp_entry");
    assert_eq!(expected.len(), 48, "the expected file is whole");
    let (ours, error) = our_rs274_calls("comp_entry");
    assert_eq!(error, None);
    for (k, (a, b)) in expected.iter().zip(&ours).enumerate() {
        assert_eq!(b, a, "call {}", k + 1);
    }
    assert_eq!(ours.len(), expected.len());
    let table = ToolTable::parse("T1 P1 Z0.511 D0.125\n").unwrap();
    for entry in ["G41 G0 X0 Y0", "G41 G1 X0 Y0", "G41 G2 X0 Y0 R0.5"] {
        let program = format!("G20 T1 M6 F10\nG0 X0.06 Y0\n{entry}\nG40 G0 X1\nM2\n");
        let err = Interpreter::new(Config::linuxcnc(table.clone()))
            .run(&program, &mut Vec::<(Origin, Canon)>::new())
            .expect_err(entry);
        assert!(
            err.kind
                .to_string()
                .ends_with("is not greater than the tool radius"),
            "{entry}: {}",
            err.kind
        );
    }
    // A hole smaller than the tool is still refused (one of its size is filled).
    let program = "G20 T1 M6 F10\nG0 X0.2 Y0.06\nG41 G0 X0 Y0.06\nG3 X0 Y0.06 I0 J-0.06\nM2\n";
    let err = Interpreter::new(Config::linuxcnc(table))
        .run(program, &mut Vec::<(Origin, Canon)>::new())
        .unwrap_err();
    assert_eq!(
        err.kind.to_string(),
        "Tool radius not less than arc radius with comp"
    );
}

/// G38.2–G38.5 under `ProbeModel::Rs274` (what `canon` uses): the probe calls, `#5061`…
/// `#5070` and the position after each probe agree with rs274's 44 calls (its probe never
/// trips and stops 0.01 in short of the target).
#[test]
fn probing_matches_rs274_call_for_call() {
    let expected = rs274_expected("probe");
    assert_eq!(expected.len(), 44, "the expected file is whole");
    let (ours, error) = our_rs274_calls("probe");
    assert_eq!(error, None);
    for (k, (a, b)) in expected.iter().zip(&ours).enumerate() {
        assert_eq!(b, a, "call {}", k + 1);
    }
    assert_eq!(ours.len(), expected.len());
}

/// LinuxCNC's probing errors; and where moves are made for a machine (the default
/// `ProbeModel::Unavailable`), a probe that passes them is refused at its G38 word rather
/// than run as a feed that never trips.
#[test]
fn probing_errors_are_linuxcnc_s_and_runs_refuse_probing() {
    use tezgah_gcode::{Canon, Interpreter, Origin};
    let cases = [
        ("G38.2 X1", "Cannot probe with zero feed rate"),
        ("F10 G38.2", "All axes missing with motion code"),
        ("F10 G38.2 X0", "Start point too close to probe point"),
        ("F10 G38.4 X0", "Start point too close to probe point"),
        (
            "F10 G41.1 D0.1 G0 X1\nG38.2 X2",
            "Cannot probe with cutter radius comp on",
        ),
        (
            "G95 F10 S100 M3 G38.2 X1",
            "Cannot probe with feed per rev mode",
        ),
        ("G93 G38.2 X1 F10", "Cannot probe with zero feed rate"),
    ];
    for (program, text) in cases {
        for config in [Config::linuxcnc(Default::default()), Config::default()] {
            let err = Interpreter::new(config)
                .run(
                    &format!("{program}\nM2\n"),
                    &mut Vec::<(Origin, Canon)>::new(),
                )
                .expect_err(program);
            assert_eq!(err.kind.to_string(), text, "{program}");
        }
    }
    // G38.3 to where it stands is no error for rs274.
    Interpreter::new(Config::linuxcnc(Default::default()))
        .run("F10 G38.3 X0\nM2\n", &mut Vec::<(Origin, Canon)>::new())
        .unwrap();
    let err = Interpreter::new(Config::default())
        .run(
            "G21 F100\nG38.2 Z-10\nM2\n",
            &mut Vec::<(Origin, Canon)>::new(),
        )
        .unwrap_err();
    assert_eq!(
        err.kind.to_string(),
        "G38.2 probing needs a probe: a machine file's [probe] (`tezgah run`, `serve`, MDI) or \
         `tezgah run --probe`; `check` does not probe"
    );
    assert_eq!((err.span.line, err.span.column), (2, 1));
}

/// The executor's hand-off (`ProbeModel::Answered`): a pass stops at the probe it has no
/// answer for; with the answer, `#5061`… hold the trip point in program coordinates (G54
/// offset and G91 included), `#5070` = 1, and the program reads on from where the machine
/// stopped; an untripped G38.2/G38.4 and a probe already in the sought state fail as in
/// LinuxCNC's motion controller, G38.3 goes on from the move's end with `#5070` = 0.
#[test]
fn probe_answers_drive_the_interpreter() {
    use std::sync::Arc;
    use tezgah_gcode::{Canon, Interpreter, Origin, ProbeModel, ProbeOutcome};
    // Z from 10 down to -10 in G54 (Z offset 5): the trip at a quarter of the way, z = 5.
    let program = "G21 G90 G10 L2 P1 Z5\nG0 X1 Z10\nF100 G38.2 Z-10\n\
                   G10 L20 P1 Z[#5063 - #5063]\nG91 G1 X[#5070] Z[#5061]\nM2\n";
    let run = |answers: &[ProbeOutcome]| {
        let config = Config {
            probe: ProbeModel::Answered(Arc::from(answers)),
            ..Config::default()
        };
        let mut interp = Interpreter::new(config);
        let mut calls = Vec::<(Origin, Canon)>::new();
        let result = interp.run(program, &mut calls);
        (result, interp, calls)
    };
    let (result, _, calls) = run(&[]);
    let err = result.unwrap_err();
    assert_eq!(
        err.kind.to_string(),
        "G38.2 probe move awaits the machine's answer"
    );
    assert_eq!(err.span.line, 3);
    assert!(matches!(calls.last(), Some((_, Canon::TurnProbeOff))));
    let tripped = ProbeOutcome::Tripped {
        at: 0.25,
        stopped: 0.3,
    };
    let (result, interp, calls) = run(&[tripped]);
    result.unwrap();
    let p = interp.params();
    assert_eq!((p.get(5061), p.get(5063), p.get(5070)), (1.0, 5.0, 1.0));
    // Stopped at 0.3 of the way (z = 4 in G54, 9 in machine Z); G10 L20 makes that Z0 of
    // G54, so the G91 move from there goes X+1 (#5070) and Z+1 (#5061).
    assert_eq!(p.get(5223), 9.0);
    let last = calls
        .iter()
        .rev()
        .find_map(|(_, c)| match c {
            Canon::StraightFeed(e) => Some(*e),
            _ => None,
        })
        .unwrap();
    assert_eq!((last.x(), last.z()), (2.0, 1.0));
    let failing = [
        (
            ProbeOutcome::Completed,
            "G38.2 move finished without making contact.",
        ),
        (
            ProbeOutcome::AlreadyThere,
            "Probe is already tripped when starting G38.2 or G38.3 move",
        ),
    ];
    for (outcome, text) in failing {
        let (result, _, _) = run(&[outcome]);
        let err = result.unwrap_err();
        assert_eq!((err.kind.to_string().as_str(), err.span.line), (text, 3));
    }
    let g383 = |outcome| {
        let config = Config {
            probe: ProbeModel::Answered(Arc::from([outcome])),
            ..Config::default()
        };
        let mut interp = Interpreter::new(config);
        let text = "G21 F50 G38.3 X8\nG38.5 X0\nM2\n";
        let result = interp.run(text, &mut Vec::<(Origin, Canon)>::new());
        (result, interp.params().get(5061), interp.params().get(5070))
    };
    // G38.3 untripped: on from X8, #5070 = 0; the G38.5 after it awaits its own answer.
    let (result, x, tripped) = g383(ProbeOutcome::Completed);
    assert_eq!(
        result.unwrap_err().kind.to_string(),
        "G38.5 probe move awaits the machine's answer"
    );
    assert_eq!((x, tripped), (8.0, 0.0));
}

/// G33 and G33.1 (absolute, G91, inches, G95 around them, polar, I and E words): every
/// canonical call agrees with rs274's — `START_SPEED_FEED_SYNC`, the feed or `RIGID_TAP`,
/// `STOP_SPEED_FEED_SYNCH`, the tap leaving the current point where it was.
#[test]
fn g33_and_g33_1_match_rs274_call_for_call() {
    let expected = rs274_expected("spindle_sync");
    assert_eq!(expected.len(), 63, "the expected file is whole");
    let (ours, error) = our_rs274_calls("spindle_sync");
    assert_eq!(error, None);
    for (k, (a, b)) in expected.iter().zip(&ours).enumerate() {
        assert_eq!(b, a, "call {}", k + 1);
    }
    assert_eq!(ours.len(), expected.len());
}

/// LinuxCNC's errors for G33/G33.1, in its order: the other words' rules first, then K
/// missing (K is not modal), then F, then the spindle at execution.
#[test]
fn g33_errors_as_linuxcnc() {
    use tezgah_gcode::{Canon, Interpreter, Origin};
    let run = |program: &str| {
        Interpreter::new(Config::linuxcnc(Default::default()))
            .run(program, &mut Vec::<(Origin, Canon)>::new())
            .unwrap_err()
            .kind
            .to_string()
    };
    let cases = [
        ("G21\nG33 Z-1 K0.05\nM2\n", "Spindle not turning in G33"),
        ("G21\nM5\nG33.1 Z-1 K1\nM2\n", "Spindle not turning in G33.1"),
        ("G21\nM3 S100\nG33 Z-1\nM2\n", "K word missing with g33/g33.1"),
        ("G21\nM3 S100\nG33 Z-1 K1\nZ-2\nM2\n", "K word missing with g33/g33.1"),
        ("G21\nG33 Z-1 F10\nM2\n", "K word missing with g33/g33.1"),
        ("G21\nG33 Z-1 E1\nM2\n", "K word missing with g33/g33.1"),
        ("G21\nM3 S100\nG33.1 Z-1 K1 F1\nM2\n", "F word used with a g33/g33.1"),
        (
            "G21\nG33 Z-1 K1 I2\nM2\n",
            "I word with no G2, G3, G5, G5.1, G10, G33.1, G76, or G87 to use it",
        ),
        ("G21\nG33 Z-1 P1\nM2\n", "P word with no G2 G3 G4 G10 G64 G5 G5.2 G76 G82 G86 G88 G89 or M50 M51 M52 M53 M62 M63 M64 M65 M66 M98 or user M code to use it"),
        ("G21\nM3 S100\nG33 K1\nM2\n", "All axes missing with motion code"),
        ("G21\nM3 S100\nG53 G33 Z-1 K1\nM2\n", "Must use g0 or g1 with g53"),
    ];
    for (program, message) in cases {
        assert_eq!(run(program), message, "{program:?}");
    }
}
