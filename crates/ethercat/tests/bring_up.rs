use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tezgah_ethercat::emulator::{Bus, IDENTITY};
use tezgah_ethercat::master::link::InProcess;
use tezgah_ethercat::master::{Master, MasterOptions};
use tezgah_ethercat::{DriveSection, DriveSlave};

fn section(n: usize) -> DriveSection {
    DriveSection {
        slaves: (0..n)
            .map(|j| DriveSlave {
                joint: j,
                joint_name: format!("j{j}"),
                vendor_id: IDENTITY.vendor_id,
                product_code: IDENTITY.product_code,
                counts_per_unit: 1000.0,
                following_error_limit: 1.0,
                following_error_counts: 1000,
            })
            .collect(),
    }
}

#[test]
fn brings_three_drives_up() {
    let bus = Arc::new(Mutex::new(Bus::drives(3, 1.0)));
    let t = Instant::now();
    let m = Master::open(
        Box::new(InProcess::new(bus.clone())),
        &section(3),
        MasterOptions::for_period(Duration::from_millis(1)),
    );
    let m = match m {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    };
    eprintln!(
        "open took {:?}, {} frames",
        t.elapsed(),
        bus.lock().unwrap().frames
    );
    assert_eq!(m.inputs().len(), 3);
}
