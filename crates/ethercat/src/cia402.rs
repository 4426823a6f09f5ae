//! The CiA-402 drive state machine as the master sees it (IEC 61800-7-201 / CiA 402-2, 2021,
//! §5.1 "device control", figure 5 and tables 30–31): the state read from the statusword
//! (0x6041), and the controlword (0x6040) that moves a drive one transition toward
//! *operation enabled*, resets a fault or stops it quickly. The master's enable walk and the
//! cyclic exchange (`crate::master`) use it; the emulated drive implements the other side.

use std::fmt;

/// The drive's state (CiA 402-2 figure 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

/// Statusword bits (CiA 402-2 table 30).
pub mod status {
    pub const READY_TO_SWITCH_ON: u16 = 1 << 0;
    pub const SWITCHED_ON: u16 = 1 << 1;
    pub const OPERATION_ENABLED: u16 = 1 << 2;
    pub const FAULT: u16 = 1 << 3;
    pub const VOLTAGE_ENABLED: u16 = 1 << 4;
    /// Active low: 0 while a quick stop is in progress.
    pub const QUICK_STOP: u16 = 1 << 5;
    pub const SWITCH_ON_DISABLED: u16 = 1 << 6;
    pub const WARNING: u16 = 1 << 7;
    pub const REMOTE: u16 = 1 << 9;
    /// In cyclic synchronous position mode: the drive follows the target (CiA 402-2 §11.4.1).
    pub const CSP_FOLLOWING_TARGET: u16 = 1 << 12;
    /// In cyclic synchronous position mode: following error (CiA 402-2 §11.4.1).
    pub const CSP_FOLLOWING_ERROR: u16 = 1 << 13;
}

impl State {
    /// Decodes the statusword: the six state bits 0–3, 5, 6 under the masks of table 30.
    pub fn from_statusword(sw: u16) -> State {
        if sw & 0x004F == 0x0000 {
            State::NotReadyToSwitchOn
        } else if sw & 0x004F == 0x0040 {
            State::SwitchOnDisabled
        } else if sw & 0x006F == 0x0021 {
            State::ReadyToSwitchOn
        } else if sw & 0x006F == 0x0023 {
            State::SwitchedOn
        } else if sw & 0x006F == 0x0027 {
            State::OperationEnabled
        } else if sw & 0x006F == 0x0007 {
            State::QuickStopActive
        } else if sw & 0x004F == 0x000F {
            State::FaultReactionActive
        } else if sw & 0x004F == 0x0008 {
            State::Fault
        } else {
            // Patterns table 30 leaves undefined: treat as not ready, the safe reading.
            State::NotReadyToSwitchOn
        }
    }

    /// The statusword's state bits for this state (what a drive reports; bit 5, quick stop,
    /// is set outside a quick stop as table 30 shows).
    pub fn statusword_bits(self) -> u16 {
        match self {
            State::NotReadyToSwitchOn => 0x0000,
            State::SwitchOnDisabled => 0x0040,
            State::ReadyToSwitchOn => 0x0021,
            State::SwitchedOn => 0x0023,
            State::OperationEnabled => 0x0027,
            State::QuickStopActive => 0x0007,
            State::FaultReactionActive => 0x000F,
            State::Fault => 0x0008,
        }
    }

    pub fn is_fault(self) -> bool {
        matches!(self, State::Fault | State::FaultReactionActive)
    }

    /// The name CiA 402 gives it.
    pub fn name(self) -> &'static str {
        match self {
            State::NotReadyToSwitchOn => "not ready to switch on",
            State::SwitchOnDisabled => "switch on disabled",
            State::ReadyToSwitchOn => "ready to switch on",
            State::SwitchedOn => "switched on",
            State::OperationEnabled => "operation enabled",
            State::QuickStopActive => "quick stop active",
            State::FaultReactionActive => "fault reaction active",
            State::Fault => "fault",
        }
    }
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Controlword commands (CiA 402-2 table 31): bits 0 switch on, 1 enable voltage, 2 quick
/// stop (active low), 3 enable operation, 7 fault reset (acts on its rising edge).
pub mod command {
    pub const SHUTDOWN: u16 = 0x0006;
    pub const SWITCH_ON: u16 = 0x0007;
    pub const DISABLE_VOLTAGE: u16 = 0x0000;
    pub const QUICK_STOP: u16 = 0x0002;
    pub const DISABLE_OPERATION: u16 = 0x0007;
    pub const ENABLE_OPERATION: u16 = 0x000F;
    pub const FAULT_RESET: u16 = 0x0080;
}

