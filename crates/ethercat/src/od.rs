//! The CiA-402 objects tezgah's drive bus reads and writes, by object-dictionary index (CiA 402-2,
//! 2021, ch. 6–8; CiA 301 for the communication objects), and the process-data mapping both the
//! master and the emulated drive use: what goes out and comes back each cycle.

/// Error code (u16): the drive's last fault, CiA 301 §7.2.7.1 codes (`crate::error_code`).
pub const ERROR_CODE: u16 = 0x603F;
/// Controlword (u16), master → drive: the state machine's commands (`crate::cia402`).
pub const CONTROLWORD: u16 = 0x6040;
/// Statusword (u16), drive → master: the state machine's state.
pub const STATUSWORD: u16 = 0x6041;
/// Modes of operation (i8), written once over SDO.
pub const MODES_OF_OPERATION: u16 = 0x6060;
/// Modes of operation display (i8): the mode the drive is in.
pub const MODES_OF_OPERATION_DISPLAY: u16 = 0x6061;
/// Position actual value (i32, counts).
pub const POSITION_ACTUAL: u16 = 0x6064;
/// Following error window (u32, counts): the drive faults beyond it (0xFFFF_FFFF: off).
pub const FOLLOWING_ERROR_WINDOW: u16 = 0x6065;
/// Target position (i32, counts): the set-point in cyclic synchronous position mode.
pub const TARGET_POSITION: u16 = 0x607A;
/// Following error actual value (i32, counts).
pub const FOLLOWING_ERROR_ACTUAL: u16 = 0x60F4;

/// Identity object (CiA 301 §7.5.2.6): sub 1 vendor id, 2 product code, 3 revision, 4 serial.
pub const IDENTITY: u16 = 0x1018;
/// First receive-PDO mapping (master → drive).
pub const RX_PDO_MAPPING: u16 = 0x1600;
/// First transmit-PDO mapping (drive → master).
pub const TX_PDO_MAPPING: u16 = 0x1A00;
/// Sync manager 2 (outputs) PDO assignment (ETG.1000.6 §5.6.7.4).
pub const SM2_ASSIGNMENT: u16 = 0x1C12;
/// Sync manager 3 (inputs) PDO assignment.
pub const SM3_ASSIGNMENT: u16 = 0x1C13;

/// Cyclic synchronous position mode (CiA 402-2 §6.2.2: modes of operation value 8).
pub const MODE_CSP: i8 = 8;

/// One mapped object: index, sub-index and length in bits, packed as a PDO mapping entry is
/// (index << 16 | sub << 8 | bits, CiA 301 §7.4.8.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mapped {
    pub index: u16,
    pub sub: u8,
    pub bits: u8,
}

impl Mapped {
    pub const fn entry(self) -> u32 {
        (self.index as u32) << 16 | (self.sub as u32) << 8 | self.bits as u32
    }

    pub const fn from_entry(e: u32) -> Mapped {
        Mapped {
            index: (e >> 16) as u16,
            sub: (e >> 8) as u8,
            bits: e as u8,
        }
    }

    pub const fn bytes(self) -> usize {
        self.bits as usize / 8
    }
}

/// What the master sends each cycle: controlword, target position (6 bytes).
pub const OUTPUTS: [Mapped; 2] = [
    Mapped {
        index: CONTROLWORD,
        sub: 0,
        bits: 16,
    },
    Mapped {
        index: TARGET_POSITION,
        sub: 0,
        bits: 32,
    },
];

/// What each drive returns each cycle: statusword, position actual, following error actual,
/// error code (12 bytes). The error code rides along so a fault's cause is known in the cycle
/// it appears, without a mailbox round trip.
pub const INPUTS: [Mapped; 4] = [
    Mapped {
        index: STATUSWORD,
        sub: 0,
        bits: 16,
    },
    Mapped {
        index: POSITION_ACTUAL,
        sub: 0,
        bits: 32,
    },
    Mapped {
        index: FOLLOWING_ERROR_ACTUAL,
        sub: 0,
        bits: 32,
    },
    Mapped {
        index: ERROR_CODE,
        sub: 0,
        bits: 16,
    },
];

/// Bytes of a mapping.
pub const fn mapping_bytes(m: &[Mapped]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < m.len() {
        n += m[i].bytes();
        i += 1;
    }
    n
}

/// The outputs one drive takes, decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Outputs {
    pub controlword: u16,
    pub target: i32,
}

impl Outputs {
    pub const LEN: usize = mapping_bytes(&OUTPUTS);

    /// Writes them in [`OUTPUTS`] order, little-endian (EtherCAT's byte order).
    pub fn write(&self, out: &mut [u8]) -> bool {
        let Some(out) = out.get_mut(..Self::LEN) else {
            return false;
        };
        out[0..2].copy_from_slice(&self.controlword.to_le_bytes());
        out[2..6].copy_from_slice(&self.target.to_le_bytes());
        true
    }

    pub fn read(b: &[u8]) -> Option<Outputs> {
        let b = b.get(..Self::LEN)?;
        Some(Outputs {
            controlword: u16::from_le_bytes([b[0], b[1]]),
            target: i32::from_le_bytes([b[2], b[3], b[4], b[5]]),
        })
    }
}

/// The inputs one drive returns, decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Inputs {
    pub statusword: u16,
    pub position: i32,
    pub following_error: i32,
    pub error_code: u16,
}

impl Inputs {
    pub const LEN: usize = mapping_bytes(&INPUTS);

    pub fn read(b: &[u8]) -> Option<Inputs> {
        let b = b.get(..Self::LEN)?;
        Some(Inputs {
            statusword: u16::from_le_bytes([b[0], b[1]]),
            position: i32::from_le_bytes([b[2], b[3], b[4], b[5]]),
            following_error: i32::from_le_bytes([b[6], b[7], b[8], b[9]]),
            error_code: u16::from_le_bytes([b[10], b[11]]),
        })
    }

    pub fn write(&self, out: &mut [u8]) -> bool {
        let Some(out) = out.get_mut(..Self::LEN) else {
            return false;
        };
        out[0..2].copy_from_slice(&self.statusword.to_le_bytes());
        out[2..6].copy_from_slice(&self.position.to_le_bytes());
        out[6..10].copy_from_slice(&self.following_error.to_le_bytes());
        out[10..12].copy_from_slice(&self.error_code.to_le_bytes());
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_entries_pack_as_cia301_says() {
        // CiA 301 §7.4.8.4: 0x607A0020 maps target position, sub 0, 32 bits.
        assert_eq!(OUTPUTS[1].entry(), 0x607A_0020);
        assert_eq!(INPUTS[0].entry(), 0x6041_0010);
        assert_eq!(Mapped::from_entry(0x60F4_0020), INPUTS[2]);
        assert_eq!(Outputs::LEN, 6);
        assert_eq!(Inputs::LEN, 12);
    }

    #[test]
    fn process_data_round_trips() {
        let i = Inputs {
            statusword: 0x1237,
            position: -123_456,
            following_error: 42,
            error_code: 0x8611,
        };
        let mut b = [0u8; 12];
        assert!(i.write(&mut b));
        assert_eq!(Inputs::read(&b), Some(i));
        assert_eq!(Inputs::read(&b[..11]), None);
        let o = Outputs {
            controlword: 0x000F,
            target: i32::MIN,
        };
        let mut b = [0u8; 6];
        assert!(o.write(&mut b));
        assert_eq!(b[0..2], [0x0F, 0x00]);
        assert_eq!(Outputs::read(&b), Some(o));
    }
}
