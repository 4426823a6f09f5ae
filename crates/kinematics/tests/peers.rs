//! Cross-checks against peers' formulas, each re-implemented here from its published
//! equations: LinuxCNC lineardeltakins, Klipper's delta (inverse per stepper, forward by
//! trilateration), Ayyıldız's (2017) closed form as corrected in docs/errata.md, and LinuxCNC's
//! xyzac/xyzbc-trt kinematics (trtfuncs.c, TCP with tool offset).

use nalgebra::Vector3;
use proptest::prelude::*;
use tezgah_kinematics::linear_delta::{DeltaGeometry, LinearDelta};
use tezgah_kinematics::trunnion::{TiltAxis, Trunnion};
use tezgah_kinematics::{JointKind, JointLimit, Joints, Kinematics, Tolerances, Tool, ToolPose};

fn free_limits(kinds: &[JointKind]) -> Vec<JointLimit> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, k)| JointLimit::unlimited(&format!("j{i}"), *k))
        .collect()
}

fn delta(radius: f64, rod: f64, angles_deg: [f64; 3], offsets: [f64; 3]) -> LinearDelta {
    LinearDelta::new(
        DeltaGeometry {
            radius,
            rod_length: rod,
            tower_angles: angles_deg.map(f64::to_radians),
            carriage_offsets: offsets,
            min_rod_angle: 0.0,
            max_joint_angle: None,
        },
        free_limits(&[JointKind::Linear; 3]),
        Tolerances::default(),
    )
    .unwrap()
}

// ---- LinuxCNC lineardeltakins (tower 0 at (0, R), 1 at (−sin60·R, −cos60·R), 2 at (sin60·R, −cos60·R))

struct Lcnc {
    l: f64,
    t: [(f64, f64); 3],
    joff: [f64; 3],
}

impl Lcnc {
    fn new(r: f64, l: f64, joff: [f64; 3]) -> Self {
        let (s60, c60) = (3f64.sqrt() / 2.0, 0.5);
        Self {
            l,
            t: [(0.0, r), (-s60 * r, -c60 * r), (s60 * r, -c60 * r)],
            joff,
        }
    }
    fn inverse(&self, p: Vector3<f64>) -> [f64; 3] {
        let l2 = self.l * self.l;
        [0, 1, 2].map(|i| {
            p.z + (l2 - (self.t[i].0 - p.x).powi(2) - (self.t[i].1 - p.y).powi(2)).sqrt()
                + self.joff[i]
        })
    }
    fn forward(&self, j: [f64; 3]) -> Option<Vector3<f64>> {
        let [(_, ay), (bx, by), (cx, cy)] = self.t;
        let (q1, q2, q3) = (
            j[0] - self.joff[0],
            j[1] - self.joff[1],
            j[2] - self.joff[2],
        );
        let den = (by - ay) * cx - (cy - ay) * bx;
        let w1 = ay * ay + q1 * q1;
        let w2 = bx * bx + by * by + q2 * q2;
        let w3 = cx * cx + cy * cy + q3 * q3;
        let a1 = (q2 - q1) * (cy - ay) - (q3 - q1) * (by - ay);
        let b1 = -((w2 - w1) * (cy - ay) - (w3 - w1) * (by - ay)) / 2.0;
        let a2 = -(q2 - q1) * cx + (q3 - q1) * bx;
        let b2 = ((w2 - w1) * cx - (w3 - w1) * bx) / 2.0;
        let a = a1 * a1 + a2 * a2 + den * den;
        let b = 2.0 * (a1 * b1 + a2 * (b2 - ay * den) - q1 * den * den);
        let c = (b2 - ay * den).powi(2) + b1 * b1 + den * den * (q1 * q1 - self.l * self.l);
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let z = -0.5 * (b + disc.sqrt()) / a;
        Some(Vector3::new((a1 * z + b1) / den, (a2 * z + b2) / den, z))
    }
}

