//! Re-timing: the path-time scale r = dτ/dt between wall time t and the planned profile's
//! time τ. Feed override sets the target r, feed hold drives it to 0, resume back; the path
//! itself never changes (re-timed, not re-shaped).
//!
//! With the plan at τ giving speed v, acceleration a and jerk j along the path, the re-timed
//! motion has ṡ = r·v, s̈ = ṙ·v + r²·a and s⃛ = r̈·v + 3r·ṙ·a + r³·j (chain rule). With
//! 0 ≤ r ≤ 1 the speed stays within the plan's; each period r̈ is held constant and chosen so
//! that |s̈| ≤ A and |s⃛| ≤ J of each piece's path limits hold at every instant of the period
//! (the exact check of `period`) — which keeps every joint within its limits, since the
//! planner derived the path limits for any speed up to the piece's V. The candidates come from
//! the linear bound at five instants (`Plan::period_range`); the exact check then accepts or
//! refuses them (`Plan::fit` pulls a refused one toward the middle of that range). Above
//! 100 % override r may exceed 1 on pieces whose overspeed limits allow it
//! ([`crate::overspeed`]; `PieceView::fast`), never across a junction the plan passes moving.
//!
//! Why a look-ahead on r: the plan itself may use the whole jerk (r³j = J at r = 1), and then
//! no r̈ can brake ṙ; a ramp that runs into such a stretch with ṙ ≠ 0 cannot stop in time and
//! would overshoot r = 0 or 1 (an acceleration step). Holding r constant is always admissible
//! (s̈ = r²a, s⃛ = r³j), so a state is kept only if from it ṙ can be braked to 0 within the
//! limits against the plan's actual states ahead (`TimeScale::can_settle`; above 1, brought
//! back down to 1 first). Each period takes the most direct of a few candidate r̈ (the
//! square-root approach to the target, blended toward the settling law) that passes that test.

use tezgah_motion::{Limits, Profile, State};

mod period;

/// Share of the path limits for the ramp's own rate and acceleration bounds (A/v, J/v); the
/// checks against the plan's terms use the full limits either way. Half was tried first: holds
/// then took 1.4× the time-optimal distance from cruise; the whole share reaches it (1.00×)
/// with no more jerk (the checks, not this share, keep the limits).
const RAMP_SHARE: f64 = 1.0;

/// Largest change of r in one period.
const MAX_SWING: f64 = 0.1;

/// Slack on the limit checks for rounding.
const SLACK: f64 = 1e-9;

/// Shares of the way from a wanted r̈ to the sampled range's middle tried in turn (see
/// `Plan::fit`).
const PULL: [f64; 5] = [0.0, 0.02, 0.1, 0.3, 1.0];

/// Share of a piece's speed limit below which its end speed is rest (rounding of the profile's
/// integration leaves ~1e-16 mm/s where it stops).
const REST: f64 = 1e-9;

/// Periods the settling test looks ahead at most.
const HORIZON: usize = 4000;

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
    /// Whether the period passed the exact check (|s̈| ≤ A, |s⃛| ≤ J at every instant of it);
    /// false only when no admissible r̈ was found and the scale braked regardless.
    pub checked: bool,
}

/// One planned piece as the scale sees it: its profile and path limits.
#[derive(Clone, Copy)]
pub struct PieceView<'a> {
    pub profile: &'a Profile,
    pub limits: &'a Limits,
    /// The limits above the planned speed, if the piece may run faster than planned
    /// ([`crate::overspeed`]); `None` keeps r ≤ 1 on it.
    pub fast: Option<Limits>,
}

/// Where τ falls: the plan's state there and the limits in force, or past what is known.
struct At<'a> {
    state: State,
    limits: &'a Limits,
    /// Past the pieces known: the end state, jerk unknown.
    unknown: bool,
}

/// The plan along the piece in hand and the next one if it is planned already; past them the
/// end state with the jerk unknown (a ramp must settle before it gets there, see
/// [`TimeScale::can_settle`]).
struct Plan<'a> {
    current: PieceView<'a>,
    next: Option<PieceView<'a>>,
    /// Largest r allowed (1, or the override's target where the pieces allow more).
    r_max: f64,
}

