//! The machine as the planner sees it: for every joint, which path quantity drives it and its
//! velocity, acceleration and jerk limits in internal units (mm, rad, s).
//!
//! Cartesian machines: linear joints x y z follow the tool tip one to one (so a joint's
//! derivatives along the path are the components of the tip's), extra rotary joints follow the
//! programmed A B C linearly. Linear-delta machines (3-axis programs): the joints' derivatives
//! along the path are taken by differences of the inverse kinematics along each segment
//! (`numeric`). Five-axis models need the tool axis from A/B/C and are refused for now.

use tezgah_kinematics::{Machine, Model};

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
    /// The model, when joint derivatives are taken by differences of its inverse.
    pub numeric: Option<Model>,
}

impl PlanMachine {
    /// From a validated machine; refuses models whose joints are not the tip's coordinates.
    pub fn from_machine(machine: &Machine) -> Result<Self, PlanError> {
        let numeric = match machine.kinematics {
            Model::Cartesian(_) => None,
            Model::LinearDelta(_) => Some(machine.kinematics.clone()),
            _ => {
                return Err(PlanError::UnsupportedKinematics {
                    kind: machine.kinematics.type_name(),
                    supported: "cartesian and linear-delta",
                })
            }
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
        })
    }

    pub fn joint_count(&self) -> usize {
        self.map.len()
    }
}
