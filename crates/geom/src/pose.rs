//! Positions of the six program axes X Y Z (mm) and A B C (degrees).
//!
//! A `Pose` is what a block of G-code commands: the tool tip and the rotary axes. Later stages
//! interpret A B C through the machine's kinematics.

use std::ops::{Add, Index, IndexMut, Neg, Sub};

/// One of the six program axes, in the order LinuxCNC prints them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    X,
    Y,
    Z,
    A,
    B,
    C,
}

impl Axis {
    /// All axes in canonical order.
    pub const ALL: [Axis; 6] = [Axis::X, Axis::Y, Axis::Z, Axis::A, Axis::B, Axis::C];

    /// Index into a [`Pose`].
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Linear axes are X, Y and Z; A, B and C are rotary (degrees).
    pub const fn is_linear(self) -> bool {
        (self as usize) < 3
    }

    /// The upper-case letter of the axis.
    pub const fn letter(self) -> char {
        ['X', 'Y', 'Z', 'A', 'B', 'C'][self as usize]
    }
}

/// A position of the six program axes: X Y Z in length units, A B C in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose(pub [f64; 6]);

impl Pose {
    pub const ZERO: Pose = Pose([0.0; 6]);

    pub const fn new(x: f64, y: f64, z: f64, a: f64, b: f64, c: f64) -> Self {
        Pose([x, y, z, a, b, c])
    }

    pub fn x(&self) -> f64 {
        self.0[0]
    }
    pub fn y(&self) -> f64 {
        self.0[1]
    }
    pub fn z(&self) -> f64 {
        self.0[2]
    }

    /// The linear part as an array.
    pub fn xyz(&self) -> [f64; 3] {
        [self.0[0], self.0[1], self.0[2]]
    }

    /// Scale the linear axes only (unit conversion leaves degrees alone).
    pub fn scale_linear(self, k: f64) -> Pose {
        let mut p = self;
        for v in &mut p.0[..3] {
            *v *= k;
        }
        p
    }

    /// Euclidean length of the linear part of a displacement.
    pub fn linear_norm(&self) -> f64 {
        (self.0[0] * self.0[0] + self.0[1] * self.0[1] + self.0[2] * self.0[2]).sqrt()
    }

    /// Euclidean length of the rotary part of a displacement (degrees).
    pub fn rotary_norm(&self) -> f64 {
        (self.0[3] * self.0[3] + self.0[4] * self.0[4] + self.0[5] * self.0[5]).sqrt()
    }
}

impl Index<Axis> for Pose {
    type Output = f64;
    fn index(&self, a: Axis) -> &f64 {
        &self.0[a.index()]
    }
}

impl IndexMut<Axis> for Pose {
    fn index_mut(&mut self, a: Axis) -> &mut f64 {
        &mut self.0[a.index()]
    }
}

impl Add for Pose {
    type Output = Pose;
    fn add(self, o: Pose) -> Pose {
        Pose(std::array::from_fn(|i| self.0[i] + o.0[i]))
    }
}

impl Sub for Pose {
    type Output = Pose;
    fn sub(self, o: Pose) -> Pose {
        Pose(std::array::from_fn(|i| self.0[i] - o.0[i]))
    }
}

impl Neg for Pose {
    type Output = Pose;
    fn neg(self) -> Pose {
        Pose(self.0.map(|v| -v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_linear_keeps_degrees() {
        let p = Pose::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0).scale_linear(25.4);
        assert_eq!(p, Pose::new(25.4, 50.8, 76.19999999999999, 4.0, 5.0, 6.0));
        assert_eq!(p[Axis::C], 6.0);
    }
}
