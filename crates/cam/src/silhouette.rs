//! The cutter's true silhouette across the feed, to check the side steps the osculating-circle
//! model (`scallop`, `effective_radius`) proposes: far from the contact a bull-nose's torus or a
//! flat end's rim rises faster than its circle of curvature at the contact (a D8 r2 torus at 10°
//! lead: 0.151 mm at 1.87 mm beside the contact against the circle's 0.130), so the cusp between
//! two passes is higher than the model says. The strategies shrink a side step until the cusp
//! on the true silhouette fits (`Context::side_step`).
//!
//! The cutting end is convex: the points within `r` of a core cylinder of radius `R − r` from
//! height `r` to the flute length (as the verifying simulation models it). The lowest point of a
//! convex body `K` along `n` on the slice `P·t = y` follows from its support function
//! `h_K(d) = max_{P∈K} P·d` by Lagrange duality: `min {P·n : P·t = y} = max_μ (−h_K(−n − μt) −
//! μy)`, a concave maximisation in one variable. For this body
//! `h_K(d) = (R − r)|d − (d·a)a| + max(r d·a, L d·a) + r|d|` (Minkowski sum of the core with a
//! ball of radius `r`; tip at the origin, axis `a`).

use tezgah_geom::Vec3;

use crate::cutter::CutterShape;

/// Golden-section iterations on the multiplier (its bracket shrinks by 0.618⁸⁰).
const ITERATIONS: usize = 80;

/// The support function of the cutting end (tip at the origin, unit axis `a`, flutes up to
/// `flute_length`) in direction `d`.
fn support(shape: &CutterShape, flute_length: f64, a: &Vec3, d: &Vec3) -> f64 {
    let (big_r, r) = (shape.radius(), shape.corner_radius());
    let along = d.dot(a);
    let across = (d - a * along).norm();
    (big_r - r) * across + (r * along).max(flute_length.max(r) * along) + r * d.norm()
}

