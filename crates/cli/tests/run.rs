//! `tezgah run` and `tezgah machines` end to end through the binary: the demo on the default
//! machine, the samples CSV and report JSON as the README documents them, plots, and errors.

mod common;

use common::{assert_joints_within_limits, read_json, succeeded_with_report, tezgah, tmp, TOOLS};

#[test]
fn demo_run_writes_samples_report_and_plots() {
    let (csv, json, plots) = (tmp("s.csv"), tmp("r.json"), tmp("plots"));
    let out = tezgah()
        .args(["run", "--samples"])
        .arg(&csv)
        .arg("--report")
        .arg(&json)
        .arg("--plot")
        .arg(&plots)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("cycle time"), "{stdout}");
    assert!(stdout.contains("max deviation"), "{stdout}");

    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "t,line,x,y,z,tip_x,tip_y,tip_z");
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[0], k as f64 * 0.001, "row {k} time");
        assert_eq!(r.len(), 8);
    }
    // First and last rows at rest at the same place (the demo returns home with G28).
    assert_eq!(rows[0][2..], rows.last().unwrap()[2..]);

    let report = read_json(&json);
    assert_eq!(
        report["cycle_time_s"].as_f64().unwrap(),
        rows.last().unwrap()[0]
    );
    assert_eq!(report["samples"].as_u64().unwrap() as usize, rows.len());
    let d = report["duration_s"].as_f64().unwrap();
    assert!(d <= report["cycle_time_s"].as_f64().unwrap() && d > 1.0);
    assert!(report["max_deviation_mm"].as_f64().unwrap() <= 0.01);
    assert_joints_within_limits(&report, true, "demo");
    for name in ["feed.svg", "feed.png", "x_jerk.svg", "z_acceleration.png"] {
        assert!(plots.join(name).exists(), "{name}");
    }
    // Every plot has a title, axis labels with units, tick labels and, for a joint, its limits
    // (mill3: x 200 mm/s, y 2000 mm/s², z 25000 mm/s³).
    let text = |name: &str| {
        let svg = std::fs::read_to_string(plots.join(name)).unwrap();
        svg.split("<text")
            .skip(1)
            .filter_map(|t| {
                Some(
                    t.split_once('>')?
                        .1
                        .split_once("</text>")?
                        .0
                        .trim()
                        .to_owned(),
                )
            })
            .collect::<Vec<String>>()
    };
    let feed = text("feed.svg");
    assert!(feed.iter().any(|t| t.starts_with("Feed — ")), "{feed:?}");
    assert!(feed.contains(&"path speed (mm/s)".to_owned()), "{feed:?}");
    assert!(feed.contains(&"time (s)".to_owned()), "{feed:?}");
    for (file, label, limit) in [
        ("x_velocity.svg", "velocity (mm/s)", "limit ±200"),
        ("y_acceleration.svg", "acceleration (mm/s²)", "limit ±2000"),
        ("z_jerk.svg", "jerk (mm/s³)", "limit ±25000"),
    ] {
        let t = text(file);
        assert!(t.contains(&label.to_owned()), "{file}: {t:?}");
        assert!(t.contains(&limit.to_owned()), "{file}: {t:?}");
        assert!(
            t.iter().any(|s| s.ends_with(" — built-in demo")),
            "{file}: {t:?}"
        );
        // Tick labels: numbers on both axes.
        let numbers = t.iter().filter(|s| s.parse::<f64>().is_ok()).count();
        assert!(numbers >= 6, "{file}: {t:?}");
    }
}

#[test]
fn machines_lists_the_builtins() {
    let out = tezgah().arg("machines").output().unwrap();
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for name in ["mill3", "yzca", "table-ac", "table-bc", "linear-delta"] {
        assert!(s.contains(name), "{s}");
    }
}

