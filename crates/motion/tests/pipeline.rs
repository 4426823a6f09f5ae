//! End to end on generated programs: direct path → plan → interpolate → verify on the
//! built-in `mill3`. No sample over any joint limit (0.5 % for the finite differences), the
//! tip within the tolerance, block ends hit exactly, and for G61.1 the cycle time equal to the
//! sum of the per-block optimal profile durations.

#[path = "../benches/common/mod.rs"]
mod common;

use proptest::prelude::*;
use tezgah_geom::{ArcMove, FeedMode, Move, MoveKind, PathMode, Plane, Pose, ToolControl, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::{run, Sample};
use tezgah_motion::path::direct::{build, DirectOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::program::ProgramPath;
use tezgah_motion::verify::{Report, Verifier};
use tezgah_motion::{solve, Limits};

const TOL: f64 = 0.01;

struct Out {
    report: Report,
    duration: f64,
    samples: Vec<Sample>,
}

fn run_moves(moves: &[Move]) -> Out {
    run_on(&Machine::default_machine(), moves)
}

fn run_on(machine: &Machine, moves: &[Move]) -> Out {
    run_under(machine, moves, ToolControl::OFF)
}

/// Tool-centre-point control from the start (the machine file's `tcp = "always"`), no tool.
fn run_tcp(machine: &Machine, moves: &[Move]) -> Out {
    run_under(machine, moves, TCP)
}

const TCP: ToolControl = ToolControl::CentrePoint { tool_length: 0.0 };

fn run_under(machine: &Machine, moves: &[Move], control: ToolControl) -> Out {
    let mut pm = PlanMachine::from_machine(machine).unwrap();
    pm.initial = control;
    let items = build(
        moves,
        Pose::ZERO,
        DirectOptions {
            tolerance: TOL,
            control,
            ..DirectOptions::default()
        },
    )
    .unwrap();
    // Against the program: the direct path keeps it, so only the chord error shows.
    let program = ProgramPath::new(Pose::ZERO, control, moves);
    let mut verifier = Verifier::new(&pm, machine.motion.period_s).against(&pm, program);
    let mut samples = vec![];
    let duration = run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |s, seg| {
            verifier.push(s, seg);
            samples.push(*s);
        },
    )
    .unwrap();
    Out {
        report: verifier.finish(),
        duration,
        samples,
    }
}

fn assert_within_limits(out: &Out) {
    common::assert_joints_within(&out.report);
    assert!(
        out.report.max_deviation <= TOL,
        "deviation {} at line {}",
        out.report.max_deviation,
        out.report.max_deviation_line
    );
    // Rows on the grid, the last one at the duration rounded up.
    let last = out.samples.last().unwrap();
    assert_eq!(last.index as usize + 1, out.samples.len());
    assert!(last.t >= out.duration - 1e-9 && last.t < out.duration + 0.001 + 1e-9);
    assert_eq!(out.report.cycle_time, last.t);
}

fn mv(line: u32, kind: MoveKind) -> Move {
    Move { line, kind }
}
fn feed(line: u32, x: f64, y: f64, z: f64) -> Move {
    mv(
        line,
        MoveKind::Feed {
            end: Pose::new(x, y, z, 0.0, 0.0, 0.0),
        },
    )
}
fn rapid(line: u32, x: f64, y: f64, z: f64) -> Move {
    mv(
        line,
        MoveKind::Rapid {
            end: Pose::new(x, y, z, 0.0, 0.0, 0.0),
        },
    )
}
fn f(line: u32, mm_per_min: f64) -> Move {
    mv(line, MoveKind::FeedRate { value: mm_per_min })
}
fn mode(line: u32, m: PathMode) -> Move {
    mv(line, MoveKind::PathMode(m))
}
fn arc(line: u32, end: [f64; 3], center: [f64; 2], turn: i32) -> Move {
    mv(
        line,
        MoveKind::Arc(ArcMove {
            plane: Plane::XY,
            end: Pose::new(end[0], end[1], end[2], 0.0, 0.0, 0.0),
            center,
            turn,
        }),
    )
}

/// A deterministic pseudo-random stream (no dependency on a seed crate).
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

/// Dense surfacing: a wavy zig-zag of 0.05–0.3 mm segments.
fn surfacing(passes: usize, per_pass: usize) -> Vec<Move> {
    let mut r = Lcg(7);
    let mut m = vec![
        f(1, 3000.0),
        mode(2, PathMode::Continuous { tolerance: None }),
    ];
    m.push(rapid(3, 0.0, 0.0, 2.0));
    m.push(feed(4, 0.0, 0.0, 0.0));
    let (mut x, mut line) = (0.0, 5);
    for p in 0..passes {
        let y = p as f64 * 0.5;
        let dir = if p % 2 == 0 { 1.0 } else { -1.0 };
        m.push(feed(line, x, y, (x * 0.3).sin() * 0.5));
        line += 1;
        for _ in 0..per_pass {
            x += dir * (0.05 + 0.25 * r.next());
            m.push(feed(
                line,
                x,
                y,
                (x * 0.3).sin() * 0.5 + 0.2 * (y * 0.2).cos(),
            ));
            line += 1;
        }
    }
    m
}

#[test]
fn dense_surfacing_within_limits_and_tolerance() {
    let out = run_moves(&surfacing(3, 120));
    assert_within_limits(&out);
    // Final position hit exactly.
    let last = out.samples.last().unwrap();
    assert!(last.tip.norm() > 0.0);
}

#[test]
fn arcs_helices_and_rapids_in_every_mode() {
    for (k, pm) in [
        PathMode::ExactPath,
        PathMode::ExactStop,
        PathMode::Continuous { tolerance: None },
        PathMode::Continuous {
            tolerance: Some(0.002),
        },
    ]
    .into_iter()
    .enumerate()
    {
        let m = vec![
            mode(1, pm),
            rapid(2, -20.0, 0.0, 5.0),
            f(3, 2400.0),
            feed(4, -20.0, 0.0, 0.0),
            // Full helix down.
            arc(5, [-20.0, 0.0, -3.0], [-10.0, 0.0], 1),
            // Tangent line then arcs of various radii.
            feed(6, -20.0, 10.0, -3.0),
            arc(7, [-10.0, 20.0, -3.0], [-10.0, 10.0], -1),
            arc(8, [0.0, 20.0, -3.0], [-5.0, 20.0], -1),
            arc(9, [0.5, 20.5, -3.0], [0.5, 20.0], 1),
            feed(10, 30.0, 20.5, -3.0),
            rapid(11, 30.0, 20.5, 10.0),
            rapid(12, 0.0, 0.0, 0.0),
        ];
        let out = run_moves(&m);
        assert_within_limits(&out);
        let last = out.samples.last().unwrap();
        assert_eq!(last.tip, Vec3::zeros(), "mode {k}: end hit exactly");
    }
}

#[test]
fn dwell_holds_block_end_exactly() {
    let m = vec![
        f(1, 600.0),
        feed(2, 3.3, 1.7, -0.9),
        mv(3, MoveKind::Dwell { seconds: 0.05 }),
        feed(4, 0.0, 0.0, 0.0),
    ];
    let out = run_moves(&m);
    assert_within_limits(&out);
    let held: Vec<_> = out.samples.iter().filter(|s| s.line == 3).collect();
    assert!(held.len() >= 49, "{} dwell samples", held.len());
    for s in held {
        assert_eq!(s.tip, Vec3::new(3.3, 1.7, -0.9));
    }
}

#[test]
fn exact_stop_cycle_time_is_sum_of_optimal_profiles() {
    let machine = Machine::default_machine();
    let pts = [
        [10.0, 0.0, 0.0],
        [10.0, 7.0, -1.0],
        [-3.0, 2.0, 4.0],
        [0.0, 0.0, 0.0],
        [60.0, -5.0, 0.0],
    ];
    let mut m = vec![mode(1, PathMode::ExactStop), f(2, 9000.0)];
    for (i, p) in pts.iter().enumerate() {
        m.push(feed(3 + i as u32, p[0], p[1], p[2]));
    }
    let out = run_moves(&m);
    assert_within_limits(&out);
    // Independent expectation: each block rest to rest with V = min(F, Vi/|ti|), A and J the
    // same per-axis projection (v ≤ min_i Vmax_i/|t_i|).
    let mut expected = 0.0;
    let mut prev = [0.0; 3];
    for p in pts {
        let d = Vec3::new(p[0] - prev[0], p[1] - prev[1], p[2] - prev[2]);
        let len = d.norm();
        let t = d / len;
        let (mut v, mut a, mut j) = (9000.0 / 60.0, f64::INFINITY, f64::INFINITY);
        for (i, joint) in machine.joints.iter().enumerate() {
            if t[i] != 0.0 {
                v = f64::min(v, joint.max_velocity / t[i].abs());
                a = a.min(joint.max_acceleration / t[i].abs());
                j = j.min(joint.max_jerk / t[i].abs());
            }
        }
        let lim = Limits::new(v, a, j).unwrap();
        expected += solve(len, 0.0, 0.0, &lim).unwrap().duration();
        prev = p;
    }
    assert!(
        (out.duration - expected).abs() <= 1e-9 * expected,
        "{} vs {}",
        out.duration,
        expected
    );
}

#[test]
fn inverse_time_and_rotary_only_moves() {
    let m = vec![
        mv(1, MoveKind::FeedMode(FeedMode::InverseTime)),
        f(2, 60.0), // each move takes ≥ 1 s
        feed(3, 5.0, 0.0, 0.0),
        mv(
            4,
            MoveKind::Feed {
                end: Pose::new(5.0, 0.0, 0.0, 90.0, 0.0, 0.0),
            },
        ),
        feed(5, 0.0, 0.0, 0.0),
    ];
    let out = run_moves(&m);
    assert_within_limits(&out);
    assert!(out.duration >= 3.0, "{}", out.duration);
}

#[test]
fn g61_stops_at_kinks_and_g64_passes_small_ones() {
    let corner = |pm, dy| {
        let m = vec![
            mode(1, pm),
            f(2, 6000.0),
            feed(3, 50.0, 0.0, 0.0),
            feed(4, 100.0, dy, 0.0),
        ];
        run_moves(&m)
    };
    for dy in [0.5, 0.005] {
        let exact = corner(PathMode::ExactPath, dy);
        let cont = corner(PathMode::Continuous { tolerance: None }, dy);
        assert_within_limits(&exact);
        assert_within_limits(&cont);
        // G61 stops at the kink; G64 (direct) passes it at the speed its jump allows, or
        // stops when that speed is a crawl (0.57°).
        if dy > 0.1 {
            assert!(cont.duration <= exact.duration);
        } else {
            assert!(cont.duration < exact.duration);
        }
    }
}

fn random_program(seed: u64, n: usize) -> Vec<Move> {
    let mut r = Lcg(seed);
    let mut m = vec![f(1, 600.0 + 6000.0 * r.next())];
    let mut p = [0.0f64; 3];
    for i in 0..n {
        let line = 2 + i as u32;
        let k = r.next();
        if k < 0.15 {
            let modes = [
                PathMode::ExactPath,
                PathMode::ExactStop,
                PathMode::Continuous { tolerance: None },
            ];
            m.push(mode(line, modes[(r.next() * 3.0) as usize % 3]));
            continue;
        }
        let scale = if r.next() < 0.5 { 0.2 } else { 20.0 };
        let q = [
            (p[0] + scale * (r.next() - 0.5)).clamp(-150.0, 150.0),
            (p[1] + scale * (r.next() - 0.5)).clamp(-120.0, 120.0),
            (p[2] + 0.2 * scale * (r.next() - 0.5)).clamp(-80.0, 80.0),
        ];
        if k < 0.3 {
            m.push(rapid(line, q[0], q[1], q[2]));
        } else if k < 0.55 {
            // Arc with the centre off the chord's midpoint.
            let c = [
                0.5 * (p[0] + q[0]) + (q[1] - p[1]) * (r.next() - 0.5),
                0.5 * (p[1] + q[1]) - (q[0] - p[0]) * (r.next() - 0.5),
            ];
            let r0 = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt();
            let r1 = ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2)).sqrt();
            if (r0 - r1).abs() > 1e-9 || r0 < 1e-3 {
                // Make the end lie on the circle.
                let a = (q[1] - c[1]).atan2(q[0] - c[0]);
                let e = [c[0] + r0 * a.cos(), c[1] + r0 * a.sin(), q[2]];
                if r0 < 1e-3 {
                    continue;
                }
                m.push(arc(line, e, c, if r.next() < 0.5 { 1 } else { -1 }));
                p = e;
                continue;
            }
            m.push(arc(line, q, c, if r.next() < 0.5 { 1 } else { -1 }));
        } else {
            m.push(feed(line, q[0], q[1], q[2]));
        }
        p = q;
    }
    m
}

