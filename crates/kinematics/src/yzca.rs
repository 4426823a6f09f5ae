//! Four-axis Y-Z-C-A machine of Kelekçi (2021, §5.3.1): Y and Z move the tool,
//! A tilts the tool about X, C is an endless rotary table under the part. Joints
//! `[y, z, c, a]` (mm, rad); planning happens in the part frame and this maps it to joints.
//!
//! Conventions (fixing the sign of C in the thesis's eq. 5.4; docs/errata.md):
//! * the Y slide moves the tool along the table's radial line, which is the part's +X
//!   direction when C = 0;
//! * C > 0 turns the table counter-clockwise seen from +Z (right-handed about +Z), so a tool
//!   at radius r sees the part polar angle −C: `x_w = r·cos C`, `y_w = −r·sin C` (eq. 5.2);
//! * A > 0 tilts the tool tip toward +Y (right-handed about +X): `r = y + l·sin A`,
//!   `z_w = z − l·cos A`, tool axis `(−sin A·cos C, sin A·sin C, cos A)`;
//! * `l` = pivot-to-gauge distance + tool length; the inverse is C = −atan2(y_w, x_w)
//!   (not the printed eq. 5.4, which gives +45° where −45° is meant), unwrapped.

use nalgebra::Vector3;
use serde::Deserialize;
use tezgah_geom::Axis;

use crate::angle::{atan2, atan2_pair, unwrap_near, unwrap_within};
use crate::error::KinematicsError;
use crate::kinematics::{
    check_input, check_pose, check_tip, choose_nearest, Jacobian, Kinematics, Tolerances,
};
use crate::machine::{check_joint_kinds, finite, limits, refused, require, tolerances};
use crate::machine::{FromSection, Joint, MachineError};
use crate::pose::{check_limits, JointKind, JointLimit, Joints, Tool, ToolPose};

const Y: usize = 0;
const Z: usize = 1;
const C: usize = 2;
const A: usize = 3;

/// The Y-Z-C-A machine.
#[derive(Clone, Debug)]
pub struct Yzca {
    pivot_to_gauge: f64,
    limits: Vec<JointLimit>,
    tolerances: Tolerances,
    axis_sin: f64,
    pole_sin: f64,
}

impl Yzca {
    /// A Y-Z-C-A machine; `pivot_to_gauge` (mm) is the distance from the A pivot to the
    /// spindle gauge point along the tool; `limits` holds four joints `[y, z, c, a]`.
    pub fn new(
        pivot_to_gauge: f64,
        limits: Vec<JointLimit>,
        tolerances: Tolerances,
    ) -> Result<Self, KinematicsError> {
        if limits.len() != 4 {
            return Err(KinematicsError::BadInput {
                reason: format!("yzca has 4 joints (y z c a), got {}", limits.len()),
            });
        }
        Ok(Self {
            pivot_to_gauge,
            limits,
            tolerances,
            axis_sin: tolerances.axis_rad.sin(),
            pole_sin: tolerances.pole_cone_rad.sin(),
        })
    }

    #[inline]
    fn lever(&self, tool: &Tool) -> f64 {
        self.pivot_to_gauge + tool.length
    }

    /// The joint set for table angle `c` (radial direction (cos C, −sin C)) and tilt `a`.
    #[inline]
    fn joints_at(&self, tip: &Vector3<f64>, c: f64, a: f64, l: f64) -> Joints {
        let (sc, cc) = c.sin_cos();
        let r = tip.x * cc - tip.y * sc;
        let (sa, ca) = a.sin_cos();
        Joints::new([r - l * sa, tip.z + l * ca, c, a])
    }

    /// Tip on the C axis: the radial plane from the axis's horizontal part (the A > 0
    /// branch: that part is −sin A·(cos C, −sin C)), or keep C when the axis is vertical too.
    #[cold]
    fn radial_on_axis(&self, k: &Vector3<f64>, previous_c: f64) -> (f64, f64, f64) {
        let hk = (k.x * k.x + k.y * k.y).sqrt();
        if hk > self.pole_sin {
            (atan2(k.y, -k.x), k.y / hk, -k.x / hk)
        } else {
            let (s, co) = previous_c.sin_cos();
            (previous_c, s, co)
        }
    }

    /// Direction of the radial plane (as a C value) through a tip, or `fallback` when the
    /// tip is on the C axis.
    #[inline]
    fn radial_c(&self, tip: &Vector3<f64>, fallback: f64) -> f64 {
        if (tip.x * tip.x + tip.y * tip.y).sqrt() > self.tolerances.centre_mm {
            atan2(-tip.y, tip.x)
        } else {
            fallback
        }
    }
}

/// `[kinematics]` of a `yzca` machine.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct YzcaSection {
    /// A pivot to spindle gauge point along the tool, mm (required).
    pivot_to_gauge: Option<f64>,
    axis_tolerance_deg: Option<f64>,
    pole_cone_deg: Option<f64>,
    centre_tolerance_mm: Option<f64>,
}

