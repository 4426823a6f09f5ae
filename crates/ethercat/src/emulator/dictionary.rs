//! The emulated drive's object dictionary and its SDO server (CiA 301 §7.4; CoE per
//! ETG.1000.6 §5.6.2): expedited upload and download of the objects a CSP drive needs, with
//! the PDO mapping and assignment writable in PRE-OP only and checked as a drive checks them.
//! The mailbox carries the requests (`super::esc`); the cyclic exchange reads and writes the
//! mapped objects here too, so SDO and PDO see one dictionary.

use std::collections::BTreeMap;

use crate::od::{self, Mapped};

/// SDO abort codes (CiA 301 table 22).
pub mod abort {
    pub const COMMAND: u32 = 0x0504_0001;
    pub const READ_ONLY: u32 = 0x0601_0002;
    pub const NO_OBJECT: u32 = 0x0602_0000;
    pub const NOT_MAPPABLE: u32 = 0x0604_0041;
    pub const LENGTH: u32 = 0x0607_0010;
    pub const NO_SUBINDEX: u32 = 0x0609_0011;
    pub const RANGE: u32 = 0x0609_0030;
    pub const STATE: u32 = 0x0800_0022;
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    ReadOnly,
    ReadWrite,
    /// Writable in PRE-OP only (mapping and assignment objects).
    PreOp,
}

#[derive(Debug, Clone, Copy)]
struct Entry {
    bytes: u8,
    value: u32,
    access: Access,
}

/// The objects, each a value of up to 4 bytes.
#[derive(Debug, Clone)]
pub struct Dictionary {
    entries: BTreeMap<(u16, u8), Entry>,
}

/// Objects a drive lets the master map, per direction.
const RX_MAPPABLE: [u16; 2] = [od::CONTROLWORD, od::TARGET_POSITION];
const TX_MAPPABLE: [u16; 5] = [
    od::STATUSWORD,
    od::POSITION_ACTUAL,
    od::FOLLOWING_ERROR_ACTUAL,
    od::ERROR_CODE,
    od::MODES_OF_OPERATION_DISPLAY,
];

impl Dictionary {
    pub fn new(id: &super::sii::Identity) -> Dictionary {
        use Access::*;
        let mut d = Dictionary {
            entries: BTreeMap::new(),
        };
        // Device type: profile 402, servo drive (CiA 402-2 §6.3.1).
        d.add(0x1000, 0, 4, 0x0002_0192, ReadOnly);
        d.add(od::IDENTITY, 0, 1, 4, ReadOnly);
        d.add(od::IDENTITY, 1, 4, id.vendor_id, ReadOnly);
        d.add(od::IDENTITY, 2, 4, id.product_code, ReadOnly);
        d.add(od::IDENTITY, 3, 4, id.revision, ReadOnly);
        d.add(od::IDENTITY, 4, 4, id.serial, ReadOnly);
        for (map, default) in [
            (od::RX_PDO_MAPPING, &od::OUTPUTS[..]),
            (od::TX_PDO_MAPPING, &od::INPUTS[..]),
        ] {
            d.add(map, 0, 1, default.len() as u32, PreOp);
            for sub in 1..=8u8 {
                let v = default.get(sub as usize - 1).map_or(0, |m| m.entry());
                d.add(map, sub, 4, v, PreOp);
            }
        }
        d.add(od::SM2_ASSIGNMENT, 0, 1, 1, PreOp);
        d.add(od::SM2_ASSIGNMENT, 1, 2, od::RX_PDO_MAPPING as u32, PreOp);
        d.add(od::SM3_ASSIGNMENT, 0, 1, 1, PreOp);
        d.add(od::SM3_ASSIGNMENT, 1, 2, od::TX_PDO_MAPPING as u32, PreOp);
        d.add(od::ERROR_CODE, 0, 2, 0, ReadOnly);
        d.add(od::CONTROLWORD, 0, 2, 0, ReadWrite);
        d.add(od::STATUSWORD, 0, 2, 0, ReadOnly);
        d.add(od::MODES_OF_OPERATION, 0, 1, 0, ReadWrite);
        d.add(od::MODES_OF_OPERATION_DISPLAY, 0, 1, 0, ReadOnly);
        d.add(od::POSITION_ACTUAL, 0, 4, 0, ReadOnly);
        d.add(od::FOLLOWING_ERROR_WINDOW, 0, 4, u32::MAX, ReadWrite);
        d.add(od::TARGET_POSITION, 0, 4, 0, ReadWrite);
        d.add(od::FOLLOWING_ERROR_ACTUAL, 0, 4, 0, ReadOnly);
        d
    }

