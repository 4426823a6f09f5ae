//! The profile solver against Ruckig (pantor/ruckig, Python binding), the reference for the
//! one-axis time-optimal jerk-limited motion with zero end accelerations.
//!
//! 160 000 seeded random forward moves (distance, start/end speed, limits) go to one Python
//! process (tests/oracle/ruckig_batch.py) run with `$TEZGAH_PYTHON`; the test is ignored by a plain
//! `cargo test` and fails when that is unset or cannot `import ruckig` (`.ci/install-ruckig`
//! prints a python that can). For each case:
//! * Ruckig's trajectory never drives backward ⇒ ours succeeds with the same duration (1e-6
//!   relative);
//! * Ruckig needs backward motion (its lowest speed < 0) ⇒ ours reports the end speed as
//!   unreachable (a path cannot be driven backward), with a reachable speed that `solve` accepts;
//! * for the first 20 000 cases, ours and Ruckig's trajectories agree at 9 times along the way
//!   (s within 1e-9·(L + V·T), v within 1e-9·V, a within 1e-6·A): the optimum is unique, so
//!   this checks `state_at` against Ruckig's `at_time`;
//! * ours holds the limits at ≥ 20 sample times and at every phase knot (|v| ≤ V, |a| ≤ A,
//!   |j| ≤ J, v ≥ 0, each within 1e-9 relative for rounding) and reaches the end state
//!   (s = L, v = v1, a = 0 within 1e-9 relative).
//!
//! At L = 0 with v0 = v1 ours must not move (duration 0); Ruckig is not compared there (it
//! returns a detour). Ruckig's optimum with its lowest speed within 1e-12·V of 0 sits on the
//! forward/backward boundary; there either answer is accepted (a success must still match).
//!
//! Ruckig ends within ~1e-8 of the target position, not exactly at it, and the optimal duration
//! jumps where the shape changes (just below L = d(v0→v1) a slow-down-then-speed-up takes over
//! from a single ramp). So where ours disagrees with Ruckig for L, ours is solved again for the
//! position Ruckig actually reaches; agreement there is counted as "explained by Ruckig's end
//! position" and listed. Such cases, and Ruckig failures, must stay rare (≤ 1e-4 of all).

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

mod rng_support;
use rng_support::Rng;
use tezgah_motion::profile::{solve, speed_change_distance, Limits, Profile, ProfileError};

const CASES: usize = 160_000;
const SEED: u64 = 0x7e29_a4c1_5eed_0005;
/// The first this many cases also compare the state along the way, at `SAMPLES` times.
const SAMPLED_CASES: usize = 20_000;
const SAMPLES: usize = 9;

#[derive(Debug, Clone, Copy)]
struct Case {
    distance: f64,
    v0: f64,
    v1: f64,
    vmax: f64,
    amax: f64,
    jmax: f64,
}

/// A speed in [0, V]: often exactly 0 or V (the ends of look-ahead segments), else uniform.
fn speed(rng: &mut Rng, vmax: f64) -> f64 {
    match rng.unit() {
        p if p < 0.15 => 0.0,
        p if p < 0.25 => vmax,
        _ => rng.unit() * vmax,
    }
}

