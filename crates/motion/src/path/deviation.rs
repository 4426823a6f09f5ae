//! The deviation measure: how far a built path strays from the programmed one, by dense
//! sampling of every segment plus golden-section refinement around each local maximum
//! (geom's [`tezgah_geom::deviation::maximise`]). Used by the tests and by `tezgah run`'s report.
//!
//! Two directions are measured: every point of the built path to the nearest programmed piece
//! (lines, arcs), and every programmed vertex to the nearest built segment (a blend that cuts a
//! sharp corner short is seen here). Nearest pieces are found with a bounding-box filter.

use tezgah_geom::deviation::{closest_point, maximise, point_segment_distance, DEFAULT_SAMPLES};
use tezgah_geom::{Arc, Curve, Line, Move, MoveKind, Nurbs, Pose, Vec3};

use crate::path::PathItem;

/// A programmed piece with its bounding box.
enum Prog {
    Line(Line),
    Arc(Arc),
    Nurbs(std::sync::Arc<Nurbs>),
}

struct Boxed<T> {
    item: T,
    lo: Vec3,
    hi: Vec3,
}

fn box_distance(q: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    let d = Vec3::from_fn(|i, _| (lo[i] - q[i]).max(q[i] - hi[i]).max(0.0));
    d.norm()
}

/// Distance from `q` to the nearest item, `dist` per item, boxes pruning; `hint` is the index
/// of the last nearest item (neighbouring queries are near each other).
fn nearest<T>(items: &[Boxed<T>], q: &Vec3, hint: &mut usize, dist: impl Fn(&T) -> f64) -> f64 {
    if items.is_empty() {
        return f64::INFINITY;
    }
    let h = (*hint).min(items.len() - 1);
    let mut best = dist(&items[h].item);
    for (i, it) in items.iter().enumerate() {
        if i == h || box_distance(q, &it.lo, &it.hi) >= best {
            continue;
        }
        let d = dist(&it.item);
        if d < best {
            best = d;
            *hint = i;
        }
    }
    best
}

fn bbox_of<C: Curve + ?Sized>(c: &C, pad: f64) -> (Vec3, Vec3) {
    let (a, b) = c.domain();
    let mut lo = c.point(a);
    let mut hi = lo;
    let n = 64;
    for i in 1..=n {
        let p = c.point(a + (b - a) * i as f64 / n as f64);
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    let pad = Vec3::repeat(pad);
    (lo - pad, hi + pad)
}

/// The programmed pieces of `moves` from `start` (moves that fail to build are skipped: the
/// builder reports those).
fn programmed(start: Pose, moves: &[Move]) -> (Vec<Boxed<Prog>>, Vec<Vec3>) {
    let mut pos = start;
    let mut out = Vec::new();
    let mut vertices = vec![Vec3::from(start.xyz())];
    for m in moves {
        let (item, end) = match &m.kind {
            &MoveKind::Rapid { end } | &MoveKind::Feed { end } => {
                match Line::new(Vec3::from(pos.xyz()), Vec3::from(end.xyz())) {
                    Ok(l) => (Prog::Line(l), end),
                    Err(_) => continue,
                }
            }
            MoveKind::Arc(a) => match Arc::from_move(&pos, a) {
                Ok(arc) => (Prog::Arc(arc), a.end),
                Err(_) => continue,
            },
            // A TCP switch moves nothing; the next move starts from the point read anew.
            &MoveKind::ToolControl { at, .. } => {
                pos = at;
                vertices.push(Vec3::from(pos.xyz()));
                continue;
            }
            MoveKind::Nurbs(n) => (Prog::Nurbs(n.curve.clone()), n.end),
            _ => continue,
        };
        let (lo, hi) = match &item {
            Prog::Line(l) => (l.start().inf(&l.end()), l.start().sup(&l.end())),
            // Chord sagitta between 64 samples of an arc is tiny; pad by a tenth of the radius
            // over 64 to stay a true bound.
            Prog::Arc(a) => bbox_of(a, a.radius().max(a.end_radius()) * 0.01),
            // A NURBS lies in the convex hull of its control points: a true bound.
            Prog::Nurbs(c) => c.control_points().iter().fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            ),
        };
        out.push(Boxed { item, lo, hi });
        pos = end;
        vertices.push(Vec3::from(pos.xyz()));
    }
    (out, vertices)
}

fn prog_distance(p: &Prog, q: &Vec3) -> f64 {
    match p {
        Prog::Line(l) => point_segment_distance(q, &l.start(), &l.end()),
        Prog::Arc(a) => arc_distance(a, q, 0.0, 1.0).unwrap_or_else(|| {
            let (u0, u1) = a.domain();
            closest_point(a, q, u0, u1, 16).distance
        }),
        Prog::Nurbs(c) => {
            let (u0, u1) = c.domain();
            closest_on_spans(c.as_ref(), q, u0, u1)
        }
    }
}

/// Distance from `q` to the part `u ∈ [u0, u1]` of a plane arc of constant radius, in closed
/// form ([`arc_nearest`]). `None` for helices and arcs of changing radius (no closed form;
/// callers sample).
pub(crate) fn arc_distance(a: &Arc, q: &Vec3, u0: f64, u1: f64) -> Option<f64> {
    arc_nearest(a, q, u0, u1).map(|(d, _)| d)
}

