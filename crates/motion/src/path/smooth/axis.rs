//! The tool axis across a corner blend (5-axis under TCP): the two-curve blend of Kahraman
//! et al. (§3) built in step with the tip blend, and its angular deviation from the programmed
//! axis, which the builder keeps within the angular tolerance by shortening the legs.

use tezgah_geom::deviation::{closest_point, maximise};
use tezgah_geom::{Curve, Vec3};

use super::blend::{cuts, Placed};
use super::piece::{Geo, Piece};
use crate::path::orient::{AxisBlend, AxisEnd};

/// The axis blend for a placed tip blend between `a` and `b`; `None` if a piece carries no
/// axis or the blend would not be well defined.
///
/// Along a piece the axis is `O(f)` with `f = s/S`; at a blend end the tip blend's speed is
/// `|C′| = λ` and `s_uu = C′·C″/|C′| = 0` (`C″ = λ²κn ⊥ t`), so `O′ = (λ/S)·dO/df` and
/// `O″ = (λ/S)²·d²O/df²` — Step 5's rigid-body formulas `Q′ = P′ + hω×O`,
/// `Q″ = P″ + h(α×O + ω×(ω×O))` with `ω = θ̇k`, `α = 0` at the ends, divided by `h`.
pub(crate) fn blend(a: &Piece, b: &Piece, p: &Placed) -> Option<AxisBlend> {
    let end = |piece: &Piece, u: f64| -> Option<AxisEnd> {
        let g = piece.axis?;
        let f = piece.fraction(u);
        let [d1, d2] = g.derivatives(f);
        let r = p.speed / piece.full_length;
        Some(AxisEnd {
            axis: g.at(f),
            d1: d1 * r,
            d2: d2 * (r * r),
        })
    };
    AxisBlend::new(end(a, p.ua)?, end(b, p.ub)?)
}

/// A leg of a piece as the deviation measure sees it: a line by its end points (the
/// projection in closed form), any other curve by its knot cuts.
enum Leg<'a> {
    Line {
        p0: Vec3,
        p1: Vec3,
        u0: f64,
        u1: f64,
    },
    Curve {
        piece: &'a Piece,
        cuts: Vec<f64>,
    },
}

impl<'a> Leg<'a> {
    fn new(piece: &'a Piece, u0: f64, u1: f64) -> Self {
        match &piece.geo {
            Geo::Line(_) => Leg::Line {
                p0: piece.geo.point(u0),
                p1: piece.geo.point(u1),
                u0,
                u1,
            },
            _ => Leg::Curve {
                piece,
                cuts: cuts(piece, u0, u1),
            },
        }
    }

    /// Nearest point to `q`: (distance, parameter).
    fn nearest(&self, q: &Vec3) -> (f64, f64) {
        match self {
            Leg::Line { p0, p1, u0, u1 } => {
                // Lines run linearly in their parameter.
                let d = p1 - p0;
                let len2 = d.norm_squared();
                let t = if len2 > 0.0 {
                    ((q - p0).dot(&d) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                ((p0 + d * t - q).norm(), u0 + (u1 - u0) * t)
            }
            Leg::Curve { piece, cuts } => cuts
                .windows(2)
                .map(|w| {
                    let c = closest_point(&piece.geo, q, w[0], w[1], 8);
                    (c.distance, c.u)
                })
                .fold(
                    (f64::INFINITY, cuts[0]),
                    |x, y| if y.0 < x.0 { y } else { x },
                ),
        }
    }
}

/// Largest angle (rad) between the blend's tool axis and the programmed axis at the nearest
/// programmed tip point on the two legs it replaces (the axis is compared where the tool is,
/// as the tip is compared with the nearest programmed point): 16 samples, golden-section
/// refinement around the largest. Zero at both ends, where the blend meets the pieces. The
/// search runs on the chord `|O − O_p|`, monotone in the angle `2 asin(chord/2)`, which
/// spares an `atan2` per evaluation.
pub(crate) fn deviation(a: &Piece, b: &Piece, p: &Placed, axis: &AxisBlend) -> f64 {
    let (la, lb) = (
        Leg::new(a, p.ua, a.geo.domain().1),
        Leg::new(b, b.geo.domain().0, p.ub),
    );
    let chord = maximise(
        |u| {
            let tip = p.curve.point(u);
            let (da, ua) = la.nearest(&tip);
            let (db, ub) = lb.nearest(&tip);
            let programmed = if da <= db {
                a.axis_at(ua)
            } else {
                b.axis_at(ub)
            };
            programmed.map_or(0.0, |o| (axis.at(u) - o).norm())
        },
        0.0,
        1.0,
        16,
    )
    .distance;
    2.0 * (0.5 * chord).min(1.0).asin()
}
