//! `tezgah serve --drive ethercat:<interface>` end to end on a real interface: two network
//! namespaces joined by a veth pair, three emulated CiA-402 drives on a raw socket in one, the
//! server in the other; a WebSocket client (in the server's namespace) runs a program and the
//! drives end where the program does; a drive fault injected mid-program stops the machine with
//! the drive's code and text in the status. A machine file naming a drive the bus lacks is
//! refused at start with the drive's place.
//!
//! Needs root; without it the test says so and returns, except under CI=true, where it fails.

mod common;
#[path = "common/ws.rs"]
mod ws;

use std::process::{Child, Command, Stdio};
use std::time::Duration;

use serde_json::json;
use tezgah_ethercat::emulator::netns::{enter, DrivesOnVeth, Veth};
use tezgah_ethercat::emulator::{Bus, IDENTITY};
use tezgah_kinematics::Machine;
use ws::{request, state, wait_for};

fn can_run() -> bool {
    // SAFETY: no arguments, no side effects.
    let root = unsafe { libc::geteuid() } == 0;
    if root {
        return true;
    }
    assert!(
        std::env::var("CI").map_or(true, |v| v != "true"),
        "serve over EtherCAT needs root, and under CI=true it must run"
    );
    eprintln!("serve over EtherCAT: not run: it needs root");
    false
}

/// mill3 with its three joints on emulated drives (1000 counts/mm).
fn machine_file(products: [u32; 3]) -> std::path::PathBuf {
    let mut t = Machine::builtin_text("mill3").unwrap().to_owned();
    for (j, p) in ["x", "y", "z"].iter().zip(products) {
        t += &format!(
            "\n[[drive.slave]]\njoint = \"{j}\"\nvendor_id = {}\nproduct_code = {p}\n\
             counts_per_unit = 1000.0\nfollowing_error_limit = 1.0\n",
            IDENTITY.vendor_id
        );
    }
    let path = common::tmp_dir(&format!("serve-ethercat-{}", products[2])).join("mill3.toml");
    std::fs::write(&path, t).unwrap();
    path
}

struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `tezgah serve` in the master's namespace; the WebSocket URL, or what it printed when it
/// stopped.
fn serve(v: &Veth, machine: &std::path::Path) -> Result<(Server, String), String> {
    use std::io::{BufRead, BufReader, Read};
    let drive = format!("ethercat:{}", v.master_if);
    let mut child = Command::new("ip")
        .args([
            "netns",
            "exec",
            &v.master_ns,
            env!("CARGO_BIN_EXE_tezgah"),
            "serve",
        ])
        .args([
            "--listen",
            "127.0.0.1:0",
            "--lead-ms",
            "100",
            "--status-ms",
            "10",
        ])
        // The check is on the wiring and the faults, not on this shared computer's scheduling:
        // a frame counts as lost after 50 ms (the emulated drives run time-shared).
        .args([
            "--no-realtime",
            "--bus-timeout-ms",
            "50",
            "--drive",
            &drive,
            "--machine",
        ])
        .arg(machine)
        .env("NO_COLOR", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut err = child.stderr.take().unwrap();
    let server = Server(child);
    let mut lines = String::new();
    while !lines.contains("the panel is at") {
        if out.read_line(&mut lines).unwrap() == 0 {
            let mut e = String::new();
            let _ = err.read_to_string(&mut e);
            return Err(e);
        }
    }
    let ws = lines
        .split_whitespace()
        .find(|w| w.starts_with("ws://"))
        .unwrap()
        .to_owned();
    Ok((server, ws))
}

#[test]
fn serve_runs_a_program_on_emulated_drives_over_a_veth_pair() {
    if !can_run() {
        return;
    }
    let v = Veth::new("cli").expect("namespaces and veth");
    let drives = DrivesOnVeth::start(&v, Bus::drives(3, 1.0), false).unwrap();
    // This thread joins the server's namespace to reach its loopback.
    enter(&v.master_ns).unwrap();

    let (_server, url) = serve(&v, &machine_file([IDENTITY.product_code; 3]))
        .unwrap_or_else(|e| panic!("serve did not start: {e}"));
    let (mut ws, _) = tungstenite::connect(url).unwrap();
    let program = "G21 G90 F3000\nG1 X10 Y5\nG1 X12 Y-3 Z-1\nM2\n";
    assert_eq!(
        request(
            &mut ws,
            json!({"id": 1, "command": "load", "program": program})
        )["ok"],
        true
    );
    assert_eq!(
        request(&mut ws, json!({"id": 2, "command": "cycle_start"}))["ok"],
        true
    );
    wait_for(&mut ws, |s| state(s) == "running");
    // The planner is idle a ring ahead of the machine; then the drives arrive where the
    // program ended, to the count, and the status' measured joints say so.
    let end = [12.0, -3.0, -1.0];
    let s = wait_for(&mut ws, |s| {
        state(s) == "idle"
            && (0..3)
                .all(|i| (s["measured"][i].as_f64().unwrap_or(f64::NAN) - end[i]).abs() < 1.5e-3)
    });
    assert!(s["error"].is_null(), "{s}");
    // Each drive's state and actual position in the status.
    assert_eq!(s["drives"][0]["joint"], "x");
    assert_eq!(s["drives"][2]["state"], "operation enabled");
    assert_eq!(s["drives"][1]["position"], -3.0);
    {
        let bus = drives.bus.lock().unwrap();
        let ends: Vec<i32> = bus
            .slaves
            .iter()
            .map(|s| *s.targets.last().unwrap())
            .collect();
        assert_eq!(ends, [12_000, -3_000, -1_000]);
        // many periods went by, each one target to each drive
        assert!(bus.slaves[0].targets.len() > 300);
        assert!(bus
            .slaves
            .iter()
            .all(|s| s.targets.len() == bus.slaves[0].targets.len()));
    }

    // A drive fault mid-program stops the machine and names the drive's error.
    let program = "G21 G90 F600\nG1 X40\nG1 X0\nM2\n";
    assert_eq!(
        request(
            &mut ws,
            json!({"id": 3, "command": "load", "program": program})
        )["ok"],
        true
    );
    assert_eq!(
        request(&mut ws, json!({"id": 4, "command": "cycle_start"}))["ok"],
        true
    );
    wait_for(&mut ws, |s| state(s) == "running");
    std::thread::sleep(Duration::from_millis(200));
    drives.bus.lock().unwrap().slaves[1]
        .servo
        .inject_fault(0x7121);
    let s = wait_for(&mut ws, |s| state(s) == "fault");
    let e = s["error"].as_str().unwrap_or_default();
    assert!(
        e.contains("joint 1: drive error 0x7121: motor blocked"),
        "{s}"
    );
}

#[test]
fn a_drive_the_bus_lacks_is_refused_at_start() {
    if !can_run() {
        return;
    }
    let v = Veth::new("cl2").expect("namespaces and veth");
    let _drives = DrivesOnVeth::start(&v, Bus::drives(3, 1.0), false).unwrap();
    let e = match serve(
        &v,
        &machine_file([IDENTITY.product_code, IDENTITY.product_code, 0x99]),
    ) {
        Ok(_) => panic!("serve started"),
        Err(e) => e,
    };
    assert!(
        e.contains("slave 2 is vendor 0x00000e5a product 0x00000402 (tezgah emulated CiA-402 drive); drive.slave[2] (joint z) wants vendor 0x00000e5a product 0x00000099"),
        "{e}"
    );
}
