//! The CAM chain end to end through the binary: a tool path on a convex cylinder, posted for
//! table-ac (tool-centre-point and joint output, feed per minute and inverse time), is accepted
//! by `tezgah check` and executed by `tezgah run --machine table-ac` within every joint limit
//! and the path tolerance. `tezgah cam` refuses bad options without a panic.

mod common;

use common::{tezgah, tmp};
use tezgah_cam::post::{post, FeedOutput, OutputForm, PostOptions};
use tezgah_cam::{Cutter, CutterLocation, CutterShape, Pass, ToolPath};
use tezgah_geom::{NurbsSurface, Vec3};
use tezgah_kinematics::Machine;

/// A convex cylinder ρ = 20 about Y (±25°, 12 mm long) and a ball D = 3 zig-zag around it
/// (passes along the circumference, so A changes inside every pass and changes sign).
fn cylinder_job() -> ToolPath {
    let (rho, half, len, r) = (20.0_f64, 25f64.to_radians(), 12.0, 1.5);
    let arc = [
        Vec3::new(-rho * half.sin(), 0.0, rho * half.cos()),
        Vec3::new(0.0, 0.0, rho / half.cos()),
        Vec3::new(rho * half.sin(), 0.0, rho * half.cos()),
    ];
    let mut pts = Vec::new();
    let mut ws = Vec::new();
    for (k, p) in arc.iter().enumerate() {
        for y in [0.0, len] {
            pts.push(Vec3::new(p.x, y, p.z));
            ws.push(if k == 1 { half.cos() } else { 1.0 });
        }
    }
    let s = NurbsSurface::new(
        2,
        1,
        &pts,
        &ws,
        vec![0., 0., 0., 1., 1., 1.],
        vec![0., 0., 1., 1.],
    )
    .unwrap();
    let passes = (0..5)
        .map(|i| {
            let v = i as f64 / 4.0;
            let mut points: Vec<CutterLocation> = (0..=16)
                .map(|j| {
                    let u = j as f64 / 16.0;
                    let d = s.derivs(u, v);
                    let n = d.su.cross(&d.sv).normalize();
                    CutterLocation {
                        // Axis along the normal: the ball centre is R above the contact, the tip on it.
                        tip: d.point,
                        axis: n,
                        contact: d.point,
                        normal: n,
                        uv: (u, v),
                    }
                })
                .collect();
            if i % 2 == 1 {
                points.reverse();
            }
            Pass { points }
        })
        .collect();
    ToolPath {
        cutter: Cutter::standard(CutterShape::Ball { radius: r }),
        passes,
    }
}

/// `check` and `run` on table-ac ([`common::check_and_run`]), and the run ends where the
/// program's last block says.
fn check_and_run(program: &str, name: &str) -> serde_json::Value {
    std::fs::write(tmp(&format!("{name}.ngc")), program).unwrap();
    let csv = tmp(&format!("{name}.csv"));
    let report = common::check_and_run(name, Some(&csv));
    // The machine ends where the program's last block says, read the way the output form
    // means it: under TCP the samples' tip is X Y Z; with joint output (TCP off, G43) the
    // joints are X Y Z with the tool length (28.5 mm) added to Z, A and C.
    let samples = std::fs::read_to_string(&csv).unwrap();
    let last: Vec<f64> = samples
        .lines()
        .last()
        .unwrap()
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    // The last motion block (modal G0 may leave the G word out).
    let block = program
        .lines()
        .rfind(|l| !l.starts_with('(') && l.contains('X') && l.contains('C'))
        .unwrap();
    let word = |c: char| -> f64 {
        block
            .split(' ')
            .find_map(|w| w.strip_prefix(c).filter(|v| !v.is_empty()))
            .unwrap()
            .parse()
            .unwrap()
    };
    let (x, y, z, a, c) = (word('X'), word('Y'), word('Z'), word('A'), word('C'));
    // Columns: t, line, x, y, z, a, c, tip_x, tip_y, tip_z, tool_i, tool_j, tool_k (the tip
    // is the tool tip by forward kinematics: X Y Z under TCP; with TCP off the joints carry
    // the program axes, read here).
    let (got, want) = if program.contains("G43.4") {
        ([last[7], last[8], last[9]], [x, y, z])
    } else {
        ([last[2], last[3], last[4]], [x, y, z + 28.5])
    };
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() < 1e-6,
            "{name}: ends at {got:?}, program says {want:?}"
        );
    }
    assert!(
        (last[5] - a).abs() < 1e-6 && (last[6] - c).abs() < 1e-6,
        "{name}: {last:?}"
    );
    report
}

