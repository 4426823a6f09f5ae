//! The exact check of one period of the time scale: with r̈ = c held over the period, the
//! re-timed path acceleration s̈ = ṙv + r²a and jerk s⃛ = r̈v + 3rṙa + r³j are bounded at
//! every instant of it, not only at samples. The scale ([`super::TimeScale`]) accepts a
//! period only if this check passes.
//!
//! Over t ∈ [0, Ts]: r(t) = r₀ + ṙ₀t + ct²/2 (a parabola: its range is its ends and vertex),
//! ṙ(t) = ṙ₀ + ct (its ends), τ(t) = τ₀ + ∫r ∈ [τ₀, τ₀ + Δτ] (r ≥ 0). Over that τ span the
//! plan's jerk is piecewise constant, its acceleration piecewise linear and its speed
//! piecewise quadratic, so their ranges are exact from the phase ends and the speed's
//! vertices. Interval arithmetic over these ranges (Moore, "Interval Analysis", 1966) then
//! contains every value s̈ and s⃛ take in the period; the bound is loose only by the
//! correlation it ignores, which is O(Ts) relative.

use tezgah_motion::{Limits, Profile, State};

use super::Plan;

/// A closed interval [lo, hi].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Span {
    pub lo: f64,
    pub hi: f64,
}

impl Span {
    pub fn point(x: f64) -> Span {
        Span { lo: x, hi: x }
    }

    fn include(&mut self, x: f64) {
        self.lo = self.lo.min(x);
        self.hi = self.hi.max(x);
    }

