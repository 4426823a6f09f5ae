//! Iso-scallop: each pass is offset from the previous one across the feed by the side step
//! that leaves exactly the target scallop there (Can, 2010, §3.4.12, "iso-scallop II", done as a
//! propagated front rather than fixed 0.001/0.0001 parametric marches). The front is a
//! polyline in the parameter plane; every front point moves along the cross-feed direction
//! `t = n × f` mapped to `(du, dv)`, by the surface distance `ω` from the exact scallop model,
//! found by a bracketed root search. Points that run past the far edge are clamped onto it;
//! where a point was already on the edge the pass there would only repeat the previous one,
//! so that part is not cut again. The plan ends with the front lying wholly on the far edge.
//!
//! A propagated front can fold (its offsets cross where it is concave, and the points that
//! fall back are dropped) or fan out (near a pole, where a step across the feed is a large
//! parameter step), and the cleaned front may then run farther from the old one than the step
//! allowed. Each new front is therefore checked from the old one: wherever an old point lies
//! farther than its step from the new front, extra passes are inserted between the two there
//! (Lin & Koren 1996; Feng & Li 2002 fill such gaps the same way), so no gap between
//! neighbouring cuts exceeds the step.

use tezgah_geom::Vec3;

use super::iso_parametric::MAX_PASSES;
use super::true_cusp::STEP_BISECTIONS;
use super::{Context, PassPath};
use crate::error::CamError;
use crate::forward_step::UvPolyline;

/// One front point in (side, feed) parameters.
#[derive(Debug, Clone, Copy)]
struct FrontPoint {
    s: f64,
    f: f64,
    /// Clamped onto the far side edge.
    edge: bool,
    /// On the edge, and so was the point it was offset from: nothing new to cut.
    repeat: bool,
}

/// Relative excess of the gap between fronts over the allowed step tolerated before
/// [`pull_back`] moves a point.
const PULL_BACK_SLACK: f64 = 0.002;
/// Relative narrowing of the side step at the new pass, compared with the old, above which
/// the offset is redone with the narrower step.
const NARROWING_SLACK: f64 = 0.01;
/// Front points on either side used for the front's tangent.
const TANGENT_STENCIL: usize = 3;
/// Samples of the way to the far edge searched for a point beyond the side step when the
/// edge itself lies within it (a closed surface: the far edge is the seam it started from).
const SEAM_SCAN: usize = 64;
/// Root-search iterations for one offset (bracketed, so the bound only stops a stall).
const OFFSET_ITERATIONS: usize = 40;
/// Relative excess of an old point's distance to the new front over its step above which a
/// fill pass is inserted there.
const GAP_SLACK: f64 = 0.05;
/// Most fill passes between two fronts (a gap wider than this many steps is split into this
/// many, which the verification would then flag).
const MAX_FILLS: usize = 16;

/// Spacing of the front's points (mm): fine enough that the front between them is close to
/// linear in the parameter plane.
fn guide_spacing(ctx: &Context) -> f64 {
    (0.5 * ctx.shape().radius()).clamp(0.25, 1.5)
}

pub(super) fn passes(ctx: &Context) -> Result<Vec<PassPath>, CamError> {
    let axes = ctx.axes;
    let guide = guide_spacing(ctx);
    let mut front = densify(
        ctx,
        vec![
            FrontPoint {
                s: axes.side.0,
                f: axes.feed.0,
                edge: false,
                repeat: false,
            },
            FrontPoint {
                s: axes.side.0,
                f: axes.feed.1,
                edge: false,
                repeat: false,
            },
        ],
        guide,
    );
    let mut out = Vec::new();
    for _ in 0..MAX_PASSES {
        emit_runs(ctx, &front, &mut out);
        if front.iter().all(|p| p.edge) {
            return Ok(out);
        }
        let (next, fills) = advance(ctx, &front, guide)?;
        out.extend(fills);
        front = next;
    }
    Err(CamError::TooLarge {
        what: "passes",
        limit: MAX_PASSES,
    })
}

