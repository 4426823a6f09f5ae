//! The tool axis along the path (5-axis under tool-centre-point control): a unit vector in the
//! workpiece frame, carried along a segment by Rodrigues rotation about the common normal of
//! its end axes (Kahraman et al., eqs 1–3) and through a corner blend by the two-curve method
//! (their §3).
//! The path builder attaches an [`AxisPath`] to each segment; the planner and the interpolator
//! turn tip + axis into joints through the machine's inverse kinematics.

use std::fmt::Debug;

use tezgah_geom::{Curve, Quintic, State, ToolControl, Vec3};

/// Largest turn (rad) between the end axes of one move: at a reversal (π) the common normal,
/// and so the rotation, is undefined (Kahraman et al., eq. 1: opposite axes are refused).
pub const MAX_TURN: f64 = std::f64::consts::PI - 1e-6;

/// A programmed point: tip (mm, workpiece frame) and A B C (degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramPoint {
    pub tip: Vec3,
    pub rotary: [f64; 3],
}

/// Gives the tool axis for the programmed rotary angles: the machine's model seen by the path
/// stage, which knows no kinematics itself.
pub trait ToolAxisMap: Debug + Send + Sync {
    /// The unit tool axis (workpiece frame, from the tip toward the spindle) for A B C
    /// (degrees) at `tip` under `control`; `None` where the program angles do not orient the
    /// tool (TCP off, a machine whose rotaries do not tilt the tool) or the pose is out of
    /// reach (the planner then reports it with its line).
    fn axis(&self, control: ToolControl, tip: &Vec3, rotary: &[f64; 3]) -> Option<Vec3>;

    /// Whether the joints that follow `path` continuously (nearest solution at each step)
    /// from the programmed angles at `from` end on the programmed angles at `to` — the same
    /// tilt branch and the same turns — without a jump on the way. Not so where the program
    /// asks for what the axis alone cannot say: C turning with the tool along the C axis (the
    /// pole), leaving the pole toward another C, whole turns, the long way round, a change of
    /// tilt branch; the move then keeps its angles linear.
    fn follows(
        &self,
        control: ToolControl,
        from: &ProgramPoint,
        to: &ProgramPoint,
        path: &GreatCircle,
    ) -> bool;
}

/// Rodrigues' rotation of `v` about the unit axis `k` by `theta` (Kahraman et al., eq. 2):
/// `v cos θ + (k × v) sin θ + k (k·v)(1 − cos θ)`. `k` must be a unit vector: the paper's
/// Eq 1 takes the raw cross product, whose end value is neither the target nor of unit length.
pub fn rotate(v: &Vec3, k: &Vec3, theta: f64) -> Vec3 {
    let (s, c) = theta.sin_cos();
    v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c))
}

/// The axis path along one segment: the great circle from `from` to `to`, at the fraction
/// `f` of the segment's arc length (Eq 3, `θ = θmax·s/S`, so the axis turns in step with the
/// tip). Both ends are returned bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GreatCircle {
    from: Vec3,
    to: Vec3,
    /// Unit common normal `V × U / |V × U|` (zero when the axis stands still).
    k: Vec3,
    /// `θmax = atan2(|V × U|, V·U)`, rad.
    angle: f64,
}

/// Why an axis path cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum AxisError {
    #[error("tool axis is not a finite non-zero vector")]
    NotFinite,
    #[error("the tool axis turns {0:.6}° in one move: at a reversal the rotation is undefined")]
    Reversal(f64),
}

impl GreatCircle {
    /// The rotation from `from` to `to`. Vectors of unit length to rounding are kept as they
    /// are, so the ends are the given axes bit for bit; others are normalised.
    pub fn new(from: Vec3, to: Vec3) -> Result<Self, AxisError> {
        let (nf, nt) = (from.norm(), to.norm());
        if !(nf.is_finite() && nt.is_finite() && nf > 0.0 && nt > 0.0) {
            return Err(AxisError::NotFinite);
        }
        let unit = |v: Vec3, n: f64| if (n - 1.0).abs() <= 1e-12 { v } else { v / n };
        let (from, to) = (unit(from, nf), unit(to, nt));
        let cross = from.cross(&to);
        let sin = cross.norm();
        // atan2, not acos: acos(V·U) loses small turns to rounding.
        let angle = sin.atan2(from.dot(&to));
        if angle > MAX_TURN {
            return Err(AxisError::Reversal(angle.to_degrees()));
        }
        let k = if sin > 0.0 {
            cross / sin
        } else {
            Vec3::zeros()
        };
        Ok(GreatCircle {
            from,
            to,
            k,
            angle: if sin > 0.0 { angle } else { 0.0 },
        })
    }

    /// A constant axis.
    pub fn still(axis: Vec3) -> Result<Self, AxisError> {
        Self::new(axis, axis)
    }

    /// The axis at fraction `f` of the segment (clamped; the ends exactly).
    pub fn at(&self, f: f64) -> Vec3 {
        if f.is_nan() || f <= 0.0 {
            self.from
        } else if f >= 1.0 {
            self.to
        } else {
            rotate(&self.from, &self.k, self.angle * f)
        }
    }