    fn add(self, o: Span) -> Span {
        Span {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }

    fn mul(self, o: Span) -> Span {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        Span {
            lo: p.iter().copied().fold(f64::INFINITY, f64::min),
            hi: p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    fn scale(self, k: f64) -> Span {
        self.mul(Span::point(k))
    }

    /// x³ is monotone.
    fn cube(self) -> Span {
        Span {
            lo: self.lo.powi(3),
            hi: self.hi.powi(3),
        }
    }

    fn within(self, bound: f64) -> bool {
        self.lo >= -bound && self.hi <= bound
    }
}

/// The plan's speed, acceleration and jerk over a span of path time, and the tightest path
/// limits in force there.
#[derive(Debug, Clone, Copy)]
pub(super) struct PlanRange {
    pub v: Span,
    pub a: Span,
    pub j: Span,
    pub max_velocity: f64,
    pub max_acceleration: f64,
    pub max_jerk: f64,
    /// The piece's limits above its planned speed, if it may run faster.
    pub fast: Option<Limits>,
    /// The span reaches a junction the plan passes moving: r must be ≤ 1 there (the
    /// junction's cap holds up to the planned speed only).
    pub junction: bool,
}

impl PlanRange {
    fn empty() -> PlanRange {
        let e = Span {
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        };
        PlanRange {
            v: e,
            a: e,
            j: e,
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            max_jerk: f64::INFINITY,
            fast: None,
            junction: false,
        }
    }

    fn limit(&mut self, l: &Limits) {
        self.max_velocity = self.max_velocity.min(l.max_velocity());
        self.max_acceleration = self.max_acceleration.min(l.max_acceleration());
        self.max_jerk = self.max_jerk.min(l.max_jerk());
    }

    fn state(&mut self, x: &State) {
        self.v.include(x.v);
        self.a.include(x.a);
    }

    /// The profile over its own time [t0, t1] (within its duration): phase by phase, with
    /// the speed's vertex (a = 0) where it falls inside a phase.
    fn profile(&mut self, p: &Profile, t0: f64, t1: f64) {
        let knots = p.knots();
        for k in 0..knots.len() - 1 {
            let (ts, x) = knots[k];
            let te = knots[k + 1].0;
            let (lo, hi) = (t0.max(ts), t1.min(te));
            if hi < lo || (te <= ts && !(t0 <= ts && ts <= t1)) {
                continue;
            }
            let at = |dt: f64| State {
                s: 0.0,
                v: x.v + dt * (x.a + 0.5 * dt * x.j),
                a: x.a + dt * x.j,
                j: x.j,
            };
            self.j.include(x.j);
            self.state(&at(lo - ts));
            self.state(&at(hi - ts));
            if x.j != 0.0 {
                let vertex = -x.a / x.j;
                if vertex > lo - ts && vertex < hi - ts {
                    self.state(&at(vertex));
                }
            }
        }
        if t1 >= p.duration() {
            // Past the end the motion continues at the end speed.
            self.state(&p.end());
            self.j.include(0.0);
        }
    }

    /// Past the pieces known: the end speed, acceleration 0 there, any jerk within the last
    /// limits (the next piece's limits may be lower; see `TimeScale::can_settle`).
    fn unknown(&mut self, end: &State, max_jerk: f64) {
        self.v.include(end.v);
        self.a.include(0.0);
        self.j.include(-max_jerk);
        self.j.include(max_jerk);
    }
}

impl Plan<'_> {
    /// The plan over path time [τ0, τ1], one range per piece it touches (the piece in hand,
    /// the next, past them), each with its own limits: a piece's jerk is checked against its
    /// own J, not the lower J of the piece after it.
    pub(super) fn ranges(&self, tau0: f64, tau1: f64) -> [Option<PlanRange>; 3] {
        let mut out = [None; 3];
        let d = self.current.profile.duration();
        let moving_junction = self.current.profile.end().v > 0.0;
        if tau0 <= d {
            let mut r = PlanRange::empty();
            r.limit(self.current.limits);
            r.profile(self.current.profile, tau0, tau1.min(d));
            r.fast = self.current.fast;
            r.junction = tau1 >= d && moving_junction;
            out[0] = Some(r);
        }
        if tau1 <= d {
            return out;
        }
        let last = match self.next {
            Some(n) => {
                let dn = n.profile.duration();
                let (t0, t1) = ((tau0 - d).max(0.0), tau1 - d);
                if t0 <= dn {
                    let mut r = PlanRange::empty();
                    r.limit(n.limits);
                    r.profile(n.profile, t0, t1.min(dn));
                    r.fast = n.fast;
                    r.junction = moving_junction;
                    out[1] = Some(r);
                }
                if t1 <= dn {
                    return out;
                }
                n
            }
            None => self.current,
        };
        let mut r = PlanRange::empty();
        r.limit(last.limits);
        r.unknown(&last.profile.end(), last.limits.max_jerk());
        out[2] = Some(r);
        out
    }
}

/// One period checked: where it leaves the scale, or why it was refused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Period {
    pub r: f64,
    pub rate: f64,
    pub dtau: f64,
}

/// The period from (r, ṙ) at τ with r̈ = `c` over `ts`, if r stays within [0, r_max], the
/// path speed within the plan's limit, and |s̈| ≤ A, |s⃛| ≤ J at every instant of it. Where
/// r exceeds 1 in the period the piece's overspeed limits apply, and no junction may lie in
/// it.
pub(super) fn check(plan: &Plan, r: f64, rd: f64, c: f64, tau: f64, ts: f64) -> Option<Period> {
    let motion = Motion { r, rd, c, tau };
    let rr = motion.r_range(0.0, ts);
    if rr.lo < -super::SLACK || rr.hi > plan.r_max + super::SLACK {
        return None;
    }
    motion.within(plan, 0.0, ts, SPLITS).then(|| Period {
        r: motion.r_at(ts).clamp(0.0, plan.r_max),
        rate: rd + c * ts,
        dtau: (motion.tau_at(ts) - tau).max(0.0),
    })
}

/// Halvings of a period the check may make where the bound over a whole span is too loose:
/// the interval product ignores that the plan's acceleration and r's rate take their extremes
/// at different instants (a ramp braking ṙ as the plan comes to rest read as 126 mm/s³ of
/// cross term where the true one is below 1). Sound at every depth; 4 gives spans of Ts/16.
const SPLITS: u32 = 4;

/// r over the period: r(t) = r₀ + ṙ₀t + ct²/2 from path time τ₀.
#[derive(Debug, Clone, Copy)]
struct Motion {
    r: f64,
    rd: f64,
    c: f64,
    tau: f64,
}

impl Motion {
    fn r_at(&self, t: f64) -> f64 {
        self.r + t * (self.rd + t * self.c / 2.0)
    }

    fn tau_at(&self, t: f64) -> f64 {
        self.tau + t * (self.r + t * (self.rd / 2.0 + t * self.c / 6.0))
    }

    /// r over [t0, t1]: its ends and the parabola's vertex if inside.
    fn r_range(&self, t0: f64, t1: f64) -> Span {
        let mut rr = Span::point(self.r_at(t0));
        rr.include(self.r_at(t1));
        if self.c != 0.0 {
            let vertex = -self.rd / self.c;
            if vertex > t0 && vertex < t1 {
                rr.include(self.r_at(vertex));
            }
        }
        rr
    }

