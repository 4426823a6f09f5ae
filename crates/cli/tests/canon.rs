//! `tezgah canon` end to end through the binary: a program that reads an INI file's values and
//! calls a subroutine from the INI file's `SUBROUTINE_PATH`.

mod common;

use common::tezgah;

#[test]
fn canon_reads_ini_values_and_subroutine_path() {
    let dir = std::env::temp_dir().join(format!("tezgah-canon-test-{}", std::process::id()));
    let subs = dir.join("subs");
    std::fs::create_dir_all(&subs).unwrap();
    std::fs::write(
        dir.join("machine.ini"),
        "[RS274NGC]\nSUBROUTINE_PATH = subs\n[VARS]\nSAFE_Z = 12.5\n",
    )
    .unwrap();
    std::fs::write(
        subs.join("lift.ngc"),
        "o<lift> sub\nG0 Z#<_ini[vars]safe_z>\no<lift> endsub\nM2\n",
    )
    .unwrap();
    let program = dir.join("prog.ngc");
    std::fs::write(
        &program,
        "G21\no<lift> call\nG0 X[#<_ini[vars]safe_z> * 2]\nM2\n",
    )
    .unwrap();
    let out = tezgah()
        .arg("canon")
        .arg(&program)
        .arg("--ini")
        .arg(dir.join("machine.ini"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let traverses: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("STRAIGHT_TRAVERSE"))
        .collect();
    assert_eq!(
        traverses,
        [
            "STRAIGHT_TRAVERSE(0.0000, 0.0000, 12.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(25.0000, 0.0000, 12.5000, 0.0000, 0.0000, 0.0000)",
        ]
    );

    // Without the INI file the value is not defined: an error naming it, exit status 1.
    let out = tezgah()
        .arg("canon")
        .arg(&program)
        .arg("--subroutine-path")
        .arg(&subs)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("Named parameter #<_ini[vars]safe_z> not defined"),
        "{stderr}"
    );
}

#[test]
fn canon_starts_from_a_parameter_file() {
    let dir = std::env::temp_dir().join(format!("tezgah-canon-params-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // G55 active (#5220 = 2) with its X offset 1 inch (rs274's parameters are in inches).
    std::fs::write(dir.join("offsets.var"), "5220\t2.000000\n5241\t1.000000\n").unwrap();
    let program = dir.join("p.ngc");
    std::fs::write(&program, "G21 G0 X0\nM2\n").unwrap();
    let out = tezgah()
        .arg("canon")
        .arg(&program)
        .arg("--params")
        .arg(dir.join("offsets.var"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        lines[1],
        "SET_G5X_OFFSET(2, 25.4000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"
    );
    assert!(lines.contains(&"STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"));
}
