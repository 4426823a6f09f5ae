//! The tool axis across a corner blend (5-axis under TCP): the two-curve blend of reference
//! 004 §2.4 built in step with the tip blend, and its angular deviation from the programmed
//! axis, which the builder keeps within the angular tolerance by shortening the legs.

use tezgah_geom::deviation::{closest_point, maximise};
use tezgah_geom::{Curve, Vec3};

use super::blend::{cuts, Placed};
use super::piece::{Geo, Piece};
use crate::path::orient::{angle_between, AxisBlend, AxisEnd};

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

/// Nearest point of `piece` over the knot cuts `cuts` to `q`: (distance, parameter).
fn nearest(piece: &Piece, q: &Vec3, cuts: &[f64]) -> (f64, f64) {
    let (u0, u1) = (cuts[0], cuts[cuts.len() - 1]);
    match &piece.geo {
        Geo::Line(_) => {
            // Lines run linearly in their parameter: the projection in closed form.
            let (p0, p1) = (piece.geo.point(u0), piece.geo.point(u1));
            let d = p1 - p0;
            let len2 = d.norm_squared();
            let t = if len2 > 0.0 {
                ((q - p0).dot(&d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            ((p0 + d * t - q).norm(), u0 + (u1 - u0) * t)
        }
        g => cuts
            .windows(2)
            .map(|w| {
                let c = closest_point(g, q, w[0], w[1], 8);
                (c.distance, c.u)
            })
            .fold((f64::INFINITY, u0), |x, y| if y.0 < x.0 { y } else { x }),
    }
}

/// Largest angle (rad) between the blend's tool axis and the programmed axis at the nearest
/// programmed tip point on the two legs it replaces (the axis is compared where the tool is,
/// as the tip is compared with the nearest programmed point): 16 samples, golden-section
/// refinement around the largest. Zero at both ends, where the blend meets the pieces.
pub(crate) fn deviation(a: &Piece, b: &Piece, p: &Placed, axis: &AxisBlend) -> f64 {
    let (ca, cb) = (
        cuts(a, p.ua, a.geo.domain().1),
        cuts(b, b.geo.domain().0, p.ub),
    );
    maximise(
        |u| {
            let tip = p.curve.point(u);
            let (da, ua) = nearest(a, &tip, &ca);
            let (db, ub) = nearest(b, &tip, &cb);
            let programmed = if da <= db {
                a.axis_at(ua)
            } else {
                b.axis_at(ub)
            };
            programmed.map_or(0.0, |o| angle_between(&axis.at(u), &o))
        },
        0.0,
        1.0,
        16,
    )
    .distance
}