#[test]
fn linear_delta_lines_arcs_and_rapids() {
    let machine = Machine::builtin("linear-delta").unwrap();
    for pm in [
        PathMode::ExactPath,
        PathMode::Continuous { tolerance: None },
    ] {
        let m = vec![
            mode(1, pm),
            rapid(2, -80.0, 0.0, 20.0),
            f(3, 6000.0),
            feed(4, -80.0, 0.0, 0.0),
            arc(5, [-80.0, 0.0, -10.0], [0.0, 0.0], 1),
            feed(6, 80.0, 40.0, -10.0),
            arc(7, [60.0, 60.0, -10.0], [60.0, 40.0], 1),
            rapid(8, 0.0, 0.0, 0.0),
        ];
        let out = run_on(&machine, &m);
        assert_within_limits(&out);
        assert_eq!(out.samples.last().unwrap().tip, Vec3::zeros());
    }
    let out = run_on(&machine, &surfacing(2, 80));
    assert_within_limits(&out);
}

fn feed6(line: u32, p: [f64; 6]) -> Move {
    mv(
        line,
        MoveKind::Feed {
            end: Pose::new(p[0], p[1], p[2], p[3], p[4], p[5]),
        },
    )
}

#[test]
fn five_axis_table_ac_and_yzca() {
    let ac = Machine::builtin("table-ac").unwrap();
    let m = vec![
        f(1, 3000.0),
        feed6(2, [10.0, 10.0, 5.0, 0.0, 0.0, 0.0]),
        feed6(3, [20.0, 0.0, 0.0, 30.0, 0.0, 90.0]),
        mv(
            4,
            MoveKind::Arc(ArcMove {
                plane: Plane::XY,
                end: Pose::new(0.0, 20.0, 0.0, 30.0, 0.0, 90.0),
                center: [0.0, 0.0],
                turn: 1,
            }),
        ),
        // Rotary only: the table tilts and turns under a standing tip.
        feed6(5, [0.0, 20.0, 0.0, 45.0, 0.0, 200.0]),
        feed6(6, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
    ];
    let out = run_tcp(&ac, &m);
    assert_within_limits(&out);
    assert_eq!(out.samples.last().unwrap().tip, Vec3::zeros());
    // The rotary joints really moved, and one of them works near its limits.
    assert!(out.report.joints[3].velocity > 0.0 && out.report.joints[4].velocity > 0.0);
    assert!(out.report.joints.iter().any(|j| j.worst_ratio() > 0.9));

    let yzca = Machine::builtin("yzca").unwrap();
    let m = vec![
        f(1, 3000.0),
        feed(2, 50.0, 0.0, 0.0),
        arc(3, [0.0, 50.0, -2.0], [0.0, 0.0], 1),
        feed(4, 0.0, 80.0, -2.0),
        arc(5, [80.0, 0.0, -2.0], [0.0, 0.0], -1),
    ];
    let out = run_tcp(&yzca, &m);
    assert_within_limits(&out);
}

#[test]
fn a_path_through_a_singular_pose_is_refused() {
    let yzca = Machine::builtin("yzca").unwrap();
    let mut pm = PlanMachine::from_machine(&yzca).unwrap();
    pm.initial = TCP;
    let m = vec![
        f(1, 3000.0),
        feed(2, 0.0, 0.0, -1.0),
        // Leaving the C axis sideways: C, undefined on the axis, must turn 45° at once.
        feed(3, 30.0, 30.0, -1.0),
    ];
    let options = DirectOptions {
        control: TCP,
        ..DirectOptions::default()
    };
    let items = build(&m, Pose::ZERO, options).unwrap();
    let r = run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |_, _| {},
    );
    let e = r.unwrap_err().to_string();
    assert!(e.contains("line 3") && e.contains("singular"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, .. ProptestConfig::default() })]
    #[test]
    fn random_programs_hold_limits(seed in any::<u64>()) {
        let out = run_moves(&random_program(seed, 25));
        assert_within_limits(&out);
    }
}

