//! O-word control flow checked on programs whose results have closed forms: sums, factorials
//! by recursion, loop counts, and the guards that stop runaway programs.

use tezgah_gcode::{interp::ControlLimits, Canon, Config, ErrorKind, Interpreter, Origin};

/// The `(DEBUG,…)` messages of a program, and how it ended.
fn messages(program: &str, cfg: Config) -> (Vec<String>, Result<(), tezgah_gcode::GcodeError>) {
    let mut calls: Vec<(Origin, Canon)> = Vec::new();
    let result = Interpreter::new(cfg).run(program, &mut calls);
    let texts = calls
        .into_iter()
        .filter_map(|(_, c)| match c {
            Canon::Message(m) => Some(m),
            _ => None,
        })
        .collect();
    (texts, result)
}

fn run_ok(program: &str) -> Vec<String> {
    let (m, r) = messages(program, Config::default());
    r.unwrap_or_else(|e| panic!("{e}\n{program}"));
    m
}

#[test]
fn while_loop_sums_an_arithmetic_series() {
    for n in [0, 1, 7, 100] {
        let program = format!(
            "#1=0\n#2=0\no1 while [#1 LT {n}]\n#1=[#1+1]\n#2=[#2+#1]\no1 endwhile\n(debug,#2)\nM2\n"
        );
        let expected = format!("{:.6}", f64::from(n * (n + 1) / 2));
        assert_eq!(run_ok(&program), vec![expected]);
    }
}

#[test]
fn recursive_subroutine_computes_factorials() {
    let program = "o<fact> sub\n\
                   o10 if [#1 LE 1]\n\
                   o<fact> return [1]\n\
                   o10 endif\n\
                   o<fact> call [#1-1]\n\
                   o<fact> endsub [#1*#<_value>]\n\
                   o<fact> call [6]\n(debug,#<_value>)\n\
                   o<fact> call [10]\n(debug,#<_value>)\nM2\n";
    assert_eq!(run_ok(program), vec!["720.000000", "3628800.000000"]);
}

#[test]
fn call_arguments_are_local_and_restored() {
    // #1 of the caller survives the call; a local of the callee is not seen by the caller.
    let program = "#1=5\n#<x>=1\n\
                   o2 sub\n#<x>=99\n#<_g>=[#1+#2]\no2 endsub\n\
                   o2 call [3] [4]\n(debug,#1 #<x> #<_g>)\nM2\n";
    assert_eq!(run_ok(program), vec!["5.000000 1.000000 7.000000"]);
}

#[test]
fn if_chains_take_exactly_one_branch() {
    for (v, branch) in [(1, "a"), (2, "b"), (3, "c"), (9, "d")] {
        let program = format!(
            "#1={v}\no5 if [#1 EQ 1]\n(debug,a)\no5 elseif [#1 EQ 2]\n(debug,b)\n\
             o5 elseif [#1 EQ 3]\n(debug,c)\no5 else\n(debug,d)\no5 endif\nM2\n"
        );
        assert_eq!(run_ok(&program), vec![branch.to_string()]);
    }
}

#[test]
fn repeat_do_break_and_continue_count_right() {
    let program = "#1=0\no1 repeat [5]\n#1=[#1+1]\no1 endrepeat\n(debug,#1)\n\
                   #2=0\no2 do\n#2=[#2+1]\no2 while [#2 LT 4]\n(debug,#2)\n\
                   #3=0\no3 while [1]\n#3=[#3+1]\no4 if [#3 GE 3]\no3 break\no4 endif\no3 endwhile\n(debug,#3)\n\
                   #4=0\n#5=0\no6 while [#4 LT 10]\n#4=[#4+1]\no7 if [[#4 MOD 2] EQ 0]\no6 continue\no7 endif\n#5=[#5+1]\no6 endwhile\n(debug,#5)\nM2\n";
    assert_eq!(
        run_ok(program),
        vec!["5.000000", "4.000000", "3.000000", "5.000000"]
    );
}

