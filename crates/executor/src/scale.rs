//! Re-timing: the path-time scale r = dτ/dt between wall time t and the planned profile's
//! time τ. Feed override sets the target r, feed hold drives it to 0, resume back; the path
//! itself never changes (re-timed, not re-shaped), and r moves along a ramp whose rate and
//! acceleration are chosen each period so the re-timed motion keeps the segment's limits.
//!
//! With the plan at τ giving speed v, acceleration a and jerk j along the path, the re-timed
//! path moves at ṡ = r·v, s̈ = ṙ·v + r²·a and s⃛ = r̈·v + 3r·ṙ·a + r³·j (chain rule). With
//! r ≤ 1 the speed stays within the plan's; |s̈| ≤ A bounds ṙ to
//! [(−A − r²a)/v, (A − r²a)/v] and |s⃛| ≤ J bounds r̈ to [(−J − 3rṙa − r³j)/v, (J − …)/v].
//! Within those bounds r follows a square-root approach to its target (the time-optimal
//! second-order approach: ṙ = ±√(2·r̈_max·|e|)). Where the plan brakes at its limit
//! (a = −A at r = 1) no faster slowing is possible and r waits: the hold then never stops
//! later than the plan itself would.

use tezgah_motion::{Limits, State};

/// A share of each path limit the re-timed motion may use; the rest absorbs the
/// discretisation of r̈ per period.
const LIMIT_SHARE: f64 = 0.97;

/// The time scale and its rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeScale {
    pub r: f64,
    pub rate: f64,
}

impl Default for TimeScale {
    fn default() -> Self {
        TimeScale { r: 1.0, rate: 0.0 }
    }
}

/// One period of the scale: how far τ moved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Advance {
    /// Path time advanced, s of planned time.
    pub dtau: f64,
}

impl TimeScale {
    /// At rest (r = 0), as after a hold.
    pub fn held() -> TimeScale {
        TimeScale { r: 0.0, rate: 0.0 }
    }

    /// Whether r is 0 and stays there.
    pub fn is_stopped(&self) -> bool {
        self.r == 0.0 && self.rate == 0.0
    }

    /// Advances one period `ts` toward `target` (0 ≤ target ≤ 1) given the plan's state at
    /// the current τ and the path limits in force.
    pub fn step(&mut self, target: f64, plan: &State, limits: &Limits, ts: f64) -> Advance {
        let target = target.clamp(0.0, 1.0);
        let (r, rd) = (self.r, self.rate);
        let v = plan.v.max(0.0);
        let a_max = LIMIT_SHARE * limits.max_acceleration();
        let j_max = LIMIT_SHARE * limits.max_jerk();
        // At (near) rest r may change freely: nothing moves whatever r does. Otherwise the
        // ramp's own bounds are those a speed v allows.
        let v_ref = v.max(1e-9);
        let rdd_max = j_max / v_ref;
        let rd_max = a_max / v_ref;
        let e = target - r;
        // Square-root approach: the rate from which r̈_max stops exactly at the target.
        let want = e.signum() * (2.0 * rdd_max * e.abs()).sqrt().min(rd_max);
        let mut rdd = ((want - rd) / ts).clamp(-rdd_max, rdd_max);
        if v > 0.0 {
            // |ṙv + r²a| ≤ A on the rate reached at the period's end.
            let (lo, hi) = ((-a_max - r * r * plan.a) / v, (a_max - r * r * plan.a) / v);
            rdd = rdd.clamp(((lo - rd) / ts).min(0.0), ((hi - rd) / ts).max(0.0));
            // |r̈v + 3rṙa + r³j| ≤ J.
            let rest = 3.0 * r * rd * plan.a + r * r * r * plan.j;
            let (lo, hi) = ((-j_max - rest) / v, (j_max - rest) / v);
            if lo <= hi {
                rdd = rdd.clamp(lo, hi);
            }
        }
        let mut r1 = r + rd * ts + rdd * ts * ts / 2.0;
        let mut rd1 = rd + rdd * ts;
        let mut dtau = r * ts + rd * ts * ts / 2.0 + rdd * ts * ts * ts / 6.0;
        // Arrival: crossing (or touching) the target ends the ramp there. The rate left is
        // ≤ √(2·r̈·|e|) → small, and nothing moves at r = 0.
        if (r - target) * (r1 - target) <= 0.0 && (rd1.abs() <= rdd_max * ts || v == 0.0) {
            r1 = target;
            rd1 = 0.0;
        }
        if r1 < 0.0 {
            r1 = 0.0;
            rd1 = 0.0;
        }
        if r1 > 1.0 {
            r1 = 1.0;
            rd1 = 0.0;
        }
        dtau = dtau.max(0.0);
        self.r = r1;
        self.rate = rd1;
        Advance { dtau }
    }
}
