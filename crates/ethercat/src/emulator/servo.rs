//! The emulated drive's application: the CiA-402 state machine on the device side (CiA 402-2,
//! 2021, figure 5: transitions 2–16 from the controlword, fault reset on the rising edge of
//! bit 7) and a motor that follows the target position in cyclic synchronous position mode.
//!
//! The motor is a first-order lag per cycle: x ← x + g·(target − x), g in (0, 1]. With g = 1
//! the drive is where it was told (a perfect position loop); with g < 1 a ramp of v counts per
//! cycle lags by e = v·(1 − g)/g in steady state (from e = (1 − g)(e + v)), a closed form the
//! tests check. Each cycle runs when the process data arrive, so the position it reports is
//! the one after the previous cycle's target: the one-cycle delay of a real CSP drive.

use crate::cia402::{status, Command, State};

/// One emulated drive's application state.
#[derive(Debug, Clone)]
pub struct Servo {
    pub state: State,
    /// Position, counts (fractional inside the motor model).
    pub actual: f64,
    /// The last fault's code (0x603F).
    pub error_code: u16,
    /// Motor gain g per cycle.
    pub gain: f64,
    last_controlword: u16,
    /// A fault to raise at the next cycle (test injection).
    pending_fault: Option<u16>,
    /// |following error| over this (counts) faults with 0x8611 (0x6065; u32::MAX: never).
    pub window: u32,
    pub following_error: i32,
}

/// What a cycle returns: the objects of the inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Feedback {
    pub statusword: u16,
    pub position: i32,
    pub following_error: i32,
    pub error_code: u16,
}

impl Servo {
    pub fn new(gain: f64) -> Servo {
        Servo {
            // Transitions 0 and 1 happen on power-up by themselves.
            state: State::SwitchOnDisabled,
            actual: 0.0,
            error_code: 0,
            gain: gain.clamp(1e-6, 1.0),
            last_controlword: 0,
            pending_fault: None,
            window: u32::MAX,
            following_error: 0,
        }
    }

    /// Raises a fault with `code` at the next cycle (transition 13).
    pub fn inject_fault(&mut self, code: u16) {
        self.pending_fault = Some(code);
    }

    /// Takes the outputs (`op`: the EtherCAT state machine is in OP, so outputs count);
    /// returns the inputs.
    pub fn cycle(&mut self, controlword: u16, target: i32, op: bool) -> Feedback {
        let cw = if op { controlword } else { 0 };
        let reset_edge = cw & 0x80 != 0 && self.last_controlword & 0x80 == 0;
        self.last_controlword = cw;
        let cmd = Command::from_controlword(cw);
        use State::*;
        self.state = match (self.state, cmd) {
            (FaultReactionActive, _) => Fault, // 14: the reaction (a stop) is immediate here
            (Fault, _) if reset_edge => {
                self.error_code = 0;
                SwitchOnDisabled // 15
            }
            (Fault, _) => Fault,
            (SwitchOnDisabled, Command::Shutdown) => ReadyToSwitchOn, // 2
            (ReadyToSwitchOn, Command::SwitchOn) => SwitchedOn,       // 3
            (ReadyToSwitchOn, Command::SwitchOnEnable) => OperationEnabled, // 3 + 4
            (ReadyToSwitchOn, Command::DisableVoltage | Command::QuickStop) => SwitchOnDisabled, // 7
            (SwitchedOn, Command::SwitchOnEnable) => OperationEnabled, // 4
            (SwitchedOn, Command::Shutdown) => ReadyToSwitchOn,        // 6
            (SwitchedOn, Command::DisableVoltage | Command::QuickStop) => SwitchOnDisabled, // 10
            (OperationEnabled, Command::SwitchOn) => SwitchedOn,       // 5
            (OperationEnabled, Command::Shutdown) => ReadyToSwitchOn,  // 8
            (OperationEnabled, Command::DisableVoltage) => SwitchOnDisabled, // 9
            (OperationEnabled, Command::QuickStop) => QuickStopActive, // 11
            // 12: quick stop option code 2 (CiA 402-2 §6.5.4): stopped, then disabled.
            (QuickStopActive, Command::DisableVoltage) => SwitchOnDisabled,
            (QuickStopActive, _) => SwitchOnDisabled,
            (s, _) => s,
        };
        if self.state == OperationEnabled {
            self.actual += self.gain * (target as f64 - self.actual);
            self.following_error = (target as f64 - self.actual).round() as i32;
            if self.window != u32::MAX && self.following_error.unsigned_abs() > self.window {
                self.pending_fault.get_or_insert(0x8611);
            }
        } else {
            self.following_error = 0;
        }
        if let Some(code) = self.pending_fault.take() {
            self.error_code = code;
            self.state = FaultReactionActive; // 13
        }
        let mut sw = self.state.statusword_bits() | status::REMOTE;
        if matches!(
            self.state,
            ReadyToSwitchOn | SwitchedOn | OperationEnabled | QuickStopActive
        ) {
            sw |= status::VOLTAGE_ENABLED;
        }
        if self.state == OperationEnabled {
            sw |= status::CSP_FOLLOWING_TARGET;
        }
        Feedback {
            statusword: sw,
            position: self.actual.round() as i32,
            following_error: self.following_error,
            error_code: self.error_code,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cia402::{command, toward_enabled};

    #[test]
    fn the_master_walk_enables_in_three_cycles() {
        let mut s = Servo::new(1.0);
        let mut sw = s.cycle(0, 0, true).statusword;
        let mut n = 0;
        while State::from_statusword(sw) != State::OperationEnabled {
            sw = s
                .cycle(
                    toward_enabled(State::from_statusword(sw), n % 2 == 0),
                    0,
                    true,
                )
                .statusword;
            n += 1;
            assert!(n < 10);
        }
        assert_eq!(n, 3);
        assert_eq!(
            sw & status::CSP_FOLLOWING_TARGET,
            status::CSP_FOLLOWING_TARGET
        );
    }

    #[test]
    fn a_lagging_motor_has_the_closed_form_error() {
        let (g, v) = (0.25, 40.0);
        let mut s = Servo::new(g);
        s.state = State::OperationEnabled;
        let mut fb = s.cycle(command::ENABLE_OPERATION, 0, true);
        for k in 1..200 {
            fb = s.cycle(command::ENABLE_OPERATION, (v * k as f64) as i32, true);
        }
        assert_eq!(fb.following_error, (v * (1.0 - g) / g) as i32);
    }

    #[test]
    fn a_fault_needs_a_reset_edge() {
        let mut s = Servo::new(1.0);
        s.state = State::OperationEnabled;
        s.inject_fault(0x7121);
        let fb = s.cycle(command::ENABLE_OPERATION, 0, true);
        assert_eq!(
            State::from_statusword(fb.statusword),
            State::FaultReactionActive
        );
        assert_eq!(fb.error_code, 0x7121);
        let fb = s.cycle(command::FAULT_RESET, 0, true);
        // the edge came while reacting: still a fault
        assert_eq!(State::from_statusword(fb.statusword), State::Fault);
        let fb = s.cycle(command::FAULT_RESET, 0, true);
        assert_eq!(State::from_statusword(fb.statusword), State::Fault);
        s.cycle(0, 0, true);
        let fb = s.cycle(command::FAULT_RESET, 0, true);
        assert_eq!(
            State::from_statusword(fb.statusword),
            State::SwitchOnDisabled
        );
        assert_eq!(fb.error_code, 0);
    }
}