#[test]
fn nested_loops_move_the_tool() {
    // A 3 × 4 grid of G1 moves from two nested while loops.
    let program = "G21 G90 F100\n#1=0\no1 while [#1 LT 3]\n#2=0\no2 while [#2 LT 4]\n\
                   G1 X[#1*10] Y[#2*10]\n#2=[#2+1]\no2 endwhile\n#1=[#1+1]\no1 endwhile\nM2\n";
    let moves = tezgah_gcode::program_moves(program, Config::default()).unwrap();
    let feeds = moves
        .iter()
        .filter(|m| matches!(m.kind, tezgah_geom::MoveKind::Feed { .. }))
        .count();
    assert_eq!(feeds, 12);
}

#[test]
fn runaway_loop_and_recursion_are_stopped() {
    let cfg = Config {
        limits: ControlLimits {
            max_loop_iterations: 1000,
            max_call_depth: 8,
        },
        ..Config::default()
    };
    let (_, r) = messages("o1 while [1]\no1 endwhile\nM2\n", cfg.clone());
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::RunawayLoop("1".into(), 1000)
    );
    let (_, r) = messages("o9 sub\no9 call\no9 endsub\no9 call\nM2\n", cfg.clone());
    assert_eq!(r.unwrap_err().kind, ErrorKind::CallsTooDeep(8));
    // A peck smaller than the depth's last bit (found by fuzzing) never reaches the bottom.
    let (_, r) = messages(
        "G21 F100\nG0 Z5\nG83 X1 Z-3 R1 Q0.000000000000000000000000000000007\nM2\n",
        cfg.clone(),
    );
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::TooManyPecks(83, 7e-33, 1000)
    );
    let (_, r) = messages("G21 F100\nG0 Z5\nG73 X1 Z-3 R1 Q0.001\nM2\n", cfg.clone());
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::TooManyPecks(73, 0.001, 1000)
    );
    let (_, r) = messages(
        "G21 F100\nG0 Z5\nG91 G81 X1 Z-3 R1 L2000000000\nM2\n",
        cfg.clone(),
    );
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::TooManyRepeats(2_000_000_000, 1000)
    );
    // 4 mm in 0.01 mm pecks: 400, within the guard.
    let (_, r) = messages("G21 F100\nG0 Z5\nG83 X1 Z-3 R1 Q0.01\nM2\n", cfg.clone());
    assert!(r.is_ok(), "{r:?}");
    // A loop left open inside another (a `repeat` or `while` with no end) must not hide the
    // outer loop's passes from the guard (found by fuzzing: it ran for ever and the loop stack
    // grew without bound).
    for inner in ["o6 repeat [3]", "o7 while [1]", "o8 do"] {
        let program = format!("o2 while [1]\n{inner}\nG0 X1\no2 endwhile\nM2\n");
        let (_, r) = messages(&program, cfg.clone());
        assert_eq!(
            r.unwrap_err().kind,
            ErrorKind::RunawayLoop("2".into(), 1000),
            "{inner}"
        );
    }
}

#[test]
fn unfinished_control_flow_is_an_error() {
    let (_, r) = messages("o1 call\nM2\n", Config::default());
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::SubroutineNotFound("1".into())
    );
    let (_, r) = messages("o1 if [0]\nG0 X1\nM2\n", Config::default());
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::OWordTargetMissing("1".into(), "endif")
    );
    let (_, r) = messages("o1 endwhile\nM2\n", Config::default());
    assert_eq!(
        r.unwrap_err().kind,
        ErrorKind::UnmatchedOWord("endwhile", "1".into())
    );
}

#[test]
fn predefined_parameters_show_the_state() {
    let program = "G20 G91 G55\nG0 X1\n(debug,#<_metric> #<_imperial> #<_incremental> #<_coord_system> #<_x> #<_line>)\nM2\n";
    assert_eq!(
        run_ok(program),
        vec!["0.000000 1.000000 1.000000 550.000000 1.000000 3.000000"]
    );
}
