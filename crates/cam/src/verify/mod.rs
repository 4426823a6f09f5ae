//! Independent verification of a tool path: a dexel simulation of the cut. Sits after the
//! post-processor (it sweeps the cutter along the program as the machine moves it) or after a
//! strategy (along the tool path itself), and measures the largest scallop and the deepest
//! gouge on the surface, with their error bounds.
//!
//! Dexels stand on the surface along its outward normal at the nodes of a grid in (u, v) over
//! the machined region ([`MachinedRegion`]: the surface's whole domain limited to what the
//! machine reaches, or only the box of the cutter-contact parameters), spaced at most `cell`
//! mm apart on the surface. A strip of the region that no pass touched shows as uncut or as
//! a scallop: the region is what the program is meant to machine, not what it did. Each holds the material height above its foot; every cutter pose
//! lowers it to where the dexel enters the cutter ([`solid`]). Afterwards a positive height is
//! a scallop, a negative one a gouge.
//!
//! Error bounds (both one-sided, DESIGN.md asks that they be stated):
//! * sweep: the cutter is placed at discrete poses no point of it moving more than `δ`
//!   between two; the material left between two placements is at most the sagitta of the
//!   cutter's section where the dexel meets it: at a scallop of height h that section of the
//!   corner (radius ρ: the corner radius, the tool radius for a flat end) is a circle of radius
//!   ≥ ρ − h, so heights are over-estimated by at most `δ²/(8(ρ − h))`. A flat end's
//!   section along the motion also has a corner at the rim, behind which its bottom rises at
//!   the tool's lean θ from the normal: `δ·tan θ` more (θ the largest lean of the path).
//! * grid: the highest scallop is sampled at a node at most `c/√2` from it (c the largest
//!   node spacing); the scallop's flank rises with slope at most `tan φ`, `cos φ = 1 − h/ρ`
//!   (the cutter's profile meeting the surface at the height h; on a convex surface ρ is
//!   replaced by the effective `1/(1/ρ + κ)`, κ the largest convex curvature), so the sampled
//!   maximum is below the true one by at most `tan φ · c/√2`. The same bound covers a gouge's depth.
//!   Every node within that bound of the maximum then gets a lattice twice as fine around it;
//!   when all fit under the cap the bound is halved (the true maximum lies within half a cell
//!   of a sub-node), otherwise the highest are refined and the coarse bound stands.
//!

pub mod solid;

use tezgah_geom::{NurbsSurface, Vec3};

pub use solid::{CutterPose, CutterSolid};

use crate::arc_grid::{arc_nodes, spread};
use crate::toolpath::ToolPath;

/// How finely to simulate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifyOptions {
    /// Largest spacing of dexels on the surface, mm (at most a twentieth of the step-over).
    pub cell_mm: f64,
    /// Largest motion of any cutter point between two simulated poses, mm.
    pub sweep_spacing_mm: f64,
    /// Where the surface is judged.
    pub region: MachinedRegion,
}

/// The part of the surface a program is meant to machine, which the simulation judges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MachinedRegion {
    /// The box of the path's contact parameters: what the path reached. A strip beyond its
    /// outermost passes (toward a boundary the path should have reached) is not looked at.
    ContactBox,
    /// The surface's whole domain (an untrimmed face) limited to the points whose outward
    /// normal leans at most `max_tilt_deg` from +Z: what a table-tilting machine reaches with
    /// the tool along the normal (the planner's `max_axis_tilt_deg`). Where the normal is
    /// undefined (a pole) there is no dexel.
    Reachable { max_tilt_deg: f64 },
}

/// What the simulation measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Verification {
    /// Dexels simulated.
    pub dexels: usize,
    /// Largest node spacing achieved on the surface, mm.
    pub cell_mm: f64,
    /// Cutter poses swept.
    pub poses: usize,
    /// Dexels of the region that no pose reached.
    pub uncut: usize,
    /// Highest material left above the surface (along the normal), mm; 0 if none.
    pub max_scallop_mm: f64,
    /// Where: (u, v) and the surface point.
    pub max_scallop_at: Option<((f64, f64), Vec3)>,
    /// Deepest cut below the surface, mm; 0 if none.
    pub gouge_depth_mm: f64,
    pub gouge_at: Option<((f64, f64), Vec3)>,
    /// Grid error bound, mm (the true maxima exceed the measured ones by at most this).
    pub grid_bound_mm: f64,
    /// Sweep error bound, mm (measured heights exceed the true ones by at most this).
    pub sweep_bound_mm: f64,
    /// The region judged, and the (u, v) box its grid spans.
    pub region: MachinedRegion,
    pub region_u: (f64, f64),
    pub region_v: (f64, f64),
}

