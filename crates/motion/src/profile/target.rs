//! The position interface from any state: the time-optimal motion from (v0, a0) over a signed
//! distance L to end speed v1 at zero acceleration, under |v| ≤ V, |a| ≤ A, |j| ≤ J — Ruckig's
//! one-axis step 1 (Berscheid & Kröger, RSS 2021: the time-optimal profiles of one DoF, jerk
//! pattern UDDU, and their case analysis by reached limits). The motion
//! may run backward where that is faster (as Ruckig's does); a path asks [`super::solve`].
//!
//! A start outside the limits is braked first ([`super::brake`]). A UDDU profile then has
//! jerk ±J, 0, ∓J, 0, ∓J, 0, ±J; the middle two jerk phases merge when there is no cruise.
//! Where the acceleration crosses 0 inside them it is a velocity-interface change to a peak
//! speed vp ([`Change`]), a cruise at vp, and a change from vp to v1: each half bang-bang, so
//! vp alone fixes the shape, its distance is D(vp), and a cruise can only be at ±V (anywhere
//! else a higher peak is faster). The duration grows as vp leaves the speeds v_r (where a0
//! runs out at full jerk, v0 + a0|a0|/2J) and v1, so:
//! * upper side, vp ≥ max(v_r, v1) (jerk +J first): the lowest vp with D(vp) = L, else cruise
//!   at V when D(V) < L;
//! * lower side, vp ≤ min(v_r, v1) (jerk −J first): the mirror image;
//! * relaxed: where the acceleration does not reach 0 in the middle — a0 is relaxed toward 0
//!   for τ ∈ [0, |a0|/J], then the change to v1 turns the other way. This exists only when v1
//!   lies beyond v_r on the side a0 points to, and it joins the two sides' ends (τ = 0 is the
//!   direct change to v1, τ = |a0|/J the peak at v_r); every root counts.
//!
//! The fastest candidate wins, as in Ruckig's enumeration of profile types.
//!
//! D has no convenient closed-form inverse once a0 ≠ 0 (Ruckig solves quartics per case); it is
//! continuous and piecewise smooth in u = √|vp − side's base| (√τ), so the roots are bracketed on a
//! fine grid in u, local extrema between grid points checked by golden section (a near-double
//! root cannot hide between two samples), and refined by Brent's method to the last bits.

use tezgah_geom::deviation::golden;

use super::brake;
use super::error::ProfileError;
use super::knots::advance;
use super::roots::brent;
use super::solve::solve;
use super::velocity::{check_start, Change};
use super::{Limits, Profile, State};

/// Grid intervals per side: D is a piecewise polynomial of low degree in u, with few extrema.
const GRID: usize = 48;

/// The time-optimal profile from `start` over `distance` (signed, mm) to speed `v1` at zero
/// acceleration (see the module comment); `start.s` is where it starts, and it ends at
/// `start.s + distance`. With a0 = 0, 0 ≤ v0, v1 ≤ V and a forward optimum it is exactly
/// [`solve`]'s profile (the closed forms), so the look-ahead planner and this agree.
///
/// # Errors
/// [`ProfileError::Start`] for a start state that is not finite, [`ProfileError::Target`] for
/// an end speed that is not finite or beyond ±V, [`ProfileError::TargetDistance`] for a
/// distance that is not finite.
pub fn solve_from(
    start: State,
    distance: f64,
    v1: f64,
    limits: &Limits,
) -> Result<Profile, ProfileError> {
    check_start(&start)?;
    if !distance.is_finite() {
        return Err(ProfileError::TargetDistance(distance));
    }
    if !v1.is_finite() || v1.abs() > limits.max_velocity() {
        return Err(ProfileError::Target(v1));
    }
    let v_max = limits.max_velocity();
    if start.a == 0.0 && (0.0..=v_max).contains(&start.v) && v1 >= 0.0 && distance >= 0.0 {
        if let Ok(p) = solve(distance, start.v, v1, limits) {
            return Ok(Profile::from_phases(start, p.durations(), p.jerks()).ending_at(v1, 0.0));
        }
    }
    Ok(general(start, distance, v1, limits))
}