impl FromSection for Yzca {
    type Section = YzcaSection;

    /// Joints y z (linear), c a (rotary).
    fn from_section(
        kind: &'static str,
        section: YzcaSection,
        joints: &[Joint],
    ) -> Result<Self, MachineError> {
        use JointKind::{Linear as L, Rotary as R};
        check_joint_kinds(kind, joints, &[L, L, R, R])?;
        let field = "kinematics.pivot_to_gauge";
        let pivot_to_gauge = finite(field, require(field, kind, section.pivot_to_gauge)?)?;
        let tolerances = tolerances(
            section.axis_tolerance_deg,
            section.pole_cone_deg,
            section.centre_tolerance_mm,
        )?;
        Yzca::new(pivot_to_gauge, limits(joints), tolerances).map_err(refused("kinematics"))
    }
}

/// Turns of (C, A) nearest `previous` within limits, or `None`.
#[inline(always)]
fn turns(
    c: f64,
    a: f64,
    previous: &Joints,
    lc: &JointLimit,
    la: &JointLimit,
) -> Option<(f64, f64)> {
    Some((
        unwrap_within(c, previous[C], lc.min, lc.max)?,
        unwrap_within(a, previous[A], la.min, la.max)?,
    ))
}

#[cold]
fn out_of_plane(t: f64) -> KinematicsError {
    KinematicsError::AxisUnreachable {
        reason: format!(
            "Y-Z-C-A tilts only in the radial plane; the axis is {:.3e} rad out of it",
            t.clamp(-1.0, 1.0).asin()
        ),
    }
}

/// The two tilts that put the tool normal to a path direction (Δy, Δz) in the Y-Z plane,
/// "inside" and "outside" the curve (Kelekçi, 2021, eq. 5.6). Geometry cannot choose between
/// them; [`choose_tilt`] uses the programmed A. Returns `None` for a zero direction.
///
/// With this file's A sign the tool axis (−sin A, cos A) ⟂ (Δy, Δz) gives A = atan2(Δz, Δy)
/// and A + π. (The printed eq. 5.6 table is not self-consistent: rows 1 and 3 give an axis
/// that is not normal to the path; see docs/errata.md.)
pub fn normal_tilts(dy: f64, dz: f64) -> Option<[f64; 2]> {
    if dy == 0.0 && dz == 0.0 {
        return None;
    }
    let a = dz.atan2(dy);
    Some([a, crate::angle::wrap_pi(a + std::f64::consts::PI)])
}

/// Of the candidate tilts, the one nearest the programmed A (each unwrapped next to it).
pub fn choose_tilt(candidates: &[f64; 2], programmed_a: f64) -> f64 {
    let c0 = unwrap_near(candidates[0], programmed_a);
    let c1 = unwrap_near(candidates[1], programmed_a);
    if (c0 - programmed_a).abs() <= (c1 - programmed_a).abs() {
        c0
    } else {
        c1
    }
}

impl Kinematics for Yzca {
    fn joint_limits(&self) -> &[JointLimit] {
        &self.limits
    }

    fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError> {
        check_input(q, 4)?;
        let l = self.lever(tool);
        let (sa, ca) = q[A].sin_cos();
        let (sc, cc) = q[C].sin_cos();
        // Kelekçi (2021), eq. 5.2, cleaned: r = y + l·sin A, z_w = z − l·cos A.
        let r = q[Y] + l * sa;
        let tip = Vector3::new(r * cc, -r * sc, q[Z] - l * ca);
        Ok(ToolPose::new(tip, Vector3::new(-sa * cc, sa * sc, ca)))
    }