/// Why the simulation could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum VerifyError {
    #[error("{what} must be a finite number > 0, got {value}")]
    Option { what: &'static str, value: f64 },
    #[error("the tool path has no cutter locations")]
    Empty,
    #[error("the grid would need {0} dexels (more than {MAX_DEXELS}); use a coarser cell")]
    TooFine(usize),
    #[error("no point of the surface lies within the machined region ({0:?})")]
    EmptyRegion(MachinedRegion),
}

/// Memory guard: 4 M dexels are ~0.35 GB of grid data.
pub const MAX_DEXELS: usize = 4_000_000;

/// Surface samples per direction when estimating the largest parametric speed.
const SPEED_SAMPLES: usize = 33;

struct Dexel {
    /// Grid node (i along u, j along v); sub-nodes of the refinement carry their parent's.
    node: (usize, usize),
    foot: Vec3,
    normal: Vec3,
    uv: (f64, f64),
    height: f64,
}

/// Poses along a tool path's passes as straight tip motion and great-circle axis motion
/// between cutter locations (links left out), no cutter point moving more than `spacing`.
pub fn path_poses(path: &ToolPath, spacing: f64) -> Vec<CutterPose> {
    let reach = path
        .cutter
        .shape
        .radius()
        .hypot(path.cutter.shape.corner_radius());
    let mut out = Vec::new();
    for pass in &path.passes {
        let Some(first) = pass.points.first() else {
            continue;
        };
        out.push(CutterPose {
            tip: first.tip,
            axis: first.axis.normalize(),
        });
        for w in pass.points.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let (ua, ub) = (a.axis.normalize(), b.axis.normalize());
            let angle = ua.angle(&ub);
            let span = (b.tip - a.tip).norm() + reach * angle;
            let n = ((span / spacing).ceil() as usize).clamp(1, 1_000_000);
            for k in 1..=n {
                let t = k as f64 / n as f64;
                let axis = if angle > 1e-12 {
                    let k_rot = ua.cross(&ub).normalize();
                    let th = t * angle;
                    ua * th.cos() + k_rot.cross(&ua) * th.sin()
                } else {
                    ua
                };
                out.push(CutterPose {
                    tip: a.tip + (b.tip - a.tip) * t,
                    axis,
                });
            }
        }
    }
    out
}

/// The step-over of a path: over neighbouring passes, the median distance from a pass's
/// contact points to the next pass's contact polyline; the smallest such median. `None`
/// with fewer than two passes.
pub fn step_over(path: &ToolPath) -> Option<f64> {
    let mut best: Option<f64> = None;
    for w in path.passes.windows(2) {
        let next: Vec<Vec3> = w[1].points.iter().map(|c| c.contact).collect();
        if next.is_empty() || w[0].points.is_empty() {
            continue;
        }
        let stride = (w[0].points.len() / 50).max(1);
        let mut d: Vec<f64> = w[0]
            .points
            .iter()
            .step_by(stride)
            .map(|c| tezgah_geom::deviation::point_polyline_distance(&c.contact, &next))
            .collect();
        d.sort_by(f64::total_cmp);
        let median = d[d.len() / 2];
        if median > 0.0 {
            best = Some(best.map_or(median, |b| b.min(median)));
        }
    }
    best
}

fn positive(what: &'static str, value: f64) -> Result<f64, VerifyError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(VerifyError::Option { what, value })
    }
}

