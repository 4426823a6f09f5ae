//! One bus cycle in process: three emulated drives, the master's frame built by ethercrab,
//! carried by the port, answered by the emulator and read back — the master's cost per period
//! without the wire.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use tezgah_ethercat::emulator::{Bus, IDENTITY};
use tezgah_ethercat::master::link::InProcess;
use tezgah_ethercat::master::{Master, MasterOptions};
use tezgah_ethercat::od::Outputs;
use tezgah_ethercat::{DriveSection, DriveSlave};

fn bench(c: &mut Criterion) {
    let section = DriveSection {
        slaves: (0..3)
            .map(|j| DriveSlave {
                joint: j,
                joint_name: format!("j{j}"),
                vendor_id: IDENTITY.vendor_id,
                product_code: IDENTITY.product_code,
                counts_per_unit: 1000.0,
                following_error_limit: 1.0,
                following_error_counts: u32::MAX - 1,
            })
            .collect(),
    };
    let bus = Arc::new(Mutex::new(Bus::drives(3, 1.0)));
    let mut m = Master::open(
        Box::new(InProcess::new(bus.clone())),
        &section,
        MasterOptions::for_period(Duration::from_millis(1)),
    )
    .expect("bus up");
    let mut out = [Outputs {
        controlword: 0x000F,
        target: 0,
    }; 3];
    let mut k = 0i32;
    c.bench_function("ethercat cycle, 3 emulated drives in process", |b| {
        b.iter(|| {
            k = k.wrapping_add(1) % 100_000;
            for o in &mut out {
                o.target = k;
            }
            m.exchange(&out).expect("cycle");
            bus.lock().unwrap().clear_logs();
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