/// The brake and the candidate families (module comment), for valid input.
fn general(start: State, distance: f64, v1: f64, limits: &Limits) -> Profile {
    let v_max = limits.max_velocity();
    let brake = brake::position(start.v, start.a, limits);
    let x = brake::apply(start, &brake);
    let rest = distance - (x.s - start.s);
    let a_max = limits.max_acceleration();
    let problem = Problem {
        v0: x.v,
        a0: x.a.clamp(-a_max, a_max),
        v1,
        distance: rest,
        limits,
    };
    let best = [1.0, -1.0]
        .into_iter()
        .filter_map(|sign| {
            problem
                .mirrored(sign)
                .outer_side()
                .map(|c| c.mirrored(sign))
        })
        .chain(problem.relaxed())
        .min_by(|a, b| a.duration.total_cmp(&b.duration));
    // The outer sides together cover every distance (the cruise at ±V reaches any L), so a
    // candidate exists; rounding aside, the upper side's cruise is the fallback.
    let c = best.unwrap_or_else(|| problem.cruise_at(v_max));
    let durations = c.phases.map(|p| p.0);
    let jerks = c.phases.map(|p| p.1);
    Profile::braked(start, brake, durations, jerks, Some(c.peak)).ending_at(v1, 0.0)
}

/// The problem after the brake (a start within the limits), possibly mirrored.
#[derive(Clone, Copy)]
struct Problem<'a> {
    v0: f64,
    a0: f64,
    v1: f64,
    distance: f64,
    limits: &'a Limits,
}

/// One profile of the families: its seven (duration, jerk) phases, duration, and the speed
/// where the acceleration is 0 between its halves (the cruise speed if it cruises).
#[derive(Debug, Clone, Copy)]
struct Candidate {
    phases: [(f64, f64); 7],
    duration: f64,
    peak: f64,
}

impl Candidate {
    /// The phases of a change to a peak speed, a cruise, and a change to the end speed.
    fn peaked(first: &Change, peak: f64, cruise: f64, second: &Change) -> Candidate {
        let mut phases = [(0.0, 0.0); 7];
        phases[..3].copy_from_slice(&first.phases());
        phases[3] = (cruise, 0.0);
        phases[4..].copy_from_slice(&second.phases());
        Candidate {
            phases,
            duration: first.duration() + cruise + second.duration(),
            peak,
        }
    }

    /// The candidate of the mirror image (`sign` = −1 flips every jerk).
    fn mirrored(self, sign: f64) -> Candidate {
        Candidate {
            phases: self.phases.map(|(d, j)| (d, sign * j)),
            peak: sign * self.peak,
            ..self
        }
    }

    /// D − L: where the phases end from `start`, against the distance.
    /// As the profile integrates it: the cruise at exactly zero acceleration and the peak.
    fn excess(&self, start: State, distance: f64) -> f64 {
        let mut x = start;
        for (k, &(dt, jk)) in self.phases.iter().enumerate() {
            if k == 3 && dt > 0.0 {
                x.a = 0.0;
                x.v = self.peak;
            }
            x = advance(x, jk, dt);
        }
        x.s - distance
    }
}