/// Simulates `poses` of the path's cutter over `surface` and measures scallop and gouge on the
/// region the path's contact points span.
pub fn simulate(
    surface: &NurbsSurface,
    path: &ToolPath,
    poses: &[CutterPose],
    options: &VerifyOptions,
) -> Result<Verification, VerifyError> {
    let cell = positive("the cell size", options.cell_mm)?;
    let spacing = positive("the sweep spacing", options.sweep_spacing_mm)?;
    let cls: Vec<_> = path.passes.iter().flat_map(|p| &p.points).collect();
    let first = cls.first().ok_or(VerifyError::Empty)?;
    // Orient the normals out of the material as the path's first contact says.
    let flip = surface
        .normal(first.uv.0, first.uv.1)
        .is_some_and(|n| n.dot(&first.normal) < 0.0);
    let outward = |u: f64, v: f64| {
        surface.normal(u, v).map(|n| {
            if flip {
                -n.into_inner()
            } else {
                n.into_inner()
            }
        })
    };
    // cos of the largest lean a judged dexel's normal may have from +Z.
    let min_normal_z = match options.region {
        MachinedRegion::ContactBox => None,
        MachinedRegion::Reachable { max_tilt_deg } => {
            let t = positive("the region's tilt limit", max_tilt_deg)?;
            Some(t.min(180.0).to_radians().cos() - REACH_SLACK)
        }
    };
    let (u0, u1, v0, v1) = match min_normal_z {
        None => contact_box(surface, &cls),
        Some(z) => {
            reachable_box(surface, z, &outward).ok_or(VerifyError::EmptyRegion(options.region))?
        }
    };
    // Grid lines at equal steps of arc length (each parameter's speed taken as its largest
    // across the other parameter): a surface whose parametric speed varies — STEP fits often
    // run 5:1 — gets nodes no denser than the cell where it is slow.
    let (us, lu) = arc_nodes(|u, v| surface.derivs(u, v).su.norm(), (u0, u1), (v0, v1));
    let (vs, lv) = arc_nodes(|v, u| surface.derivs(u, v).sv.norm(), (v0, v1), (u0, u1));
    let nu = ((lu / cell).ceil() as usize).max(1) + 1;
    let nv = ((lv / cell).ceil() as usize).max(1) + 1;
    let count = nu.saturating_mul(nv);
    if count > MAX_DEXELS {
        return Err(VerifyError::TooFine(count));
    }
    let achieved = (lu / (nu - 1) as f64).max(lv / (nv - 1) as f64);
    let u_nodes = spread(&us, nu);
    let v_nodes = spread(&vs, nv);
    // A parameter on the lattice `f` times finer than the grid.
    let fine_at = |nodes: &[f64], k: i64, f: i64| -> f64 {
        let i = (k / f) as usize;
        if i + 1 >= nodes.len() {
            return nodes[nodes.len() - 1];
        }
        let t = (k % f) as f64 / f as f64;
        nodes[i] + (nodes[i + 1] - nodes[i]) * t
    };
    // The surface's largest convex curvature (bending away from the outward normal): a scallop
    // flank rises over it as over a plane under a cutter of the smaller effective radius
    // 1/(1/ρ + κ), so the grid bound uses that.
    let mut convex = 0.0_f64;
    for i in 0..SPEED_SAMPLES {
        for j in 0..SPEED_SAMPLES {
            let u = u0 + (u1 - u0) * i as f64 / (SPEED_SAMPLES - 1) as f64;
            let v = v0 + (v1 - v0) * j as f64 / (SPEED_SAMPLES - 1) as f64;
            if let Some(k) = surface.principal_curvatures(u, v) {
                // Curvatures are positive toward S_u × S_v; the most convex is the most
                // negative toward the outward normal.
                let outward_min = if flip { -k.k1 } else { k.k2 };
                convex = convex.max(-outward_min);
            }
        }
    }
    let r = path.cutter.shape.radius();
    // Dexels reach the cutter radius above and below the surface: higher material counts as
    // uncut, deeper gouges are reported as that deep.
    let up = r;
    let depth = r;
    // One dexel on the surface at (u, v), along its outward normal (none where that is
    // undefined); one surface evaluation each.
    let dexel = |node: (usize, usize), u: f64, v: f64| {
        let d = surface.derivs(u, v);
        let n = d.normal()?.into_inner();
        let n = if flip { -n } else { n };
        if min_normal_z.is_some_and(|z| n.z < z) {
            return None;
        }
        Some(Dexel {
            node,
            foot: d.point,
            normal: n,
            uv: (u, v),
            height: up,
        })
    };
    let mut dexels: Vec<Dexel> = Vec::with_capacity(count);
    for (i, &u) in u_nodes.iter().enumerate() {
        for (j, &v) in v_nodes.iter().enumerate() {
            dexels.extend(dexel((i, j), u, v));
        }
    }
    let sweeper = Sweeper {
        solid: CutterSolid::of(&path.cutter),
        radius: r,
        depth,
        bucket: r.max(4.0 * cell),
    };
    sweeper.run(&mut dexels, poses);
    let mut out = Verification {
        dexels: dexels.len(),
        cell_mm: achieved,
        poses: poses.len(),
        uncut: 0,
        max_scallop_mm: 0.0,
        max_scallop_at: None,
        gouge_depth_mm: 0.0,
        gouge_at: None,
        grid_bound_mm: 0.0,
        sweep_bound_mm: 0.0,
        region: options.region,
        region_u: (u0, u1),
        region_v: (v0, v1),
    };
    out.uncut = dexels.iter().filter(|d| d.height >= up).count();
    measure(&dexels, up, &mut out);
    let solid = sweeper.solid;
    let rho = if solid.corner > 0.0 { solid.corner } else { r };
    let edge = if solid.corner > 0.0 {
        0.0
    } else {
        rim_bound(spacing, &cls, r)
    };
    out.sweep_bound_mm = sweep_bound(spacing, rho, out.max_scallop_mm) + edge;
    let rho_flank = 1.0 / (1.0 / rho + convex);
    let coarse = grid_bound(&out, rho_flank, achieved);

    // Refinement: every node that may stand next to the true maximum (its height within the
    // grid bound of the measured one, likewise for the gouge) gets a 9×9 sub-grid over its
    // neighbouring cells. If they all fit under the cap, the true extremes lie within a
    // quarter cell of a sub-node and the bound shrinks fourfold; otherwise the highest ones are
    // refined and the coarse bound stands.
    let mut scallops: Vec<usize> = (0..dexels.len())
        .filter(|&k| dexels[k].height < up && dexels[k].height >= out.max_scallop_mm - coarse)
        .collect();
    let mut gouges: Vec<usize> = (0..dexels.len())
        .filter(|&k| dexels[k].height < 0.0 && -dexels[k].height >= out.gouge_depth_mm - coarse)
        .collect();
    let complete = scallops.len() + gouges.len() <= REFINE_CAP;
    scallops.sort_by(|&a, &b| dexels[b].height.total_cmp(&dexels[a].height));
    gouges.sort_by(|&a, &b| dexels[a].height.total_cmp(&dexels[b].height));
    scallops.truncate(REFINE_CAP / 2);
    gouges.truncate(REFINE_CAP / 2);
    // Sub-nodes on the lattice REFINE times finer than the grid, shared between neighbouring
    // candidates (a ridge of candidates costs a strip, not a box each).
    let f = REFINE as i64;
    let mut lattice = std::collections::HashSet::new();
    let mut fine: Vec<Dexel> = Vec::new();
    for &k in scallops.iter().chain(&gouges) {
        let (i, j) = dexels[k].node;
        for di in -f..=f {
            for dj in -f..=f {
                let (fi, fj) = (f * i as i64 + di, f * j as i64 + dj);
                if fi < 0 || fj < 0 || fi > f * (nu as i64 - 1) || fj > f * (nv as i64 - 1) {
                    continue;
                }
                if !lattice.insert((fi, fj)) {
                    continue;
                }
                let uu = fine_at(&u_nodes, fi, f);
                let vv = fine_at(&v_nodes, fj, f);
                fine.extend(dexel((i, j), uu, vv));
            }
        }
    }
    if !fine.is_empty() {
        sweeper.run(&mut fine, poses);
        measure(&fine, up, &mut out);
    }
    out.sweep_bound_mm = sweep_bound(spacing, rho, out.max_scallop_mm) + edge;
    out.grid_bound_mm = if complete {
        grid_bound(&out, rho_flank, achieved / REFINE as f64)
    } else {
        grid_bound(&out, rho_flank, achieved)
    };
    Ok(out)
}