    /// First and second derivative of the axis by `f` at `f`: `θmax (k × O)` and
    /// `θmax² k × (k × O)` (the derivatives of Kahraman et al.'s eq. 2 with θ̇ = θmax, θ̈ = 0).
    pub fn derivatives(&self, f: f64) -> [Vec3; 2] {
        let o = self.at(f);
        let n = self.k.cross(&o);
        [n * self.angle, self.k.cross(&n) * (self.angle * self.angle)]
    }

    /// The part from fraction `f0` to `f1`: the same great circle, so a trimmed segment keeps
    /// its axis path (its ends are [`Self::at`] of `f0` and `f1`, bit for bit).
    pub fn part(&self, f0: f64, f1: f64) -> GreatCircle {
        GreatCircle {
            from: self.at(f0),
            to: self.at(f1),
            k: self.k,
            angle: self.angle * (f1 - f0).max(0.0),
        }
    }

    /// The turn, rad.
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// The unit common normal (zero for a still axis).
    pub fn normal(&self) -> Vec3 {
        self.k
    }
}

/// One end of an axis blend: the axis and its first and second derivatives by the blend's
/// parameter `u` (the tip blend's parameter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisEnd {
    pub axis: Vec3,
    pub d1: Vec3,
    pub d2: Vec3,
}

/// The tool axis across a corner blend, by the two-curve method (Kahraman et al., §3): the
/// lower curve `P(u)` is the tip blend, the upper `Q(u)` a point at distance `h` along the
/// tool axis, both quintic Hermites in the same `u ∈ [0, 1]` whose end data are the
/// neighbours' (Step 5: `Q = P + hO`, `Q′ = P′ + hO′`, `Q″ = P″ + hO″`), and the axis is
/// `O = (Q − P)/|Q − P|` (Eq 7). Hermite interpolation is linear in its data, so
/// `Q − P = h·H(u)` with `H` the quintic Hermite of the axis data alone: `O = H/|H|`, the
/// same for every `h`. `H` is stored, which spares the cancellation of `Q − P` far from the
/// origin; [`Self::upper`] gives `Q` for any `h`. At the ends `O`, `O′`, `O″` are the
/// neighbours' (`|H| = 1`, `H′ ⊥ H` there), so the axis is C² across both joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisBlend {
    h: Quintic,
    start: Vec3,
    end: Vec3,
}

/// Smallest `|H|` accepted inside a blend: the axis data at the two ends are within a small
/// angle, so `|H|` stays near 1; far below means the data disagree and `H/|H|` would swing.
const MIN_NORM: f64 = 0.5;

impl AxisBlend {
    /// The blend between two ends; `None` when the data are not finite or `|H|` falls below
    /// [`MIN_NORM`] somewhere (checked at 64 points).
    pub fn new(start: AxisEnd, end: AxisEnd) -> Option<AxisBlend> {
        let state = |e: &AxisEnd| State {
            p: e.axis,
            v: e.d1,
            a: e.d2,
        };
        let h = Quintic::hermite(state(&start), state(&end), 1.0).ok()?;
        let ok = (0..=64).all(|i| {
            let n = h.point(i as f64 / 64.0).norm();
            n.is_finite() && n >= MIN_NORM
        });
        ok.then_some(AxisBlend {
            h,
            start: start.axis,
            end: end.axis,
        })
    }

    /// The unit axis at blend parameter `u` (the ends exactly).
    pub fn at(&self, u: f64) -> Vec3 {
        if u.is_nan() || u <= 0.0 {
            self.start
        } else if u >= 1.0 {
            self.end
        } else {
            // Horner on the coefficients: the deviation measure calls this in its inner loop.
            let c = self.h.coefficients();
            let h = ((((c[5] * u + c[4]) * u + c[3]) * u + c[2]) * u + c[1]) * u + c[0];
            h.normalize()
        }
    }

    /// The axis and its first and second derivatives by `u`: with `n = |H|`, `O = H/n`,
    /// `n′ = O·H′`, `O′ = (H′ − O n′)/n`, `n″ = O′·H′ + O·H″`, `O″ = (H″ − 2O′n′ − O n″)/n`.
    pub fn derivatives(&self, u: f64) -> [Vec3; 3] {
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        let [h, h1, h2, _] = self.h.derivs(u);
        let n = h.norm();
        let o = h / n;
        let n1 = o.dot(&h1);
        let o1 = (h1 - o * n1) / n;
        let n2 = o1.dot(&h1) + o.dot(&h2);
        let o2 = (h2 - o1 * (2.0 * n1) - o * n2) / n;
        [self.at(u), o1, o2]
    }

    /// The upper curve `Q(u) = P(u) + h·H(u)` of the two-curve method for the tip `p` at `u`.
    pub fn upper(&self, p: &Vec3, h: f64, u: f64) -> Vec3 {
        p + self.h.point(u.clamp(0.0, 1.0)) * h
    }
}

/// How the tool axis moves along a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisPath {
    /// Along a programmed (possibly trimmed) move: the great circle, in step with the tip's
    /// arc length.
    Rotate(GreatCircle),
    /// Across a corner blend: in step with the tip blend's parameter.
    Blend(AxisBlend),
}

