//! Segmentation by deviation, not time: a move that is straight in program space is split so
//! that interpolating the JOINTS linearly inside each piece keeps the tool tip within the
//! tolerance of the programmed line. Used between the planner and joint-space sinks for
//! non-linear machines (Ayyıldız, 2017, converts end points only: its 100 mm XY
//! diagonal sags 4.6 mm in Z, Table 5.2).
//!
//! Program space: tip on the straight line; tool axis on the great circle between the end
//! axes (Rodrigues with the normalised rotation axis; Kahraman et al.'s eq. 1 omits the
//! normalisation), or, under TCP, the rotary angles interpolated linearly.

use nalgebra::{Unit, Vector3};

use crate::error::KinematicsError;
use crate::kinematics::Kinematics;
use crate::pose::{Joints, Tool, ToolPose};
use crate::tcp::ProgramPose;

/// How finely to split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentOptions {
    /// Largest distance (mm) of the joint-interpolated tip from the programmed line.
    pub tolerance_mm: f64,
    /// Largest angle (rad) between the joint-interpolated and the programmed tool axis;
    /// `None` checks the tip only.
    pub axis_tolerance_rad: Option<f64>,
    /// Interior points checked per piece (the sag of a short piece is close to a parabola,
    /// largest near the middle; 3 catches it, more are safer on long pieces).
    pub checks_per_piece: usize,
    /// Largest number of halvings; reaching it means the tolerance cannot be met here
    /// (e.g. a pass through a singularity) and is an error rather than a silent overrun.
    pub max_depth: u32,
}

impl SegmentOptions {
    /// Tip tolerance only, 3 checks per piece, at most 2⁴⁰ pieces along any branch.
    pub fn tip(tolerance_mm: f64) -> Self {
        Self {
            tolerance_mm,
            axis_tolerance_rad: None,
            checks_per_piece: 3,
            max_depth: 40,
        }
    }
}

/// The joint waypoints of a split move, including both ends; joints are interpolated
/// linearly between consecutive waypoints.
#[derive(Clone, Debug, PartialEq)]
pub struct Segmented {
    /// (path parameter s ∈ [0, 1], joints) per waypoint, increasing s.
    pub points: Vec<(f64, Joints)>,
    /// Largest tip deviation found at the accepted pieces' check points, mm.
    pub max_deviation_mm: f64,
}

/// The tool axis a fraction `t` of the way from `v` to `u` along the great circle:
/// O(θ) = V·cos θ + (k̂ × V)·sin θ with k̂ = V×U/|V×U| (Kahraman et al., eqs 1–3, with
/// the normalisation the paper omits). Fails for opposite axes, where the circle is undefined.
pub fn slerp_axis(
    v: &Unit<Vector3<f64>>,
    u: &Unit<Vector3<f64>>,
    t: f64,
) -> Result<Unit<Vector3<f64>>, KinematicsError> {
    let cross = v.cross(u);
    let s = cross.norm();
    let theta_max = s.atan2(v.dot(u));
    if s <= f64::EPSILON {
        if v.dot(u) > 0.0 {
            return Ok(*v);
        }
        return Err(KinematicsError::BadInput {
            reason: "tool axis reverses: the rotation between opposite axes is undefined".into(),
        });
    }
    let k = cross / s;
    let th = t * theta_max;
    Ok(Unit::new_normalize(
        v.into_inner() * th.cos() + k.cross(v) * th.sin(),
    ))
}

/// Distance from `p` to the segment `a`–`b`, with the offset vector p − closest.
#[inline]
pub fn distance_to_segment(
    p: &Vector3<f64>,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
) -> (f64, Vector3<f64>) {
    let d = b - a;
    let len2 = d.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let off = p - (a + d * t);
    (off.norm(), off)
}

/// The worst tip deviation when the joints move linearly from `q0` to `q1` and the
/// programmed path is the straight line `a`–`b`, checked at `samples` evenly spaced interior
/// points. Returns (distance mm, parameter t, offset vector from the line).
pub fn joint_line_deviation<K: Kinematics + ?Sized>(
    kinematics: &K,
    tool: &Tool,
    q0: &Joints,
    q1: &Joints,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    samples: usize,
) -> Result<(f64, f64, Vector3<f64>), KinematicsError> {
    let mut worst = (0.0, 0.0, Vector3::zeros());
    for k in 1..=samples {
        let t = k as f64 / (samples + 1) as f64;
        let tip = kinematics.forward(&q0.lerp(q1, t), tool)?.tip;
        let (d, off) = distance_to_segment(&tip, a, b);
        if d > worst.0 {
            worst = (d, t, off);
        }
    }
    Ok(worst)
}

/// Splits a move between two tool poses (tip straight, axis on the great circle).
/// `previous` is the joint set before the move (continuity of every inverse).
pub fn segment_pose_line<K: Kinematics + ?Sized>(
    kinematics: &K,
    tool: &Tool,
    start: &ToolPose,
    end: &ToolPose,
    previous: &Joints,
    options: &SegmentOptions,
) -> Result<Segmented, KinematicsError> {
    // Fail early on a reversing axis rather than in the middle of the recursion.
    slerp_axis(&start.axis, &end.axis, 0.5)?;
    let target = |s: f64, prev: &Joints| -> Result<(Joints, Unit<Vector3<f64>>), KinematicsError> {
        let axis = slerp_axis(&start.axis, &end.axis, s)?;
        let pose = ToolPose {
            tip: start.tip + (end.tip - start.tip) * s,
            axis,
        };
        Ok((kinematics.inverse(&pose, tool, prev)?, axis))
    };
    segment_line_by(
        kinematics, tool, &start.tip, &end.tip, previous, options, &target,
    )
}

