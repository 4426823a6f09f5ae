//! The bus behind the executor's [`Drive`] trait: each period the set-point's joint positions
//! go out as target counts, the drives' feedback comes back as measured joints, and anything
//! wrong becomes a [`DriveFault`] that halts the real-time loop. After a fault the bus keeps
//! cycling (so the drives keep their link) with every drive commanded to quick stop, then
//! disabled: the machine stops by the drives' own ramps and stays stopped.

use tezgah_executor::{Drive, DriveFault, DriveStatus, SetPoint};
use tezgah_kinematics::Joints;

use crate::cia402::{command, State};
use crate::master::link::Link;
use crate::master::{CycleError, Master, MasterOptions, OpenError};
use crate::monitor::Monitor;
use crate::od::Outputs;
use crate::section::DriveSection;

/// CiA-402 drives on EtherCAT as the executor's drive.
pub struct EthercatDrive {
    master: Master,
    monitor: std::sync::Arc<Monitor>,
    outputs: Vec<Outputs>,
    position: Joints,
    fault: Option<DriveFault>,
}

impl EthercatDrive {
    /// Brings the bus up (see [`Master::open`]) for a machine of `joints` joints; every joint
    /// must have its drive in `section`.
    pub fn open(
        link: Box<dyn Link>,
        section: &DriveSection,
        joints: usize,
        options: MasterOptions,
    ) -> Result<EthercatDrive, OpenError> {
        let master = Master::open(link, section, options)?;
        let mut position = Joints::zeros(joints);
        for (s, i) in master.slaves().iter().zip(master.inputs()) {
            if s.joint < joints {
                position[s.joint] = s.from_counts(i.position);
            }
        }
        let monitor = std::sync::Arc::new(Monitor::new(master.slaves()));
        Ok(EthercatDrive {
            monitor,
            outputs: vec![Outputs::default(); master.slaves().len()],
            master,
            position,
            fault: None,
        })
    }

    /// Where the drives stand (internal units): the machine's start.
    pub fn position(&self) -> Joints {
        self.position
    }

    pub fn master(&self) -> &Master {
        &self.master
    }

    /// The drives' states and positions for the front end (updated every cycle).
    pub fn monitor(&self) -> std::sync::Arc<Monitor> {
        self.monitor.clone()
    }

    fn publish(&self) {
        for (k, i) in self.master.inputs().iter().enumerate() {
            self.monitor
                .record(k, i.statusword, i.position, i.error_code);
        }
    }

    /// One cycle toward `sp`; the first fault found, if any.
    fn cycle(&mut self, sp: &SetPoint) -> Option<DriveFault> {
        for (o, s) in self.outputs.iter_mut().zip(self.master.slaves()) {
            o.controlword = command::ENABLE_OPERATION;
            let q = sp.position.as_slice().get(s.joint).copied().unwrap_or(0.0);
            match s.to_counts(q) {
                Some(c) => o.target = c,
                // Beyond the encoder's range: refuse rather than wrap.
                None => return Some(DriveFault::FollowingError { joint: s.joint }),
            }
        }
        match self.master.exchange(&self.outputs) {
            Ok(()) => {}
            Err(CycleError::Lost) => return Some(DriveFault::LostFrame),
            Err(CycleError::LinkDown) => return Some(DriveFault::Offline),
            Err(CycleError::WorkingCounter { expected, got }) => {
                return Some(DriveFault::WorkingCounter { expected, got })
            }
        }
        let mut fault = None;
        for (s, i) in self.master.slaves().iter().zip(self.master.inputs()) {
            if s.joint < self.position.len() {
                self.position[s.joint] = s.from_counts(i.position);
            }
            let state = State::from_statusword(i.statusword);
            let f = if state.is_fault() {
                Some(DriveFault::Drive {
                    joint: s.joint,
                    code: i.error_code,
                    text: crate::error_code::text(i.error_code),
                })
            } else if state != State::OperationEnabled {
                // Disabled without a fault: its enable or power went (safe torque off, mains).
                Some(DriveFault::Offline)
            } else if i.following_error.unsigned_abs() > s.following_error_counts {
                Some(DriveFault::FollowingError { joint: s.joint })
            } else {
                None
            };
            fault = fault.or(f);
        }
        fault
    }

    /// After a fault: quick stop every drive still enabled, disable the rest, hold targets at
    /// the actual positions; errors are no news now.
    fn stopped_cycle(&mut self) {
        for (o, i) in self.outputs.iter_mut().zip(self.master.inputs()) {
            o.controlword = match State::from_statusword(i.statusword) {
                State::OperationEnabled => command::QUICK_STOP,
                _ => command::DISABLE_VOLTAGE,
            };
            o.target = i.position;
        }
        let _ = self.master.exchange(&self.outputs);
        for (s, i) in self.master.slaves().iter().zip(self.master.inputs()) {
            if s.joint < self.position.len() {
                self.position[s.joint] = s.from_counts(i.position);
            }
        }
    }
}

impl Drive for EthercatDrive {
    fn apply(&mut self, setpoint: &SetPoint) -> DriveStatus {
        if self.fault.is_none() {
            self.fault = self.cycle(setpoint);
        } else {
            self.stopped_cycle();
        }
        self.publish();
        let mut following_error = Joints::zeros(self.position.len());
        for (k, e) in following_error.as_mut_slice().iter_mut().enumerate() {
            let c = setpoint.position.as_slice().get(k).copied().unwrap_or(0.0);
            *e = c - self.position[k];
        }
        DriveStatus {
            position: self.position,
            following_error,
            fault: self.fault,
        }
    }
}
