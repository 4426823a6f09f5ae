//! Two network namespaces joined by a veth pair, for running the master and emulated drives on
//! real interfaces in one computer (the namespace tests, the soak example, trying `serve`):
//! the master's end in one namespace, the drives' in the other, so the kernel carries every
//! frame as it would to a cable. Linux only; needs root and `ip` (iproute2).

use std::fs::File;
use std::io;
use std::os::fd::AsRawFd;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use super::Bus;
use crate::master::link::{serve_interface, RawSocket};

/// Runs `ip` with `args`; its complaint as the error.
pub fn ip(args: &[&str]) -> io::Result<()> {
    let out = Command::new("ip").args(args).output()?;
    if out.status.success() {
        Ok(())
    } else {
        Err(io::Error::other(format!(
            "ip {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        )))
    }
}

/// Two namespaces and the veth between them, both ends up; removed on drop.
#[derive(Debug)]
pub struct Veth {
    pub master_ns: String,
    pub slave_ns: String,
    pub master_if: String,
    pub slave_if: String,
}

impl Veth {
    /// Names from `tag` (a few letters) and the process id, each at most 15 characters.
    pub fn new(tag: &str) -> io::Result<Veth> {
        let id = std::process::id() % 100_000;
        let tag: String = tag.chars().take(4).collect();
        let v = Veth {
            master_ns: format!("tzm{tag}{id}"),
            slave_ns: format!("tzs{tag}{id}"),
            master_if: format!("tzm{tag}{id}"),
            slave_if: format!("tzs{tag}{id}"),
        };
        // Left over from a run that was killed: start clean.
        let _ = ip(&["netns", "del", &v.master_ns]);
        let _ = ip(&["netns", "del", &v.slave_ns]);
        ip(&["netns", "add", &v.master_ns])?;
        ip(&["netns", "add", &v.slave_ns])?;
        ip(&[
            "link",
            "add",
            &v.master_if,
            "netns",
            &v.master_ns,
            "type",
            "veth",
            "peer",
            "name",
            &v.slave_if,
            "netns",
            &v.slave_ns,
        ])?;
        ip(&["-n", &v.master_ns, "link", "set", &v.master_if, "up"])?;
        ip(&["-n", &v.slave_ns, "link", "set", &v.slave_if, "up"])?;
        // Loopback too, for a server listening on 127.0.0.1 in the master's namespace.
        ip(&["-n", &v.master_ns, "link", "set", "lo", "up"])?;
        Ok(v)
    }
}

impl Drop for Veth {
    fn drop(&mut self) {
        let _ = ip(&["netns", "del", &self.master_ns]);
        let _ = ip(&["netns", "del", &self.slave_ns]);
    }
}

/// Moves the calling thread (only it) into network namespace `ns`.
pub fn enter(ns: &str) -> io::Result<()> {
    let f = File::open(format!("/var/run/netns/{ns}"))?;
    // SAFETY: a valid descriptor of a network namespace; affects this thread only.
    let r = unsafe { libc::setns(f.as_raw_fd(), libc::CLONE_NEWNET) };
    if r == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Emulated drives answering on the drives' end of a [`Veth`], from a thread of their own in
/// the drives' namespace, until stopped (or dropped): what the namespace tests, the soak and a
/// `serve` test put on the far end of the cable.
pub struct DrivesOnVeth {
    /// The drives, to read what they received or to inject faults.
    pub bus: Arc<Mutex<Bus>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<io::Result<u64>>>,
}

impl DrivesOnVeth {
    /// Starts `bus` on `veth`'s drives' end and returns once it listens (so the master's first
    /// frame finds it). `realtime`: the thread at the executor's best-effort real-time
    /// settings, answering at once as hardware does.
    pub fn start(veth: &Veth, bus: Bus, realtime: bool) -> io::Result<DrivesOnVeth> {
        let bus = Arc::new(Mutex::new(bus));
        let stop = Arc::new(AtomicBool::new(false));
        let (ready, listening) = std::sync::mpsc::channel();
        let thread = {
            let (bus, stop) = (bus.clone(), stop.clone());
            let (ns, ifname) = (veth.slave_ns.clone(), veth.slave_if.clone());
            std::thread::spawn(move || {
                enter(&ns)?;
                if realtime {
                    let _ = tezgah_executor::realtime::apply(
                        &tezgah_executor::realtime::RealtimeSettings::BEST_EFFORT,
                    );
                }
                let sock = RawSocket::open(&ifname);
                let _ = ready.send(());
                serve_interface(sock?, bus, &stop)
            })
        };
        if listening.recv().is_err() {
            // The thread ended before listening: its error says why.
            let e = match thread.join() {
                Ok(Err(e)) => e,
                _ => io::Error::other("the emulated drives' thread stopped"),
            };
            return Err(e);
        }
        Ok(DrivesOnVeth {
            bus,
            stop,
            thread: Some(thread),
        })
    }

    /// Stops the drives; the frames they answered, or their socket's error.
    pub fn stop(mut self) -> io::Result<u64> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err(io::Error::other("the emulated drives' thread panicked")),
            None => Ok(0),
        }
    }
}

impl Drop for DrivesOnVeth {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
