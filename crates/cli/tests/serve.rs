//! `tezgah serve` end to end: the binary on a free port, a WebSocket client that loads and
//! runs a program, mixes in MDI, holds, resumes and aborts, and reads the status stream; a
//! program calling subroutine files from `--subroutine-path`, refused with the file's place or
//! run. The executor runs on the wall clock here, so the checks are on states and positions,
//! never on timings.

mod common;
#[path = "common/ws.rs"]
mod ws;

use common::{Banner, Server};
use serde_json::{json, Value};
use tungstenite::Message;
use ws::{next, request, state, wait_for, Socket};

fn start() -> (Server, Socket) {
    start_with(&[])
}

/// The server with `extra` options, and a client connected to it.
fn start_with(extra: &[&str]) -> (Server, Socket) {
    let (server, banner) = launch(extra);
    let (ws, _) = tungstenite::connect(banner.ws.clone()).unwrap();
    (server, ws)
}

/// The server with `extra` options, and what it printed.
fn launch(extra: &[&str]) -> (Server, Banner) {
    let mut options = vec!["--lead-ms", "200", "--status-ms", "10"];
    options.extend(extra);
    common::serve(&options)
}

/// A handshake request to `url` with extra headers.
fn handshake(url: &str, headers: &[(&str, &str)]) -> Result<Socket, Box<tungstenite::Error>> {
    use tungstenite::client::IntoClientRequest;
    let mut request = url.into_client_request().unwrap();
    for (k, v) in headers {
        request.headers_mut().insert(
            tungstenite::http::HeaderName::from_bytes(k.as_bytes()).unwrap(),
            v.parse().unwrap(),
        );
    }
    tungstenite::connect(request)
        .map(|(ws, _)| ws)
        .map_err(Box::new)
}

/// The HTTP status of a refused handshake, and its body.
fn refused(result: Result<Socket, Box<tungstenite::Error>>) -> (u16, String) {
    match result.map_err(|e| *e) {
        Err(tungstenite::Error::Http(response)) => (
            response.status().as_u16(),
            String::from_utf8_lossy(response.body().as_deref().unwrap_or_default()).into_owned(),
        ),
        Err(e) => panic!("refused otherwise: {e}"),
        Ok(_) => panic!("the handshake was accepted"),
    }
}

