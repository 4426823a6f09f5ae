//! Compression of short G1 runs: consecutive short feed moves that turn gently become one C²
//! cubic B-spline (geom's tolerance-bounded least squares, Piegl & Tiller A9.7 plus knot
//! insertion), within the compression share of the tolerance of every programmed point and
//! segment. Sharp vertices end a run, so they stay corners for the blender.

use tezgah_geom::fit::{approximate, Parameterisation};
use tezgah_geom::{Curve, Vec3};

use super::piece::{Geo, Mode, Piece};
use super::Tok;
use crate::path::SegmentFeed;

/// Fewest segments worth fitting: three segments (four points) and a cubic can absorb at least
/// two vertices; shorter runs are left to the blender.
pub(crate) const MIN_RUN: usize = 3;

/// Whether a piece may join a run: a short feed line in G64, with the rotary axes still.
fn eligible(p: &Piece, short: f64) -> Option<(Vec3, Vec3)> {
    match (&p.geo, p.feed, p.mode) {
        (Geo::Line(l), SegmentFeed::Feed(_), Mode::Continuous)
            if p.full_length > 0.0 && p.full_length <= short && p.rotary[0] == p.rotary[1] =>
        {
            Some((l.start(), l.end()))
        }
        _ => None,
    }
}

/// Whether `b` may follow `a` in one run: same feed, tolerance and rotary values, and a turn
/// at their common vertex of at most `max_turn` rad.
fn continues(a: &Piece, b: &Piece, max_turn: f64) -> bool {
    let (Geo::Line(la), Geo::Line(lb)) = (&a.geo, &b.geo) else {
        return false;
    };
    let cos = la.direction().dot(&lb.direction()).clamp(-1.0, 1.0);
    a.feed == b.feed
        && a.tolerance == b.tolerance
        && a.rotary[1] == b.rotary[0]
        && la.end() == lb.start()
        && cos.acos() <= max_turn
}

/// Replace every run of at least [`MIN_RUN`] eligible lines by a spline fitted within
/// `share · tolerance`. A run whose fit fails stays as lines (the blender still rounds them).
pub(crate) fn compress(toks: Vec<Tok>, short: f64, max_turn: f64, share: f64) -> Vec<Tok> {
    let mut out: Vec<Tok> = Vec::with_capacity(toks.len());
    let mut run: Vec<Piece> = Vec::new();
    let flush = |run: &mut Vec<Piece>, out: &mut Vec<Tok>| {
        if run.len() >= MIN_RUN {
            if let Some(p) = fit_run(run, share) {
                out.push(Tok::Piece(p));
                run.clear();
                return;
            }
        }
        out.extend(run.drain(..).map(Tok::Piece));
    };
    for tok in toks {
        match tok {
            Tok::Piece(p) if eligible(&p, short).is_some() => {
                if let Some(last) = run.last() {
                    if !continues(last, &p, max_turn) {
                        flush(&mut run, &mut out);
                    }
                }
                run.push(p);
            }
            other => {
                flush(&mut run, &mut out);
                out.push(other);
            }
        }
    }
    flush(&mut run, &mut out);
    out
}

/// The spline of one run, or `None` if the fit fails.
fn fit_run(run: &[Piece], share: f64) -> Option<Piece> {
    let first = run.first()?;
    let mut points: Vec<Vec3> = Vec::with_capacity(run.len() + 1);
    points.push(first.geo.point(first.geo.domain().0));
    for p in run {
        points.push(p.geo.point(p.geo.domain().1));
    }
    let tol = share * first.tolerance;
    let fit = approximate(&points, 3, tol, Parameterisation::Centripetal).ok()?;
    let mut piece = Piece::new(
        Geo::Spline(Box::new(fit.curve)),
        first.rotary,
        first.line,
        first.feed,
        first.tolerance,
        first.mode,
    );
    if !(piece.full_length.is_finite() && piece.full_length > 0.0) {
        return None;
    }
    piece.moves = run.len();
    Some(piece)
}
