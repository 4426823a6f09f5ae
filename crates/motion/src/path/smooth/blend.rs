//! Corner blending: at a junction of two pieces, trim both back by a leg `ℓ` and insert a
//! curvature-continuous (G2) quintic micro-spline between the trim points (Kahraman et
//! al., §3; corner rounding as Beudaert, Lavernhe & Tournier, 2013, and Tulsyan & Altıntaş).
//!
//! The blend is Kahraman et al.'s quintic Hermite (§3) in a normalised parameter
//! `u ∈ [0, 1]` (duration 1): at each end it takes the neighbour's point, `λ·t` as first and
//! `λ²·κn` as second derivative (`t` unit tangent, `κn` curvature vector of the neighbour in
//! arc length). Then the blend's unit tangent is `t` and its curvature vector
//! `(C'' − (C''·t)t)/|C'|² = κn`: position, tangent and curvature continue, whatever `λ`.
//! With `λ = 2ℓ` it is exactly the paper's line–line blend with `T = 2ℓ/v`, whose corner
//! deviation is `δ = (3/8)·ℓ·sin(φ/2)` (the paper gives no closed form: integrating
//! `C' = 2ℓ(t0 + (t1 − t0)w)` from `−ℓt0` puts the mid-blend point at `(3/16)·ℓ·(t1 − t0)`
//! from the corner, and `|t1 − t0| = 2 sin(φ/2)`); so `ℓ = 8ε/(3 sin(φ/2))` puts it at the
//! tolerance `ε` exactly: the tolerance-exact leg.

use tezgah_geom::arclen::gauss_legendre;
use tezgah_geom::deviation::{closest_point, maximise, point_segment_distance};
use tezgah_geom::{Curve, Quintic, State, Vec3};

use super::bound::away_bound;
use super::piece::{Geo, Piece};

/// Largest share of a neighbour's (remaining) length a leg may take: two legs on one piece
/// then leave at least a fifth of it (`1 − 2·0.4`), so blends never overlap or eat a piece.
pub(crate) const LEG_SHARE: f64 = 0.4;

/// Below this turning angle (rad) a junction is tangent: no blend is needed (or possible: the
/// leg `8ε/(3 sin(φ/2))` would be unbounded).
pub(crate) const TANGENT_ANGLE: f64 = 1e-9;

/// Acceptance of a panel of the blend-length quadrature (relative difference of the whole
/// and its halves), and the splits always made first. A looser 1e-7 without the forced splits
/// accepted by coincidence on a 172.5° blend, 1.7e-6 relative off (caught by the property
/// tests against geom's map).
const LENGTH_RTOL: f64 = 1e-10;
const MIN_DEPTH: u32 = 2;

/// Halvings of the leg tried when a blend between curved pieces is measured outside its share.
const LEG_HALVINGS: usize = 12;

/// The blend curve: a quintic on `[0, 1]` that returns its end points bit for bit, so the
/// joints with the trimmed neighbours meet exactly (the polynomial form alone would round).
#[derive(Debug, Clone, Copy)]
pub struct Blend {
    q: Quintic,
    start: Vec3,
    end: Vec3,
}

/// One end of a blend: the neighbour's point, unit tangent and curvature vector there, and
/// the blend's parametric speed at that end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct End {
    pub p: Vec3,
    pub t: Vec3,
    pub k: Vec3,
    pub speed: f64,
}

impl End {
    fn state(&self) -> State {
        State {
            p: self.p,
            v: self.t * self.speed,
            a: self.k * (self.speed * self.speed),
        }
    }
}

impl Blend {
    /// The G2 blend between two ends; `None` if the data are not finite.
    pub fn g2(start: End, end: End) -> Option<Blend> {
        let q = Quintic::hermite(start.state(), end.state(), 1.0).ok()?;
        Some(Blend {
            q,
            start: start.p,
            end: end.p,
        })
    }

