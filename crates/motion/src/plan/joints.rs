//! The machine as the planner sees it: for every joint, which path quantity drives it and its
//! velocity, acceleration and jerk limits in internal units (mm, rad, s), under the tool
//! control in force on each segment (TCP on or off, [`ToolControl`]).
//!
//! Joints follow the path directly where they are program axes: on a Cartesian machine always
//! (x y z the tip's coordinates, with the tool length a constant along Z; extra rotaries the
//! programmed A B C), and on a machine whose rotaries orient the tool when TCP is off (joints
//! driven by the program axes of their names). Otherwise — TCP on, or a delta — the joints
//! are the tool-centre-point inverse of the program pose (tip + the model's program angles,
//! `tezgah_kinematics::tcp`, with the tool length along the tool axis), and their derivatives
//! along the path are taken by differences of that map along each segment (`limits`).

use tezgah_geom::{Axis, Pose, ToolControl, Vec3};
use tezgah_kinematics::tcp::ProgramPose;
use tezgah_kinematics::{
    Joints, Kinematics, KinematicsError, Machine, Model, TcpSwitch, Tool, ToolPose,
};

use crate::path::orient::{AxisPath, GreatCircle, ProgramPoint, ToolAxisMap};

use super::PlanError;

/// Steps along a rotary-only segment at which the tool axis is sampled to measure its turn:
/// between samples the axis path is close to a great circle, so the sum of the angles between
/// consecutive axes is within ~1e-4 (relative) of its turn at 64 steps.
const SWEEP_STEPS: usize = 64;
use crate::path::Segment;

/// A program axis "moves" along a segment when its ends or middle differ by more than this
/// (mm or degrees): round-off of the path builders, far below any resolution.
const STILL: f64 = 1e-9;

/// What drives a joint when it follows the path directly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointMap {
    /// Tip coordinate 0, 1 or 2 (mm).
    Tip(usize),
    /// Programmed rotary axis 0, 1 or 2 (A, B, C; degrees in the program, rad in the joint).
    Rotary(usize),
}

/// Joint maps and limits (internal units).
#[derive(Debug, Clone)]
pub struct PlanMachine {
    /// The model (forward and inverse kinematics).
    pub model: Model,
    /// Program axes → joints where the joints follow them directly: a Cartesian machine's
    /// joints, or with TCP off the joints of a machine whose rotaries orient the tool (the
    /// model's [`Kinematics::joint_axes`]; `None` where a joint carries no program axis).
    pub map: Option<Vec<JointMap>>,
    pub max_velocity: Vec<f64>,
    pub max_acceleration: Vec<f64>,
    pub max_jerk: Vec<f64>,
    /// The program axes carrying the model's TCP angles (`Machine::tcp_axes`).
    pub axes: Vec<Axis>,
    /// The tool control before the program says otherwise (machine file `tcp`).
    pub initial: ToolControl,
}

impl PlanMachine {
    /// From a validated machine; refuses models whose joints cannot follow program axes.
    pub fn from_machine(machine: &Machine) -> Result<Self, PlanError> {
        let axes = machine
            .tcp_axes()
            .map_err(|_| PlanError::UnsupportedKinematics {
                kind: machine.kinematics.type_name(),
                supported: "machines whose rotary joints carry program axes",
            })?;
        // The model's own joint-to-axis map: a joint that no program axis names (a delta's
        // carriages) leaves the joints to the inverse kinematics.
        let map: Option<Vec<JointMap>> = machine
            .kinematics
            .joint_axes()
            .into_iter()
            .map(|axis| {
                axis.map(|x| match x.index() {
                    i @ 0..=2 => JointMap::Tip(i),
                    i => JointMap::Rotary(i - 3),
                })
            })
            .collect();
        let (mut v, mut a, mut j) = (vec![], vec![], vec![]);
        for joint in &machine.joints {
            let s = joint.to_internal();
            v.push(joint.max_velocity * s);
            a.push(joint.max_acceleration * s);
            j.push(joint.max_jerk * s);
        }
        Ok(PlanMachine {
            model: machine.kinematics.clone(),
            map,
            max_velocity: v,
            max_acceleration: a,
            max_jerk: j,
            axes,
            initial: match machine.tcp {
                TcpSwitch::Program => ToolControl::OFF,
                TcpSwitch::Always => ToolControl::CentrePoint { tool_length: 0.0 },
            },
        })
    }

