//! LinuxCNC's predefined named parameters (`#<_ccomp>`, `#<_current_pocket>`,
//! `#<_feed_override>`, …) through tool changes, modes, override switches and compensation.
//! `data/system_params.expected` is what LinuxCNC 2.9's `rs274` printed for the program; with
//! `TEZGAH_RS274` set, rs274 is also run again and must agree (an ignored test: `.ci/run` runs it
//! with `--include-ignored`).

mod support;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use tezgah_gcode::{Canon, Config, Interpreter, Origin, ToolTable};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The MESSAGE calls tezgah prints for the program, one per line.
fn our_messages() -> Vec<String> {
    let program = std::fs::read_to_string(data("system_params.ngc")).unwrap();
    let table = std::fs::read_to_string(data("system_params.tbl")).unwrap();
    let config = Config::linuxcnc(ToolTable::parse(&table).unwrap());
    let mut calls = Vec::<(Origin, Canon)>::new();
    Interpreter::new(config).run(&program, &mut calls).unwrap();
    calls
        .iter()
        .map(|(_, c)| c.to_string())
        .filter(|c| c.starts_with("MESSAGE("))
        .collect()
}

#[test]
fn predefined_parameters_read_as_in_rs274() {
    let expected: Vec<String> = std::fs::read_to_string(data("system_params.expected"))
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect();
    assert_eq!(expected.len(), 33, "the expected file is whole");
    assert_eq!(our_messages(), expected);
}

#[test]
#[ignore = "needs LinuxCNC's rs274: set TEZGAH_RS274 (see .ci/install-rs274)"]
fn rs274_still_prints_the_expected_parameters() {
    let rs274 = support::rs274();
    let out = Command::new(rs274)
        .arg("-t")
        .arg(data("system_params.tbl"))
        .arg("-g")
        .arg(data("system_params.ngc"))
        .stdin(Stdio::null())
        .output()
        .expect("run rs274");
    let theirs: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.find("MESSAGE(").map(|i| l[i..].to_owned()))
        .collect();
    assert_eq!(our_messages(), theirs);
}
