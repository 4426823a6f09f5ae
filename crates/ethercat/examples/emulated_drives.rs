//! Emulated CiA-402 drives on a network interface, to try `tezgah serve --drive ethercat:…`
//! without hardware: every EtherCAT frame arriving on the interface passes the drives and goes
//! back. Needs root (a raw socket). With a veth pair between two namespaces (README):
//!
//! ```sh
//! ip netns exec drives cargo run -p tezgah-ethercat --example emulated_drives -- veth1 3
//! ```

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use tezgah_ethercat::emulator::Bus;
use tezgah_ethercat::master::link::{serve_interface, RawSocket};

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(interface), count) = (args.next(), args.next()) else {
        eprintln!("usage: emulated_drives INTERFACE [COUNT (default 3)]");
        std::process::exit(2);
    };
    let count: usize = match count.as_deref().map(str::parse).unwrap_or(Ok(3)) {
        Ok(n) if (1..=16).contains(&n) => n,
        _ => {
            eprintln!("COUNT must be 1 to 16");
            std::process::exit(2);
        }
    };
    let sock = match RawSocket::open(&interface) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{interface}: {e}");
            std::process::exit(1);
        }
    };
    let id = tezgah_ethercat::emulator::IDENTITY;
    println!(
        "{count} emulated drives on {interface}: vendor_id = {:#x}, product_code = {:#x}",
        id.vendor_id, id.product_code
    );
    let bus = Arc::new(Mutex::new(Bus::drives(count, 1.0)));
    if let Err(e) = serve_interface(sock, bus, &AtomicBool::new(false)) {
        eprintln!("{interface}: {e}");
        std::process::exit(1);
    }
}
