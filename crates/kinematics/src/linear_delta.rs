//! Linear delta (3-PSS, as Ayyıldız, 2017): three vertical towers whose carriages carry rods of
//! length L to a platform that only translates. Joints are carriage heights, as LinuxCNC's
//! lineardeltakins: `q_i = z + √(L² − (x − x_i)² − (y − y_i)²) − offset_i`.
//!
//! The forward map is Ayyıldız's closed-form trilateration (2017, eqs 3.6–3.15) *corrected*:
//! as printed it does not invert eq. 3.5 (docs/errata.md), written for any tower
//! angles: subtracting closure equations gives x, y linear in z; the smaller root of the
//! remaining quadratic is the platform below the carriages.

use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use tezgah_geom::Axis;

use crate::error::KinematicsError;
use crate::kinematics::{
    check_input, check_pose, check_vertical_axis, Jacobian, Kinematics, Tolerances,
};
use crate::machine::{check_joint_kinds, finite, finite3, invalid, limits, positive, refused};
use crate::machine::{require, tolerances, FromSection, Joint, MachineError};
use crate::pose::{check_limits, JointKind, JointLimit, Joints, Tool, ToolPose};

/// Geometry of a linear delta.
#[derive(Clone, Debug, PartialEq)]
pub struct DeltaGeometry {
    /// Effective radius r = R_base − R_platform, mm (centre to tower, less platform joint radius).
    pub radius: f64,
    /// Rod length L, mm.
    pub rod_length: f64,
    /// Tower angles from +X, rad (LinuxCNC's and Klipper's default 90°, 210°, 330°).
    pub tower_angles: [f64; 3],
    /// Subtracted from each carriage height, mm: joint = height − offset. Ayyıldız (2017) uses
    /// √(L² − r²) = 311.28765 so the platform at the origin reads joints (0, 0, 0).
    pub carriage_offsets: [f64; 3],
    /// Smallest angle between a rod and the platform plane, rad (Ayyıldız, 2017, uses 5°):
    /// the rate q̇ = J·ṗ blows up as a rod becomes horizontal.
    pub min_rod_angle: f64,
    /// Largest angle, rad, between a rod and its direction with the platform at the centre:
    /// the spherical joints' cone (Ayyıldız's joints turn 22°). `None`: unchecked.
    pub max_joint_angle: Option<f64>,
}

/// The linear-delta model: joints `[tower 1, tower 2, tower 3]` carriage heights, mm.
#[derive(Clone, Debug)]
pub struct LinearDelta {
    geometry: DeltaGeometry,
    towers: [(f64, f64); 3],
    rod2: f64,
    max_d2: f64,
    limits: Vec<JointLimit>,
    axis_sin: f64,
    /// Unit rod directions (platform → carriage) with the platform at the centre, and the
    /// cosine of the joint cone, when the cone is checked.
    cone: Option<([Vector3<f64>; 3], f64)>,
}

/// `[kinematics]` of a `linear-delta` machine: the geometry in mm and degrees.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct DeltaSection {
    /// Required, > 0.
    radius: Option<f64>,
    /// Required, > `radius`.
    rod_length: Option<f64>,
    /// Default 90°, 210°, 330° (LinuxCNC, Klipper).
    tower_angles: Option<[f64; 3]>,
    /// Default 0.
    carriage_offsets: Option<[f64; 3]>,
    /// Default 0, in [0, 90).
    min_rod_angle_deg: Option<f64>,
    /// Default unchecked, in (0, 180).
    max_joint_angle_deg: Option<f64>,
    axis_tolerance_deg: Option<f64>,
}

impl FromSection for LinearDelta {
    type Section = DeltaSection;

    /// Three linear joints, the carriages of towers 1, 2, 3.
    fn from_section(
        kind: &'static str,
        s: DeltaSection,
        joints: &[Joint],
    ) -> Result<Self, MachineError> {
        check_joint_kinds(kind, joints, &[JointKind::Linear; 3])?;
        let field = |name: &str| format!("kinematics.{name}");
        let radius = positive(&field("radius"), require(&field("radius"), kind, s.radius)?)?;
        let rod_field = field("rod_length");
        let rod_length = positive(&rod_field, require(&rod_field, kind, s.rod_length)?)?;
        if rod_length <= radius {
            return Err(invalid(
                rod_field,
                format!("must be greater than radius ({radius}) or the centre is unreachable"),
            ));
        }
        let angles = finite3(
            &field("tower_angles"),
            s.tower_angles.unwrap_or([90.0, 210.0, 330.0]),
        )?;
        let offsets = finite3(
            &field("carriage_offsets"),
            s.carriage_offsets.unwrap_or([0.0; 3]),
        )?;
        let min_angle = finite(
            &field("min_rod_angle_deg"),
            s.min_rod_angle_deg.unwrap_or(0.0),
        )?;
        if !(0.0..90.0).contains(&min_angle) {
            return Err(invalid(field("min_rod_angle_deg"), "must be in [0, 90)"));
        }
        let max_joint_angle = match s.max_joint_angle_deg {
            Some(v) if v.is_finite() && v > 0.0 && v < 180.0 => Some(v.to_radians()),
            Some(_) => return Err(invalid(field("max_joint_angle_deg"), "must be in (0, 180)")),
            None => None,
        };
        let geometry = DeltaGeometry {
            max_joint_angle,
            radius,
            rod_length,
            tower_angles: [angles.x, angles.y, angles.z].map(f64::to_radians),
            carriage_offsets: [offsets.x, offsets.y, offsets.z],
            min_rod_angle: min_angle.to_radians(),
        };
        let tolerances = tolerances(s.axis_tolerance_deg, None, None)?;
        // Towers on one line is the one refusal left to the constructor.
        LinearDelta::new(geometry, limits(joints), tolerances)
            .map_err(refused("kinematics.tower_angles"))
    }
}