    /// Length by adaptive 8-point Gauss–Legendre: a panel is split in halves until the halves
    /// agree with the whole to [`LENGTH_RTOL`], after at least [`MIN_DEPTH`] splits; the kept
    /// halves are far better than that (tested
    /// against geom's 1e-13 map to 1e-9 relative, also on a 170° blend whose speed dips to cos 85°). No table
    /// is built (the planner builds its own map if it needs one).
    pub fn arc_length(&self) -> f64 {
        let whole = gauss_legendre(self, 0.0, 1.0);
        self.panel(0.0, 1.0, whole, 0)
    }

    /// Power coefficients `[c0 … c5]` on `u ∈ [0, 1]` (for the Bernstein form of [`super::bound`]).
    pub(crate) fn coefficients(&self) -> [Vec3; 6] {
        self.q.coefficients()
    }

    fn panel(&self, a: f64, b: f64, whole: f64, depth: u32) -> f64 {
        let m = 0.5 * (a + b);
        let (l, r) = (gauss_legendre(self, a, m), gauss_legendre(self, m, b));
        if (depth >= MIN_DEPTH && (whole - (l + r)).abs() <= LENGTH_RTOL * (l + r)) || depth >= 24 {
            l + r
        } else {
            self.panel(a, m, l, depth + 1) + self.panel(m, b, r, depth + 1)
        }
    }
}

impl Curve for Blend {
    fn domain(&self) -> (f64, f64) {
        (0.0, 1.0)
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        let mut d = self.q.derivs(u);
        if u <= 0.0 || u.is_nan() {
            d[0] = self.start;
        } else if u >= 1.0 {
            d[0] = self.end;
        }
        d
    }
    /// Position only (the deviation measures' integrand): one Horner instead of four.
    fn point(&self, u: f64) -> Vec3 {
        if u.is_nan() || u <= 0.0 {
            return self.start;
        }
        if u >= 1.0 {
            return self.end;
        }
        horner(&self.q.coefficients(), u)
    }
    /// Velocity only (the arc-length quadrature's integrand): one Horner instead of four.
    fn d1(&self, u: f64) -> Vec3 {
        let t = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        let c = self.q.coefficients();
        (((c[5] * 5.0 * t + c[4] * 4.0) * t + c[3] * 3.0) * t + c[2] * 2.0) * t + c[1]
    }
    fn speed(&self, u: f64) -> f64 {
        self.d1(u).norm()
    }
}

/// `Σ c_k u^k` by Horner's rule.
pub(crate) fn horner(c: &[Vec3; 6], u: f64) -> Vec3 {
    ((((c[5] * u + c[4]) * u + c[3]) * u + c[2]) * u + c[1]) * u + c[0]
}

fn gl8(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    tezgah_geom::arclen::gauss_legendre_8(f, a, b)
}

fn adaptive(f: &impl Fn(f64) -> f64, a: f64, b: f64, whole: f64, depth: u32) -> f64 {
    let m = 0.5 * (a + b);
    let (l, r) = (gl8(f, a, m), gl8(f, m, b));
    if (depth >= MIN_DEPTH && (whole - (l + r)).abs() <= LENGTH_RTOL * (l + r)) || depth >= 24 {
        l + r
    } else {
        adaptive(f, a, m, l, depth + 1) + adaptive(f, m, b, r, depth + 1)
    }
}

/// Length of the line–line blend with legs `ℓ` and turn `φ`, in closed form up to a scalar
/// quadrature: `C'(u) = 2ℓ (t0 + (t1 − t0) w)`, `w = 3u² − 2u³` (the line–line quintic), so
/// `|C'| = 2ℓ √(1 − 2w(1−w)(1 − cos φ))`, symmetric about `u = ½`. Same rule and acceptance as
/// [`Blend::arc_length`], on a scalar instead of a vector integrand (the bench's hot spot).
pub(crate) fn line_line_length(leg: f64, cos_phi: f64) -> f64 {
    let g = |u: f64| {
        let w = u * u * (3.0 - 2.0 * u);
        (1.0 - 2.0 * w * (1.0 - w) * (1.0 - cos_phi))
            .max(0.0)
            .sqrt()
    };
    let whole = gl8(&g, 0.0, 0.5);
    4.0 * leg * adaptive(&g, 0.0, 0.5, whole, 0)
}

