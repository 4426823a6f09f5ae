//! The Python oracles' plumbing shared by the cycle-time tests: find the oracle's python (or
//! fail, naming the install script) and run one of `tests/oracle/*.py` on a text input.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

/// The python in `var`, which must import `module`: panics otherwise.
pub fn python(var: &str, module: &str, install: &str) -> std::ffi::OsString {
    let Some(python) = std::env::var_os(var) else {
        panic!("{var} is not set: install {module} with {install}");
    };
    let probe = Command::new(&python)
        .args(["-c", &format!("import {module}")])
        .output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "{python:?} cannot import {module} (see {install})"
    );
    python
}

/// Runs `script` with `input` on stdin and returns its stdout lines.
pub fn ask(python: &std::ffi::OsString, script: &str, input: String) -> Vec<String> {
    let mut child = Command::new(python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start the oracle");
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let lines: Vec<String> = BufReader::new(child.stdout.take().unwrap())
        .lines()
        .map(|l| l.unwrap())
        .collect();
    writer.join().unwrap().unwrap();
    assert!(child.wait().unwrap().success(), "oracle failed");
    lines
}