/// The (u, v) box of the path's contact points, within the domain.
fn contact_box(
    surface: &NurbsSurface,
    cls: &[&crate::toolpath::CutterLocation],
) -> (f64, f64, f64, f64) {
    let (mut u0, mut u1, mut v0, mut v1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for c in cls {
        u0 = u0.min(c.uv.0);
        u1 = u1.max(c.uv.0);
        v0 = v0.min(c.uv.1);
        v1 = v1.max(c.uv.1);
    }
    let (du0, du1) = surface.domain_u();
    let (dv0, dv1) = surface.domain_v();
    (u0.max(du0), u1.min(du1), v0.max(dv0), v1.min(dv1))
}

/// A dexel whose normal's z falls short of the reach limit's cosine by less than this still
/// counts as reachable (the planner's own test allows 10⁻¹² and a contact exactly on the
/// limit must stay judged).
const REACH_SLACK: f64 = 1e-9;

/// Samples per parameter when [`reachable_box`] looks for the reachable part of the domain.
const REACH_SAMPLES: usize = 128;

/// The (u, v) box holding every reachable point (outward normal's z ≥ `min_z`): the sampled
/// reachable nodes' box grown by one sample spacing (the region's edge lies between a
/// reachable node and an unreachable neighbour), within the domain; `None` if no node is
/// reachable. Nodes without a normal (a pole) count as reachable when a neighbour is, so a
/// cap around a pole keeps its pole inside the box.
fn reachable_box(
    surface: &NurbsSurface,
    min_z: f64,
    outward: &impl Fn(f64, f64) -> Option<Vec3>,
) -> Option<(f64, f64, f64, f64)> {
    let (du, dv) = (surface.domain_u(), surface.domain_v());
    let n = REACH_SAMPLES;
    let at = |k: usize, r: (f64, f64)| r.0 + (r.1 - r.0) * k as f64 / n as f64;
    let (mut i0, mut i1, mut j0, mut j1) = (usize::MAX, 0, usize::MAX, 0);
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = (at(i, du), at(j, dv));
            let reach = |z: Option<Vec3>| z.is_some_and(|n| n.z >= min_z);
            let here = outward(u, v);
            let inside = reach(here)
                || (here.is_none()
                    && [
                        (i.saturating_sub(1), j),
                        ((i + 1).min(n), j),
                        (i, j.saturating_sub(1)),
                        (i, (j + 1).min(n)),
                    ]
                    .iter()
                    .any(|&(a, b)| reach(outward(at(a, du), at(b, dv)))));
            if inside {
                (i0, i1, j0, j1) = (i0.min(i), i1.max(i), j0.min(j), j1.max(j));
            }
        }
    }
    if i0 == usize::MAX {
        return None;
    }
    Some((
        at(i0.saturating_sub(1), du),
        at((i1 + 1).min(n), du),
        at(j0.saturating_sub(1), dv),
        at((j1 + 1).min(n), dv),
    ))
}