/// `TEZGAH_ORACLE_CASES` and `TEZGAH_ORACLE_SEED` override the count and seed for longer runs.
fn cases() -> Vec<Case> {
    let env = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<u64>().ok());
    let n = env("TEZGAH_ORACLE_CASES").map_or(CASES, |n| n as usize);
    let mut rng = Rng(env("TEZGAH_ORACLE_SEED").unwrap_or(SEED) | 1);
    (0..n)
        .map(|_| {
            let vmax = rng.log_uniform(0.5, 1000.0);
            let amax = rng.log_uniform(5.0, 2e4);
            let jmax = rng.log_uniform(50.0, 1e6);
            let v0 = speed(&mut rng, vmax);
            let v1 = if rng.unit() < 0.1 {
                v0
            } else {
                speed(&mut rng, vmax)
            };
            let limits = Limits::new(vmax, amax, jmax).unwrap();
            // Distances around the scale of the move, so that every regime appears: end speed
            // out of reach, slow-down-then-speed-up, peaks below V with and without plateaus,
            // cruise at V.
            let direct = speed_change_distance(v0, v1, &limits).unwrap();
            let stop_go = speed_change_distance(v0, 0.0, &limits).unwrap()
                + speed_change_distance(0.0, v1, &limits).unwrap();
            let scale = direct + speed_change_distance(0.0, vmax, &limits).unwrap();
            let distance = match rng.unit() {
                p if p < 0.02 => 0.0,
                // Between a stop-and-go and a single ramp: only slowing down first can meet v1.
                p if p < 0.2 && stop_go < direct => stop_go + rng.unit() * (direct - stop_go),
                // Mostly long enough for v1 (about a quarter not), down to very short moves.
                p if p < 0.2 => scale * 10f64.powf(rng.unit() * 2.5 - 3.0),
                _ => scale * 10f64.powf(rng.unit() * 1.7 - 1.0),
            };
            Case {
                distance,
                v0,
                v1,
                vmax,
                amax,
                jmax,
            }
        })
        .collect()
}

/// Ruckig's answer for one case.
#[derive(Debug, Clone)]
struct Answer {
    duration: f64,
    /// Lowest speed along Ruckig's trajectory.
    vmin: f64,
    /// Where Ruckig's trajectory ends (L up to its tolerance).
    end: f64,
    /// (s, v, a) at duration·k/(SAMPLES−1), for the first `SAMPLED_CASES` cases.
    samples: Vec<[f64; 3]>,
}

/// Ruckig's answer per case; panics when the oracle is unavailable.
fn ruckig(cases: &[Case]) -> Vec<Answer> {
    let python = std::env::var_os("TEZGAH_PYTHON")
        .expect("TEZGAH_PYTHON is not set: install Ruckig with .ci/install-ruckig");
    let probe = Command::new(&python).args(["-c", "import ruckig"]).output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "{python:?} cannot import ruckig (see .ci/install-ruckig)"
    );
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/oracle/ruckig_batch.py");
    let mut child = Command::new(&python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start the Ruckig batch");
    let mut stdin = child.stdin.take().unwrap();
    let input: String = cases
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let n = if i < SAMPLED_CASES { SAMPLES } else { 0 };
            format!(
                "{:?} {:?} {:?} {:?} {:?} {:?} {n}\n",
                c.distance, c.v0, c.v1, c.vmax, c.amax, c.jmax
            )
        })
        .collect();
    // Write from a thread: the script answers while it reads, and the pipes are finite.
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let answers: Vec<Answer> = stdout
        .lines()
        .map(|l| {
            let l = l.expect("read the Ruckig batch");
            let f: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            assert!(f.len() >= 3 && f.len() % 3 == 0, "bad answer line {l:?}");
            Answer {
                duration: f[0],
                vmin: f[1],
                end: f[2],
                samples: f[3..].chunks(3).map(|x| [x[0], x[1], x[2]]).collect(),
            }
        })
        .collect();
    writer.join().unwrap().expect("write the Ruckig batch");
    assert!(child.wait().unwrap().success(), "Ruckig batch failed");
    assert_eq!(answers.len(), cases.len(), "one answer per case");
    answers
}

