//! Switching tool-centre-point control (G43.4 / G49) between the path stage and the planner:
//! where the control changes, the machine is at rest (the path builders end the segment before
//! with a stop) and the same program point may need other joints under the new reading — the
//! tool length now along the tool axis, or program axes now joints. This module inserts the
//! move that takes that difference up, straight in joint space, before the next segment.
//!
//! Straight in joint space keeps every joint between two values inside its limits, so the
//! take-up never leaves the machine's range; it runs at the rapid speed and ends at rest.

use std::sync::Arc;

use tezgah_geom::{Curve, Line, ToolControl, Vec3};
use tezgah_kinematics::{Joints, KinematicsError};

use crate::path::{Junction, PathItem, Segment, SegmentFeed};
use crate::plan::PlanMachine;

/// Joint differences at or below this (mm or rad) need no take-up: round-off of the two
/// inverse kinematics, far below any machine's resolution.
const SAME_JOINTS: f64 = 1e-9;

/// A switch whose take-up cannot be computed: the point is unreachable under one of the
/// two controls.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("line {line}: tool-centre-point switch: {source}")]
pub struct TakeUpError {
    pub line: u32,
    pub source: KinematicsError,
}

/// Watches the path items for control switches; [`TakeUp::before`] gives the take-up move to
/// run before an item, if one is needed.
#[derive(Debug)]
pub struct TakeUp {
    machine: Arc<PlanMachine>,
    control: ToolControl,
    /// The program point where the last segment ended (tip mm, A B C degrees) and the joints
    /// there, under `control`.
    end: (Vec3, [f64; 3]),
    joints: Joints,
}

impl TakeUp {
    /// Starting at `start` (tip, A B C) with joints `joints`, under the machine's initial
    /// control.
    pub fn new(machine: &PlanMachine, start: (Vec3, [f64; 3]), joints: Joints) -> Self {
        TakeUp {
            machine: Arc::new(machine.clone()),
            control: machine.initial,
            end: start,
            joints,
        }
    }

    /// Whether `item` is a segment under another reading of the program point than the one
    /// before (TCP switched, or its tool length changed): the machine is then at rest before
    /// it, and the caller may run everything before it and give the joints reached to
    /// [`TakeUp::before_from`].
    pub fn switches(&self, item: &PathItem) -> bool {
        matches!(item, PathItem::Segment(seg) if !seg.control.same_reading(&self.control))
    }

    /// The take-up segment to run before `item` (a segment under another control than the
    /// one before), or `None`. The old joints are worked out from the last segment's end,
    /// nearest the joints of the previous switch: exact where the program angles are the
    /// joints (trunnions), but an endless C that follows the tip (Y-Z-C-A) and turned more
    /// than half a turn since may come out a turn off; prefer [`TakeUp::before_from`] where
    /// the joints reached are known.
    pub fn before(&mut self, item: &PathItem) -> Result<Option<PathItem>, TakeUpError> {
        self.take_up(item, None)
    }

    /// As [`TakeUp::before`], from `reached`: the joints the machine actually stands at, at
    /// the end of the last segment (the interpolator's exact end pose, not a sample).
    pub fn before_from(
        &mut self,
        item: &PathItem,
        reached: &Joints,
    ) -> Result<Option<PathItem>, TakeUpError> {
        self.take_up(item, Some(reached))
    }