/// The runs of the front with something new to cut, each widened by one point on either
/// side so it reaches the edge it leaves from.
fn emit_runs(ctx: &Context, front: &[FrontPoint], out: &mut Vec<PassPath>) {
    let mut i = 0;
    while i < front.len() {
        if front[i].repeat {
            i += 1;
            continue;
        }
        let start = i.saturating_sub(1);
        while i < front.len() && !front[i].repeat {
            i += 1;
        }
        let end = (i + 1).min(front.len());
        if end - start >= 2 {
            let points = front[start..end]
                .iter()
                .map(|p| ctx.axes.uv(p.s, p.f))
                .collect();
            out.push(PassPath::Poly(UvPolyline { points }));
        }
    }
}

/// The next front: every point offset by its side step, then cleaned (feed parameter
/// increasing, both feed ends reached, no gaps wider than the guide spacing); and the fill
/// passes between the old front and it where they run farther apart than the step.
fn advance(
    ctx: &Context,
    front: &[FrontPoint],
    guide: f64,
) -> Result<(Vec<FrontPoint>, Vec<PassPath>), CamError> {
    let axes = ctx.axes;
    let n = front.len();
    let tiny = (axes.feed.1 - axes.feed.0) * 1e-9;
    let mut next = Vec::with_capacity(n + 8);
    let mut ends = Vec::with_capacity(n);
    let mut steps = Vec::with_capacity(n);
    let mut kept = Vec::with_capacity(n);
    for i in 0..n {
        let p = front[i];
        // A wide stencil: the side direction follows the front's course, not the jitter of
        // neighbouring points (their offsets would amplify it, pass after pass).
        let (a, b) = (
            front[i.saturating_sub(TANGENT_STENCIL)],
            front[(i + TANGENT_STENCIL).min(n - 1)],
        );
        let tangent = axes.uv(b.s - a.s, b.f - a.f);
        let (u, v) = axes.uv(p.s, p.f);
        // No normal here (a pole): the point drops out and its neighbours fill the gap.
        let Some(local) = ctx.local(u, v, tangent) else {
            continue;
        };
        // Where the cutter gouges locally the placement refuses the point anyway; step by the
        // plane's value so the front moves on.
        let w = ctx.side_step(&local).unwrap_or_else(|| {
            crate::scallop::stepover_exact(ctx.shape().radius(), 0.0, ctx.settings.scallop)
                .unwrap_or(ctx.settings.scallop)
        });
        // The front's ends slide along the feed-end boundaries: offset across the front, an
        // end would leave the boundary and the front's end, put back on it, would then stand
        // more than the step from the old end (a saddle's edge: 1.46 steps).
        let on_end =
            (i == 0 && p.f <= axes.feed.0 + tiny) || (i + 1 == n && p.f >= axes.feed.1 - tiny);
        let (dir_s, dir_f) = if on_end {
            along_side(ctx, &local)
        } else {
            cross_direction(ctx, &local)
        };
        let mut moved = offset(ctx, p, (dir_s, dir_f), &local.d.point, w);
        // The step is set by the curvature at the old pass; where it changes quickly across
        // the step (a blade's rounded edge) the surface between the passes allows less, and
        // the ridge can stand anywhere there. The smallest step over samples of the way is
        // taken (twice: the narrower way may hold a narrower place still).
        let mut w = w;
        for _ in 0..2 {
            let narrowest = narrowest_step(ctx, p, moved, tangent).unwrap_or(w);
            if narrowest >= w * (1.0 - NARROWING_SLACK) {
                break;
            }
            w = narrowest;
            moved = offset(ctx, p, (dir_s, dir_f), &local.d.point, w);
        }
        // The models see the surface across the step as its osculating circle at one point;
        // the cusp is checked on the true surface and the step shrunk until it fits.
        if !ctx.cusp_fits((u, v), axes.uv(moved.s, moved.f), tangent) {
            let (mut lo, mut hi) = (0.0, w);
            let mut fitted = None;
            for _ in 0..STEP_BISECTIONS {
                let mid = 0.5 * (lo + hi);
                let m = offset(ctx, p, (dir_s, dir_f), &local.d.point, mid);
                if ctx.cusp_fits((u, v), axes.uv(m.s, m.f), tangent) {
                    (lo, fitted) = (mid, Some(m));
                } else {
                    hi = mid;
                }
            }
            w = lo;
            moved = fitted.unwrap_or_else(|| offset(ctx, p, (dir_s, dir_f), &local.d.point, lo));
        }
        next.push(moved);
        ends.push(on_end);
        steps.push(w);
        kept.push(p);
    }
    if next.is_empty() {
        let (u, v) = axes.uv(front[0].s, front[0].f);
        return Err(CamError::Degenerate { u, v });
    }
    // The feed parameter must increase along the front: a point that falls back (where the
    // front folds over itself near a converging region) is dropped. So is an inner point
    // clamped onto a feed-end boundary where the front's end slid along it: it stopped short
    // of its offset, and the end's own offset stands for the front there.
    let mut clean: Vec<FrontPoint> = Vec::with_capacity(next.len());
    let on_feed_end = |p: &FrontPoint| p.f <= axes.feed.0 + tiny || p.f >= axes.feed.1 - tiny;
    let slid = |k: usize| ends[k] && on_feed_end(&next[k]);
    let (first_slid, last_slid) = (slid(0), slid(next.len() - 1));
    let last_index = next.len() - 1;
    for (k, p) in next.iter().copied().enumerate() {
        let inner = k != 0 && k != last_index;
        if inner
            && ((first_slid && p.f <= axes.feed.0 + tiny)
                || (last_slid && p.f >= axes.feed.1 - tiny))
        {
            continue;
        }
        if clean.last().is_none_or(|q| p.f > q.f + tiny) {
            clean.push(p);
        }
    }
    if let Some(first) = clean.first().copied() {
        if first.f > axes.feed.0 + tiny {
            clean.insert(
                0,
                FrontPoint {
                    f: axes.feed.0,
                    ..first
                },
            );
        }
    }
    if let Some(last) = clean.last().copied() {
        if last.f < axes.feed.1 - tiny {
            clean.push(FrontPoint {
                f: axes.feed.1,
                ..last
            });
        }
    }
    let mut dense = densify(ctx, clean, guide);
    pull_back(ctx, &kept, &steps, &mut dense);
    let fills = fill_gaps(ctx, &kept, &steps, &dense);
    Ok((dense, fills))
}