/// The lowest point along `n` of the cutter's slice `P·t = y` (`n`, `t` orthonormal).
fn lowest(shape: &CutterShape, flute_length: f64, a: &Vec3, n: &Vec3, t: &Vec3, y: f64) -> f64 {
    let f = |mu: f64| -support(shape, flute_length, a, &-(n + t * mu)) - mu * y;
    // The optimal multiplier is the silhouette's slope, bounded well inside ±1e3 for any slice
    // short of the cutter's side.
    let (mut lo, mut hi) = (-1e3, 1e3);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..ITERATIONS {
        if f1 >= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    f1.max(f2)
}

/// How far the cutter's silhouette across the feed has risen along `n` at `y` beside the
/// contact (the lowest point): `n` the surface normal, `t` the cross-feed direction, `a` the
/// tool axis, all unit.
pub fn rise(shape: &CutterShape, flute_length: f64, a: &Vec3, n: &Vec3, t: &Vec3, y: f64) -> f64 {
    let bottom = -support(shape, flute_length, a, &-n);
    lowest(shape, flute_length, a, n, t, y) - bottom
}

/// Where the contact (the cutter's lowest point along `n`) lies across the feed, `P·t`: the
/// support point of the body in direction `−n` — on the core, the corner circle's point
/// farthest along `−n`'s part across the axis, at height `r`; plus `r` along `−n`. A cutter
/// leaned across the feed touches off its axis (a flat end at its rim, `R·cos λ` aside).
fn contact_across(shape: &CutterShape, a: &Vec3, n: &Vec3, t: &Vec3) -> f64 {
    let (big_r, r) = (shape.radius(), shape.corner_radius());
    let d = -n;
    let across = d - a * d.dot(a);
    let len = across.norm();
    if len < 1e-12 {
        return 0.0;
    }
    (a * r + across * ((big_r - r) / len) + d * r).dot(t)
}

/// Bisections for where two neighbouring silhouettes cross (the bracket shrinks by 2⁻⁴⁰).
const CROSSING_BISECTIONS: usize = 40;

/// The lower envelope of a cutter standing anywhere, seen along the feed: the lowest `P·n` over
/// the cutting end on the slice `P·t = y`, for the cutter with its tip at `tip` and unit axis
/// `a` (`n`, `t` orthonormal, coordinates in any common origin). This is the cross-section of
/// the swept pass (the feed is normal to `n` and `t`), so two passes' envelopes meet at their
/// cusp. A ball's is its sphere's circle (closed form; the flutes above it only matter at
/// its side), `f64::INFINITY` beside it; the dual search returns a large value there for the
/// others.
#[allow(clippy::too_many_arguments)]
pub fn envelope(
    shape: &CutterShape,
    flute_length: f64,
    tip: &Vec3,
    a: &Vec3,
    n: &Vec3,
    t: &Vec3,
    y: f64,
) -> f64 {
    if let CutterShape::Ball { radius } = *shape {
        let centre = tip + a * radius;
        let dy = y - centre.dot(t);
        let d2 = radius * radius - dy * dy;
        return if d2 >= 0.0 {
            centre.dot(n) - d2.sqrt()
        } else {
            f64::INFINITY
        };
    }
    tip.dot(n) + lowest(shape, flute_length, a, n, t, y - tip.dot(t))
}

/// The cusp between two passes `w` apart on a cross-feed section of normal curvature `kappa`
/// (positive concave, as `scallop`). What the two passes leave at `x` from the first contact is
/// the lower of their silhouettes there, `min(rise(x), rise(x − w))`; its highest point is where
/// they cross (`rise` grows away from the contact on either side). A silhouette symmetric about
/// its contact crosses at `w/2`; a leaned flat end's is not (its rim is a corner, the wall
/// beyond it vertical), so the crossing is found by bisection. There the surface has risen
/// `ρ − √(ρ² − (w/2)²)` toward the tool (concave) or fallen as much (convex), taken at the
/// midpoint of the two contacts.
pub fn cusp(
    shape: &CutterShape,
    flute_length: f64,
    a: &Vec3,
    n: &Vec3,
    t: &Vec3,
    kappa: f64,
    w: f64,
) -> f64 {
    let y0 = contact_across(shape, a, n, t);
    let rise_at = |x: f64| rise(shape, flute_length, a, n, t, y0 + x);
    let (mut lo, mut hi) = (0.0, w);
    for _ in 0..CROSSING_BISECTIONS {
        let x = 0.5 * (lo + hi);
        if rise_at(x) < rise_at(x - w) {
            lo = x;
        } else {
            hi = x;
        }
    }
    let x = 0.5 * (lo + hi);
    let tool = rise_at(x).max(rise_at(x - w));
    let y = 0.5 * w;
    let surface = if kappa.abs() < 1e-12 {
        0.0
    } else {
        let rho = 1.0 / kappa.abs();
        let fall = rho - (rho * rho - y * y).max(0.0).sqrt();
        fall * kappa.signum()
    };
    tool - surface
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ball_and_tilted_flat_match_their_closed_forms() {
        let (n, t, f) = (Vec3::z(), Vec3::y(), Vec3::x());
        // A ball's silhouette is its circle: R − √(R² − y²).
        let ball = CutterShape::Ball { radius: 3.0 };
        for y in [0.0_f64, 0.5, 1.5, 2.5] {
            let want = 3.0 - (9.0 - y * y).sqrt();
            let got = rise(&ball, 18.0, &n, &n, &t, y);
            assert!((got - want).abs() < 1e-9, "{y}: {got} {want}");
        }
        // A flat end leaned λ toward the feed: its rim, (R − √(R² − y²))·sin λ.
        let lam = 10f64.to_radians();
        let a = (n * lam.cos() + f * lam.sin()).normalize();
        let flat = CutterShape::Flat { radius: 4.0 };
        for y in [0.5_f64, 1.33, 3.0] {
            let want = (4.0 - (16.0 - y * y).sqrt()) * lam.sin();
            let got = rise(&flat, 24.0, &a, &n, &t, y);
            assert!((got - want).abs() < 1e-9, "{y}: {got} {want}");
        }
    }

    #[test]
    fn a_flat_leaned_across_the_feed_leaves_the_cusp_of_its_face_and_wall() {
        // Axis leaned λ toward the cross-feed t: the contact is the rim; toward the disk the
        // face rises as d·tan λ, beyond the rim the wall as d·cot λ. Passes w apart cross at
        // x = w·sin²λ, so the cusp is w·sin λ·cos λ on a plane (the midpoint rule said
        // (w/2)·cot λ, five times more at 11°, which shrank such steps to nothing).
        let (n, t) = (Vec3::z(), Vec3::y());
        let flat = CutterShape::Flat { radius: 3.0 };
        for deg in [5.0_f64, 11.0, 30.0] {
            let lam = deg.to_radians();
            let a = (n * lam.cos() + t * lam.sin()).normalize();
            for w in [0.2_f64, 1.0, 2.0] {
                let want = w * lam.sin() * lam.cos();
                let got = cusp(&flat, 20.0, &a, &n, &t, 0.0, w);
                assert!((got - want).abs() < 1e-9, "{deg}° w {w}: {got} {want}");
            }
        }
    }

    #[test]
    fn ball_envelope_is_the_dual_search_of_its_body() {
        // The ball's closed-form circle against the generic search on a bull-nose of corner
        // radius = radius (the same body), with the axis leaned along the feed and an offset
        // tip (leaned sideways, the flutes above the ball would reach below its circle's ends).
        let (n, t) = (Vec3::z(), Vec3::y());
        let a = Vec3::new(0.3, 0.0, 1.0).normalize();
        let tip = Vec3::new(0.7, -1.1, 0.4);
        let ball = CutterShape::Ball { radius: 3.0 };
        let torus = CutterShape::BullNose {
            radius: 3.0,
            corner_radius: 3.0,
        };
        for y in [-3.5_f64, -2.0, -0.5, 0.3, 1.5] {
            let got = envelope(&ball, 18.0, &tip, &a, &n, &t, y);
            let want = envelope(&torus, 18.0, &tip, &a, &n, &t, y);
            assert!((got - want).abs() < 1e-7, "{y}: {got} {want}");
        }
        assert_eq!(envelope(&ball, 18.0, &tip, &a, &n, &t, 5.0), f64::INFINITY);
    }

    #[test]
    fn torus_rises_faster_than_its_osculating_circle() {
        // D8 r2 at 10° lead (module comment): brute-force silhouette 0.1515 mm at 1.87 mm.
        let (n, t, f) = (Vec3::z(), Vec3::y(), Vec3::x());
        let lam = 10f64.to_radians();
        let a = (n * lam.cos() + f * lam.sin()).normalize();
        let bull = CutterShape::BullNose {
            radius: 4.0,
            corner_radius: 2.0,
        };
        let got = rise(&bull, 24.0, &a, &n, &t, 1.87);
        assert!((got - 0.1515).abs() < 2e-3, "{got}");
        // On a plane the cusp of passes w apart is the rise at w/2.
        let c = cusp(&bull, 24.0, &a, &n, &t, 0.0, 3.74);
        assert!((c - got).abs() < 1e-12);
        // A concave section takes its rise off, a convex one adds it.
        let rho: f64 = 40.0;
        let fall = rho - (rho * rho - 1.87 * 1.87).sqrt();
        assert!((cusp(&bull, 24.0, &a, &n, &t, 1.0 / rho, 3.74) - (got - fall)).abs() < 1e-12);
        assert!((cusp(&bull, 24.0, &a, &n, &t, -1.0 / rho, 3.74) - (got + fall)).abs() < 1e-12);
    }
}