impl<'a> Plan<'a> {
    fn at(&self, tau: f64) -> At<'a> {
        let d = self.current.profile.duration();
        if tau <= d {
            return At {
                state: self.current.profile.state_at(tau),
                limits: self.current.limits,
                unknown: false,
            };
        }
        if let Some(n) = self.next {
            if tau - d <= n.profile.duration() {
                return At {
                    state: n.profile.state_at(tau - d),
                    limits: n.limits,
                    unknown: false,
                };
            }
        }
        let last = self.next.unwrap_or(self.current);
        let mut e = last.profile.end();
        e.a = 0.0;
        e.j = 0.0;
        At {
            state: e,
            limits: last.limits,
            unknown: true,
        }
    }

    /// The r̈ interval over one period from τ that keeps |s⃛| ≤ J at five instants of it (the
    /// plan's jerk may switch inside the period, and r, ṙ move): at a fraction f of the
    /// period, r ≈ r₀ + ṙ₀fTs and ṙ = ṙ₀ + r̈fTs, so s⃛ = r̈(v + 3r·fTs·a) + 3rṙ₀a + r³j is
    /// linear in r̈. This only proposes: the exact check ([`period::check`]) decides.
    fn period_range(&self, r: f64, rd: f64, tau: f64, ts: f64) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for f in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let rf = (r + rd * f * ts).clamp(0.0, self.r_max);
            let at = self.at(tau + f * rf * ts);
            let (st, j_max) = (at.state, at.limits.max_jerk());
            let c = st.v + 3.0 * rf * f * ts * st.a;
            if c <= 0.0 {
                continue;
            }
            let cross = 3.0 * rf * rd * st.a;
            let (l, h) = if at.unknown {
                let room = j_max * (1.0 - rf * rf * rf) - cross.abs();
                (-room / c, room / c)
            } else {
                let rest = cross + rf * rf * rf * st.j;
                ((-j_max - rest) / c, (j_max - rest) / c)
            };
            lo = lo.max(l);
            hi = hi.min(h);
        }
        // Whatever the bounds allow, r̈ never swings r by more than MAX_SWING in a period:
        // the checks above sample the period and assume r moves little within it.
        let swing = MAX_SWING / (ts * ts);
        (lo.max(-swing), hi.min(swing))
    }
}

impl Plan<'_> {
    /// The period with r̈ nearest `want` that passes the exact check: `want`, or `want`
    /// within the sampled range, else pulled toward the range's middle (the exact bound is a
    /// little stricter than the samples near the range's ends).
    fn fit(
        &self,
        r: f64,
        rd: f64,
        want: f64,
        (lo, hi): (f64, f64),
        tau: f64,
        ts: f64,
    ) -> Option<period::Period> {
        // The wanted r̈ itself first: the sampled range has no rounding slack and may leave
        // out what the exact check accepts (r = 1 + 1e-10 against a plan at full jerk).
        if !(lo..=hi).contains(&want) {
            if let Some(p) = period::check(self, r, rd, want, tau, ts) {
                return Some(p);
            }
        }
        let c = want.clamp(lo, hi);
        let mid = 0.5 * (lo + hi);
        PULL.iter().find_map(|&k| {
            let rdd = c + k * (mid - c);
            period::check(self, r, rd, rdd, tau, ts)
        })
    }
}