/// Why a junction is not blended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum NoBlend {
    /// Tangents agree: `Smooth` if curvature also does, else `Tangent`.
    Tangent { same_curvature: bool },
    /// A corner the blender cannot round (zero-length neighbour, reversal, tolerance too
    /// small for the available length).
    Corner,
}

/// A blend ready to insert, with the trim parameters of both neighbours.
pub(crate) struct Placed {
    pub curve: Blend,
    pub length: f64,
    /// New end parameter of the incoming piece, new start parameter of the outgoing one.
    pub ua: f64,
    pub ub: f64,
    /// Corner deviation achieved (distance from the programmed corner to the blend), mm.
    pub deviation: f64,
    /// The blend's parametric speed `|C′|` at both ends (`λ = 2ℓ`).
    pub speed: f64,
}

/// `min(best, distance from q to the piece's geometry over [u0, u1])`; `cuts` are the piece's
/// knots in that range with both ends ([`cuts`]), found once per leg rather than per sample: a
/// spline's knot vector has hundreds of entries and the blend measure calls this ~50 times.
/// A knot span whose control points' box is already `best` or farther from `q` cannot lower
/// the minimum (the span lies in the box) and is not searched.
fn distance_to(p: &Piece, q: &Vec3, cuts: &[f64], best: f64) -> f64 {
    let (u0, u1) = (cuts[0], cuts[cuts.len() - 1]);
    match &p.geo {
        Geo::Line(_) => best.min(point_segment_distance(
            q,
            &p.geo.point(u0),
            &p.geo.point(u1),
        )),
        Geo::Arc(a) => best.min(
            crate::path::deviation::arc_distance(a, q, u0, u1)
                .unwrap_or_else(|| closest_point(a.as_ref(), q, u0, u1, 8).distance),
        ),
        Geo::Spline(n) => cuts.windows(2).fold(best, |best, w| {
            if n.hull_box(w[0], w[1])
                .is_some_and(|b| b.distance(q) >= best)
            {
                best
            } else {
                best.min(closest_point(&p.geo, q, w[0], w[1], 8).distance)
            }
        }),
    }
}

/// `[u0, the piece's knots strictly inside, u1]` (just the ends for lines and arcs).
pub(crate) fn cuts(p: &Piece, u0: f64, u1: f64) -> Vec<f64> {
    let mut c = vec![u0];
    if let Geo::Spline(n) = &p.geo {
        let k = n.knots();
        let lo = k.partition_point(|&x| x <= u0);
        let hi = k.partition_point(|&x| x < u1);
        for &x in &k[lo..hi.max(lo)] {
            if c.last() != Some(&x) {
                c.push(x);
            }
        }
    }
    c.push(u1);
    c
}

/// Whether `a` runs into `b` without a turn (a tangent junction, where a blend only spreads a
/// curvature jump; see [`place`]).
pub(crate) fn tangent(a: &Piece, b: &Piece) -> bool {
    match (a.frame(a.geo.domain().1), b.frame(b.geo.domain().0)) {
        (Some((ta, _)), Some((tb, _))) => ta.cross(&tb).norm().atan2(ta.dot(&tb)) < TANGENT_ANGLE,
        _ => false,
    }
}

