//! Shared test rig: the executor on a virtual clock on the built-in mill3, its set-points
//! replayed through motion's `Verifier` (joint limits by finite differences, distance to the
//! planned path), and random G-code programs.
#![allow(dead_code)]

use tezgah_executor::command::{Command, RunState};
use tezgah_executor::executor::{ExecOptions, Executor, Produced};
use tezgah_geom::Pose;
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::Sample;
use tezgah_motion::verify::{Report, Verifier};

pub const TOL: f64 = 0.01;

pub fn executor() -> Executor {
    let m = Machine::default_machine();
    Executor::new(&m, ExecOptions::for_machine(&m), Pose::ZERO).unwrap()
}

/// Every set-point produced, replayed through the verifier.
pub struct Trace {
    pub out: Vec<Produced>,
    verifier: Verifier,
    period: f64,
}

impl Trace {
    /// Starts with the machine at rest where it stands (the verifier's differences then see
    /// the first period's motion from rest).
    pub fn new(exec: &Executor) -> Trace {
        let st = exec.status();
        let mut verifier = Verifier::new(exec.machine(), exec.period());
        let rest = Sample {
            index: 0,
            t: 0.0,
            line: 0,
            tip: tezgah_geom::Vec3::new(st.tip[0], st.tip[1], st.tip[2]),
            rotary: [0.0; 3],
            joints: tezgah_kinematics::Joints::from_slice(&st.joints).unwrap(),
            feed: 0.0,
        };
        verifier.push(&rest, &[]);
        Trace {
            out: Vec::new(),
            verifier,
            period: exec.period(),
        }
    }

    pub fn push(&mut self, exec: &Executor, p: &Produced) {
        let sp = &p.setpoint;
        let sample = Sample {
            index: sp.index,
            t: sp.index as f64 * self.period,
            line: sp.line,
            tip: p.tip,
            rotary: p.rotary,
            joints: sp.position,
            feed: p.feed,
        };
        self.verifier.push(&sample, exec.passed());
        self.out.push(*p);
    }

    pub fn report(self) -> (Vec<Produced>, Report) {
        (self.out, self.verifier.finish())
    }
}

/// Steps the executor until it stops producing (idle, held, paused) or `max` periods;
/// `each(k, exec)` runs before period k (to send commands at chosen instants).
pub fn drive(
    exec: &mut Executor,
    trace: &mut Trace,
    max: usize,
    mut each: impl FnMut(usize, &mut Executor),
) -> usize {
    for k in 0..max {
        each(k, exec);
        match exec.step().unwrap() {
            Some(p) => trace.push(exec, &p),
            None => return k,
        }
    }
    max
}

/// One MDI block, run to its end.
pub fn run_mdi(exec: &mut Executor, trace: &mut Trace, block: &str) {
    exec.command(Command::Mdi {
        block: block.into(),
    })
    .unwrap();
    drive(exec, trace, 1_000_000, |_, _| {});
    assert_eq!(exec.state(), RunState::Idle);
}

/// Loads `program` and starts it.
pub fn start(exec: &mut Executor, program: &str) {
    exec.command(Command::Load {
        program: program.into(),
    })
    .unwrap();
    exec.command(Command::CycleStart).unwrap();
}

pub fn run_program(exec: &mut Executor, trace: &mut Trace, program: &str) {
    start(exec, program);
    drive(exec, trace, 2_000_000, |_, _| {});
    assert_eq!(exec.state(), RunState::Idle);
}

/// The finite differences' margin over a joint limit, as motion's pipeline tests.
pub const LIMIT_MARGIN: f64 = 1.005;

/// Velocity, acceleration and jerk within [`LIMIT_MARGIN`] of the joint limits, also while
/// re-timing (hold, override, abort): the time scale bounds |s⃛| ≤ J at every instant of a
/// period. Deviation from the planned path within [`TOL`].
pub fn assert_within_limits(report: &Report) {
    for (i, j) in report.joints.iter().enumerate() {
        assert!(
            j.velocity <= j.max_velocity * LIMIT_MARGIN
                && j.acceleration <= j.max_acceleration * LIMIT_MARGIN
                && j.jerk <= j.max_jerk * LIMIT_MARGIN,
            "joint {i}: v {} / {}, a {} / {}, j {} / {} (lines {} {} {})",
            j.velocity,
            j.max_velocity,
            j.acceleration,
            j.max_acceleration,
            j.jerk,
            j.max_jerk,
            j.velocity_line,
            j.acceleration_line,
            j.jerk_line
        );
    }
    assert!(
        report.max_deviation <= TOL,
        "deviation {} at line {}",
        report.max_deviation,
        report.max_deviation_line
    );
}

/// Path coordinate never goes back and the tool never jumps: every step's chord is at most
/// the path advanced (a chord is never longer than the arc it spans).
pub fn assert_continuous(out: &[Produced]) {
    for w in out.windows(2) {
        assert!(
            w[1].path >= w[0].path - 1e-12,
            "path went back from {} to {} at index {}",
            w[0].path,
            w[1].path,
            w[1].setpoint.index
        );
        let chord = (w[1].tip - w[0].tip).norm();
        assert!(
            chord <= (w[1].path - w[0].path) + 1e-9,
            "jump of {chord} over {} of path at line {}",
            w[1].path - w[0].path,
            w[1].setpoint.line
        );
        assert_eq!(w[1].setpoint.index, w[0].setpoint.index + 1);
    }
}