impl AxisPath {
    /// The axis at curve parameter `u` (blends) or arc-length fraction `f` (moves).
    pub fn at(&self, u: f64, f: f64) -> Vec3 {
        match self {
            AxisPath::Rotate(g) => g.at(f),
            AxisPath::Blend(b) => b.at(u),
        }
    }

    /// The axis and its first and second derivatives by arc length on the segment whose tip
    /// curve is `curve` (length `length`), at curve parameter `u` and length fraction `f`:
    /// `O_s = O_u/s_u`, `O_ss = (O_uu − O_s s_uu)/s_u²` with `s_u = |C′|`,
    /// `s_uu = C′·C″/|C′|` for a blend; `O_f/L`, `O_ff/L²` along a move.
    pub fn arc_derivatives(&self, curve: &dyn Curve, length: f64, u: f64, f: f64) -> [Vec3; 3] {
        match self {
            AxisPath::Rotate(g) => {
                let [d1, d2] = g.derivatives(f);
                [g.at(f), d1 / length, d2 / (length * length)]
            }
            AxisPath::Blend(b) => {
                let [o, ou, ouu] = b.derivatives(u);
                let [_, c1, c2, _] = curve.derivs(u);
                let su = c1.norm();
                let suu = c1.dot(&c2) / su;
                let os = ou / su;
                [o, os, (ouu - os * suu) / (su * su)]
            }
        }
    }

    /// The axis at the start and the end.
    pub fn ends(&self) -> [Vec3; 2] {
        match self {
            AxisPath::Rotate(g) => [g.from, g.to],
            AxisPath::Blend(b) => [b.start, b.end],
        }
    }
}

/// Angle between two unit vectors, rad, accurate near 0 (atan2 of cross and dot).
pub fn angle_between(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rodrigues_30_degrees() {
        // Eqs 1–3 by hand: V = (0,0,1), U = (0.5, 0, √3/2): k = (0,1,0), θmax = 30°.
        let v = Vec3::z();
        let u = Vec3::new(0.5, 0.0, 0.75f64.sqrt());
        let g = GreatCircle::new(v, u).unwrap();
        assert!((g.normal() - Vec3::y()).norm() < 1e-15);
        assert!((g.angle().to_degrees() - 30.0).abs() < 1e-12);
        let mid = g.at(0.5);
        assert!(
            (mid - Vec3::new(0.258819, 0.0, 0.965926)).norm() < 1e-6,
            "{mid}"
        );
        assert_eq!(g.at(1.0), u);
        // Just before the end the formula itself lands on U (not only the exact end value).
        assert!((g.at(1.0 - 1e-15) - u).norm() < 1e-14);
        // The paper's Eq 1 without normalising k: (0.25, 0, 0.866025), neither U nor unit.
        let raw = v.cross(&u);
        let wrong = rotate(&v, &raw, 30f64.to_radians());
        assert!(
            (wrong - Vec3::new(0.25, 0.0, 0.866025)).norm() < 1e-6,
            "{wrong}"
        );
        assert!((wrong.norm() - 1.0).abs() > 0.05);
    }

    #[test]
    fn reversal_refused_and_still_axis() {
        assert!(matches!(
            GreatCircle::new(Vec3::z(), -Vec3::z()),
            Err(AxisError::Reversal(_))
        ));
        assert_eq!(
            GreatCircle::new(Vec3::zeros(), Vec3::z()),
            Err(AxisError::NotFinite)
        );
        let g = GreatCircle::still(Vec3::new(0.0, 0.6, 0.8)).unwrap();
        assert_eq!(g.angle(), 0.0);
        assert_eq!(g.at(0.3), Vec3::new(0.0, 0.6, 0.8));
    }

    #[test]
    fn part_is_the_same_circle() {
        let g = GreatCircle::new(Vec3::z(), Vec3::new(0.6, 0.0, 0.8)).unwrap();
        let p = g.part(0.2, 0.7);
        assert_eq!(p.at(0.0), g.at(0.2));
        assert_eq!(p.at(1.0), g.at(0.7));
        for i in 0..=10 {
            let f = i as f64 / 10.0;
            assert!((p.at(f) - g.at(0.2 + 0.5 * f)).norm() < 1e-15);
        }
    }

    #[test]
    fn derivatives_match_differences() {
        let g = GreatCircle::new(Vec3::new(0.1, 0.2, 0.97), Vec3::new(0.5, -0.3, 0.8)).unwrap();
        let h = 1e-4;
        for f in [0.1, 0.5, 0.9] {
            let [d1, d2] = g.derivatives(f);
            let fd1 = (g.at(f + h) - g.at(f - h)) / (2.0 * h);
            let fd2 = (g.at(f + h) - g.at(f) * 2.0 + g.at(f - h)) / (h * h);
            assert!((d1 - fd1).norm() < 1e-8, "{d1} {fd1}");
            assert!((d2 - fd2).norm() < 1e-5, "{d2} {fd2}");
        }
    }
}
