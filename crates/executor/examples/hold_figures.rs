//! Figures of the executor's holds and re-timing on random programs, printed (they were two
//! ignored tests; the bounds themselves are asserted by `tests/executor.rs`):
//!
//! ```text
//! cargo run -p tezgah-executor --profile test --example hold_figures [holds|retime]
//! ```
//!
//! `holds`: hold distances over the time-optimal stop at 200 random holds; `retime`: the worst
//! joint ratios over 60 runs with override changes and holds. Both without an argument.

#[path = "../tests/support/mod.rs"]
mod support;

use support::*;
use tezgah_executor::command::{Command, RunState};

fn main() {
    let which = std::env::args().nth(1);
    let want = |name: &str| which.as_deref().is_none_or(|w| w == name);
    if want("holds") {
        hold_distance_distribution();
    }
    if want("retime") {
        retime_limit_figures();
    }
}

/// The distribution of hold distances over the optimum on random holds; the bound itself is
/// asserted in every hold of the tests.
fn hold_distance_distribution() {
    let mut ratios = vec![];
    let mut net = 0.0f64;
    for seed in 0..40u64 {
        let program = random_program(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15), 12);
        let n = reference(&program).len();
        for k in 1..=5 {
            let at = n * k / 6;
            if let (_, Some(d)) = hold_and_resume(&program, at) {
                if d.optimal > 1e-4 {
                    let ratio = (d.travelled - d.allowance) / d.optimal;
                    net = net.max(ratio);
                    if ratio > HOLD_RATIO {
                        eprintln!("seed {seed} at {at}: {ratio} of {}", d.optimal);
                    }
                    ratios.push(d.travelled / d.optimal);
                }
            }
        }
    }
    ratios.sort_by(f64::total_cmp);
    let q = |p: f64| ratios[((ratios.len() - 1) as f64 * p).round() as usize];
    eprintln!(
        "{} holds: min {:.4} median {:.4} p90 {:.4} max {:.4}; less a period's travel, max {:.4}",
        ratios.len(),
        q(0.0),
        q(0.5),
        q(0.9),
        q(1.0),
        net
    );
}

/// Worst joint speed, acceleration and jerk over their limits in a verifier's report.
fn worst_ratios(report: &tezgah_motion::verify::Report) -> [f64; 3] {
    let mut w = [0.0f64; 3];
    for j in &report.joints {
        w[0] = w[0].max(j.velocity / j.max_velocity);
        w[1] = w[1].max(j.acceleration / j.max_acceleration);
        w[2] = w[2].max(j.jerk / j.max_jerk);
    }
    w
}

/// 60 random programs, each with an override
/// change (150, 200, 30, 0 or 120 %) back to 100 % 0.8 s later and a hold resumed 0.3 s
/// later at deterministic pseudo-random instants; worst joint ratios by finite differences
/// and the periods the time scale could not verify. The limits themselves are asserted by
/// the property tests.
fn retime_limit_figures() {
    let mut all = vec![];
    let mut unchecked = 0;
    for seed in 100..160u64 {
        let program = random_program(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15), 10);
        let n = reference(&program).len();
        let mut exec = executor();
        let mut trace = Trace::new(&exec);
        start(&mut exec, &program);
        let hold = (seed as usize * 7919) % n;
        let change = (seed as usize * 104_729) % n;
        let percent = [150.0, 200.0, 30.0, 0.0, 120.0][seed as usize % 5];
        for k in 0..100 * n + 100_000 {
            if k == change {
                exec.command(Command::FeedOverride { percent }).unwrap();
            }
            if k == change + 800 {
                exec.command(Command::FeedOverride { percent: 100.0 })
                    .unwrap();
            }
            if k == hold {
                exec.command(Command::FeedHold).unwrap();
            }
            if k == hold + 300 {
                exec.command(Command::Resume).unwrap();
            }
            match exec.step().unwrap() {
                Some(p) => trace.push(&exec, &p),
                None if exec.state() == RunState::Idle => break,
                None => {}
            }
        }
        assert_eq!(exec.state(), RunState::Idle);
        unchecked += exec.unchecked_periods();
        all.push(worst_ratios(&trace.report().1));
    }
    let column = |i: usize| {
        let mut c: Vec<f64> = all.iter().map(|w| w[i]).collect();
        c.sort_by(f64::total_cmp);
        (c[c.len() / 2], c[c.len() - 1])
    };
    eprintln!(
        "{} runs: jerk/J median {:.6} max {:.6}; acceleration/A max {:.6}; speed/V max {:.5}; \
         unchecked periods {unchecked}",
        all.len(),
        column(2).0,
        column(2).1,
        column(1).1,
        column(0).1
    );
}
