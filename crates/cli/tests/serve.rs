//! `tezgah serve` end to end: the binary on a free port, a WebSocket client that loads and
//! runs a program, mixes in MDI, holds, resumes and aborts, and reads the status stream; a
//! program calling subroutine files from `--subroutine-path`, refused with the file's place or
//! run. The executor runs on the wall clock here, so the checks are on states and positions,
//! never on timings.

mod common;

use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

type Socket = WebSocket<MaybeTlsStream<TcpStream>>;

/// The server process, killed when the test ends (also on a failed assertion).
struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn start() -> (Server, Socket) {
    start_with(&[])
}

/// The server with `extra` options.
fn start_with(extra: &[&str]) -> (Server, Socket) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tezgah"))
        .args(["serve", "--listen", "127.0.0.1:0", "--lead-ms", "200"])
        .args(["--status-ms", "10"])
        .args(extra)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let server = Server(child);
    let url = first
        .split_whitespace()
        .find(|w| w.starts_with("ws://"))
        .unwrap_or_else(|| panic!("no address in {first:?}"))
        .to_owned();
    let (ws, _) = tungstenite::connect(url).unwrap();
    (server, ws)
}

fn next(ws: &mut Socket) -> Value {
    loop {
        if let Message::Text(t) = ws.read().unwrap() {
            return serde_json::from_str(t.as_str()).unwrap();
        }
    }
}

/// Sends a request and returns its reply (status messages in between are skipped).
fn request(ws: &mut Socket, message: Value) -> Value {
    ws.send(Message::text(message.to_string())).unwrap();
    loop {
        let m = next(ws);
        if m["type"] == "reply" {
            return m;
        }
    }
}

/// Reads statuses until `done` holds for one (at most 20 s of wall time).
fn wait_for(ws: &mut Socket, done: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut last = Value::Null;
    loop {
        assert!(
            Instant::now() < deadline,
            "timed out waiting for a status; the last: {last}"
        );
        let m = next(ws);
        if m["type"] == "status" {
            if done(&m) {
                return m;
            }
            last = m;
        }
    }
}

fn state(status: &Value) -> &str {
    status["state"]["state"].as_str().unwrap()
}

fn tip(status: &Value) -> [f64; 3] {
    let t = &status["tip"];
    [0, 1, 2].map(|i| t[i].as_f64().unwrap())
}

#[test]
fn serve_runs_programs_mdi_hold_resume_and_abort_over_a_websocket() {
    let (_server, mut ws) = start();

    // Refusals are replies with the reason, and change nothing.
    let r = request(&mut ws, json!({"id": 1, "command": "fly"}));
    assert_eq!(r["ok"], false);
    assert!(
        r["error"].as_str().unwrap().contains("not a command"),
        "{r}"
    );
    let r = request(
        &mut ws,
        json!({"id": 2, "command": "feed_override", "percent": 250}),
    );
    assert_eq!(
        (r["id"].as_u64(), r["ok"].as_bool()),
        (Some(2), Some(false))
    );
    let r = request(&mut ws, json!({"id": 3, "command": "cycle_start"}));
    assert_eq!(r["ok"], false, "no program loaded: {r}");

    // AUTO: load, start, run to the end; the executing line passes 2 and 3.
    let program = "G21 G90\nG1 X10 Y5 F3000\nG1 X20 Y0\nM2\n";
    let r = request(
        &mut ws,
        json!({"id": 4, "command": "load", "program": program}),
    );
    assert_eq!(r["ok"], true, "{r}");
    let r = request(&mut ws, json!({"id": 5, "command": "cycle_start"}));
    assert_eq!(r["ok"], true, "{r}");
    wait_for(&mut ws, |s| s["executing_line"] == 2);
    wait_for(&mut ws, |s| s["executing_line"] == 3);
    let end = wait_for(&mut ws, |s| state(s) == "idle");
    let p = tip(&end);
    assert!((p[0] - 20.0).abs() < 1e-9 && p[1].abs() < 1e-9, "{p:?}");
    assert_eq!(end["underruns"], 0);

    // MDI between programs.
    let r = request(
        &mut ws,
        json!({"id": 6, "command": "mdi", "block": "G1 X5 F1200"}),
    );
    assert_eq!(r["ok"], true, "{r}");
    let end = wait_for(&mut ws, |s| {
        state(s) == "idle" && (tip(s)[0] - 5.0).abs() < 1e-9
    });
    assert_eq!(end["mode"], "mdi");

    // A long move, held on the way: the tool stops and stays; resume goes on; abort ends it.
    let r = request(&mut ws, json!({"command": "mdi", "block": "G1 X100 F600"}));
    assert_eq!(r["ok"], true, "{r}");
    wait_for(&mut ws, |s| tip(s)[0] > 6.0);
    let r = request(&mut ws, json!({"command": "feed_hold"}));
    assert_eq!(r["ok"], true, "{r}");
    let held = wait_for(&mut ws, |s| state(s) == "held");
    let x_held = tip(&held)[0];
    assert!(x_held > 6.0 && x_held < 100.0, "{x_held}");
    for _ in 0..20 {
        let s = wait_for(&mut ws, |_| true);
        assert_eq!(tip(&s)[0], x_held, "a held machine stands still");
    }
    let r = request(&mut ws, json!({"command": "resume"}));
    assert_eq!(r["ok"], true, "{r}");
    wait_for(&mut ws, |s| tip(s)[0] > x_held + 0.5);
    let r = request(&mut ws, json!({"command": "abort"}));
    assert_eq!(r["ok"], true, "{r}");
    let end = wait_for(&mut ws, |s| state(s) == "idle");
    let x = tip(&end)[0];
    assert!(x > x_held + 0.5 && x < 100.0, "abort stops on the way: {x}");
    assert_eq!(end["underruns"], 0);
    let r = request(&mut ws, json!({"command": "close"}));
    assert_eq!(r["ok"], false);
}

#[test]
fn serve_loads_subroutine_files_and_names_them_in_errors() {
    let dir = common::tmp_dir("serve-subs");
    // Line 3 of far.ngc leaves mill3's X range; near.ngc ends at X20 Y5.
    for (name, body) in [
        ("far", "G1 X10\n  G1 X5000\n"),
        ("near", "G1 X10\nG1 X20 Y5\n"),
    ] {
        let text = format!("o<{name}> sub\n{body}o<{name}> endsub\nM2\n");
        std::fs::write(dir.join(format!("{name}.ngc")), text).unwrap();
    }
    let (_server, mut ws) = start_with(&["--subroutine-path", dir.to_str().unwrap()]);
    // The program's line 3 is blank: the file's line 3 taken for the program's would show.
    let program = |name: &str| format!("G21 G90\nF3000\n\no<{name}> call\nM2\n");
    let r = request(
        &mut ws,
        json!({"id": 1, "command": "load", "program": program("far")}),
    );
    assert_eq!(r["ok"], false, "{r}");
    let place = format!(
        "{}:3:3: out of reach before anything moves",
        dir.join("far.ngc").display()
    );
    assert!(r["error"].as_str().unwrap().contains(&place), "{r}");
    let r = request(
        &mut ws,
        json!({"id": 2, "command": "load", "program": program("near")}),
    );
    assert_eq!(r["ok"], true, "{r}");
    let r = request(&mut ws, json!({"id": 3, "command": "cycle_start"}));
    assert_eq!(r["ok"], true, "{r}");
    wait_for(&mut ws, |s| {
        state(s) == "idle" && (tip(s)[0] - 20.0).abs() < 1e-9 && (tip(s)[1] - 5.0).abs() < 1e-9
    });
}