    /// The least change of joint `i` between neighbouring samples, in the joint's own unit
    /// (mm or rad), that the joint-jump rule reads as motion: what the joint moves in
    /// [`JUMP_FLOOR_S`] at its top speed. Smaller changes are the inverse kinematics' rounding
    /// (C moves 1e-9 rad where a path arrives exactly at table-bc's pole), which halving the
    /// step does not halve either; a true jump (C turning 180° across a pole) is millions of
    /// times larger.
    pub fn jump_floor(&self, i: usize) -> f64 {
        self.max_velocity[i] * JUMP_FLOOR_S
    }

    pub fn joint_count(&self) -> usize {
        self.max_velocity.len()
    }

    /// Whether the rotary joints orient the tool (trunnions, Y-Z-C-A): only there does
    /// switching TCP change what the program axes mean.
    fn orients(&self) -> bool {
        !matches!(self.model, Model::Cartesian(_) | Model::LinearDelta(_))
    }

    /// Whether the program angles alone give the tool axis, which the path can then carry as
    /// a vector: the five-axis trunnions. Not Y-Z-C-A, a four-axis machine whose C follows the
    /// tip (the axis must stay in the plane through the tip and the C axis, so a vector
    /// interpolated freely between two reachable axes is not reachable in between).
    fn carries_axis(&self) -> bool {
        matches!(self.model, Model::TableAc(_) | Model::TableBc(_))
    }

    /// The tool axis (workpiece frame) and the joints of the program point (`tip`, A B C)
    /// under tool-centre-point control with a tool `tool_length` long, joints nearest
    /// `previous`; `None` out of reach.
    fn axis_of(
        &self,
        tool_length: f64,
        tip: &Vec3,
        rotary: &[f64; 3],
        previous: &Joints,
    ) -> Option<(Vec3, Joints)> {
        let control = ToolControl::CentrePoint { tool_length };
        let q = self.joints(control, tip, rotary, previous).ok()?;
        let pose = self
            .model
            .forward(&q, &Tool::with_length(tool_length))
            .ok()?;
        Some((pose.axis.into_inner(), q))
    }

    /// The angle (degrees) the tool axis turns through along a rotary-only segment under
    /// tool-centre-point control on a machine whose rotaries orient the tool: the length of
    /// its path on the unit sphere, summed over [`SWEEP_STEPS`] steps of the program angles
    /// (which move linearly). `None` for any other segment, or where the axis stands still
    /// (C turning at the pole): the axes' own travel times those.
    pub fn tool_axis_sweep(&self, seg: &Segment) -> Option<f64> {
        let ToolControl::CentrePoint { tool_length } = seg.control else {
            return None;
        };
        if !seg.rotary_only() || !self.orients() {
            return None;
        }
        // The axis on a great circle: its turn is the circle's angle.
        if let Some(AxisPath::Rotate(g)) = seg.axis {
            let degrees = g.angle().to_degrees();
            return (degrees > 1e-9).then_some(degrees);
        }
        let tip = seg.curve.point(seg.curve.domain().0);
        let [r0, r1] = seg.rotary;
        let mut previous = Joints::zeros(self.joint_count());
        let mut axis_at = |f: f64| -> Option<Vec3> {
            let rotary = [0, 1, 2].map(|i| r0[i] + (r1[i] - r0[i]) * f);
            let (axis, q) = self.axis_of(tool_length, &tip, &rotary, &previous)?;
            previous = q;
            Some(axis)
        };
        let mut last = axis_at(0.0)?;
        let mut sweep = 0.0;
        for k in 1..=SWEEP_STEPS {
            let next = axis_at(k as f64 / SWEEP_STEPS as f64)?;
            sweep += last.angle(&next);
            last = next;
        }
        let degrees = sweep.to_degrees();
        (degrees > 1e-9).then_some(degrees)
    }

    /// The direct map under `control`, or `None` where the joints come from the TCP inverse.
    pub fn map_for(&self, control: ToolControl) -> Option<&[JointMap]> {
        let direct = match self.model {
            Model::Cartesian(_) => true,
            Model::LinearDelta(_) => false,
            _ => control.is_joints(),
        };
        if direct {
            self.map.as_deref()
        } else {
            None
        }
    }

