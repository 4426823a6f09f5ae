//! The EtherCAT master for CiA-402 drives: [`Master::open`] scans the bus, checks it against
//! the machine file's `[drive]` table, configures each drive over SDO (cyclic synchronous
//! position, the PDO mapping of `crate::od`, its following-error window), takes the bus to OP
//! and walks every drive to *operation enabled*; [`Master::exchange`] is one cycle: targets
//! out, feedback in, the working counter checked. ethercrab builds the frames; [`port`] moves
//! them over a [`link`].

pub mod link;
pub mod port;

use std::fmt;
use std::time::{Duration, Instant};

use ethercrab::subdevice_group::Op;
use ethercrab::{
    DefaultLock, MainDevice, MainDeviceConfig, PduStorage, RetryBehaviour, SubDeviceGroup,
    SubDeviceState, Timeouts,
};

use crate::cia402::{self, State};
use crate::od::{self, Inputs, Outputs};
use crate::section::{DriveSection, DriveSlave};
use link::Link;
use port::{Port, PortError};

/// Drives a bus may hold.
pub const MAX_DRIVES: usize = 16;
/// Process data image, bytes (18 per drive).
const MAX_PDI: usize = 512;
const MAX_FRAMES: usize = 16;
const FRAME_DATA: usize = PduStorage::element_size(1100);

type Storage = PduStorage<MAX_FRAMES, FRAME_DATA>;
type Group = SubDeviceGroup<MAX_DRIVES, MAX_PDI, DefaultLock, Op>;

/// Why the bus could not be brought up.
#[derive(Debug)]
pub enum OpenError {
    /// The link or the scan failed.
    Scan(String),
    /// Nothing answered.
    NoSlaves,
    /// Another number of slaves than the machine file lists.
    Count { found: Vec<String>, expected: usize },
    /// A slave is not the drive the machine file names at its place.
    Identity {
        position: usize,
        joint: String,
        found: (u32, u32, String),
        expected: (u32, u32),
    },
    /// A drive refused its configuration.
    Configure {
        position: usize,
        joint: String,
        message: String,
    },
    /// The bus did not reach OP.
    Op(String),
    /// A drive did not reach operation enabled.
    Enable {
        position: usize,
        joint: String,
        state: State,
        error: u16,
    },
}

