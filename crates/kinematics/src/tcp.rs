//! Tool-centre-point control (Fanuc G43.4 type 1, LinuxCNC trt kinematics with the tool
//! offset): with TCP on, program coordinates are the tool tip in the workpiece frame plus the
//! rotary angles, the path is planned in that space and the joints follow through this map;
//! with TCP off, program axes are joints. The interpreter's G43.4 parsing lives elsewhere.

use nalgebra::Vector3;
use tezgah_geom::{Axis, Pose};

use crate::error::KinematicsError;
use crate::kinematics::Kinematics;
use crate::pose::{Joints, Tool, ToolPose};

/// A point of a TCP program: tip (mm, workpiece frame) and the model's program angles
/// ([`Kinematics::tcp_angles`], rad): (A, C) or (B, C) on a trunnion, (C, A) on Y-Z-C-A,
/// the extra joints on a Cartesian machine, none on a delta.
#[derive(Clone, Copy, PartialEq, Debug)]
pub struct ProgramPose {
    /// Tool tip, mm, workpiece frame.
    pub tip: Vector3<f64>,
    /// Program angles, rad.
    pub angles: Joints,
}

impl ProgramPose {
    /// The TCP program pose of an interpreter [`Pose`] (X Y Z in mm, A B C in degrees):
    /// the tip is X Y Z, the angles are the program axes `axes` in the model's order (see
    /// [`crate::machine::Machine::tcp_axes`]), converted to radians.
    pub fn from_program(pose: &Pose, axes: &[Axis]) -> Result<Self, KinematicsError> {
        let mut angles = Joints::zeros(axes.len());
        for (v, a) in angles.as_mut_slice().iter_mut().zip(axes) {
            if a.is_linear() {
                return Err(KinematicsError::BadInput {
                    reason: format!("{} is not an orientation axis", a.letter()),
                });
            }
            *v = pose[*a].to_radians();
        }
        if axes.len() > crate::pose::MAX_JOINTS {
            return Err(KinematicsError::BadInput {
                reason: "too many orientation axes".into(),
            });
        }
        Ok(Self {
            tip: Vector3::new(pose.x(), pose.y(), pose.z()),
            angles,
        })
    }

    /// Back to an interpreter [`Pose`] (angles in degrees; axes not listed are zero).
    pub fn to_program(&self, axes: &[Axis]) -> Pose {
        let mut p = Pose::new(self.tip.x, self.tip.y, self.tip.z, 0.0, 0.0, 0.0);
        for (v, a) in self.angles.as_slice().iter().zip(axes) {
            p[*a] = v.to_degrees();
        }
        p
    }

    /// Linear interpolation of tip and angles: the TCP path between two program points.
    pub fn lerp(&self, other: &ProgramPose, t: f64) -> ProgramPose {
        ProgramPose {
            tip: self.tip + (other.tip - self.tip) * t,
            angles: self.angles.lerp(&other.angles, t),
        }
    }
}

/// The TCP transform of one machine with one tool: program pose ↔ joints.
#[derive(Clone, Copy, Debug)]
pub struct Tcp<'a, K: Kinematics + ?Sized> {
    kinematics: &'a K,
    tool: Tool,
}

impl<'a, K: Kinematics + ?Sized> Tcp<'a, K> {
    /// TCP on `kinematics` with the tool of the tool table (its length enters the tip).
    pub fn new(kinematics: &'a K, tool: Tool) -> Self {
        Self { kinematics, tool }
    }

    /// The tool in use.
    pub fn tool(&self) -> Tool {
        self.tool
    }

    /// Program pose → joints (limits checked). `previous` resolves what the program leaves
    /// open (e.g. turns on a Y-Z-C-A table).
    pub fn joints(&self, p: &ProgramPose, previous: &Joints) -> Result<Joints, KinematicsError> {
        self.kinematics
            .tcp_inverse(&p.tip, &p.angles, &self.tool, previous)
    }

    /// Joints → program pose.
    pub fn program(&self, q: &Joints) -> Result<ProgramPose, KinematicsError> {
        let pose = self.kinematics.forward(q, &self.tool)?;
        Ok(ProgramPose {
            tip: pose.tip,
            angles: self.kinematics.tcp_angles(q),
        })
    }

    /// Program pose → tool pose (tip and axis) in the workpiece frame.
    pub fn tool_pose(
        &self,
        p: &ProgramPose,
        previous: &Joints,
    ) -> Result<ToolPose, KinematicsError> {
        let q = self.joints(p, previous)?;
        self.kinematics.forward(&q, &self.tool)
    }
}
