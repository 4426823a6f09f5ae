//! The one profile solver from any start state against Ruckig (pantor/ruckig, Python binding):
//! the velocity interface (`reach_velocity`) and the position interface (`solve_from`), start
//! speed and acceleration anywhere, within the limits or beyond them (then braked first).
//!
//! 40 000 seeded random cases, half each, go to one Python process (tests/oracle/ruckig_state.py)
//! run with `$TEZGAH_PYTHON`; ignored by a plain `cargo test`, failing when that is unset or cannot
//! `import ruckig` (`.ci/install-ruckig`). Per case:
//! * the same duration within 1e-9 relative (+1e-12 s);
//! * the same state at 7 times along the way (p within 1e-8·(|v|max·T + |L| + 1), v within
//!   1e-8·(|v|max + A·T), a within 1e-6·A: at a sample next to a jerk switch a rounding-level
//!   shift of the switch moves a by J·δt) — the optimum is unique, so this checks the shape;
//! * ours on its own terms: it ends on the target (s = L, v = v1, a = 0 within 1e-9
//!   relative), |j| ≤ J, and after the brake |a| ≤ A and (position interface) |v| ≤ V at every
//!   knot and every speed extremum inside a phase — or, where the brake ends with the speed
//!   still beyond V (a start acceleration that cannot run out sooner), no further out.
//!
//! Ruckig refuses a few start states (|a0| exactly A in the velocity interface), and after a
//! long brake its step 1 can fall back to a slower profile than the optimum (ours then valid
//! and faster: listed, none in this seed); each must stay below 1e-3 of the cases. Start
//! speeds and accelerations reach twice the limits; A²/J lies between 1 % and 2 V (far beyond,
//! the brake's excursion grows to many V and Ruckig fails in a few percent of cases).
//! Measured (seed below): worst relative duration difference 4.8e-11 (position), 5.5e-15
//! (velocity); 5 117 of the cases start with a brake.

mod python_oracle;
mod rng_support;
use rng_support::Rng;
use tezgah_motion::profile::{reach_velocity, solve_from, Limits, Profile, State};

const CASES: usize = 40_000;
const SAMPLES: usize = 7;

/// A value on [−m, m], often exactly 0 or ±m, and one case in ten up to 2m (beyond).
fn around(rng: &mut Rng, m: f64) -> f64 {
    match rng.unit() {
        p if p < 0.12 => 0.0,
        p if p < 0.18 => m,
        p if p < 0.24 => -m,
        p if p < 0.34 => (2.0 * rng.unit() - 1.0) * 2.0 * m,
        _ => (2.0 * rng.unit() - 1.0) * m,
    }
}

#[derive(Debug, Clone, Copy)]
struct Case {
    position: bool,
    v0: f64,
    a0: f64,
    distance: f64,
    v1: f64,
    vmax: f64,
    amax: f64,
    jmax: f64,
}

fn cases() -> Vec<Case> {
    let mut rng = Rng(0x5eed_27a0_c4df_05ab);
    (0..CASES)
        .map(|i| {
            // The speed a full acceleration ramp takes, A²/J, from 1 % to twice V: a start
            // state a machine can be in (far beyond, the brake's excursion grows to many V and
            // Ruckig's step 1 fails in a few percent of cases).
            let (vmax, amax) = (rng.log_uniform(1.0, 500.0), rng.log_uniform(10.0, 1e4));
            // J within 1e2–1e6 (Ruckig's absolute tolerances, ~1e-8, dominate motions of
            // microseconds and nanometres).
            let jmax = (amax * amax / (vmax * rng.log_uniform(0.01, 2.0))).clamp(1e2, 1e6);
            let v0 = around(&mut rng, vmax);
            let a0 = around(&mut rng, amax);
            let mut v1 = around(&mut rng, vmax);
            if v1.abs() > vmax {
                v1 = v1.clamp(-vmax, vmax);
            }
            // Distances around the scale of a full speed change, either way.
            let scale = vmax * vmax / amax + vmax * amax / jmax;
            let sign = if rng.unit() < 0.7 { 1.0 } else { -1.0 };
            let distance = sign * rng.log_uniform(1e-4 * scale, 10.0 * scale);
            Case {
                position: i % 2 == 0,
                v0,
                a0,
                distance,
                v1,
                vmax,
                amax,
                jmax,
            }
        })
        .collect()
}

fn ours(c: &Case) -> Profile {
    let limits = Limits::new(c.vmax, c.amax, c.jmax).unwrap();
    let start = State {
        s: 0.0,
        v: c.v0,
        a: c.a0,
        j: 0.0,
    };
    if c.position {
        solve_from(start, c.distance, c.v1, &limits).unwrap()
    } else {
        reach_velocity(start, c.v1, &limits).unwrap()
    }
}