#[test]
fn posted_programs_pass_check_and_run_on_table_ac() {
    let machine = Machine::builtin("table-ac").unwrap();
    let path = cylinder_job();
    for (form, feed, name) in [
        (OutputForm::CentrePoint, FeedOutput::PerMinute, "tcp"),
        (OutputForm::CentrePoint, FeedOutput::InverseTime, "tcp-g93"),
        (OutputForm::Joints, FeedOutput::InverseTime, "joints-g93"),
    ] {
        let options = PostOptions {
            form,
            feed_output: feed,
            tool_number: 2,
            tool_length_mm: 28.5,
            ..PostOptions::new(1200.0, 0.01)
        };
        let posted = post(&path, &machine, &options).unwrap();
        let report = check_and_run(&posted.program, name);
        // The A joint really tilts both ways and the run takes at least the cutting time.
        let a = &report["joints"][3];
        assert!(a["peak_velocity"].as_f64().unwrap() > 1.0, "{name}: {a}");
        let duration = report["duration_s"].as_f64().unwrap();
        assert!(
            duration >= posted.stats.feed_time_s * 0.999,
            "{name}: {duration} < {:?}",
            posted.stats
        );
    }
}

#[test]
fn cam_refuses_bad_options_without_a_panic() {
    let out_ngc = tmp("never.ngc");
    for extra in [
        ["--tool", "cone:3", "--strategy", "zigzag"],
        ["--tool", "ball:3", "--strategy", "spiral"],
    ] {
        let out = tezgah()
            .args(["cam", "surface.stp"])
            .args(extra)
            .args(["--scallop", "0.05", "--tolerance", "0.01", "-o"])
            .arg(&out_ngc)
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !err.contains("panicked") && (err.contains("tool") || err.contains("strategy")),
            "{err}"
        );
    }
    // The one-sided band takes the tolerance from the scallop: it must be smaller.
    let out = tezgah()
        .args([
            "cam",
            "surface.stp",
            "--tool",
            "ball:3",
            "--strategy",
            "zigzag",
        ])
        .args(["--scallop", "0.01", "--tolerance", "0.01", "-o"])
        .arg(&out_ngc)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("must be below --scallop"), "{err}");
    let out = tezgah()
        .args([
            "cam",
            "s.stp",
            "--tool",
            "ball:3",
            "--strategy",
            "zigzag",
            "--scallop",
            "-1",
        ])
        .args(["--tolerance", "0.01", "-o"])
        .arg(&out_ngc)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(!out_ngc.exists());
    // Out-of-range reach and verification options are refused before any file is read.
    for (flag, value, word) in [
        ("--max-tilt", "181", "--max-tilt"),
        ("--feed-along", "w", "--feed-along"),
        ("--max-tilt", "0", "--max-tilt"),
        ("--verify-cell", "0", "--verify-cell"),
    ] {
        let out = tezgah()
            .args([
                "cam",
                "missing.stp",
                "--tool",
                "ball:3",
                "--strategy",
                "zigzag",
            ])
            .args(["--scallop", "0.1", "--tolerance", "0.01", flag, value, "-o"])
            .arg(&out_ngc)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(!err.contains("panicked") && err.contains(word), "{err}");
        assert!(!out_ngc.exists());
    }
}
