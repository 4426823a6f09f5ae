//! The text of a drive's error code (object 0x603F): the emergency error codes of CiA 301
//! (v4.2, §7.2.7.1, table 21: the classes by high byte and nibble) with the drive-specific
//! codes of CiA 402-2 / IEC 61800-7-201 (annex: power stage, motor, sensors, controllers).
//! A code without its own entry is named by its class, and a manufacturer's code (0xFFxx)
//! says so, so the operator always reads the number and what kind of fault it is.

/// Codes with their own text: exact matches first.
const EXACT: &[(u16, &str)] = &[
    (0x0000, "no error"),
    (0x2310, "continuous overcurrent"),
    (0x2320, "short circuit or earth leakage"),
    (0x2330, "earth leakage"),
    (0x2340, "short circuit"),
    (0x3110, "mains overvoltage"),
    (0x3120, "mains undervoltage"),
    (0x3130, "mains phase failure"),
    (0x3210, "DC link overvoltage"),
    (0x3220, "DC link undervoltage"),
    (0x4210, "excess temperature of the device"),
    (0x4310, "excess temperature of the drive"),
    (0x5112, "supply voltage fault (24 V)"),
    (0x5441, "safe torque off active"),
    (0x6010, "software reset (watchdog)"),
    (0x6320, "parameter error"),
    (0x7121, "motor blocked"),
    (0x7122, "motor error or commutation malfunction"),
    (0x7305, "incremental sensor 1 fault"),
    (0x7306, "incremental sensor 2 fault"),
    (0x7310, "speed sensor fault"),
    (0x7320, "position sensor fault"),
    (0x8130, "life guard or heartbeat error"),
    (0x8210, "process data not processed: length error"),
    (0x8400, "velocity (speed) controller fault"),
    (0x8500, "position controller fault"),
    (0x8611, "following error"),
    (0x8612, "reference limit"),
];

/// Classes by high byte (0xXY00), then by high nibble (0xX000).
const CLASSES: &[(u16, u16, &str)] = &[
    (
        0xFF00,
        0xFF00,
        "manufacturer-specific error (see the drive's manual)",
    ),
    (0xFF00, 0x2100, "current on the device's input side"),
    (0xFF00, 0x2200, "current inside the device"),
    (0xFF00, 0x2300, "current on the device's output side"),
    (0xFF00, 0x3100, "mains voltage"),
    (0xFF00, 0x3200, "voltage inside the device"),
    (0xFF00, 0x3300, "output voltage"),
    (0xFF00, 0x4100, "ambient temperature"),
    (0xFF00, 0x4200, "device temperature"),
    (0xFF00, 0x4300, "drive temperature"),
    (0xFF00, 0x7100, "power stage or motor"),
    (0xFF00, 0x7300, "sensor"),
    (0xFF00, 0x8100, "communication"),
    (0xFF00, 0x8200, "protocol error"),
    (0xFF00, 0x8600, "positioning controller"),
    (0xF000, 0x1000, "generic error"),
    (0xF000, 0x2000, "current"),
    (0xF000, 0x3000, "voltage"),
    (0xF000, 0x4000, "temperature"),
    (0xF000, 0x5000, "device hardware"),
    (0xF000, 0x6000, "device software"),
    (0xF000, 0x7000, "additional modules"),
    (0xF000, 0x8000, "monitoring"),
    (0xF000, 0x9000, "external error"),
    (0xF000, 0xF000, "additional functions"),
];

/// The text for error code `code` (never empty).
pub fn text(code: u16) -> &'static str {
    if let Some((_, t)) = EXACT.iter().find(|(c, _)| *c == code) {
        return t;
    }
    CLASSES
        .iter()
        .find(|(mask, class, _)| code & mask == *class)
        .map(|(_, _, t)| *t)
        .unwrap_or("unknown error code")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_classes() {
        assert_eq!(text(0x8611), "following error");
        assert_eq!(text(0x3210), "DC link overvoltage");
        // no own entry: its class
        assert_eq!(text(0x2311), "current on the device's output side");
        assert_eq!(text(0x4999), "temperature");
        assert_eq!(
            text(0xFF42),
            "manufacturer-specific error (see the drive's manual)"
        );
        assert_eq!(text(0x0042), "unknown error code");
        for c in 0..=u16::MAX {
            assert!(!text(c).is_empty());
        }
    }

    #[test]
    fn exact_codes_are_listed_once_and_sorted() {
        assert!(EXACT.windows(2).all(|w| w[0].0 < w[1].0));
    }
}
