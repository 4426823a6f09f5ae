//! Five-axis table-tilting (trunnion) chain shared by `table-ac` and `table-bc`: a part point
//! `p` sits at `pivot + R_tilt(θ)·(c_offset + Rz(C)·p)` in machine coordinates
//! (docs/machine-files.md, "Kinematic conventions"). Joints: X Y Z (spindle gauge point), tilt (A
//! or B), C.

use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use tezgah_geom::Axis;

use crate::angle::{atan2_pair, unwrap_within};
use crate::error::KinematicsError;
use crate::kinematics::{check_input, check_pose, check_tip, Jacobian, Kinematics, Tolerances};
use crate::machine::{check_joint_kinds, finite3, limits, refused, require, tolerances};
use crate::machine::{FromSection, Joint, MachineError};
use crate::pose::{check_limits, JointKind, JointLimit, Joints, Tool, ToolPose};
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

/// `[kinematics]` of a `table-ac` or `table-bc` machine.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TrunnionSection {
    /// Machine coordinates of a point on the tilt axis, mm (required).
    pivot: Option<[f64; 3]>,
    /// From that point to the C axis origin with the tilt at 0, mm (default 0: they meet).
    c_offset: Option<[f64; 3]>,
    axis_tolerance_deg: Option<f64>,
    pole_cone_deg: Option<f64>,
}

impl FromSection for Trunnion {
    type Section = TrunnionSection;

