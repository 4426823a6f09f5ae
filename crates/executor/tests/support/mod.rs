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

/// Jerk margin while re-timing (hold, override, abort): the same finite-difference margin as
/// everywhere (0.5 %), since the time scale bounds |s⃛| ≤ J at every instant of a period (it
/// was 3 % while the bound held only at five instants of it; session 4 saw 1.023).
pub const RETIME_JERK: f64 = 1.005;

pub fn executor() -> Executor {
    let m = Machine::default_machine();
    Executor::new(&m, ExecOptions::for_machine(&m).unwrap(), Pose::ZERO).unwrap()
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

pub fn run_program(exec: &mut Executor, trace: &mut Trace, program: &str) {
    exec.command(Command::Load {
        program: program.into(),
    })
    .unwrap();
    exec.command(Command::CycleStart).unwrap();
    drive(exec, trace, 2_000_000, |_, _| {});
    assert_eq!(exec.state(), RunState::Idle);
}

pub fn assert_within_limits(report: &Report) {
    assert_within(report, 1.005);
}

/// Velocity and acceleration within 0.5 % (the finite differences' margin, as motion's
/// pipeline tests), jerk within `jerk_ratio`.
pub fn assert_within(report: &Report, jerk_ratio: f64) {
    for (i, j) in report.joints.iter().enumerate() {
        assert!(
            j.velocity <= j.max_velocity * 1.005
                && j.acceleration <= j.max_acceleration * 1.005
                && j.jerk <= j.max_jerk * jerk_ratio,
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
