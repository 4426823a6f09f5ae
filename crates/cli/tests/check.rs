//! Where `check`, `run` and `canon` say an error is: the file, line and column of the offending
//! block, also inside a subroutine file, and on one line into a pipe however long the path.

mod common;

use std::path::{Path, PathBuf};

use common::{tezgah, tmp_dir};

/// `main.ngc` calling subroutine `name`, whose file (in the same folder) has `body` as its
/// lines 2 on. The program's line 3 is blank, so a report that takes the subroutine file's line
/// for the program's shows.
fn program_with_sub(dir: &Path, name: &str, body: &str) -> (PathBuf, PathBuf) {
    let main = dir.join("main.ngc");
    std::fs::write(&main, format!("G21 G90\nF1000\n\no<{name}> call\nM2\n")).unwrap();
    let sub = dir.join(format!("{name}.ngc"));
    std::fs::write(&sub, format!("o<{name}> sub\n{body}o<{name}> endsub\nM2\n")).unwrap();
    (main, sub)
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn preflight_error_in_a_subroutine_file_names_that_file() {
    let dir = tmp_dir("sub-limit");
    // Line 3 of far.ngc leaves mill3's X range [-200, 200]; its first word is in column 3.
    let (main, sub) = program_with_sub(&dir, "far", "G1 X10\n  G1 X5000\n");
    let place = format!("{}:3:3: joint 0 (`x`)", sub.display());
    for command in ["check", "run"] {
        let out = tezgah()
            .arg(command)
            .arg(&main)
            .args(["--machine", "mill3"])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{command}");
        let err = stderr(&out);
        assert!(
            err.contains(&place) && err.contains("outside its limits [-200, 200]"),
            "{command}: {err}"
        );
        // The subroutine file's own line is shown, not the program's line 3.
        assert!(err.contains("3 │   G1 X5000"), "{command}: {err}");
        assert!(!err.contains("main.ngc:3"), "{command}: {err}");
    }
    // Without a machine the interpreter finds nothing wrong.
    let out = tezgah().arg("check").arg(&main).output().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn syntax_error_in_a_subroutine_file_names_that_file() {
    let dir = tmp_dir("sub-syntax");
    // Line 3 of bad.ngc: `Y` without a value, column 8.
    let (main, sub) = program_with_sub(&dir, "bad", "G1 X10\nG1 X5 Y\n");
    let place = format!(
        "{}:3:8: No characters found in reading real value (in a subroutine called from {})",
        sub.display(),
        main.display()
    );
    for command in ["check", "run", "canon"] {
        let out = tezgah().arg(command).arg(&main).output().unwrap();
        assert!(!out.status.success(), "{command}");
        let err = stderr(&out);
        assert!(err.contains(&place), "{command}: {err}");
        assert!(err.contains("3 │ G1 X5 Y"), "{command}: {err}");
    }
}

#[test]
fn error_messages_are_one_line_into_a_pipe_however_long_the_path() {
    // A path far past 80 columns: miette would wrap the message at the terminal width.
    let dir = tmp_dir(&format!("a-folder-name-{}", "long-".repeat(30)));
    let program = dir.join("tool.ngc");
    std::fs::write(&program, "G21\nG43.4 H1\nG1 X1 F100\nM2\n").unwrap();
    let out = tezgah()
        .arg("run")
        .arg(&program)
        .args(["--machine", "table-ac"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = stderr(&out);
    let message = format!(
        "{}:2:7: Requested tool 1 not found in the tool table",
        program.display()
    );
    assert!(message.len() > 200);
    assert!(err.lines().any(|l| l.contains(&message)), "{err}");
}

#[test]
fn check_with_a_machine_counts_and_passes_a_program_with_subroutines() {
    // One pass of the interpreter feeds the summary and the machine's pre-flight: the counts
    // are the program's (its lines, not the subroutine file's), and the moves reach the path.
    let dir = tmp_dir("sub-ok");
    // The square's moves are on its file's lines 6 to 9, past the program's last line (5).
    let body = "(one)\n(two)\n(three)\n(four)\nG1 X10\nG1 Y10\nG1 X0\nG1 Y0\n";
    let (main, _) = program_with_sub(&dir, "square", body);
    let out = tezgah()
        .arg("check")
        .arg(&main)
        .args(["--machine", "mill3"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("OK on mill3, 5 lines, 0 rapid, 4 feed"),
        "{stdout}"
    );
    // `run` prints each sample's line in its own file: the square's lines 6 to 9.
    let csv = dir.join("samples.csv");
    let out = tezgah()
        .arg("run")
        .arg(&main)
        .arg("--samples")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<u32> = text
        .lines()
        .skip(1)
        .map(|row| row.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    lines.dedup();
    assert_eq!(lines.iter().max(), Some(&9), "{lines:?}");
    for line in 6..=9 {
        assert!(lines.contains(&line), "{lines:?}");
    }
}

/// `check --machine` reads the program as `run` does on a machine with `tcp = "always"`: Z-390
/// is the joint z itself with TCP off (inside ±400), but under TCP the tip at Z-390 puts the
/// gauge point at −150 + 50 − 390 = −490 on table-ac: refused with the block's place.
#[test]
fn check_with_a_tcp_always_machine_reads_the_program_under_tcp() {
    let dir = tmp_dir("tcp-always");
    let program = dir.join("deep.ngc");
    std::fs::write(&program, "G21 G90\nG0 X0 Y0 Z-390\nM2\n").unwrap();
    let machine = dir.join("always.toml");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../machines/table-ac.toml"
    ))
    .unwrap()
    .replace("tcp = \"program\"", "tcp = \"always\"");
    std::fs::write(&machine, text).unwrap();
    let ok = tezgah()
        .arg("check")
        .arg(&program)
        .args(["--machine", "table-ac"])
        .output()
        .unwrap();
    assert!(ok.status.success(), "{}", stderr(&ok));
    let refused = tezgah()
        .arg("check")
        .arg(&program)
        .arg("--machine")
        .arg(&machine)
        .output()
        .unwrap();
    assert!(!refused.status.success());
    let err = stderr(&refused);
    assert!(err.contains("deep.ngc:2:1: joint 2 (`z`)"), "{err}");
}

/// A word of an axis the machine lacks is refused where LinuxCNC refuses it (its axis mask):
/// `check --machine machines/mill3.toml` and `run` name the line and the column of the `A`,
/// while the table-ac machine, which has A, and `check` without a machine (rs274's XYZABC)
/// pass it.
#[test]
fn an_axis_the_machine_lacks_is_a_bad_character_at_its_line_and_column() {
    let dir = tmp_dir("axis-mask");
    let program = dir.join("rotary.ngc");
    std::fs::write(&program, "G21 G90\nG1 X10 A90 F600\nM2\n").unwrap();
    let mill3 = concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/mill3.toml");
    let place = format!("{}:2:8: Bad character 'a' used", program.display());
    for (command, machine) in [("check", mill3), ("run", "mill3")] {
        let out = tezgah()
            .arg(command)
            .arg(&program)
            .args(["--machine", machine])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{command}");
        let err = stderr(&out);
        assert!(err.contains(&place), "{command}: {err}");
    }
    for machine in [&["--machine", "table-ac"][..], &[]] {
        let out = tezgah()
            .arg("check")
            .arg(&program)
            .args(machine)
            .output()
            .unwrap();
        assert!(out.status.success(), "{machine:?}: {}", stderr(&out));
    }
}

/// A program that ends without M2, M30 or `%` passes `check` and `run` with a warning that
/// names the file and its last line; `canon` keeps rs274's error.
#[test]
fn a_missing_program_end_is_a_warning_naming_the_file() {
    let dir = tmp_dir("no-end");
    let program = dir.join("grbl.ngc");
    std::fs::write(&program, "G21 G90\nG1 X10 F600\nG1 Y5\n").unwrap();
    let warning = format!(
        "warning: {}:3:6: File ended with no percent sign or program end; run as if it ended \
         with M2",
        program.display()
    );
    for (command, machine) in [
        ("check", None),
        ("check", Some("mill3")),
        ("run", Some("mill3")),
    ] {
        let mut cmd = tezgah();
        cmd.arg(command).arg(&program);
        if let Some(m) = machine {
            cmd.args(["--machine", m]);
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success(), "{command}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(&warning),
            "{command}: {}",
            stderr(&out)
        );
    }
    let out = tezgah().arg("canon").arg(&program).output().unwrap();
    assert!(!out.status.success());
    assert!(stderr(&out).contains("File ended with no percent sign or program end"));
}
