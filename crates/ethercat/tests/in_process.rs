//! The master against emulated CiA-402 drives in the same process (ethercrab's frames carried
//! by `master::port` to `emulator::Bus`): bring-up, the set-point stream, and every fault the
//! machine must stop on, each with its message.

mod common;

use std::sync::{Arc, Mutex};

use common::*;
use tezgah_ethercat::drive::EthercatDrive;
use tezgah_ethercat::emulator::{Bus, Identity, Slave, IDENTITY};
use tezgah_ethercat::master::link::InProcess;
use tezgah_ethercat::master::MasterOptions;
use tezgah_executor::{Drive, DriveFault, SetPoint};
use tezgah_kinematics::Joints;

fn sp(k: u64, q: [f64; 3]) -> SetPoint {
    SetPoint::at_rest(k, 0, Joints::new(q))
}

/// A smooth three-axis path, mm, at period k.
fn path(k: u64) -> [f64; 3] {
    let t = k as f64 * 1e-3;
    [
        20.0 * (1.3 * t).sin(),
        -15.0 * (0.7 * t).cos() + 15.0,
        3.0 * t,
    ]
}

#[test]
fn bring_up_configures_csp_and_enables() {
    let (bus, d) = open(1.0, 1.0);
    let bus = bus.lock().unwrap();
    for s in &bus.slaves {
        assert_eq!(s.al_state(), tezgah_ethercat::emulator::esc::OP);
        assert_eq!(
            s.servo.state,
            tezgah_ethercat::cia402::State::OperationEnabled
        );
        assert_eq!(s.dictionary.get(0x6061, 0), 8, "CSP");
        // the machine file's limit, 1 mm at 1000 counts/mm, is the drive's window too
        assert_eq!(s.dictionary.get(0x6065, 0), 1000);
    }
    assert_eq!(d.position(), Joints::zeros(3));
    assert_eq!(d.master().slaves().len(), 3);
}

#[test]
fn every_setpoint_arrives_once_in_order() {
    let (bus, mut d) = open(1.0, 1.0);
    let n = 3000u64;
    let mut previous = Joints::zeros(3);
    for k in 1..=n {
        let st = d.apply(&sp(k, path(k)));
        assert_eq!(st.fault, None, "period {k}");
        // A CSP drive takes the target at the cycle and reports the position it reached one
        // cycle later: the measured position is the previous set-point, to the count.
        for j in 0..3 {
            assert!(
                (st.position[j] - previous[j]).abs() <= 0.5 / COUNTS_PER_MM,
                "{k} {j}"
            );
        }
        previous = Joints::new(path(k));
    }
    let bus = bus.lock().unwrap();
    for (j, s) in bus.slaves.iter().enumerate() {
        let expected: Vec<i32> = (1..=n)
            .map(|k| (path(k)[j] * COUNTS_PER_MM).round() as i32)
            .collect();
        assert_eq!(s.targets, expected, "drive {j}");
    }
}

#[test]
fn bus_order_need_not_be_joint_order() {
    let (m, s) = machine_and_section(["z", "x", "y"], 1.0);
    let bus = Arc::new(Mutex::new(Bus::drives(3, 1.0)));
    let mut d = EthercatDrive::open(
        Box::new(InProcess::new(bus.clone())),
        &s,
        m.joints.len(),
        MasterOptions::for_period(PERIOD),
    )
    .unwrap();
    bus.lock().unwrap().clear_logs();
    d.apply(&sp(1, [1.0, 2.0, 3.0]));
    let st = d.apply(&sp(2, [1.0, 2.0, 3.0]));
    assert_eq!(st.position, Joints::new([1.0, 2.0, 3.0]));
    let bus = bus.lock().unwrap();
    // drive 0 moves z, drive 1 x, drive 2 y
    assert_eq!(bus.slaves[0].targets, [3000, 3000]);
    assert_eq!(bus.slaves[1].targets, [1000, 1000]);
    assert_eq!(bus.slaves[2].targets, [2000, 2000]);
}