/// The nearest point of `front`'s polyline (on the surface, between its points' surface
/// points) to `x`: its distance and parameters.
fn nearest_on(front: &[FrontPoint], front_xyz: &[Vec3], x: &Vec3) -> (f64, f64, f64) {
    let mut best = (f64::INFINITY, front[0].s, front[0].f);
    for k in 0..front.len() {
        let (a, b) = (front_xyz[k], front_xyz[(k + 1).min(front.len() - 1)]);
        let ab = b - a;
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            ((x - a).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = (x - (a + ab * t)).norm();
        if d < best.0 {
            let q = front[(k + 1).min(front.len() - 1)];
            let p = front[k];
            best = (d, p.s + (q.s - p.s) * t, p.f + (q.f - p.f) * t);
        }
    }
    best
}

/// Fill passes between the old front (`old`, cut with side steps `steps`) and the new one:
/// every run of old points that lies farther than its step from the new front gets
/// `⌈gap / step⌉ − 1` passes between it and the nearest new points (straight in the parameters
/// from each old point to its nearest new point, at equal fractions), widened by one old point
/// on either side so they join the cuts around the gap.
fn fill_gaps(
    ctx: &Context,
    old: &[FrontPoint],
    steps: &[f64],
    new: &[FrontPoint],
) -> Vec<PassPath> {
    let axes = ctx.axes;
    let xyz = |p: &FrontPoint| {
        let (u, v) = axes.uv(p.s, p.f);
        ctx.surface.point(u, v)
    };
    if new.is_empty() || old.is_empty() {
        return Vec::new();
    }
    let new_xyz: Vec<Vec3> = new.iter().map(xyz).collect();
    let nearest: Vec<(f64, f64, f64)> = old
        .iter()
        .map(|p| nearest_on(new, &new_xyz, &xyz(p)))
        .collect();
    // How many passes the gap at each old point needs (0: none). An old point on the edge
    // that was already cut before (`repeat`) was not cut now and judges nothing.
    let need: Vec<usize> = old
        .iter()
        .zip(&nearest)
        .zip(steps)
        .map(|((p, n), w)| {
            if p.repeat || n.0.is_nan() || n.0 <= w * (1.0 + GAP_SLACK) {
                0
            } else {
                ((n.0 / w).ceil() as usize)
                    .saturating_sub(1)
                    .clamp(1, MAX_FILLS)
            }
        })
        .collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < old.len() {
        if need[i] == 0 {
            i += 1;
            continue;
        }
        let start = i;
        while i < old.len() && need[i] > 0 {
            i += 1;
        }
        let (a, b) = (start.saturating_sub(1), i.min(old.len() - 1));
        let count = need[start..i].iter().copied().max().unwrap_or(1);
        for m in 1..=count {
            let x = m as f64 / (count + 1) as f64;
            let points = (a..=b)
                .map(|k| {
                    let (p, n) = (old[k], nearest[k]);
                    axes.uv(p.s + (n.1 - p.s) * x, p.f + (n.2 - p.f) * x)
                })
                .collect::<Vec<_>>();
            if points.len() >= 2 {
                out.push(PassPath::Poly(UvPolyline { points }));
            }
        }
    }
    out
}

/// Where the new front runs farther from the old one than the side step allowed there (the
/// offsets of a front with a corner fan out ahead of it, and dropping the points that fold
/// back shortcuts the corner), its points are moved back toward their nearest old point until
/// the distance is the allowed step: the scallop between two passes is set by the gap
/// between them, wherever it is measured from.
fn pull_back(ctx: &Context, old: &[FrontPoint], steps: &[f64], new: &mut [FrontPoint]) {
    let axes = ctx.axes;
    let xyz = |s: f64, f: f64| {
        let (u, v) = axes.uv(s, f);
        ctx.surface.point(u, v)
    };
    let old_xyz: Vec<Vec3> = old.iter().map(|p| xyz(p.s, p.f)).collect();
    for q in new.iter_mut().filter(|q| !q.edge) {
        for _ in 0..3 {
            let here = xyz(q.s, q.f);
            // Nearest point of the old front's polyline, with its parameters and allowed step.
            let mut best = (f64::INFINITY, 0.0, 0.0, 0.0);
            for k in 0..old.len().saturating_sub(1) {
                let (a, b) = (old_xyz[k], old_xyz[k + 1]);
                let ab = b - a;
                let len2 = ab.norm_squared();
                let x = if len2 > 0.0 {
                    ((here - a).dot(&ab) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let d = (here - (a + ab * x)).norm();
                if d < best.0 {
                    let (s, f) = (
                        old[k].s + (old[k + 1].s - old[k].s) * x,
                        old[k].f + (old[k + 1].f - old[k].f) * x,
                    );
                    best = (d, s, f, steps[k] + (steps[k + 1] - steps[k]) * x);
                }
            }
            let (d, s, f, w) = best;
            if d.is_nan() || d <= w * (1.0 + PULL_BACK_SLACK) {
                break;
            }
            let x = w / d;
            q.s = s + (q.s - s) * x;
            q.f = f + (q.f - f) * x;
        }
    }
}

/// The cross-feed direction `t` at a front point in (side, feed) parameters, oriented toward the far
/// side; pure `+s` where `t` has no side component.
fn cross_direction(ctx: &Context, local: &super::Local) -> (f64, f64) {
    let d = &local.d;
    let t = local.frame.cross.into_inner();
    let (e, f, g) = (d.su.dot(&d.su), d.su.dot(&d.sv), d.sv.dot(&d.sv));
    let det = e * g - f * f;
    let (a, b) = (d.su.dot(&t), d.sv.dot(&t));
    let (du, dv) = ((g * a - f * b) / det, (e * b - f * a) / det);
    let (mut ds, mut df) = ctx.axes.sf((du, dv));
    if ds < 0.0 {
        (ds, df) = (-ds, -df);
    }
    if !(ds.is_finite() && df.is_finite()) || ds <= 1e-12 * (ds.abs() + df.abs()) {
        return along_side(ctx, local);
    }
    (ds, df)
}

/// The side parameter's direction `+s` (unit speed) at a front point.
fn along_side(ctx: &Context, local: &super::Local) -> (f64, f64) {
    let ss = if ctx.axes.along_v {
        local.d.su
    } else {
        local.d.sv
    };
    (1.0 / ss.norm().max(1e-300), 0.0)
}

/// Samples of the way between a front point and its offset where [`narrowest_step`] looks.
const WAY_SAMPLES: usize = 4;

/// The smallest side step allowed at [`WAY_SAMPLES`] places on the straight parameter line
/// from `from` to `to` (`to` included), for a pass running along `tangent`; `None` if none
/// has one.
fn narrowest_step(
    ctx: &Context,
    from: FrontPoint,
    to: FrontPoint,
    tangent: (f64, f64),
) -> Option<f64> {
    (1..=WAY_SAMPLES)
        .filter_map(|k| {
            let x = k as f64 / WAY_SAMPLES as f64;
            let (u, v) = ctx
                .axes
                .uv(from.s + (to.s - from.s) * x, from.f + (to.f - from.f) * x);
            ctx.local(u, v, tangent).and_then(|l| ctx.side_step(&l))
        })
        .reduce(f64::min)
}

/// `p` moved along the parameter direction `dir` until its surface point lies `w` mm (chord)
/// from `origin`, or onto the far edge if that comes first.
fn offset(ctx: &Context, p: FrontPoint, dir: (f64, f64), origin: &Vec3, w: f64) -> FrontPoint {
    let axes = ctx.axes;
    let at = |lam: f64| {
        let s = (p.s + dir.0 * lam).min(axes.side.1);
        let f = (p.f + dir.1 * lam).clamp(axes.feed.0, axes.feed.1);
        (s, f)
    };
    let dist = |lam: f64| {
        let (s, f) = at(lam);
        let (u, v) = axes.uv(s, f);
        (ctx.surface.point(u, v) - origin).norm() - w
    };
    let to_edge = (axes.side.1 - p.s) / dir.0;
    let edge_point = |lam: f64| {
        let (s, f) = at(lam);
        FrontPoint {
            s,
            f,
            edge: true,
            repeat: p.edge,
        }
    };
    if to_edge.is_nan() || to_edge <= 0.0 {
        return edge_point(0.0);
    }
    let g_edge = dist(to_edge);
    let (mut lo, mut glo, mut hi, mut ghi) = (0.0, -w, to_edge, g_edge);
    if g_edge <= 0.0 {
        // Within reach of the far edge — unless the surface closes on itself (a seam: the far
        // edge is the near one), when it comes back within `w` of the origin after going far
        // away. The first sample beyond `w` on the way brackets the true offset.
        let mut found = false;
        for k in 1..SEAM_SCAN {
            let lam = to_edge * k as f64 / SEAM_SCAN as f64;
            let g = dist(lam);
            if g > 0.0 {
                (hi, ghi) = (lam, g);
                found = true;
                break;
            }
            (lo, glo) = (lam, g);
        }
        if !found {
            return edge_point(to_edge);
        }
    }
    // Bracketed Illinois (regula falsi) on g(λ) = |S(p + λ·dir) − origin| − w, g(lo) ≤ 0.
    let mut side = 0;
    let mut lam = hi;
    for _ in 0..OFFSET_ITERATIONS {
        lam = (lo * ghi - hi * glo) / (ghi - glo);
        let g = dist(lam);
        if g.abs() <= 1e-9 * w {
            break;
        }
        if g < 0.0 {
            (lo, glo) = (lam, g);
            if side == -1 {
                ghi *= 0.5;
            }
            side = -1;
        } else {
            (hi, ghi) = (lam, g);
            if side == 1 {
                glo *= 0.5;
            }
            side = 1;
        }
    }
    let (s, f) = at(lam);
    FrontPoint {
        s,
        f,
        edge: false,
        repeat: false,
    }
}

/// Inserts points (linear in parameters) where neighbours lie more than `guide` mm apart.
fn densify(ctx: &Context, points: Vec<FrontPoint>, guide: f64) -> Vec<FrontPoint> {
    let axes = ctx.axes;
    let xyz = |p: &FrontPoint| {
        let (u, v) = axes.uv(p.s, p.f);
        ctx.surface.point(u, v)
    };
    let mut out = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        if let Some(q) = points.get(k + 1) {
            out.push(*p);
            let gap = (xyz(q) - xyz(p)).norm();
            let pieces = (gap / guide).ceil().min(10_000.0) as usize;
            for m in 1..pieces {
                let x = m as f64 / pieces as f64;
                out.push(FrontPoint {
                    s: p.s + (q.s - p.s) * x,
                    f: p.f + (q.f - p.f) * x,
                    edge: p.edge && q.edge,
                    repeat: p.repeat && q.repeat,
                });
            }
        } else {
            out.push(*p);
        }
    }
    out
}