    /// Joints x y z (linear), tilt and c (rotary); `table-ac` tilts about X, `table-bc` about Y.
    fn from_section(
        kind: &'static str,
        section: TrunnionSection,
        joints: &[Joint],
    ) -> Result<Self, MachineError> {
        use JointKind::{Linear as L, Rotary as R};
        check_joint_kinds(kind, joints, &[L, L, L, R, R])?;
        let field = "kinematics.pivot";
        let pivot = finite3(field, require(field, kind, section.pivot)?)?;
        let c_offset = finite3("kinematics.c_offset", section.c_offset.unwrap_or([0.0; 3]))?;
        let tilt = if kind == "table-ac" {
            TiltAxis::X
        } else {
            TiltAxis::Y
        };
        let tolerances = tolerances(section.axis_tolerance_deg, section.pole_cone_deg, None)?;
        Trunnion::new(tilt, pivot, c_offset, limits(joints), tolerances)
            .map_err(refused("kinematics"))
    }
}

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

    /// Gauge-point joints for a part-frame tip at fixed table angles: the TCP map of the
    /// linear axes.
    #[inline]
    fn linear_for(&self, tip: &Vector3<f64>, tilt: f64, c: f64, tool: &Tool) -> Vector3<f64> {
        let (st, ct) = tilt.sin_cos();
        let (sc, cc) = c.sin_cos();
        self.linear_sc(tip, st, ct, sc, cc, tool)
    }

    /// As [`Self::linear_for`] from the sines and cosines, which the inverse already has from
    /// the tool axis (no trigonometry in the 1 ms loop beyond two `atan2`).
    #[inline]
    fn linear_sc(
        &self,
        tip: &Vector3<f64>,
        st: f64,
        ct: f64,
        sc: f64,
        cc: f64,
        tool: &Tool,
    ) -> Vector3<f64> {
        // c_offset + Rz(C)·p, then R_tilt, then pivot; the gauge point is the tool length above.
        let v =
            Vector3::new(cc * tip.x - sc * tip.y, sc * tip.x + cc * tip.y, tip.z) + self.c_offset;
        let w = match self.tilt {
            TiltAxis::X => Vector3::new(v.x, ct * v.y - st * v.z, st * v.y + ct * v.z),
            TiltAxis::Y => Vector3::new(ct * v.x + st * v.z, v.y, -st * v.x + ct * v.z),
        };
        self.pivot + w + Vector3::new(0.0, 0.0, tool.length)
    }

    /// Turns of (tilt, C) nearest `previous` within the rotary limits, or `None`.
    #[inline(always)]
    fn turns(&self, tilt: f64, c: f64, previous: &Joints) -> Option<(f64, f64)> {
        let lt = &self.limits[TILT];
        let lc = &self.limits[C];
        Some((
            unwrap_within(tilt, previous[TILT], lt.min, lt.max)?,
            unwrap_within(c, previous[C], lc.min, lc.max)?,
        ))
    }

    /// The pole: C is undefined, keep it (no jump) and tilt as little as needed.
    #[cold]
    fn inverse_at_pole(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        let k = pose.axis.into_inner();
        let c = previous[C];
        let t = match self.tilt {
            TiltAxis::X => table_ac::tilt_keeping_c(&k, c),
            TiltAxis::Y => table_bc::tilt_keeping_c(&k, c),
        };
        let (t, c) = self
            .turns(t, c, previous)
            .ok_or_else(|| self.limits[TILT].violation(TILT, t))?;
        let m = self.linear_for(&pose.tip, t, c, tool);
        let q = Joints::new([m.x, m.y, m.z, t, c]);
        check_limits(&q, &self.limits)?;
        Ok(q)
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
        let h = (k.x * k.x + k.y * k.y).sqrt();
        if h <= self.pole_sin {
            return self.inverse_at_pole(pose, tool, previous);
        }
        // Branch 1 (tilt ≥ 0) from the axis (table_ac/table_bc `solutions`), with its sines
        // and cosines read off the unit axis; branch 2 is (−tilt, C + π). The two angles are
        // independent: one two-lane atan2 gives both.
        let inv_h = 1.0 / h;
        let (cy, cx) = match self.tilt {
            TiltAxis::X => (k.x, k.y),
            TiltAxis::Y => (k.y, -k.x),
        };
        let [t1, c1] = atan2_pair([h, cy], [k.z, cx]);
        let (sc, cc) = (cy * inv_h, cx * inv_h);
        let b1 = self.turns(t1, c1, previous);
        // The usual case along a path, decided without branch 2: the previous tilt is ≥ 0,
        // branch 1 needs no turn of the tilt and at most a quarter turn of C. Branch 2 then
        // costs at least |t1 + pt| + π − d ≥ |t1 − pt| + d (its C is half a turn away, so
        // at least π − d from the previous C), so branch 1 is the nearest.
        if let Some((t, c)) = b1 {
            let d = (c - previous[C]).abs();
            if previous[TILT] >= 0.0 && t == t1 && d <= std::f64::consts::FRAC_PI_2 {
                let m = self.linear_sc(&pose.tip, h, k.z, sc, cc, tool);
                let q = Joints::new([m.x, m.y, m.z, t, c]);
                if check_limits(&q, &self.limits).is_ok() {
                    return Ok(q);
                }
            }
        }
        let b2 = self.turns(-t1, c1 + std::f64::consts::PI, previous);
        let cost = |b: &Option<(f64, f64)>| {
            b.map_or(f64::INFINITY, |(t, c)| {
                (t - previous[TILT]).abs() + (c - previous[C]).abs()
            })
        };
        let first_is_1 = cost(&b1) <= cost(&b2);
        let order = if first_is_1 {
            [(b1, 1.0), (b2, -1.0)]
        } else {
            [(b2, -1.0), (b1, 1.0)]
        };
        let mut err = None;
        for (b, sign) in order {
            let Some((t, c)) = b else { continue };
            let m = self.linear_sc(&pose.tip, sign * h, k.z, sign * sc, sign * cc, tool);
            let q = Joints::new([m.x, m.y, m.z, t, c]);
            match check_limits(&q, &self.limits) {
                Ok(()) => return Ok(q),
                Err(e) => {
                    err.get_or_insert(e);
                }
            }
        }
        Err(err.unwrap_or_else(|| {
            // No turn of either branch fits the rotary limits: name the tilt if that is why.
            let lt = &self.limits[TILT];
            if unwrap_within(t1, previous[TILT], lt.min, lt.max).is_none()
                && unwrap_within(-t1, previous[TILT], lt.min, lt.max).is_none()
            {
                lt.violation(TILT, t1)
            } else {
                self.limits[C].violation(C, c1)
            }
        }))
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
        check_tip(tip)?;
        check_input(previous, 5)?;
        check_input(angles, 2)?;
        // Under TCP the program's angles are the table angles themselves.
        let m = self.linear_for(tip, angles[0], angles[1], tool);
        let q = Joints::new([m.x, m.y, m.z, angles[0], angles[1]]);
        check_limits(&q, &self.limits)?;
        Ok(q)
    }

    fn joint_axes(&self) -> Vec<Option<Axis>> {
        let tilt = match self.tilt {
            TiltAxis::X => Axis::A,
            TiltAxis::Y => Axis::B,
        };
        [Axis::X, Axis::Y, Axis::Z, tilt, Axis::C]
            .map(Some)
            .to_vec()
    }

    fn tcp_joints(&self) -> Vec<usize> {
        vec![TILT, C]
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

#[cfg(test)]
mod axis_maps {
    use nalgebra::Vector3;

    type Axis = fn(f64, f64) -> Vector3<f64>;
    type Solutions = fn(&Vector3<f64>) -> [(f64, f64); 2];
    type TiltKeepingC = fn(&Vector3<f64>, f64) -> f64;

    /// For both trunnions: both solutions give back the axis, and keeping C at the exact pole
    /// gives tilt 0.
    #[test]
    fn solutions_reproduce_the_axis() {
        let maps: [(Axis, Solutions, TiltKeepingC); 2] = [
            (
                super::table_ac::axis,
                super::table_ac::solutions,
                super::table_ac::tilt_keeping_c,
            ),
            (
                super::table_bc::axis,
                super::table_bc::solutions,
                super::table_bc::tilt_keeping_c,
            ),
        ];
        for (axis, solutions, tilt_keeping_c) in maps {
            for (t, c) in [
                (0.3, 0.2),
                (1.2, -2.5),
                (-0.7, 3.0),
                (2.0, 1.0),
                (0.01, -0.01),
            ] {
                let k = axis(t, c);
                for (ts, cs) in solutions(&k) {
                    assert!((axis(ts, cs) - k).norm() < 1e-14, "{t} {c} → {ts} {cs}");
                }
                let (t0, c0) = solutions(&k)[0];
                assert!(t0 >= 0.0 && ((t0 - t.abs()).abs() < 1e-14));
                // the tilt that keeps a given C reproduces the axis when C is one of the solutions
                assert!((axis(tilt_keeping_c(&k, c0), c0) - k).norm() < 1e-14);
            }
            assert_eq!(tilt_keeping_c(&Vector3::z(), 1.234), 0.0);
        }
    }
}
