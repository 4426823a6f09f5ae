//! The JOG/homing velocity ramp (`manual::ramp::VelocityRamp`) against Ruckig's velocity
//! control interface (pantor/ruckig, Python binding), the reference for the one-axis
//! time-optimal jerk-limited change of speed from any start acceleration.
//!
//! 20 000 seeded random cases (start speed and acceleration, target speed, limits) go to one
//! Python process (tests/oracle/ruckig_velocity.py) run with `$TEZGAH_PYTHON`; ignored by a
//! plain `cargo test`, and failing when that is unset or cannot `import ruckig`
//! (`.ci/install-ruckig` prints a python that can). Ruckig refuses a few start states with
//! |a0| exactly A; those (at most 1e-3 of the cases) are listed and skipped. Per case: the same
//! duration (1e-9 relative, 1e-12 s absolute) and the same state at 7 times along the way
//! (p within 1e-9·(|v|max·T + 1), v within 1e-9·(|v|max + A·T), a within 1e-9·A) — the optimum
//! is unique, so this checks the closed forms and `state_at`.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

use tezgah_executor::manual::VelocityRamp;
use tezgah_motion::profile::State;

const CASES: usize = 20_000;
const SAMPLES: usize = 7;

/// xorshift64* (Vigna 2016), reproducible everywhere.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.unit() * (hi.ln() - lo.ln())).exp()
    }
}

#[test]
#[ignore = "needs Ruckig: set TEZGAH_PYTHON (see .ci/install-ruckig)"]
fn velocity_ramp_matches_ruckig() {
    let python = std::env::var_os("TEZGAH_PYTHON")
        .expect("TEZGAH_PYTHON is not set: install Ruckig with .ci/install-ruckig");
    let probe = Command::new(&python).args(["-c", "import ruckig"]).output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "{python:?} cannot import ruckig (see .ci/install-ruckig)"
    );
    let mut rng = Rng(0x5eed_0f7e_29a4_c1d3);
    let cases: Vec<[f64; 5]> = (0..CASES)
        .map(|_| {
            let a = rng.log_uniform(10.0, 1e4);
            let j = rng.log_uniform(1e2, 1e6);
            let v = rng.log_uniform(0.1, 500.0);
            let pick = |r: &mut Rng| match r.unit() {
                p if p < 0.1 => 0.0,
                p if p < 0.2 => -v,
                p if p < 0.3 => v,
                _ => (2.0 * r.unit() - 1.0) * v,
            };
            let v0 = pick(&mut rng);
            let vt = pick(&mut rng);
            let a0 = match rng.unit() {
                p if p < 0.2 => 0.0,
                p if p < 0.3 => a,
                p if p < 0.4 => -a,
                _ => (2.0 * rng.unit() - 1.0) * a,
            };
            [v0, a0, vt, a, j]
        })
        .collect();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/oracle/ruckig_velocity.py"
    );
    let mut child = Command::new(&python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("python runs");
    {
        let mut input = child.stdin.take().unwrap();
        let mut text = String::new();
        for c in &cases {
            text += &format!("{} {} {} {} {} {SAMPLES}\n", c[0], c[1], c[2], c[3], c[4]);
        }
        input.write_all(text.as_bytes()).unwrap();
    }
    let out = BufReader::new(child.stdout.take().unwrap());
    let mut checked = 0;
    let mut ruckig_failed = Vec::new();
    let mut failures = Vec::new();
    for (c, line) in cases.iter().zip(out.lines()) {
        let line = line.unwrap();
        let f: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        if f[0].is_nan() {
            ruckig_failed.push(*c);
            continue;
        }
        let [v0, a0, vt, a, j] = *c;
        let ramp = VelocityRamp::new(
            State {
                s: 0.0,
                v: v0,
                a: a0,
                j: 0.0,
            },
            vt,
            a,
            j,
        );
        let t = f[0];
        let vmax = v0.abs().max(vt.abs()) + a * a / j;
        let mut bad = (ramp.duration() - t).abs() > 1e-9 * t + 1e-12;
        for k in 0..SAMPLES {
            let tk = t * k as f64 / (SAMPLES - 1) as f64;
            let (p, v, acc) = (f[1 + 3 * k], f[2 + 3 * k], f[3 + 3 * k]);
            let st = ramp.state_at(tk);
            bad |= (st.s - p).abs() > 1e-9 * (vmax * t + 1.0)
                || (st.v - v).abs() > 1e-9 * (vmax + a * t)
                || (st.a - acc).abs() > 1e-9 * a;
        }
        if bad && failures.len() < 10 {
            failures.push(format!(
                "{c:?}: ours {} ruckig {t}; end {:?}",
                ramp.duration(),
                ramp.end()
            ));
        }
        checked += 1;
    }
    assert!(child.wait().unwrap().success());
    // Ruckig refuses a few start states exactly on |a0| = A; they must stay rare.
    println!(
        "Ruckig failed on {} cases: {ruckig_failed:?}",
        ruckig_failed.len()
    );
    assert!(ruckig_failed.len() * 1000 <= CASES, "{ruckig_failed:?}");
    assert_eq!(checked + ruckig_failed.len(), CASES);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