/// Place a blend between `a` (incoming, trimmed up to `a.u1`) and `b` (outgoing, from `b.u0`)
/// within `share` mm of the programmed path; `max_angle` (rad) is the largest turn blended.
pub(crate) fn place(a: &Piece, b: &Piece, share: f64, max_angle: f64) -> Result<Placed, NoBlend> {
    if !(a.moves_tip() && b.moves_tip()) {
        return Err(NoBlend::Corner);
    }
    let (ta, ka) = a.frame(a.geo.domain().1).ok_or(NoBlend::Corner)?;
    let (tb, kb) = b.frame(b.geo.domain().0).ok_or(NoBlend::Corner)?;
    // atan2, not acos: acos(t·u) loses every turn below ~1e-8 rad to rounding.
    let phi = ta.cross(&tb).norm().atan2(ta.dot(&tb));
    if !phi.is_finite() {
        return Err(NoBlend::Corner);
    }
    let tangent = phi < TANGENT_ANGLE;
    let jump = (ka - kb).norm();
    if tangent {
        let scale = ka.norm().max(kb.norm());
        let same = jump <= 1e-9 * scale.max(1e-300) || scale == 0.0;
        // A curvature jump (a line into a tangent arc) is an acceleration step at any speed:
        // seen at the period it is a jerk of v²·Δκ/Ts, which only a crawl keeps within the
        // limits. Where the program allows a deviation, the jump is spread over a G2 blend.
        if same || max_angle <= 0.0 {
            return Err(NoBlend::Tangent {
                same_curvature: same,
            });
        }
    } else if phi > max_angle {
        return Err(NoBlend::Corner);
    }
    let half = (0.5 * phi).sin();
    // Room on each side: the piece's remaining length times the share, but never past a
    // blend already placed at the piece's other end.
    let room_a = a.full_length * LEG_SHARE;
    let room_b = b.full_length * LEG_SHARE;
    let room_a = room_a.min(a.s_at(a.u1) - a.s_at(a.u0));
    let room_b = room_b.min(b.s_at(b.u1) - b.s_at(b.u0));
    // A hair below the tolerance-exact leg: at exactly 8ε/(3 sin(φ/2)) the closed-form
    // deviation rounds to either side of ε, and a rounding up halved the leg.
    let ideal = if tangent {
        // A clothoid that takes the curvature from κa to κb over a length L lies ~L²·Δκ/24
        // off the two curves it replaces (the shift of a transition curve, Meek & Walton
        // 1992); the blend spans about 2·leg.
        0.5 * (24.0 * share / jump).sqrt()
    } else {
        8.0 * share / (3.0 * half) * (1.0 - 1e-12)
    };
    let room = room_a.min(room_b);
    let refuse = || {
        if tangent {
            NoBlend::Tangent {
                same_curvature: false,
            }
        } else {
            NoBlend::Corner
        }
    };
    let both_lines = !tangent && matches!(a.geo, Geo::Line(_)) && matches!(b.geo, Geo::Line(_));
    let corner = a.geo.point(a.geo.domain().1);
    // The blend of legs `leg` and its deviation, if within the share.
    let trial = |leg: f64| -> Result<(f64, Option<Placed>), NoBlend> {
        if !(leg > 0.0 && leg.is_finite()) {
            return Err(refuse());
        }
        let ua = a.u_at(a.full_length - leg);
        let ub = b.u_at(leg);
        let (pa, pb) = (a.geo.point(ua), b.geo.point(ub));
        let (fa, fb) = match (a.frame(ua), b.frame(ub)) {
            (Some(fa), Some(fb)) => (fa, fb),
            _ => return Err(refuse()),
        };
        let lam = 2.0 * leg;
        let curve = Blend::g2(
            End {
                p: pa,
                t: fa.0,
                k: fa.1,
                speed: lam,
            },
            End {
                p: pb,
                t: fb.0,
                k: fb.1,
                speed: lam,
            },
        )
        .ok_or_else(refuse)?;
        let deviation = if both_lines {
            // Closed form (module doc): the corner's distance to the blend.
            0.375 * leg * half
        } else {
            // Both directions, measured: the corner to the blend, and the blend to the two
            // programmed pieces around the corner.
            let to_corner = closest_point(&curve, &corner, 0.0, 1.0, 16).distance;
            let (ca, cb) = (cuts(a, ua, a.geo.domain().1), cuts(b, b.geo.domain().0, ub));
            // A hull bound first (a few control-point distances); it is ≥ the sampled
            // maximum, so where it is within the share, sampling would accept too.
            let bound = away_bound(&curve, a, &ca, b, &cb, share);
            let away = bound.unwrap_or_else(|| away_sampled(&curve, a, &ca, b, &cb));
            to_corner.max(away)
        };
        if deviation > share {
            return Ok((deviation, None));
        }
        let length = if both_lines {
            line_line_length(leg, ta.dot(&tb))
        } else {
            curve.arc_length()
        };
        if !(length > 0.0 && length.is_finite()) {
            return Err(refuse());
        }
        Ok((
            deviation,
            Some(Placed {
                curve,
                length,
                ua,
                ub,
                deviation,
                speed: lam,
            }),
        ))
    };
    let mut leg = ideal.min(room);
    if tangent {
        // The clothoid estimate is far from what the quintic deviates: with λ = 2ℓ its
        // curvature rises nearly linearly along the blend and it stays inside the two curves
        // it joins, ~1/15 of the estimate off them (R10 line–arc at ε 0.008: 0.0005 mm).
        // The jerk a speed v asks on a transition is ~v³·Δκ/L, so the longest blend the
        // share allows is the fastest: measured, the legs grow until the share is met.
        let reach = (leg * TANGENT_REACH).min(room);
        if let Some(p) = longest_within(leg * TANGENT_START, reach, share, &trial)? {
            return Ok(p);
        }
    }
    for _ in 0..=LEG_HALVINGS {
        if let (_, Some(p)) = trial(leg)? {
            return Ok(p);
        }
        leg *= 0.5;
    }
    Err(refuse())
}