/// Candidate nodes refined at most (each adds up to (2·REFINE + 1)² sub-dexels, fewer where
/// neighbours share them).
const REFINE_CAP: usize = 4096;

/// The refinement lattice is this many times finer than the grid.
const REFINE: usize = 2;

/// A flat end's section along its motion has a corner at the rim: behind the front rim point
/// the bottom face rises at the tool's lean θ from the surface normal, so between two
/// placements δ apart it leaves up to `δ·tan θ` — θ the largest lean over the cutter
/// locations (capped at the tool radius).
fn rim_bound(spacing: f64, cls: &[&crate::toolpath::CutterLocation], radius: f64) -> f64 {
    let lean = cls
        .iter()
        .map(|c| {
            let cos = c.axis.dot(&c.normal) / (c.axis.norm() * c.normal.norm());
            cos.clamp(-1.0, 1.0).acos()
        })
        .filter(|a| a.is_finite())
        .fold(0.0, f64::max);
    (spacing * lean.tan()).min(radius)
}

/// `δ²/(8(ρ − h))`: the sagitta between two placements δ apart of the cutter's section at
/// the height h of the highest scallop, a circle of radius at least ρ − h (ρ when h ≥ ρ would
/// make it meaningless: then ρ itself, the whole corner, is the bound).
fn sweep_bound(spacing: f64, rho: f64, h: f64) -> f64 {
    if h < rho {
        (spacing * spacing / (8.0 * (rho - h))).min(rho)
    } else {
        rho
    }
}

