//! The machine as the planner sees it: for every joint, which path quantity drives it and its
//! velocity, acceleration and jerk limits in internal units (mm, rad, s).
//!
//! Cartesian machines: linear joints x y z follow the tool tip one to one (so a joint's
//! derivatives along the path are the components of the tip's), extra rotary joints follow the
//! programmed A B C linearly. Every other model (delta, trunnions, Y-Z-C-A): the joints are
//! the tool-centre-point inverse of the program pose (tip + the model's program angles, see
//! `tezgah_kinematics::tcp`), and their derivatives along the path are taken by differences
//! of that map along each segment (`numeric`).

use tezgah_geom::{Axis, Pose, Vec3};
use tezgah_kinematics::tcp::ProgramPose;
use tezgah_kinematics::{Joints, Kinematics, KinematicsError, Machine, Model, Tool};

use super::PlanError;

/// What drives a joint.
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
    pub map: Vec<JointMap>,
    pub max_velocity: Vec<f64>,
    pub max_acceleration: Vec<f64>,
    pub max_jerk: Vec<f64>,
    /// The model, when joints come from its tool-centre-point inverse (not Cartesian).
    pub numeric: Option<Model>,
    /// The program axes carrying the model's TCP angles (`Machine::tcp_axes`).
    pub axes: Vec<Axis>,
}

impl PlanMachine {
    /// From a validated machine; refuses models whose joints are not the tip's coordinates.
    pub fn from_machine(machine: &Machine) -> Result<Self, PlanError> {
        let numeric = match machine.kinematics {
            Model::Cartesian(_) => None,
            _ => Some(machine.kinematics.clone()),
        };
        let axes = match numeric {
            Some(_) => machine
                .tcp_axes()
                .map_err(|_| PlanError::UnsupportedKinematics {
                    kind: machine.kinematics.type_name(),
                    supported: "machines whose rotary joints carry program axes",
                })?,
            None => vec![],
        };
        let mut map = Vec::with_capacity(machine.joints.len());
        let (mut v, mut a, mut j) = (vec![], vec![], vec![]);
        for (i, joint) in machine.joints.iter().enumerate() {
            map.push(if i < 3 || numeric.is_some() {
                JointMap::Tip(i)
            } else {
                // Cartesian extra joints are named a, b or c (kinematics README).
                let k = match joint.name.as_str() {
                    "b" => 1,
                    "c" => 2,
                    _ => 0,
                };
                JointMap::Rotary(k)
            });
            let s = joint.to_internal();
            v.push(joint.max_velocity * s);
            a.push(joint.max_acceleration * s);
            j.push(joint.max_jerk * s);
        }
        Ok(PlanMachine {
            map,
            max_velocity: v,
            max_acceleration: a,
            max_jerk: j,
            numeric,
            axes,
        })
    }

    pub fn joint_count(&self) -> usize {
        self.map.len()
    }
}

/// Joints of a non-Cartesian machine for the tip (mm) and A B C (degrees), nearest `previous`.
pub fn tcp_joints(
    model: &Model,
    axes: &[Axis],
    tip: &Vec3,
    rotary: &[f64; 3],
    previous: &Joints,
) -> Result<Joints, KinematicsError> {
    let pose = Pose::new(tip.x, tip.y, tip.z, rotary[0], rotary[1], rotary[2]);
    let p = ProgramPose::from_program(&pose, axes)?;
    model.tcp_inverse(&p.tip, &p.angles, &Tool::default(), previous)
}
