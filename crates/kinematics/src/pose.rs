//! Typed values that flow through kinematics: joint sets, tool poses, tools and joint limits.
//! Joint sets go in and out of every model; poses are what the interpolator produces in
//! workpiece coordinates (ARCHITECTURE.md, "Data flow"). Internal units are mm and rad.

use nalgebra::{Unit, Vector3};

use crate::error::KinematicsError;

/// Largest number of joints a model handles (X Y Z plus three rotaries).
pub const MAX_JOINTS: usize = 6;

/// A joint set in internal units: mm for linear joints, **radians** for rotary joints.
///
/// Fixed capacity so the inverse kinematics in the 1 ms loop never allocates. Degrees exist
/// only at the machine-file and samples-CSV boundary (see [`crate::machine::Machine::to_file_units`]).
#[derive(Clone, Copy, PartialEq, Debug)]
pub struct Joints {
    len: u8,
    v: [f64; MAX_JOINTS],
}

impl Joints {
    /// Joint set from a slice; fails if there are more than [`MAX_JOINTS`] values.
    pub fn from_slice(values: &[f64]) -> Result<Self, KinematicsError> {
        if values.len() > MAX_JOINTS {
            return Err(KinematicsError::BadInput {
                reason: format!("{} joints given, at most {MAX_JOINTS}", values.len()),
            });
        }
        let mut v = [0.0; MAX_JOINTS];
        v[..values.len()].copy_from_slice(values);
        Ok(Self {
            len: values.len() as u8,
            v,
        })
    }

    /// Joint set from a fixed array (compile-time sized; `N ≤ MAX_JOINTS` is checked at compile time).
    pub const fn new<const N: usize>(values: [f64; N]) -> Self {
        const { assert!(N <= MAX_JOINTS) };
        let mut v = [0.0; MAX_JOINTS];
        let mut i = 0;
        while i < N {
            v[i] = values[i];
            i += 1;
        }
        Self { len: N as u8, v }
    }

    /// `n` joints at zero (`n` is clamped to [`MAX_JOINTS`]).
    #[inline]
    pub fn zeros(n: usize) -> Self {
        Self {
            len: n.min(MAX_JOINTS) as u8,
            v: [0.0; MAX_JOINTS],
        }
    }

    /// Number of joints.
    #[inline]
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// True for a machine without joints (never a valid machine; useful as a placeholder).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The values.
    #[inline]
    pub fn as_slice(&self) -> &[f64] {
        &self.v[..self.len as usize]
    }

    /// The values, mutable.
    #[inline]
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.v[..self.len as usize]
    }

    /// Linear interpolation `self + t·(other − self)`, joint by joint (the joint-space move).
    pub fn lerp(&self, other: &Joints, t: f64) -> Joints {
        let mut out = *self;
        for (o, (a, b)) in out
            .as_mut_slice()
            .iter_mut()
            .zip(self.as_slice().iter().zip(other.as_slice()))
        {
            *o = a + t * (b - a);
        }
        out
    }

    /// All values finite.
    pub fn is_finite(&self) -> bool {
        self.as_slice().iter().all(|x| x.is_finite())
    }
}

impl std::ops::Index<usize> for Joints {
    type Output = f64;
    #[inline]
    fn index(&self, i: usize) -> &f64 {
        &self.as_slice()[i]
    }
}

impl std::ops::IndexMut<usize> for Joints {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.as_mut_slice()[i]
    }
}

/// Tool tip and tool axis in the workpiece frame (mm; the axis is a unit vector from the
/// tip toward the spindle; docs/machine-files.md, "Kinematic conventions").
#[derive(Clone, Copy, PartialEq, Debug)]
pub struct ToolPose {
    /// Tool tip, mm, workpiece frame.
    pub tip: Vector3<f64>,
    /// Unit tool axis, tip → spindle, workpiece frame.
    pub axis: Unit<Vector3<f64>>,
}

