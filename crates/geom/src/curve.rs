//! The `Curve` trait: what every path piece (line, arc/helix, NURBS, Bézier, quintic blend)
//! offers to the planner — parameter domain, point, derivatives up to the third, curvature,
//! length and arc-length evaluation — so path building and feed planning never match on kinds.

use crate::arclen::{gauss_legendre_8, gauss_nodes_8, ArcLengthMap, PrebuiltArcLength};

/// A point or vector in the workpiece frame, mm.
pub type Vec3 = nalgebra::Vector3<f64>;

/// Absolute length tolerance (mm) used by [`Curve::length`] when a curve has no closed form.
pub const LENGTH_TOLERANCE: f64 = 1e-10;

/// A parametric curve `C(u)`, `u` in `domain()`. Parameters outside the domain are clamped.
///
/// Derivatives are with respect to the curve's own parameter `u`; the arc-length map converts
/// to and from the arc length `s`.
pub trait Curve {
    /// `(u_start, u_end)`, `u_start <= u_end` (equal only for a zero-length line).
    fn domain(&self) -> (f64, f64);

    /// `[C, C', C'', C''']` at `u`.
    fn derivs(&self, u: f64) -> [Vec3; 4];

    /// `C(u)`.
    fn point(&self, u: f64) -> Vec3 {
        self.derivs(u)[0]
    }

    /// `C'(u)`.
    fn d1(&self, u: f64) -> Vec3 {
        self.derivs(u)[1]
    }

    /// Parametric speed `|C'(u)|`, the arc-length integrand.
    fn speed(&self, u: f64) -> f64 {
        self.d1(u).norm()
    }

    /// `∫_a^b |C'(u)| du` by 8-point Gauss–Legendre ([`crate::arclen::gauss_legendre_8`]), the
    /// arc-length quadrature's one rule. Curves that can evaluate the eight nodes of one knot
    /// span together (one span lookup) override it with the same values.
    fn speed_integral(&self, a: f64, b: f64) -> f64 {
        gauss_legendre_8(|u| self.speed(u), a, b)
    }

    /// `|C'|` at the eight nodes of [`Self::speed_integral`]'s rule on `[a, b]`
    /// ([`crate::arclen::gauss_nodes_8`]'s order). Curves with a span cache override it as
    /// they override `speed_integral`, with the same values.
    fn gauss_speeds(&self, a: f64, b: f64) -> [f64; 8] {
        gauss_nodes_8(|u| self.speed(u), a, b)
    }

    /// Curvature `|C' × C''| / |C'|³` (1/mm): infinite at a cusp, never NaN.
    fn curvature(&self, u: f64) -> f64 {
        let [_, d1, d2, _] = self.derivs(u);
        curvature_of(&d1, &d2)
    }

    /// Parameters where derivatives may jump (knots); the arc-length quadrature never
    /// integrates across one. Always contains both domain ends, sorted, without repeats.
    fn breakpoints(&self) -> Vec<f64> {
        let (a, b) = self.domain();
        vec![a, b]
    }

    /// An upper bound of `max |C'| / min |C'|` over `[a, b]` (within one breakpoint span)
    /// where the curve can prove one cheaply; `None` when it cannot (a near-cusp may be
    /// there). The arc-length map starts an evenly paced span with fewer panels.
    fn speed_ratio(&self, a: f64, b: f64) -> Option<f64> {
        let _ = (a, b);
        None
    }

    /// Arc length over the whole domain, mm (closed form where one exists, else adaptive
    /// Gauss–Legendre to [`LENGTH_TOLERANCE`]).
    fn length(&self) -> f64 {
        ArcLengthMap::new(self, LENGTH_TOLERANCE)
            .map(|m| m.length())
            .unwrap_or(f64::NAN)
    }

    /// An arc-length map its producer already built, over the curve this one is a part of:
    /// a consumer that needs `s → u` (the interpolator) reuses it instead of building its own.
    /// `None` (the default) when there is none.
    fn prebuilt_arc_length(&self) -> Option<PrebuiltArcLength<'_>> {
        None
    }
}

/// Curvature from the first two derivatives; a zero first derivative is a cusp (infinite
/// curvature) unless the curve is standing still there (both zero: curvature 0).
pub fn curvature_of(d1: &Vec3, d2: &Vec3) -> f64 {
    let speed = d1.norm();
    let cross = d1.cross(d2).norm();
    if speed == 0.0 {
        return if d2.norm() == 0.0 { 0.0 } else { f64::INFINITY };
    }
    let k = cross / (speed * speed * speed);
    if k.is_nan() {
        f64::INFINITY
    } else {
        k
    }
}

/// Clamp `u` into `[a, b]`; NaN maps to `a` so evaluation never sees a NaN parameter.
pub(crate) fn clamp_param(u: f64, a: f64, b: f64) -> f64 {
    if u.is_nan() {
        a
    } else {
        u.clamp(a, b)
    }
}

/// References and boxes of curves are curves: every method forwards (so the overrides of the
/// curve behind them are kept).
macro_rules! forward_curve {
    ($($t:ty),*) => {$(
        impl<C: Curve + ?Sized> Curve for $t {
            fn domain(&self) -> (f64, f64) {
                (**self).domain()
            }
            fn derivs(&self, u: f64) -> [Vec3; 4] {
                (**self).derivs(u)
            }
            fn point(&self, u: f64) -> Vec3 {
                (**self).point(u)
            }
            fn d1(&self, u: f64) -> Vec3 {
                (**self).d1(u)
            }
            fn speed(&self, u: f64) -> f64 {
                (**self).speed(u)
            }
            fn speed_integral(&self, a: f64, b: f64) -> f64 {
                (**self).speed_integral(a, b)
            }
            fn gauss_speeds(&self, a: f64, b: f64) -> [f64; 8] {
                (**self).gauss_speeds(a, b)
            }
            fn curvature(&self, u: f64) -> f64 {
                (**self).curvature(u)
            }
            fn breakpoints(&self) -> Vec<f64> {
                (**self).breakpoints()
            }
            fn speed_ratio(&self, a: f64, b: f64) -> Option<f64> {
                (**self).speed_ratio(a, b)
            }
            fn length(&self) -> f64 {
                (**self).length()
            }
            fn prebuilt_arc_length(&self) -> Option<PrebuiltArcLength<'_>> {
                (**self).prebuilt_arc_length()
            }
        }
    )*};
}

forward_curve!(&C, Box<C>);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::line::Line;

    #[test]
    fn curves_are_object_safe_and_boxable() {
        let l = Line::new(Vec3::zeros(), Vec3::new(3.0, 4.0, 0.0)).unwrap();
        let path: Vec<Box<dyn Curve>> = vec![Box::new(l)];
        assert_eq!(path[0].length(), 5.0);
        assert_eq!(path[0].point(5.0), Vec3::new(3.0, 4.0, 0.0));
        assert_eq!(curvature_of(&Vec3::zeros(), &Vec3::x()), f64::INFINITY);
        assert_eq!(curvature_of(&Vec3::zeros(), &Vec3::zeros()), 0.0);
    }
}