fn integrate(r: f64, rd: f64, rdd: f64, ts: f64) -> (f64, f64, f64) {
    (
        r + rd * ts + rdd * ts * ts / 2.0,
        rd + rdd * ts,
        r * ts + rd * ts * ts / 2.0 + rdd * ts * ts * ts / 6.0,
    )
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

    /// The r̈ the settling test plays from (r, ṙ) at τ (a function of the state alone, so
    /// the test's first period is always a candidate of the next step): brake ṙ to 0 at
    /// r ≤ 1; above 1 (override past 100 %) the square-root approach down to r = 1.
    fn settle_rdd(plan: &Plan, r: f64, rd: f64, tau: f64, ts: f64) -> f64 {
        if r <= 1.0 + SLACK {
            return -rd / ts;
        }
        let at = plan.at(tau);
        let v = at.state.v.max(1e-9);
        let (rd_max, rdd_max) = ramp_bounds(at.limits, v, ts);
        approach(1.0 - r, rd, rd_max, rdd_max, ts).clamp(-rdd_max, rdd_max)
    }

    /// Whether from (r, ṙ) at τ the scale can settle — ṙ braked to 0 with r ≤ 1, where
    /// holding r constant is admissible (s̈ = r²a, s⃛ = r³j) — within the limits against
    /// the plan ahead ([`TimeScale::settle_rdd`] played period by period, each passing the
    /// exact check).
    fn can_settle(plan: &Plan, mut r: f64, mut rd: f64, mut tau: f64, ts: f64) -> bool {
        for _ in 0..HORIZON {
            if rd == 0.0 && r <= 1.0 + SLACK {
                return true;
            }
            let at = plan.at(tau);
            if at.state.v <= 0.0 {
                return true;
            }
            if at.unknown {
                // The limits past the pieces known may be far lower: a ramp must have settled
                // by then, unless the plan stops there (its end speed is zero but for
                // rounding: a hold that ended just short of the program's end resumes).
                return at.state.v <= REST * at.limits.max_velocity();
            }
            let (lo, hi) = plan.period_range(r, rd, tau, ts);
            if lo > hi {
                return false;
            }
            let want = Self::settle_rdd(plan, r, rd, tau, ts);
            let Some(p) = plan.fit(r, rd, want, (lo, hi), tau, ts) else {
                return false;
            };
            // A braking step of r̈ = −ṙ/Ts lands on ṙ = 0 but for rounding; one pulled
            // further (see `Plan::fit`) swings ṙ past 0, and that swing must settle too.
            r = snap_to_one(p.r);
            rd = if p.rate.abs() <= 1e-12 * rd.abs().max(1.0) {
                0.0
            } else {
                p.rate
            };
            tau += p.dtau;
        }
        false
    }

    /// Advances one period `ts` toward `target` (≥ 0; above 1 only as far as the pieces'
    /// overspeed limits allow) at path time `tau` of the piece in hand (`next`: the following
    /// piece, if planned already).
    pub fn step(
        &mut self,
        target: f64,
        current: PieceView,
        next: Option<PieceView>,
        tau: f64,
        ts: f64,
    ) -> Advance {
        let limits = current.limits;
        // Above the planned speed no faster than the overspeed limit allows on the piece's
        // fastest stretch (r·v ≤ V_fast wherever v ≤ V).
        let cap = current
            .fast
            .map_or(1.0, |f| f.max_velocity() / limits.max_velocity())
            .max(1.0);
        let target = target.clamp(0.0, cap);
        // The bound on r depends on the pieces only, not on the target: a settling test passed
        // under one bound must still pass next period whatever the override did meanwhile.
        let plan = Plan {
            current,
            next,
            r_max: cap.max(self.r),
        };
        let st = plan.at(tau).state;
        let v = st.v.max(0.0);
        if v == 0.0 && st.a == 0.0 {
            // The plan is at rest here: r may jump (ṡ = s̈ = 0 whatever r is; s⃛ = r³j ≤ J
            // for r ≤ 1; above 1 the ramp starts from there).
            self.r = target.min(1.0);
            self.rate = 0.0;
            return Advance {
                dtau: self.r * ts,
                checked: true,
            };
        }
        let (r, rd) = (self.r, self.rate);
        let (rd_max, rdd_max) = ramp_bounds(limits, v.max(1e-9), ts);
        // Speeding the ramp up uses its share; slowing it down may use whatever the full
        // limits leave (the range below), so a ramp never overshoots for want of braking.
        let want_rate = rd + approach(target - r, rd, rd_max, rdd_max, ts) * ts;
        let mut direct = (want_rate - rd) / ts;
        if direct * rd >= 0.0 || want_rate * rd < 0.0 {
            direct = direct.clamp(-rdd_max, rdd_max);
        }
        let (lo, hi) = plan.period_range(r, rd, tau, ts);
        let (lo, hi) = (lo.min(hi), hi.max(lo));
        // Unclamped: `fit` tries it as it is first, exactly as the settling test does, so the
        // last candidate is the test's first period.
        let settle = Self::settle_rdd(&plan, r, rd, tau, ts);
        let mut chosen = None;
        for lambda in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let rdd = direct * (1.0 - lambda) + settle * lambda;
            if let Some(p) = plan.fit(r, rd, rdd, (lo, hi), tau, ts) {
                if Self::can_settle(&plan, p.r, p.rate, tau + p.dtau, ts) {
                    chosen = Some(p);
                    break;
                }
            }
        }
        let checked = chosen.is_some();
        let p = chosen.unwrap_or_else(|| {
            // Nothing passes (the state before was not settled-checked, e.g. a ramp the
            // plan's next piece surprised): settle as hard as the sampled bounds allow.
            let (r1, rate, dtau) = integrate(r, rd, settle.clamp(lo, hi), ts);
            period::Period { r: r1, rate, dtau }
        });
        let (mut r1, mut rd1) = (p.r, p.rate);
        if (target - r1).abs() < 1e-9 && rd1.abs() < 1e-3 {
            // Arrived (the approach lands with ṙ ≈ √(2r̈·1e-9): no step worth the name).
            r1 = target;
            rd1 = 0.0;
        }
        let r1 = snap_to_one(r1);
        self.r = r1.clamp(0.0, plan.r_max);
        self.rate = if self.r == r1 { rd1 } else { 0.0 };
        Advance {
            dtau: p.dtau.max(0.0),
            checked,
        }
    }
}

