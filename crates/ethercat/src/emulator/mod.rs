//! Emulated CiA-402 drives on an emulated EtherCAT segment, for the tests and for trying
//! `tezgah serve` without hardware. [`Bus::process`] takes one Ethernet frame as the master
//! sent it and returns it as it comes back after passing every slave in cable order
//! (ETG.1000.4 §5: each datagram read or written by the slaves it addresses, its working
//! counter raised by each). The master reaches it in process (`crate::master::link::InProcess`)
//! or on a network interface through a raw socket (`crate::master::link::RawSocket`,
//! [`serve_interface`]).

pub mod dictionary;
pub mod esc;
pub mod netns;
pub mod servo;
pub mod sii;

pub use esc::Slave;
pub use sii::Identity;

/// EtherCAT's EtherType.
pub const ETHERTYPE: u16 = 0x88A4;

/// The identity the emulated drives report unless told otherwise.
pub const IDENTITY: Identity = Identity {
    vendor_id: 0x0000_0E5A,
    product_code: 0x0000_0402,
    revision: 1,
    serial: 0,
};

/// A segment of emulated slaves.
#[derive(Debug, Clone, Default)]
pub struct Bus {
    pub slaves: Vec<Slave>,
    /// Frames to swallow before answering again (a lost frame).
    pub drop_frames: u32,
    /// The cable is cut before the first slave: nothing answers.
    pub cut: bool,
    /// Frames answered.
    pub frames: u64,
}

impl Bus {
    /// `n` drives with the default identity (serials 1…n) and motor gain `gain`.
    pub fn drives(n: usize, gain: f64) -> Bus {
        let mut b = Bus::default();
        for i in 0..n {
            b.push(Slave::new(
                Identity {
                    serial: i as u32 + 1,
                    ..IDENTITY
                },
                gain,
            ));
        }
        b
    }

    /// Adds a slave at the end of the cable.
    pub fn push(&mut self, s: Slave) {
        self.slaves.push(s);
        let n = self.slaves.len();
        for (i, s) in self.slaves.iter_mut().enumerate() {
            s.set_links(i + 1 < n);
        }
    }

    /// Forgets the received targets (after the enable walk).
    pub fn clear_logs(&mut self) {
        for s in &mut self.slaves {
            s.targets.clear();
        }
    }

    /// Passes one Ethernet frame through the segment in place; `false` when it is not an
    /// EtherCAT frame or does not come back (dropped, cable cut).
    pub fn process(&mut self, frame: &mut [u8]) -> bool {
        if frame.len() < 16 || u16::from_be_bytes([frame[12], frame[13]]) != ETHERTYPE {
            return false;
        }
        if self.cut {
            return false;
        }
        if self.drop_frames > 0 {
            self.drop_frames -= 1;
            return false;
        }
        // EtherCAT header: 11 bits length, type 1 (PDUs) in the top nibble.
        let header = u16::from_le_bytes([frame[14], frame[15]]);
        if header >> 12 != 1 {
            return false;
        }
        let end = (16 + (header & 0x07FF) as usize).min(frame.len());
        let mut at = 16;
        while at + 12 <= end {
            let len_field = u16::from_le_bytes([frame[at + 6], frame[at + 7]]);
            let len = (len_field & 0x07FF) as usize;
            if at + 12 + len > end {
                return false;
            }
            let (head, rest) = frame[at..].split_at_mut(10);
            let (data, tail) = rest.split_at_mut(len);
            let mut wkc = u16::from_le_bytes([tail[0], tail[1]]);
            self.datagram(head, data, &mut wkc);
            tail[0..2].copy_from_slice(&wkc.to_le_bytes());
            at += 12 + len;
            if len_field & 0x8000 == 0 {
                break;
            }
        }
        // The first slave sets the locally administered bit of the source address: the
        // master tells its frames coming back from those it sent.
        frame[6] |= 0x02;
        self.frames += 1;
        true
    }