    /// Whether ṡ ≤ V, |s̈| ≤ A and |s⃛| ≤ J hold over [t0, t1], halving the span up to
    /// `depth` times where the bound over it is too loose.
    fn within(&self, plan: &Plan, t0: f64, t1: f64, depth: u32) -> bool {
        let rr = self.r_range(t0, t1);
        let rr = Span {
            lo: rr.lo.max(0.0),
            hi: rr.hi,
        };
        let mut rdr = Span::point(self.rd + self.c * t0);
        rdr.include(self.rd + self.c * t1);
        let slack = 1.0 + super::SLACK;
        let rr2 = rr.mul(rr);
        let rr3 = rr.cube();
        let cross = rr.mul(rdr).scale(3.0);
        let (tau0, tau1) = (self.tau_at(t0), self.tau_at(t1));
        let ok = plan.ranges(tau0, tau1.max(tau0)).iter().flatten().all(|p| {
            let (v_max, a_max, j_max) = if rr.hi > 1.0 + super::SLACK {
                match p.fast {
                    Some(f) if !p.junction => (
                        f.max_velocity(),
                        f.max_acceleration().min(p.max_acceleration),
                        f.max_jerk().min(p.max_jerk),
                    ),
                    _ => return false,
                }
            } else {
                (p.max_velocity, p.max_acceleration, p.max_jerk)
            };
            let speed = rr.mul(p.v);
            let acc = rdr.mul(p.v).add(rr2.mul(p.a));
            let jerk = p.v.scale(self.c).add(cross.mul(p.a)).add(rr3.mul(p.j));
            speed.hi <= v_max * slack && acc.within(a_max * slack) && jerk.within(j_max * slack)
        });
        if ok {
            return true;
        }
        let tm = 0.5 * (t0 + t1);
        depth > 0 && self.within(plan, t0, tm, depth - 1) && self.within(plan, tm, t1, depth - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scale::PieceView;
    use proptest::prelude::*;
    use tezgah_motion::{solve, Limits};

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// The plan's ranges contain its state at many instants of the span, and the check's
        /// verdict holds at a fine sampling of the period (the bound is never optimistic).
        #[test]
        fn ranges_contain_the_plan(length in 0.5..50.0f64, v0 in 0.0..1.0f64, v1 in 0.0..1.0f64,
                                   tau0 in 0.0..1.0f64, span in 0.0..0.01f64,
                                   r in 0.0..1.0f64, rd in -5.0..5.0f64, c in -3e3..3e3f64) {
            let limits = Limits::new(100.0, 1000.0, 5e4).unwrap();
            let profile = solve(length, 100.0 * v0, 100.0 * v1, &limits);
            // Ends a length cannot join are not a plan.
            prop_assume!(profile.is_ok());
            let profile = profile.unwrap();
            let piece = PieceView { profile: &profile, limits: &limits, fast: None };
            let plan = Plan { current: piece, next: None, r_max: 1.0 };
            let d = profile.duration();
            let t0 = tau0 * d;
            let t1 = (t0 + span).min(d);
            let range = plan.ranges(t0, t1)[0].unwrap();
            for k in 0..=50 {
                let x = profile.state_at(t0 + (t1 - t0) * k as f64 / 50.0);
                prop_assert!(range.v.lo - 1e-9 <= x.v && x.v <= range.v.hi + 1e-9);
                prop_assert!(range.a.lo - 1e-9 <= x.a && x.a <= range.a.hi + 1e-9);
            }
            let ts = 0.001;
            if let Some(p) = check(&plan, r, rd, c, t0, ts) {
                for k in 0..=200 {
                    let t = ts * k as f64 / 200.0;
                    let rt = r + rd * t + c * t * t / 2.0;
                    let rdt = rd + c * t;
                    let tau = t0 + r * t + rd * t * t / 2.0 + c * t * t * t / 6.0;
                    let x = profile.state_at(tau);
                    let acc = rdt * x.v + rt * rt * x.a;
                    let jerk = c * x.v + 3.0 * rt * rdt * x.a + rt * rt * rt * x.j;
                    prop_assert!(acc.abs() <= 1000.0 * (1.0 + 1e-6), "a {acc}");
                    prop_assert!(jerk.abs() <= 5e4 * (1.0 + 1e-6), "j {jerk}");
                }
                prop_assert!((0.0..=1.0).contains(&p.r));
            }
        }
    }
}
