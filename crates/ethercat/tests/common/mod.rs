//! What the bus tests share: a machine with a `[drive]` table for emulated drives, and opening
//! a bus of them in process.

#![allow(dead_code)]

use std::sync::{Arc, Mutex};
use std::time::Duration;

use tezgah_ethercat::drive::EthercatDrive;
use tezgah_ethercat::emulator::{Bus, IDENTITY};
use tezgah_ethercat::master::link::InProcess;
use tezgah_ethercat::master::MasterOptions;
use tezgah_ethercat::DriveSection;
use tezgah_kinematics::Machine;

/// Counts per mm of every emulated axis.
pub const COUNTS_PER_MM: f64 = 1000.0;

/// mill3 with a `[drive]` table: x, y, z on drives 0, 1, 2 (`order` permutes them).
pub fn machine_text(order: [&str; 3], following_error_limit_mm: f64) -> String {
    let mut t = Machine::builtin_text("mill3").unwrap().to_owned();
    for j in order {
        t += &format!(
            "\n[[drive.slave]]\njoint = \"{j}\"\nvendor_id = {}\nproduct_code = {}\n\
             counts_per_unit = {COUNTS_PER_MM:.1}\nfollowing_error_limit = {following_error_limit_mm}\n",
            IDENTITY.vendor_id, IDENTITY.product_code
        );
    }
    t
}

pub fn machine_and_section(order: [&str; 3], limit_mm: f64) -> (Machine, DriveSection) {
    let text = machine_text(order, limit_mm);
    let m = Machine::from_toml_str(&text).unwrap();
    let s = DriveSection::from_machine_text(&text, &m).unwrap().unwrap();
    (m, s)
}

pub const PERIOD: Duration = Duration::from_millis(1);

/// A bus of three emulated drives with motor gain `gain`, opened in process.
pub fn open(gain: f64, limit_mm: f64) -> (Arc<Mutex<Bus>>, EthercatDrive) {
    let (m, s) = machine_and_section(["x", "y", "z"], limit_mm);
    let bus = Arc::new(Mutex::new(Bus::drives(3, gain)));
    let d = EthercatDrive::open(
        Box::new(InProcess::new(bus.clone())),
        &s,
        m.joints.len(),
        MasterOptions::for_period(PERIOD),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    bus.lock().unwrap().clear_logs();
    (bus, d)
}
pub mod veth;
