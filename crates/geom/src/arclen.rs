//! Arc-length map of any [`Curve`]: `s(u)` by adaptive Gauss–Legendre quadrature per knot span
//! and `u(s)` by a panel table plus safeguarded Newton. The feed planner runs in `s`; curves
//! are evaluated in `u`; this module is the bridge between them.
//!
//! # Error bound
//!
//! Each knot span (breakpoint interval, where the integrand `|C'(u)|` is smooth) starts as 8
//! panels (2 where the curve proves its speed varies by at most 2× there,
//! [`Curve::speed_ratio`]: no narrow feature to hide) and is split adaptively. A panel `[a, b]` is accepted when the 8-point Gauss–Legendre value `G(a, b)`
//! and the sum of the two half-panel values `G(a, m) + G(m, b)` differ by at most
//! `tol · (b − a) / (u_end − u_start)`; the halves are kept. The difference bounds the error
//! of the coarse value, and the kept halves are more accurate by the rule's order (error
//! ∝ h¹⁶, so about 2¹⁶ times smaller for a smooth integrand), hence
//! `|length − true length| ≤ Σ differences ≤ tol`. The bound is an a-posteriori estimate: it
//! is rigorous in the asymptotic regime of a smooth integrand on each panel, which the span
//! split and the halving test enforce; a panel that reaches the depth limit (a cusp where
//! `C' = 0` has a kink in `|C'|`) is accepted anyway and its difference still counts in
//! [`ArcLengthMap::error_estimate`]. Like every adaptive rule it can be fooled by a feature of
//! `|C'|` narrower than the panel that both estimates miss alike ("accidental agreement"); the
//! 8 starting panels per span are there because random rational curves with a near-cusp did
//! fool a 1-panel start (3e-8 off under a 1e-9 bound); with them, thousands of random curves
//! stay within the bound (tests/properties.rs). `u(s)` solves `s(u) = s` with the same panel quadrature
//! (safeguarded Newton from a cubic Hermite guess; the last quadrature is skipped when the
//! Newton step's second-order residual is already below the tolerance), so `s(u(s)) = s` to the
//! Newton tolerance (`tol / 100`), and `u(s)` inherits the bound above as an arc-length error.
//! For samples that move forward, [`ArcLengthMap::advance`] (`arclen/cursor.rs`) is the same
//! inverse from the last answer.

use crate::curve::{clamp_param, Curve, Vec3};
use crate::error::CurveError;

mod cursor;
pub use cursor::{ArcLengthCursor, ArcPosition};

/// 8-point Gauss–Legendre nodes (positive half) and weights on [-1, 1].
const GL_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Panels each knot span starts with before adaptive halving.
const MIN_PANELS: usize = 8;

/// Panels an evenly paced span starts with: one whose speed provably varies by at most
/// [`EVEN_SPEED`] ([`Curve::speed_ratio`]) has no narrow feature of `|C'|` to fool the halving
/// test, which the eight panels are there for; the test still decides every panel.
const EVEN_PANELS: usize = 2;
/// Largest `max |C'| / min |C'|` of an evenly paced span.
const EVEN_SPEED: f64 = 2.0;

/// Deepest halving of one panel (2⁻⁴⁰ of a span) before it is accepted regardless.
const MAX_DEPTH: u32 = 40;

/// Panel-count safety net (24 MB of table): past it, panels are accepted as they come and the
/// shortfall shows in the error estimate instead of in memory.
const MAX_PANELS: usize = 1 << 20;

/// Relative rounding floor of the halving test (64 ulp of the panel's value).
const ROUNDING_FLOOR: f64 = 64.0 * f64::EPSILON;

/// `∫_a^b |C'(u)| du` by 8-point Gauss–Legendre.
pub fn gauss_legendre<C: Curve + ?Sized>(curve: &C, a: f64, b: f64) -> f64 {
    curve.speed_integral(a, b)
}

/// `∫_a^b f(u) du` by 8-point Gauss–Legendre (exact for polynomials of degree 15).
#[inline]
pub fn gauss_legendre_8(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut sum = 0.0;
    for (x, w) in GL_X.iter().zip(GL_W.iter()) {
        sum += w * (f(m - h * x) + f(m + h * x));
    }
    sum * h
}

/// `f` at the eight nodes of [`gauss_legendre_8`] on `[a, b]`, in the order
/// `m − h·x_i, m + h·x_i` for the positive nodes `x_i` (`m`, `h` the middle and half-width):
/// what a caller needs to fit the integrand as well as integrate it (the cursor's panel
/// polynomial, `arclen/cursor.rs`).
#[inline]
pub fn gauss_nodes_8(f: impl Fn(f64) -> f64, a: f64, b: f64) -> [f64; 8] {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut out = [0.0; 8];
    for (pair, x) in out.chunks_exact_mut(2).zip(GL_X.iter()) {
        pair[0] = f(m - h * x);
        pair[1] = f(m + h * x);
    }
    out
}