#[test]
fn planner_streams_with_bounded_memory() {
    use tezgah_motion::plan::{Planned, Planner};
    let machine = Machine::default_machine();
    let options = PlanOptions::default();
    let bound = options.window * options.max_group + 2;
    let mut planner = Planner::new(PlanMachine::from_machine(&machine).unwrap(), options).unwrap();
    let mut direct = tezgah_motion::path::direct::Direct::new(Pose::ZERO, DirectOptions::default());
    let (mut pushed, mut emitted, mut most_held) = (0usize, 0usize, 0usize);
    let mut items = vec![];
    direct.push(&f(1, 3000.0), &mut items).unwrap();
    for k in 0..20_000u32 {
        // A gentle zig-zag of 0.2 mm moves (kinks of ~0.02 rad: passed at speed in G64).
        let x = 0.2 * (k + 1) as f64;
        let y = if k % 2 == 0 { 0.0 } else { 0.004 };
        direct.push(&feed(2 + k, x, y, 0.0), &mut items).unwrap();
        for item in items.drain(..) {
            pushed += 1;
            planner.push(item).unwrap();
        }
        while let Some(p) = planner.pop() {
            if let Planned::Motion(piece) = p {
                emitted += piece.segments.len();
            }
        }
        most_held = most_held.max(pushed - emitted);
    }
    assert!(emitted > 15_000, "planned while streaming: {emitted}");
    assert!(most_held <= bound, "held {most_held} > {bound}");
    direct.finish(&mut items);
    for item in items.drain(..) {
        pushed += 1;
        planner.push(item).unwrap();
    }
    planner.finish().unwrap();
    while let Some(p) = planner.pop() {
        if let Planned::Motion(piece) = p {
            emitted += piece.segments.len();
        }
    }
    assert_eq!(emitted, pushed);
}

