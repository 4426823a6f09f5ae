//! One emulated slave's EtherCAT slave controller (ESC, after ETG.1000.4 and the Beckhoff
//! ET1100 register map): its memory (registers below 0x1000, process RAM above), what reads
//! and writes of the registers set off (AL state requests, EEPROM reads, mailbox hand-over),
//! FMMU translation of logical datagrams, and the drive application behind it
//! (`super::dictionary`, `super::servo`). `super::Bus` passes each frame's datagrams through
//! the slaves in cable order.

use super::dictionary::{serve_mailbox, Dictionary};
use super::servo::Servo;
use super::sii::{self, Identity};
use crate::od::{self, Mapped};

const MEMORY: usize = 0x2000;

// Registers (ETG.1000.4 table 31 ff.).
const STATION_ADDRESS: usize = 0x0010;
const DL_STATUS: usize = 0x0110;
const AL_CONTROL: usize = 0x0120;
const AL_STATUS: usize = 0x0130;
const AL_STATUS_CODE: usize = 0x0134;
const SII_CONTROL: usize = 0x0502;
const SII_ADDRESS: usize = 0x0504;
const SII_DATA: usize = 0x0508;
const FMMU0: usize = 0x0600;
const SM0: usize = 0x0800;

/// AL states (ETG.1000.6 §6.4.1).
pub const INIT: u8 = 1;
pub const PRE_OP: u8 = 2;
pub const SAFE_OP: u8 = 4;
pub const OP: u8 = 8;

/// AL status codes (ETG.1000.6 table 11).
const INVALID_STATE_CHANGE: u16 = 0x0011;
const UNKNOWN_STATE: u16 = 0x0012;
const INVALID_MAILBOX_CONFIG: u16 = 0x0016;
const INVALID_OUTPUT_CONFIG: u16 = 0x001D;
const INVALID_INPUT_CONFIG: u16 = 0x001E;

/// One emulated slave: an ESC with a CiA-402 drive behind it.
#[derive(Debug, Clone)]
pub struct Slave {
    mem: Vec<u8>,
    eeprom: Vec<u8>,
    pub identity: Identity,
    pub dictionary: Dictionary,
    pub servo: Servo,
    /// The read mailbox (SM1) holds a reply the master has not read.
    reply_waiting: bool,
    /// The process data layout fixed at SAFE-OP.
    outputs: Vec<Mapped>,
    inputs: Vec<Mapped>,
    /// Targets received in OPERATION ENABLED, in order (what the tests compare).
    pub targets: Vec<i32>,
    /// Process-data cycles run.
    pub cycles: u64,
}

impl Slave {
    pub fn new(identity: Identity, gain: f64) -> Slave {
        let mut s = Slave {
            mem: vec![0; MEMORY],
            eeprom: sii::image(&identity),
            identity,
            dictionary: Dictionary::new(&identity),
            servo: Servo::new(gain),
            reply_waiting: false,
            outputs: Vec::new(),
            inputs: Vec::new(),
            targets: Vec::new(),
            cycles: 0,
        };
        s.mem[0x0000] = 0x11; // ESC type
        s.mem[0x0004] = 4; // FMMUs
        s.mem[0x0005] = 4; // sync managers
        s.mem[0x0006] = 8; // process RAM, KiB
        s.mem[0x0007] = 0x0F; // ports 0 and 1: MII
        s.mem[AL_STATUS] = INIT;
        s.mem[SII_CONTROL] = 0x40; // EEPROM reads return 8 bytes
        s
    }

    /// Sets the link bits of the DL status (port 0 toward the master, port 1 onward).
    pub(super) fn set_links(&mut self, onward: bool) {
        // bit 0 PDI operational, bit 4 link on port 0, bit 5 link on port 1; a closed port
        // loops back (bit 10 for port 1).
        let v: u16 = 0x0011 | if onward { 0x0020 } else { 0x0400 };
        self.mem[DL_STATUS..DL_STATUS + 2].copy_from_slice(&v.to_le_bytes());
    }

    pub fn station_address(&self) -> u16 {
        self.u16_at(STATION_ADDRESS)
    }

    pub fn al_state(&self) -> u8 {
        self.mem[AL_STATUS] & 0x0F
    }

    fn u16_at(&self, a: usize) -> u16 {
        u16::from_le_bytes([self.mem[a], self.mem[a + 1]])
    }

    /// Sync manager `n`: (start, length, enabled).
    fn sm(&self, n: usize) -> (usize, usize, bool) {
        let b = SM0 + 8 * n;
        (
            self.u16_at(b) as usize,
            self.u16_at(b + 2) as usize,
            self.mem[b + 6] & 1 == 1,
        )
    }

