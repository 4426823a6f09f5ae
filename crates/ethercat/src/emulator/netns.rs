//! Two network namespaces joined by a veth pair, for running the master and emulated drives on
//! real interfaces in one computer (the namespace tests, the soak example, trying `serve`):
//! the master's end in one namespace, the drives' in the other, so the kernel carries every
//! frame as it would to a cable. Linux only; needs root and `ip` (iproute2).

use std::fs::File;
use std::io;
use std::os::fd::AsRawFd;
use std::process::Command;

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