/// Limits held at 24 uniform samples and at every knot; end state reached.
fn check_profile(c: &Case, p: &Profile) -> Result<(), String> {
    let t_end = p.duration();
    let times = (0..24)
        .map(|i| t_end * i as f64 / 23.0)
        .chain(p.knots().iter().map(|k| k.0));
    for t in times {
        let x = p.state_at(t);
        let ok = x.v <= c.vmax * (1.0 + 1e-9)
            && x.v >= -1e-9 * c.vmax
            && x.a.abs() <= c.amax * (1.0 + 1e-9)
            && x.j.abs() <= c.jmax * (1.0 + 1e-9);
        if !ok {
            return Err(format!("limit broken at t = {t}: {x:?}"));
        }
    }
    let e = p.state_at(t_end);
    if (e.s - c.distance).abs() > 1e-9 * c.distance
        || (e.v - c.v1).abs() > 1e-9 * c.vmax
        || e.a.abs() > 1e-9 * c.amax
    {
        return Err(format!(
            "end state {e:?} misses s = {}, v = {}",
            c.distance, c.v1
        ));
    }
    Ok(())
}

/// How ours compares with Ruckig for one case solved for `distance`.
enum Verdict {
    /// Both forward, durations agree (relative difference).
    Same(f64),
    /// Ruckig drives backward (or sits on the boundary) and ours reports the end speed unreachable.
    Unreachable,
}

fn judge(c: &Case, distance: f64, r: &Answer, limits: &Limits) -> Result<Verdict, String> {
    let goes_back = r.vmin < -1e-12 * c.vmax;
    let on_boundary = !goes_back && r.vmin < 0.0;
    match solve(distance, c.v0, c.v1, limits) {
        Ok(p) if goes_back => Err(format!(
            "Ruckig goes backward (vmin {}), ours forward in {}",
            r.vmin,
            p.duration()
        )),
        Ok(p) => {
            let diff = (p.duration() - r.duration).abs() / r.duration.max(1e-300);
            if diff <= 1e-6 {
                Ok(Verdict::Same(diff))
            } else {
                Err(format!(
                    "duration {} vs Ruckig {}",
                    p.duration(),
                    r.duration
                ))
            }
        }
        Err(ProfileError::EndSpeedUnreachable { .. }) if goes_back || on_boundary => {
            Ok(Verdict::Unreachable)
        }
        Err(e) => Err(format!("ours: {e}; Ruckig forward in {}", r.duration)),
    }
}

