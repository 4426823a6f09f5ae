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
//! a chord is made for the piece itself on each spline neighbour (between where its ends
//! project, so that no fixed chord shorter than the piece spoils the bound by its ends), and
//! failing that the blend is halved (de Casteljau) up to [`DEPTH`] times before giving up.
//! Long, nearly tangent blends between two splines (where windows cut a raster row) need that:
//! legs of ~10 mm, ~0.75 of the share away from the splines all along.

use tezgah_geom::{Curve, Vec3};

use super::blend::Blend;
use super::piece::{Geo, Piece};

/// Halvings of the blend before the bound gives up (at most `2^DEPTH` pieces).
const DEPTH: u32 = 7;
/// Halvings of a neighbour's knot span while its slack exceeds [`SLACK_SHARE`] of the share
/// (few: the fixed chords serve short blends and locate the per-piece ones).
const SPAN_DEPTH: u32 = 2;
/// A chord's slack is worth refining above this share of the blend's tolerance share.
const SLACK_SHARE: f64 = 0.125;
/// Chords kept per blend; a neighbour needing more is left to sampling.
const MAX_CHORDS: usize = 64;

/// A chord of a neighbour, with the neighbour's largest distance from it.
#[derive(Debug, Clone, Copy)]
struct Chord {
    a: Vec3,
    ab: Vec3,
    /// `1 / |ab|²`, 0 for a zero-length chord (then the distance is to `a`).
    inv_len2: f64,
    slack: f64,
    /// The spline (index into [`Chords::splines`]) and parameters the chord spans; `None`
    /// for a line.
    span: Option<(usize, f64, f64)>,
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
            span: None,
        }
    }

    /// Where along the chord `p` projects, `[0, 1]`.
    fn along(&self, p: &Vec3) -> f64 {
        ((p - self.a).dot(&self.ab) * self.inv_len2).clamp(0.0, 1.0)
    }

    fn distance2(&self, p: &Vec3) -> f64 {
        let t = self.along(p);
        (p - self.a - self.ab * t).norm_squared()
    }
}

/// The chords of both neighbours of a blend.
struct Chords<'a> {
    list: Vec<Chord>,
    /// The spline neighbours and the parameter range the blend sits next to.
    splines: Vec<(&'a tezgah_geom::Nurbs, f64, f64)>,
}

impl<'a> Chords<'a> {
    /// Chords of `p` over `[u0, u1]` (the part the blend sits next to), `cuts` its knots there
    /// with both ends. `None` where the piece cannot be covered within [`MAX_CHORDS`]: arcs
    /// (a helix strays from its chord in ways the sagitta does not bound), splines without
    /// the Bézier cache, or slack that does not shrink.
    fn add(&mut self, p: &'a Piece, cuts: &[f64], share: f64) -> Option<()> {
        match &p.geo {
            Geo::Line(_) => {
                let (u0, u1) = (cuts[0], cuts[cuts.len() - 1]);
                self.list
                    .push(Chord::new(p.geo.point(u0), p.geo.point(u1), 0.0));
                Some(())
            }
            Geo::Arc(_) => None,
            Geo::Spline(n) => {
                let owner = self.splines.len();
                self.splines.push((n, cuts[0], cuts[cuts.len() - 1]));
                for w in cuts.windows(2) {
                    self.span(n, owner, w[0], w[1], share, SPAN_DEPTH)?;
                }
                Some(())
            }
        }
    }

    fn span(
        &mut self,
        n: &tezgah_geom::Nurbs,
        owner: usize,
        u0: f64,
        u1: f64,
        share: f64,
        depth: u32,
    ) -> Option<()> {
        let c = spline_chord(n, u0, u1)?;
        if c.slack > SLACK_SHARE * share && depth > 0 {
            let m = 0.5 * (u0 + u1);
            if m > u0 && m < u1 {
                self.span(n, owner, u0, m, share, depth - 1)?;
                return self.span(n, owner, m, u1, share, depth - 1);
            }
        }
        if self.list.len() >= MAX_CHORDS {
            return None;
        }
        self.list.push(Chord {
            span: Some((owner, u0, u1)),
            ..c
        });
        Some(())
    }

    /// The bound through chords made for this piece of the blend: on each spline neighbour,
    /// the part between where the piece's ends project (through the nearest chord), widened
    /// by a quarter either side, as one chord with its own slack. The fixed chords can be
    /// shorter than a piece of a long blend, which then overshoots every one of them along
    /// its length.
    fn local_upper(&self, ctrl: &[Vec3; 6]) -> f64 {
        let mut best = f64::INFINITY;
        for (k, &(n, lo, hi)) in self.splines.iter().enumerate() {
            let (Some(v0), Some(v1)) = (self.project(k, &ctrl[0]), self.project(k, &ctrl[5]))
            else {
                continue;
            };
            let (a, b) = (v0.min(v1), v0.max(v1));
            let pad = 0.25 * (b - a);
            let Some(c) = spline_chord(n, (a - pad).max(lo), (b + pad).min(hi)) else {
                continue;
            };
            let far = ctrl.iter().map(|q| c.distance2(q)).fold(0.0, f64::max);
            best = best.min(far.sqrt() + c.slack);
        }
        best
    }

    /// The parameter of spline `k` nearest `q` as seen through its nearest chord.
    fn project(&self, k: usize, q: &Vec3) -> Option<f64> {
        self.list
            .iter()
            .filter_map(|c| match c.span {
                Some((owner, w0, w1)) if owner == k => Some((c.distance2(q), c, w0, w1)),
                _ => None,
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, c, w0, w1)| w0 + (w1 - w0) * c.along(q))
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

/// The chord of `n` over `[u0, u1]` and, as slack, the hull bound of the piece's distance
/// from it (`None` without the Bézier cache).
fn spline_chord(n: &tezgah_geom::Nurbs, u0: f64, u1: f64) -> Option<Chord> {
    let c = Chord::new(n.point(u0), n.point(u1), 0.0);
    let slack = n.hull_max(u0, u1, |q| c.distance2(q))?.max(0.0).sqrt();
    Some(Chord { slack, ..c })
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
        splines: Vec::with_capacity(2),
    };
    chords.add(a, ca, share)?;
    chords.add(b, cb, share)?;
    piece_bound(&bernstein(blend), &chords, share, DEPTH)
}

/// The bound over one Bézier piece, halving it while the bound exceeds `share`; `None` as soon
/// as a piece's end is provably farther than `share` (the blend violates: sampling will say by
/// how much) or the depth runs out.
fn piece_bound(ctrl: &[Vec3; 6], chords: &Chords, share: f64, depth: u32) -> Option<f64> {
    let mut up = chords.upper(ctrl);
    if up > share {
        up = up.min(chords.local_upper(ctrl));
    }
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
