//! A cheap, still *bounding*, measure of how far a corner blend strays from the two pieces it
//! joins: the blend placer ([`super::blend::place`]) asks this first and samples the blend
//! (geom's `maximise`, each sample two closest-point searches) only when the bound cannot decide.
//!
//! Each neighbour is covered by chords `L_j` with a slack `h_j` such that every point of the
//! neighbour lies within `h_j` of `L_j` and the piece runs from one end of `L_j` to the other.
//! Projected on `L_j`'s line, that piece then passes every point `x` of `L_j` (intermediate
//! values), at a point within `h_j` of `x`: so `d(q, piece) ≤ d(q, L_j) + h_j` for any `q`, and
//! `d(q, piece) ≥ d(q, L_j) − h_j`. The distance to a segment is convex, so over a Bézier piece
//! of the blend it is largest at a control point (convex-hull property, Piegl & Tiller §1.4):
//! `max_u min(d_a, d_b) ≤ min_j (max_i d(P_i, L_j) + h_j)`. Where that is not below the share,
//! the blend is halved (de Casteljau) a few times before giving up.

use tezgah_geom::{Curve, Vec3};

use super::blend::Blend;
use super::piece::{Geo, Piece};

/// Halvings of the blend before the bound gives up (at most `2^DEPTH` pieces).
const DEPTH: u32 = 5;
/// Halvings of a neighbour's knot span while its slack exceeds [`SLACK_SHARE`] of the share.
const SPAN_DEPTH: u32 = 4;
/// A chord's slack is worth refining above this share of the blend's tolerance share.
const SLACK_SHARE: f64 = 0.125;
/// Chords kept per blend; a neighbour needing more is left to sampling.
const MAX_CHORDS: usize = 32;

/// A chord of a neighbour, with the neighbour's largest distance from it.
#[derive(Debug, Clone, Copy)]
struct Chord {
    a: Vec3,
    ab: Vec3,
    /// `1 / |ab|²`, 0 for a zero-length chord (then the distance is to `a`).
    inv_len2: f64,
    slack: f64,
}

impl Chord {
    fn new(a: Vec3, b: Vec3, slack: f64) -> Chord {
        let ab = b - a;
        let len2 = ab.norm_squared();
        Chord {
            a,
            ab,
            inv_len2: if len2 > 0.0 { 1.0 / len2 } else { 0.0 },
            slack,
        }
    }

    fn distance2(&self, p: &Vec3) -> f64 {
        let ap = p - self.a;
        let t = (ap.dot(&self.ab) * self.inv_len2).clamp(0.0, 1.0);
        (ap - self.ab * t).norm_squared()
    }
}

/// The chords of both neighbours of a blend.
struct Chords {
    list: Vec<Chord>,
}

impl Chords {
    /// Chords of `p` over `[u0, u1]` (the part the blend sits next to), `cuts` its knots there
    /// with both ends. `None` where the piece cannot be covered within [`MAX_CHORDS`]: arcs
    /// (a helix strays from its chord in ways the sagitta does not bound), splines without
    /// the Bézier cache, or slack that does not shrink.
    fn add(&mut self, p: &Piece, cuts: &[f64], share: f64) -> Option<()> {
        match &p.geo {
            Geo::Line(_) => {
                let (u0, u1) = (cuts[0], cuts[cuts.len() - 1]);
                self.list
                    .push(Chord::new(p.geo.point(u0), p.geo.point(u1), 0.0));
                Some(())
            }
            Geo::Arc(_) => None,
            Geo::Spline(n) => {
                for w in cuts.windows(2) {
                    self.span(n, w[0], w[1], share, SPAN_DEPTH)?;
                }
                Some(())
            }
        }
    }

    fn span(
        &mut self,
        n: &tezgah_geom::Nurbs,
        u0: f64,
        u1: f64,
        share: f64,
        depth: u32,
    ) -> Option<()> {
        let (a, b) = (n.point(u0), n.point(u1));
        let probe = Chord::new(a, b, 0.0);
        let slack = n.hull_max(u0, u1, |q| probe.distance2(q))?.max(0.0).sqrt();
        if slack > SLACK_SHARE * share && depth > 0 {
            let m = 0.5 * (u0 + u1);
            if m > u0 && m < u1 {
                self.span(n, u0, m, share, depth - 1)?;
                return self.span(n, m, u1, share, depth - 1);
            }
        }
        if self.list.len() >= MAX_CHORDS {
            return None;
        }
        self.list.push(Chord { slack, ..probe });
        Some(())
    }

