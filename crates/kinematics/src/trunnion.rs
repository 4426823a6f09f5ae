//! Five-axis table-tilting (trunnion) chain shared by `table-ac` and `table-bc`: a part point
//! `p` sits at `pivot + R_tilt(θ)·(c_offset + Rz(C)·p)` in machine coordinates (DESIGN.md
//! "Kinematic conventions"). Joints: X Y Z (spindle gauge point), tilt (A or B), C.

use nalgebra::{Matrix3, Vector3};

use crate::angle::unwrap_within;
use crate::error::KinematicsError;
use crate::kinematics::{
    check_input, check_pose, choose_nearest, Jacobian, Kinematics, Tolerances,
};
use crate::pose::{check_limits, JointLimit, Joints, Tool, ToolPose};
use crate::{table_ac, table_bc};

/// Which machine axis the table tilts about.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum TiltAxis {
    /// A about machine X (`table-ac`).
    X,
    /// B about machine Y (`table-bc`).
    Y,
}

/// A trunnion machine: joints `[x, y, z, tilt, c]`, mm and rad.
#[derive(Clone, Debug)]
pub struct Trunnion {
    tilt: TiltAxis,
    pivot: Vector3<f64>,
    c_offset: Vector3<f64>,
    limits: Vec<JointLimit>,
    tolerances: Tolerances,
    pole_sin: f64,
}

const TILT: usize = 3;
const C: usize = 4;

impl Trunnion {
    /// A trunnion; `limits` must hold five joints (X Y Z, tilt, C).
    pub fn new(
        tilt: TiltAxis,
        pivot: Vector3<f64>,
        c_offset: Vector3<f64>,
        limits: Vec<JointLimit>,
        tolerances: Tolerances,
    ) -> Result<Self, KinematicsError> {
        if limits.len() != 5 {
            return Err(KinematicsError::BadInput {
                reason: format!("a table-tilting machine has 5 joints, got {}", limits.len()),
            });
        }
        Ok(Self {
            tilt,
            pivot,
            c_offset,
            limits,
            tolerances,
            pole_sin: tolerances.pole_cone_rad.sin(),
        })
    }

    /// The tolerances in force.
    pub fn tolerances(&self) -> &Tolerances {
        &self.tolerances
    }

    /// The tilt axis.
    pub fn tilt_axis(&self) -> TiltAxis {
        self.tilt
    }

    #[inline]
    fn r_tilt(&self, t: f64) -> Matrix3<f64> {
        let (s, c) = t.sin_cos();
        match self.tilt {
            TiltAxis::X => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
            TiltAxis::Y => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        }
    }

    #[inline]
    fn tilt_unit(&self) -> Vector3<f64> {
        match self.tilt {
            TiltAxis::X => Vector3::x(),
            TiltAxis::Y => Vector3::y(),
        }
    }

    /// Joints for a part-frame tip at fixed table angles: the TCP map of the linear axes.
    #[inline]
    fn linear_for(&self, tip: &Vector3<f64>, tilt: f64, c: f64, tool: &Tool) -> Vector3<f64> {
        let m = self.pivot + self.r_tilt(tilt) * (self.c_offset + rz(c) * tip);
        Vector3::new(m.x, m.y, m.z + tool.length)
    }

    /// One candidate joint set for raw angles (tilt, C): turns chosen nearest `previous`
    /// within limits; `None` if no turn fits.
    #[inline]
    fn candidate(
        &self,
        tip: &Vector3<f64>,
        tilt: f64,
        c: f64,
        tool: &Tool,
        previous: &Joints,
    ) -> Option<Joints> {
        let lt = &self.limits[TILT];
        let lc = &self.limits[C];
        let t = unwrap_within(tilt, previous[TILT], lt.min, lt.max)?;
        let c = unwrap_within(c, previous[C], lc.min, lc.max)?;
        let m = self.linear_for(tip, t, c, tool);
        Some(Joints::new([m.x, m.y, m.z, t, c]))
    }
}

#[inline]
fn rz(c: f64) -> Matrix3<f64> {
    let (s, co) = c.sin_cos();
    Matrix3::new(co, -s, 0.0, s, co, 0.0, 0.0, 0.0, 1.0)
}

impl Kinematics for Trunnion {
    fn joint_limits(&self) -> &[JointLimit] {
        &self.limits
    }

    fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError> {
        check_input(q, 5)?;
        // Tip in machine coordinates: the gauge point minus the tool along machine +Z.
        let m = Vector3::new(q[0], q[1], q[2] - tool.length);
        let back = rz(q[C]).transpose() * self.r_tilt(q[TILT]).transpose();
        let tip = back * (m - self.pivot) - rz(q[C]).transpose() * self.c_offset;
        let axis = match self.tilt {
            TiltAxis::X => table_ac::axis(q[TILT], q[C]),
            TiltAxis::Y => table_bc::axis(q[TILT], q[C]),
        };
        Ok(ToolPose::new(tip, axis))
    }

    fn inverse(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_pose(pose)?;
        check_input(previous, 5)?;
        let k = pose.axis.into_inner();
        if k.x.hypot(k.y) <= self.pole_sin {
            // The pole: C is undefined, keep it (no jump) and tilt as little as needed.
            let c = previous[C];
            let t = match self.tilt {
                TiltAxis::X => table_ac::tilt_keeping_c(&k, c),
                TiltAxis::Y => table_bc::tilt_keeping_c(&k, c),
            };
            return match self.candidate(&pose.tip, t, c, tool, previous) {
                Some(q) => check_limits(&q, &self.limits).map(|_| q),
                None => Err(self.limits[TILT].violation(TILT, t)),
            };
        }
        let sols = match self.tilt {
            TiltAxis::X => table_ac::solutions(&k),
            TiltAxis::Y => table_bc::solutions(&k),
        };
        let cands = [
            self.candidate(&pose.tip, sols[0].0, sols[0].1, tool, previous),
            self.candidate(&pose.tip, sols[1].0, sols[1].1, tool, previous),
        ];
        let err = if cands.iter().all(Option::is_none) {
            // Report the tilt (or C) that no turn could bring inside its limits.
            let (t, c) = sols[0];
            Some(
                if unwrap_within(
                    t,
                    previous[TILT],
                    self.limits[TILT].min,
                    self.limits[TILT].max,
                )
                .is_none()
                {
                    self.limits[TILT].violation(TILT, t)
                } else {
                    self.limits[C].violation(C, c)
                },
            )
        } else {
            None
        };
        choose_nearest(&cands, err, previous, &[TILT, C], &self.limits)
    }

    fn tcp_angles(&self, q: &Joints) -> Joints {
        let v = q.as_slice();
        Joints::new([v.get(TILT), v.get(C)].map(|x| x.copied().unwrap_or(f64::NAN)))
    }

    fn tcp_inverse(
        &self,
        tip: &Vector3<f64>,
        angles: &Joints,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_input(previous, 5)?;
        check_input(angles, 2)?;
        // Under TCP the program's angles are the table angles themselves.
        let m = self.linear_for(tip, angles[0], angles[1], tool);
        let q = Joints::new([m.x, m.y, m.z, angles[0], angles[1]]);
        check_limits(&q, &self.limits)?;
        Ok(q)
    }

    fn jacobian(&self, q: &Joints, tool: &Tool) -> Result<Jacobian, KinematicsError> {
        check_input(q, 5)?;
        let m = Vector3::new(q[0], q[1], q[2] - tool.length);
        let rzt = rz(q[C]).transpose();
        let rtt = self.r_tilt(q[TILT]).transpose();
        let w = rtt * (m - self.pivot);
        let p = rzt * (w - self.c_offset);
        let k_t = rtt * Vector3::z();
        let k = rzt * k_t;
        let u = self.tilt_unit();
        let ez = Vector3::z();
        let mut j = Jacobian::zeros(5);
        // ∂p/∂xyz = Rzᵀ·R_tiltᵀ; the axis does not depend on the linear joints.
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(rzt * rtt));
        // d(R_tilt(θ)ᵀ)/dθ = −[u]×·R_tiltᵀ and d(Rz(C)ᵀ)/dC = −[ẑ]×·Rzᵀ.
        let dp_dt = -(rzt * u.cross(&w));
        let dk_dt = -(rzt * u.cross(&k_t));
        let dp_dc = -ez.cross(&p);
        let dk_dc = -ez.cross(&k);
        j.fixed_view_mut::<3, 1>(0, TILT).copy_from(&dp_dt);
        j.fixed_view_mut::<3, 1>(3, TILT).copy_from(&dk_dt);
        j.fixed_view_mut::<3, 1>(0, C).copy_from(&dp_dc);
        j.fixed_view_mut::<3, 1>(3, C).copy_from(&dk_dc);
        Ok(j)
    }
}