    /// One datagram through every slave. `head`: command, index, address (4), length, IRQ.
    fn datagram(&mut self, head: &mut [u8], data: &mut [u8], wkc: &mut u16) {
        let cmd = head[0];
        for s in &mut self.slaves {
            let adp = u16::from_le_bytes([head[2], head[3]]);
            let ado = u16::from_le_bytes([head[4], head[5]]) as usize;
            let (addressed, increment) = match cmd {
                1..=3 => (adp == 0, true),                    // APRD, APWR, APRW
                4..=6 => (adp == s.station_address(), false), // FPRD, FPWR, FPRW
                7..=9 => (true, true),                        // BRD, BWR, BRW
                13 => (adp == 0, true),                       // ARMW
                14 => (adp == s.station_address(), false),    // FRMW
                10..=12 => {
                    let la = u32::from_le_bytes([head[2], head[3], head[4], head[5]]);
                    *wkc = wkc.wrapping_add(s.logical(cmd, la, data));
                    continue;
                }
                _ => return,
            };
            if addressed {
                match cmd {
                    1 | 4 => {
                        s.read(ado, data, false);
                        *wkc += 1;
                    }
                    7 => {
                        s.read(ado, data, true);
                        *wkc += 1;
                    }
                    2 | 5 | 8 => {
                        s.write(ado, data);
                        *wkc += 1;
                    }
                    3 | 6 | 9 => {
                        let incoming = data.to_vec();
                        s.read(ado, data, false);
                        s.write(ado, &incoming);
                        *wkc += 3;
                    }
                    // read-multiple-write: the addressed slave reads, the others write
                    13 | 14 => {
                        s.read(ado, data, false);
                        *wkc += 1;
                    }
                    _ => {}
                }
            } else if cmd == 13 || cmd == 14 {
                s.write(ado, data);
                *wkc += 1;
            }
            if increment {
                head[2..4].copy_from_slice(&adp.wrapping_add(1).to_le_bytes());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Any bytes under the EtherCAT EtherType: answered or refused, never a panic, and the
        /// frame keeps its length.
        #[test]
        fn any_frame_is_survived(body in proptest::collection::vec(any::<u8>(), 0..400),
                                 header in any::<u16>()) {
            let mut bus = Bus::drives(2, 0.5);
            let mut frame = vec![0xFFu8; 12];
            frame.extend_from_slice(&ETHERTYPE.to_be_bytes());
            frame.extend_from_slice(&header.to_le_bytes());
            frame.extend_from_slice(&body);
            let n = frame.len();
            bus.process(&mut frame);
            prop_assert_eq!(frame.len(), n);
        }

        /// Datagrams well framed but aimed anywhere (any command, address, length).
        #[test]
        fn any_datagram_is_survived(cmd in 0u8..16, adp in any::<u16>(), ado in any::<u16>(),
                                    data in proptest::collection::vec(any::<u8>(), 0..200)) {
            let mut bus = Bus::drives(2, 0.5);
            let mut frame = vec![0xFFu8; 12];
            frame.extend_from_slice(&ETHERTYPE.to_be_bytes());
            let len = 12 + data.len();
            frame.extend_from_slice(&((len as u16) | 0x1000).to_le_bytes());
            frame.extend_from_slice(&[cmd, 0]);
            frame.extend_from_slice(&adp.to_le_bytes());
            frame.extend_from_slice(&ado.to_le_bytes());
            frame.extend_from_slice(&(data.len() as u16).to_le_bytes());
            frame.extend_from_slice(&[0, 0]);
            frame.extend_from_slice(&data);
            frame.extend_from_slice(&[0, 0]);
            prop_assert!(bus.process(&mut frame));
        }
    }

    #[test]
    fn a_broadcast_read_counts_every_slave() {
        // BRD of the ESC type register: wkc = number of slaves (what the master's scan counts).
        let mut bus = Bus::drives(3, 1.0);
        let mut frame = vec![0xFFu8; 12];
        frame.extend_from_slice(&ETHERTYPE.to_be_bytes());
        frame.extend_from_slice(&(13u16 | 0x1000).to_le_bytes());
        frame.extend_from_slice(&[7, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0]);
        assert!(bus.process(&mut frame));
        assert_eq!(frame[26], 0x11);
        assert_eq!(u16::from_le_bytes([frame[27], frame[28]]), 3);
        assert_eq!(frame[6] & 0x02, 0x02, "locally administered bit set");
    }
}
