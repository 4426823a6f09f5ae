//! The veth rig the namespace test and the soak example share: two network namespaces and a
//! veth pair between them, the emulated drives on a raw socket in one, the master in the other,
//! a path run at 1 ms with its timing figures, and a tshark capture of the master's side.
//! Included by `tests/veth.rs` and `examples/veth_soak.rs` (`#[path]`), one copy.

#![allow(dead_code)]

use std::fs::File;
use std::process::{Child, Command, Stdio};

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::{machine_and_section, COUNTS_PER_MM, PERIOD};
use tezgah_ethercat::drive::EthercatDrive;
pub use tezgah_ethercat::emulator::netns::Veth;
use tezgah_ethercat::emulator::netns::{enter, DrivesOnVeth};
use tezgah_ethercat::emulator::Bus;
use tezgah_ethercat::master::link::RawSocket;
use tezgah_ethercat::master::MasterOptions;
use tezgah_executor::{Drive, SetPoint};
use tezgah_kinematics::Joints;

pub fn ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// Whether the test can run here; under CI it must.
pub fn can_run(what: &str) -> bool {
    // SAFETY: no arguments, no side effects.
    let root = unsafe { libc::geteuid() } == 0;
    let ip = Command::new("ip").arg("-V").output().is_ok();
    if root && ip {
        return true;
    }
    let why = if root {
        "the `ip` command (iproute2) is missing"
    } else {
        "it needs root"
    };
    assert!(!ci(), "{what}: {why}, and under CI=true it must run");
    eprintln!("{what}: not run: {why}");
    false
}

/// A tshark capture on the master's interface.
pub struct Capture {
    child: Child,
    file: std::path::PathBuf,
}

pub fn tshark_available() -> bool {
    let ok = Command::new("tshark")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        ok || !ci(),
        "tshark (Debian `tshark`) is missing, and under CI=true it must run"
    );
    if !ok {
        eprintln!("tshark missing: the dissector check is not run");
    }
    ok
}

impl Capture {
    pub fn start(v: &Veth) -> Capture {
        let dir = std::env::temp_dir().join(format!("tezgah-veth-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("bus.pcapng");
        let err = dir.join("tshark.err");
        let child = Command::new("ip")
            .args([
                "netns",
                "exec",
                &v.master_ns,
                "tshark",
                "-i",
                &v.master_if,
                "-q",
            ])
            // EtherCAT only: the kernel's own IPv6 neighbour discovery shares the link.
            .args(["-f", "ether proto 0x88a4", "-w"])
            .arg(&file)
            .stdout(Stdio::null())
            .stderr(File::create(&err).unwrap())
            .spawn()
            .expect("starting tshark");
        let t = Instant::now();
        while !std::fs::read_to_string(&err)
            .unwrap_or_default()
            .contains("Capturing on")
        {
            assert!(
                t.elapsed() < Duration::from_secs(30),
                "tshark did not start"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
        Capture { child, file }
    }

    /// Stops the capture; returns each frame's protocol stack and the malformed frames.
    pub fn finish(mut self) -> (Vec<String>, usize) {
        // Let the capture write the last frames out, then stop it.
        std::thread::sleep(Duration::from_millis(300));
        // SAFETY: signalling our own child.
        unsafe { libc::kill(self.child.id() as i32, libc::SIGINT) };
        let _ = self.child.wait();
        let fields = |filter: &str| {
            let out = Command::new("tshark")
                .arg("-r")
                .arg(&self.file)
                .args(["-Y", filter, "-T", "fields", "-e", "frame.protocols"])
                .output()
                .expect("tshark -r");
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .map(str::to_owned)
                .collect::<Vec<_>>()
        };
        let all = fields("frame");
        let malformed = fields("_ws.malformed || _ws.expert.severity >= 8388608").len();
        (all, malformed)
    }
}

/// Figures of a run.
#[derive(Debug, Default)]
pub struct Figures {
    pub cycles: u64,
    /// Wake-up lateness of the cycle, µs: worst and mean.
    pub late_worst_us: f64,
    pub late_mean_us: f64,
    /// Frame out to answer in, µs: worst and mean.
    pub exchange_worst_us: f64,
    pub exchange_mean_us: f64,
    /// Cycles whose exchange ended past the next period's start.
    pub overran: u64,
}

pub fn path(k: u64) -> [f64; 3] {
    let t = k as f64 * 1e-3;
    [
        20.0 * (1.3 * t).sin(),
        10.0 * (0.9 * t).sin(),
        2.0 * (2.1 * t).sin(),
    ]
}

/// Runs `cycles` set-points at 1 ms through drives on the veth; returns the figures, the
/// drive and the emulated bus. `realtime`: the drives' thread at SCHED_FIFO (as hardware, it
/// answers at once; the soak asks for it, the test leaves the scheduler alone).
pub fn run(v: &Veth, cycles: u64, realtime: bool) -> (Figures, EthercatDrive, Arc<Mutex<Bus>>) {
    // The drives listen before the master sends its first frame.
    let drives = DrivesOnVeth::start(v, Bus::drives(3, 1.0), realtime)
        .expect("the emulated drives on the veth");
    let bus = drives.bus.clone();
    enter(&v.master_ns).expect("entering the master's namespace");
    let (m, s) = machine_and_section(["x", "y", "z"], 1.0);
    let link = RawSocket::open(&v.master_if).expect("raw socket");
    let options = MasterOptions {
        // The test checks the wire, not this shared computer's scheduling: a frame counts as
        // lost after 20 ms; cycles that overran the 1 ms period are counted as a figure.
        cycle_timeout: Duration::from_millis(20),
        open_timeout: Duration::from_secs(20),
    };
    let mut d = EthercatDrive::open(Box::new(link), &s, m.joints.len(), options)
        .unwrap_or_else(|e| panic!("{e}"));
    bus.lock().unwrap().clear_logs();
    let mut f = Figures::default();
    let (mut late_sum, mut ex_sum) = (0.0, 0.0);
    let start = Instant::now();
    for k in 1..=cycles {
        let due = start + PERIOD * k as u32;
        let now = Instant::now();
        if due > now {
            std::thread::sleep(due - now);
        }
        let woke = Instant::now();
        let late = woke.duration_since(due).as_secs_f64() * 1e6;
        let st = d.apply(&SetPoint::at_rest(k, 0, Joints::new(path(k))));
        let done = Instant::now();
        assert_eq!(st.fault, None, "cycle {k}");
        let ex = done.duration_since(woke).as_secs_f64() * 1e6;
        f.late_worst_us = f.late_worst_us.max(late);
        f.exchange_worst_us = f.exchange_worst_us.max(ex);
        late_sum += late;
        ex_sum += ex;
        if done > due + PERIOD {
            f.overran += 1;
        }
        f.cycles += 1;
    }
    f.late_mean_us = late_sum / cycles as f64;
    f.exchange_mean_us = ex_sum / cycles as f64;
    {
        let b = bus.lock().unwrap();
        for (j, s) in b.slaves.iter().enumerate() {
            let expected: Vec<i32> = (1..=cycles)
                .map(|k| (path(k)[j] * COUNTS_PER_MM).round() as i32)
                .collect();
            assert!(
                s.targets == expected,
                "drive {j}: set-points missing, repeated or out of order"
            );
        }
    }
    drives.stop().expect("the emulated drives' socket");
    (f, d, bus)
}
