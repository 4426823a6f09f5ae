//! Cartesian machine: X Y Z position the spindle gauge point directly, further joints are
//! independent (rotary or linear) axes that do not move the tool. The default machine
//! (`machines/mill3.toml`); the identity map of the data flow's inverse step. Its
//! `[kinematics]` section has only `axis_tolerance_deg`.

use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use tezgah_geom::Axis;

use crate::error::KinematicsError;
use crate::kinematics::{
    check_input, check_pose, check_tip, check_vertical_axis, Jacobian, Kinematics, Tolerances,
};
use crate::machine::{check_joint_kinds, invalid, limits, refused, tolerances};
use crate::machine::{FromSection, Joint, MachineError};
use crate::pose::{check_limits, JointKind, JointLimit, Joints, Tool, ToolPose};

/// X Y Z plus independent axes; the tool axis is always workpiece +Z.
#[derive(Clone, Debug)]
pub struct Cartesian {
    limits: Vec<JointLimit>,
    axis_sin: f64,
    /// The program axis of each joint after X Y Z: from the machine file, the one the joint's
    /// name gives (`a`, `b` or `c`, as a controller's axis letters), else none.
    extra_axes: Vec<Option<Axis>>,
}

/// `[kinematics]` of a `cartesian` machine.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CartesianSection {
    /// Largest angle between a requested tool axis and +Z, degrees.
    axis_tolerance_deg: Option<f64>,
}

impl FromSection for Cartesian {
    type Section = CartesianSection;

    /// X Y Z linear, then up to [`crate::pose::MAX_JOINTS`] in all.
    fn from_section(
        kind: &'static str,
        section: CartesianSection,
        joints: &[Joint],
    ) -> Result<Self, MachineError> {
        if joints.len() < 3 || joints.len() > crate::pose::MAX_JOINTS {
            return Err(invalid(
                "joint",
                format!(
                    "{kind} needs 3 to {} joints, the file has {}",
                    crate::pose::MAX_JOINTS,
                    joints.len()
                ),
            ));
        }
        check_joint_kinds(kind, &joints[..3], &[JointKind::Linear; 3])?;
        let tolerances = tolerances(section.axis_tolerance_deg, None, None)?;
        let mut model =
            Cartesian::new(limits(joints), tolerances).map_err(refused("kinematics"))?;
        model.extra_axes = joints[3..]
            .iter()
            .map(|j| match j.name.to_ascii_lowercase().as_str() {
                "a" => Some(Axis::A),
                "b" => Some(Axis::B),
                "c" => Some(Axis::C),
                _ => None,
            })
            .collect();
        Ok(model)
    }
}

impl Cartesian {
    /// A Cartesian machine; joints 0–2 are X Y Z (linear), the rest independent (carrying no
    /// program axis: a machine file names theirs).
    /// Fails unless there are 3 to [`crate::pose::MAX_JOINTS`] joints.
    pub fn new(limits: Vec<JointLimit>, tolerances: Tolerances) -> Result<Self, KinematicsError> {
        if limits.len() < 3 || limits.len() > crate::pose::MAX_JOINTS {
            return Err(KinematicsError::BadInput {
                reason: format!("cartesian needs 3 to 6 joints, got {}", limits.len()),
            });
        }
        Ok(Self {
            extra_axes: vec![None; limits.len() - 3],
            limits,
            axis_sin: tolerances.axis_rad.sin(),
        })
    }
}

impl Kinematics for Cartesian {
    fn joint_limits(&self) -> &[JointLimit] {
        &self.limits
    }

    fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError> {
        check_input(q, self.limits.len())?;
        Ok(ToolPose::vertical(Vector3::new(
            q[0],
            q[1],
            q[2] - tool.length,
        )))
    }

    fn inverse(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_pose(pose)?;
        check_input(previous, self.limits.len())?;
        check_vertical_axis(pose, self.axis_sin, "a Cartesian machine")?;
        let mut q = *previous;
        q[0] = pose.tip.x;
        q[1] = pose.tip.y;
        q[2] = pose.tip.z + tool.length;
        check_limits(&q, &self.limits)?;
        Ok(q)
    }

    fn tcp_angles(&self, q: &Joints) -> Joints {
        Joints::from_slice(&q.as_slice()[3.min(q.len())..]).unwrap_or(Joints::zeros(0))
    }

    fn tcp_inverse(
        &self,
        tip: &Vector3<f64>,
        angles: &Joints,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_tip(tip)?;
        check_input(previous, self.limits.len())?;
        check_input(angles, self.limits.len() - 3)?;
        let mut q = *previous;
        q[0] = tip.x;
        q[1] = tip.y;
        q[2] = tip.z + tool.length;
        q.as_mut_slice()[3..].copy_from_slice(angles.as_slice());
        check_limits(&q, &self.limits)?;
        Ok(q)
    }

    fn joint_axes(&self) -> Vec<Option<Axis>> {
        [Some(Axis::X), Some(Axis::Y), Some(Axis::Z)]
            .into_iter()
            .chain(self.extra_axes.iter().copied())
            .collect()
    }

    fn tcp_joints(&self) -> Vec<usize> {
        (3..self.limits.len()).collect()
    }

    fn jacobian(&self, q: &Joints, _tool: &Tool) -> Result<Jacobian, KinematicsError> {
        check_input(q, self.limits.len())?;
        let mut j = Jacobian::zeros(self.limits.len());
        j.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&Matrix3::identity());
        Ok(j)
    }
}