/// Raises the result's scallop and gouge to what `dexels` show.
fn measure(dexels: &[Dexel], up: f64, out: &mut Verification) {
    for d in dexels {
        if d.height >= up {
            continue;
        }
        if d.height > out.max_scallop_mm {
            out.max_scallop_mm = d.height;
            out.max_scallop_at = Some((d.uv, d.foot));
        } else if -d.height > out.gouge_depth_mm {
            out.gouge_depth_mm = -d.height;
            out.gouge_at = Some((d.uv, d.foot));
        }
    }
}

/// `tan φ · c/√2` with `cos φ = 1 − (h + e)/ρ`, solved for e by a few fixed-point rounds
/// (h the larger of scallop and gouge; the flank's slope grows with the height it reaches).
fn grid_bound(out: &Verification, rho: f64, cell: f64) -> f64 {
    let worst = out.max_scallop_mm.max(out.gouge_depth_mm);
    let mut e = 0.0;
    for _ in 0..3 {
        let c = 1.0 - (worst + e) / rho;
        let slope = if c > 0.0 {
            (1.0 - c * c).sqrt() / c
        } else {
            f64::INFINITY
        };
        e = (slope * cell / std::f64::consts::SQRT_2).min(rho);
    }
    e
}

/// Lowers dexels to where they enter the cutter at each pose.
struct Sweeper {
    solid: CutterSolid,
    radius: f64,
    depth: f64,
    bucket: f64,
}

impl Sweeper {
    fn run(&self, dexels: &mut [Dexel], poses: &[CutterPose]) {
        let grid = Buckets::new(dexels, self.bucket);
        let (r, depth, solid) = (self.radius, self.depth, &self.solid);
        // Dexels reach at most this far from their feet.
        let reach_out = dexels.iter().map(|d| d.height).fold(depth, f64::max);
        for pose in poses {
            let axis = pose.axis;
            // The solid lies within R of its axis segment from the corner's centre to the top.
            let (s0, s1) = (
                pose.tip + axis * solid.corner,
                pose.tip + axis * solid.core_top,
            );
            let grow = r + reach_out;
            let lo = s0.inf(&s1).add_scalar(-grow);
            let hi = s0.sup(&s1).add_scalar(grow);
            grid.visit(&lo, &hi, |k| {
                let d = &mut dexels[k];
                let (a, b) = (d.foot - d.normal * depth, d.foot + d.normal * d.height);
                if segment_distance(&a, &b, &s0, &s1) > r {
                    return;
                }
                if let Some(t) = solid.entry(pose, &d.foot, &d.normal, -depth, d.height) {
                    if t < d.height {
                        d.height = t;
                    }
                }
            });
        }
    }
}

/// Distance between the segments p0–p1 and q0–q1 (Ericson, *Real-Time Collision Detection*,
/// §5.1.9: the closest points by clamped parameters).
fn segment_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> f64 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let (s, t) = if a <= f64::EPSILON && e <= f64::EPSILON {
        (0.0, 0.0)
    } else if a <= f64::EPSILON {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= f64::EPSILON {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p0 + d1 * s) - (q0 + d2 * t)).norm()
}