/// Ours on its own terms (module comment).
fn check(c: &Case, p: &Profile) -> Result<(), String> {
    let end = p.end();
    let tol = 1e-9 * (c.distance.abs() + c.vmax * p.duration() + 1.0);
    if c.position && (end.s - c.distance).abs() > tol {
        return Err(format!("ends at s = {} for {}", end.s, c.distance));
    }
    // The last phase's integration, not the snapped end knot.
    let knots = p.knots();
    let (tl, xl) = knots[knots.len() - 2];
    let t = p.duration() - tl;
    let v = xl.v + t * (xl.a + 0.5 * t * xl.j);
    let a = xl.a + t * xl.j;
    if (v - c.v1).abs() > 1e-9 * (c.vmax + c.v0.abs() + c.amax * p.duration())
        || a.abs() > 1e-9 * (c.amax + c.a0.abs())
    {
        return Err(format!("ends at v = {v}, a = {a}"));
    }
    let braked: f64 = p.brake().iter().map(|b| b.0).sum();
    // Where the brake leaves the speed beyond V (a start acceleration that must run out),
    // the profile returns from there monotonically; it may not go further out.
    let v_cap = c.vmax.max(p.state_at(braked).v.abs());
    for w in knots.windows(2) {
        let ((t0, x), (t1, _)) = (w[0], w[1]);
        if x.j.abs() > c.jmax {
            return Err(format!("jerk {} at {t0}", x.j));
        }
        if t0 < braked {
            continue;
        }
        let mut vs = vec![x.v];
        if x.j != 0.0 {
            let tau = -x.a / x.j;
            if tau > 0.0 && tau < t1 - t0 {
                vs.push(x.v - 0.5 * x.a * x.a / x.j);
            }
        }
        if x.a.abs() > c.amax * (1.0 + 1e-9) {
            return Err(format!("a = {} at {t0}", x.a));
        }
        if c.position && vs.iter().any(|v| v.abs() > v_cap * (1.0 + 1e-9)) {
            return Err(format!("v = {vs:?} at {t0}"));
        }
    }
    Ok(())
}

#[test]
#[ignore = "needs Ruckig: set TEZGAH_PYTHON (see .ci/install-ruckig)"]
fn any_start_state_matches_ruckig() {
    let python = python_oracle::python("TEZGAH_PYTHON", "ruckig", ".ci/install-ruckig");
    let cases = cases();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/oracle/ruckig_state.py");
    let mut text = String::new();
    for c in &cases {
        let kind = if c.position { "p" } else { "v" };
        text += &format!(
            "{kind} {} {} {} {} {} {} {} {SAMPLES}\n",
            c.v0, c.a0, c.distance, c.v1, c.vmax, c.amax, c.jmax
        );
    }
    let out = python_oracle::ask(&python, script, text);
    let (mut checked, mut braked) = ([0usize; 2], 0);
    let mut worst = [(0.0f64, 0usize); 2];
    let (mut ruckig_failed, mut ruckig_slower) = (Vec::new(), Vec::new());
    let mut failures = Vec::new();
    assert_eq!(out.len(), cases.len(), "one line per case");
    for (i, (c, line)) in cases.iter().zip(&out).enumerate() {
        let f: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        if f[0].is_nan() {
            ruckig_failed.push(*c);
            continue;
        }
        let p = ours(c);
        if p.brake().iter().any(|b| b.0 > 0.0) {
            braked += 1;
        }
        let t = f[0];
        let rel = (p.duration() - t).abs() / t.max(1e-300);
        let kind = usize::from(c.position);
        if rel > worst[kind].0 {
            worst[kind] = (rel, i);
        }
        let mut bad = Vec::new();
        if let Err(e) = check(c, &p) {
            bad.push(e);
        } else if p.duration() < t * (1.0 - 1e-9) {
            // Ours is valid and faster: Ruckig missed the optimum (its numerical fallbacks
            // after a long brake). Listed; must stay rare.
            ruckig_slower.push(format!("#{i} {c:?}: ours {} Ruckig {t}", p.duration()));
            checked[kind] += 1;
            continue;
        }
        if (p.duration() - t).abs() > 1e-9 * t + 1e-12 {
            bad.push(format!("duration ours {} Ruckig {t}", p.duration()));
        }
        let vmax = c.v0.abs().max(c.vmax);
        for k in 0..SAMPLES {
            let tk = t * k as f64 / (SAMPLES - 1) as f64;
            let (x, v, a) = (f[1 + 3 * k], f[2 + 3 * k], f[3 + 3 * k]);
            let y = p.state_at(tk);
            if (y.s - x).abs() > 1e-8 * (vmax * t + c.distance.abs() + 1.0)
                || (y.v - v).abs() > 1e-8 * (vmax + c.amax * t)
                || (y.a - a).abs() > 1e-6 * c.amax.max(c.a0.abs())
            {
                bad.push(format!("at {tk}: ours {y:?}, Ruckig ({x}, {v}, {a})"));
            }
        }
        if !bad.is_empty() && failures.len() < 12 {
            failures.push(format!("#{i} {c:?}: {}", bad.join("; ")));
        }
        checked[kind] += 1;
    }
    println!(
        "position: {} cases, worst relative duration difference {:.2e} (#{}); velocity: {} \
         cases, worst {:.2e} (#{}); {braked} braked; Ruckig failed on {}, slower on {}: {:#?}",
        checked[1],
        worst[1].0,
        worst[1].1,
        checked[0],
        worst[0].0,
        worst[0].1,
        ruckig_failed.len(),
        ruckig_slower.len(),
        ruckig_slower
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(ruckig_failed.len() * 1000 <= CASES, "{ruckig_failed:?}");
    assert!(ruckig_slower.len() * 1000 <= CASES);
    assert_eq!(checked[0] + checked[1] + ruckig_failed.len(), CASES);
}