    /// A physical read of `data.len()` bytes at `addr` (APRD, FPRD, BRD and the read half of
    /// the read-writes). `or`: broadcast reads OR into the datagram.
    pub(super) fn read(&mut self, addr: usize, data: &mut [u8], or: bool) {
        for (i, d) in data.iter_mut().enumerate() {
            let a = addr + i;
            let v = self.read_byte(a);
            *d = if or { *d | v } else { v };
        }
        // Reading the read mailbox's last byte hands it back to the slave.
        let (start, len, on) = self.sm(1);
        if on && len > 0 && addr < start + len && start + len - 1 < addr + data.len() {
            self.reply_waiting = false;
        }
    }

    fn read_byte(&self, a: usize) -> u8 {
        if (SM0..SM0 + 8 * 4).contains(&a) && (a - SM0) % 8 == 5 {
            // SM status: bit 3 "mailbox full" (ETG.1000.4 table 58)
            let n = (a - SM0) / 8;
            return if n == 1 && self.reply_waiting {
                0x08
            } else {
                0
            };
        }
        self.mem.get(a).copied().unwrap_or(0)
    }

    /// A physical write, then whatever the written registers set off.
    pub(super) fn write(&mut self, addr: usize, data: &[u8]) {
        let end = addr + data.len();
        for (i, d) in data.iter().enumerate() {
            let a = addr + i;
            // Read-only: identity, DL status, AL status and code.
            let ro = a < 0x0010
                || (DL_STATUS..DL_STATUS + 2).contains(&a)
                || (AL_STATUS..0x0136).contains(&a);
            if !ro && a < MEMORY {
                self.mem[a] = *d;
            }
        }
        let touches = |a: usize| addr <= a && a < end;
        if touches(AL_CONTROL) {
            self.al_request(self.mem[AL_CONTROL]);
        }
        if touches(SII_CONTROL + 1) && self.mem[SII_CONTROL + 1] & 0x01 != 0 {
            self.sii_read();
        }
        let (start, len, on) = self.sm(0);
        if on && len >= 16 && touches(start + len - 1) {
            self.mailbox();
        }
    }

    /// The EEPROM read command: 8 bytes from the word address into the data register.
    fn sii_read(&mut self) {
        let word = u32::from_le_bytes(
            self.mem[SII_ADDRESS..SII_ADDRESS + 4]
                .try_into()
                .unwrap_or_default(),
        ) as usize;
        for i in 0..8 {
            self.mem[SII_DATA + i] = self.eeprom.get(word * 2 + i).copied().unwrap_or(0xFF);
        }
        // done at once: command bits and busy cleared, 8-byte reads
        self.mem[SII_CONTROL] = 0x40;
        self.mem[SII_CONTROL + 1] = 0;
    }

    /// A mailbox request came in SM0: answer it into SM1.
    fn mailbox(&mut self) {
        let (rs, rl, _) = self.sm(0);
        let (ws, wl, won) = self.sm(1);
        if !won || wl < 16 || rs + rl > MEMORY || ws + wl > MEMORY {
            return;
        }
        let request = self.mem[rs..rs + rl].to_vec();
        let pre_op = self.al_state() == PRE_OP;
        let mut reply = vec![0u8; wl];
        if serve_mailbox(&mut self.dictionary, pre_op, &request, &mut reply).is_some() {
            self.mem[ws..ws + wl].copy_from_slice(&reply);
            self.reply_waiting = true;
        }
    }

    /// An AL control write: move to the requested state or refuse with a status code.
    fn al_request(&mut self, control: u8) {
        let want = control & 0x0F;
        let now = self.al_state();
        let ack = control & 0x10 != 0;
        let error = self.mem[AL_STATUS] & 0x10 != 0;
        if error && !ack && want != INIT {
            return; // an error must be acknowledged first
        }
        let result = match (now, want) {
            (_, INIT) => Ok(()),
            (INIT, PRE_OP) => self.check_mailbox(),
            (PRE_OP | SAFE_OP | OP, PRE_OP) => Ok(()),
            (PRE_OP, SAFE_OP) => self.fix_process_data(),
            (SAFE_OP | OP, SAFE_OP) => Ok(()),
            (SAFE_OP | OP, OP) => Ok(()),
            (_, PRE_OP | SAFE_OP | OP) => Err(INVALID_STATE_CHANGE),
            _ => Err(UNKNOWN_STATE),
        };
        match result {
            Ok(()) => {
                if now == OP
                    && want != OP
                    && self.servo.state == crate::cia402::State::OperationEnabled
                {
                    // Process data stop: the drive disables (no outputs, no motion).
                    self.servo.cycle(0, 0, false);
                }
                self.mem[AL_STATUS] = want;
                self.mem[AL_STATUS_CODE..AL_STATUS_CODE + 2].fill(0);
            }
            Err(code) => {
                self.mem[AL_STATUS] = now | 0x10;
                self.mem[AL_STATUS_CODE..AL_STATUS_CODE + 2].copy_from_slice(&code.to_le_bytes());
            }
        }
    }