/// Back from above 1 to within rounding of it: exactly 1, where holding r is admissible
/// whatever the plan does (just above, a plan at full jerk leaves no room to brake ṙ). The
/// step and the settling test both apply it, so the test plays what the step will do.
fn snap_to_one(r: f64) -> f64 {
    if r > 1.0 && r - 1.0 < SLACK {
        1.0
    } else {
        r
    }
}

/// The ramp's own bounds on ṙ and r̈ at plan speed v: its share of A/v and J/v, and at low
/// speed at most a few percent of r per period (the plan's state is only sampled there).
fn ramp_bounds(limits: &Limits, v: f64, ts: f64) -> (f64, f64) {
    (
        (RAMP_SHARE * limits.max_acceleration() / v).min(MAX_SWING / ts),
        (RAMP_SHARE * limits.max_jerk() / v).min(MAX_SWING / (4.0 * ts * ts)),
    )
}

/// Discrete-time square-root approach: the rate toward an error `e` from which braking at
/// r̈_max in whole periods ends exactly on it, ṙ = r̈Ts·(√(¼ + 2|e|/(r̈Ts²)) − ½), at most
/// `rd_max`.
fn approach_rate(e: f64, rd_max: f64, rdd_max: f64, ts: f64) -> f64 {
    let step = rdd_max * ts;
    let brake_rate = step * ((0.25 + 2.0 * e.abs() / (step * ts)).sqrt() - 0.5);
    e.signum() * brake_rate.min(rd_max)
}

