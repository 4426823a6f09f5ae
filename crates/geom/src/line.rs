//! A straight segment (G0/G1 move) as a [`Curve`], parameterised by arc length so that the
//! arc-length map is the identity and the planner's `u` is the distance travelled.

use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;

/// Line from `start` to `end`, `u` in `[0, length]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    start: Vec3,
    end: Vec3,
    length: f64,
    dir: Vec3,
}

impl Line {
    /// A line between two points. A zero-length line is allowed (it stands still: its
    /// direction is zero and its domain `[0, 0]`), since a program may repeat a point.
    pub fn new(start: Vec3, end: Vec3) -> Result<Self, CurveError> {
        if !start.iter().chain(end.iter()).all(|c| c.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        let length = (end - start).norm();
        let dir = if length > 0.0 {
            (end - start) / length
        } else {
            Vec3::zeros()
        };
        Ok(Line {
            start,
            end,
            length,
            dir,
        })
    }

    pub fn start(&self) -> Vec3 {
        self.start
    }
    pub fn end(&self) -> Vec3 {
        self.end
    }
    /// Unit direction (zero for a zero-length line).
    pub fn direction(&self) -> Vec3 {
        self.dir
    }
}

impl Curve for Line {
    fn domain(&self) -> (f64, f64) {
        (0.0, self.length)
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        let u = clamp_param(u, 0.0, self.length);
        let z = Vec3::zeros();
        // The end is returned exactly, not as start + dir·length (rounding): joints must
        // meet bit for bit.
        let p = if u >= self.length {
            self.end
        } else {
            self.start + self.dir * u
        };
        [p, self.dir, z, z]
    }
    fn curvature(&self, _u: f64) -> f64 {
        0.0
    }
    fn length(&self) -> f64 {
        self.length
    }
}
