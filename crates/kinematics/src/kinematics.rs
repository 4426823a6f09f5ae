//! The `Kinematics` trait every machine model implements: forward, inverse with continuity,
//! the Jacobian, limits and the tool-centre-point (TCP) mapping. The planner calls it through
//! [`crate::machine::Machine`]; the interpolator calls `inverse` once per sample.

use nalgebra::{Matrix6xX, Vector3, Vector6};
use tezgah_geom::Axis;

use crate::error::KinematicsError;
use crate::pose::{check_limits, JointLimit, Joints, Tool, ToolPose};

/// ∂(tip, axis)/∂q: 6 rows (tip x y z, then axis x y z) by one column per joint.
pub type Jacobian = Matrix6xX<f64>;

/// Numerical tolerances of the inverse kinematics, explicit so that no model buries a literal.
#[derive(Clone, Copy, PartialEq, Debug)]
pub struct Tolerances {
    /// Largest angle (rad) between a requested tool axis and the nearest one the machine can
    /// produce before the pose is refused (e.g. a tilted axis on a 3-axis mill).
    pub axis_rad: f64,
    /// Half-angle (rad) of the cone around a table's C axis inside which C is undefined and
    /// the previous C is kept (the pole: near it dC ≈ |d(i, j)|/sin A, so a path passing close
    /// would swing C half a turn in one block; posts hold C inside a small cone).
    pub pole_cone_rad: f64,
    /// Distance (mm) from the C axis under which a tip is treated as on the axis (Y-Z-C-A).
    pub centre_mm: f64,
}

impl Default for Tolerances {
    /// 1e-9 rad and 1e-9 mm: far below any machining tolerance, far above `f64` round-off
    /// of the forward kinematics (≈1e-15 rad, ≈1e-13 mm at 500 mm).
    fn default() -> Self {
        Self {
            axis_rad: 1e-9,
            pole_cone_rad: 1e-9,
            centre_mm: 1e-9,
        }
    }
}

/// A machine model: joints ↔ tool pose in the workpiece frame.
///
/// Joint values are in internal units (mm, rad) in machine-file joint order. Models are
/// closed-form and allocation-free in `forward`/`inverse` so the 1 ms loop can afford them.
pub trait Kinematics {
    /// Limits of every joint, in machine-file order and internal units.
    fn joint_limits(&self) -> &[JointLimit];

    /// Number of joints.
    fn joint_count(&self) -> usize {
        self.joint_limits().len()
    }

    /// Joints → tool tip and tool axis in the workpiece frame.
    fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError>;