/// The command a drive decodes from a controlword (the device side of table 31; the emulated
/// drive uses it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    Shutdown,
    SwitchOn,
    /// Switch on and enable operation at once (transition 3 then 4).
    SwitchOnEnable,
    DisableVoltage,
    QuickStop,
    DisableOperation,
    EnableOperation,
}

impl Command {
    /// Decodes bits 0–3 (bit 7, fault reset, is an edge the drive watches separately).
    pub fn from_controlword(cw: u16) -> Command {
        // Table 31, in its order of precedence: disable voltage (bit 1 = 0) over quick stop
        // (bit 2 = 0) over the rest.
        if cw & 0x0002 == 0 {
            Command::DisableVoltage
        } else if cw & 0x0004 == 0 {
            Command::QuickStop
        } else if cw & 0x0001 == 0 {
            Command::Shutdown
        } else if cw & 0x0008 == 0 {
            // switch on and disable operation share a pattern
            Command::SwitchOn
        } else {
            Command::SwitchOnEnable
        }
    }
}

/// The controlword that takes a drive in `state` one transition toward operation enabled.
///
/// A fault is reset by a rising edge of bit 7: `toggle` alternates between calls (pass the
/// cycle count's parity) so that a drive still in fault sees a new edge every other cycle.
/// States the drive leaves on its own (not ready, fault reaction) get no command.
pub fn toward_enabled(state: State, toggle: bool) -> u16 {
    match state {
        State::NotReadyToSwitchOn | State::FaultReactionActive => command::DISABLE_VOLTAGE,
        State::SwitchOnDisabled => command::SHUTDOWN,
        State::ReadyToSwitchOn => command::SWITCH_ON,
        State::SwitchedOn | State::OperationEnabled => command::ENABLE_OPERATION,
        // Transition 12: quick stop active → switch on disabled, then up again.
        State::QuickStopActive => command::DISABLE_VOLTAGE,
        State::Fault if toggle => command::FAULT_RESET,
        State::Fault => command::DISABLE_VOLTAGE,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [State; 8] = [
        State::NotReadyToSwitchOn,
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::OperationEnabled,
        State::QuickStopActive,
        State::FaultReactionActive,
        State::Fault,
    ];

    #[test]
    fn every_state_reads_back_from_its_bits() {
        for s in ALL {
            assert_eq!(State::from_statusword(s.statusword_bits()), s, "{s}");
            // the other bits (voltage, warning, remote, mode-specific) do not change the state
            let noisy = s.statusword_bits() | 0xFF90;
            assert_eq!(State::from_statusword(noisy), s, "{s} with {noisy:#06x}");
        }
    }

    #[test]
    fn statuswords_from_drive_manuals() {
        // Typical values read from drives: 0x0250 switch on disabled (remote, voltage),
        // 0x0231 ready, 0x0233 switched on, 0x1237 operation enabled in CSP, 0x0218 fault.
        assert_eq!(State::from_statusword(0x0250), State::SwitchOnDisabled);
        assert_eq!(State::from_statusword(0x0231), State::ReadyToSwitchOn);
        assert_eq!(State::from_statusword(0x0233), State::SwitchedOn);
        assert_eq!(State::from_statusword(0x1237), State::OperationEnabled);
        assert_eq!(State::from_statusword(0x0218), State::Fault);
        assert_eq!(State::from_statusword(0x0217), State::QuickStopActive);
    }

    #[test]
    fn the_walk_commands_decode_to_their_transitions() {
        use Command as C;
        let t = |s| C::from_controlword(toward_enabled(s, false));
        assert_eq!(t(State::SwitchOnDisabled), C::Shutdown); // transition 2
        assert_eq!(t(State::ReadyToSwitchOn), C::SwitchOn); // 3
        assert_eq!(t(State::SwitchedOn), C::SwitchOnEnable); // 4
        assert_eq!(t(State::QuickStopActive), C::DisableVoltage); // 12
        assert_eq!(C::from_controlword(command::QUICK_STOP), C::QuickStop); // 11
        assert_eq!(C::from_controlword(command::DISABLE_OPERATION), C::SwitchOn); // 5
        assert_eq!(toward_enabled(State::Fault, true), command::FAULT_RESET);
        assert_eq!(toward_enabled(State::Fault, false) & 0x80, 0);
    }
}