/// Reads messages until a `control` message comes.
fn control(ws: &mut Socket) -> Value {
    loop {
        let m = next(ws);
        if m["type"] == "control" {
            return m;
        }
    }
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
    // The real-time thread's lateness is reported (the wall clock's: some, well under 1 s).
    let late = end["late_worst_s"].as_f64().unwrap();
    assert!((0.0..1.0).contains(&late), "{late}");
    assert!(end["late_over_half"].is_u64(), "{end}");

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

#[test]
fn serve_refuses_a_foreign_origin_before_any_command() {
    let (_server, banner) = launch(&[]);
    let port = banner.ws.rsplit(':').next().unwrap().to_owned();
    let (status, body) = refused(handshake(
        &banner.ws,
        &[("Origin", "http://evil.example.com")],
    ));
    assert_eq!(status, 403);
    assert!(body.contains("evil.example.com"), "{body}");
    // DNS rebinding: a page of evil.example.com resolved to 127.0.0.1 names its own host.
    let (status, body) = refused(handshake(
        &banner.ws,
        &[
            ("Host", &format!("evil.example.com:{port}")),
            ("Origin", &format!("http://evil.example.com:{port}")),
        ],
    ));
    assert_eq!(status, 403);
    assert!(body.contains("loopback"), "{body}");
    // The server's own page is welcome, and nothing was loaded by the refused ones.
    let own = format!("http://127.0.0.1:{port}");
    let mut ws = handshake(&banner.ws, &[("Origin", &own)]).unwrap();
    let s = wait_for(&mut ws, |_| true);
    assert_eq!(s["program_loaded"], false);
    assert_eq!(state(&s), "idle");
    let r = request(&mut ws, json!({"command": "mdi", "block": "G1 X1 F600"}));
    assert_eq!(r["ok"], true, "{r}");
}

#[test]
fn serve_lets_one_client_drive_and_the_others_watch_until_they_take_control() {
    let (_server, banner) = launch(&[]);
    let (mut a, _) = tungstenite::connect(banner.ws.clone()).unwrap();
    let c = control(&mut a);
    assert_eq!(
        (c["you"].as_bool(), c["holder"].clone()),
        (Some(true), c["client"].clone())
    );
    let (mut b, _) = tungstenite::connect(banner.ws.clone()).unwrap();
    let c = control(&mut b);
    assert_eq!(c["you"], false);
    let (a_id, b_id) = (c["holder"].as_u64().unwrap(), c["client"].as_u64().unwrap());
    assert_ne!(a_id, b_id);

    // The watcher sees the status but cannot command.
    let r = request(
        &mut b,
        json!({"id": 1, "command": "mdi", "block": "G1 X7 F1200"}),
    );
    assert_eq!(
        (r["id"].as_u64(), r["ok"].as_bool()),
        (Some(1), Some(false))
    );
    let e = r["error"].as_str().unwrap();
    assert!(
        e.contains("watching") && e.contains(&format!("client {a_id} holds control")),
        "{e}"
    );
    let s = wait_for(&mut b, |_| true);
    assert_eq!(state(&s), "idle");
    assert_eq!(tip(&s)[0], 0.0, "the refused MDI did not move the machine");

    // Taking control is announced to both; then the roles swap.
    let r = request(&mut b, json!({"id": 2, "command": "take_control"}));
    assert_eq!(r["ok"], true, "{r}");
    let c = control(&mut a);
    assert_eq!(
        (c["you"].as_bool(), c["holder"].as_u64()),
        (Some(false), Some(b_id))
    );
    let c = control(&mut b);
    assert_eq!(
        (c["you"].as_bool(), c["holder"].as_u64()),
        (Some(true), Some(b_id))
    );
    let r = request(&mut a, json!({"command": "abort"}));
    assert_eq!(r["ok"], false, "{r}");
    let r = request(&mut b, json!({"command": "mdi", "block": "G1 X7 F1200"}));
    assert_eq!(r["ok"], true, "{r}");
    wait_for(&mut a, |s| {
        state(s) == "idle" && (tip(s)[0] - 7.0).abs() < 1e-9
    });

    // Released, nobody drives until someone takes it; closing the holder frees it too.
    let r = request(&mut b, json!({"command": "release_control"}));
    assert_eq!(r["ok"], true, "{r}");
    assert_eq!(control(&mut a)["holder"], Value::Null);
    let r = request(&mut b, json!({"command": "home"}));
    assert!(
        r["error"]
            .as_str()
            .unwrap()
            .contains("nobody holds control"),
        "{r}"
    );
    let r = request(&mut a, json!({"command": "take_control"}));
    assert_eq!(r["ok"], true, "{r}");
    assert_eq!(control(&mut b)["holder"].as_u64(), Some(a_id));
    a.close(None).unwrap();
    drop(a);
    let c = control(&mut b);
    assert_eq!(
        (c["you"].as_bool(), c["holder"].clone()),
        (Some(false), Value::Null)
    );
}

#[test]
fn serve_requires_the_token_when_told_and_reads_it_from_a_file() {
    // Off loopback the token is always required (the rule is unit-tested in access.rs);
    // `--require-token` applies the same rule here, since tests stay on loopback.
    let (_server, banner) = launch(&["--require-token"]);
    let token = banner
        .panel
        .split_once("?token=")
        .unwrap_or_else(|| panic!("no token in {}", banner.panel))
        .1
        .to_owned();
    assert_eq!(token.len(), 32, "{token}");
    let (status, body) = refused(handshake(&banner.ws, &[]));
    assert_eq!(status, 403);
    assert!(body.contains("token is required"), "{body}");
    let (status, body) = refused(handshake(&format!("{}/?token=0123", banner.ws), &[]));
    assert_eq!((status, body.trim()), (403, "refused: wrong token"));
    let mut ws = handshake(&format!("{}/?token={token}", banner.ws), &[]).unwrap();
    assert_eq!(control(&mut ws)["you"], true);
    let mut ws = handshake(&banner.ws, &[("Authorization", &format!("Bearer {token}"))]).unwrap();
    assert_eq!(control(&mut ws)["you"], false);

    let dir = common::tmp_dir("serve-token");
    let file = dir.join("token");
    std::fs::write(&file, "correct-horse-battery-staple\n").unwrap();
    let (_server, banner) = launch(&["--token-file", file.to_str().unwrap()]);
    assert!(
        banner
            .panel
            .ends_with("?token=correct-horse-battery-staple"),
        "{}",
        banner.panel
    );
    assert_eq!(refused(handshake(&banner.ws, &[])).0, 403);
    let url = format!("{}/?token=correct-horse-battery-staple", banner.ws);
    assert!(handshake(&url, &[]).is_ok());
}

#[test]
fn serve_answers_malformed_and_oversized_messages_and_the_job_goes_on() {
    let (_server, banner) = launch(&[]);
    let (mut ws, _) = tungstenite::connect(banner.ws.clone()).unwrap();
    let r = request(&mut ws, json!({"command": "mdi", "block": "G1 X60 F600"}));
    assert_eq!(r["ok"], true, "{r}");
    wait_for(&mut ws, |s| state(s) == "running" && tip(s)[0] > 1.0);

    // Malformed: answered, the connection stays.
    for garbage in ["{", "[1,2]", "{\"command\": 5}", "\u{0}\u{1}"] {
        ws.send(Message::text(garbage)).unwrap();
        let r = request_reply(&mut ws);
        assert_eq!(r["ok"], false, "{garbage}: {r}");
        assert!(
            r["error"].as_str().unwrap().contains("not a command"),
            "{r}"
        );
    }
    ws.send(Message::binary(vec![0xffu8; 1000])).unwrap();
    let r = request_reply(&mut ws);
    assert!(r["error"].as_str().unwrap().contains("binary"), "{r}");
    // 5 MB of garbage is within the limit (16 MiB): answered, the connection stays.
    let garbage: String = (0..5_000_000)
        .map(|i| (b'a' + (i % 26) as u8) as char)
        .collect();
    ws.send(Message::text(garbage)).unwrap();
    let r = request_reply(&mut ws);
    assert!(
        r["error"].as_str().unwrap().contains("not a command"),
        "{r}"
    );
    let s = wait_for(&mut ws, |_| true);
    assert_eq!(state(&s), "running", "{s}");

    // Oversized (17 MB): answered, then that connection is closed.
    let x_before = tip(&s)[0];
    let big = "x".repeat(17 << 20);
    let _ = ws.send(Message::text(big));
    let r = request_reply(&mut ws);
    let e = r["error"].as_str().unwrap();
    assert!(
        e.contains("message too large") && e.contains("16 MiB"),
        "{e}"
    );
    loop {
        match ws.read() {
            Ok(Message::Close(Some(frame))) => {
                assert_eq!(u16::from(frame.code), 1009);
                break;
            }
            Ok(_) => {}
            Err(e) => panic!("no close frame: {e}"),
        }
    }
    // The job was not disturbed: a new connection finds it running further on, to its end.
    let (mut watcher, _) = tungstenite::connect(banner.ws.clone()).unwrap();
    let s = wait_for(&mut watcher, |_| true);
    assert_eq!(state(&s), "running", "{s}");
    assert!(tip(&s)[0] > x_before, "{s}");
    let end = wait_for(&mut watcher, |s| state(s) == "idle");
    assert!((tip(&end)[0] - 60.0).abs() < 1e-9, "{end}");
    assert_eq!(end["error"], Value::Null);
    assert_eq!(end["underruns"], 0);
}

/// The next reply (status and control messages in between are skipped).
fn request_reply(ws: &mut Socket) -> Value {
    loop {
        let m = next(ws);
        if m["type"] == "reply" {
            return m;
        }
    }
}

#[test]
fn serve_reports_the_tool_axis_on_a_machine_with_rotary_joints() {
    let (_server, mut ws) = start_with(&["--machine", "table-ac"]);
    let s = wait_for(&mut ws, |_| true);
    let axis = |s: &Value| [0, 1, 2].map(|i| s["tool_axis"][i].as_f64().unwrap());
    let a = axis(&s);
    assert!((a[2] - 1.0).abs() < 1e-12 && a[0].abs() < 1e-12, "{a:?}");
    // The table tilted 30° about X: in the workpiece frame the tool leans 30° off Z, in Y Z.
    let r = request(&mut ws, json!({"command": "mdi", "block": "G0 A30"}));
    assert_eq!(r["ok"], true, "{r}");
    let s = wait_for(&mut ws, |s| state(s) == "idle" && s["mode"] == "mdi");
    let a = axis(&s);
    let c = 30f64.to_radians();
    assert!(a[0].abs() < 1e-9, "{a:?}");
    assert!((a[1].abs() - c.sin()).abs() < 1e-9, "{a:?}");
    assert!((a[2] - c.cos()).abs() < 1e-9, "{a:?}");
    // A machine without rotary joints sends none.
    let (_server, mut ws) = start();
    let s = wait_for(&mut ws, |_| true);
    assert!(s.get("tool_axis").is_none(), "{s}");
}

/// A program that probes, on mill3 with a plane in its machine file's `[probe]`: the status
/// stream reports the probe (fitted, the input, the last probe move's trip), and the move after
/// the probe lands at the probed height.
#[test]
fn serve_probes_on_the_machine_files_probe_and_reports_it() {
    let dir = std::env::temp_dir().join(format!("tezgah-serve-probe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let machine = dir.join("mill3-probe.toml");
    let mill3 = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../machines/mill3.toml"),
    )
    .unwrap();
    let probe = "\n[probe]\ntool_radius_mm = 1.0\n[[probe.plane]]\npoint = [0, 0, -4]\n\
                 normal = [0, 0, 1]\n";
    std::fs::write(&machine, mill3 + probe).unwrap();
    let (_server, mut ws) = start_with(&["--machine", machine.to_str().unwrap()]);
    let first = wait_for(&mut ws, |_| true);
    assert_eq!(first["probe"]["fitted"], true, "{first}");
    let program = "G21 G90\nG0 X3 Z2\nG38.2 Z-10 F600\nG0 X6 Z[#5063 + 0.5]\nM2\n";
    let r = request(
        &mut ws,
        json!({"id": 1, "command": "load", "program": program}),
    );
    assert_eq!(r["ok"], true, "{r}");
    let r = request(&mut ws, json!({"id": 2, "command": "cycle_start"}));
    assert_eq!(r["ok"], true, "{r}");
    let touching = wait_for(&mut ws, |s| s["probe"]["input"] == true);
    assert_eq!(touching["probe"]["probing"], true, "{touching}");
    let end = wait_for(&mut ws, |s| state(s) == "idle" && tip(s)[0] == 6.0);
    let last = &end["probe"]["last"];
    assert_eq!(
        (&last["code"], &last["tripped"]),
        (&json!("G38.2"), &json!(true))
    );
    let z = last["trip_mm"][2].as_f64().unwrap();
    // Contact at z = -4 + 1; at most one period's travel (10 mm/s × 1 ms) past it.
    assert!(z <= -3.0 && z > -3.0 - 0.01 - 1e-12, "trip {z}");
    assert!((tip(&end)[2] - (z + 0.5)).abs() < 1e-9, "{end}");
    assert_eq!(end["probe"]["input"], false);
    assert!(end["error"].is_null(), "{end}");
    std::fs::remove_dir_all(&dir).ok();
}
