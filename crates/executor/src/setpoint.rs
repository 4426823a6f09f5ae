//! The set-point: what the executor hands the drives once per period (the 1 ms stream of
//! Kelekçi, 2021, §4.2). Position, velocity and acceleration per joint, so a drive can feed
//! forward; internal units (mm, rad), machine-file joint order. Fixed size: it crosses the
//! lock-free ring into the real-time thread, which never allocates.
//!
//! The velocity and acceleration a set-point carries are the state at its own instant of the
//! cubic through it and the three positions before it ([`History`]): the real-time side
//! starts an underrun stop from them, and a stop that starts from that state continues the
//! played positions twice differentiably, so their differences stay within the joint limits
//! from the first period of the stop (a backward difference, the state half a period earlier,
//! made the stop's first periods read up to 20 J on tight fast curves; notes, session 5).

use tezgah_kinematics::Joints;

/// One period's command to every joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetPoint {
    /// Period index k; the set-point is due at t = k·Ts.
    pub index: u64,
    /// 1-based source line of the block being executed (0 outside a program: jog, home).
    pub line: u32,
    pub position: Joints,
    pub velocity: Joints,
    pub acceleration: Joints,
}

impl SetPoint {
    /// At rest at `position`.
    pub fn at_rest(index: u64, line: u32, position: Joints) -> SetPoint {
        let zero = Joints::zeros(position.len());
        SetPoint {
            index,
            line,
            position,
            velocity: zero,
            acceleration: zero,
        }
    }
}

/// The last positions played, newest first: what a new set-point's velocity and acceleration
/// are derived from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct History {
    positions: [Joints; 3],
}

impl History {
    /// At rest at `position` (standing there for ever before).
    pub fn at_rest(position: Joints) -> History {
        History {
            positions: [position; 3],
        }
    }

    /// The newest position played.
    pub fn last(&self) -> Joints {
        self.positions[0]
    }

    /// The set-point at `position` one period of `period` s after the last one, with the
    /// velocity and acceleration at its instant of the cubic through the last four positions
    /// (backward differentiation formulas of third order:
    /// v = (11q₀ − 18q₋₁ + 9q₋₂ − 2q₋₃)/(6Ts), a = (2q₀ − 5q₋₁ + 4q₋₂ − q₋₃)/Ts²). Exact for
    /// motion that is cubic over those three periods, as a jerk-limited plan is between its
    /// switching instants; in every case the continuation from that state passes through the
    /// played positions, with the jerk of their third difference (see the module text).
    pub fn setpoint(&mut self, index: u64, line: u32, position: Joints, period: f64) -> SetPoint {
        let [q1, q2, q3] = self.positions;
        let mut velocity = position;
        let mut acceleration = position;
        for i in 0..position.len() {
            let (q0, q1, q2, q3) = (position[i], q1[i], q2[i], q3[i]);
            velocity[i] = (11.0 * q0 - 18.0 * q1 + 9.0 * q2 - 2.0 * q3) / (6.0 * period);
            acceleration[i] = (2.0 * q0 - 5.0 * q1 + 4.0 * q2 - q3) / (period * period);
        }
        self.positions = [position, q1, q2];
        SetPoint {
            index,
            line,
            position,
            velocity,
            acceleration,
        }
    }

    /// A set-point whose velocity and acceleration are known exactly (a manual motion's
    /// ramps), taken as it is; its position joins the history.
    pub fn exact(&mut self, setpoint: SetPoint) -> SetPoint {
        let [q1, q2, _] = self.positions;
        self.positions = [setpoint.position, q1, q2];
        setpoint
    }

    /// The set-point at rest at `position` (a stop that is exact: the real-time side must see
    /// the machine at rest to idle without calling it an underrun); the positions played stay
    /// the history.
    pub fn rest(&mut self, index: u64, line: u32, position: Joints) -> SetPoint {
        let [q1, q2, _] = self.positions;
        self.positions = [position, q1, q2];
        SetPoint::at_rest(index, line, position)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The formulas are exact on cubics: q = c₀ + c₁t + c₂t² + c₃t³ sampled at the period.
    #[test]
    fn exact_on_cubics() {
        let ts = 1e-3;
        let c = [3.0, -20.0, 700.0, -9000.0];
        let q = |t: f64| c[0] + t * (c[1] + t * (c[2] + t * c[3]));
        let j = |x: f64| Joints::from_slice(&[x]).unwrap();
        let mut h = History::at_rest(j(q(-3.0 * ts)));
        for k in -2..=5 {
            let t = k as f64 * ts;
            let sp = h.setpoint(0, 0, j(q(t)), ts);
            if k >= 1 {
                let v = c[1] + t * (2.0 * c[2] + 3.0 * t * c[3]);
                let a = 2.0 * c[2] + 6.0 * t * c[3];
                assert!((sp.velocity[0] - v).abs() < 1e-7 * v.abs().max(1.0), "{k}");
                assert!(
                    (sp.acceleration[0] - a).abs() < 1e-5 * a.abs().max(1.0),
                    "{k}"
                );
            }
        }
    }
}
