//! The master's frame pump: ethercrab builds and parses frames inside futures; this polls one
//! such future on the calling thread and carries its frames over a [`Link`] between polls
//! (ethercrab's `PduTx`/`PduRx` split). No executor, no second thread: the real-time thread
//! calls [`Port::run`] once per cycle and it returns when the answer is in or the cycle's
//! deadline has passed. Polling a ready future and moving frames allocate nothing.

use std::future::Future;
use std::io;
use std::pin::pin;
use std::task::{Context, Poll, Waker};
use std::time::{Duration, Instant};

use ethercrab::{PduRx, PduTx};

use super::link::{Link, MAX_FRAME};

/// Why [`Port::run`] gave up.
#[derive(Debug)]
pub enum PortError {
    /// Nothing came back before the deadline.
    Timeout,
    /// The link refused to send or receive (interface down or gone).
    Link(io::Error),
}

/// The frame queues and the link.
pub struct Port {
    tx: PduTx<'static>,
    rx: PduRx<'static>,
    link: Box<dyn Link>,
    buf: Box<[u8; MAX_FRAME]>,
    /// How long one receive waits before the future is polled again.
    slice: Duration,
}

impl Port {
    pub fn new(tx: PduTx<'static>, rx: PduRx<'static>, link: Box<dyn Link>) -> Port {
        Port {
            tx,
            rx,
            link,
            buf: Box::new([0; MAX_FRAME]),
            slice: Duration::from_micros(50),
        }
    }

    /// Drives `fut` to completion, moving its frames, until `deadline`.
    pub fn run<F: Future>(&mut self, fut: F, deadline: Instant) -> Result<F::Output, PortError> {
        let mut fut = pin!(fut);
        let mut cx = Context::from_waker(Waker::noop());
        loop {
            if let Poll::Ready(v) = fut.as_mut().poll(&mut cx) {
                return Ok(v);
            }
            let mut sent = false;
            while let Some(frame) = self.tx.next_sendable_frame() {
                let link = &mut self.link;
                let r = frame.send_blocking(|bytes| {
                    link.send(bytes)
                        .map(|()| bytes.len())
                        .map_err(|_| ethercrab::error::Error::SendFrame)
                });
                if r.is_err() {
                    // Ask the link again for its own error (it has one: it refused the frame).
                    return Err(PortError::Link(io::Error::new(
                        io::ErrorKind::NotConnected,
                        "the interface refused a frame (link down?)",
                    )));
                }
                sent = true;
            }
            let now = Instant::now();
            let late = now >= deadline;
            let wait = if sent || late {
                Duration::ZERO
            } else {
                self.slice.min(deadline - now)
            };
            let mut wait = wait;
            while let Some(n) = self
                .link
                .recv(&mut self.buf[..], wait)
                .map_err(PortError::Link)?
            {
                // A frame that is not ours (another protocol, a stale answer) is no error.
                let _ = self.rx.receive_frame(&self.buf[..n]);
                wait = Duration::ZERO;
            }
            if late {
                // One last look: an answer that came in by the deadline (the thread may have
                // been preempted since) still counts.
                return match fut.as_mut().poll(&mut cx) {
                    Poll::Ready(v) => Ok(v),
                    Poll::Pending => Err(PortError::Timeout),
                };
            }
        }
    }
}