    /// Tool pose → joints. Among the solutions (tilt branch, turns of endless or wide-range
    /// rotaries) the one nearest `previous` that respects every joint limit is returned; if
    /// none does, the error names the nearest solution's violated joint.
    fn inverse(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError>;

    /// The program's orientation coordinates for these joints under tool-centre-point control
    /// (the rotary joints that the program names, in joint order; empty for a delta).
    fn tcp_angles(&self, q: &Joints) -> Joints;

    /// Tool-centre-point inverse (G43.4 style): the program gives the tip in the workpiece
    /// frame and the rotary angles of [`Kinematics::tcp_angles`]; the linear joints follow.
    fn tcp_inverse(
        &self,
        tip: &Vector3<f64>,
        angles: &Joints,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError>;

    /// The program axis each joint carries when the program drives the joints directly (TCP
    /// off), in joint order; `None` for a joint no program axis names (a delta's carriages).
    /// The model's joint-to-axis map: it says which joint is Z (homed first), and with
    /// [`Kinematics::tcp_joints`] which program axes the machine has.
    fn joint_axes(&self) -> Vec<Option<Axis>>;

    /// The joints whose values [`Kinematics::tcp_angles`] returns, in that order: the rotary
    /// joints that tool-centre-point control takes from the program (their program axes are
    /// [`Kinematics::joint_axes`] of these joints).
    fn tcp_joints(&self) -> Vec<usize>;

    /// ∂(tip, axis)/∂q at `q` (analytic).
    fn jacobian(&self, q: &Joints, tool: &Tool) -> Result<Jacobian, KinematicsError>;

    /// Joint rates q̇ for a tip velocity and axis rate: the least-squares solution of
    /// J·q̇ = (ṗ, ȧ) via SVD, exact when the motion is feasible.
    fn joint_velocity(
        &self,
        q: &Joints,
        tool: &Tool,
        tip_velocity: &Vector3<f64>,
        axis_velocity: &Vector3<f64>,
        singular_tolerance: f64,
    ) -> Result<Joints, KinematicsError> {
        let j = self.jacobian(q, tool)?;
        let rhs = Vector6::new(
            tip_velocity.x,
            tip_velocity.y,
            tip_velocity.z,
            axis_velocity.x,
            axis_velocity.y,
            axis_velocity.z,
        );
        let svd = j.svd(true, true);
        let smax = svd.singular_values.max();
        let smin = svd.singular_values.min();
        if smax <= 0.0 || smin <= singular_tolerance * smax {
            return Err(KinematicsError::Singular {
                reason: format!(
                    "Jacobian condition {:.3e}",
                    smin / smax.max(f64::MIN_POSITIVE)
                ),
            });
        }
        let x = svd
            .solve(&rhs, 0.0)
            .map_err(|e| KinematicsError::Singular { reason: e.into() })?;
        Joints::from_slice(x.as_slice())
    }

    /// Every joint within its limits.
    fn check_joints(&self, q: &Joints) -> Result<(), KinematicsError> {
        check_limits(q, self.joint_limits())
    }
}

/// Picks the candidate nearest `previous` (sum of |Δ| over the given joints) among those
/// inside every limit; the error is the violation of the nearest candidate overall.
///
/// Shared by every model that has more than one inverse solution.
pub(crate) fn choose_nearest(
    candidates: &[Option<Joints>],
    first_error: Option<KinematicsError>,
    previous: &Joints,
    compare: &[usize],
    limits: &[JointLimit],
) -> Result<Joints, KinematicsError> {
    let mut best: Option<(f64, Joints)> = None;
    let mut nearest_bad: Option<(f64, KinematicsError)> = None;
    for c in candidates.iter().flatten() {
        let cost: f64 = compare
            .iter()
            .map(|&i| (c[i] - previous.as_slice().get(i).copied().unwrap_or(0.0)).abs())
            .sum();
        match check_limits(c, limits) {
            Ok(()) => {
                if best.as_ref().is_none_or(|(b, _)| cost < *b) {
                    best = Some((cost, *c));
                }
            }
            Err(e) => {
                if nearest_bad.as_ref().is_none_or(|(b, _)| cost < *b) {
                    nearest_bad = Some((cost, e));
                }
            }
        }
    }
    match (best, nearest_bad, first_error) {
        (Some((_, q)), _, _) => Ok(q),
        (None, Some((_, e)), _) => Err(e),
        (None, None, Some(e)) => Err(e),
        (None, None, None) => Err(KinematicsError::Unreachable {
            reason: "no inverse solution".into(),
        }),
    }
}

/// Checks the joint-set size and finiteness at the API boundary.
#[inline]
pub(crate) fn check_input(q: &Joints, n: usize) -> Result<(), KinematicsError> {
    if q.len() != n {
        return Err(KinematicsError::BadInput {
            reason: format!("{} joints given, machine has {n}", q.len()),
        });
    }
    if !q.is_finite() {
        return Err(KinematicsError::BadInput {
            reason: "non-finite joint value".into(),
        });
    }
    Ok(())
}

/// Checks a tip is finite (TCP input).
#[inline]
pub(crate) fn check_tip(t: &Vector3<f64>) -> Result<(), KinematicsError> {
    if t.x.is_finite() && t.y.is_finite() && t.z.is_finite() {
        Ok(())
    } else {
        Err(KinematicsError::BadInput {
            reason: "non-finite tip".into(),
        })
    }
}

/// Checks a pose is finite.
#[inline]
pub(crate) fn check_pose(p: &ToolPose) -> Result<(), KinematicsError> {
    let (t, a) = (&p.tip, &p.axis);
    if t.x.is_finite()
        && t.y.is_finite()
        && t.z.is_finite()
        && a.x.is_finite()
        && a.y.is_finite()
        && a.z.is_finite()
    {
        Ok(())
    } else {
        Err(KinematicsError::BadInput {
            reason: "non-finite pose".into(),
        })
    }
}

/// Checks the tool axis of a machine that only translates the tool: +Z, within `axis_sin`
/// (the sine of the angle tolerated). `machine` says which kind of machine, for the message.
pub(crate) fn check_vertical_axis(
    pose: &ToolPose,
    axis_sin: f64,
    machine: &str,
) -> Result<(), KinematicsError> {
    let a = &pose.axis;
    // The sine of the angle to +Z is the horizontal part of the unit axis.
    if a.z <= 0.0 || (a.x * a.x + a.y * a.y).sqrt() > axis_sin {
        return Err(KinematicsError::AxisUnreachable {
            reason: format!(
                "{machine}: the tool axis is +Z; requested ({:.6}, {:.6}, {:.6})",
                a.x, a.y, a.z
            ),
        });
    }
    Ok(())
}