impl Problem<'_> {
    /// The same problem with speeds, acceleration and distance multiplied by `sign` (±1).
    fn mirrored(&self, sign: f64) -> Self {
        Problem {
            v0: sign * self.v0,
            a0: sign * self.a0,
            v1: sign * self.v1,
            distance: sign * self.distance,
            ..*self
        }
    }

    fn start(&self) -> State {
        State {
            s: 0.0,
            v: self.v0,
            a: self.a0,
            j: 0.0,
        }
    }

    /// The speed at which the start acceleration runs out at full jerk.
    fn released(&self) -> f64 {
        self.v0 + self.a0 * self.a0.abs() / (2.0 * self.limits.max_jerk())
    }

    /// Through peak speed `peak` with a cruise there of `cruise` s.
    fn through(&self, peak: f64, cruise: f64) -> Candidate {
        let first = Change::new(self.v0, self.a0, peak, self.limits);
        let second = Change::new(peak, 0.0, self.v1, self.limits);
        Candidate::peaked(&first, peak, cruise, &second)
    }

    /// Peak `v` (±V) with the rest of the distance as cruise.
    fn cruise_at(&self, v: f64) -> Candidate {
        let g = self.through(v, 0.0).excess(self.start(), self.distance);
        self.through(v, (-g / v).max(0.0))
    }

    /// The upper side (module comment): the lowest root above max(v_r, v1), else cruise at V.
    fn outer_side(&self) -> Option<Candidate> {
        let v_max = self.limits.max_velocity();
        let base = self.released().max(self.v1).min(v_max);
        let g = |peak: f64| self.through(peak, 0.0).excess(self.start(), self.distance);
        let mut first = None;
        scan(g, base, v_max, |peak| {
            first = Some(peak);
            false
        });
        match first {
            Some(peak) => Some(self.through(peak, 0.0)),
            None if g(v_max) < 0.0 => Some(self.cruise_at(v_max)),
            None => None,
        }
    }

    /// The start acceleration relaxed toward 0 for τ, then the change to v1 turning the other
    /// way: the profiles whose acceleration never reaches 0 in the middle (module comment).
    fn relax(&self, tau: f64) -> Candidate {
        let jerk = -self.a0.signum() * self.limits.max_jerk();
        let x = advance(self.start(), jerk, tau);
        let change = Change::new(x.v, x.a, self.v1, self.limits);
        let none = Change::new(0.0, 0.0, 0.0, self.limits);
        let mut c = Candidate::peaked(&none, 0.0, 0.0, &change);
        c.phases[0] = (tau, jerk);
        c.duration += tau;
        c
    }

    /// The fastest relaxed profile that covers the distance, if the family exists: only when
    /// the change to v1 turns against a0 (v1 beyond v_r on the side a0 points to).
    fn relaxed(&self) -> Option<Candidate> {
        if self.a0 == 0.0 || (self.v1 - self.released()) * self.a0 <= 0.0 {
            return None;
        }
        let end = self.a0.abs() / self.limits.max_jerk();
        let mut best: Option<Candidate> = None;
        scan(
            |tau| self.relax(tau).excess(self.start(), self.distance),
            0.0,
            end,
            |tau| {
                let c = self.relax(tau);
                if best.is_none_or(|b| c.duration < b.duration) {
                    best = Some(c);
                }
                true
            },
        );
        best
    }
}