/// Splits a TCP move: tip straight, program angles linear (G43.4 semantics).
pub fn segment_tcp_line<K: Kinematics + ?Sized>(
    kinematics: &K,
    tool: &Tool,
    start: &ProgramPose,
    end: &ProgramPose,
    previous: &Joints,
    options: &SegmentOptions,
) -> Result<Segmented, KinematicsError> {
    let target = |s: f64, prev: &Joints| -> Result<(Joints, Unit<Vector3<f64>>), KinematicsError> {
        let p = start.lerp(end, s);
        let q = kinematics.tcp_inverse(&p.tip, &p.angles, tool, prev)?;
        Ok((q, kinematics.forward(&q, tool)?.axis))
    };
    segment_line_by(
        kinematics, tool, &start.tip, &end.tip, previous, options, &target,
    )
}

/// The joints (and tool axis) at fraction `s` ∈ [0, 1] of a straight tip move, solved nearest
/// the given joints: how a caller tells [`segment_line_by`] what the program asks for.
pub type Target<'a> =
    dyn Fn(f64, &Joints) -> Result<(Joints, Unit<Vector3<f64>>), KinematicsError> + 'a;

/// Splits a straight tip move `a`–`b` whose joints along it come from `target` (the tip at
/// fraction `s` must be `a + (b − a)·s`): the one splitter behind [`segment_pose_line`],
/// [`segment_tcp_line`] and callers with their own pose law (a planned path's tool axis).
///
/// Walks to the end in a few steps so the end joints continue the path (a C table that turns
/// more than half a turn during the move must not be unwrapped the short way), then halves
/// the move until each piece meets the tolerance. Midpoints are solved with the joint-space
/// midpoint as the continuity reference, so they stay on the same branch and turn.
pub fn segment_line_by<K: Kinematics + ?Sized>(
    kinematics: &K,
    tool: &Tool,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    previous: &Joints,
    options: &SegmentOptions,
    target: &Target<'_>,
) -> Result<Segmented, KinematicsError> {
    const WALK: usize = 8;
    let (q_start, _) = target(0.0, previous)?;
    let mut q_end = q_start;
    let mut ax_end = None;
    for k in 1..=WALK {
        let (q, ax) = target(k as f64 / WALK as f64, &q_end)?;
        q_end = q;
        ax_end = Some(ax);
    }
    let ax_end = ax_end.unwrap_or_else(Vector3::z_axis);
    let mut points = vec![(0.0, q_start)];
    let mut max_dev: f64 = 0.0;
    refine(
        kinematics,
        tool,
        a,
        b,
        options,
        target,
        (0.0, q_start),
        (1.0, q_end, ax_end),
        0,
        &mut points,
        &mut max_dev,
    )?;
    Ok(Segmented {
        points,
        max_deviation_mm: max_dev,
    })
}

#[allow(clippy::too_many_arguments)]
fn refine<K: Kinematics + ?Sized>(
    kinematics: &K,
    tool: &Tool,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    options: &SegmentOptions,
    target: &Target<'_>,
    left: (f64, Joints),
    right: (f64, Joints, Unit<Vector3<f64>>),
    depth: u32,
    points: &mut Vec<(f64, Joints)>,
    max_dev: &mut f64,
) -> Result<(), KinematicsError> {
    let (s0, q0) = left;
    let (s1, q1, ax1) = right;
    let n = options.checks_per_piece.max(1);
    let mut worst: f64 = 0.0;
    let mut axis_ok = true;
    for k in 1..=n {
        let t = k as f64 / (n + 1) as f64;
        let pose = kinematics.forward(&q0.lerp(&q1, t), tool)?;
        worst = worst.max(distance_to_segment(&pose.tip, a, b).0);
        if let Some(tol) = options.axis_tolerance_rad {
            let s = s0 + (s1 - s0) * t;
            let (_, want) = target(s, &q0.lerp(&q1, t))?;
            let ang = pose.axis.cross(&want).norm().atan2(pose.axis.dot(&want));
            axis_ok &= ang <= tol;
        }
    }
    if worst <= options.tolerance_mm && axis_ok {
        *max_dev = max_dev.max(worst);
        points.push((s1, q1));
        return Ok(());
    }
    if depth >= options.max_depth {
        return Err(KinematicsError::Unreachable {
            reason: format!(
                "cannot keep the tip within {} mm near s = {:.6} (deviation {:.3e} mm after {} halvings)",
                options.tolerance_mm, s0, worst, depth
            ),
        });
    }
    let sm = 0.5 * (s0 + s1);
    let (qm, axm) = target(sm, &q0.lerp(&q1, 0.5))?;
    refine(
        kinematics,
        tool,
        a,
        b,
        options,
        target,
        (s0, q0),
        (sm, qm, axm),
        depth + 1,
        points,
        max_dev,
    )?;
    refine(
        kinematics,
        tool,
        a,
        b,
        options,
        target,
        (sm, qm),
        (s1, q1, ax1),
        depth + 1,
        points,
        max_dev,
    )
}
