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
        // A fit that hooks at an end is retried without that end's move (kept as a line,
        // which the blender then joins to the spline), a few times.
        let (mut lo, mut hi) = (0, run.len());
        let mut fitted = None;
        for _ in 0..HOOK_RETRIES {
            if hi - lo < MIN_RUN {
                break;
            }
            match fit_run(&run[lo..hi], share) {
                Fit::Spline(p) => {
                    fitted = Some(p);
                    break;
                }
                Fit::Hook { start, end } => {
                    lo += usize::from(start);
                    hi -= usize::from(end);
                }
                Fit::Failed => break,
            }
        }
        match fitted {
            Some(p) => {
                let mut rest = run.drain(..);
                out.extend(rest.by_ref().take(lo).map(Tok::Piece));
                out.push(Tok::Piece(*p));
                out.extend(rest.skip(hi - lo).map(Tok::Piece));
            }
            None => out.extend(run.drain(..).map(Tok::Piece)),
        }
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

/// Fits tried per run when the spline hooks at an end.
const HOOK_RETRIES: usize = 4;

/// What fitting a run gave.
enum Fit {
    Spline(Box<Piece>),
    /// The spline leaves backwards at its start and/or end (see [`fit_run`]).
    Hook {
        start: bool,
        end: bool,
    },
    Failed,
}

/// The spline of one run.
fn fit_run(run: &[Piece], share: f64) -> Fit {
    let Some(first) = run.first() else {
        return Fit::Failed;
    };
    let mut points: Vec<Vec3> = Vec::with_capacity(run.len() + 1);
    points.push(first.geo.point(first.geo.domain().0));
    for p in run {
        points.push(p.geo.point(p.geo.domain().1));
    }
    let tol = share * first.tolerance;
    // Chord-length parameters (Piegl & Tiller eq. 9.5): a run turns at most
    // `compress_corner_angle` per vertex, so chords approximate arc length and the spline's
    // parametric speed stays even. Centripetal parameters (Lee 1989) are made for sharp turns;
    // on uneven 0.05–0.3 mm spacing they gave the least squares uneven speed to fix, and the
    // refined fit folded into the vertices: 1.0/mm peaks on a surface of 0.04/mm, 117/mm on a
    // wavy one (measured when chord length replaced centripetal parameters). Chord length: 0.04/mm
    // and 10/mm, with fewer control points.
    let Ok(fit) = approximate(&points, 3, tol, Parameterisation::ChordLength) else {
        return Fit::Failed;
    };
    // Least squares pins the end points but not the end tangents: on a short first or last
    // move the spline can leave backwards and hook round within the tolerance (seen after a
    // reversal: a near-cusp, whose arc length even geom's quadrature misjudges). Such a spline
    // would hide a curvature spike (or a reversal) in the spline; the caller refits without
    // that end's move. Only a backward end tangent (more than 90° off the end move) counts.
    let (u0, u1) = fit.curve.domain();
    let n = points.len();
    let ok_end = |u: f64, a: Vec3, b: Vec3| {
        let d = fit.curve.d1(u);
        let chord = b - a;
        let cos = d.dot(&chord) / (d.norm() * chord.norm());
        cos.is_finite() && cos > 0.0
    };
    let (start, end) = (
        !ok_end(u0, points[0], points[1]),
        !ok_end(u1, points[n - 2], points[n - 1]),
    );
    if start || end {
        return Fit::Hook { start, end };
    }
    let mut piece = Piece::new(
        Geo::Spline(std::sync::Arc::new(fit.curve)),
        first.rotary,
        first.line,
        first.feed,
        first.tolerance,
        first.mode,
    );
    if !(piece.full_length.is_finite() && piece.full_length > 0.0) {
        return Fit::Failed;
    }
    piece.moves = run.len();
    // The rotary axes stand still along a run, so does the tool axis.
    piece.axis = first.axis;
    Fit::Spline(Box::new(piece))
}