impl LinearDelta {
    /// A delta; `limits` holds the three carriage joints.
    pub fn new(
        geometry: DeltaGeometry,
        limits: Vec<JointLimit>,
        tolerances: Tolerances,
    ) -> Result<Self, KinematicsError> {
        if limits.len() != 3 {
            return Err(KinematicsError::BadInput {
                reason: format!("linear-delta has 3 joints, got {}", limits.len()),
            });
        }
        let g = &geometry;
        if !(g.radius > 0.0
            && g.rod_length > 0.0
            && g.radius.is_finite()
            && g.rod_length.is_finite())
        {
            return Err(KinematicsError::BadInput {
                reason: "radius and rod_length must be positive".into(),
            });
        }
        let towers = g
            .tower_angles
            .map(|a| (g.radius * a.cos(), g.radius * a.sin()));
        // The trilateration divides by this determinant: towers must not be collinear.
        let det = (towers[1].0 - towers[0].0) * (towers[2].1 - towers[0].1)
            - (towers[2].0 - towers[0].0) * (towers[1].1 - towers[0].1);
        if det.abs() < 1e-9 * g.radius * g.radius {
            return Err(KinematicsError::BadInput {
                reason: "tower angles put the towers on one line".into(),
            });
        }
        let max_d = g.rod_length * g.min_rod_angle.cos();
        let h0 = (g.rod_length * g.rod_length - g.radius * g.radius)
            .max(0.0)
            .sqrt();
        let cone = g.max_joint_angle.map(|a| {
            (
                towers.map(|(x, y)| Vector3::new(x, y, h0) / g.rod_length),
                a.cos(),
            )
        });
        Ok(Self {
            cone,
            towers,
            rod2: g.rod_length * g.rod_length,
            max_d2: max_d * max_d,
            limits,
            axis_sin: tolerances.axis_rad.sin(),
            geometry,
        })
    }

    /// The geometry.
    pub fn geometry(&self) -> &DeltaGeometry {
        &self.geometry
    }

    /// Tower positions (x_i, y_i), mm.
    pub fn towers(&self) -> [(f64, f64); 3] {
        self.towers
    }

    /// Joints for a platform point (tool length already removed), checked against the rod
    /// angle (not the joint cone: see [`Self::inverse_platform_checked`]); the hot path of the
    /// 1 ms loop (three square roots).
    #[inline(always)]
    pub fn inverse_platform(&self, p: &Vector3<f64>) -> Result<[f64; 3], KinematicsError> {
        let mut q = [0.0; 3];
        for (i, (qi, (tx, ty))) in q.iter_mut().zip(self.towers).enumerate() {
            let dx = p.x - tx;
            let dy = p.y - ty;
            let d2 = dx * dx + dy * dy;
            if d2 > self.max_d2 {
                return Err(self.rod_error(i, d2));
            }
            *qi = p.z + (self.rod2 - d2).sqrt() - self.geometry.carriage_offsets[i];
        }
        Ok(q)
    }

    /// [`Self::inverse_platform`] plus the spherical-joint cone when the machine has one.
    #[inline(always)]
    pub fn inverse_platform_checked(&self, p: &Vector3<f64>) -> Result<[f64; 3], KinematicsError> {
        let q = self.inverse_platform(p)?;
        if self.cone.is_some() {
            self.check_cone(p, &q)?;
        }
        Ok(q)
    }