#[test]
#[ignore = "needs Ruckig: set TEZGAH_PYTHON (see .ci/install-ruckig)"]
fn durations_match_ruckig() {
    let cases = cases();
    let oracle = ruckig(&cases);
    let (mut forward, mut backward, mut ruckig_errors, mut trivial) = (0, 0, 0, 0);
    let (mut cruise, mut dip, mut plateau, mut plain) = (0, 0, 0, 0);
    let (mut borderline, mut deepest) = (0, 0.0f64);
    let mut worst = (0.0f64, 0usize);
    let (mut sampled, mut state_worst) = (0, [0.0f64; 3]);
    let (mut explained, mut failures) = (Vec::new(), Vec::new());
    for (i, (c, r)) in cases.iter().zip(&oracle).enumerate() {
        let limits = Limits::new(c.vmax, c.amax, c.jmax).unwrap();
        let ours = solve(c.distance, c.v0, c.v1, &limits);
        if c.distance == 0.0 && c.v0 == c.v1 {
            // Already at the target: the optimum is no motion. Ruckig returns a detour through
            // negative speeds instead when v0 > 0 (docs/errata.md).
            trivial += 1;
            match ours {
                Ok(p) if p.duration() == 0.0 && p.end().s == 0.0 => {}
                other => failures.push(format!("#{i} {c:?}: at target, got {other:?}")),
            }
            continue;
        }
        if r.duration.is_nan() {
            ruckig_errors += 1;
            explained.push(format!(
                "#{i} {c:?}: Ruckig error (ours: {:?})",
                ours.map(|p| p.duration())
            ));
            continue;
        }
        if r.vmin < 0.0 && r.vmin >= -1e-12 * c.vmax {
            borderline += 1;
            deepest = deepest.min(r.vmin / c.vmax);
        }
        match judge(c, c.distance, r, &limits) {
            Ok(Verdict::Same(diff)) => {
                if diff > worst.0 {
                    worst = (diff, i);
                }
                if let (Ok(p), false) = (&ours, r.samples.is_empty()) {
                    sampled += 1;
                    let n = r.samples.len() - 1;
                    for (k, x) in r.samples.iter().enumerate() {
                        let y = p.state_at(r.duration * k as f64 / n as f64);
                        let scale = c.distance + c.vmax * r.duration;
                        let e = [
                            (y.s - x[0]).abs() / scale,
                            (y.v - x[1]).abs() / c.vmax,
                            (y.a - x[2]).abs() / c.amax,
                        ];
                        for (m, e) in state_worst.iter_mut().zip(e) {
                            *m = m.max(e);
                        }
                        // a is looser: at a sample next to a jerk switch, a rounding-level
                        // shift of the switch time moves a by J·δt.
                        if e[0] > 1e-9 || e[1] > 1e-9 || e[2] > 1e-6 {
                            failures.push(format!(
                                "#{i} {c:?}: at sample {k} ours {y:?} vs Ruckig {x:?}"
                            ));
                        }
                    }
                }
            }
            Ok(Verdict::Unreachable) => {}
            Err(e) => match judge(c, r.end, r, &limits) {
                Ok(_) => explained.push(format!(
                    "#{i} {c:?}: {e}; Ruckig ends at {} (off by {:.1e}), ours for that agrees",
                    r.end,
                    r.end - c.distance
                )),
                Err(_) => failures.push(format!("#{i} {c:?}: {e}")),
            },
        }
        // Our own answer, checked on its own terms.
        match ours {
            Ok(p) => {
                forward += 1;
                if let Err(e) = check_profile(c, &p) {
                    failures.push(format!("#{i} {c:?}: {e}"));
                }
                let d = p.durations();
                if d[3] > 0.0 {
                    cruise += 1;
                } else if p.jerks()[0] < 0.0 && d[0] > 0.0 {
                    dip += 1;
                } else if d[1] > 0.0 || d[5] > 0.0 {
                    plateau += 1;
                } else {
                    plain += 1;
                }
            }
            Err(ProfileError::EndSpeedUnreachable { reachable, .. }) => {
                backward += 1;
                let side_ok = if c.v1 > c.v0 {
                    (c.v0..c.v1).contains(&reachable)
                } else {
                    reachable > c.v1 && reachable <= c.v0
                };
                if !side_ok || solve(c.distance, c.v0, reachable, &limits).is_err() {
                    failures.push(format!("#{i} {c:?}: bad reachable end speed {reachable}"));
                }
            }
            Err(e) => failures.push(format!("#{i} {c:?}: unexpected {e}")),
        }
    }
    println!(
        "Ruckig oracle: {} cases: {forward} solved (with cruise {cruise}; slow down, then up \
         {dip}; peak below V with an acceleration plateau {plateau}, without {plain}), \
         {backward} end speed unreachable, {trivial} already at the target (L = 0, v0 = v1); \
         {borderline} with Ruckig's lowest speed in [{deepest:.1e}·V, 0) (boundary); \
         {ruckig_errors} Ruckig errors; {} disagreements explained by Ruckig's end position \
         or errors; max relative duration difference {:.3e} (case #{})",
        cases.len(),
        explained.len(),
        worst.0,
        worst.1
    );
    println!(
        "states compared along {sampled} trajectories at {SAMPLES} times: largest difference \
         s {:.1e}·(L + V·T), v {:.1e}·V, a {:.1e}·A",
        state_worst[0], state_worst[1], state_worst[2]
    );
    for f in explained.iter().take(5).chain(failures.iter().take(20)) {
        println!("{f}");
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases fail",
        failures.len(),
        cases.len()
    );
    // Ruckig itself is not under test: its rare failures and inexact ends are listed above.
    assert!(
        explained.len() <= cases.len() / 10_000,
        "Ruckig failed or missed the target too often"
    );
}
