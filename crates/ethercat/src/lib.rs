//! tezgah-ethercat: the drive bus. CiA-402 servo drives in cyclic synchronous position over
//! EtherCAT, with the `ethercrab` crate as the master's frame engine.
//!
//! [`od`] names the objects and the process-data layout, [`cia402`] the drive state machine
//! from the master's side, [`error_code`] the texts of a drive's 0x603F, [`section`] the
//! machine file's `[drive]` table. [`emulator`] is a CiA-402 drive that answers EtherCAT frames
//! (for tests and demos; `emulator::netns` makes the veth pair the namespace tests use);
//! [`master`] scans, configures and runs the bus, [`drive`] puts it behind the executor's
//! `Drive` trait, and [`monitor`] shows the drives' states and positions to the front end.

pub mod cia402;
pub mod drive;
pub mod emulator;
pub mod error_code;
pub mod master;
pub mod monitor;
pub mod od;
pub mod section;

pub use section::{DriveSection, DriveSlave, SectionError};
