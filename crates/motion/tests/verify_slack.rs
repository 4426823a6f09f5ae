//! Slack in the replay: the time below the feed with no joint within 90 % of a limit, and the
//! time at each tenth of the feed. Synthetic samples of a known profile give closed forms; the
//! planner's own plans give the two ends: a feed far below the limits (slack only where the
//! jerk switches) and a feed above what the joints allow (cruise at a joint's limit: no slack).

use std::sync::Arc;

use tezgah_geom::{Line, ToolControl, Vec3};
use tezgah_geom::{Move, MoveKind, PathMode, Pose};
use tezgah_kinematics::{Joints, Machine};
use tezgah_motion::interpolate::{run, Sample};
use tezgah_motion::path::direct::{build, DirectOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::slack::BINS;
use tezgah_motion::verify::{Report, Verifier};
use tezgah_motion::{Junction, Segment, SegmentFeed};

const TS: f64 = 0.001;

/// A jerk-limited ramp from rest to `f` at constant jerk `j` (no constant-acceleration
/// phase: the double-S velocity profile of Biagiotti & Melchiorri, *Trajectory Planning for
/// Automatic Machines and Robots*, 2008, §3.4, with `a_max` not reached): duration
/// `T = 2√(f/j)`, position and speed at `t`.
struct Ramp {
    f: f64,
    j: f64,
}

impl Ramp {
    fn duration(&self) -> f64 {
        2.0 * (self.f / self.j).sqrt()
    }
    fn at(&self, t: f64) -> (f64, f64) {
        let (f, j, tr) = (self.f, self.j, self.duration());
        let h = 0.5 * tr;
        if t <= 0.0 {
            (0.0, 0.0)
        } else if t <= h {
            (j * t * t * t / 6.0, 0.5 * j * t * t)
        } else if t <= tr {
            let r = tr - t;
            // The S-curve is symmetric: half way in time is half the average speed's distance.
            (
                0.5 * f * tr - (f * r - j * r * r * r / 6.0),
                f - 0.5 * j * r * r,
            )
        } else {
            (0.5 * f * tr + f * (t - tr), f)
        }
    }
    /// Time into the ramp at which the speed is `frac · f`.
    fn time_at_fraction(&self, frac: f64) -> f64 {
        let tr = self.duration();
        if frac <= 0.5 {
            tr * (0.5 * frac).sqrt()
        } else {
            tr * (1.0 - (0.5 * (1.0 - frac)).sqrt())
        }
    }
}

/// Samples along X of ramp up, `cruise` s at `f`, ramp down, on one line segment fed as
/// `feed`, through the verifier of mill3 (joints x y z = the tip).
fn synthetic(ramp: &Ramp, cruise: f64, feed: SegmentFeed) -> (Report, usize) {
    let pm = PlanMachine::from_machine(&Machine::default_machine()).unwrap();
    let tr = ramp.duration();
    let end = 2.0 * tr + cruise;
    let length = ramp.f * (tr + cruise);
    let line = Line::new(Vec3::zeros(), Vec3::new(length, 0.0, 0.0)).unwrap();
    let seg = Arc::new(Segment {
        length,
        curve: Box::new(line),
        rotary: [[0.0; 3]; 2],
        line: 1,
        feed,
        end: Junction::Stop,
        tolerance: 0.01,
        control: ToolControl::OFF,
        feed_override: true,
        tool_axis_travel: None,
        axis: None,
    });
    let mut v = Verifier::new(&pm, TS);
    let n = (end / TS).ceil() as usize;
    for k in 0..=n {
        let t = k as f64 * TS;
        let (x, speed) = if t <= tr + cruise {
            ramp.at(t)
        } else {
            let (x, s) = ramp.at(end - t);
            (length - x, s)
        };
        let s = Sample {
            index: k as u64,
            t,
            line: 1,
            tip: Vec3::new(x, 0.0, 0.0),
            rotary: [0.0; 3],
            joints: Joints::from_slice(&[x, 0.0, 0.0]).unwrap(),
            feed: speed,
        };
        v.push(&s, std::slice::from_ref(&seg));
    }
    (v.finish(), n + 1)
}

/// Ramps at half the jerk limit to a quarter of the velocity limit: no joint is ever within
/// 90 % of a limit, so every sample below the feed is slack — the two ramps, ⌈T/Ts⌉ samples
/// each (T = 2√(F/J′) is not on the grid and the cruise is); the histogram's bins hold the
/// closed-form time between the fractions, ±1 sample per ramp.
#[test]
fn slack_is_the_ramps_when_no_joint_is_near_a_limit() {
    let ramp = Ramp {
        f: 50.0,
        j: 25_000.0,
    };
    let tr = ramp.duration();
    assert!((tr / TS).fract() > 0.1, "the ramp ends between samples");
    let (r, n) = synthetic(&ramp, 1.0, SegmentFeed::Feed(50.0));
    let per_ramp = (tr / TS).ceil();
    assert!(
        (r.slack.slack - 2.0 * per_ramp * TS).abs() < 1e-12,
        "{:?}",
        r.slack
    );
    assert!((r.slack.moving - n as f64 * TS).abs() < 1e-12);
    assert!((r.slack.share(r.cycle_time) - 2.0 * per_ramp * TS / r.cycle_time).abs() < 1e-12);
    for i in 0..BINS - 1 {
        let dt =
            ramp.time_at_fraction((i + 1) as f64 / 10.0) - ramp.time_at_fraction(i as f64 / 10.0);
        let got = r.slack.histogram[i];
        assert!(
            (got - 2.0 * dt).abs() <= 2.0 * TS + 1e-12,
            "bin {i}: {got} against {}",
            2.0 * dt
        );
    }
    let cruise = r.slack.histogram[BINS - 1];
    assert!(
        (cruise - (n as f64 - 2.0 * per_ramp) * TS).abs() < 1e-12,
        "{cruise}"
    );
}

/// The same samples under G93: the segment's nominal speed is its length over its time, here
/// chosen 50 mm/s, so the slack and the histogram are those of the feed's.
#[test]
fn inverse_time_is_measured_against_length_over_time() {
    let ramp = Ramp {
        f: 50.0,
        j: 25_000.0,
    };
    let (by_feed, _) = synthetic(&ramp, 1.0, SegmentFeed::Feed(50.0));
    let length = ramp.f * (ramp.duration() + 1.0);
    let (by_time, _) = synthetic(&ramp, 1.0, SegmentFeed::InverseTime(length / 50.0));
    assert_eq!(by_feed.slack, by_time.slack);
    // At half the feed in time, the cruise falls in [0.5, 0.6).
    let (slow, n) = synthetic(&ramp, 1.0, SegmentFeed::InverseTime(length / 100.0));
    assert!((slow.slack.slack - n as f64 * TS).abs() < 1e-12);
    assert!(
        slow.slack.histogram[5] >= 1.0 - 1e-9,
        "{:?}",
        slow.slack.histogram
    );
}

/// The same samples as a rapid: the nominal speed is where the first joint reaches its
/// velocity limit (200 mm/s for X), so the cruise at 50 mm/s is at a quarter of it, and with
/// no joint near a limit the whole cycle is slack.
#[test]
fn a_rapid_is_measured_against_the_joint_velocity_limit() {
    let ramp = Ramp {
        f: 50.0,
        j: 25_000.0,
    };
    let (r, n) = synthetic(&ramp, 1.0, SegmentFeed::Rapid);
    assert!(
        (r.slack.slack - n as f64 * TS).abs() < 1e-12,
        "{:?}",
        r.slack
    );
    // 1 s of cruise at 0.25: bin [0.2, 0.3).
    assert!(
        r.slack.histogram[2] >= 1.0 - 1e-9,
        "{:?}",
        r.slack.histogram
    );
    assert_eq!(r.slack.histogram[BINS - 1], 0.0);
}

/// A long G1 along X on mill3 (G61.1), planned and sampled.
fn planned(feed_mm_min: f64) -> Report {
    let machine = Machine::default_machine();
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let moves = vec![
        Move {
            line: 1,
            kind: MoveKind::PathMode(PathMode::ExactStop),
        },
        Move {
            line: 2,
            kind: MoveKind::FeedRate { value: feed_mm_min },
        },
        Move {
            line: 3,
            kind: MoveKind::Feed {
                end: Pose([150.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            },
        },
    ];
    let items = build(&moves, Pose::ZERO, DirectOptions::default()).unwrap();
    let mut v = Verifier::new(&pm, machine.motion.period_s);
    run(
        items,
        pm,
        PlanOptions::default(),
        (Vec3::zeros(), [0.0; 3]),
        |s, seg: &[Arc<Segment>]| v.push(s, seg),
    )
    .unwrap();
    v.finish()
}

/// F600 (10 mm/s, 5 % of X's velocity limit): a time-optimal ramp runs at the jerk limit
/// throughout (√(F·J) = 707 mm/s² < 90 % of A, no constant-acceleration phase), so the
/// slack is only where the finite-difference jerk crosses from one level to the next: at
/// most 3 samples at each of the 6 switches of the two ramps (the backward third difference
/// spans 3 periods).
#[test]
fn a_slow_feed_has_slack_only_at_the_jerk_switches() {
    let r = planned(600.0);
    let below: f64 = r.slack.histogram[..BINS - 1].iter().sum();
    // Two ramps of 2√(F/J) = 28.3 ms each: below the feed that long, ±2 samples.
    let ramps = 4.0 * (10.0f64 / 50_000.0).sqrt();
    assert!(
        (below - ramps).abs() <= 2.0 * TS + 1e-9,
        "{below} against {ramps}"
    );
    assert!(r.slack.slack <= 6.0 * 3.0 * TS + 1e-12, "{:?}", r.slack);
}

/// F60000 (1 000 mm/s) over X's 200 mm/s: the cruise is at the velocity limit, the ramps at
/// the acceleration or jerk limit, so no slack except where the jerk switches.
#[test]
fn a_feed_above_the_joints_has_no_slack() {
    let r = planned(60_000.0);
    let below: f64 = r.slack.histogram[..BINS - 1].iter().sum();
    assert!(
        below > 0.7,
        "the whole cycle is below the feed: {below} of {}",
        r.cycle_time
    );
    assert!(r.slack.slack <= 8.0 * 3.0 * TS + 1e-12, "{:?}", r.slack);
}