/// A uniform grid of buckets over the dexel feet, for the poses' neighbourhood queries.
struct Buckets {
    origin: Vec3,
    size: f64,
    dims: [usize; 3],
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Buckets {
    fn new(dexels: &[Dexel], size: f64) -> Self {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for d in dexels {
            lo = lo.inf(&d.foot);
            hi = hi.sup(&d.foot);
        }
        if dexels.is_empty() {
            lo = Vec3::zeros();
            hi = Vec3::zeros();
        }
        // The feet lie on a surface, so most of a 3-D grid is empty: buckets grow until the
        // grid has at most a few cells per dexel (a part far larger than the tool would
        // otherwise ask for billions of cells).
        let limit = 4 * dexels.len() + 4096;
        let mut size = size;
        let mut dims = [1usize; 3];
        for _ in 0..200 {
            dims = [0, 1, 2].map(|i| ((hi[i] - lo[i]) / size).floor().clamp(0.0, 1e6) as usize + 1);
            if dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]) <= limit {
                break;
            }
            size *= 1.5;
        }
        let cells = dims[0] * dims[1] * dims[2];
        let index = |p: &Vec3| -> usize {
            let c = [0, 1, 2]
                .map(|i| (((p[i] - lo[i]) / size).floor().max(0.0) as usize).min(dims[i] - 1));
            (c[0] * dims[1] + c[1]) * dims[2] + c[2]
        };
        let mut count = vec![0u32; cells + 1];
        for d in dexels {
            count[index(&d.foot) + 1] += 1;
        }
        for i in 0..cells {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; dexels.len()];
        for (k, d) in dexels.iter().enumerate() {
            let b = index(&d.foot);
            items[fill[b] as usize] = k as u32;
            fill[b] += 1;
        }
        Buckets {
            origin: lo,
            size,
            dims,
            start: count,
            items,
        }
    }

    fn visit(&self, lo: &Vec3, hi: &Vec3, mut f: impl FnMut(usize)) {
        let range = |i: usize| -> Option<(usize, usize)> {
            let a = ((lo[i] - self.origin[i]) / self.size).floor();
            let b = ((hi[i] - self.origin[i]) / self.size).floor();
            if b < 0.0 || a > (self.dims[i] - 1) as f64 {
                return None;
            }
            Some((a.max(0.0) as usize, (b as usize).min(self.dims[i] - 1)))
        };
        let (Some(x), Some(y), Some(z)) = (range(0), range(1), range(2)) else {
            return;
        };
        for i in x.0..=x.1 {
            for j in y.0..=y.1 {
                let row = (i * self.dims[1] + j) * self.dims[2];
                let (s, e) = (
                    self.start[row + z.0] as usize,
                    self.start[row + z.1 + 1] as usize,
                );
                for &k in &self.items[s..e] {
                    f(k as usize);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dexel(foot: Vec3) -> Dexel {
        Dexel {
            node: (0, 0),
            foot,
            normal: Vec3::z(),
            uv: (0.0, 0.0),
            height: 1.0,
        }
    }

    #[test]
    fn buckets_stay_small_on_a_huge_sparse_part_and_find_their_dexels() {
        // Two feet a kilometre apart with 1 mm buckets: 10¹⁸ cells if the grid did not grow.
        let dexels = [dexel(Vec3::zeros()), dexel(Vec3::new(1e6, 1e6, 1e6))];
        let b = Buckets::new(&dexels, 1.0);
        assert!(b.start.len() <= 4 * 2 + 4096 + 1);
        let mut seen = Vec::new();
        b.visit(&Vec3::repeat(-1.0), &Vec3::repeat(1.0), |k| seen.push(k));
        assert!(seen.contains(&0));
        let mut all = Vec::new();
        b.visit(&Vec3::repeat(-1.0), &Vec3::repeat(2e6), |k| all.push(k));
        all.sort();
        assert_eq!(all, vec![0, 1]);
    }

    #[test]
    fn segment_distance_matches_closed_forms() {
        let o = Vec3::zeros();
        // Skew perpendicular lines 2 apart.
        let d = segment_distance(
            &o,
            &Vec3::x(),
            &Vec3::new(0.5, -1.0, 2.0),
            &Vec3::new(0.5, 1.0, 2.0),
        );
        assert!((d - 2.0).abs() < 1e-12);
        // Parallel, overlapping.
        let d = segment_distance(
            &o,
            &Vec3::x(),
            &Vec3::new(0.5, 3.0, 0.0),
            &Vec3::new(2.0, 3.0, 0.0),
        );
        assert!((d - 3.0).abs() < 1e-12);
        // End to end, and a point.
        let d = segment_distance(
            &o,
            &Vec3::x(),
            &Vec3::new(4.0, 4.0, 0.0),
            &Vec3::new(5.0, 4.0, 0.0),
        );
        assert!((d - 5.0).abs() < 1e-12);
        let p = Vec3::new(0.5, 0.0, 1.0);
        assert!((segment_distance(&o, &Vec3::x(), &p, &p) - 1.0).abs() < 1e-12);
    }
}
