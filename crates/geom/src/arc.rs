//! Circular arcs and helices (G2/G3) in any plane as a [`Curve`]: built from the interpreter's
//! [`ArcMove`] and the start point, with the lead along the plane normal. Sits between the
//! interpreter's moves and the path builder.

use std::f64::consts::TAU;

use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;
use crate::moves::ArcMove;
use crate::pose::Pose;

/// Below this in-plane angle (rad) an arc whose end meets its start is a full circle, as in
/// LinuxCNC: `G2 X0 Y0 I5` from the origin is one turn, not nothing.
pub const FULL_CIRCLE_ANGLE: f64 = 1e-9;

/// A helical arc: `C(u) = c + r(u)(cos θu·e1 + sin θu·e2) + h·u·n`, `u` in `[0, 1]`.
///
/// `e1, e2, n` is right-handed, so a positive sweep `θ` turns counter-clockwise seen from the
/// `+n` side. `r(u)` runs linearly from the start radius to the end radius: the interpreter
/// accepts a small mismatch between them (LinuxCNC does too), and the curve still ends exactly
/// on the programmed end point. `h` is the lead (rise along `n`) over the whole move; a plain
/// arc has `h = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// Exact end points, returned at `u = 0` and `u = 1` so joints meet bit for bit.
    start: Vec3,
    end: Vec3,
    center: Vec3,
    e1: Vec3,
    e2: Vec3,
    normal: Vec3,
    r0: f64,
    dr: f64,
    sweep: f64,
    rise: f64,
}

/// A helix is an arc with a rise; one type serves both.
pub type Helix = Arc;

fn unit(axis: usize) -> Vec3 {
    let mut v = Vec3::zeros();
    v[axis] = 1.0;
    v
}

impl Arc {
    /// The arc or helix of an interpreter move that starts at `start` (rotary axes ignored).
    pub fn from_move(start: &Pose, arc: &ArcMove) -> Result<Self, CurveError> {
        let (i, j, k) = arc.plane.axes();
        let s = Vec3::from(start.xyz());
        let e = Vec3::from(arc.end.xyz());
        let mut c = s;
        c[i] = arc.center[0];
        c[j] = arc.center[1];
        if !(s.iter().chain(e.iter()).chain(c.iter())).all(|v| v.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        if arc.turn == 0 {
            return Err(CurveError::ZeroTurn);
        }
        let normal = unit(k);
        let v0 = s - c;
        let mut v1 = e - c;
        v1[k] = 0.0;
        let r0 = v0.norm();
        if r0 == 0.0 {
            return Err(CurveError::ZeroRadius);
        }
        let e1 = v0 / r0;
        let e2 = normal.cross(&e1);
        let phi = v1.dot(&e2).atan2(v1.dot(&e1));
        let extra = f64::from(arc.turn.unsigned_abs() - 1) * TAU;
        let sweep = if arc.turn > 0 {
            let mut a = phi.rem_euclid(TAU);
            if a < FULL_CIRCLE_ANGLE {
                a = TAU;
            }
            a + extra
        } else {
            let mut a = (-phi).rem_euclid(TAU);
            if a < FULL_CIRCLE_ANGLE {
                a = TAU;
            }
            -(a + extra)
        };
        Ok(Arc {
            start: s,
            end: e,
            center: c,
            e1,
            e2,
            normal,
            r0,
            dr: v1.norm() - r0,
            sweep,
            rise: e[k] - s[k],
        })
    }

    /// A constant-radius arc about `center` starting at `start`, turning `sweep` radians
    /// (positive = counter-clockwise about `normal`) and rising `rise` along `normal`.
    /// `start - center` is projected onto the plane normal to `normal`.
    pub fn new(
        center: Vec3,
        start: Vec3,
        normal: Vec3,
        sweep: f64,
        rise: f64,
    ) -> Result<Self, CurveError> {
        let all = center.iter().chain(start.iter()).chain(normal.iter());
        if !all.chain([sweep, rise].iter()).all(|v| v.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        let n_len = normal.norm();
        if n_len == 0.0 {
            return Err(CurveError::ZeroRadius);
        }
        let normal = normal / n_len;
        let mut v0 = start - center;
        let h0 = v0.dot(&normal);
        v0 -= normal * h0;
        let r0 = v0.norm();
        if r0 == 0.0 {
            return Err(CurveError::ZeroRadius);
        }
        let e1 = v0 / r0;
        let mut arc = Arc {
            start,
            end: start,
            center: center + normal * h0,
            e1,
            e2: normal.cross(&e1),
            normal,
            r0,
            dr: 0.0,
            sweep,
            rise,
        };
        arc.end = arc.eval(1.0)[0];
        Ok(arc)
    }

    /// The formula itself, without the exact end points.
    fn eval(&self, u: f64) -> [Vec3; 4] {
        let (th, dr) = (self.sweep, self.dr);
        let r = self.r0 + dr * u;
        let (s, c) = (th * u).sin_cos();
        // rho = radial unit vector, tau = its derivative with respect to the angle.
        let rho = self.e1 * c + self.e2 * s;
        let tau = self.e2 * c - self.e1 * s;
        let p = self.center + rho * r + self.normal * (self.rise * u);
        let d1 = rho * dr + tau * (r * th) + self.normal * self.rise;
        let d2 = tau * (2.0 * dr * th) - rho * (r * th * th);
        let d3 = rho * (-3.0 * dr * th * th) - tau * (r * th * th * th);
        [p, d1, d2, d3]
    }

    /// Centre at the start's height along the normal.
    pub fn center(&self) -> Vec3 {
        self.center
    }
    /// Unit normal of the arc's plane (the helix axis).
    pub fn normal(&self) -> Vec3 {
        self.normal
    }
    /// Start radius, mm.
    pub fn radius(&self) -> f64 {
        self.r0
    }
    /// End radius, mm (equal to the start radius for a true arc).
    pub fn end_radius(&self) -> f64 {
        self.r0 + self.dr
    }
    /// Signed sweep, rad: positive counter-clockwise about the normal.
    pub fn sweep(&self) -> f64 {
        self.sweep
    }
    /// Rise along the normal over the whole move, mm.
    pub fn rise(&self) -> f64 {
        self.rise
    }
}

impl Curve for Arc {
    fn domain(&self) -> (f64, f64) {
        (0.0, 1.0)
    }

    fn derivs(&self, u: f64) -> [Vec3; 4] {
        let u = clamp_param(u, 0.0, 1.0);
        let mut d = self.eval(u);
        if u <= 0.0 {
            d[0] = self.start;
        } else if u >= 1.0 {
            d[0] = self.end;
        }
        d
    }

    fn length(&self) -> f64 {
        if self.dr == 0.0 {
            // A helix unrolls into a straight line: planar length and rise are its legs.
            (self.r0 * self.sweep).hypot(self.rise)
        } else {
            crate::arclen::ArcLengthMap::new(self, crate::curve::LENGTH_TOLERANCE)
                .map(|m| m.length())
                .unwrap_or(f64::NAN)
        }
    }
}
