//! The executor's real-time loop on emulated EtherCAT drives (in process, on a virtual clock):
//! a program's set-points reach the drives once and in order with no underrun, and a drive
//! fault halts the machine with the drive's own words in the executor's status.

mod common;

use common::*;
use tezgah_ethercat::drive::EthercatDrive;
use tezgah_executor::command::{Command, RunState};
use tezgah_executor::executor::{ExecOptions, Executor};
use tezgah_executor::ring::rings;
use tezgah_executor::rt::{RtLoop, StopLimits};
use tezgah_executor::threads::PlannerSide;
use tezgah_executor::{Drive, DriveStatus, SetPoint};
use tezgah_geom::Pose;

/// The bus drive, remembering what it was given.
struct Recording {
    drive: EthercatDrive,
    seen: Vec<SetPoint>,
}

impl Drive for Recording {
    fn apply(&mut self, sp: &SetPoint) -> DriveStatus {
        self.seen.push(*sp);
        self.drive.apply(sp)
    }
}

const PROGRAM: &str =
    "G21 G90 G17 G64 F3000\nG1 X10 Y5\nG2 X20 Y5 I5 J0\nG1 Z-2\nG3 X10 Y5 I-5 J0\nG0 Z5\nM2\n";

fn rig(
    gain: f64,
) -> (
    std::sync::Arc<std::sync::Mutex<tezgah_ethercat::emulator::Bus>>,
    PlannerSide,
    RtLoop<Recording>,
) {
    let (m, _) = machine_and_section(["x", "y", "z"], 1.0);
    let (bus, drive) = open(gain, 1.0);
    let exec = Executor::new(&m, ExecOptions::for_machine(&m), Pose::ZERO).unwrap();
    let limits = StopLimits::of(exec.machine());
    let start = drive.position();
    let (p, r) = rings(24, 4096);
    let rt = RtLoop::new(
        r,
        Recording {
            drive,
            seen: Vec::new(),
        },
        exec.period(),
        limits,
        start,
    );
    (bus, PlannerSide::new(exec, p, 24), rt)
}

#[test]
fn a_program_reaches_the_drives_once_and_in_order() {
    let (bus, mut side, mut rt) = rig(1.0);
    side.command(Command::Load {
        program: PROGRAM.into(),
    })
    .unwrap();
    side.command(Command::CycleStart).unwrap();
    let mut k = 0;
    while side.executor().state() != RunState::Idle || k < 10 {
        side.pump();
        rt.tick();
        k += 1;
        assert!(k < 60_000, "the program does not end");
    }
    let c = rt.counters();
    assert_eq!(c.underruns, 0);
    assert!(c.delivered > 1000, "{}", c.delivered);
    let seen = &rt.drive().seen;
    assert_eq!(seen.len() as u64, c.periods);
    let bus = bus.lock().unwrap();
    for (j, s) in bus.slaves.iter().enumerate() {
        // One target per period, each the set-point of that period in counts.
        let expected: Vec<i32> = seen
            .iter()
            .map(|sp| (sp.position[j] * COUNTS_PER_MM).round() as i32)
            .collect();
        assert_eq!(s.targets, expected, "drive {j}");
    }
    // The set-points' indices never go back and each new one comes once.
    let mut indices: Vec<u64> = seen.iter().map(|s| s.index).collect();
    assert!(indices.windows(2).all(|w| w[0] <= w[1]));
    indices.dedup();
    assert!(indices.len() as u64 >= c.delivered);
}

#[test]
fn a_drive_fault_halts_the_executor_with_its_text() {
    let (bus, mut side, mut rt) = rig(1.0);
    side.command(Command::Load {
        program: PROGRAM.into(),
    })
    .unwrap();
    side.command(Command::CycleStart).unwrap();
    for _ in 0..300 {
        side.pump();
        rt.tick();
    }
    bus.lock().unwrap().slaves[2].servo.inject_fault(0x2310);
    for _ in 0..20 {
        side.pump();
        rt.tick();
    }
    side.pump();
    let s = side.status();
    assert_eq!(s.state, RunState::Fault);
    let e = s.error.unwrap_or_default();
    assert!(
        e.contains("drive fault: joint 2: drive error 0x2310: continuous overcurrent"),
        "{e}"
    );
}