    /// With TCP off on a machine whose rotaries orient the tool, a program axis without a
    /// joint of its name (X on Y-Z-C-A, B on table-ac) cannot move: refused, not ignored.
    pub fn check_axes(&self, seg: &Segment) -> Result<(), PlanError> {
        let Some(map) = self.map.as_deref() else {
            return Ok(());
        };
        if !seg.control.is_joints() || !self.orients() {
            return Ok(());
        }
        let (a, b) = seg.curve.domain();
        let ends = [
            seg.curve.point(a),
            seg.curve.point(0.5 * (a + b)),
            seg.curve.point(b),
        ];
        for axis in Axis::ALL {
            let i = axis.index();
            let driven = map.iter().any(|m| match *m {
                JointMap::Tip(j) => j == i,
                JointMap::Rotary(k) => k + 3 == i,
            });
            let moves = if axis.is_linear() {
                ends.iter().any(|p| (p[i] - ends[0][i]).abs() > STILL)
            } else {
                (seg.rotary[1][i - 3] - seg.rotary[0][i - 3]).abs() > STILL
            };
            if moves && !driven {
                return Err(PlanError::NoJoint {
                    line: seg.line,
                    axis: axis.letter(),
                });
            }
        }
        Ok(())
    }

    /// Joints for the tip (mm) and A B C (degrees) under `control`, nearest `previous`;
    /// every limit checked.
    pub fn joints(
        &self,
        control: ToolControl,
        tip: &Vec3,
        rotary: &[f64; 3],
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        if let Some(q) = self.cartesian_joints(control, tip, rotary, previous) {
            return Ok(q);
        }
        self.model_joints(control, tip, rotary, previous)
    }

    /// A Cartesian machine's inverse as `Cartesian::tcp_inverse` computes it — X Y Z the tip
    /// (Z plus the tool length under TCP), further joints the programmed rotaries in radians —
    /// without building a program pose and going through the model's input checks: the
    /// interpolator's per-sample call (half of a sample's cost on long lines and arcs). `None`
    /// (the caller then takes the model's path, and its error) unless the machine is
    /// Cartesian and every input and joint is finite and inside its limits.
    fn cartesian_joints(
        &self,
        control: ToolControl,
        tip: &Vec3,
        rotary: &[f64; 3],
        previous: &Joints,
    ) -> Option<Joints> {
        let (Model::Cartesian(_), Some(map)) = (&self.model, self.map.as_deref()) else {
            return None;
        };
        let limits = self.model.joint_limits();
        // The model refuses a non-finite tip (a NaN in a coordinate no joint carries).
        if limits.len() != map.len()
            || previous.len() != map.len()
            || !(tip.x.is_finite() && tip.y.is_finite() && tip.z.is_finite())
        {
            return None;
        }
        let length = match control {
            ToolControl::CentrePoint { tool_length } => tool_length,
            ToolControl::Joints { .. } => Tool::default().length,
        };
        // One pass over the joints, with the model's own input checks (`check_input`: every
        // previous joint finite) fused in: this runs once per sample.
        let mut q = Joints::zeros(map.len());
        for (((v, m), l), p) in q
            .as_mut_slice()
            .iter_mut()
            .zip(map)
            .zip(limits)
            .zip(previous.as_slice())
        {
            *v = match *m {
                JointMap::Tip(2) => tip.z + length,
                JointMap::Tip(i) => tip[i],
                JointMap::Rotary(k) => rotary[k].to_radians(),
            };
            // `contains` is false for a NaN, and an infinite value is inside no finite limit
            // but inside an endless one: hence the explicit finiteness test.
            if !(v.is_finite() && l.contains(*v) && p.is_finite()) {
                return None;
            }
        }
        Some(q)
    }

    /// [`Self::joints`] through the model: the program pose and the model's TCP inverse.
    fn model_joints(
        &self,
        control: ToolControl,
        tip: &Vec3,
        rotary: &[f64; 3],
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        let tool = match control {
            ToolControl::CentrePoint { tool_length } => Tool::with_length(tool_length),
            ToolControl::Joints { .. } if self.orients() => {
                let map = self
                    .map
                    .as_deref()
                    .ok_or_else(|| KinematicsError::BadInput {
                        reason: "with TCP off the program axes drive the joints of their names, \
                             and this machine's joints are not named x y z a b c"
                            .into(),
                    })?;
                let mut q = Joints::zeros(map.len());
                for (v, m) in q.as_mut_slice().iter_mut().zip(map) {
                    *v = match *m {
                        JointMap::Tip(i) => tip[i],
                        JointMap::Rotary(k) => rotary[k].to_radians(),
                    };
                }
                self.model.check_joints(&q)?;
                return Ok(q);
            }
            // Cartesian and delta: X Y Z are the gauge point (the G43 length already in Z).
            ToolControl::Joints { .. } => Tool::default(),
        };
        let pose = Pose::new(tip.x, tip.y, tip.z, rotary[0], rotary[1], rotary[2]);
        let p = ProgramPose::from_program(&pose, &self.axes)?;
        self.model.tcp_inverse(&p.tip, &p.angles, &tool, previous)
    }