#[test]
fn a_lagging_motor_reports_the_closed_form_following_error() {
    // Motor gain g per cycle on a ramp of v counts per cycle: e = v(1 − g)/g.
    let (g, v_mm) = (0.5, 0.02);
    let (_bus, mut d) = open(g, 10.0);
    for k in 1..400u64 {
        let x = v_mm * k as f64;
        let st = d.apply(&sp(k, [x, 0.0, 0.0]));
        assert_eq!(st.fault, None);
    }
    let e = d.master().inputs()[0].following_error;
    assert_eq!(e, (v_mm * COUNTS_PER_MM * (1.0 - g) / g).round() as i32);
}

fn run_until_fault(d: &mut EthercatDrive, from: u64, n: u64) -> (u64, DriveFault) {
    for k in from..from + n {
        if let Some(f) = d.apply(&sp(k, path(k))).fault {
            return (k, f);
        }
    }
    panic!("no fault in {n} periods");
}

#[test]
fn a_drive_fault_stops_the_machine_with_its_code() {
    let (bus, mut d) = open(1.0, 1.0);
    for k in 1..100 {
        assert_eq!(d.apply(&sp(k, path(k))).fault, None);
    }
    bus.lock().unwrap().slaves[1].servo.inject_fault(0x7121);
    let (k, f) = run_until_fault(&mut d, 100, 10);
    // Raised in the drive at period 100, seen in the feedback of period 101.
    assert_eq!(k, 101);
    assert_eq!(
        f,
        DriveFault::Drive {
            joint: 1,
            code: 0x7121,
            text: "motor blocked"
        }
    );
    assert_eq!(f.to_string(), "joint 1: drive error 0x7121: motor blocked");
    // The others are quick-stopped, then disabled, held where they stood: no further
    // set-point reaches a drive.
    let sent = bus.lock().unwrap().slaves[0].targets.len();
    for k in 102..110 {
        assert_eq!(d.apply(&sp(k, path(k))).fault, Some(f), "the fault stays");
    }
    let bus = bus.lock().unwrap();
    let t = &bus.slaves[0].targets;
    // (the target of period 101 went out with the frame that brought the fault back)
    assert!(
        t[sent..].iter().all(|c| *c == t[sent - 2]),
        "{:?}",
        &t[sent - 2..]
    );
    for s in &bus.slaves {
        assert_ne!(
            s.servo.state,
            tezgah_ethercat::cia402::State::OperationEnabled
        );
    }
}

#[test]
fn following_error_beyond_the_limit_stops_the_machine() {
    // A slow motor (g = 0.05) asked to jump 2 mm: beyond the 1 mm limit at once.
    let (bus, mut d) = open(0.05, 1.0);
    // The master's own check (the drive's window switched off):
    for s in &mut bus.lock().unwrap().slaves {
        s.dictionary.set(0x6065, 0, u32::MAX);
    }
    assert_eq!(d.apply(&sp(1, [0.0, 0.0, 0.0])).fault, None);
    let mut fault = None;
    for k in 2..10 {
        fault = d.apply(&sp(k, [0.0, 2.0, 0.0])).fault;
        if fault.is_some() {
            break;
        }
    }
    assert_eq!(fault, Some(DriveFault::FollowingError { joint: 1 }));

    // The drive's own (0x6065 = the same limit): it faults with 0x8611.
    let (_bus, mut d) = open(0.05, 1.0);
    let mut fault = None;
    for k in 1..10 {
        fault = d.apply(&sp(k, [0.0, 0.0, 2.0])).fault;
        if fault.is_some() {
            break;
        }
    }
    let f = fault.expect("faults");
    assert_eq!(
        f.to_string(),
        "joint 2: drive error 0x8611: following error"
    );
}

