//! What the front end shows of the drives: each drive's last statusword, actual position and
//! error code, written by the real-time thread after every cycle into atomics (no lock, no
//! allocation) and read by the server whenever it sends a status.

use std::sync::atomic::{AtomicI32, AtomicU16, Ordering};

use serde::Serialize;

use crate::cia402::State;
use crate::section::DriveSlave;

/// The drives' last feedback, shared between the real-time thread and the front end.
#[derive(Debug)]
pub struct Monitor {
    slaves: Vec<DriveSlave>,
    statuswords: Vec<AtomicU16>,
    positions: Vec<AtomicI32>,
    error_codes: Vec<AtomicU16>,
}

/// One drive as the status shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveReading {
    /// The joint it moves.
    pub joint: String,
    /// Its CiA-402 state (`operation enabled`, `fault`, …).
    pub state: &'static str,
    /// Its actual position, internal units (mm or rad).
    pub position: f64,
    /// Its error code (0x603F), 0 for none.
    pub error_code: u16,
    /// The code's text, when there is an error.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<&'static str>,
}

impl Monitor {
    pub fn new(slaves: &[DriveSlave]) -> Monitor {
        Monitor {
            slaves: slaves.to_vec(),
            statuswords: slaves.iter().map(|_| AtomicU16::new(0)).collect(),
            positions: slaves.iter().map(|_| AtomicI32::new(0)).collect(),
            error_codes: slaves.iter().map(|_| AtomicU16::new(0)).collect(),
        }
    }

    /// Records drive `k`'s feedback (the real-time thread, every cycle).
    pub fn record(&self, k: usize, statusword: u16, position: i32, error_code: u16) {
        if let (Some(s), Some(p), Some(e)) = (
            self.statuswords.get(k),
            self.positions.get(k),
            self.error_codes.get(k),
        ) {
            s.store(statusword, Ordering::Relaxed);
            p.store(position, Ordering::Relaxed);
            e.store(error_code, Ordering::Relaxed);
        }
    }

    /// Every drive, in bus order.
    pub fn readings(&self) -> Vec<DriveReading> {
        self.slaves
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let code = self.error_codes[k].load(Ordering::Relaxed);
                DriveReading {
                    joint: s.joint_name.clone(),
                    state: State::from_statusword(self.statuswords[k].load(Ordering::Relaxed))
                        .name(),
                    position: s.from_counts(self.positions[k].load(Ordering::Relaxed)),
                    error_code: code,
                    error: (code != 0).then(|| crate::error_code::text(code)),
                }
            })
            .collect()
    }
}