    /// `min_j (max_i d(P_i, L_j) + h_j)`: an upper bound of the Bézier piece's distance from
    /// the neighbours.
    fn upper(&self, ctrl: &[Vec3; 6]) -> f64 {
        let mut best = f64::INFINITY;
        'chords: for c in &self.list {
            // Squared-distance cut-off: a chord whose bound cannot beat `best` is dropped at
            // the first control point that shows it (most chords are far from most pieces).
            let reach = best - c.slack;
            if reach <= 0.0 {
                continue;
            }
            let reach2 = reach * reach;
            let mut far = 0.0f64;
            for q in ctrl {
                far = far.max(c.distance2(q));
                if far >= reach2 {
                    continue 'chords;
                }
            }
            best = far.sqrt() + c.slack;
        }
        best
    }

    /// `min_j (d(q, L_j) − h_j)`: a lower bound of `q`'s distance from the neighbours.
    fn lower(&self, q: &Vec3) -> f64 {
        self.list.iter().fold(f64::INFINITY, |best, c| {
            best.min(c.distance2(q).sqrt() - c.slack)
        })
    }
}

/// An upper bound (≥ the true value) of the largest distance from `blend` to the pieces `a`
/// over `ca` and `b` over `cb` (their knots there with both ends, as the sampled measure uses),
/// when that bound is within `share`; `None` when it cannot tell (then sample).
pub(crate) fn away_bound(
    blend: &Blend,
    a: &Piece,
    ca: &[f64],
    b: &Piece,
    cb: &[f64],
    share: f64,
) -> Option<f64> {
    let mut chords = Chords {
        list: Vec::with_capacity(8),
    };
    chords.add(a, ca, share)?;
    chords.add(b, cb, share)?;
    piece_bound(&bernstein(blend), &chords, share, DEPTH)
}

/// The bound over one Bézier piece, halving it while the bound exceeds `share`; `None` as soon
/// as a piece's end is provably farther than `share` (the blend violates: sampling will say by
/// how much) or the depth runs out.
fn piece_bound(ctrl: &[Vec3; 6], chords: &Chords, share: f64, depth: u32) -> Option<f64> {
    let up = chords.upper(ctrl);
    if up <= share {
        return Some(up);
    }
    if depth == 0 || chords.lower(&ctrl[0]) > share || chords.lower(&ctrl[5]) > share {
        return None;
    }
    let (l, r) = halves(ctrl);
    let left = piece_bound(&l, chords, share, depth - 1)?;
    Some(left.max(piece_bound(&r, chords, share, depth - 1)?))
}

/// The blend's Bézier control points on `[0, 1]`: `b_i = Σ_{k≤i} C(i,k)/C(5,k) m_k` from its
/// power coefficients `m_k` (Farin, *Curves and Surfaces for CAGD*, §10.2).
fn bernstein(blend: &Blend) -> [Vec3; 6] {
    // C(i,k)/C(5,k) for k ≤ i ≤ 5.
    const W: [[f64; 6]; 6] = [
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1.0, 0.2, 0.0, 0.0, 0.0, 0.0],
        [1.0, 0.4, 0.1, 0.0, 0.0, 0.0],
        [1.0, 0.6, 0.3, 0.1, 0.0, 0.0],
        [1.0, 0.8, 0.6, 0.4, 0.2, 0.0],
        [1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
    ];
    let m = blend.coefficients();
    std::array::from_fn(|i| (0..=i).fold(Vec3::zeros(), |acc, k| acc + m[k] * W[i][k]))
}

/// De Casteljau at `½`: the control points of both halves.
fn halves(c: &[Vec3; 6]) -> ([Vec3; 6], [Vec3; 6]) {
    let mut work = *c;
    let mut l = [Vec3::zeros(); 6];
    let mut r = [Vec3::zeros(); 6];
    for level in 0..6 {
        l[level] = work[0];
        r[5 - level] = work[5 - level];
        for i in 0..5 - level {
            work[i] = (work[i] + work[i + 1]) * 0.5;
        }
    }
    (l, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bernstein_form_is_the_same_curve_and_halves_split_it() {
        let z = Vec3::zeros();
        let b = Blend::g2(
            super::super::blend::End {
                p: Vec3::new(-1.0, 0.2, 0.1),
                t: Vec3::x(),
                k: Vec3::new(0.0, 0.3, 0.0),
                speed: 2.0,
            },
            super::super::blend::End {
                p: Vec3::new(0.0, 1.0, -0.3),
                t: Vec3::new(0.0, 0.6, 0.8),
                k: z,
                speed: 1.5,
            },
        )
        .unwrap();
        let c = bernstein(&b);
        let de_casteljau = |c: &[Vec3; 6], t: f64| {
            let mut w = *c;
            for level in 1..6 {
                for i in 0..6 - level {
                    w[i] = w[i] * (1.0 - t) + w[i + 1] * t;
                }
            }
            w[0]
        };
        let (l, r) = halves(&c);
        for i in 0..=40 {
            let u = i as f64 / 40.0;
            let p = b.point(u);
            assert!((de_casteljau(&c, u) - p).norm() < 1e-13, "{u}");
            let half = if u <= 0.5 {
                de_casteljau(&l, 2.0 * u)
            } else {
                de_casteljau(&r, 2.0 * u - 1.0)
            };
            assert!((half - p).norm() < 1e-13, "{u}");
        }
    }
}