    /// The spherical-joint cone, kept out of the plain inverse so a machine without it pays
    /// one predictable branch.
    #[inline(never)]
    fn check_cone(&self, p: &Vector3<f64>, q: &[f64; 3]) -> Result<(), KinematicsError> {
        let Some((home, cos_max)) = &self.cone else {
            return Ok(());
        };
        for (i, (tx, ty)) in self.towers.into_iter().enumerate() {
            // rod from the platform joint to the carriage joint, length L
            let h = q[i] + self.geometry.carriage_offsets[i] - p.z;
            let rod = Vector3::new(tx - p.x, ty - p.y, h);
            let cos = rod.dot(&home[i]) / self.geometry.rod_length;
            if cos < *cos_max {
                return Err(self.cone_error(i, cos));
            }
        }
        Ok(())
    }

    #[cold]
    fn cone_error(&self, i: usize, cos: f64) -> KinematicsError {
        KinematicsError::Unreachable {
            reason: format!(
                "tower {} rod {:.3}° from its central direction (spherical joint limit {:.3}°)",
                i + 1,
                cos.clamp(-1.0, 1.0).acos().to_degrees(),
                self.geometry.max_joint_angle.unwrap_or(0.0).to_degrees()
            ),
        }
    }

    /// Workspace volume, mm³: grid points (spacing `step_mm`) where the inverse succeeds
    /// within the rod angle, the joint cone and the carriage strokes, times the cell volume.
    /// Ayyıldız (2017, §3) reports 18 786 cm³ without a method; a grid count gives ≈ 46 900 cm³
    /// (500 mm stroke, 5° rod angle) and ≈ 16 600 cm³ (plus a 22° joint cone), which this
    /// reproduces. Needs finite joint limits; refuses grids over `max_points` points.
    pub fn workspace_volume(&self, step_mm: f64, max_points: u64) -> Result<f64, KinematicsError> {
        let bad = |reason: &str| KinematicsError::BadInput {
            reason: reason.into(),
        };
        if !(step_mm.is_finite() && step_mm > 0.0) {
            return Err(bad("grid step must be > 0"));
        }
        let g = &self.geometry;
        let reach = g.radius + g.rod_length;
        let mut z_lo = f64::INFINITY;
        let mut z_hi = f64::NEG_INFINITY;
        for (l, o) in self.limits.iter().zip(g.carriage_offsets) {
            // z = q + offset − h with 0 ≤ h ≤ L
            z_lo = z_lo.min(l.min + o - g.rod_length);
            z_hi = z_hi.max(l.max + o);
        }
        if !(z_lo.is_finite() && z_hi.is_finite()) {
            return Err(bad("workspace volume needs finite carriage limits"));
        }
        let nxy = (2.0 * reach / step_mm).ceil() as u64 + 1;
        let nz = ((z_hi - z_lo) / step_mm).ceil() as u64 + 1;
        if nxy.saturating_mul(nxy).saturating_mul(nz) > max_points {
            return Err(bad("grid too fine for max_points"));
        }
        let mut inside: u64 = 0;
        for ix in 0..nxy {
            let x = -reach + ix as f64 * step_mm;
            for iy in 0..nxy {
                let y = -reach + iy as f64 * step_mm;
                for iz in 0..nz {
                    let p = Vector3::new(x, y, z_lo + iz as f64 * step_mm);
                    if let Ok(q) = self.inverse_platform_checked(&p) {
                        if q.iter().zip(&self.limits).all(|(v, l)| l.contains(*v)) {
                            inside += 1;
                        }
                    }
                }
            }
        }
        Ok(inside as f64 * step_mm.powi(3))
    }

    #[cold]
    fn rod_error(&self, i: usize, d2: f64) -> KinematicsError {
        let d = d2.sqrt();
        if d >= self.geometry.rod_length {
            return KinematicsError::Unreachable {
                reason: format!(
                    "tower {} is {d:.3} mm away horizontally, beyond the rod length {}",
                    i + 1,
                    self.geometry.rod_length
                ),
            };
        }
        KinematicsError::Unreachable {
            reason: format!(
                "tower {} rod would be {:.3}° from the platform plane (minimum {:.3}°)",
                i + 1,
                (d2.sqrt() / self.geometry.rod_length)
                    .min(1.0)
                    .acos()
                    .to_degrees(),
                self.geometry.min_rod_angle.to_degrees()
            ),
        }
    }