    fn inverse(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_pose(pose)?;
        check_input(previous, 4)?;
        let k = pose.axis.into_inner();
        let p = &pose.tip;
        let l = self.lever(tool);
        // The radial plane (cos C, −sin C): from the tip, else from the axis, else keep C.
        let rho = (p.x * p.x + p.y * p.y).sqrt();
        // Axis components along the radial and tangential (sin C, cos C) directions: a
        // 4-axis machine tilts only in the radial plane. Off the C axis, C and A are
        // independent angles: one two-lane atan2 gives both.
        let radial = |sc: f64, cc: f64| (k.x * cc - k.y * sc, k.x * sc + k.y * cc);
        let (c1, a1, sc, cc, u, t) = if rho > self.tolerances.centre_mm {
            let inv = 1.0 / rho;
            let (sc, cc) = (-p.y * inv, p.x * inv);
            let (u, t) = radial(sc, cc);
            let [c1, a1] = atan2_pair([-p.y, -u], [p.x, k.z]);
            (c1, a1, sc, cc, u, t)
        } else {
            let (c1, sc, cc) = self.radial_on_axis(&k, previous[C]);
            let (u, t) = radial(sc, cc);
            (c1, atan2(-u, k.z), sc, cc, u, t)
        };
        if t.abs() > self.axis_sin {
            return Err(out_of_plane(t));
        }
        let r = p.x * cc - p.y * sc;
        let inv_n = 1.0 / (u * u + k.z * k.z).sqrt();
        let y1 = r + l * u * inv_n; // r − l·sin A with sin A = −u/n
        let z1 = p.z + l * k.z * inv_n;
        // Branch 2 turns the table half a turn and tilts the other way: (−y, z, C + π, −A).
        let (lc, la) = (&self.limits[C], &self.limits[A]);
        let b1 = turns(c1, a1, previous, lc, la);
        // The usual case along a path, decided without branch 2 (as in the trunnions): A
        // keeps its sign and needs no turn, C moves at most a quarter turn. Branch 2 costs at
        // least |a1 + pa| + π − d ≥ |a1 − pa| + d, so branch 1 is the nearest.
        if let Some((c, a)) = b1 {
            let d = (c - previous[C]).abs();
            if a1 * previous[A] >= 0.0 && a == a1 && d <= std::f64::consts::FRAC_PI_2 {
                let q = Joints::new([y1, z1, c, a]);
                if check_limits(&q, &self.limits).is_ok() {
                    return Ok(q);
                }
            }
        }
        let b2 = turns(c1 + std::f64::consts::PI, -a1, previous, lc, la);
        let cost = |b: &Option<(f64, f64)>| {
            b.map_or(f64::INFINITY, |(c, a)| {
                (c - previous[C]).abs() + (a - previous[A]).abs()
            })
        };
        let order = if cost(&b1) <= cost(&b2) {
            [(b1, y1), (b2, -y1)]
        } else {
            [(b2, -y1), (b1, y1)]
        };
        let mut err = None;
        for (b, y) in order {
            let Some((c, a)) = b else { continue };
            let q = Joints::new([y, z1, c, a]);
            match check_limits(&q, &self.limits) {
                Ok(()) => return Ok(q),
                Err(e) => {
                    err.get_or_insert(e);
                }
            }
        }
        Err(err.unwrap_or_else(|| {
            if unwrap_within(a1, previous[A], la.min, la.max).is_none()
                && unwrap_within(-a1, previous[A], la.min, la.max).is_none()
            {
                la.violation(A, a1)
            } else {
                lc.violation(C, unwrap_near(c1, previous[C]))
            }
        }))
    }

    fn tcp_angles(&self, q: &Joints) -> Joints {
        let v = q.as_slice();
        Joints::new([v.get(C), v.get(A)].map(|x| x.copied().unwrap_or(f64::NAN)))
    }

    /// Program: tip and (C, A). A is taken as programmed (this is how the programmed A picks
    /// the tilt solution); C follows from the tip's polar angle, the branch and turn nearest
    /// the programmed C (the tool cannot reach a tip off the radial plane otherwise).
    fn tcp_inverse(
        &self,
        tip: &Vector3<f64>,
        angles: &Joints,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_tip(tip)?;
        check_input(previous, 4)?;
        check_input(angles, 2)?;
        let (c_prog, a) = (angles[0], angles[1]);
        let phi = self.radial_c(tip, c_prog);
        let lc = &self.limits[C];
        let cands = [phi, phi + std::f64::consts::PI].map(|c| {
            unwrap_within(c, c_prog, lc.min, lc.max)
                .map(|c| self.joints_at(tip, c, a, self.lever(tool)))
        });
        let err = Some(lc.violation(C, unwrap_near(phi, c_prog)));
        let mut reference = *previous;
        reference[C] = c_prog;
        let q = choose_nearest(&cands, err, &reference, &[C], &self.limits)?;
        check_limits(&q, &self.limits)?;
        Ok(q)
    }

    fn joint_axes(&self) -> Vec<Option<Axis>> {
        vec![Some(Axis::Y), Some(Axis::Z), Some(Axis::C), Some(Axis::A)]
    }

    fn tcp_joints(&self) -> Vec<usize> {
        vec![C, A]
    }

    fn jacobian(&self, q: &Joints, tool: &Tool) -> Result<Jacobian, KinematicsError> {
        check_input(q, 4)?;
        let l = self.lever(tool);
        let (sa, ca) = q[A].sin_cos();
        let (sc, cc) = q[C].sin_cos();
        let r = q[Y] + l * sa;
        #[rustfmt::skip]
        let j = Jacobian::from_column_slice(&[
            // ∂/∂y
            cc, -sc, 0.0, 0.0, 0.0, 0.0,
            // ∂/∂z
            0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
            // ∂/∂C
            -r * sc, -r * cc, 0.0, sa * sc, sa * cc, 0.0,
            // ∂/∂A
            l * ca * cc, -l * ca * sc, l * sa, -ca * cc, ca * sc, -sa,
        ]);
        Ok(j)
    }
}