/// How far beyond the clothoid estimate a tangent blend's legs are tried ([`place`]).
const TANGENT_REACH: f64 = 6.0;

/// The first leg tried, in clothoid estimates: at that estimate a line–arc quintic deviates
/// ~1/15 of the share (whatever the radius: both scale alike), so √15 of it nearly meets it.
const TANGENT_START: f64 = 3.7;

/// Aim a little inside the share: the deviation is only nearly quadratic in the leg.
const LEG_AIM: f64 = 0.97;

/// Tries at the legs the deviation predicts, and then bisections.
const LEG_TRIES: usize = 3;
const LEG_BISECTIONS: usize = 3;

/// The longest leg up to `hi` (nearly) whose blend `trial` accepts, starting from a guess
/// `start`; `trial` gives the deviation of a leg and the blend if it is within `share`.
/// `None` if no leg tried is accepted (the caller then shortens from its own estimate). A
/// tangent blend deviates about in proportion to its leg squared (a transition's shift,
/// ~L²·Δκ/24), so each try aims at the leg that scaling predicts from the last deviation
/// measured, and bisection settles what the prediction misses. Each try measures the blend
/// against both curves: one or two is what it usually costs.
fn longest_within(
    start: f64,
    hi: f64,
    share: f64,
    trial: &impl Fn(f64) -> Result<(f64, Option<Placed>), NoBlend>,
) -> Result<Option<Placed>, NoBlend> {
    let mut best: Option<Placed> = None;
    let (mut ok, mut over) = (0.0, hi * (1.0 + 1e-12));
    let mut aim = start.min(hi);
    for _ in 0..LEG_TRIES {
        let (d, placed) = trial(aim)?;
        match placed {
            Some(p) => {
                // Close to the share, or at the top of the range: done (a transition's
                // speed grows only with the cube root of its length).
                if aim >= 0.97 * hi || d >= 0.9 * LEG_AIM * share {
                    return Ok(Some(p));
                }
                ok = aim;
                best = Some(p);
            }
            None => over = aim,
        }
        let next = (aim * (LEG_AIM * share / d.max(1e-300)).sqrt()).min(hi);
        if next >= over || next <= ok {
            break;
        }
        aim = next;
    }
    if ok > 0.0 {
        for _ in 0..LEG_BISECTIONS {
            let mid = 0.5 * (ok + over.min(hi));
            if mid <= ok * 1.01 {
                break;
            }
            match trial(mid)? {
                (_, Some(p)) => {
                    best = Some(p);
                    ok = mid;
                }
                (_, None) => over = mid,
            }
        }
    }
    Ok(best)
}

