//! Where the master's frames go: a [`Link`] sends one Ethernet frame and waits a bounded time
//! for one to come back. [`InProcess`] hands them to an emulated segment in the same process;
//! [`RawSocket`] puts them on a network interface (Linux AF_PACKET, EtherType 0x88A4), which
//! is how a real bus and the namespace tests are reached. Neither allocates per frame.

use std::io;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::emulator::{Bus, ETHERTYPE};

/// Largest Ethernet frame (without FCS).
pub const MAX_FRAME: usize = 1514;

/// A frame transport.
pub trait Link: Send {
    fn send(&mut self, frame: &[u8]) -> io::Result<()>;
    /// Waits up to `wait` for a frame; its length, or `None` when none came.
    fn recv(&mut self, buf: &mut [u8], wait: Duration) -> io::Result<Option<usize>>;
}

/// The emulated segment in this process, shared with the test that inspects it.
pub struct InProcess {
    bus: Arc<Mutex<Bus>>,
    /// Frames that came back, not yet received (a small fixed ring).
    ring: Box<[[u8; MAX_FRAME]; 4]>,
    lens: [usize; 4],
    head: usize,
    count: usize,
}

impl InProcess {
    pub fn new(bus: Arc<Mutex<Bus>>) -> InProcess {
        InProcess {
            bus,
            ring: Box::new([[0; MAX_FRAME]; 4]),
            lens: [0; 4],
            head: 0,
            count: 0,
        }
    }
}

impl Link for InProcess {
    fn send(&mut self, frame: &[u8]) -> io::Result<()> {
        if frame.len() > MAX_FRAME {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "frame too long",
            ));
        }
        if self.count == self.ring.len() {
            return Err(io::Error::new(
                io::ErrorKind::WouldBlock,
                "receive ring full",
            ));
        }
        let slot = (self.head + self.count) % self.ring.len();
        let buf = &mut self.ring[slot][..frame.len()];
        buf.copy_from_slice(frame);
        let back = self
            .bus
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .process(buf);
        if back {
            self.lens[slot] = frame.len();
            self.count += 1;
        }
        Ok(())
    }

    fn recv(&mut self, buf: &mut [u8], _wait: Duration) -> io::Result<Option<usize>> {
        if self.count == 0 {
            return Ok(None);
        }
        let n = self.lens[self.head].min(buf.len());
        buf[..n].copy_from_slice(&self.ring[self.head][..n]);
        self.head = (self.head + 1) % self.ring.len();
        self.count -= 1;
        Ok(Some(n))
    }
}

/// A raw packet socket bound to one interface, EtherCAT frames only (needs CAP_NET_RAW).
pub struct RawSocket {
    fd: OwnedFd,
    name: String,
}

impl RawSocket {
    pub fn open(interface: &str) -> io::Result<RawSocket> {
        let cname = std::ffi::CString::new(interface)
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "interface name has a NUL"))?;
        // SAFETY: plain libc calls on a fresh descriptor we own; the sockaddr is fully set.
        unsafe {
            let index = libc::if_nametoindex(cname.as_ptr());
            if index == 0 {
                return Err(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!("no network interface `{interface}`"),
                ));
            }
            let proto = (ETHERTYPE).to_be() as libc::c_int;
            let fd = libc::socket(libc::AF_PACKET, libc::SOCK_RAW | libc::SOCK_CLOEXEC, proto);
            if fd < 0 {
                return Err(io::Error::last_os_error());
            }
            let fd = OwnedFd::from_raw_fd(fd);
            let mut addr: libc::sockaddr_ll = std::mem::zeroed();
            addr.sll_family = libc::AF_PACKET as u16;
            addr.sll_protocol = ETHERTYPE.to_be();
            addr.sll_ifindex = index as i32;
            let r = libc::bind(
                fd.as_raw_fd(),
                &addr as *const libc::sockaddr_ll as *const libc::sockaddr,
                std::mem::size_of::<libc::sockaddr_ll>() as u32,
            );
            if r < 0 {
                return Err(io::Error::last_os_error());
            }
            Ok(RawSocket {
                fd,
                name: interface.to_owned(),
            })
        }
    }

    pub fn interface(&self) -> &str {
        &self.name
    }
}

impl Link for RawSocket {
    fn send(&mut self, frame: &[u8]) -> io::Result<()> {
        // SAFETY: the buffer is valid for its length.
        let n = unsafe { libc::send(self.fd.as_raw_fd(), frame.as_ptr().cast(), frame.len(), 0) };
        if n < 0 {
            return Err(io::Error::last_os_error());
        }
        Ok(())
    }

    fn recv(&mut self, buf: &mut [u8], wait: Duration) -> io::Result<Option<usize>> {
        let mut pfd = libc::pollfd {
            fd: self.fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let ts = libc::timespec {
            tv_sec: wait.as_secs() as libc::time_t,
            tv_nsec: wait.subsec_nanos() as libc::c_long,
        };
        loop {
            // SAFETY: one pollfd, a valid timespec, no signal mask.
            let r = unsafe { libc::ppoll(&mut pfd, 1, &ts, std::ptr::null()) };
            if r < 0 {
                let e = io::Error::last_os_error();
                if e.kind() == io::ErrorKind::Interrupted {
                    continue;
                }
                return Err(e);
            }
            if r == 0 {
                return Ok(None);
            }
            if pfd.revents & (libc::POLLERR | libc::POLLHUP | libc::POLLNVAL) != 0 {
                return Err(io::Error::new(
                    io::ErrorKind::NotConnected,
                    format!("interface {} went away", self.name),
                ));
            }
            // SAFETY: sockaddr_ll is plain data; recvfrom writes at most its size.
            let mut from: libc::sockaddr_ll = unsafe { std::mem::zeroed() };
            let mut len = std::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t;
            let n = unsafe {
                libc::recvfrom(
                    self.fd.as_raw_fd(),
                    buf.as_mut_ptr().cast(),
                    buf.len(),
                    libc::MSG_DONTWAIT,
                    &mut from as *mut libc::sockaddr_ll as *mut libc::sockaddr,
                    &mut len,
                )
            };
            if n < 0 {
                let e = io::Error::last_os_error();
                if e.kind() == io::ErrorKind::WouldBlock {
                    return Ok(None);
                }
                return Err(e);
            }
            // A packet socket also sees what this host sent: skip it.
            if from.sll_pkttype == libc::PACKET_OUTGOING {
                continue;
            }
            return Ok(Some(n as usize));
        }
    }
}

/// Runs emulated drives on a network interface (`sock`, opened on it) until `stop` is set:
/// every EtherCAT frame that arrives is passed through `bus` and sent back (the namespace
/// tests' far end of the veth). Returns the frames answered.
pub fn serve_interface(
    mut sock: RawSocket,
    bus: Arc<Mutex<Bus>>,
    stop: &std::sync::atomic::AtomicBool,
) -> io::Result<u64> {
    let mut buf = [0u8; MAX_FRAME];
    let mut answered = 0;
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        let Some(n) = sock.recv(&mut buf, Duration::from_millis(20))? else {
            continue;
        };
        let back = bus
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .process(&mut buf[..n]);
        if back {
            sock.send(&buf[..n])?;
            answered += 1;
        }
    }
    Ok(answered)
}