/// The r̈ that takes ṙ to the square-root approach's rate toward error `e` in one period,
/// the rate being the one for the error left at the period's end: with r̈ = (ṙ₁ − ṙ₀)/Ts
/// the period moves r by (ṙ₀ + ṙ₁)·Ts/2, so ṙ₁ = rate(e − (ṙ₀ + ṙ₁)·Ts/2), solved by a few
/// fixed-point steps. (Aiming at the rate for the error at the period's start brakes a
/// period late: a ramp to 150 % overshot to 152.4 %.)
fn approach(e: f64, rd: f64, rd_max: f64, rdd_max: f64, ts: f64) -> f64 {
    let mut rate = approach_rate(e, rd_max, rdd_max, ts);
    for _ in 0..4 {
        rate = approach_rate(e - (rd + rate) * ts / 2.0, rd_max, rdd_max, ts);
    }
    (rate - rd) / ts
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use tezgah_motion::solve;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// On a cruise at the speed limit, targets switching at random periods: r stays in
        /// [0, 1], reaches each target, and the re-timed path keeps A and J (third
        /// differences at the period, as a drive sees them).
        #[test]
        fn ramps_keep_the_limits(v in 1.0..300.0f64, a in 100.0..5000.0f64, j in 1e3..1e6f64,
                                 targets in proptest::collection::vec((0.0..=1.0f64, 1usize..400), 1..6)) {
            let limits = Limits::new(v, a, j).unwrap();
            let ts = 0.001;
            let length = v * 10.0;
            let profile = solve(length, v, v, &limits).unwrap();
            let piece = PieceView { profile: &profile, limits: &limits, fast: None };
            let mut scale = TimeScale::default();
            let mut tau = 0.0;
            let mut s = vec![0.0];
            for &(target, periods) in &targets {
                for _ in 0..periods {
                    let adv = scale.step(target, piece, None, tau, ts);
                    prop_assert!(adv.checked);
                    tau += adv.dtau;
                    prop_assert!((0.0..=1.0).contains(&scale.r));
                    s.push(profile.state_at(tau).s);
                }
            }
            // Near a target held long enough (the stop from full speed takes at most
            // v/A + A/J + the discrete tail). Short of r = 0 or 1 the discrete approach may
            // circle a target by its smallest move, a period at r̈_max (r̈_max·Ts², r̈_max =
            // min(J/v, MAX_SWING/4Ts²)): a speed ripple of that share, within the limits
            // checked below. (A proportional end zone removed the circling but cost jerk
            // elsewhere — 1.06 J on a random hold — and was left out.)
            let (last, periods) = *targets.last().unwrap();
            let resolution = (j / v).min(MAX_SWING / (4.0 * ts * ts)) * ts * ts;
            if (periods as f64) * ts > 2.0 * (v / a + a / j) + 0.02 {
                prop_assert!((scale.r - last).abs() <= resolution + 1e-9,
                    "r {} target {last} resolution {resolution}", scale.r);
            }
            for w in s.windows(4) {
                let acc = (w[3] - 2.0 * w[2] + w[1]) / (ts * ts);
                let jerk = (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / (ts * ts * ts);
                prop_assert!(acc.abs() <= a * 1.005 + 1e-6, "a {acc} of {a}");
                prop_assert!(jerk.abs() <= j * 1.005, "j {jerk} of {j}");
            }
        }

        /// A piece planned below its overspeed limit (cruise at v, V_fast = k·v), targets up to
        /// 2.5 switching at random periods, the piece ending in a junction passed moving: the
        /// speed stays within V_fast, A and J hold by third differences, and r is back to 1 or
        /// below before the piece ends.
        #[test]
        fn above_one_within_the_overspeed_limits(v in 1.0..100.0f64, k in 1.0..3.0f64,
                                                 a in 100.0..5000.0f64, j in 1e3..1e6f64,
                                                 targets in proptest::collection::vec((0.0..=2.5f64, 1usize..400), 1..6)) {
            let limits = Limits::new(v, a, j).unwrap();
            let fast = Limits::new(k * v, a, j).unwrap();
            let ts = 0.001;
            let profile = solve(v * 2.0, v, v, &limits).unwrap();
            let piece = PieceView { profile: &profile, limits: &limits, fast: Some(fast) };
            let mut scale = TimeScale::default();
            let mut tau = 0.0;
            let mut s = vec![0.0];
            'run: for &(target, periods) in &targets {
                for _ in 0..periods {
                    let adv = scale.step(target, piece, None, tau, ts);
                    prop_assert!(adv.checked);
                    tau += adv.dtau;
                    if tau >= profile.duration() {
                        prop_assert!(scale.r <= 1.0, "r {} at the junction", scale.r);
                        break 'run;
                    }
                    s.push(profile.state_at(tau).s);
                }
            }
            for w in s.windows(4) {
                let speed = (w[3] - w[2]) / ts;
                let acc = (w[3] - 2.0 * w[2] + w[1]) / (ts * ts);
                let jerk = (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / (ts * ts * ts);
                prop_assert!(speed <= k * v * (1.0 + 1e-9), "v {speed} of {}", k * v);
                prop_assert!(acc.abs() <= a * 1.005 + 1e-6, "a {acc} of {a}");
                prop_assert!(jerk.abs() <= j * 1.005, "j {jerk} of {j}");
            }
        }
    }
}