    fn add(&mut self, index: u16, sub: u8, bytes: u8, value: u32, access: Access) {
        self.entries.insert(
            (index, sub),
            Entry {
                bytes,
                value,
                access,
            },
        );
    }

    /// A value (0 for a missing object: the emulator reads only objects it made).
    pub fn get(&self, index: u16, sub: u8) -> u32 {
        self.entries.get(&(index, sub)).map_or(0, |e| e.value)
    }

    /// Sets a value from the drive's side (no access check).
    pub fn set(&mut self, index: u16, sub: u8, value: u32) {
        if let Some(e) = self.entries.get_mut(&(index, sub)) {
            e.value = value & mask(e.bytes);
        }
    }

    /// SDO upload: the value and its size, or an abort code.
    pub fn upload(&self, index: u16, sub: u8) -> Result<(u32, u8), u32> {
        match self.entries.get(&(index, sub)) {
            Some(e) => Ok((e.value, e.bytes)),
            None if self.entries.keys().any(|(i, _)| *i == index) => Err(abort::NO_SUBINDEX),
            None => Err(abort::NO_OBJECT),
        }
    }

    /// SDO download of `bytes` bytes; `pre_op` says whether the slave is in PRE-OP.
    pub fn download(
        &mut self,
        index: u16,
        sub: u8,
        value: u32,
        bytes: u8,
        pre_op: bool,
    ) -> Result<(), u32> {
        let e = *self.entries.get(&(index, sub)).ok_or_else(|| {
            if self.entries.keys().any(|(i, _)| *i == index) {
                abort::NO_SUBINDEX
            } else {
                abort::NO_OBJECT
            }
        })?;
        match e.access {
            Access::ReadOnly => return Err(abort::READ_ONLY),
            Access::PreOp if !pre_op => return Err(abort::STATE),
            _ => {}
        }
        if bytes != e.bytes {
            return Err(abort::LENGTH);
        }
        let is_map = index == od::RX_PDO_MAPPING || index == od::TX_PDO_MAPPING;
        let is_assign = index == od::SM2_ASSIGNMENT || index == od::SM3_ASSIGNMENT;
        if (is_map || is_assign) && sub > 0 && self.get(index, 0) != 0 {
            // CiA 301 §7.4.8.4: entries change only while sub-index 0 is 0.
            return Err(abort::STATE);
        }
        if is_map && sub == 0 {
            let allowed: &[u16] = if index == od::RX_PDO_MAPPING {
                &RX_MAPPABLE
            } else {
                &TX_MAPPABLE
            };
            if value > 8 {
                return Err(abort::RANGE);
            }
            for s in 1..=value as u8 {
                let m = Mapped::from_entry(self.get(index, s));
                let fits = self
                    .entries
                    .get(&(m.index, m.sub))
                    .is_some_and(|t| t.bytes as u32 * 8 == m.bits as u32);
                if !allowed.contains(&m.index) || !fits {
                    return Err(abort::NOT_MAPPABLE);
                }
            }
        }
        if is_assign && sub == 0 && value > 1 {
            return Err(abort::RANGE);
        }
        if is_assign && sub == 1 {
            let want = if index == od::SM2_ASSIGNMENT {
                od::RX_PDO_MAPPING
            } else {
                od::TX_PDO_MAPPING
            };
            if value != want as u32 {
                return Err(abort::RANGE);
            }
        }
        if index == od::MODES_OF_OPERATION {
            if value as u8 as i8 != od::MODE_CSP {
                // The emulated drive knows cyclic synchronous position only.
                return Err(abort::RANGE);
            }
            self.set(od::MODES_OF_OPERATION_DISPLAY, 0, value);
        }
        self.set(index, sub, value);
        Ok(())
    }

    /// The mapped objects of an assignment object (0x1C12 or 0x1C13), in order.
    pub fn mapping(&self, assignment: u16) -> Vec<Mapped> {
        let mut out = Vec::new();
        for a in 1..=self.get(assignment, 0) as u8 {
            let pdo = self.get(assignment, a) as u16;
            for s in 1..=self.get(pdo, 0) as u8 {
                out.push(Mapped::from_entry(self.get(pdo, s)));
            }
        }
        out
    }
}

fn mask(bytes: u8) -> u32 {
    match bytes {
        1 => 0xFF,
        2 => 0xFFFF,
        _ => u32::MAX,
    }
}