/// Bug: a junction speed the backward pass had promised became unreachable when the window
/// grew. A jerk-limited ramp gains less speed over a distance the faster it starts, so the
/// highest entry speed from which a short segment reaches its end speed in one ramp *falls*
/// when that end speed rises from rest: here 0.05 mm at J = 50000 reaches 5 mm/s from rest
/// but only 4.77 mm/s from 1 mm/s. With a window of one group, the 5 mm line is committed to
/// end at 5 mm/s while the short segment is still last (it must stop); when the 1 mm/s line
/// arrives, the short segment's end may rise to 1 mm/s, its bound fell to 4.77, and the
/// forward pass failed ("end speed 1 cannot be reached from 5"). Braking 5 → 1 mm/s takes
/// 0.054 mm, braking to rest exactly the 0.05 mm: the plan must take that.
#[test]
fn a_committed_junction_speed_stays_reachable_when_the_window_grows() {
    use tezgah_motion::plan::lookahead::plan_all;
    use tezgah_motion::plan::Planned;
    let moves = [
        f(1, 600.0),
        feed(2, 5.0, 0.0, 0.0),
        f(3, 1800.0),
        feed(4, 5.05, 0.0, 0.0),
        f(5, 60.0),
        feed(6, 5.1, 0.0, 0.0),
    ];
    let items = build(&moves, Pose::ZERO, DirectOptions::default()).unwrap();
    let machine = PlanMachine::from_machine(&Machine::default_machine()).unwrap();
    let options = PlanOptions {
        window: 1,
        ..PlanOptions::default()
    };
    let planned = plan_all(items, machine, options).unwrap();
    let pieces: Vec<_> = planned
        .iter()
        .filter_map(|p| match p {
            Planned::Motion(piece) => Some(piece),
            _ => None,
        })
        .collect();
    assert_eq!(pieces.len(), 3);
    // (0.05² · 50000)^⅓ = 5 mm/s: the speed from which 0.05 mm is exactly a stop.
    assert!((pieces[0].profile.end().v - 5.0).abs() < 1e-9);
    assert!(pieces[1].profile.end().v.abs() < 1e-6);
    for w in pieces.windows(2) {
        assert!((w[0].profile.end().v - w[1].profile.start().v).abs() < 1e-9);
    }
    for p in &pieces {
        assert!((p.profile.distance() - p.length()).abs() < 1e-9 * p.length().max(1.0));
    }
}