#[test]
fn errors_are_reported_not_panics() {
    let bad = tmp("bad.ngc");
    std::fs::write(&bad, "G1 X10 F100\nG2 X5 Y5 R0.1\n").unwrap();
    let out = tezgah().arg("run").arg(&bad).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    let out = tezgah()
        .args(["run", "--machine", "no-such-machine"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let out = tezgah().args(["run", "--period", "0"]).output().unwrap();
    assert!(!out.status.success());
}

#[test]
fn five_axis_example_under_tcp_on_table_ac_holds_limits() {
    let json = tmp("r5.json");
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/five-axis.ngc");
    let out = tezgah()
        .args([
            "run",
            program,
            "--machine",
            "table-ac",
            "--tool-table",
            TOOLS,
        ])
        .arg("--report")
        .arg(&json)
        .output()
        .unwrap();
    let report = succeeded_with_report(&out, &json);
    let joints = report["joints"].as_array().unwrap();
    assert_eq!(joints.len(), 5);
    assert_eq!(joints[4]["unit"], "deg");
    assert!(
        joints[4]["peak_velocity"].as_f64().unwrap() > 1.0,
        "C turns"
    );
    assert_eq!(report["tcp"], "program");
    // The tool axis is carried and blended at the ring's corners, within the blends' share
    // (0.8) of table-ac's 0.1° angular tolerance.
    assert_eq!(report["axis_tolerance_deg"].as_f64(), Some(0.1));
    let axis = report["max_axis_deviation_deg"].as_f64().unwrap();
    assert!(axis > 0.0 && axis <= 0.08, "{axis}");
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("within angular tolerance: true"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert_joints_within_limits(&report, true, "five-axis");
    // G43.4 H1 needs tool 1 in a tool table: without one the run stops at line 5.
    let out = tezgah()
        .args(["run", program, "--machine", "table-ac"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    // Into a pipe the message is one line, however long the program's path.
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("five-axis.ngc:5:7: Requested tool 1 not found in the tool table"),
        "{err}"
    );
}

#[test]
fn spline_example_runs_within_tolerance_and_limits() {
    // examples/splines.ngc: two G06.2 NURBS (lines 6 and 21), then G5, G5 and G5.1.
    let (csv, json) = (tmp("sp.csv"), tmp("sp.json"));
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/splines.ngc");
    let out = tezgah()
        .args(["run", program, "--samples"])
        .arg(&csv)
        .arg("--report")
        .arg(&json)
        .output()
        .unwrap();
    let report = succeeded_with_report(&out, &json);
    // verify: every sample within the tolerance of the programmed curves, limits held.
    let tolerance = report["tolerance_mm"].as_f64().unwrap();
    assert!(report["max_deviation_mm"].as_f64().unwrap() <= tolerance);
    assert_joints_within_limits(&report, false, "splines");
    // The thesis curve (19.0203 mm at F1200 = 20 mm/s) takes at least 0.951 s; its first
    // sample is at its start (the tool comes down there and stops).
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let on_curve: Vec<&Vec<f64>> = rows.iter().filter(|r| r[1] == 6.0).collect();
    let seconds = on_curve.len() as f64 * 0.001;
    assert!(seconds >= 19.0203 / 20.0, "{seconds} s on the NURBS");
    let first = on_curve[0];
    assert!(first[5].hypot(first[6]) < 0.01, "{first:?}");
    assert!(rows.iter().any(|r| r[1] == 21.0), "the second NURBS runs");
}

/// A program that leaves the machine's envelope is refused whole, before anything is written:
/// on a straight move, and on an arc whose ends are inside while its middle bulges out.
#[test]
fn pre_flight_refuses_a_program_past_a_joint_limit_before_any_output() {
    let cases = [
        ("line.ngc", "G21 G90\nG1 X50 F1000\nG1 X500\nM2\n", ":3:1"),
        (
            "arc.ngc",
            "G21 G90\nG0 X190 Y-15\n  G3 X190 Y15 I0 J15 F1000\nM2\n",
            ":3:3",
        ),
    ];
    for (name, program, place) in cases {
        let (file, csv) = (tmp(name), tmp(&format!("{name}.csv")));
        std::fs::write(&file, program).unwrap();
        let out = tezgah()
            .arg("run")
            .arg(&file)
            .arg("--samples")
            .arg(&csv)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!("{name}{place}"))
                && err.contains("outside its limits [-200, 200]"),
            "{err}"
        );
        assert!(!csv.exists(), "{name}: nothing is written");
        // `check` finds it with a machine, and only the interpreter's faults without one.
        let with = tezgah()
            .arg("check")
            .arg(&file)
            .args(["--machine", "mill3"])
            .output()
            .unwrap();
        assert!(!with.status.success(), "{name}");
        assert!(String::from_utf8_lossy(&with.stderr).contains(&format!("{name}{place}")));
        let without = tezgah().arg("check").arg(&file).output().unwrap();
        assert!(without.status.success(), "{name}");
    }
}

/// `--drive servo`: a straight move along x at 50 mm/s on mill3 with x's feed-forward off
/// lags by the closed form v(1 + β/K_v)/K_p = 0.516528 mm at cruise (β = friction/inertia,
/// K_p = 2π·20 Hz/1.2872 (the −3 dB bandwidth), K_v = 4K_p), all along the path: the contour error stays ~0; the
/// joints that do not move have no error; the ideal drive reports no tracking section.
#[test]
fn servo_drive_reports_tracking_and_contour_errors() {
    let mill3 = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../machines/mill3.toml"
    ))
    .unwrap();
    let no_ff = mill3
        .replace("velocity_feed_forward = 1.0", "velocity_feed_forward = 0.0")
        .replace(
            "acceleration_feed_forward = 1.0",
            "acceleration_feed_forward = 0.0",
        );
    assert_ne!(no_ff, mill3);
    let (machine, program) = (tmp("noff.toml"), tmp("servo-line.ngc"));
    std::fs::write(&machine, no_ff).unwrap();
    std::fs::write(&program, "G21 G90 G1 X100 F3000\nM2\n").unwrap();
    let run = |machine: &std::path::Path, drive: &str, json: &std::path::Path| {
        let out = tezgah()
            .arg("run")
            .arg(&program)
            .arg("--machine")
            .arg(machine)
            .args(["--drive", drive, "--report"])
            .arg(json)
            .output()
            .unwrap();
        let report = succeeded_with_report(&out, json);
        (report, String::from_utf8_lossy(&out.stdout).into_owned())
    };
    let (r, stdout) = run(&machine, "servo", &tmp("servo.json"));
    assert!(stdout.contains("contour error RMSE"), "{stdout}");
    assert_eq!(r["drive"], "servo");
    let t = &r["tracking"];
    let joint = |i: usize, key: &str| t["joints"][i][key].as_f64().unwrap();
    let kp = 2.0 * std::f64::consts::PI * 20.0 / tezgah_kinematics::machine::SERVO_BANDWIDTH_PER_KP;
    let lag = 50.0 * (1.0 + (400.0 / 120.0) / (4.0 * kp)) / kp;
    assert!((lag - 0.516528).abs() < 1e-6);
    // The error rises to the cruise lag without overshoot (the loops are critically damped)
    // and settles there in the 2 s of cruise; its RMSE is below the largest.
    let (max_x, rmse_x) = (joint(0, "max_following_error"), joint(0, "rmse"));
    assert!((max_x - lag).abs() < 1e-6, "max {max_x} vs {lag}");
    assert!(rmse_x > 0.5 * lag && rmse_x < max_x, "rmse {rmse_x}");
    for i in [1, 2] {
        assert_eq!(joint(i, "max_following_error"), 0.0);
    }
    // A lag along a straight line is no contour error.
    let contour = t["contour_max_mm"].as_f64().unwrap();
    assert!(contour < 1e-6, "contour {contour}");
    assert!(t["fault"].is_null());

    // mill3 as shipped (full feed-forward) follows far closer; the ideal drive adds nothing.
    let (full, _) = run(std::path::Path::new("mill3"), "servo", &tmp("full.json"));
    let full_x = full["tracking"]["joints"][0]["max_following_error"]
        .as_f64()
        .unwrap();
    assert!(full_x < 1e-2 * lag, "full feed-forward {full_x}");
    let (ideal, _) = run(std::path::Path::new("mill3"), "ideal", &tmp("ideal.json"));
    assert_eq!(ideal["drive"], "ideal");
    assert!(ideal.get("tracking").is_none());
}