/// Answers one CoE mailbox message (`request`, from the mailbox header on) into `reply`;
/// returns the reply's length, or `None` for what is not a CoE SDO request.
///
/// Mailbox header (ETG.1000.6 §5.5): length, address, channel/priority, type (3 = CoE) with
/// the counter in bits 4–6. CoE header: service in the top nibble of byte 2 (2 = SDO request,
/// 3 = SDO response). SDO: command byte, index, sub-index, 4 data bytes (§5.6.2.1–5.6.2.4).
pub fn serve_mailbox(
    dict: &mut Dictionary,
    pre_op: bool,
    request: &[u8],
    reply: &mut [u8],
) -> Option<usize> {
    if request.len() < 16 || reply.len() < 16 || request[5] & 0x0F != 0x03 {
        return None;
    }
    if request[7] >> 4 != 2 {
        return None;
    }
    let counter = request[5] & 0x70;
    let cmd = request[8];
    let index = u16::from_le_bytes([request[9], request[10]]);
    let sub = request[11];
    let data = u32::from_le_bytes([request[12], request[13], request[14], request[15]]);
    let (sdo, value) = match cmd >> 5 {
        // Initiate upload (ccs 2): answer expedited, size indicated.
        2 => match dict.upload(index, sub) {
            Ok((v, n)) => (0x43 | (4 - n) << 2, v),
            Err(code) => (0x80, code),
        },
        // Initiate download (ccs 1), expedited with the size indicated.
        1 if cmd & 0x03 == 0x03 => {
            let n = 4 - ((cmd >> 2) & 0x03);
            match dict.download(index, sub, data & mask(n), n, pre_op) {
                Ok(()) => (0x60, 0),
                Err(code) => (0x80, code),
            }
        }
        _ => (0x80, abort::COMMAND),
    };
    reply[..16].fill(0);
    reply[0..2].copy_from_slice(&10u16.to_le_bytes());
    reply[5] = 0x03 | counter;
    reply[7] = 3 << 4;
    reply[8] = sdo;
    reply[9..11].copy_from_slice(&index.to_le_bytes());
    reply[11] = sub;
    reply[12..16].copy_from_slice(&value.to_le_bytes());
    Some(16)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dict() -> Dictionary {
        Dictionary::new(&super::super::sii::Identity {
            vendor_id: 1,
            product_code: 2,
            revision: 3,
            serial: 4,
        })
    }

    #[test]
    fn mapping_changes_only_with_sub_zero_cleared() {
        let mut d = dict();
        let m = od::RX_PDO_MAPPING;
        assert_eq!(d.download(m, 1, 0x6040_0010, 4, true), Err(abort::STATE));
        assert_eq!(d.download(m, 0, 0, 1, true), Ok(()));
        assert_eq!(d.download(m, 1, 0x6041_0010, 4, true), Ok(()));
        // the statusword is not an output
        assert_eq!(d.download(m, 0, 1, 1, true), Err(abort::NOT_MAPPABLE));
        assert_eq!(d.download(m, 1, 0x607A_0010, 4, true), Ok(()));
        // 16 bits of a 32-bit object
        assert_eq!(d.download(m, 0, 1, 1, true), Err(abort::NOT_MAPPABLE));
        assert_eq!(d.download(m, 1, 0x607A_0020, 4, true), Ok(()));
        assert_eq!(d.download(m, 0, 1, 1, true), Ok(()));
        assert_eq!(d.mapping(od::SM2_ASSIGNMENT), [od::OUTPUTS[1]]);
        // not in SAFE-OP
        assert_eq!(d.download(m, 0, 0, 1, false), Err(abort::STATE));
    }

    #[test]
    fn sdo_frames_follow_etg1000_6() {
        let mut d = dict();
        // upload 0x1018:1, counter 2
        let mut req = [0u8; 16];
        req[0] = 10;
        req[5] = 0x23;
        req[7] = 0x20;
        req[8] = 0x40;
        req[9..11].copy_from_slice(&0x1018u16.to_le_bytes());
        req[11] = 1;
        let mut rep = [0u8; 128];
        assert_eq!(serve_mailbox(&mut d, true, &req, &mut rep), Some(16));
        assert_eq!(rep[5], 0x23);
        assert_eq!(rep[7], 0x30);
        assert_eq!(rep[8], 0x43);
        assert_eq!(u32::from_le_bytes(rep[12..16].try_into().unwrap()), 1);
        // download mode 8 (1 byte: 0x2F), then mode 1 refused with "value range exceeded"
        req[8] = 0x2F;
        req[9..11].copy_from_slice(&0x6060u16.to_le_bytes());
        req[11] = 0;
        req[12] = 8;
        serve_mailbox(&mut d, true, &req, &mut rep);
        assert_eq!(rep[8], 0x60);
        assert_eq!(d.get(0x6061, 0), 8);
        req[12] = 1;
        serve_mailbox(&mut d, true, &req, &mut rep);
        assert_eq!(rep[8], 0x80);
        assert_eq!(
            u32::from_le_bytes(rep[12..16].try_into().unwrap()),
            abort::RANGE
        );
    }
}
