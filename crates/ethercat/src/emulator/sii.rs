//! The emulated drive's SII EEPROM image (ETG.2010, 2018: the slave information interface):
//! the fixed words a master reads first (identity at word 0x08, the standard mailbox at 0x18)
//! and the categories after word 0x40 (strings, general, FMMU usage, sync managers). The
//! master reads it through the ESC's EEPROM registers (`super::esc`).

/// Where the ESC's process RAM puts the mailboxes and the process data (byte addresses).
pub const MAILBOX_OUT: u16 = 0x1000;
pub const MAILBOX_IN: u16 = 0x1080;
pub const MAILBOX_LEN: u16 = 128;
pub const OUTPUTS_AT: u16 = 0x1100;
pub const INPUTS_AT: u16 = 0x1180;

/// Who the emulated drive says it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Identity {
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision: u32,
    pub serial: u32,
}

/// The name in the EEPROM's strings (the master shows it).
pub const NAME: &str = "tezgah emulated CiA-402 drive";

/// Category types (ETG.2010 table 3).
const STRINGS: u16 = 10;
const GENERAL: u16 = 30;
const FMMU: u16 = 40;
const SYNC_MANAGER: u16 = 41;
const END: u16 = 0xFFFF;

/// Sync manager usage types in the SyncManager category (ETG.2010 table 9).
const SM_MAILBOX_OUT: u8 = 1;
const SM_MAILBOX_IN: u8 = 2;
const SM_OUTPUTS: u8 = 3;
const SM_INPUTS: u8 = 4;

/// The EEPROM's bytes.
pub fn image(id: &Identity) -> Vec<u8> {
    let mut w = vec![0u8; 0x40 * 2];
    let put32 = |w: &mut Vec<u8>, word: usize, v: u32| {
        w[word * 2..word * 2 + 4].copy_from_slice(&v.to_le_bytes())
    };
    let put16 = |w: &mut Vec<u8>, word: usize, v: u16| {
        w[word * 2..word * 2 + 2].copy_from_slice(&v.to_le_bytes())
    };
    put32(&mut w, 0x08, id.vendor_id);
    put32(&mut w, 0x0A, id.product_code);
    put32(&mut w, 0x0C, id.revision);
    put32(&mut w, 0x0E, id.serial);
    // Standard mailbox: receive (master → slave) offset and size, send offset and size,
    // protocols (bit 2: CoE).
    put16(&mut w, 0x18, MAILBOX_OUT);
    put16(&mut w, 0x19, MAILBOX_LEN);
    put16(&mut w, 0x1A, MAILBOX_IN);
    put16(&mut w, 0x1B, MAILBOX_LEN);
    put16(&mut w, 0x1C, 0x0004);
    // EEPROM size: (kbit − 1); version 1.
    put16(&mut w, 0x3E, 0x000F);
    put16(&mut w, 0x3F, 0x0001);

    let mut strings = vec![1u8, NAME.len() as u8];
    strings.extend_from_slice(NAME.as_bytes());
    category(&mut w, STRINGS, &strings);

    let mut general = [0u8; 32];
    general[2] = 1; // order (device name) string
    general[3] = 1; // name string
    general[5] = 0x0D; // CoE: SDO, PDO assignment, PDO configuration
    category(&mut w, GENERAL, &general);

    // FMMU 0 outputs, 1 inputs, 2 mailbox status, 3 unused.
    category(&mut w, FMMU, &[1, 2, 3, 0]);

    let mut sms = Vec::new();
    for (start, len, control, kind) in [
        (MAILBOX_OUT, MAILBOX_LEN, 0x26u8, SM_MAILBOX_OUT),
        (MAILBOX_IN, MAILBOX_LEN, 0x22, SM_MAILBOX_IN),
        (OUTPUTS_AT, 0, 0x64, SM_OUTPUTS),
        (INPUTS_AT, 0, 0x20, SM_INPUTS),
    ] {
        sms.extend_from_slice(&start.to_le_bytes());
        sms.extend_from_slice(&len.to_le_bytes());
        sms.extend_from_slice(&[control, 0, 0x01, kind]);
    }
    category(&mut w, SYNC_MANAGER, &sms);
    w.extend_from_slice(&END.to_le_bytes());
    w.extend_from_slice(&[0, 0]);
    w
}

/// Appends a category: type, length in words, data padded to whole words.
fn category(w: &mut Vec<u8>, kind: u16, data: &[u8]) {
    let words = data.len().div_ceil(2);
    w.extend_from_slice(&kind.to_le_bytes());
    w.extend_from_slice(&(words as u16).to_le_bytes());
    w.extend_from_slice(data);
    if data.len() % 2 == 1 {
        w.push(0);
    }
}