/// A map built once for a whole curve, handed on with a part of that curve (a trimmed piece):
/// `Curve::prebuilt_arc_length`. The part's parameters are the whole curve's, and its arc
/// length `s` is `map`'s arc length less `start`.
#[derive(Clone, Copy)]
pub struct PrebuiltArcLength<'a> {
    /// The map, over `curve`.
    pub map: &'a ArcLengthMap,
    /// The whole curve the map was built on (evaluate points on it: the same values, with
    /// fewer layers than through the part).
    pub curve: &'a dyn Curve,
    /// Arc length along `curve` at the part's start.
    pub start: f64,
}

/// Table of panels `u_k → s_k` with the speed at each boundary.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcLengthMap {
    u: Vec<f64>,
    s: Vec<f64>,
    speed: Vec<f64>,
    tolerance: f64,
    error_estimate: f64,
    newton_tolerance: f64,
}

impl ArcLengthMap {
    /// Build the map so that the total length is within `tolerance` (mm) of the true length
    /// (see the module documentation for the sense of the bound).
    pub fn new<C: Curve + ?Sized>(curve: &C, tolerance: f64) -> Result<Self, CurveError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(CurveError::Tolerance(tolerance));
        }
        let (ua, ub) = curve.domain();
        if !(ua.is_finite() && ub.is_finite()) {
            return Err(CurveError::NotFinite);
        }
        let width = ub - ua;
        let mut map = ArcLengthMap {
            u: vec![ua],
            s: vec![0.0],
            speed: vec![curve.speed(ua)],
            tolerance,
            error_estimate: 0.0,
            newton_tolerance: 0.0,
        };
        if width <= 0.0 {
            return Ok(map);
        }
        let density = tolerance / width;
        let bps = curve.breakpoints();
        // (a, b, GL8 over [a, b], depth).
        let mut stack: Vec<(f64, f64, f64, u32)> = Vec::new();
        for w in bps.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= a {
                continue;
            }
            // Start every span at MIN_PANELS panels: a narrow feature of |C'| (a near-cusp,
            // a heavy weight) can fool the halving test on a panel that spans it whole, when
            // neither rule sees the feature and both agree on the wrong value.
            let panels = if curve.speed_ratio(a, b).is_some_and(|r| r <= EVEN_SPEED) {
                EVEN_PANELS
            } else {
                MIN_PANELS
            };
            let h = (b - a) / panels as f64;
            for i in (0..panels).rev() {
                let x0 = a + h * i as f64;
                let x1 = if i + 1 == panels {
                    b
                } else {
                    a + h * (i + 1) as f64
                };
                stack.push((x0, x1, gauss_legendre(curve, x0, x1), 0));
            }
            // Depth-first, left half first, so panels come out in order of u.
            while let Some((a, b, whole, depth)) = stack.pop() {
                let m = 0.5 * (a + b);
                let (left, right) = (gauss_legendre(curve, a, m), gauss_legendre(curve, m, b));
                let diff = (whole - (left + right)).abs();
                // Never ask for less than rounding allows on this panel: a sum of 16 positive
                // terms carries up to ~16 ulp of noise, and a floor below the noise would make
                // the test fail at random and the panel count grow exponentially.
                let allowed = (density * (b - a)).max(ROUNDING_FLOOR * whole.abs());
                let give_up = depth >= MAX_DEPTH || map.u.len() >= MAX_PANELS;
                if diff <= allowed || give_up || !diff.is_finite() {
                    map.error_estimate += diff;
                    map.push(curve, m, left);
                    map.push(curve, b, right);
                } else {
                    stack.push((m, b, right, depth + 1));
                    stack.push((a, m, left, depth + 1));
                }
            }
        }
        let len = map.length();
        map.newton_tolerance = (tolerance * 0.01).max(4.0 * f64::EPSILON * len);
        Ok(map)
    }

    fn push<C: Curve + ?Sized>(&mut self, curve: &C, u: f64, ds: f64) {
        let s = self.s.last().copied().unwrap_or(0.0) + ds;
        self.u.push(u);
        self.s.push(s);
        self.speed.push(curve.speed(u));
    }

    /// Total arc length, mm.
    pub fn length(&self) -> f64 {
        self.s.last().copied().unwrap_or(0.0)
    }
    /// The tolerance the map was built for.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }
    /// Sum of the accepted panels' coarse-versus-fine differences: the error bound actually
    /// achieved (≤ the tolerance unless a panel hit the depth limit).
    pub fn error_estimate(&self) -> f64 {
        self.error_estimate
    }
    /// Number of quadrature panels in the table.
    pub fn panels(&self) -> usize {
        self.u.len().saturating_sub(1)
    }

    /// Arc length from the start to parameter `u`.
    pub fn s_at<C: Curve + ?Sized>(&self, curve: &C, u: f64) -> f64 {
        let n = self.panels();
        if n == 0 {
            return 0.0;
        }
        let u = clamp_param(u, self.u[0], self.u[n]);
        let k = self.u.partition_point(|&x| x <= u).clamp(1, n) - 1;
        self.s[k] + gauss_legendre(curve, self.u[k], u)
    }

    /// The point at arc length `s`.
    pub fn point_at<C: Curve + ?Sized>(&self, curve: &C, s: f64) -> Vec3 {
        curve.point(self.u_at(curve, s))
    }

    /// `[C, dC/ds, d²C/ds², d³C/ds³]` at arc length `s`: position, unit tangent, curvature
    /// vector and its rate — what the feed planner multiplies by ṡ, s̈, s⃛ to get velocity,
    /// acceleration and jerk. Chain rule with `u(s)`: `u_s = 1/v`, `u_ss = −(C'·C'')/v⁴`,
    /// `u_sss = −(|C''|² + C'·C⁽³⁾)/v⁵ + 4(C'·C'')²/v⁷`, `v = |C'|`. Zero speed (a cusp) gives
    /// zero derivatives rather than NaN.
    pub fn derivs_at<C: Curve + ?Sized>(&self, curve: &C, s: f64) -> [Vec3; 4] {
        let [p, d1, d2, d3] = curve.derivs(self.u_at(curve, s));
        let v = d1.norm();
        if v == 0.0 || !v.is_finite() {
            return [p, Vec3::zeros(), Vec3::zeros(), Vec3::zeros()];
        }
        let dot12 = d1.dot(&d2);
        let g1 = 1.0 / v;
        let g2 = -dot12 / v.powi(4);
        let g3 = -(d2.norm_squared() + d1.dot(&d3)) / v.powi(5) + 4.0 * dot12 * dot12 / v.powi(7);
        [
            p,
            d1 * g1,
            d2 * (g1 * g1) + d1 * g2,
            d3 * (g1 * g1 * g1) + d2 * (3.0 * g1 * g2) + d1 * g3,
        ]
    }

    /// Parameter `u` at arc length `s` (clamped to `[0, length]`).
    pub fn u_at<C: Curve + ?Sized>(&self, curve: &C, s: f64) -> f64 {
        let n = self.panels();
        if n == 0 {
            return self.u[0];
        }
        let s = clamp_param(s, 0.0, self.length());
        let k = self.s.partition_point(|&x| x <= s).clamp(1, n) - 1;
        let (ua, ub, sa, sb) = (self.u[k], self.u[k + 1], self.s[k], self.s[k + 1]);
        let ds = sb - sa;
        if ds <= 0.0 {
            return ua;
        }
        // Cubic Hermite guess for u(s) from du/ds = 1/|C'| at the panel ends.
        let t = (s - sa) / ds;
        let du = ub - ua;
        let (va, vb) = (self.speed[k], self.speed[k + 1]);
        let mut u = if va > 0.0 && vb > 0.0 {
            let (ma, mb) = (ds / va / du, ds / vb / du);
            let (t2, t3) = (t * t, t * t * t);
            let h = (t3 - 2.0 * t2 + t) * ma + (-2.0 * t3 + 3.0 * t2) + (t3 - t2) * mb;
            ua + du * h.clamp(0.0, 1.0)
        } else {
            ua + du * t
        };
        let (mut lo, mut hi) = (ua, ub);
        for _ in 0..60 {
            let f = sa + gauss_legendre(curve, ua, u) - s;
            if f.abs() <= self.newton_tolerance {
                break;
            }
            if f > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            if hi - lo <= f64::EPSILON * (ua.abs() + ub.abs()) {
                break;
            }
            let [_, d1, d2, _] = curve.derivs(u);
            let v = d1.norm();
            let step = f / v;
            let next = u - step;
            // Newton inside the bracket, bisection when it would leave it (or v = 0).
            if next > lo && next < hi {
                // After the step the residual is F''·δ²/2 to third order (F' = |C'|,
                // F'' = C'·C''/|C'|); when that is far inside the tolerance, the quadrature
                // that would confirm it can be skipped.
                let fpp = d1.dot(&d2) / v;
                if (fpp * step * step).abs() <= 0.5 * self.newton_tolerance {
                    return next;
                }
                u = next;
            } else {
                u = 0.5 * (lo + hi);
            }
        }
        u
    }
}