impl ToolPose {
    /// Pose from a tip and any non-zero axis vector (normalised here).
    pub fn new(tip: Vector3<f64>, axis: Vector3<f64>) -> Self {
        Self {
            tip,
            axis: Unit::new_normalize(axis),
        }
    }

    /// Pose with the tool along workpiece +Z (3-axis work).
    pub fn vertical(tip: Vector3<f64>) -> Self {
        Self {
            tip,
            axis: Vector3::z_axis(),
        }
    }
}

/// The tool as kinematics sees it: its length from the spindle gauge point to the tip.
///
/// Linear joints position the gauge point (tool length 0); the tip is `length` further
/// along −axis. The tool table supplies the value (G43/G43.4 H).
#[derive(Clone, Copy, PartialEq, Debug, Default)]
pub struct Tool {
    /// Gauge point to tool tip, mm (≥ 0 in practice; not enforced so probes can be modelled).
    pub length: f64,
}

impl Tool {
    /// A tool of the given length (mm).
    pub const fn with_length(length: f64) -> Self {
        Self { length }
    }
}

/// Linear (mm) or rotary (degrees in files, radians inside).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum JointKind {
    /// Moves in mm.
    Linear,
    /// Turns; degrees at the boundary, radians inside.
    Rotary,
}

/// Position limits of one joint in internal units (mm or rad).
#[derive(Clone, PartialEq, Debug)]
pub struct JointLimit {
    /// Joint name from the machine file (for error messages).
    pub name: String,
    /// Linear or rotary.
    pub kind: JointKind,
    /// Lower limit (mm or rad); `-inf` for an endless rotary.
    pub min: f64,
    /// Upper limit (mm or rad); `+inf` for an endless rotary.
    pub max: f64,
}

impl JointLimit {
    /// A limit in internal units.
    pub fn new(name: &str, kind: JointKind, min: f64, max: f64) -> Self {
        Self {
            name: name.to_owned(),
            kind,
            min,
            max,
        }
    }

    /// An endless rotary (a C table that turns forever).
    pub fn endless(name: &str) -> Self {
        Self::new(name, JointKind::Rotary, f64::NEG_INFINITY, f64::INFINITY)
    }

    /// No limit at all (used by models built in code without a machine file).
    pub fn unlimited(name: &str, kind: JointKind) -> Self {
        Self::new(name, kind, f64::NEG_INFINITY, f64::INFINITY)
    }

    /// True if `value` is inside `[min, max]`.
    #[inline]
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }

    /// The error for `value` at joint index `joint`, in machine-file units.
    pub fn violation(&self, joint: usize, value: f64) -> KinematicsError {
        let (scale, unit) = match self.kind {
            JointKind::Linear => (1.0, "mm"),
            JointKind::Rotary => (180.0 / std::f64::consts::PI, "deg"),
        };
        KinematicsError::JointLimit {
            joint,
            name: self.name.clone(),
            value: value * scale,
            min: self.min * scale,
            max: self.max * scale,
            unit,
        }
    }
}

/// Checks every joint against its limit; the first violation is the error.
#[inline]
pub fn check_limits(q: &Joints, limits: &[JointLimit]) -> Result<(), KinematicsError> {
    if q.len() != limits.len() {
        return Err(KinematicsError::BadInput {
            reason: format!("{} joints given, machine has {}", q.len(), limits.len()),
        });
    }
    if q.as_slice().iter().zip(limits).all(|(v, l)| l.contains(*v)) {
        return Ok(());
    }
    limit_violation(q, limits)
}

#[cold]
fn limit_violation(q: &Joints, limits: &[JointLimit]) -> Result<(), KinematicsError> {
    for (i, (v, l)) in q.as_slice().iter().zip(limits).enumerate() {
        if !l.contains(*v) {
            return Err(l.violation(i, *v));
        }
    }
    Ok(())
}