    /// Joints and program angles (A B C, degrees) of `seg` at curve parameter `u` (tip `tip`)
    /// and fraction `f` of its length (or of its rotary travel), nearest `previous`: where the
    /// segment carries a tool axis ([`Segment::axis`], under TCP), the inverse kinematics of
    /// tip + axis, with the angles read back from the joints; otherwise A B C linear in `f`.
    /// The one place the planner and the interpolator turn a point of a segment into joints.
    pub fn segment_joints(
        &self,
        seg: &Segment,
        u: f64,
        f: f64,
        tip: &Vec3,
        previous: &Joints,
    ) -> Result<(Joints, [f64; 3]), KinematicsError> {
        let [r0, r1] = seg.rotary;
        let mut rotary = if f >= 1.0 {
            r1
        } else {
            [0, 1, 2].map(|i| r0[i] + (r1[i] - r0[i]) * f)
        };
        match (seg.axis, seg.control) {
            (Some(path), ToolControl::CentrePoint { tool_length }) if self.carries_axis() => {
                let pose = ToolPose::new(*tip, path.at(u, f));
                let q = self
                    .model
                    .inverse(&pose, &Tool::with_length(tool_length), previous)?;
                let angles = self.model.tcp_angles(&q);
                for (v, a) in angles.as_slice().iter().zip(&self.axes) {
                    rotary[a.index() - 3] = v.to_degrees();
                }
                Ok((q, rotary))
            }
            _ => {
                // The shortcut straight away: one `Result` layer less per sample.
                if let Some(q) = self.cartesian_joints(seg.control, tip, &rotary, previous) {
                    return Ok((q, rotary));
                }
                Ok((
                    self.model_joints(seg.control, tip, &rotary, previous)?,
                    rotary,
                ))
            }
        }
    }

    /// The program point (tip mm, A B C degrees) of joints `q` with TCP off: where a take-up
    /// move in joint mode starts and ends. Program axes without a joint read 0.
    pub fn joint_mode_point(&self, q: &Joints) -> Result<(Vec3, [f64; 3]), KinematicsError> {
        let mut tip = Vec3::zeros();
        let mut rotary = [0.0; 3];
        if !self.orients() {
            tip = self.model.forward(q, &Tool::default())?.tip;
        }
        for (v, m) in q.as_slice().iter().zip(self.map.iter().flatten()) {
            match *m {
                JointMap::Tip(i) if self.orients() => tip[i] = *v,
                JointMap::Tip(_) => {}
                JointMap::Rotary(k) => rotary[k] = v.to_degrees(),
            }
        }
        Ok((tip, rotary))
    }
}

/// The model's tool axis for program angles, under TCP on a machine whose rotaries orient the
/// tool: the smoothing builder's view of the machine.
impl ToolAxisMap for PlanMachine {
    fn axis(&self, control: ToolControl, tip: &Vec3, rotary: &[f64; 3]) -> Option<Vec3> {
        let ToolControl::CentrePoint { tool_length } = control else {
            return None;
        };
        if !self.carries_axis() {
            return None;
        }
        // The rotary joints are the angles themselves (no branch to choose), so the axis
        // depends on the angles alone, bit for bit.
        let zeros = Joints::zeros(self.joint_count());
        Some(self.axis_of(tool_length, tip, rotary, &zeros)?.0)
    }

