//! G43.4 H<n> (Fanuc's tool-centre-point control) and G49: the canonical calls, the moves the
//! planner receives, and the errors for a missing or unknown H.

use tezgah_gcode::{program_moves, Canon, Config, ErrorKind, Interpreter, ToolTable};
use tezgah_geom::{MoveKind, Pose, ToolControl};

fn config() -> Config {
    Config {
        tool_table: ToolTable::parse("T1 P1 Z35.0 D6\nT2 P2 Z28.5 D3\n").unwrap(),
        ..Config::default()
    }
}

fn canon(program: &str) -> Vec<String> {
    let mut calls: Vec<(tezgah_gcode::Origin, Canon)> = Vec::new();
    Interpreter::new(config()).run(program, &mut calls).unwrap();
    calls.iter().map(|(_, c)| c.to_string()).collect()
}

#[test]
fn canon_prints_the_offset_and_the_switch() {
    let calls = canon("G21\nG43.4 H1\nG0 X1\nG49\nM2\n");
    let i = calls
        .iter()
        .position(|c| c.starts_with("SET_TOOL_CENTRE_POINT"))
        .unwrap();
    assert_eq!(calls[i], "SET_TOOL_CENTRE_POINT(ON, 35.0000)");
    // The length is in force as for G43 H1: the call before says so.
    assert_eq!(
        calls[i - 1],
        "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 35.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)"
    );
    let off: Vec<&String> = calls
        .iter()
        .filter(|c| c.starts_with("SET_TOOL_CENTRE_POINT(OFF"))
        .collect();
    assert_eq!(off, ["SET_TOOL_CENTRE_POINT(OFF)"]);
}

#[test]
fn g43_replaces_g43_4_and_turns_tcp_off_g49_without_tcp_prints_no_switch() {
    let calls = canon("G21\nG49\nG43.4 H2\nG43 H1\nM2\n");
    let switches: Vec<&String> = calls
        .iter()
        .filter(|c| c.starts_with("SET_TOOL_CENTRE_POINT"))
        .collect();
    assert_eq!(
        switches,
        [
            "SET_TOOL_CENTRE_POINT(ON, 28.5000)",
            "SET_TOOL_CENTRE_POINT(OFF)"
        ]
    );
}

#[test]
fn moves_carry_the_tip_under_tcp_and_the_gauge_point_without() {
    // Z0 at the start: the gauge point at 0. G43.4 H1 keeps the tool where it is, so the tip
    // is 35 below (the next move starts there, in TCP coordinates); G1 Z5 goes to tip Z5
    // with no Z offset added. G49 ends TCP: the point reads as the gauge point again.
    let moves =
        program_moves("G21 G90\nG43.4 H1\nG1 Z5 F100\nG49\nG1 Z10\nM2\n", config()).unwrap();
    let seen: Vec<(u32, String)> = moves
        .iter()
        .filter_map(|m| match m.kind {
            MoveKind::ToolControl { control, at } => {
                Some((m.line, format!("{control:?} {:?}", at.0)))
            }
            MoveKind::Feed { end } => Some((m.line, format!("feed {:?}", end.0))),
            _ => None,
        })
        .collect();
    let z = |v: f64| format!("{:?}", Pose::new(0.0, 0.0, v, 0.0, 0.0, 0.0).0);
    assert_eq!(
        seen,
        vec![
            (
                2,
                format!("CentrePoint {{ tool_length: 35.0 }} {}", z(-35.0))
            ),
            (3, format!("feed {}", z(5.0))),
            (4, format!("Joints {{ tool_length: 0.0 }} {}", z(40.0))),
            (5, format!("feed {}", z(10.0))),
        ]
    );
}

#[test]
fn tcp_always_turns_g43_into_a_tcp_length() {
    let cfg = Config {
        tool_centre_point_always: true,
        ..config()
    };
    let moves = program_moves("G21\nG43 H1\nG1 Z5 F100\nG49\nM2\n", cfg).unwrap();
    let controls: Vec<(u32, ToolControl, f64)> = moves
        .iter()
        .filter_map(|m| match m.kind {
            MoveKind::ToolControl { control, at } => Some((m.line, control, at.z())),
            _ => None,
        })
        .collect();
    assert_eq!(
        controls,
        vec![
            (1, ToolControl::CentrePoint { tool_length: 0.0 }, 0.0),
            (2, ToolControl::CentrePoint { tool_length: 35.0 }, -35.0),
            (4, ToolControl::CentrePoint { tool_length: 0.0 }, 5.0 + 35.0),
        ]
    );
    let feed = moves.iter().find_map(|m| match m.kind {
        MoveKind::Feed { end } => Some(end.z()),
        _ => None,
    });
    assert_eq!(feed, Some(5.0), "no Z offset under TCP");
}

#[test]
fn g43_4_needs_an_h_word_naming_a_tool_of_the_table() {
    let err = program_moves("G21\nG43.4\nM2\n", config()).unwrap_err();
    assert_eq!(err.kind, ErrorKind::CentrePointMissingH);
    assert_eq!(err.to_string(), "H word missing with G43.4");
    assert_eq!((err.span.line, err.span.column), (2, 1));
    let err = program_moves("G21\nG43.4 H7\nM2\n", config()).unwrap_err();
    assert_eq!(err.kind, ErrorKind::ToolNotFound(7));
    assert_eq!(
        err.to_string(),
        "Requested tool 7 not found in the tool table"
    );
    assert_eq!((err.span.line, err.span.column), (2, 7));
    let err = program_moves("G21\nG43.4 H0\nM2\n", config()).unwrap_err();
    assert_eq!(err.kind, ErrorKind::ToolNotFound(0));
    // G43.4 and G49 share modal group 8.
    let err = program_moves("G21\nG43.4 H1 G49\nM2\n", config()).unwrap_err();
    assert!(err.to_string().contains("modal group"), "{err}");
}

#[test]
fn g43_with_tcp_off_announces_its_length_once_the_block_is_done() {
    // G43 H1 (35 mm) then G49, TCP off: each length is announced at the next call, with the
    // point unchanged (the gauge point); G43 H2 followed by G43.4 H2 announces only TCP.
    let moves = program_moves(
        "G21 G90\nG43 H1\nG1 Z5 F100\nG49\nG1 Z10\nG43 H2\nG43.4 H2\nG1 Z0\nM2\n",
        config(),
    )
    .unwrap();
    let controls: Vec<(u32, ToolControl, f64)> = moves
        .iter()
        .filter_map(|m| match m.kind {
            MoveKind::ToolControl { control, at } => Some((m.line, control, at.z())),
            _ => None,
        })
        .collect();
    assert_eq!(
        controls,
        vec![
            (2, ToolControl::Joints { tool_length: 35.0 }, 0.0),
            (4, ToolControl::Joints { tool_length: 0.0 }, 40.0),
            (
                7,
                ToolControl::CentrePoint { tool_length: 28.5 },
                10.0 - 28.5
            ),
        ]
    );
}
