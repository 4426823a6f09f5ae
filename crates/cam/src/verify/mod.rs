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
//! Error bounds (both one-sided, and stated, so a report can be trusted):
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
mod sweep;

use tezgah_geom::{NurbsSurface, Vec3};

pub use solid::{CutterPose, CutterSolid};

use rayon::prelude::*;

use crate::arc_grid::{arc_nodes, spread};
use crate::region::FaceRegion;
use crate::toolpath::ToolPath;
use sweep::Sweeper;

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
    /// How deep below its foot it reaches into the material: the simulation's depth, less
    /// where another face of the part bounds the material sooner along it.
    floor: f64,
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
    simulate_on(surface, path, poses, options, None)
}

/// [`simulate`] on a trimmed face: only the surface inside `face` (its (u, v) region) is
/// judged, within `options.region`. Outside the face the surface is not part of the part, so
/// the cutter reaching past the trim (by up to its radius, as it must to cut up to the trim)
/// is neither a gouge nor anything else there; on the face itself both checks hold as on a
/// whole surface.
pub fn simulate_on(
    surface: &NurbsSurface,
    path: &ToolPath,
    poses: &[CutterPose],
    options: &VerifyOptions,
    face: Option<&FaceRegion>,
) -> Result<Verification, VerifyError> {
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
    let uv_box = match face {
        None => (u0, u1, v0, v1),
        Some(f) => f
            .clip_box((u0, u1), (v0, v1))
            .map(|((u0, u1), (v0, v1))| (u0, u1, v0, v1))
            .ok_or(VerifyError::EmptyRegion(options.region))?,
    };
    let judging = Judging {
        face,
        flip,
        min_normal_z,
        uv_box,
        bounded_by: None,
    };
    simulate_over(surface, path, poses, options, &judging)
}

/// The same cut simulated over another face of the part (`neighbour`) where the tool comes
/// near it, its dexels ending where the `machined` face bounds the material: the
/// part of its domain whose points lie within the tool's reach of a pose (a lattice of
/// [`REACH_SAMPLES`]² nodes, its box grown by one node). Only the gouge counts there (the
/// program does not machine that face; what it leaves on it is no fault). `None` when the
/// tool never comes near the face.
pub fn simulate_neighbour(
    neighbour: Bounding,
    machined: Bounded,
    path: &ToolPath,
    poses: &[CutterPose],
    options: &VerifyOptions,
) -> Result<Option<Verification>, VerifyError> {
    let Bounding {
        surface,
        outward_is_su_x_sv,
        face,
    } = neighbour;
    let r = path.cutter.shape.radius();
    let height = crate::gouge::rear::checked_height(&path.cutter);
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in poses {
        for q in [p.tip, p.tip + p.axis * height] {
            lo = lo.inf(&q);
            hi = hi.sup(&q);
        }
    }
    let (du, dv) = (surface.domain_u(), surface.domain_v());
    let n = REACH_SAMPLES;
    let at = |(a, b): (f64, f64), k: usize| a + (b - a) * k as f64 / n as f64;
    let mut uv_box = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = (at(du, i), at(dv, j));
            let d = surface.derivs(u, v);
            // A node stands for the surface within a node's spacing of it.
            let reach =
                r + d.su.norm() * (du.1 - du.0) / n as f64 + d.sv.norm() * (dv.1 - dv.0) / n as f64;
            let p = d.point;
            if (0..3).all(|k| p[k] >= lo[k] - reach && p[k] <= hi[k] + reach) {
                uv_box = (
                    uv_box.0.min(at(du, i.saturating_sub(1))),
                    uv_box.1.max(at(du, (i + 1).min(n))),
                    uv_box.2.min(at(dv, j.saturating_sub(1))),
                    uv_box.3.max(at(dv, (j + 1).min(n))),
                );
            }
        }
    }
    if !(uv_box.0 < uv_box.1 && uv_box.2 < uv_box.3) {
        return Ok(None);
    }
    if let Some(f) = face {
        match f.clip_box((uv_box.0, uv_box.1), (uv_box.2, uv_box.3)) {
            Some(((u0, u1), (v0, v1))) => uv_box = (u0, u1, v0, v1),
            None => return Ok(None),
        }
    }
    let judging = Judging {
        face,
        flip: !outward_is_su_x_sv,
        min_normal_z: None,
        uv_box,
        bounded_by: Some(machined),
    };
    simulate_over(surface, path, poses, options, &judging).map(Some)
}

/// How a surface is judged: its trim, whether its outward normal is `−S_u × S_v`, the reach
/// limit on the normal's z (none: every normal), and the (u, v) box its dexels stand in.
struct Judging<'a> {
    face: Option<&'a FaceRegion>,
    flip: bool,
    min_normal_z: Option<f64>,
    uv_box: (f64, f64, f64, f64),
    /// Another face that bounds the material below this one (the machined face, beside one
    /// of its neighbours).
    bounded_by: Option<Bounded<'a>>,
}

/// A face of the part: its surface, which side is its outside, and its trim.
#[derive(Debug, Clone, Copy)]
pub struct Bounding<'a> {
    pub surface: &'a NurbsSurface,
    pub outward_is_su_x_sv: bool,
    pub face: Option<&'a FaceRegion>,
}