/// The program played at 100 % without commands, within every limit and continuous.
pub fn reference(program: &str) -> Vec<Produced> {
    let mut exec = executor();
    let mut trace = Trace::new(&exec);
    run_program(&mut exec, &mut trace, program);
    let (out, report) = trace.report();
    assert_within_limits(&report);
    assert_continuous(&out);
    out
}

/// The distance a hold at period `at` travelled, the time-optimal jerk-limited stop from the
/// hold state (speed, and acceleration by backward difference, under the path limits where it
/// began and ended, and of every piece between), and the allowance the bound adds: two
/// periods' travel.
pub struct HoldDistance {
    pub travelled: f64,
    pub optimal: f64,
    pub allowance: f64,
}

/// Holds at period `at`, checks the stop, resumes; returns the whole trace and, if it held
/// before the program ended, the hold's distance.
pub fn hold_and_resume(program: &str, at: usize) -> (Vec<Produced>, Option<HoldDistance>) {
    let mut exec = executor();
    let mut trace = Trace::new(&exec);
    start(&mut exec, program);
    // The path limits of every piece the stop passes through: a stop that runs into a piece
    // of weaker limits (a short arc, a blend) brakes as that piece allows.
    let mut crossed = vec![];
    drive(&mut exec, &mut trace, 2_000_000, |k, e| {
        if k == at {
            e.command(Command::FeedHold).unwrap();
        }
        if k >= at && e.state() != RunState::Held {
            crossed.extend(e.path_limits());
        }
    });
    let mut distance = None;
    // Held, or the program ended before the hold.
    if exec.state() == RunState::Held {
        let out = &trace.out;
        let before = &out[at.saturating_sub(1)];
        let prev = &out[at.saturating_sub(2)];
        let a = (before.feed - prev.feed) / exec.period();
        crossed.push(exec.path_limits().expect("held inside a piece"));
        // Under the limits of the piece where the hold began; if it stopped further on, the
        // largest of the stops under the limits of each piece it crossed (braking as each
        // allows lies between them).
        let optimal = crossed
            .iter()
            .map(|l| {
                tezgah_executor::stop::stopping_distance(
                    before.feed,
                    a.clamp(-l.max_acceleration(), l.max_acceleration()),
                    l,
                )
            })
            .fold(0.0, f64::max);
        let d = HoldDistance {
            travelled: out.last().unwrap().path - before.path,
            optimal,
            // A period's travel for the command taking hold, and one for the backward
            // difference's view of the acceleration: a plan already braking at the hold
            // reads a stop of zero length under its own limits.
            allowance: 2.0 * before.feed * exec.period() + 1e-9,
        };
        distance = Some(d);
        // Standing: nothing produced while held.
        assert_eq!(exec.step().unwrap(), None);
        exec.command(Command::Resume).unwrap();
        drive(&mut exec, &mut trace, 2_000_000, |_, _| {});
    }
    assert_eq!(exec.state(), RunState::Idle);
    assert_eq!(exec.unchecked_periods(), 0);
    let (out, report) = trace.report();
    assert_within_limits(&report);
    assert_continuous(&out);
    (out, distance)
}

/// Bound on a hold's distance over the optimum (plus two periods' travel).
pub const HOLD_RATIO: f64 = 1.2;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn round4(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

/// A random 3-axis program: lines, rapids and arcs, short and long, under G64 and G61, with
/// feeds from 600 to 6600 mm/min; ends with M2.
pub fn random_program(seed: u64, n: usize) -> String {
    let mut r = Lcg(seed ^ 0x9e37_79b9_7f4a_7c15);
    let mut text = format!("G21 G90 G17 G64 F{:.0}\n", 600.0 + 6000.0 * r.next());
    let mut p = [0.0f64; 3];
    for _ in 0..n {
        let k = r.next();
        if k < 0.1 {
            text.push_str(if r.next() < 0.5 { "G61\n" } else { "G64\n" });
            continue;
        }
        let scale = if r.next() < 0.4 { 0.5 } else { 30.0 };
        let q = [
            round4((p[0] + scale * (r.next() - 0.5)).clamp(-150.0, 150.0)),
            round4((p[1] + scale * (r.next() - 0.5)).clamp(-120.0, 120.0)),
            round4((p[2] + 0.2 * scale * (r.next() - 0.5)).clamp(-80.0, 80.0)),
        ];
        if k < 0.25 {
            text.push_str(&format!("G0 X{:.4} Y{:.4} Z{:.4}\n", q[0], q[1], q[2]));
            p = q;
        } else if k < 0.5 {
            let c = [
                round4(0.5 * (p[0] + q[0]) + (q[1] - p[1]) * (r.next() - 0.5)),
                round4(0.5 * (p[1] + q[1]) - (q[0] - p[0]) * (r.next() - 0.5)),
            ];
            let r0 = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt();
            if r0 < 0.05 {
                continue;
            }
            let a = (q[1] - c[1]).atan2(q[0] - c[0]);
            let e = [
                round4(c[0] + r0 * a.cos()),
                round4(c[1] + r0 * a.sin()),
                q[2],
            ];
            if e[0].abs() > 150.0 || e[1].abs() > 120.0 {
                continue;
            }
            let g = if r.next() < 0.5 { 2 } else { 3 };
            text.push_str(&format!(
                "G{g} X{:.4} Y{:.4} Z{:.4} I{:.4} J{:.4}\n",
                e[0],
                e[1],
                e[2],
                c[0] - p[0],
                c[1] - p[1]
            ));
            p = e;
        } else {
            text.push_str(&format!("G1 X{:.4} Y{:.4} Z{:.4}\n", q[0], q[1], q[2]));
            p = q;
        }
    }
    text.push_str("M2\n");
    text
}
