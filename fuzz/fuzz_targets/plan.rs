//! Random valid moves through the whole motion chain as `tezgah run` builds it — smoothing,
//! feed planning, interpolation — and the replay: no panic, and every joint within its
//! velocity, acceleration and jerk at every sample (0.5 % for the finite differences). Each
//! 8-byte record is one move: kind, then x y z as signed 16-bit hundredths of a millimetre
//! (arcs take a centre offset from the fourth byte pair), feeds from one byte.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tezgah_geom::{ArcMove, Move, MoveKind, PathMode, Plane, Pose, Vec3};
use tezgah_kinematics::Machine;
use tezgah_motion::interpolate::run;
use tezgah_motion::path::smooth::{self, SmoothOptions};
use tezgah_motion::plan::{PlanMachine, PlanOptions};
use tezgah_motion::verify::Verifier;

fn moves(data: &[u8]) -> Vec<Move> {
    let mut out = vec![Move {
        line: 1,
        kind: MoveKind::FeedRate { value: 3000.0 },
    }];
    let mut at = Vec3::zeros();
    for (k, r) in data.chunks_exact(8).take(200).enumerate() {
        let line = k as u32 + 2;
        let c = |i: usize| f64::from(i16::from_le_bytes([r[i], r[i + 1]])) / 100.0;
        let end = Vec3::new(c(1), c(3), c(5) / 10.0);
        let pose = Pose::new(end.x, end.y, end.z, 0.0, 0.0, 0.0);
        let kind = match r[0] % 8 {
            0 => MoveKind::Rapid { end: pose },
            1 => MoveKind::FeedRate {
                value: 60.0 + 100.0 * f64::from(r[1]),
            },
            2 => MoveKind::PathMode(match r[1] % 3 {
                0 => PathMode::ExactPath,
                1 => PathMode::ExactStop,
                _ => PathMode::Continuous {
                    tolerance: Some(0.001 + f64::from(r[2]) / 1000.0),
                },
            }),
            3 | 4 => {
                // An arc from `at` about a centre off the chord, ending on its circle.
                let centre = [at.x + c(6), at.y + c(6) * 0.5];
                let r0 = ((at.x - centre[0]).powi(2) + (at.y - centre[1]).powi(2)).sqrt();
                let a = (end.y - centre[1]).atan2(end.x - centre[0]);
                if !(r0 > 1e-3) {
                    continue;
                }
                let e = Vec3::new(centre[0] + r0 * a.cos(), centre[1] + r0 * a.sin(), end.z);
                at = e;
                out.push(Move {
                    line,
                    kind: MoveKind::Arc(ArcMove {
                        plane: Plane::XY,
                        end: Pose::new(e.x, e.y, e.z, 0.0, 0.0, 0.0),
                        center: centre,
                        turn: if r[0] % 8 == 3 { 1 } else { -1 },
                    }),
                });
                continue;
            }
            _ => MoveKind::Feed { end: pose },
        };
        if matches!(kind, MoveKind::Rapid { .. } | MoveKind::Feed { .. }) {
            at = end;
        }
        out.push(Move { line, kind });
    }
    out
}

fuzz_target!(|data: &[u8]| {
    let moves = moves(data);
    let machine = Machine::default_machine();
    let Ok(items) = smooth::build(
        moves.into_iter(),
        &SmoothOptions {
            tolerance: machine.motion.tolerance_mm,
            start: Pose::ZERO,
            ..SmoothOptions::default()
        },
    ) else {
        return;
    };
    let pm = PlanMachine::from_machine(&machine).unwrap();
    let mut verifier = Verifier::new(&pm, machine.motion.period_s);
    let options = PlanOptions {
        period: machine.motion.period_s,
        chord_share: smooth::CHORD_SHARE,
        ..PlanOptions::default()
    };
    if run(items, pm, options, (Vec3::zeros(), [0.0; 3]), |s, segs| verifier.push(s, segs)).is_err() {
        return;
    }
    for j in verifier.finish().joints {
        assert!(j.worst_ratio() <= 1.005, "{j:?}");
    }
});