/// Bug: verify measured the chord between two samples only against the segments of its two
/// ends. At 50 mm/s a 1 ms chord is 0.05 mm and spans three collinear 0.03 mm lines; its
/// midpoint lies on the middle one, up to 0.015 mm beyond the ends of the outer two, and was
/// reported as a deviation above the 0.01 mm tolerance although every chord lies on the path.
#[test]
fn chords_across_several_short_segments_are_measured_against_all_of_them() {
    let mut moves = vec![f(1, 3000.0)];
    for k in 0..200u32 {
        moves.push(feed(2 + k, 0.03 * (k + 1) as f64, 0.0, 0.0));
    }
    let out = run_moves(&moves);
    let top = out.samples.iter().map(|s| s.feed).fold(0.0, f64::max);
    assert!((top - 50.0).abs() < 1e-9, "reaches the feed: {top}");
    assert!(
        out.report.max_deviation < 1e-12,
        "{} at line {}",
        out.report.max_deviation,
        out.report.max_deviation_line
    );
}

/// G95: F in mm per spindle revolution, times the programmed S. A 30 mm line at F0.1 mm/rev
/// and S2000 runs at 200 mm/min = 3.333 mm/s: 9 s plus the speed's rise and fall (well under
/// 0.1 s at mill3's accelerations); at S1000 twice as long. Without S the move is refused.
#[test]
fn feed_per_revolution_is_f_times_the_spindle_speed() {
    let moves = |rpm: Option<f64>| {
        let mut m = vec![
            Move {
                line: 1,
                kind: MoveKind::FeedMode(FeedMode::UnitsPerRevolution),
            },
            Move {
                line: 1,
                kind: MoveKind::FeedRate { value: 0.1 },
            },
        ];
        if let Some(rpm) = rpm {
            m.push(Move {
                line: 1,
                kind: MoveKind::SpindleSpeed { rpm },
            });
        }
        m.push(Move {
            line: 2,
            kind: MoveKind::Feed {
                end: Pose([30.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            },
        });
        m
    };
    let fast = run_moves(&moves(Some(2000.0)));
    assert_within_limits(&fast);
    assert!((9.0..9.1).contains(&fast.duration), "{}", fast.duration);
    let slow = run_moves(&moves(Some(1000.0)));
    assert!((18.0..18.1).contains(&slow.duration), "{}", slow.duration);
    let refused = build(&moves(None), Pose::ZERO, DirectOptions::default());
    assert!(refused.unwrap_err().to_string().contains("G95"));
}
