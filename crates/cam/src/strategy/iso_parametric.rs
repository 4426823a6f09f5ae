//! Iso-parametric zig-zag (Can, 2010, §3.4.8–3.4.9): passes along the feed parameter at one
//! constant parametric side step, chosen so the scallop stays within the target everywhere.
//! Can (2010, §3.4.8) sizes it at the point of tightest convex radius only; here the step is the
//! minimum over a lattice of the whole surface of the local allowed step `ω / |S_s · t|` (the side
//! step's component across the feed per unit parameter). On a trimmed face the lattice and the
//! passes cover the face's box, and only lattice points on the face count: a tight place of the
//! surface beyond the trim does not narrow the step.

use rayon::prelude::*;

use super::true_cusp::STEP_BISECTIONS;
use super::{Axes, Context, PassPath};
use crate::error::CamError;
use crate::forward_step::IsoLine;

/// Lattice size (per direction) over which the constant side step is minimised.
const LATTICE: usize = 48;
/// Most passes a plan may have.
pub(super) const MAX_PASSES: usize = 200_000;

/// The constant parametric side step of the iso-parametric strategies.
pub fn iso_parametric_side_step(
    surface: &tezgah_geom::NurbsSurface,
    cutter: &crate::cutter::Cutter,
    settings: &super::Settings,
) -> Result<f64, CamError> {
    settings.validate()?;
    super::validate_cutter(cutter)?;
    let ctx = Context::new(surface, cutter, settings)?;
    side_step(&ctx)
}

/// The (side, feed) ranges the passes cover: the domain's, or on a trimmed face the part of
/// them its region's box spans.
fn face_box(ctx: &Context) -> ((f64, f64), (f64, f64)) {
    let Axes {
        side,
        feed,
        along_v,
    } = ctx.axes;
    let (u, v) = if along_v { (side, feed) } else { (feed, side) };
    match ctx.settings.region.as_ref().and_then(|r| r.clip_box(u, v)) {
        Some((u, v)) if along_v => (u, v),
        Some((u, v)) => (v, u),
        None => (side, feed),
    }
}

fn side_step(ctx: &Context) -> Result<f64, CamError> {
    let (side, feed) = face_box(ctx);
    let mut best = side.1 - side.0;
    for i in 0..=LATTICE {
        let s = side.0 + (side.1 - side.0) * i as f64 / LATTICE as f64;
        for j in 0..=LATTICE {
            let f = feed.0 + (feed.1 - feed.0) * j as f64 / LATTICE as f64;
            let (u, v) = ctx.axes.uv(s, f);
            if !ctx.on_face(u, v) {
                continue;
            }
            let tangent = ctx.axes.uv(0.0, 1.0);
            let Some(local) = ctx.local(u, v, tangent) else {
                continue;
            };
            // Where the cutter gouges locally there is no scallop to size; placement reports it.
            let Some(w) = ctx.side_step(&local) else {
                continue;
            };
            let ss = if ctx.axes.along_v {
                local.d.su
            } else {
                local.d.sv
            };
            let across = ss.dot(&local.frame.cross).abs();
            if across > 0.0 {
                best = best.min(w / across);
            }
        }
    }
    Ok(true_surface_step(ctx, best))
}

/// `step`, shrunk until the cusp between passes `step` apart, measured on the true surface
/// (`true_cusp`), fits the target at every lattice point: the worst place of a constant step
/// is where the model's osculating circle departs most from the surface across it.
fn true_surface_step(ctx: &Context, step: f64) -> f64 {
    let (side, feed) = face_box(ctx);
    let tangent = ctx.axes.uv(0.0, 1.0);
    let allowed = |s: f64, f: f64| -> f64 {
        let (u, v) = ctx.axes.uv(s, f);
        if !ctx.on_face(u, v) {
            return step;
        }
        let fits = |d: f64| {
            let s2 = s + d;
            let (u2, v2) = ctx.axes.uv(s2, f);
            if s2 > side.1 || !ctx.on_face(u2, v2) {
                return true;
            }
            ctx.cusp_fits((u, v), (u2, v2), tangent)
        };
        if fits(step) {
            return step;
        }
        let (mut lo, mut hi) = (0.0, step);
        for _ in 0..STEP_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if fits(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    (0..=LATTICE)
        .into_par_iter()
        .map(|i| {
            let s = side.0 + (side.1 - side.0) * i as f64 / LATTICE as f64;
            (0..=LATTICE)
                .map(|j| allowed(s, feed.0 + (feed.1 - feed.0) * j as f64 / LATTICE as f64))
                .fold(step, f64::min)
        })
        .reduce(|| step, f64::min)
}

/// The passes: iso lines at `side.0 + k·Δ`, `k = 0..=n`, `n = ⌈range / Δs⌉`, in order.
pub(super) fn passes(ctx: &Context) -> Result<Vec<PassPath>, CamError> {
    let along_v = ctx.axes.along_v;
    let (side, feed) = face_box(ctx);
    let step = side_step(ctx)?;
    let range = side.1 - side.0;
    let count = (range / step).ceil();
    if !(count.is_finite() && count < MAX_PASSES as f64) {
        return Err(CamError::TooLarge {
            what: "passes",
            limit: MAX_PASSES,
        });
    }
    let n = (count as usize).max(1);
    Ok((0..=n)
        .map(|k| {
            PassPath::Iso(IsoLine {
                fixed: side.0 + range * k as f64 / n as f64,
                along_v,
                start: feed.0,
                end: feed.1,
            })
        })
        .collect())
}
