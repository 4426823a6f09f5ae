//! How much faster than planned a piece may be re-timed (feed override above 100 % on moves
//! already planned): the path limits that hold at any speed up to the machine's, not only up
//! to the programmed feed. The time scale ([`crate::scale`]) lets r exceed 1 only where the
//! re-timed state stays within these.
//!
//! Only pieces whose joints move linearly along the path (q'' = q''' = 0 on every segment,
//! motion's `Geometry::curved` false) qualify: there the path acceleration and jerk limits
//! are A = minᵢ Aᵢ/|q'ᵢ| and J = minᵢ Jᵢ/|q'ᵢ| whatever the speed (the chain rule of
//! `plan::limits` has no curvature terms), so the planned A and J stand and only the speed
//! limit rises, to minᵢ Vᵢ/|q'ᵢ| and the caps of the junctions inside the piece. On curved
//! segments A and J were derived at the planned speed (curvature and cross terms grow with it)
//! and the piece keeps r ≤ 1.

use tezgah_motion::plan::limits::{analyse, junction_cap};
use tezgah_motion::plan::{Piece, PlanMachine, PlanOptions};
use tezgah_motion::Limits;

/// The limits of `piece` for speeds above its planned one, if it may run faster at all.
pub fn overspeed_limits(
    piece: &Piece,
    machine: &PlanMachine,
    options: &PlanOptions,
) -> Option<Limits> {
    let n = machine.joint_count();
    let mut v = f64::INFINITY;
    let mut before = None;
    for seg in &piece.segments {
        let g = analyse(seg, machine).ok()?;
        if g.curved() || g.rotary_only {
            return None;
        }
        for i in 0..n.min(g.g1.len()) {
            if g.g1[i] > 0.0 {
                v = v.min(machine.max_velocity[i] / g.g1[i]);
            }
        }
        if let Some(prev) = &before {
            v = v.min(junction_cap(prev, &g, machine, options));
        }
        before = Some(g);
    }
    let planned = &piece.limits;
    if !(v.is_finite() && v > planned.max_velocity()) {
        return None;
    }
    Limits::new(v, planned.max_acceleration(), planned.max_jerk()).ok()
}

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
    /// 10 mm/s, to the joint's 200 mm/s; A and J stay. An arc keeps r ≤ 1.
    #[test]
    fn lines_rise_to_the_joint_speed_arcs_do_not() {
        let (p, pm, plan) = pieces("G21 G90 F600\nG1 X50\nG2 X60 Y10 I0 J10\nM2\n");
        let line = &p[0];
        let fast = overspeed_limits(line, &pm, &plan).unwrap();
        assert!((line.limits.max_velocity() - 10.0).abs() < 1e-9);
        assert!((fast.max_velocity() - pm.max_velocity[0]).abs() < 1e-6);
        assert_eq!(fast.max_acceleration(), line.limits.max_acceleration());
        assert_eq!(fast.max_jerk(), line.limits.max_jerk());
        let arc = p
            .iter()
            .find(|q| q.segments.iter().any(|s| s.line == 3))
            .unwrap();
        assert_eq!(overspeed_limits(arc, &pm, &plan), None);
    }
}