    fn check_mailbox(&self) -> Result<(), u16> {
        let ok = |n: usize, start: u16| {
            let (s, l, on) = self.sm(n);
            on && s == start as usize && l == sii::MAILBOX_LEN as usize
        };
        if ok(0, sii::MAILBOX_OUT) && ok(1, sii::MAILBOX_IN) {
            Ok(())
        } else {
            Err(INVALID_MAILBOX_CONFIG)
        }
    }

    /// PRE-OP → SAFE-OP: the process data sync managers must match the PDO mapping.
    fn fix_process_data(&mut self) -> Result<(), u16> {
        let outputs = self.dictionary.mapping(od::SM2_ASSIGNMENT);
        let inputs = self.dictionary.mapping(od::SM3_ASSIGNMENT);
        let bytes = |m: &[Mapped]| m.iter().map(|m| m.bytes()).sum::<usize>();
        let (_, ol, oon) = self.sm(2);
        let (_, il, ion) = self.sm(3);
        if ol != bytes(&outputs) || (ol > 0 && !oon) {
            return Err(INVALID_OUTPUT_CONFIG);
        }
        if il != bytes(&inputs) || (il > 0 && !ion) {
            return Err(INVALID_INPUT_CONFIG);
        }
        self.outputs = outputs;
        self.inputs = inputs;
        self.refresh_inputs();
        Ok(())
    }

    /// A logical datagram (LRD 10, LWR 11, LRW 12) at logical address `la`: through each
    /// enabled FMMU; returns the working-counter increment (read 1, write 2, ETG.1000.4 §5.4).
    pub(super) fn logical(&mut self, cmd: u8, la: u32, data: &mut [u8]) -> u16 {
        let (mut read, mut wrote) = (false, false);
        for f in 0..4 {
            let b = FMMU0 + 16 * f;
            if self.mem[b + 12] & 1 == 0 {
                continue;
            }
            let ls = u32::from_le_bytes(self.mem[b..b + 4].try_into().unwrap_or_default());
            let len = self.u16_at(b + 4) as u32;
            let ps = self.u16_at(b + 8) as usize;
            let kind = self.mem[b + 11];
            let from = ls.max(la);
            let to = ls
                .saturating_add(len)
                .min(la.saturating_add(data.len() as u32));
            if from >= to {
                continue;
            }
            for l in from..to {
                let p = ps + (l - ls) as usize;
                let d = (l - la) as usize;
                if p >= MEMORY {
                    continue;
                }
                if kind & 0x02 != 0 && cmd != 10 {
                    self.mem[p] = data[d];
                    wrote = true;
                }
                if kind & 0x01 != 0 && cmd != 11 {
                    data[d] = self.mem[p];
                    read = true;
                }
            }
        }
        if wrote {
            self.process_data_cycle();
        }
        read as u16 + 2 * wrote as u16
    }

    /// The application's cycle when new outputs arrived: the drive runs on them and the
    /// inputs are refreshed for the next exchange.
    fn process_data_cycle(&mut self) {
        let (os, _, _) = self.sm(2);
        let mut at = os;
        for m in &self.outputs {
            let n = m.bytes().min(4);
            let Some(bytes) = self.mem.get(at..at + n) else {
                break;
            };
            let mut v = [0u8; 4];
            v[..n].copy_from_slice(bytes);
            self.dictionary.set(m.index, m.sub, u32::from_le_bytes(v));
            at += n;
        }
        let op = self.al_state() == OP;
        let cw = self.dictionary.get(od::CONTROLWORD, 0) as u16;
        let target = self.dictionary.get(od::TARGET_POSITION, 0) as i32;
        let enabled = self.servo.state == crate::cia402::State::OperationEnabled;
        self.servo.window = self.dictionary.get(od::FOLLOWING_ERROR_WINDOW, 0);
        let fb = self.servo.cycle(cw, target, op);
        if op && enabled {
            self.targets.push(target);
        }
        self.cycles += 1;
        self.dictionary.set(od::STATUSWORD, 0, fb.statusword as u32);
        self.dictionary
            .set(od::POSITION_ACTUAL, 0, fb.position as u32);
        self.dictionary
            .set(od::FOLLOWING_ERROR_ACTUAL, 0, fb.following_error as u32);
        self.dictionary.set(od::ERROR_CODE, 0, fb.error_code as u32);
        self.refresh_inputs();
    }

    fn refresh_inputs(&mut self) {
        let (is, _, _) = self.sm(3);
        let mut at = is;
        for m in &self.inputs {
            let n = m.bytes().min(4);
            let v = self.dictionary.get(m.index, m.sub).to_le_bytes();
            if at + n <= MEMORY {
                self.mem[at..at + n].copy_from_slice(&v[..n]);
            }
            at += n;
        }
    }
}
