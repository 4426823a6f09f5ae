//! What the binary's end-to-end tests share: the binary, a scratch folder, the example tool
//! table, the checks every run report must pass (success, joint peaks within limits), and the
//! `check`-then-`run` of a posted program on table-ac that the CAM tests end with.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The example tool table (tool 1: a 6 mm ball, 28.5 mm long).
pub const TOOLS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/tools.tbl");

/// The `tezgah` binary under test, its output plain text whatever the environment asks: no
/// colour codes (`NO_COLOR`, and no `FORCE_COLOR`/`CLICOLOR_FORCE` of a CI), and, into a pipe,
/// error messages never wrapped (the binary's `miette` hook), so tests can search them.
pub fn tezgah() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tezgah"));
    c.env("NO_COLOR", "1")
        .env_remove("FORCE_COLOR")
        .env_remove("CLICOLOR_FORCE");
    c
}

/// A fresh folder in this test process's scratch folder.
pub fn tmp_dir(name: &str) -> PathBuf {
    let d = tmp(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A path in this test process's scratch folder.
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tezgah-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// The command succeeded; else its output is shown under `what`.
pub fn assert_success(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A JSON report, read back.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The run succeeded (else its output is shown) and its JSON report, read back.
pub fn succeeded_with_report(out: &Output, json: &Path) -> serde_json::Value {
    assert_success(out, "run");
    read_json(json)
}

/// Every joint's peak velocity, acceleration and jerk of a run report within 0.5 % of its
/// limit (verify's finite differences at the period), and (with `moving`) above zero.
pub fn assert_joints_within_limits(report: &serde_json::Value, moving: bool, what: &str) {
    for j in report["joints"].as_array().unwrap() {
        for q in ["velocity", "acceleration", "jerk"] {
            let peak = j[format!("peak_{q}")].as_f64().unwrap();
            let max = j[format!("max_{q}")].as_f64().unwrap();
            assert!(
                peak <= 1.005 * max && (!moving || peak > 0.0),
                "{what} {}: peak {q} {peak}, limit {max}",
                j["name"]
            );
        }
    }
}

/// `tezgah check` accepts the program `tmp("{name}.ngc")` and `tezgah run --machine table-ac`
/// executes it with every joint's peaks within 0.5 % of its limits and the path within
/// 0.01 mm; the run report (`tmp("{name}-run.json")`). With `samples`, the run writes its
/// samples CSV there.
pub fn check_and_run(name: &str, samples: Option<&Path>) -> serde_json::Value {
    let ngc = tmp(&format!("{name}.ngc"));
    let out = tezgah()
        .arg("check")
        .arg(&ngc)
        .args(["--tool-table", TOOLS])
        .output()
        .unwrap();
    assert_success(&out, &format!("check {name}"));
    let json = tmp(&format!("{name}-run.json"));
    let mut run = tezgah();
    run.arg("run")
        .arg(&ngc)
        .args(["--machine", "table-ac", "--tool-table", TOOLS, "--report"])
        .arg(&json);
    if let Some(csv) = samples {
        run.arg("--samples").arg(csv);
    }
    let out = run.output().unwrap();
    assert_success(&out, &format!("run {name}"));
    let report = read_json(&json);
    assert_joints_within_limits(&report, false, name);
    assert!(
        report["max_deviation_mm"].as_f64().unwrap() <= 0.01,
        "{name}: {report}"
    );
    report
}

/// A `tezgah serve` process, killed when dropped (also on a failed assertion).
pub struct Server(pub std::process::Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// What `tezgah serve` printed when it started.
pub struct Banner {
    /// `ws://127.0.0.1:port`
    pub ws: String,
    /// The panel's URL, with `?token=…` when one is needed.
    pub panel: String,
}

/// `tezgah serve --listen 127.0.0.1:0` with `options`, and what it printed up to the panel's
/// URL.
pub fn serve(options: &[&str]) -> (Server, Banner) {
    use std::io::{BufRead, BufReader};
    let mut child = Command::new(env!("CARGO_BIN_EXE_tezgah"))
        .args(["serve", "--listen", "127.0.0.1:0"])
        .args(options)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let server = Server(child);
    let mut lines = String::new();
    while !lines.contains("the panel is at") {
        let n = out.read_line(&mut lines).unwrap();
        assert!(n > 0, "the server stopped; it printed {lines:?}");
    }
    let word = |prefix: &str| {
        lines
            .split_whitespace()
            .find(|w| w.starts_with(prefix))
            .unwrap_or_else(|| panic!("no {prefix} in {lines:?}"))
            .to_owned()
    };
    let banner = Banner {
        ws: word("ws://"),
        panel: word("http://"),
    };
    (server, banner)
}