/// The samples CSV of `program` on `machine`: its header and rows.
fn samples(machine: &str, program: &str, name: &str) -> (String, Vec<Vec<f64>>) {
    let (ngc, csv, json) = (
        tmp(&format!("{name}.ngc")),
        tmp(&format!("{name}.csv")),
        tmp(&format!("{name}.json")),
    );
    std::fs::write(&ngc, program).unwrap();
    let out = tezgah()
        .arg("run")
        .arg(&ngc)
        .args(["--machine", machine, "--tool-table", TOOLS, "--samples"])
        .arg(&csv)
        .arg("--report")
        .arg(&json)
        .output()
        .unwrap();
    let report = succeeded_with_report(&out, &json);
    assert!(
        report["max_deviation_mm"].as_f64().unwrap() <= 0.01,
        "{report}"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_owned();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

fn close(got: [f64; 3], want: [f64; 3], tol: f64, what: &str) {
    let d = (0..3)
        .map(|i| (got[i] - want[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(d < tol, "{what}: {got:?} vs {want:?}");
}

/// table-ac with TCP off: the joints are the program axes, and the tip columns are the tool
/// tip by the table-ac convention (docs/machine-files.md) — p = Rz(−C)·(Rx(−A)·(q − L·ẑ − pivot) −
/// c_offset) with G43's L = 28.5 (T2) — and the tool axis (sin A sin C, sin A cos C, cos A).
/// Columns print 12 decimals, hence the 1e-9.
#[test]
fn samples_tip_and_tool_axis_are_the_forward_kinematics_on_table_ac() {
    let program = "G21 G90 G94 G61\nG43 H2\nG0 X10 Y20 Z30 A0 C0\n\
                   G1 X40 Y-10 Z20 A25 C70 F2000\nG1 A10 C200 F3000\nM2\n";
    let (header, rows) = samples("table-ac", program, "kin-ac");
    assert_eq!(
        header,
        "t,line,x,y,z,a,c,tip_x,tip_y,tip_z,tool_i,tool_j,tool_k"
    );
    let (pivot, c_offset) = ([0.0, 0.0, -150.0], [0.0, 2.0, 50.0]);
    let mut tilted = 0;
    for r in &rows {
        assert_eq!(r.len(), 13);
        let (a, c) = (r[5].to_radians(), r[6].to_radians());
        let w = [r[2] - pivot[0], r[3] - pivot[1], r[4] - 28.5 - pivot[2]];
        let (sa, ca) = a.sin_cos();
        let (sc, cc) = c.sin_cos();
        let u = [
            w[0] - c_offset[0],
            ca * w[1] + sa * w[2] - c_offset[1],
            -sa * w[1] + ca * w[2] - c_offset[2],
        ];
        let tip = [cc * u[0] + sc * u[1], -sc * u[0] + cc * u[1], u[2]];
        close([r[7], r[8], r[9]], tip, 1e-9, "tip");
        close([r[10], r[11], r[12]], [sa * sc, sa * cc, ca], 1e-11, "axis");
        tilted += usize::from(r[5] > 1.0);
    }
    assert!(tilted > 500, "{tilted} tilted rows");
    // While A = C = 0 (the G0, ending at rest under G61), the tip is the program point
    // (the joints less G43's 28.5 in z) less pivot + c_offset = (0, 2, −100).
    let on_g0: Vec<&Vec<f64>> = rows.iter().filter(|r| r[1] == 3.0).collect();
    assert!(on_g0.len() > 10);
    for r in on_g0 {
        assert_eq!((r[5], r[6]), (0.0, 0.0));
        close(
            [r[7], r[8], r[9]],
            [r[2], r[3] - 2.0, r[4] - 28.5 + 100.0],
            1e-9,
            "A = C = 0",
        );
    }
}

/// yzca with TCP off (joints y z c a): tip (r cos C, −r sin C, z − L cos A) with
/// r = y + L sin A, axis (−sin A cos C, sin A sin C, cos A) (README's yzca convention).
#[test]
fn samples_tip_and_tool_axis_are_the_forward_kinematics_on_yzca() {
    let program = "G21 G90 G94\nG43 H2\nG0 Y50 Z20 A0 C0\nG1 Y80 Z10 A20 C120 F2000\nM2\n";
    let (header, rows) = samples("yzca", program, "kin-yzca");
    assert_eq!(
        header,
        "t,line,y,z,c,a,tip_x,tip_y,tip_z,tool_i,tool_j,tool_k"
    );
    for r in &rows {
        let (c, a) = (r[4].to_radians(), r[5].to_radians());
        let (sa, ca) = a.sin_cos();
        let (sc, cc) = c.sin_cos();
        let rad = r[2] + 28.5 * sa;
        close(
            [r[6], r[7], r[8]],
            [rad * cc, -rad * sc, r[3] - 28.5 * ca],
            1e-9,
            "tip",
        );
        close([r[9], r[10], r[11]], [-sa * cc, sa * sc, ca], 1e-11, "axis");
    }
}

/// TCP on (G43.4 H1): the tip columns are the program's tip — at the end the last block's
/// X Y Z — and after G49 on a Cartesian mill the tip is the gauge point (no length in force).
#[test]
fn samples_tip_is_the_program_tip_under_tcp_and_the_tool_tip_under_g43() {
    let program = "G21 G90 G94\nG43.4 H1\nG0 X10 Y5 Z20 A0 C0\nG1 A30 C40 F3600\n\
                   G1 X20 Y-10 Z-3 F900\nM2\n";
    let (_, rows) = samples("table-ac", program, "kin-tcp");
    let last = rows.last().unwrap();
    close(
        [last[7], last[8], last[9]],
        [20.0, -10.0, -3.0],
        1e-9,
        "end",
    );
    let (a, c) = (30f64.to_radians(), 40f64.to_radians());
    close(
        [last[10], last[11], last[12]],
        [a.sin() * c.sin(), a.sin() * c.cos(), a.cos()],
        1e-11,
        "axis",
    );
    // mill3: G43 H1 (35 mm) then down to Z-2: the tip at -2 while the spindle (z) is at 33;
    // no tool axis columns (no rotary joint).
    let (header, rows) = samples(
        "mill3",
        "G21 G90\nG43 H1\nG0 X10 Y20 Z5\nG1 Z-2 F600\nM2\n",
        "kin-mill",
    );
    assert_eq!(header, "t,line,x,y,z,tip_x,tip_y,tip_z");
    for r in &rows[1..] {
        assert!((r[4] - r[7] - 35.0).abs() < 1e-9, "{r:?}");
    }
    let last = rows.last().unwrap();
    close(
        [last[5], last[6], last[7]],
        [10.0, 20.0, -2.0],
        1e-9,
        "mill3 end",
    );
}

/// The report measures against the program: square corners under `G64 P0.5` are blended up to
/// 0.4 × 0.5 mm away from them, which `max_deviation_mm` shows (within the 0.5 mm in force:
/// success) while the smoothed-path figure is the chord error alone; the slack section's
/// histogram accounts for every moving second, and a straight G1 far below every limit is at
/// the feed but for its two ramps (2·2√(F/J) = 56.6 ms at F600 on mill3, ± 2 samples).
#[test]
fn the_report_measures_against_the_program_and_gives_the_slack() {
    let (prog, json) = (tmp("p05.ngc"), tmp("p05.json"));
    std::fs::write(
        &prog,
        "G21 G90 G17\nG64 P0.5\nG1 F3000 X20\nY20\nX0\nY40\nX20\nG61.1\nG1 F600 X170\nM2\n",
    )
    .unwrap();
    let out = tezgah()
        .args(["run"])
        .arg(&prog)
        .arg("--report")
        .arg(&json)
        .output()
        .unwrap();
    let r = succeeded_with_report(&out, &json);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("slack"), "{stdout}");
    let d = r["max_deviation_mm"].as_f64().unwrap();
    assert!((0.15..=0.3).contains(&d), "{d}");
    let over = r["max_deviation_over_tolerance"].as_f64().unwrap();
    assert!((d / 0.5 - over).abs() < 1e-12 && over <= 1.0, "{over}");
    let smoothed = r["max_deviation_smoothed_mm"].as_f64().unwrap();
    assert!(smoothed <= 0.2 * 0.5 && smoothed < d / 10.0, "{smoothed}");
    let slack = &r["slack"];
    let bins: Vec<f64> = slack["feed_fraction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["time_s"].as_f64().unwrap())
        .collect();
    assert_eq!(bins.len(), 11);
    let moving = slack["moving_s"].as_f64().unwrap();
    assert!((bins.iter().sum::<f64>() - moving).abs() < 1e-6, "{bins:?}");
    let share = slack["slack_share"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&share), "{share}");
    // The last move alone: 150 mm at 10 mm/s, 15 s at the feed.
    assert!(bins[10] > 15.0 - 0.06 && bins[10] < moving, "{bins:?}");
}

/// Runs `program` with `args` (the probe's source: `--probe FILE` or `--machine FILE`); the
/// output and the report's path (the samples CSV beside it, `.csv`).
fn run_probing(
    name: &str,
    program: &str,
    args: &[&std::path::Path],
) -> (std::process::Output, std::path::PathBuf) {
    let (ngc, json) = (tmp(&format!("{name}.ngc")), tmp(&format!("{name}.json")));
    std::fs::write(&ngc, program).unwrap();
    let out = tezgah()
        .arg("run")
        .arg(&ngc)
        .args(args)
        .arg("--report")
        .arg(&json)
        .arg("--samples")
        .arg(json.with_extension("csv"))
        .output()
        .unwrap();
    (out, json)
}

/// `--probe FILE` with a probe file of `text`, written as `{name}.toml`.
fn probe_option(name: &str, text: &str) -> [std::path::PathBuf; 2] {
    let file = tmp(&format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    ["--probe".into(), file]
}

/// The last row of a samples CSV (t, line, x, y, z, …).
fn last_sample(json: &std::path::Path) -> Vec<f64> {
    let text = std::fs::read_to_string(json.with_extension("csv")).unwrap();
    let last = text.lines().last().unwrap();
    last.split(',').map(|v| v.parse().unwrap()).collect()
}

/// The report's probe `k`: trip point (mm) and rest pose.
fn probe_at(report: &serde_json::Value, k: usize) -> (Vec<f64>, Vec<f64>) {
    let p = &report["probes"][k];
    let v = |key: &str| -> Vec<f64> {
        p[key]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    (v("trip_mm"), v("stopped"))
}

/// G38.2 down onto the plane z = −5 with a 2 mm ball at three feeds: the input is read once a
/// period, so each trip is at most one period's travel (F/60 · 1 ms) past the contact
/// z = −5 + 2, and the stop from that feed is the jerk-limited one of mill3's Z
/// (J = 25000 mm/s³, from cruise: d = v·√(v/J)). The program then zeroes G54 Z at the rest
/// point (G10 L20) and goes 1 mm above the probed point (#5063, program coordinates of the
/// probe time), ending where the closed form says; the verifier holds every joint within its
/// limits through the trips and stops.
#[test]
fn probing_a_plane_trips_at_the_ball_radius_and_the_program_reads_on() {
    let program = "G21 G90 G17\nG0 X10 Y10 Z10\nF120 G38.2 Z-20\nG0 Z10\nF300 G38.2 Z-20\n\
                   G0 Z10\nF600 G38.2 Z-20\nG0 Z-2.99\nG38.2 Z-20\n\
                   G10 L20 P1 Z0\nG0 Z5\nG1 X20 F600\n\
                   G0 X[10 + 5 * #5070] Z[#5063 + 1]\nM2\n";
    let probe = "tool_radius_mm = 2\n[[plane]]\npoint = [0, 0, -5]\nnormal = [0, 0, 1]\n";
    let [flag, file] = probe_option("probe-plane", probe);
    let (out, json) = run_probing("probe-plane", program, &[&flag, &file]);
    let report = succeeded_with_report(&out, &json);
    assert_joints_within_limits(&report, true, "probe-plane");
    assert!(report["max_deviation_mm"].as_f64().unwrap() <= 0.01);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("probe    G38.2 line 3: tripped at X10.0000 Y10.0000 Z-3.00"),
        "{stdout}"
    );
    for (k, feed) in [120.0, 300.0, 600.0].into_iter().enumerate() {
        let (trip, rest) = probe_at(&report, k);
        let v = feed / 60.0;
        assert_eq!((trip[0], trip[1]), (10.0, 10.0));
        assert!(
            trip[2] <= -3.0 && trip[2] > -3.0 - v * 0.001 - 1e-9,
            "{feed}: {trip:?}"
        );
        let stop = v * (v / 25000.0).sqrt();
        assert!(
            (trip[2] - rest[2] - stop).abs() < 1e-9,
            "{feed}: stopped {} past the trip, closed form {stop}",
            trip[2] - rest[2]
        );
    }
    // From 0.01 mm above the contact the trip comes while the speed still ramps up (jerk
    // phase: a ≈ J·∛(6·0.01/J) ≈ 335 mm/s²); the stop starts from that acceleration.
    let (trip, rest) = probe_at(&report, 3);
    assert!(trip[2] <= -3.0 && trip[2] > -3.0 - 10.0 * 0.001, "{trip:?}");
    assert!(rest[2] < trip[2]);
    let last = (trip[2], rest[2]);
    // Machine Z at the end: G54 Z is the rest point's machine Z; the last move goes to
    // #5063 + 1 in it, X to 10 + 5·#5070 = 15.
    let end = last_sample(&json);
    let expected = last.1 + last.0 + 1.0;
    assert_eq!(end[2], 15.0);
    assert!(
        (end[4] - expected).abs() < 1e-9,
        "end z {}, closed form {expected}",
        end[4]
    );
}

/// A machine file with a `[probe]` section: a box (X 20…40, Y −10…10, Z −30…0) and a 3 mm
/// ball. G38.2 +X trips on the −X face at x = 20 − 3 (within a period's travel past it) and
/// stops in mill3's X jerk-limited distance v·√(v/J), J = 50000 mm/s³; G38.4 backs off until
/// the contact breaks, inside the same period's travel; G38.2 −Y trips on the +Y face at
/// y = 10 + 3; G38.3 clear of the box runs to its end and the move after it uses #5070 = 0.
#[test]
fn probing_a_box_from_the_machine_file_finds_its_walls() {
    let machine =
        format!(
        "{}\n[probe]\ntool_radius_mm = 3\n[[probe.box]]\nmin = [20, -10, -30]\nmax = [40, 10, 0]\n",
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/mill3.toml"))
            .unwrap()
    );
    let file = tmp("probe-box-machine.toml");
    std::fs::write(&file, machine).unwrap();
    let program = "G21 G90\nG0 X0 Y0 Z-5\nF200 G38.2 X50\nG38.4 X0 F100\nG0 X30 Y30\n\
                   F200 G38.2 Y0\nG0 Y30\nG38.3 Y40\nG0 X[#5070 * 100 + 1]\nM2\n";
    let flag = std::path::PathBuf::from("--machine");
    let (out, json) = run_probing("probe-box", program, &[&flag, &file]);
    let report = succeeded_with_report(&out, &json);
    assert_joints_within_limits(&report, true, "probe-box");
    let (v_in, v_out) = (200.0 / 60.0, 100.0 / 60.0);
    let (trip, rest) = probe_at(&report, 0);
    assert!(trip[0] >= 17.0 && trip[0] < 17.0 + v_in * 0.001, "{trip:?}");
    let stop = v_in * (v_in / 50000.0f64).sqrt();
    assert!((rest[0] - trip[0] - stop).abs() < 1e-9, "{rest:?}");
    let (trip, _) = probe_at(&report, 1);
    assert!(
        trip[0] < 17.0 && trip[0] >= 17.0 - v_out * 0.001,
        "{trip:?}"
    );
    let (trip, _) = probe_at(&report, 2);
    assert!(trip[1] <= 13.0 && trip[1] > 13.0 - v_in * 0.001, "{trip:?}");
    let untripped = &report["probes"][3];
    assert_eq!(
        (&untripped["tripped"], &untripped["trip_mm"]),
        (&false.into(), &serde_json::Value::Null)
    );
    assert_eq!(
        untripped["stopped"],
        serde_json::json!([30.0, 40.0, -5.0, 0.0, 0.0, 0.0])
    );
    assert_eq!(last_sample(&json)[2..5], [1.0, 40.0, -5.0]);
}

/// LinuxCNC's motion errors at the probe's line: G38.2 that reaches its end, G38.4 that never
/// leaves contact, G38.2 starting in contact, G38.5 starting clear.
#[test]
fn probing_errors_name_the_probe_line() {
    let probe = "tool_radius_mm = 1\n[[plane]]\npoint = [0, 0, 0]\nnormal = [0, 0, 1]\n";
    let cases = [
        (
            "G21 G0 Z10\nF100 G38.2 Z5\nM2\n",
            "probe-miss.ngc:2:6: G38.2 move finished without making contact.",
        ),
        (
            "G21 G0 Z0.5\nF100 G38.4 Z0.2\nM2\n",
            "probe-stay.ngc:2:6: G38.4 move finished without breaking contact.",
        ),
        (
            "G21 G0 Z0.5\nF100 G38.2 Z-1\nM2\n",
            "probe-on.ngc:2:6: Probe is already tripped when starting G38.2 or G38.3 move",
        ),
        (
            "G21 G0 Z5\nF100 G38.5 Z10\nM2\n",
            "probe-off.ngc:2:6: Probe is already clear when starting G38.4 or G38.5 move",
        ),
    ];
    for (program, message) in cases {
        let name = message.split('.').next().unwrap();
        let [flag, file] = probe_option(name, probe);
        let (out, _) = run_probing(name, program, &[&flag, &file]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(stderr.contains(message), "{stderr}");
    }
}

/// A tool-length change right after a probe (G43.1) takes the rest point as the current point:
/// the next move starts there (no jump: joints within limits, the path within tolerance) and,
/// as in LinuxCNC, the program Z shifts by the length while the machine's Z stays. The next
/// probe touches with the tool tip, 1 mm below the gauge point the moves carry: it trips with
/// the tip at z = −5 + 2, and the machine's Z rests 1 mm above the tip.
#[test]
fn a_tool_length_change_after_a_probe_starts_from_the_rest_point() {
    let program = "G21 G90\nG0 X10 Y10 Z10\nF300 G38.2 Z-20\nG43.1 Z1\nG1 X20 F600\n\
                   G0 Z10\nG38.2 Z-20 F300\nM2\n";
    let probe = "tool_radius_mm = 2\n[[plane]]\npoint = [0, 0, -5]\nnormal = [0, 0, 1]\n";
    let [flag, file] = probe_option("probe-g43", probe);
    let (out, json) = run_probing("probe-g43", program, &[&flag, &file]);
    let report = succeeded_with_report(&out, &json);
    assert_joints_within_limits(&report, true, "probe-g43");
    assert!(report["max_deviation_mm"].as_f64().unwrap() <= 0.01);
    let (first, _) = probe_at(&report, 0);
    let (second, rest) = probe_at(&report, 1);
    for trip in [&first, &second] {
        assert!(trip[2] <= -3.0 && trip[2] > -3.0 - 5.0 * 0.001, "{trip:?}");
    }
    let text = std::fs::read_to_string(json.with_extension("csv")).unwrap();
    let at_x20 = text
        .lines()
        .find(|l| l.split(',').nth(1) == Some("7"))
        .unwrap();
    // The first row of line 7 (the second probe) starts where G1 X20 left the machine.
    let row: Vec<f64> = at_x20.split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(row[2..4], [20.0, 10.0]);
    let end = last_sample(&json);
    assert!(
        (end[4] - rest[2]).abs() < 1e-9 && (end[4] - end[7] - 1.0).abs() < 1e-9,
        "{end:?}"
    );
    // The tip at rest: the trip (a period's travel at most past z = −3) and the stop from
    // 5 mm/s, v·√(v/J) with mill3's Z jerk 25000 mm/s³.
    let stop = 5.0 * (5.0f64 / 25000.0).sqrt();
    assert!(
        end[7] < -3.0 && end[7] > -3.0 - 0.005 - stop - 1e-9,
        "{end:?}"
    );
}

/// `examples/probe.ngc` on `examples/probe.toml` (block top Z-20, left side X20, ball 2 mm):
/// G54 Z0 goes on the top as the first probe found it (trip − radius), the second probe finds
/// the side at X18, and the cut along Y (line 16) runs 0.5 mm under the found top, 1 mm inside
/// the found side: X = 18 + 2 + 1, Z = trip − 2 − 0.5.
#[test]
fn the_probing_example_cuts_where_it_found_the_block() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let (json, csv) = (tmp("probe-example.json"), tmp("probe-example.csv"));
    let out = tezgah()
        .arg("run")
        .arg(format!("{dir}/probe.ngc"))
        .arg("--probe")
        .arg(format!("{dir}/probe.toml"))
        .arg("--report")
        .arg(&json)
        .arg("--samples")
        .arg(&csv)
        .output()
        .unwrap();
    let report = succeeded_with_report(&out, &json);
    assert_joints_within_limits(&report, true, "probe example");
    let (top, _) = probe_at(&report, 0);
    let (side, _) = probe_at(&report, 1);
    assert!(top[2] <= -18.0 && top[2] > -18.0 - 5.0 * 0.001, "{top:?}");
    assert_eq!(side[0], 18.0);
    let text = std::fs::read_to_string(&csv).unwrap();
    let cut: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap())
                .collect::<Vec<f64>>()
        })
        .filter(|r| r[1] == 16.0)
        .collect();
    assert!(cut.len() > 100);
    // Away from the corners at its ends (blended within the path tolerance), on the line.
    let z = top[2] - 2.5;
    let inner: Vec<_> = cut.iter().filter(|r| r[3].abs() <= 9.0).collect();
    assert!(inner.len() > 100);
    for r in inner {
        assert!(
            (r[2] - 21.0).abs() < 1e-9 && (r[4] - z).abs() < 1e-9,
            "{r:?}"
        );
    }
}

/// `examples/thread.ngc`: a G33 thread (K1.5 at 600 rev/min) and a G33.1 rigid tap (K1 at
/// 300 rev/min, I2) on mill3's default spindle (50 rev/s²). The thread holds its lead within
/// the synchronisation error it reports; the tap overshoots its depth by what the spindle turns
/// while it reverses, ω²/2α = 0.25 rev × K, to within that error; the run stays within every
/// joint limit and within the tolerance of the program (the tap's turning points included).
#[test]
fn threading_and_rigid_tapping_follow_the_simulated_spindle() {
    let program = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/thread.ngc");
    let json = tmp("thread.json");
    let out = tezgah()
        .args(["run", program, "--report"])
        .arg(&json)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("sync     G33 line 7: lead 1.50000 mm/rev"),
        "{stdout}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let synced = &report["synced"];
    let f = |k: usize, key: &str| synced[k][key].as_f64().unwrap();
    // The thread: 21 mm at 1.5 mm/rev.
    let turns = 21.0 / 1.5;
    assert!((f(0, "lead_mm") - 1.5).abs() * turns <= 2.0 * f(0, "sync_error_mm") + 1e-9);
    assert!(f(0, "sync_error_mm") < 1e-3);
    assert_eq!(synced[1]["code"], "G33.1");
    let closed = 1.0 * 5.0 * 5.0 / (2.0 * 50.0);
    let overshoot = f(1, "overshoot_mm");
    assert!(
        (overshoot - closed).abs() <= f(1, "sync_error_mm") + 5e-3,
        "{overshoot} vs {closed}"
    );
    assert!(
        report["max_deviation_mm"].as_f64().unwrap() <= 0.01,
        "{report}"
    );
}

/// `check --machine` cannot play a synchronised move and says so at its line.
#[test]
fn check_with_a_machine_names_the_g33_line() {
    let ngc = tmp("g33-check.ngc");
    std::fs::write(&ngc, "G21 G90\nM3 S600\nG33 Z-5 K1\nM2\n").unwrap();
    let out = tezgah()
        .args(["check", "--machine", "mill3"])
        .arg(&ngc)
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
    assert!(
        !out.status.success()
            && text.contains("3:1")
            && text.contains("G33/G33.1 follow the spindle"),
        "{text}"
    );
}