#[test]
fn a_lost_frame_stops_the_machine() {
    let (bus, mut d) = open(1.0, 1.0);
    for k in 1..50 {
        assert_eq!(d.apply(&sp(k, path(k))).fault, None);
    }
    bus.lock().unwrap().drop_frames = 1;
    assert_eq!(
        d.apply(&sp(50, path(50))).fault,
        Some(DriveFault::LostFrame)
    );
}

#[test]
fn a_cut_cable_stops_the_machine() {
    let (bus, mut d) = open(1.0, 1.0);
    for k in 1..50 {
        assert_eq!(d.apply(&sp(k, path(k))).fault, None);
    }
    bus.lock().unwrap().cut = true;
    let st = d.apply(&sp(50, path(50)));
    assert_eq!(st.fault, Some(DriveFault::LostFrame));
    // the position stays the last one measured
    let counted = path(48).map(|q| (q * COUNTS_PER_MM).round() / COUNTS_PER_MM);
    assert_eq!(st.position, Joints::new(counted));
}

#[test]
fn a_drive_dropping_off_the_bus_is_a_wrong_working_counter() {
    let (bus, mut d) = open(1.0, 1.0);
    for k in 1..50 {
        assert_eq!(d.apply(&sp(k, path(k))).fault, None);
    }
    bus.lock().unwrap().slaves.pop();
    let f = d.apply(&sp(50, path(50))).fault;
    assert_eq!(
        f,
        Some(DriveFault::WorkingCounter {
            expected: 9,
            got: 6
        })
    );
    assert_eq!(
        f.unwrap().to_string(),
        "bus working counter 6, expected 9: a drive did not answer"
    );
}

fn open_error(bus: Bus) -> String {
    let (m, s) = machine_and_section(["x", "y", "z"], 1.0);
    match EthercatDrive::open(
        Box::new(InProcess::new(Arc::new(Mutex::new(bus)))),
        &s,
        m.joints.len(),
        MasterOptions::for_period(PERIOD),
    ) {
        Ok(_) => panic!("opened"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_missing_or_wrong_drive_is_refused_at_start() {
    let e = open_error(Bus::drives(2, 1.0));
    assert!(
        e.starts_with("the machine file's [drive] lists 3 drives, the bus has 2: 0: tezgah emulated CiA-402 drive"),
        "{e}"
    );
    let mut bus = Bus::drives(2, 1.0);
    bus.push(Slave::new(
        Identity {
            product_code: 0x1234,
            ..IDENTITY
        },
        1.0,
    ));
    let e = open_error(bus);
    assert_eq!(
        e,
        "slave 2 is vendor 0x00000e5a product 0x00001234 (tezgah emulated CiA-402 drive); \
         drive.slave[2] (joint z) wants vendor 0x00000e5a product 0x00000402"
    );
    assert_eq!(
        open_error(Bus::default()),
        "no EtherCAT slave answered (cable, interface?)"
    );
}

#[test]
fn the_monitor_shows_states_positions_and_faults() {
    let (bus, mut d) = open(1.0, 1.0);
    let m = d.monitor();
    d.apply(&sp(1, [1.5, -2.0, 0.25]));
    d.apply(&sp(2, [1.5, -2.0, 0.25]));
    let r = m.readings();
    assert_eq!(r.len(), 3);
    assert_eq!(r[1].joint, "y");
    assert_eq!(r[1].state, "operation enabled");
    assert_eq!(r[1].position, -2.0);
    assert_eq!(r[1].error, None);
    bus.lock().unwrap().slaves[2].servo.inject_fault(0x3220);
    d.apply(&sp(3, [1.5, -2.0, 0.25]));
    d.apply(&sp(4, [1.5, -2.0, 0.25]));
    let r = m.readings();
    assert_eq!(r[2].state, "fault reaction active");
    assert_eq!(r[2].error_code, 0x3220);
    assert_eq!(r[2].error, Some("DC link undervoltage"));
    let json = serde_json::to_string(&r[2]).unwrap();
    assert_eq!(
        json,
        r#"{"joint":"z","state":"fault reaction active","position":0.25,"error_code":12832,"error":"DC link undervoltage"}"#
    );
}