// ---- Klipper delta: stepper position sqrt(arm² − dx² − dy²) + z; forward by trilateration

fn klipper_towers(radius: f64, angles: [f64; 3]) -> [(f64, f64); 3] {
    angles.map(|a| (a.to_radians().cos() * radius, a.to_radians().sin() * radius))
}

fn klipper_trilateration(spheres: [Vector3<f64>; 3], arm2: f64) -> Vector3<f64> {
    // Sphere intersection in the frame spanned by the three carriage joints (all radii arm).
    let [s1, s2, s3] = spheres;
    let s21 = s2 - s1;
    let s31 = s3 - s1;
    let d = s21.norm();
    let ex = s21 / d;
    let i = ex.dot(&s31);
    let vect_ey = s31 - ex * i;
    let ey = vect_ey / vect_ey.norm();
    let ez = ex.cross(&ey);
    let j = ey.dot(&s31);
    let x = (d * d) / (2.0 * d);
    let y = (i * i + j * j - 2.0 * i * x) / (2.0 * j);
    let z = -(arm2 - x * x - y * y).sqrt();
    s1 + ex * x + ey * y + ez * z
}

// ---- Ayyıldız (2017), eqs 3.6–3.15 corrected (towers at 0°, 120°, 240°, absolute q)

fn ref002_forward(r: f64, l: f64, q: [f64; 3]) -> Vector3<f64> {
    let s = 3f64.sqrt();
    let (q1, q2, q3) = (q[0], q[1], q[2]);
    let a = (q3 - q2) / (s * r);
    let b = (q2 * q2 - q3 * q3) / (2.0 * s * r);
    let c = (2.0 * (q2 - q1) + s * r * a) / (3.0 * r);
    let d = (q1 * q1 - q2 * q2 + s * r * b) / (3.0 * r);
    let f = a * a + c * c + 1.0;
    let g = c * (d - r) + a * b - q1;
    let h = (d - r).powi(2) + b * b + q1 * q1 - l * l;
    let z = (-g - (g * g - f * h).sqrt()) / f;
    Vector3::new(c * z + d, a * z + b, z)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn linuxcnc_lineardeltakins(x in -100.0..100.0f64, y in -100.0..100.0f64, z in -50.0..50.0f64,
                                j0 in -5.0..5.0f64, j1 in -5.0..5.0f64, j2 in -5.0..5.0f64) {
        // LinuxCNC's defaults: R = 198.25 − 33 − 35 = 130.25, L = 269. Its joint offsets are
        // added; ours are subtracted.
        let peer = Lcnc::new(130.25, 269.0, [j0, j1, j2]);
        let ours = delta(130.25, 269.0, [90.0, 210.0, 330.0], [-j0, -j1, -j2]);
        let p = Vector3::new(x, y, z);
        let qp = peer.inverse(p);
        let qo = ours.inverse(&ToolPose::vertical(p), &Tool::default(), &Joints::zeros(3)).unwrap();
        for i in 0..3 { prop_assert!((qp[i] - qo[i]).abs() < 1e-9, "{qp:?} vs {qo:?}"); }
        let fp = peer.forward(qp).unwrap();
        let fo = ours.forward(&qo, &Tool::default()).unwrap().tip;
        prop_assert!((fp - fo).norm() < 1e-9 && (fo - p).norm() < 1e-9, "{fp:?} {fo:?} {p:?}");
    }

    #[test]
    fn klipper_delta(x in -100.0..100.0f64, y in -100.0..100.0f64, z in -50.0..50.0f64,
                     radius in 100.0..200.0f64, arm_extra in 50.0..200.0f64) {
        // Klipper's default stepper angles 210°, 330°, 90°.
        let angles = [210.0, 330.0, 90.0];
        let arm = radius + arm_extra;
        let ours = delta(radius, arm, angles, [0.0; 3]);
        let towers = klipper_towers(radius, angles);
        let p = Vector3::new(x, y, z);
        prop_assume!(towers.iter().all(|(tx, ty)| (tx - x).hypot(ty - y) < 0.99 * arm));
        let q: Vec<f64> = towers.iter().map(|(tx, ty)| (arm * arm - (tx - x).powi(2) - (ty - y).powi(2)).sqrt() + z).collect();
        let qo = ours.inverse(&ToolPose::vertical(p), &Tool::default(), &Joints::zeros(3)).unwrap();
        for i in 0..3 { prop_assert!((q[i] - qo[i]).abs() < 1e-9); }
        let spheres = [0, 1, 2].map(|i| Vector3::new(towers[i].0, towers[i].1, q[i]));
        let fk = klipper_trilateration(spheres, arm * arm);
        let fo = ours.forward(&qo, &Tool::default()).unwrap().tip;
        prop_assert!((fk - fo).norm() < 1e-8, "{fk:?} vs {fo:?}");
    }

    #[test]
    fn ayyildiz_corrected_closed_form(x in -120.0..120.0f64, y in -120.0..120.0f64, z in -100.0..100.0f64) {
        let ours = delta(160.0, 350.0, [0.0, 120.0, 240.0], [0.0; 3]);
        let p = Vector3::new(x, y, z);
        let q = ours.inverse(&ToolPose::vertical(p), &Tool::default(), &Joints::zeros(3)).unwrap();
        let f = ref002_forward(160.0, 350.0, [q[0], q[1], q[2]]);
        let fo = ours.forward(&q, &Tool::default()).unwrap().tip;
        prop_assert!((f - p).norm() < 1e-9 && (fo - p).norm() < 1e-9, "{f:?} {fo:?} {p:?}");
    }

    /// LinuxCNC xyzac-trt (trtfuncs.c): rot point, y/z offsets and tool offset. Our
    /// pivot = rot + d, c_offset = −d, part tip = pos − rot − tool·ẑ, where pos is LinuxCNC's
    /// tool-length-compensated position and d = (0, dy, dz).
    #[test]
    fn linuxcnc_xyzac_trt(px in -100.0..100.0f64, py in -100.0..100.0f64, pz in -100.0..100.0f64,
                          a in -120.0..120.0f64, c in -400.0..400.0f64,
                          rx in -50.0..50.0f64, ry in -50.0..50.0f64, rz in -50.0..50.0f64,
                          dy in -20.0..20.0f64, dz in -20.0..20.0f64, dt in 0.0..100.0f64) {
        let (ar, cr) = (a.to_radians(), c.to_radians());
        let (sa, ca, sc, cc) = (ar.sin(), ar.cos(), cr.sin(), cr.cos());
        let dzt = dz + dt;
        // trtfuncs.c xyzacKinematicsInverse
        let jx = cc * (px - rx) - sc * (py - ry) + rx;
        let jy = sc * ca * (px - rx) + cc * ca * (py - ry) - sa * (pz - rz) - ca * dy + sa * dzt + dy + ry;
        let jz = sc * sa * (px - rx) + cc * sa * (py - ry) + ca * (pz - rz) - sa * dy - ca * dzt + dzt + rz;
        let d = Vector3::new(0.0, dy, dz);
        let rot = Vector3::new(rx, ry, rz);
        let m = Trunnion::new(TiltAxis::X, rot + d, -d, free_limits(&[JointKind::Linear, JointKind::Linear, JointKind::Linear, JointKind::Rotary, JointKind::Rotary]), Tolerances::default()).unwrap();
        let tool = Tool::with_length(dt);
        let tip = Vector3::new(px, py, pz) - rot - Vector3::z() * dt;
        let q = m.tcp_inverse(&tip, &Joints::new([ar, cr]), &tool, &Joints::zeros(5)).unwrap();
        prop_assert!((q[0] - jx).abs() < 1e-9 && (q[1] - jy).abs() < 1e-9 && (q[2] - jz).abs() < 1e-9,
            "{:?} vs ({jx}, {jy}, {jz})", q);
        // trtfuncs.c xyzacKinematicsForward
        let fx = cc * jx - cc * rx + sc * ca * (jy - dy - ry) + sc * sa * (jz - dzt - rz) + sc * dy + rx;
        let fy = -sc * (jx - rx) + cc * ca * (jy - dy - ry) + cc * sa * (jz - dzt - rz) + cc * dy + ry;
        let fz = -sa * (jy - dy - ry) + ca * (jz - dzt - rz) + dzt + rz;
        let f = m.forward(&q, &tool).unwrap().tip + rot + Vector3::z() * dt;
        prop_assert!((f - Vector3::new(fx, fy, fz)).norm() < 1e-9);
        prop_assert!((f - Vector3::new(px, py, pz)).norm() < 1e-9);
    }

    /// LinuxCNC xyzbc-trt (trtfuncs.c), d = (dx, 0, dz).
    #[test]
    fn linuxcnc_xyzbc_trt(px in -100.0..100.0f64, py in -100.0..100.0f64, pz in -100.0..100.0f64,
                          b in -120.0..120.0f64, c in -400.0..400.0f64,
                          rx in -50.0..50.0f64, ry in -50.0..50.0f64, rz in -50.0..50.0f64,
                          dx in -20.0..20.0f64, dz in -20.0..20.0f64, dt in 0.0..100.0f64) {
        let (br, cr) = (b.to_radians(), c.to_radians());
        let (sb, cb, sc, cc) = (br.sin(), br.cos(), cr.sin(), cr.cos());
        let dzt = dz + dt;
        let dpx = -cb * dx - sb * dzt + dx;
        let dpz = sb * dx - cb * dzt + dzt;
        // trtfuncs.c xyzbcKinematicsInverse
        let jx = cc * cb * (px - rx) - sc * cb * (py - ry) + sb * (pz - rz) + dpx + rx;
        let jy = sc * (px - rx) + cc * (py - ry) + ry;
        let jz = -cc * sb * (px - rx) + sc * sb * (py - ry) + cb * (pz - rz) + dpz + rz;
        let d = Vector3::new(dx, 0.0, dz);
        let rot = Vector3::new(rx, ry, rz);
        let m = Trunnion::new(TiltAxis::Y, rot + d, -d, free_limits(&[JointKind::Linear, JointKind::Linear, JointKind::Linear, JointKind::Rotary, JointKind::Rotary]), Tolerances::default()).unwrap();
        let tool = Tool::with_length(dt);
        let tip = Vector3::new(px, py, pz) - rot - Vector3::z() * dt;
        let q = m.tcp_inverse(&tip, &Joints::new([br, cr]), &tool, &Joints::zeros(5)).unwrap();
        prop_assert!((q[0] - jx).abs() < 1e-9 && (q[1] - jy).abs() < 1e-9 && (q[2] - jz).abs() < 1e-9,
            "{:?} vs ({jx}, {jy}, {jz})", q);
        // trtfuncs.c xyzbcKinematicsForward
        let fx = cc * cb * (jx - dx - rx) + sc * (jy - ry) - cc * sb * (jz - dzt - rz) + cc * dx + rx;
        let fy = -sc * cb * (jx - dx - rx) + cc * (jy - ry) + sc * sb * (jz - dzt - rz) - sc * dx + ry;
        let fz = sb * (jx - dx - rx) + cb * (jz - dzt - rz) + dzt + rz;
        let f = m.forward(&q, &tool).unwrap().tip + rot + Vector3::z() * dt;
        prop_assert!((f - Vector3::new(fx, fy, fz)).norm() < 1e-9);
        prop_assert!((f - Vector3::new(px, py, pz)).norm() < 1e-9);
    }
}