/// The blend's largest distance from the pieces `a` over `ca` and `b` over `cb`, sampled and
/// refined (geom's `maximise`): a lower estimate of the true value, used where the hull bound
/// of [`away_bound`] cannot decide.
pub(crate) fn away_sampled(curve: &Blend, a: &Piece, ca: &[f64], b: &Piece, cb: &[f64]) -> f64 {
    maximise(
        |u| {
            let q = curve.point(u);
            // The cheaper neighbour first (a spline is searched, a line or arc is
            // closed form): its distance lets the spline skip knot spans.
            if matches!(a.geo, Geo::Spline(_)) {
                distance_to(a, &q, ca, distance_to(b, &q, cb, f64::INFINITY))
            } else {
                distance_to(b, &q, cb, distance_to(a, &q, ca, f64::INFINITY))
            }
        },
        0.0,
        1.0,
        16,
    )
    .distance
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_line_line_90() {
        // Kahraman et al.'s quintic at a 90° corner, ℓ = 1, v = 10 mm/s:
        // x = −1 + 10τ − 250τ³ + 625τ⁴ with T = 0.2, i.e. u = 5τ.
        let z = Vec3::zeros();
        let b = Blend::g2(
            End {
                p: Vec3::new(-1.0, 0.0, 0.0),
                t: Vec3::x(),
                k: z,
                speed: 2.0,
            },
            End {
                p: Vec3::new(0.0, 1.0, 0.0),
                t: Vec3::y(),
                k: z,
                speed: 2.0,
            },
        )
        .unwrap();
        for i in 0..=10 {
            let tau = 0.02 * i as f64;
            let p = b.point(tau / 0.2);
            let x = -1.0 + 10.0 * tau - 250.0 * tau.powi(3) + 625.0 * tau.powi(4);
            let y = 250.0 * tau.powi(3) - 625.0 * tau.powi(4);
            assert!((p.x - x).abs() < 1e-12 && (p.y - y).abs() < 1e-12, "{tau}");
        }
        let mid = b.point(0.5).norm();
        assert!((mid - 0.265165).abs() < 5e-7, "{mid}");
        let exact = tezgah_geom::ArcLengthMap::new(&b, 1e-13).unwrap().length();
        assert!(
            (b.arc_length() - exact).abs() < 1e-11,
            "{} {exact}",
            b.arc_length()
        );
        // A near-reversal (170°): the speed dips to cos 85° at mid-blend.
        let t1 = Vec3::new(
            (170f64).to_radians().cos(),
            (170f64).to_radians().sin(),
            0.0,
        );
        let c = Blend::g2(
            End {
                p: Vec3::new(-1.0, 0.0, 0.0),
                t: Vec3::x(),
                k: z,
                speed: 2.0,
            },
            End {
                p: t1,
                t: t1,
                k: z,
                speed: 2.0,
            },
        )
        .unwrap();
        let exact = tezgah_geom::ArcLengthMap::new(&c, 1e-13).unwrap().length();
        assert!(
            (c.arc_length() - exact).abs() < 1e-10,
            "{} {exact}",
            c.arc_length()
        );
    }

    /// Random corners between splines and lines: wherever the hull bound decides, it is at
    /// least the sampled maximum (it bounds the true value) and within the share; and it
    /// decides most placed blends (else it saves nothing).
    #[test]
    fn hull_bound_is_above_the_sampled_distance() {
        use super::super::piece::Mode;
        use crate::path::SegmentFeed;
        use std::sync::Arc as Shared;
        use tezgah_geom::{Line, Nurbs};
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let piece = |geo| {
            Piece::new(
                geo,
                [[0.0; 3]; 2],
                1,
                SegmentFeed::Feed(10.0),
                0.01,
                Mode::Continuous,
            )
        };
        let (mut decided, mut placed) = (0, 0);
        for case in 0..300 {
            let corner = Vec3::new(rnd(), rnd(), rnd());
            // Incoming spline ending at the corner: a wavy cubic over 1–3 mm, 4–9 spans.
            let spans = 4 + (case % 6);
            let dir = Vec3::new(1.0, 0.3 * rnd(), 0.2 * rnd()).normalize();
            let len = 2.0 + rnd();
            let n = spans + 3;
            let ctrl: Vec<Vec3> = (0..n)
                .map(|i| {
                    let f = i as f64 / (n - 1) as f64 - 1.0;
                    let wiggle = if i == 0 || i + 1 == n {
                        Vec3::zeros()
                    } else {
                        Vec3::new(rnd(), rnd(), rnd()) * 0.05
                    };
                    corner + dir * (f * len) + wiggle
                })
                .collect();
            let mut knots = vec![0.0; 4];
            knots.extend((1..spans).map(|i| i as f64 / spans as f64));
            knots.extend([1.0; 4]);
            let a = piece(Geo::Spline(Shared::new(
                Nurbs::bspline(3, &ctrl, knots).unwrap(),
            )));
            // Outgoing: a line or a spline, turning 20–150°, or (one case in five) nearly
            // tangent, 0.001–0.01 rad: long blends, as where two splines meet at a window.
            let turn = if case % 5 == 4 {
                0.001 + 0.009 * (0.5 + 0.5 * rnd())
            } else {
                (20.0 + 130.0 * (0.5 + 0.5 * rnd())).to_radians()
            };
            let side = dir.cross(&Vec3::new(rnd(), rnd(), rnd())).normalize();
            let out = dir * turn.cos() + side * turn.sin();
            let b = if case % 2 == 0 {
                piece(Geo::Line(
                    Line::new(corner, corner + out * (1.0 + 0.5 * rnd())).unwrap(),
                ))
            } else {
                let ctrl: Vec<Vec3> = (0..6)
                    .map(|i| {
                        corner
                            + out * (0.3 * i as f64)
                            + if i == 0 {
                                Vec3::zeros()
                            } else {
                                side * (0.02 * rnd())
                            }
                    })
                    .collect();
                let knots = vec![0.0, 0.0, 0.0, 0.0, 0.4, 0.7, 1.0, 1.0, 1.0, 1.0];
                piece(Geo::Spline(Shared::new(
                    Nurbs::bspline(3, &ctrl, knots).unwrap(),
                )))
            };
            for share in [0.004, 0.02, 0.1] {
                let Ok(p) = place(&a, &b, share, 175f64.to_radians()) else {
                    continue;
                };
                placed += 1;
                let (ca, cb) = (
                    cuts(&a, p.ua, a.geo.domain().1),
                    cuts(&b, b.geo.domain().0, p.ub),
                );
                let sampled = away_sampled(&p.curve, &a, &ca, &b, &cb);
                // Also a tighter share than the blend was placed for: must not claim it.
                for s in [share, 0.5 * sampled] {
                    if let Some(bound) = away_bound(&p.curve, &a, &ca, &b, &cb, s) {
                        if s == share {
                            decided += 1;
                        }
                        assert!(bound <= s, "case {case}: bound {bound} > share {s}");
                        assert!(
                            bound >= sampled * (1.0 - 1e-12),
                            "case {case}: bound {bound} < sampled {sampled}"
                        );
                    }
                }
            }
        }
        assert!(placed > 600, "{placed}");
        assert!(decided * 10 >= placed * 9, "decided {decided} of {placed}");
    }
}