/// Distance from `q` to the part `u ∈ [u0, u1]` of a plane arc of constant radius and the
/// parameter where it is reached, in closed form: `q`'s own angle if the part holds it
/// (on a part of more than a turn, the turn nearest the part's middle), else the nearer end.
/// `None` for helices and spirals.
pub(crate) fn arc_nearest(a: &Arc, q: &Vec3, u0: f64, u1: f64) -> Option<(f64, f64)> {
    use std::f64::consts::TAU;
    // A radius mismatch at rounding level (arc ends computed by the program's author) is no
    // spiral: the closed form is off by at most the mismatch.
    if a.rise() != 0.0 || (a.radius() - a.end_radius()).abs() > 1e-12 * a.radius() {
        return None;
    }
    let (c, n, r, sweep) = (a.center(), a.normal(), a.radius(), a.sweep().abs());
    let e1 = (a.point(0.0) - c) / r;
    let e2 = n.cross(&e1);
    let d = q - c;
    let (x, y, h) = (d.dot(&e1), d.dot(&e2), d.dot(&n));
    let rho = x.hypot(y);
    let ends = || {
        let (p0, p1) = ((a.point(u0) - q).norm(), (a.point(u1) - q).norm());
        if p0 <= p1 {
            (p0, u0)
        } else {
            (p1, u1)
        }
    };
    if rho == 0.0 || sweep == 0.0 {
        // On the axis every point of the arc is as near.
        return Some((r.hypot(h), 0.5 * (u0 + u1)));
    }
    // The angle of q in the arc's own sense, in [0, 2π).
    let theta = (y.atan2(x) * a.sweep().signum()).rem_euclid(TAU);
    let (t0, t1) = (sweep * u0, sweep * u1);
    let mid = 0.5 * (t0 + t1);
    let k = ((mid - theta) / TAU).round();
    let mut t = theta + k * TAU;
    if t < t0 {
        t += TAU;
    } else if t > t1 {
        t -= TAU;
    }
    if (t0..=t1).contains(&t) {
        Some(((rho - r).hypot(h), t / sweep))
    } else {
        Some(ends())
    }
}

/// Distance from `q` to the curve over `[u0, u1]`, searched knot span by knot span: on a
/// spline whose parameter speed varies a lot between spans (centripetal parameters over very
/// uneven chords), 16 samples over the whole domain can land the refinement in the wrong basin
/// (seen: 0.0154 mm reported where 0.0004 mm was true).
pub(crate) fn closest_on_spans<C: Curve + ?Sized>(c: &C, q: &Vec3, u0: f64, u1: f64) -> f64 {
    let mut cuts = vec![u0];
    cuts.extend(c.breakpoints().into_iter().filter(|&b| b > u0 && b < u1));
    cuts.push(u1);
    cuts.windows(2)
        .map(|w| closest_point(c, q, w[0], w[1], 8).distance)
        .fold(f64::INFINITY, f64::min)
}

/// Largest distance between the built path `smoothed` and the programmed `moves` (starting
/// at `start`), both directions as described in the module documentation, mm.
pub fn deviation(start: Pose, moves: &[Move], smoothed: &[PathItem]) -> f64 {
    let (prog, vertices) = programmed(start, moves);
    let mut hint = 0;
    let mut worst = 0.0f64;
    let mut segs = Vec::new();
    for item in smoothed {
        let PathItem::Segment(s) = item else { continue };
        let c = &s.curve;
        let bps = c.breakpoints();
        for w in bps.windows(2) {
            let d = maximise(
                |u| {
                    let q = c.point(u);
                    let mut h = hint;
                    nearest(&prog, &q, &mut h, |p| prog_distance(p, &q))
                },
                w[0],
                w[1],
                DEFAULT_SAMPLES,
            );
            // Move the hint along with the path.
            let q = c.point(w[1]);
            nearest(&prog, &q, &mut hint, |p| prog_distance(p, &q));
            worst = worst.max(d.distance);
        }
        let (lo, hi) = bbox_of(c.as_ref(), 0.0);
        // A bounding box of samples may miss a bulge between samples; pad generously.
        let pad = Vec3::repeat(1e-3 * (hi - lo).norm());
        segs.push(Boxed {
            item: s,
            lo: lo - pad,
            hi: hi + pad,
        });
    }
    let mut hint = 0;
    for v in &vertices {
        let d = nearest(&segs, v, &mut hint, |s| {
            let (a, b) = s.curve.domain();
            closest_on_spans(s.curve.as_ref(), v, a, b)
        });
        if d.is_finite() {
            worst = worst.max(d);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_distance_matches_sampling() {
        let a = Arc::new(
            Vec3::zeros(),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::z(),
            -4.0,
            0.0,
        )
        .unwrap();
        let b = Arc::new(Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), Vec3::z(), 7.0, 0.0).unwrap();
        for arc in [a, b] {
            for i in 0..200 {
                let t = i as f64 * 0.37;
                let q = Vec3::new(3.0 * t.cos(), 2.5 * (1.3 * t).sin(), 0.3 * (t * 0.7).sin());
                for (u0, u1) in [(0.0, 1.0), (0.2, 0.7)] {
                    let exact = arc_distance(&arc, &q, u0, u1).unwrap();
                    let brute = (0..=20000)
                        .map(|k| (arc.point(u0 + (u1 - u0) * k as f64 / 20000.0) - q).norm())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        exact <= brute + 1e-12 && brute - exact < 1e-6,
                        "{exact} {brute}"
                    );
                }
            }
        }
    }
}
