//! Scalar root finding for the profile solver: the one real root of a depressed cubic in closed
//! form, and Brent's bracketing method for the equations that have no convenient closed form.
//!
//! Brent (Brent 1973, ch. 4; the `zbrent` form of Numerical Recipes §9.3) keeps a sign-changing
//! bracket, so it cannot diverge, and converges superlinearly on the smooth pieces we give it.

/// The real root u ≥ 0 of u³ + p·u − q = 0 for p ≥ 0, q ≥ 0 (the cubic is then increasing, so
/// the root is unique).
///
/// Cardano's sum of cube roots cancels badly when p³ ≫ q²; the hyperbolic form
/// u = 2√(p/3)·sinh(⅓·asinh(3q/(2p)·√(3/p))) does not.
pub(crate) fn depressed_cubic(p: f64, q: f64) -> f64 {
    if q <= 0.0 {
        return 0.0;
    }
    if p <= 0.0 {
        return q.cbrt();
    }
    let k = (p / 3.0).sqrt();
    let arg = 1.5 * q / (p * k);
    if !arg.is_finite() {
        // p is so small next to q that p·k underflowed: the cubic is u³ = q.
        return q.cbrt();
    }
    2.0 * k * (arg.asinh() / 3.0).sinh()
}

/// A root of `f` in [a, b], given f(a)·f(b) ≤ 0 (the values are passed in so callers can reuse
/// them). Stops when the bracket is a few ulps wide or after 200 evaluations.
pub(crate) fn brent(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64, fa: f64, fb: f64) -> f64 {
    let (mut fa, mut fb) = (fa, fb);
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    let (mut c, mut fc) = (b, fb);
    let (mut d, mut e) = (b - a, b - a);
    for _ in 0..200 {
        if (fb > 0.0) == (fc > 0.0) {
            // Keep [b, c] a bracket.
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            // b is the best estimate so far.
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return b;
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            // Inverse quadratic interpolation (secant when only two points are distinct).
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            }
            p = p.abs();
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_root() {
        for (p, q) in [
            (0.0, 8.0),
            (3.0, 4.0),
            (1e6, 1e-6),
            (1e-300, 5.0),
            (2.0, 0.0),
        ] {
            let u = depressed_cubic(p, q);
            let r = u * u * u + p * u - q;
            assert!(
                r.abs() <= 1e-14 * (q + p * u).max(1e-300),
                "{p} {q} {u} {r}"
            );
        }
    }

    #[test]
    fn brent_finds_roots() {
        let f = |x: f64| x * x * x - 2.0;
        let r = brent(f, 0.0, 2.0, f(0.0), f(2.0));
        assert!((r - 2f64.cbrt()).abs() < 1e-15);
        let g = |x: f64| x.sqrt() - 1e-10;
        let r = brent(g, 0.0, 1.0, g(0.0), g(1.0));
        assert!((r - 1e-20).abs() < 1e-30, "{r}");
    }
}