    fn take_up(
        &mut self,
        item: &PathItem,
        reached: Option<&Joints>,
    ) -> Result<Option<PathItem>, TakeUpError> {
        let PathItem::Segment(seg) = item else {
            return Ok(None);
        };
        let err = |source| TakeUpError {
            line: seg.line,
            source,
        };
        let (a, b) = seg.curve.domain();
        let start = (seg.curve.point(a), seg.rotary[0]);
        let mut out = None;
        if !seg.control.same_reading(&self.control) {
            let m = &self.machine;
            let old = match reached {
                Some(q) => *q,
                None => m
                    .joints(self.control, &self.end.0, &self.end.1, &self.joints)
                    .map_err(err)?,
            };
            let new = m
                .joints(seg.control, &start.0, &start.1, &old)
                .map_err(err)?;
            let moved = old
                .as_slice()
                .iter()
                .zip(new.as_slice())
                .any(|(p, q)| (p - q).abs() > SAME_JOINTS);
            if moved {
                out = Some(PathItem::Segment(
                    joint_line(m, &old, &new, seg).map_err(err)?,
                ));
            }
            self.joints = new;
        }
        // A new G43 length with TCP off reads the same joints: only remembered.
        self.control = seg.control;
        self.end = (seg.curve.point(b), seg.rotary[1]);
        Ok(out)
    }
}

/// A rapid straight in joint space from `from` to `to` (TCP off: the program axes are the
/// joints, or on a Cartesian machine or a delta the gauge point), at rest at both ends.
fn joint_line(
    m: &PlanMachine,
    from: &Joints,
    to: &Joints,
    next: &Segment,
) -> Result<Segment, KinematicsError> {
    let (p0, r0) = m.joint_mode_point(from)?;
    let (p1, r1) = m.joint_mode_point(to)?;
    let line = Line::new(p0, p1).map_err(|e| KinematicsError::BadInput {
        reason: e.to_string(),
    })?;
    Ok(Segment {
        length: line.length(),
        curve: Box::new(line),
        rotary: [r0, r1],
        line: next.line,
        feed: SegmentFeed::Rapid,
        end: Junction::Stop,
        tolerance: next.tolerance,
        control: ToolControl::OFF,
        feed_override: next.feed_override,
        tool_axis_travel: None,
        axis: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_kinematics::Machine;

    fn line(a: Vec3, b: Vec3, rotary: [f64; 3], control: ToolControl) -> PathItem {
        let l = Line::new(a, b).unwrap();
        PathItem::Segment(Segment {
            length: l.length(),
            curve: Box::new(l),
            rotary: [rotary, rotary],
            line: 1,
            feed: SegmentFeed::Rapid,
            end: Junction::Stop,
            tolerance: 0.01,
            control,
            feed_override: true,
            tool_axis_travel: None,
            axis: None,
        })
    }

    /// The take-up starts from the joints given as reached — here C a turn on from where the
    /// end point's joints alone would put it — and turns C back by that turn, not from the
    /// joints worked out from the program point.
    #[test]
    fn the_take_up_starts_from_the_joints_reached() {
        let pm = PlanMachine::from_machine(&Machine::builtin("table-ac").unwrap()).unwrap();
        let tcp = ToolControl::CentrePoint { tool_length: 35.0 };
        let (p, q) = (Vec3::new(10.0, 5.0, 20.0), Vec3::new(20.0, 5.0, 20.0));
        let rotary = [30.0, 0.0, 40.0];
        let start = pm
            .joints(ToolControl::OFF, &p, &rotary, &Joints::zeros(5))
            .unwrap();
        let mut takeup = TakeUp::new(&pm, (p, rotary), start);
        assert!(takeup.before(&line(p, q, rotary, tcp)).unwrap().is_some());
        let off = line(q, p, rotary, ToolControl::OFF);
        assert!(takeup.switches(&off));
        let mut reached = pm.joints(tcp, &q, &rotary, &start).unwrap();
        reached.as_mut_slice()[4] += std::f64::consts::TAU;
        let Some(PathItem::Segment(t)) = takeup.before_from(&off, &reached).unwrap() else {
            panic!("a take-up is needed");
        };
        assert!((t.rotary[0][2] - 400.0).abs() < 1e-9, "{:?}", t.rotary);
        assert!((t.rotary[1][2] - 40.0).abs() < 1e-9, "{:?}", t.rotary);
        let from = pm.joint_mode_point(&reached).unwrap().0;
        assert!((t.curve.point(t.curve.domain().0) - from).norm() < 1e-12);
    }
}