    /// Platform point for joints: corrected closed form (Ayyıldız, 2017, eqs 3.6–3.15), any tower
    /// angles.
    pub fn forward_platform(&self, q: &[f64; 3]) -> Result<Vector3<f64>, KinematicsError> {
        let o = &self.geometry.carriage_offsets;
        // Work relative to carriage 1's height to keep the numbers small.
        let h1 = q[0] + o[0];
        let h = [0.0, q[1] + o[1] - h1, q[2] + o[2] - h1];
        let [(a1, b1), (a2, b2), (a3, b3)] = self.towers;
        let w = |a: f64, b: f64, hz: f64| a * a + b * b + hz * hz;
        // (a_i − a_1)·x + (b_i − b_1)·y = g_i − h_i·z  for i = 2, 3 (z relative to h1)
        let g2 = 0.5 * (w(a2, b2, h[1]) - w(a1, b1, 0.0));
        let g3 = 0.5 * (w(a3, b3, h[2]) - w(a1, b1, 0.0));
        let (m11, m12, m21, m22) = (a2 - a1, b2 - b1, a3 - a1, b3 - b1);
        let det = m11 * m22 - m12 * m21;
        // x = ex + fx·z, y = ey + fy·z (Cramer's rule)
        let ex = (m22 * g2 - m12 * g3) / det;
        let fx = (-m22 * h[1] + m12 * h[2]) / det;
        let ey = (m11 * g3 - m21 * g2) / det;
        let fy = (-m11 * h[2] + m21 * h[1]) / det;
        // Closure of tower 1: (x − a1)² + (y − b1)² + z² = L²  →  F z² + 2 G z + H = 0
        let (dx, dy) = (ex - a1, ey - b1);
        let f = fx * fx + fy * fy + 1.0;
        let gq = fx * dx + fy * dy;
        let hq = dx * dx + dy * dy - self.rod2;
        let disc = gq * gq - f * hq;
        if disc.is_nan() || disc < 0.0 {
            return Err(KinematicsError::Unreachable {
                reason: format!(
                    "carriage heights {:.4}, {:.4}, {:.4} admit no assembly (rods too short)",
                    q[0], q[1], q[2]
                ),
            });
        }
        // Smaller root: the platform hangs below the carriages.
        let z = (-gq - disc.sqrt()) / f;
        Ok(Vector3::new(ex + fx * z, ey + fy * z, z + h1))
    }

    /// ∂q/∂p at a platform point, differentiating eq. 3.5: rows (−Δx/hᵢ, −Δy/hᵢ, 1).
    pub fn inverse_jacobian(&self, p: &Vector3<f64>) -> Result<Matrix3<f64>, KinematicsError> {
        let mut m = Matrix3::zeros();
        for i in 0..3 {
            let dx = p.x - self.towers[i].0;
            let dy = p.y - self.towers[i].1;
            let hi = (self.rod2 - dx * dx - dy * dy).sqrt();
            if hi.is_nan() || hi <= 0.0 {
                return Err(KinematicsError::Singular {
                    reason: format!("tower {} rod horizontal", i + 1),
                });
            }
            m[(i, 0)] = -dx / hi;
            m[(i, 1)] = -dy / hi;
            m[(i, 2)] = 1.0;
        }
        Ok(m)
    }
}

impl Kinematics for LinearDelta {
    fn joint_limits(&self) -> &[JointLimit] {
        &self.limits
    }

    fn forward(&self, q: &Joints, tool: &Tool) -> Result<ToolPose, KinematicsError> {
        check_input(q, 3)?;
        let p = self.forward_platform(&[q[0], q[1], q[2]])?;
        Ok(ToolPose::vertical(Vector3::new(
            p.x,
            p.y,
            p.z - tool.length,
        )))
    }

    fn inverse(
        &self,
        pose: &ToolPose,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_pose(pose)?;
        // A delta has one solution; `previous` is only checked, for a uniform API.
        check_input(previous, 3)?;
        check_vertical_axis(pose, self.axis_sin, "a linear delta only translates")?;
        let p = Vector3::new(pose.tip.x, pose.tip.y, pose.tip.z + tool.length);
        let q = Joints::new(self.inverse_platform_checked(&p)?);
        check_limits(&q, &self.limits)?;
        Ok(q)
    }

    fn tcp_angles(&self, _q: &Joints) -> Joints {
        Joints::zeros(0)
    }

    fn tcp_inverse(
        &self,
        tip: &Vector3<f64>,
        angles: &Joints,
        tool: &Tool,
        previous: &Joints,
    ) -> Result<Joints, KinematicsError> {
        check_input(angles, 0)?;
        self.inverse(&ToolPose::vertical(*tip), tool, previous)
    }

    /// The carriages carry no program axis: X Y Z reach them only through the inverse.
    fn joint_axes(&self) -> Vec<Option<Axis>> {
        vec![None; 3]
    }

    fn tcp_joints(&self) -> Vec<usize> {
        Vec::new()
    }

    fn jacobian(&self, q: &Joints, _tool: &Tool) -> Result<Jacobian, KinematicsError> {
        check_input(q, 3)?;
        let p = self.forward_platform(&[q[0], q[1], q[2]])?;
        let inv =
            self.inverse_jacobian(&p)?
                .try_inverse()
                .ok_or_else(|| KinematicsError::Singular {
                    reason: "delta Jacobian not invertible".into(),
                })?;
        let mut j = Jacobian::zeros(3);
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&inv);
        Ok(j)
    }
}