/// The machined face as the bound of a neighbour's material, and how close to it the tool's
/// cut counts as the face's own (it is cut to within a tolerance, so a neighbour's dexel ends
/// that far inside it).
#[derive(Debug, Clone, Copy)]
pub struct Bounded<'a> {
    pub by: Bounding<'a>,
    pub margin: f64,
}

impl Bounded<'_> {
    /// How far (≤ `depth`) the material runs from `foot` along `−n` before it comes within
    /// the margin of the face: marched in steps and bisected, each point judged by its
    /// height over the face at the face's nearest point (that point and its normal move as the
    /// face curves — the blade's edge curves by 1/1.2 mm — so no single tangent plane serves).
    /// Farther than `depth` from the face, or off its trim, the face does not bound the dexel.
    /// Without the bound a neighbour's dexels near a convex edge run on past the machined face
    /// into the air where the tool cuts it, and read that as a gouge (3 mm on the blade's
    /// bottom cap beside #17); without the margin the ball touching the face where the line
    /// leaves the part read the same.
    fn material_along(&self, foot: &Vec3, n: &Vec3, depth: f64) -> f64 {
        let Bounded { by, margin } = *self;
        // The line's signed height over the face (outward positive) at `t`, from the face
        // point nearest it; `None` off the face or beyond reach.
        let height_at = |t: f64| -> Option<f64> {
            let q = foot - n * t;
            let c = by.surface.closest_point(&q, 1e-7).ok()?;
            if c.distance > depth || by.face.is_some_and(|f| !f.contains(c.u, c.v)) {
                return None;
            }
            let m = by.surface.normal(c.u, c.v)?.into_inner();
            let m = if by.outward_is_su_x_sv { m } else { -m };
            Some((q - c.point).dot(&m))
        };
        // A face farther from the foot than the dexel is long (and the margin) cannot bound it:
        // one nearest point settles most dexels.
        match by.surface.closest_point(foot, 1e-7) {
            Ok(c) if c.distance <= depth + margin => {}
            _ => return depth,
        }
        let outside = |t: f64| height_at(t).is_some_and(|h| h >= -margin);
        let step = depth / MATERIAL_MARCH as f64;
        let Some(k) = (1..=MATERIAL_MARCH).find(|&k| outside(k as f64 * step)) else {
            return depth;
        };
        let (mut lo, mut hi) = ((k - 1) as f64 * step, k as f64 * step);
        for _ in 0..MATERIAL_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if outside(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }
}

/// Steps of [`Bounded::material_along`]'s march along the dexel.
const MATERIAL_MARCH: usize = 6;
/// Its bisections (the bracket shrinks to depth/6/2⁸, 2 µm for a D6).
const MATERIAL_BISECTIONS: usize = 8;

/// The simulation proper over `judging`'s box of `surface`.
fn simulate_over(
    surface: &NurbsSurface,
    path: &ToolPath,
    poses: &[CutterPose],
    options: &VerifyOptions,
    judging: &Judging,
) -> Result<Verification, VerifyError> {
    let cell = positive("the cell size", options.cell_mm)?;
    let spacing = positive("the sweep spacing", options.sweep_spacing_mm)?;
    let cls: Vec<_> = path.passes.iter().flat_map(|p| &p.points).collect();
    let Judging {
        face,
        flip,
        min_normal_z,
        uv_box: (u0, u1, v0, v1),
        ..
    } = *judging;
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
    // Where another face bounds the material along a dexel, the dexel ends there.
    let floor_at = |foot: &Vec3, n: &Vec3| {
        judging
            .bounded_by
            .as_ref()
            .map_or(depth, |b| b.material_along(foot, n, depth))
    };
    // One dexel on the surface at (u, v), along its outward normal (none where that is
    // undefined); one surface evaluation each.
    let dexel = |node: (usize, usize), u: f64, v: f64| {
        if face.is_some_and(|f| !f.contains(u, v)) {
            return None;
        }
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
            floor: floor_at(&d.point, &n),
        })
    };
    let dexels: Vec<Vec<Dexel>> = u_nodes
        .par_iter()
        .enumerate()
        .map(|(i, &u)| {
            v_nodes
                .iter()
                .enumerate()
                .filter_map(|(j, &v)| dexel((i, j), u, v))
                .collect()
        })
        .collect();
    let mut dexels: Vec<Dexel> = dexels.into_iter().flatten().collect();
    let sweeper = Sweeper {
        solid: CutterSolid::of(&path.cutter),
        radius: r,
        tile: TILE_CELLS * cell,
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
    // A neighbouring face is judged for gouges only: what the program leaves on a face it
    // does not machine is no scallop, and must not widen the gouge's bounds.
    let gouge_only = judging.bounded_by.is_some();
    if gouge_only {
        (out.uncut, out.max_scallop_mm, out.max_scallop_at) = (0, 0.0, None);
    }
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
    let mut scallops: Vec<usize> = if gouge_only {
        Vec::new()
    } else {
        (0..dexels.len())
            .filter(|&k| dexels[k].height < up && dexels[k].height >= out.max_scallop_mm - coarse)
            .collect()
    };
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
        if gouge_only {
            (out.max_scallop_mm, out.max_scallop_at) = (0.0, None);
        }
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

/// Edge of the simulation's tiles, in cells (a tile's dexels share their candidate poses).
const TILE_CELLS: f64 = 16.0;

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
