//! `tezgah export` from the command line: the README's delta example (its summary, the file's
//! header and letters) and a move out of the delta's reach reported at its file, line and column.

mod common;

use common::{assert_success, tezgah, tmp_dir};

const EXAMPLE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/delta.ngc");

#[test]
fn delta_example_writes_joint_program_and_summary() {
    let dir = tmp_dir("export-delta");
    let out_file = dir.join("delta_joints.ngc");
    let out = tezgah()
        .args(["export", EXAMPLE, "--machine", "linear-delta", "-o"])
        .arg(&out_file)
        .output()
        .unwrap();
    assert_success(&out, "export");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(": 7 blocks in, 936 out (q1=X q2=Y q3=Z)")
            && stdout.contains("budget 0.0020 mm of tolerance 0.01 mm"),
        "{stdout}"
    );
    let text = std::fs::read_to_string(&out_file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[3..5], ["G21 G90 G17 G40 G49 G61", "G93"]);
    assert_eq!(lines[5..7], ["N3 S12000", "N3 M3"]);
    // Every motion block numbered, in joint letters, G1 with an inverse-time F.
    for l in &lines[5..] {
        assert!(l.starts_with('N') || *l == "M2", "{l}");
        if l.contains(" G1 ") {
            assert!(l.contains(" X") && l.contains(" Y") && l.contains(" Z") && l.contains(" F"));
        }
    }
    assert_eq!(*lines.last().unwrap(), "N13 M2");
}

#[test]
fn unreachable_move_is_reported_at_its_line() {
    let dir = tmp_dir("export-far");
    let program = dir.join("far.ngc");
    std::fs::write(&program, "G21 G90\n  G1 X500 F100\nM2\n").unwrap();
    let out = tezgah()
        .args(["export"])
        .arg(&program)
        .args(["--machine", "linear-delta", "-o"])
        .arg(dir.join("out.ngc"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let place = format!("{}:2:3: pose unreachable", program.display());
    assert!(err.contains(&place), "{err}");
    assert!(!dir.join("out.ngc").exists());
}
