//! The operator panel: its pages over plain HTTP from `tezgah serve`, and end to end in a real
//! browser — Debian's Chromium driven by `playwright-core` (`tests/panel/e2e.cjs`) loads a
//! program, runs it, holds and resumes, jogs, steps, sends MDI, zero-sets and hands control
//! to a second page; screenshots go to `target/tmp/panel-shots`.
//!
//! The browser test needs `node`, Chromium (`TEZGAH_CHROMIUM`, else `/usr/bin/chromium`) and
//! playwright-core (`TEZGAH_PLAYWRIGHT_CORE`, else `~/.cache/tezgah/playwright/node_modules/
//! playwright-core`, where `.ci/run` installs it). Without them it is skipped — except in CI
//! (`CI=true`), where it fails.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

/// The server on a free loopback port, and the panel's URL it printed.
fn launch() -> (common::Server, String) {
    let (server, banner) = common::serve(&["--lead-ms", "100", "--status-ms", "20"]);
    (server, banner.panel)
}

/// A raw HTTP/1.1 GET; the response whole.
fn get(url: &str, path: &str, host: Option<&str>) -> String {
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = TcpStream::connect(addr).unwrap();
    let host = host.unwrap_or(addr);
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut r = String::new();
    s.read_to_string(&mut r).unwrap();
    r
}

#[test]
fn serve_hands_out_the_panel_and_its_files() {
    let (_server, url) = launch();
    let page = get(&url, "/", None);
    assert!(page.starts_with("HTTP/1.1 200 OK\r\n"), "{page}");
    assert!(page.contains("Content-Type: text/html"), "{page}");
    assert!(page.contains("Content-Security-Policy: default-src 'self'"));
    assert!(page.contains("X-Frame-Options: DENY"));
    assert!(page.contains("<title>tezgah panel</title>"));
    for (file, needle) in [
        ("/panel.js", "export"),
        ("/view3d.js", "class View3D"),
        ("/plots.js", "drawPlots"),
        ("/panel.css", "#dro"),
    ] {
        let r = get(&url, file, None);
        assert!(r.starts_with("HTTP/1.1 200 OK"), "{file}: {r}");
        assert!(r.contains(needle) || file == "/panel.js", "{file}");
    }
    let js = get(&url, "/panel.js", None);
    assert!(
        js.contains("text/javascript") && js.contains("new WebSocket"),
        "{js}"
    );
    assert!(get(&url, "/nothing", None).starts_with("HTTP/1.1 404"));
    // Bytes that are not UTF-8 in the request line: answered at once, not waited on.
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut sock = TcpStream::connect(addr).unwrap();
    sock.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let mut bad = b"GET /\xff\xfe\xfd HTTP/1.1\r\nHost: ".to_vec();
    bad.extend(addr.as_bytes());
    bad.extend(b"\r\n\r\n");
    sock.write_all(&bad).unwrap();
    let mut r = String::new();
    let started = Instant::now();
    sock.read_to_string(&mut r).unwrap();
    assert!(r.starts_with("HTTP/1.1 404"), "{r}");
    assert!(started.elapsed() < Duration::from_secs(2));
    // Not GET: refused.
    let mut sock = TcpStream::connect(addr).unwrap();
    write!(
        sock,
        "POST / HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 0\r\n\r\n"
    )
    .unwrap();
    let mut r = String::new();
    sock.read_to_string(&mut r).unwrap();
    assert!(r.starts_with("HTTP/1.1 405"), "{r}");
    // A page of another name re-pointed at loopback (DNS rebinding) gets nothing.
    let port = url.trim_end_matches('/').rsplit(':').next().unwrap();
    let r = get(&url, "/", Some(&format!("evil.example.com:{port}")));
    assert!(r.starts_with("HTTP/1.1 403"), "{r}");
}

/// What the browser test needs, or why it cannot run.
fn browser_tools() -> Result<(PathBuf, PathBuf), String> {
    let chromium = std::env::var_os("TEZGAH_CHROMIUM")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
    if !chromium.exists() {
        return Err(format!("no Chromium at {}", chromium.display()));
    }
    let playwright = std::env::var_os("TEZGAH_PLAYWRIGHT_CORE")
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME").map(|h| {
                PathBuf::from(h).join(".cache/tezgah/playwright/node_modules/playwright-core")
            })
        })
        .ok_or("no HOME to find playwright-core in")?;
    if !playwright.join("package.json").exists() {
        return Err(format!("no playwright-core at {}", playwright.display()));
    }
    match Command::new("node").arg("--version").output() {
        Ok(o) if o.status.success() => Ok((chromium, playwright)),
        _ => Err("no node on PATH".into()),
    }
}

#[test]
fn panel_runs_the_machine_in_a_real_browser() {
    let (chromium, playwright) = match browser_tools() {
        Ok(t) => t,
        Err(why) if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("the browser test cannot run in CI: {why} (.ci/run installs Chromium and playwright-core)")
        }
        Err(why) => {
            eprintln!("skipped: {why}");
            return;
        }
    };
    let (_server, url) = launch();
    let shots = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("panel-shots");
    let _ = std::fs::remove_dir_all(&shots);
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/panel/e2e.cjs");
    let mut child = Command::new("node")
        .arg(script)
        .arg(&url)
        .arg(&shots)
        .env("PLAYWRIGHT_CORE", &playwright)
        .env("CHROMIUM", &chromium)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // At most two minutes.
    let deadline = Instant::now() + Duration::from_secs(120);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            break None;
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut out = String::new();
    let mut err = String::new();
    let _ = child.stdout.take().unwrap().read_to_string(&mut out);
    let _ = child.stderr.take().unwrap().read_to_string(&mut err);
    println!("{out}");
    let status =
        status.unwrap_or_else(|| panic!("the browser test took over 2 minutes\n{out}\n{err}"));
    assert!(status.success(), "{out}\n{err}");
    for check in [
        "a file opened from disk is shown",
        "line 3 highlighted",
        "feed override slider 150 % then 100 %",
        "held still at X",
        "ten plots after the run",
        "jogged X to",
        "INC Y by 0.1",
        "MDI in the history",
        "MDI X5 in the zeroed frame is machine X 55",
        "the first page now watches",
        "no page errors",
        "real-time lateness shown",
        "fits a 768 px wide tablet",
    ] {
        assert!(
            out.contains(&format!("ok: {check}")),
            "{check} missing:\n{out}"
        );
    }
    for shot in [
        "panel-loaded.png",
        "panel-held.png",
        "panel-after.png",
        "panel-watching.png",
    ] {
        let len = std::fs::metadata(shots.join(shot))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(len > 20_000, "{shot}: {len} bytes");
    }
}
