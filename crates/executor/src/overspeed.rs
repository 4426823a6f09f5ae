//! How much faster than planned a piece may be re-timed (feed override above 100 % on moves
//! already planned): the path limits that hold at any speed up to the machine's, not only up
//! to the programmed feed. The time scale ([`crate::scale`]) lets r exceed 1 only where the
//! re-timed state stays within these.
//!
//! Where a segment's joints move linearly along the path (q'' = q''' = 0, motion's
//! `Geometry::curved` false) the path acceleration and jerk limits are A = minᵢ Aᵢ/|q'ᵢ| and
//! J = minᵢ Jᵢ/|q'ᵢ| whatever the speed (the chain rule of `plan::limits` has no curvature
//! terms), so the planned A and J stand and only the speed limit rises, to minᵢ Vᵢ/|q'ᵢ|. On a
//! curved segment the curvature and cross terms grow with the speed, so its limits are derived
//! again by the planner's own rule (`segment_limits_at_feed`) for the feed at the highest
//! override: a speed cap from curvature, chord error and joint speeds, and the A and J that hold
//! at every speed up to it (lower than the planned ones; the time scale's check then keeps
//! r ≤ 1 where the plan already uses more). Junctions inside the piece cap the speed too.

use tezgah_motion::plan::limits::{analyse, junction_cap, segment_limits_at_feed};
use tezgah_motion::plan::{Piece, PlanMachine, PlanOptions};
use tezgah_motion::Limits;

use crate::speed_override::Override;

/// The limits of `piece` for speeds above its planned one, if it may run faster at all.
pub fn overspeed_limits(
    piece: &Piece,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> Option<Limits> {
    let n = machine.joint_count();
    let planned = &piece.limits;
    let (mut v, mut a, mut j) = (
        f64::INFINITY,
        planned.max_acceleration(),
        planned.max_jerk(),
    );
    let mut before = None;
    for seg in &piece.segments {
        let g = analyse(seg, machine).ok()?;
        if g.rotary_only {
            return None;
        }
        if g.curved() {
            let fast = segment_limits_at_feed(seg, &g, machine, options, true, MAX_FACTOR).ok()?;
            v = v.min(fast.limits.max_velocity());
            a = a.min(fast.limits.max_acceleration());
            j = j.min(fast.limits.max_jerk());
        } else {
            for i in 0..n.min(g.g1.len()) {
                if g.g1[i] > 0.0 {
                    v = v.min(machine.max_velocity[i] / g.g1[i]);
                }
            }
        }
        if let Some(prev) = &before {
            v = v.min(junction_cap(prev, &g, machine, options));
        }
        before = Some(g);
    }
    if !(v.is_finite() && v > planned.max_velocity()) {
        return None;
    }
    Limits::new(v, a, j).ok()
}

/// The highest override as a factor on the programmed feed.
const MAX_FACTOR: f64 = Override::MAX_PERCENT / 100.0;

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_geom::Pose;
    use tezgah_kinematics::Machine;
    use tezgah_motion::path::smooth::{self, SmoothOptions};
    use tezgah_motion::plan::{Planned, Planner};

    fn pieces(program: &str) -> (Vec<Piece>, PlanMachine, PlanOptions) {
        let m = Machine::default_machine();
        let pm = PlanMachine::from_machine(&m).unwrap();
        let opts = SmoothOptions::for_machine(&m.path, &pm, m.motion.tolerance_mm, Pose::ZERO);
        let moves = tezgah_gcode::program_moves(program, tezgah_gcode::Config::default()).unwrap();
        let items = smooth::build(moves, &opts).unwrap();
        let plan = PlanOptions::default();
        let mut planner = Planner::new(pm.clone(), plan).unwrap();
        for item in items {
            planner.push(item).unwrap();
        }
        planner.finish().unwrap();
        let mut out = vec![];
        while let Some(p) = planner.pop() {
            if let Planned::Motion(p) = p {
                out.push(*p);
            }
        }
        (out, pm, plan)
    }

    /// A line along X at F600 on mill3 (X: 200 mm/s): the speed limit rises from the feed,
    /// 10 mm/s, to the joint's 200 mm/s; A and J stay.
    #[test]
    fn lines_rise_to_the_joint_speed() {
        let (p, pm, plan) = pieces("G21 G90 F600\nG1 X50\nG2 X60 Y10 I0 J10\nM2\n");
        let line = &p[0];
        let fast = overspeed_limits(line, &pm, &plan).unwrap();
        assert!((line.limits.max_velocity() - 10.0).abs() < 1e-9);
        assert!((fast.max_velocity() - pm.max_velocity[0]).abs() < 1e-6);
        assert_eq!(fast.max_acceleration(), line.limits.max_acceleration());
        assert_eq!(fast.max_jerk(), line.limits.max_jerk());
    }

    /// An R10 arc at F600 (10 mm/s): at 200 % it may run at twice the feed, and the path
    /// acceleration it is given leaves room for the centripetal part at that speed, v²/R, in
    /// every joint (on an XY circle each joint's |q'| ≤ 1 and |q''| ≤ 1/R).
    #[test]
    fn arcs_rise_to_the_highest_override_with_room_for_the_centripetal_acceleration() {
        let (p, pm, plan) = pieces("G21 G90 F600\nG1 X50\nG2 X60 Y10 I0 J10\nM2\n");
        let arc = p
            .iter()
            .find(|q| q.segments.iter().all(|s| s.line == 3))
            .unwrap();
        let fast = overspeed_limits(arc, &pm, &plan).unwrap();
        let v = fast.max_velocity();
        assert!((v - 20.0).abs() < 1e-9, "{v}");
        assert!(fast.max_acceleration() <= arc.limits.max_acceleration());
        assert!(fast.max_jerk() <= arc.limits.max_jerk());
        for i in 0..2 {
            let centripetal = v * v / 10.0;
            assert!(
                centripetal + fast.max_acceleration() <= pm.max_acceleration[i] * (1.0 + 1e-12),
                "joint {i}: {centripetal} + {} > {}",
                fast.max_acceleration(),
                pm.max_acceleration[i]
            );
            // Jerk: v³/R² (the centripetal term's turning) + 3·v·A/R (cross) + J.
            let jerk = v * v * v / 100.0 + 3.0 * v * fast.max_acceleration() / 10.0;
            assert!(
                jerk + fast.max_jerk() <= pm.max_jerk[i] * (1.0 + 1e-12),
                "joint {i}: {jerk} + {} > {}",
                fast.max_jerk(),
                pm.max_jerk[i]
            );
        }
    }
}