impl fmt::Display for OpenError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            OpenError::Scan(m) => write!(f, "EtherCAT scan failed: {m}"),
            OpenError::NoSlaves => write!(f, "no EtherCAT slave answered (cable, interface?)"),
            OpenError::Count { found, expected } => write!(
                f,
                "the machine file's [drive] lists {expected} drives, the bus has {}: {}",
                found.len(),
                found.join("; ")
            ),
            OpenError::Identity {
                position,
                joint,
                found,
                expected,
            } => write!(
                f,
                "slave {position} is vendor {:#010x} product {:#010x} ({}); drive.slave[{position}] \
                 (joint {joint}) wants vendor {:#010x} product {:#010x}",
                found.0, found.1, found.2, expected.0, expected.1
            ),
            OpenError::Configure {
                position,
                joint,
                message,
            } => write!(f, "drive {position} (joint {joint}): configuration refused: {message}"),
            OpenError::Op(m) => write!(f, "the bus did not reach OP: {m}"),
            OpenError::Enable {
                position,
                joint,
                state,
                error,
            } => {
                write!(f, "drive {position} (joint {joint}) stayed in `{state}`")?;
                if *error != 0 {
                    write!(f, ", error {error:#06x}: {}", crate::error_code::text(*error))?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for OpenError {}

/// Why a cycle failed: the machine must stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CycleError {
    /// No answer within the cycle: a frame lost, or the link down.
    Lost,
    /// The interface refused the frame: the link is down.
    LinkDown,
    /// The answer's working counter says not every drive took part.
    WorkingCounter { expected: u16, got: u16 },
}

/// Master settings.
#[derive(Debug, Clone, Copy)]
pub struct MasterOptions {
    /// How long a cycle may wait for its frame (less than the machine period).
    pub cycle_timeout: Duration,
    /// How long the scan, configuration and enable may take.
    pub open_timeout: Duration,
}

impl MasterOptions {
    /// For a machine period `period`: a cycle waits at most 80 % of it.
    pub fn for_period(period: Duration) -> MasterOptions {
        MasterOptions {
            cycle_timeout: period.mul_f64(0.8),
            open_timeout: Duration::from_secs(20),
        }
    }
}

/// A running bus of CiA-402 drives in cyclic synchronous position.
pub struct Master {
    md: &'static MainDevice<'static>,
    group: Group,
    port: Port,
    slaves: Vec<DriveSlave>,
    inputs: Vec<Inputs>,
    options: MasterOptions,
    cycles: u64,
}

impl Master {
    /// Brings the bus up: scan, check, configure, OP, enable. The frame storage and the
    /// ethercrab main device live as long as the process (one bus per process: leaked once).
    pub fn open(
        link: Box<dyn Link>,
        section: &DriveSection,
        options: MasterOptions,
    ) -> Result<Master, OpenError> {
        if section.slaves.len() > MAX_DRIVES {
            return Err(OpenError::Scan(format!(
                "{} drives listed, at most {MAX_DRIVES}",
                section.slaves.len()
            )));
        }
        let storage: &'static Storage = Box::leak(Box::new(Storage::new()));
        let (tx, rx, pdu_loop) = storage
            .try_split()
            .map_err(|()| OpenError::Scan("frame storage already in use".into()))?;
        let timeouts = Timeouts {
            pdu: Duration::from_millis(100),
            state_transition: Duration::from_secs(5),
            mailbox_response: Duration::from_secs(1),
            mailbox_echo: Duration::from_millis(500),
            eeprom: Duration::from_millis(100),
            wait_loop_delay: Duration::from_micros(200),
        };
        let md: &'static MainDevice<'static> = Box::leak(Box::new(MainDevice::new(
            pdu_loop,
            timeouts,
            MainDeviceConfig {
                // A frame lost during bring-up is sent again (the cycle has its own deadline
                // and counts a loss as a fault).
                retry_behaviour: RetryBehaviour::Count(3),
                ..MainDeviceConfig::default()
            },
        )));
        let mut port = Port::new(tx, rx, link);
        let deadline = Instant::now() + options.open_timeout;
        let run_err = |e: PortError| match e {
            PortError::Timeout => "timed out".to_owned(),
            PortError::Link(e) => e.to_string(),
        };

        let group = port
            .run(
                md.init_single_group::<MAX_DRIVES, MAX_PDI>(ethercrab::std::ethercat_now),
                deadline,
            )
            .map_err(|e| OpenError::Scan(run_err(e)))?
            .map_err(|e| OpenError::Scan(e.to_string()))?;
        if group.is_empty() {
            return Err(OpenError::NoSlaves);
        }
        let found: Vec<(u32, u32, String)> = group
            .iter(md)
            .map(|s| {
                let id = s.identity();
                (id.vendor_id, id.product_id, s.name().to_owned())
            })
            .collect();
        if found.len() != section.slaves.len() {
            return Err(OpenError::Count {
                found: found
                    .iter()
                    .enumerate()
                    .map(|(i, (v, p, n))| format!("{i}: {n} ({v:#x}/{p:#x})"))
                    .collect(),
                expected: section.slaves.len(),
            });
        }
        for (i, (f, want)) in found.iter().zip(&section.slaves).enumerate() {
            if (f.0, f.1) != (want.vendor_id, want.product_code) {
                return Err(OpenError::Identity {
                    position: i,
                    joint: want.joint_name.clone(),
                    found: f.clone(),
                    expected: (want.vendor_id, want.product_code),
                });
            }
        }
        for (i, (sd, want)) in group.iter(md).zip(&section.slaves).enumerate() {
            port.run(configure(&sd, want), deadline)
                .map_err(|e| OpenError::Scan(run_err(e)))?
                .map_err(|message| OpenError::Configure {
                    position: i,
                    joint: want.joint_name.clone(),
                    message,
                })?;
        }
        let group = port
            .run(group.into_op(md), deadline)
            .map_err(|e| OpenError::Op(run_err(e)))?
            .map_err(|e| OpenError::Op(e.to_string()))?;
        for sd in group.iter(md) {
            let io = sd.io_raw();
            if io.inputs().len() != Inputs::LEN || io.outputs().len() != Outputs::LEN {
                return Err(OpenError::Op(format!(
                    "{}: process data of {} in / {} out bytes, expected {} / {}",
                    sd.name(),
                    io.inputs().len(),
                    io.outputs().len(),
                    Inputs::LEN,
                    Outputs::LEN
                )));
            }
        }
        let mut master = Master {
            md,
            group,
            port,
            slaves: section.slaves.clone(),
            inputs: vec![Inputs::default(); section.slaves.len()],
            options,
            cycles: 0,
        };
        master.enable(deadline)?;
        Ok(master)
    }

    /// Walks every drive to operation enabled, holding each at its actual position.
    fn enable(&mut self, deadline: Instant) -> Result<(), OpenError> {
        let mut outputs = vec![Outputs::default(); self.slaves.len()];
        // A fault reset is tried a few times; a drive that keeps faulting is reported.
        loop {
            match self.exchange(&outputs) {
                Ok(()) => {}
                Err(e) => return Err(OpenError::Op(format!("{e:?} while enabling"))),
            }
            let mut all = true;
            for (o, i) in outputs.iter_mut().zip(&self.inputs) {
                let state = State::from_statusword(i.statusword);
                all &= state == State::OperationEnabled;
                o.controlword = cia402::toward_enabled(state, self.cycles % 2 == 0);
                // CSP: the target must be where the drive is when it enables (no jump).
                o.target = i.position;
            }
            if all {
                return Ok(());
            }
            if Instant::now() > deadline {
                let (position, i) = self
                    .inputs
                    .iter()
                    .enumerate()
                    .find(|(_, i)| State::from_statusword(i.statusword) != State::OperationEnabled)
                    .map(|(p, i)| (p, *i))
                    .unwrap_or_default();
                return Err(OpenError::Enable {
                    position,
                    joint: self.slaves[position].joint_name.clone(),
                    state: State::from_statusword(i.statusword),
                    error: i.error_code,
                });
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    /// The drives, in bus order.
    pub fn slaves(&self) -> &[DriveSlave] {
        &self.slaves
    }

    /// The feedback of the last cycle, in bus order.
    pub fn inputs(&self) -> &[Inputs] {
        &self.inputs
    }

    pub fn cycles(&self) -> u64 {
        self.cycles
    }

    /// One cycle: `outputs` (bus order) out, the drives' inputs in. Allocates nothing.
    pub fn exchange(&mut self, outputs: &[Outputs]) -> Result<(), CycleError> {
        for (sd, o) in self.group.iter(self.md).zip(outputs) {
            o.write(&mut sd.outputs_raw_mut());
        }
        let deadline = Instant::now() + self.options.cycle_timeout;
        let r = self.port.run(self.group.tx_rx(self.md), deadline);
        self.cycles += 1;
        let response = match r {
            Ok(Ok(r)) => r,
            Ok(Err(_)) | Err(PortError::Timeout) => return Err(CycleError::Lost),
            Err(PortError::Link(_)) => return Err(CycleError::LinkDown),
        };
        // Each drive reads its inputs (1) and writes its outputs (2): ETG.1000.4 §5.4.
        let expected = 3 * self.slaves.len() as u16;
        if response.working_counter != expected
            || response
                .subdevice_states
                .iter()
                .any(|s| *s != SubDeviceState::Op)
        {
            return Err(CycleError::WorkingCounter {
                expected,
                got: response.working_counter,
            });
        }
        for (sd, i) in self.group.iter(self.md).zip(self.inputs.iter_mut()) {
            if let Some(v) = Inputs::read(&sd.inputs_raw()) {
                *i = v;
            }
        }
        Ok(())
    }
}

/// The SDO configuration of one drive: CSP, the PDO mapping and assignment, its following
/// error window; then the mode read back.
async fn configure<S>(sd: &ethercrab::SubDeviceRef<'_, S>, slave: &DriveSlave) -> Result<(), String>
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    fn e(what: &str) -> impl Fn(ethercrab::error::Error) -> String + '_ {
        move |err| format!("{what}: {err}")
    }
    sd.sdo_write(od::MODES_OF_OPERATION, 0, od::MODE_CSP)
        .await
        .map_err(e("mode of operation 0x6060 = 8"))?;
    for (assign, map, entries) in [
        (od::SM2_ASSIGNMENT, od::RX_PDO_MAPPING, &od::OUTPUTS[..]),
        (od::SM3_ASSIGNMENT, od::TX_PDO_MAPPING, &od::INPUTS[..]),
    ] {
        let what = format!("PDO mapping {map:#06x}");
        sd.sdo_write(assign, 0, 0u8).await.map_err(e(&what))?;
        sd.sdo_write(map, 0, 0u8).await.map_err(e(&what))?;
        for (k, m) in entries.iter().enumerate() {
            sd.sdo_write(map, k as u8 + 1, m.entry())
                .await
                .map_err(e(&what))?;
        }
        sd.sdo_write(map, 0, entries.len() as u8)
            .await
            .map_err(e(&what))?;
        sd.sdo_write(assign, 1, map).await.map_err(e(&what))?;
        sd.sdo_write(assign, 0, 1u8).await.map_err(e(&what))?;
    }
    sd.sdo_write(od::FOLLOWING_ERROR_WINDOW, 0, slave.following_error_counts)
        .await
        .map_err(e("following error window 0x6065"))?;
    let mode: i8 = sd
        .sdo_read(od::MODES_OF_OPERATION_DISPLAY, 0)
        .await
        .map_err(e("mode display 0x6061"))?;
    if mode != od::MODE_CSP {
        return Err(format!("mode display 0x6061 reads {mode}, not 8 (CSP)"));
    }
    Ok(())
}