    fn follows(
        &self,
        control: ToolControl,
        from: &ProgramPoint,
        to: &ProgramPoint,
        path: &GreatCircle,
    ) -> bool {
        let ToolControl::CentrePoint { tool_length } = control else {
            return false;
        };
        let tool = Tool::with_length(tool_length);
        let zeros = Joints::zeros(self.joint_count());
        let (Ok(start), Ok(end)) = (
            self.joints(control, &from.tip, &from.rotary, &zeros),
            self.joints(control, &to.tip, &to.rotary, &zeros),
        ) else {
            return false;
        };
        // Steps of at most FOLLOW_STEP of the axis's turn: the nearest solution then tracks
        // the branch the interpolator's 1 ms samples follow.
        let steps = ((path.angle() / FOLLOW_STEP).ceil() as usize).max(8);
        let at = |f: f64, previous: &Joints| {
            let tip = from.tip + (to.tip - from.tip) * f;
            self.model
                .inverse(&ToolPose::new(tip, path.at(f)), &tool, previous)
                .ok()
        };
        let mut q = start;
        for k in 1..=steps {
            let (f0, f1) = ((k - 1) as f64 / steps as f64, k as f64 / steps as f64);
            let Some(next) = at(f1, &q) else {
                return false;
            };
            // A joint that jumps (leaving the pole, where C is free, toward another C) does
            // not halve its change when the step is halved, as a smooth joint does. The
            // joint that moves most is the one furthest over its own floor (mm and rad are
            // not compared).
            let (i, over) = (0..q.len())
                .map(|i| (i, (next[i] - q[i]).abs() / self.jump_floor(i)))
                .fold((0, 0.0), |m, x| if x.1 > m.1 { x } else { m });
            let big = (next[i] - q[i]).abs();
            if over > 1.0 {
                let Some(mid) = at(0.5 * (f0 + f1), &q) else {
                    return false;
                };
                if (mid[i] - q[i]).abs().max((next[i] - mid[i]).abs()) > 0.9 * big {
                    return false;
                }
            }
            q = next;
        }
        // The walk ends on the programmed tip and axis exactly, so on the programmed joints
        // up to rounding when it kept their branch and turns.
        (0..self.joint_count()).all(|i| (q[i] - end[i]).abs() <= FOLLOW_MATCH)
    }
}

/// Time (s) in which a joint at its top speed moves [`PlanMachine::jump_floor`]: a thousandth
/// of a 1 ms interpolation period, far below any move a period can show.
const JUMP_FLOOR_S: f64 = 1e-6;
/// Largest turn of the tool axis (rad) between two steps of [`PlanMachine::follows`]'s walk.
const FOLLOW_STEP: f64 = 0.01;
/// How close (mm, rad) the walk's joints must end to the programmed ones.
const FOLLOW_MATCH: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// mill3, and mill3 with rotary A and C joints (a Cartesian machine with extra axes).
    fn machines() -> [PlanMachine; 2] {
        let text = Machine::builtin_text("mill3").expect("mill3 is built in");
        let rotary = |name: &str| {
            format!(
                "\n[[joint]]\nname = \"{name}\"\nkind = \"rotary\"\nmin = -120.0\nmax = 120.0\n\
                 max_velocity = 3600.0\nmax_acceleration = 36000.0\nmax_jerk = 360000.0\n"
            )
        };
        let five = format!("{text}{}{}", rotary("a"), rotary("c"));
        [text.to_string(), five].map(|t| {
            let m = Machine::from_toml_str(&t).expect("valid machine");
            PlanMachine::from_machine(&m).expect("Cartesian machines plan")
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The Cartesian shortcut gives the model's joints bit for bit, and where the model
        /// refuses (outside a limit, non-finite) it steps aside so the model's error is given.
        #[test]
        fn cartesian_shortcut_is_the_model_inverse(
            x in -260.0f64..260.0, y in -200.0f64..200.0, z in -130.0f64..130.0,
            a in -150.0f64..150.0, c in -150.0f64..150.0, length in 0.0f64..40.0,
            tcp: bool, nan in 0usize..12,
        ) {
            let mut tip = Vec3::new(x, y, z);
            let mut rotary = [a, 0.0, c];
            if nan < 3 {
                tip[nan] = f64::NAN;
            } else if nan == 3 {
                rotary[0] = f64::INFINITY;
            }
            let control = if tcp {
                ToolControl::CentrePoint { tool_length: length }
            } else {
                ToolControl::OFF
            };
            for pm in machines() {
                let previous = Joints::zeros(pm.joint_count());
                let fast = pm.joints(control, &tip, &rotary, &previous);
                let model = pm.model_joints(control, &tip, &rotary, &previous);
                match (&fast, &model) {
                    (Ok(f), Ok(m)) => {
                        let bits = |q: &Joints| {
                            q.as_slice().iter().map(|v| v.to_bits()).collect::<Vec<_>>()
                        };
                        prop_assert_eq!(bits(f), bits(m));
                    }
                    _ => prop_assert_eq!(&fast, &model),
                }
                let z_joint = z + if tcp { length } else { 0.0 };
                let rotaries_in = pm.joint_count() == 3 || (a.abs() < 120.0 && c.abs() < 120.0);
                let inside = x.abs() < 200.0 && y.abs() < 150.0 && z_joint.abs() < 100.0;
                // In limits and finite, the shortcut is the path taken (the test is not vacuous).
                if nan >= 4 && inside && rotaries_in {
                    prop_assert!(pm.cartesian_joints(control, &tip, &rotary, &previous).is_some());
                }
            }
        }
    }
}