/// Calls `found` with each root of `g` on [lo, hi] from `lo` upward while it returns true
/// (grid in u = √(vp − lo), extrema by golden section, roots by Brent; see the module
/// comment).
fn scan(g: impl Fn(f64) -> f64, lo: f64, hi: f64, mut found: impl FnMut(f64) -> bool) {
    let span = (hi - lo).max(0.0);
    let at = |u: f64| lo + (u * u).min(span);
    let h = |u: f64| g(at(u));
    let top = span.sqrt();
    let us: [f64; GRID + 1] = std::array::from_fn(|k| top * k as f64 / GRID as f64);
    let hs: [f64; GRID + 1] = std::array::from_fn(|k| h(us[k]));
    if hs[0] == 0.0 && !found(lo) {
        return;
    }
    for k in 1..=GRID {
        let (ua, ub, ha, hb) = (us[k - 1], us[k], hs[k - 1], hs[k]);
        if ha != 0.0 && ha * hb <= 0.0 {
            if !found(at(brent(h, ua, ub, ha, hb))) {
                return;
            }
            continue;
        }
        // No sign change across this interval: a pair of roots may sit around an extremum of
        // g toward 0, between this sample and the next.
        if k < GRID && hb.abs() < ha.abs() && hb.abs() <= hs[k + 1].abs() && hb * hs[k + 1] > 0.0 {
            let s = hb.signum();
            // The extremum toward 0: the maximum of −s·g, shrunk to rounding (0.618⁸⁰).
            let m = golden(|u| -s * h(u), ua, us[k + 1], 80);
            let (um, hm) = (m.u, -m.distance);
            if hm <= 0.0 {
                let hm = s * hm;
                let left = if ha * hm <= 0.0 && hm != 0.0 {
                    brent(h, ua, um, ha, hm)
                } else {
                    um
                };
                if !found(at(left)) {
                    return;
                }
                let right_h = hs[k + 1];
                if hm != 0.0
                    && hm * right_h < 0.0
                    && !found(at(brent(h, um, us[k + 1], hm, right_h)))
                {
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::velocity::tests::at;
    use proptest::prelude::*;

    /// Ends on the target (s, v; a = 0 by the last phase's own integration), |j| ≤ J, and
    /// after the brake |a| ≤ A and |v| ≤ V — or, where the brake leaves the speed beyond V
    /// (an acceleration that cannot run out sooner), never further out than there.
    fn check(p: &Profile, distance: f64, v1: f64, l: &Limits) -> Result<(), String> {
        let (v_max, a_max, j_max) = (l.max_velocity(), l.max_acceleration(), l.max_jerk());
        let knots = p.knots();
        let scale = distance.abs() + v_max * p.duration() + p.start().v.abs() * p.duration();
        if (p.end().s - p.start().s - distance).abs() > 1e-9 * scale.max(1e-3) {
            return Err(format!("ends at {} for {distance}", p.end().s));
        }
        let (tl, xl) = knots[knots.len() - 2];
        let t = p.duration() - tl;
        let v = xl.v + t * (xl.a + 0.5 * t * xl.j);
        let a = xl.a + t * xl.j;
        let speeds = v_max + p.start().v.abs() + a_max * p.duration();
        if (v - v1).abs() > 1e-9 * speeds || a.abs() > 1e-9 * (a_max + p.start().a.abs()) {
            return Err(format!("ends at v {v}, a {a}"));
        }
        let braked: f64 = p.brake().iter().map(|b| b.0).sum();
        let v_cap = v_max.max(p.state_at(braked).v.abs()) * (1.0 + 1e-9);
        for w in knots.windows(2) {
            let ((t0, x), (t1, _)) = (w[0], w[1]);
            if x.j.abs() > j_max {
                return Err(format!("jerk {}", x.j));
            }
            if t0 < braked {
                continue;
            }
            let tau = if x.j != 0.0 { -x.a / x.j } else { -1.0 };
            let inside = tau > 0.0 && tau < t1 - t0;
            let peak = x.v - 0.5 * x.a * x.a / x.j;
            if x.a.abs() > a_max * (1.0 + 1e-9)
                || x.v.abs() > v_cap
                || (inside && peak.abs() > v_cap)
            {
                return Err(format!("beyond the limits at {t0}: {x:?}"));
            }
        }
        Ok(())
    }

    #[test]
    fn from_zero_acceleration_it_is_solve_exactly() {
        let l = Limits::new(50.0, 1000.0, 20000.0).unwrap();
        for (d, v0, v1) in [(1.0, 0.0, 0.0), (2.0, 40.0, 10.0), (30.0, 50.0, 50.0)] {
            let p = solve_from(at(v0, 0.0), d, v1, &l).unwrap();
            let q = solve(d, v0, v1, &l).unwrap();
            assert_eq!((p.durations(), p.jerks()), (q.durations(), q.jerks()));
        }
        // A stop from 40 mm/s takes 2√(40/J) = 0.089 s over 40·√(40/J) = 1.79 mm (A²/J = 50
        // is not reached): in 0.5 mm it cannot, and the path's solver says so; the general
        // one goes past and comes back.
        assert!(solve(0.5, 40.0, 0.0, &l).is_err());
        let p = solve_from(at(40.0, 0.0), 0.5, 0.0, &l).unwrap();
        assert!(p.knots().iter().any(|k| k.1.v < 0.0));
        check(&p, 0.5, 0.0, &l).unwrap();
    }

    #[test]
    fn bad_input_is_a_named_error() {
        let l = Limits::new(50.0, 1000.0, 20000.0).unwrap();
        assert!(matches!(
            solve_from(at(f64::NAN, 0.0), 1.0, 0.0, &l),
            Err(ProfileError::Start { .. })
        ));
        assert_eq!(
            solve_from(at(0.0, 0.0), f64::INFINITY, 0.0, &l).unwrap_err(),
            ProfileError::TargetDistance(f64::INFINITY)
        );
        assert_eq!(
            solve_from(at(0.0, 0.0), 1.0, 60.0, &l).unwrap_err(),
            ProfileError::Target(60.0)
        );
    }

    proptest! {
        /// From any start (within the limits or up to twice beyond), to any distance and end
        /// speed: on target, within the limits.
        #[test]
        fn reaches_the_target_within_limits(
            v0 in -2.0..2.0f64, a0 in -2.0..2.0f64, v1 in -1.0..=1.0f64,
            distance in -30.0..30.0f64, ramp in 0.01..2.0f64,
        ) {
            let (v_max, a_max) = (50.0, 1000.0);
            let l = Limits::new(v_max, a_max, a_max * a_max / (v_max * ramp)).unwrap();
            let p = solve_from(at(v0 * v_max, a0 * a_max), distance, v1 * v_max, &l).unwrap();
            prop_assert!(check(&p, distance, v1 * v_max, &l).is_ok(), "{:?}", check(&p, distance, v1 * v_max, &l));
        }

        /// The general path (brake and candidate families) agrees with the closed forms of
        /// `solve` where both apply: a0 = 0, forward.
        #[test]
        fn the_families_agree_with_the_closed_forms(
            v0 in 0.0..=1.0f64, v1 in 0.0..=1.0f64, distance in 0.0..20.0f64,
        ) {
            let l = Limits::new(50.0, 1000.0, 20000.0).unwrap();
            if let Ok(q) = solve(distance, v0 * 50.0, v1 * 50.0, &l) {
                let p = general(at(v0 * 50.0, 0.0), distance, v1 * 50.0, &l);
                prop_assert!((p.duration() - q.duration()).abs() <= 1e-9 * q.duration() + 1e-12,
                    "{} vs {}", p.duration(), q.duration());
                prop_assert!(check(&p, distance, v1 * 50.0, &l).is_ok());
            }
        }
    }
}

#[cfg(test)]
mod extremes {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Limits over many decades (V 1e-3–1e3, A 0.1–1e4, J 10–1e7), starts up to ten
        /// times beyond them, distances 1e-9–1e9 either way: a finite profile that ends on
        /// the target within 1e-9 of the largest position it passes.
        #[test]
        fn land_on_target(
            ev in -3.0..3.0f64, ea in -1.0..4.0f64, ej in 1.0..7.0f64,
            v0 in -10.0..10.0f64, a0 in -10.0..10.0f64, v1 in -1.0..=1.0f64,
            ed in -9.0..9.0f64, forward in prop::bool::ANY,
        ) {
            let (vm, am, jm) = (10f64.powf(ev), 10f64.powf(ea), 10f64.powf(ej));
            let l = Limits::new(vm, am, jm).unwrap();
            let d = if forward { 10f64.powf(ed) } else { -10f64.powf(ed) };
            let st = State { s: 0.0, v: v0 * vm, a: a0 * am, j: 0.0 };
            let p = solve_from(st, d, v1 * vm, &l).unwrap();
            prop_assert!(p.duration().is_finite());
            let err = (p.end().s - d).abs();
            let smax = p.knots().iter().map(|k| k.1.s.abs()).fold(0.0, f64::max);
            prop_assert!(err <= 1e-9 * (d.abs() + smax), "ends at {} for {d}", p.end().s);
        }
    }
}
