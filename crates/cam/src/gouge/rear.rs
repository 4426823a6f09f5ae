//! Rear gouge: the whole cutting end against the surface. Can (2010, §3.4.7.2.2) scans the shadow
//! of a flat tool's bottom behind the contact (Lo 1999, extended to the full bottom); here the
//! surface near the tool is tested against the solid of revolution of the cutting end — the
//! flat, torus or ball bottom and the flutes up to two tool radii — so the heel, the middle
//! of the bottom and the sides are all covered, for every cutter shape.
//!
//! Exact to the tolerance, not to the sample spacing: the cutting end is a convex solid (a
//! core cylinder grown by the corner radius, Can's torus as a Minkowski sum), so the
//! signed depth of a point in it is concave and its gradient bounds it everywhere:
//! `e(x) ≤ e(p) + g·(x − p)` (a supergradient inequality). Over the surface near a sample
//! `p` (its lattice cell, at most `c` away, bending off its tangent plane by at most `κc²/2`)
//! that gives `e ≤ e(p) + |g_t|·c + |g_n|·κc²/2`; a cell whose bound exceeds the tolerance
//! is split in four and its quarters evaluated on the surface itself (branch and bound, down
//! to cells of [`FINEST_COVER`] of the tolerance). The closest point of the torus is closed
//! form (the point's axial plane, then the corner circle: Lee & Chang 1995; Can, 2010, §3.4.7.2.2).
//! Session 5's scan of the samples alone missed heel contacts of 4–5 µm between its 0.3 mm
//! samples: the torus's tube curves by 1/r, the flat's rim is a corner.
//!
//! A trimmed face is only the part of its surface inside its loops ([`FaceRegion`]): cells
//! outside are skipped, cells across the trim are split like the others, and a point of one
//! outside the face counts only when even the nearest point of the cell could be that deep.

use nalgebra::Unit;
use tezgah_geom::{NurbsSurface, Vec3};

use super::index::{PointGrid, Reach, SurfaceSamples};
use super::sweep::Sweep;
use crate::cutter::CutterShape;
use crate::region::{FaceRegion, RectSide};

/// Height of the checked cutting end above the tip, in tool radii, at least: the flutes and a
/// shank of the tool's radius above it are checked with it when the cutter has them
/// ([`checked_height`]).
pub const CUTTING_END_RADII: f64 = 2.0;

/// How high above the tip the rear check's solid reaches for `cutter`: the cutting end's two
/// radii, the flutes (the same radius) and a shank of that radius standing on them — one
/// convex solid of revolution, checked to the tolerance; a narrower or wider shank and the
/// holder are the global check's.
pub fn checked_height(cutter: &crate::cutter::Cutter) -> f64 {
    let big_r = cutter.shape.radius();
    let mut height = (CUTTING_END_RADII * big_r).max(cutter.flute_length);
    let shank = cutter.shank;
    if shank.length > 0.0 && (shank.radius - big_r).abs() <= 1e-9 && shank.from <= height {
        height = height.max(shank.from + shank.length);
    }
    height
}

/// Cells are split until their cover falls to this fraction of the tolerance: what the bound
/// then leaves unproven is below it (`|g_t| ≤ 1`), so the check holds to `1.25 × tolerance`.
pub const FINEST_COVER: f64 = 1.0;

/// Splits of a cell at most (a cell of 0.3 mm reaches 0.07 µm after 12).
const MAX_LEVELS: usize = 12;

/// The signed depth of a point in the cutting end and a unit supergradient of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Depth {
    /// Distance to the cutting end's surface, mm: positive inside, negative outside.
    pub depth: f64,
    /// Where the depth grows fastest: `depth(x) ≤ depth + gradient·(x − p)` for every `x`.
    pub gradient: Vec3,
}

/// The depth of `p` in the cutting end standing at `tip` along `axis`: the core cylinder
/// (radius `R − r`, from `r` above the tip up to the top at two radii) grown by the corner
/// radius `r`, so `r − sd_core(p)` with the core's signed distance in tool coordinates (axial
/// `z`, radial `ρ`); the top face cuts it (the flutes above are the global check's) by the
/// smaller of that and the height below the top: exact up to the top, an upper bound (still
/// concave) above it. Flat:
/// `min(z, R − ρ)` inside; torus: `r − |(ρ, z) − (R − r, r)|`; ball: `R − |p − centre|`.
pub fn depth(shape: &CutterShape, tip: &Vec3, axis: &Unit<Vec3>, p: &Vec3) -> Depth {
    depth_to(shape, CUTTING_END_RADII * shape.radius(), tip, axis, p)
}

/// [`depth`] in the solid cut off at `height` above the tip instead of two radii.
pub fn depth_to(
    shape: &CutterShape,
    height: f64,
    tip: &Vec3,
    axis: &Unit<Vec3>,
    p: &Vec3,
) -> Depth {
    let (big_r, r) = (shape.radius(), shape.corner_radius());
    let a = axis.into_inner();
    let d = p - tip;
    let z = d.dot(&a);
    let w = d - a * z;
    let rho = w.norm();
    let radial = if rho > 0.0 {
        w / rho
    } else {
        // On the axis every radial direction serves; one perpendicular to it.
        let seed = if a.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        (seed - a * seed.dot(&a)).normalize()
    };
    let (dr, dz) = (rho - (big_r - r), r - z);
    let (sd, grad_sd) = if dr <= 0.0 && dz <= 0.0 {
        if dr >= dz {
            (dr, radial)
        } else {
            (dz, -a)
        }
    } else {
        let (er, ez) = (dr.max(0.0), dz.max(0.0));
        // Millimetre lengths: no overflow for `hypot` to guard against, and its care cost the
        // iso-scallop bench 16 %.
        let dist = (er * er + ez * ez).sqrt();
        (dist, (radial * er - a * ez) / dist)
    };
    let (depth, gradient) = (r - sd, -grad_sd);
    let top = height - z;
    if top < depth {
        Depth {
            depth: top,
            gradient: -a,
        }
    } else {
        Depth { depth, gradient }
    }
}

/// How deep `p` lies inside the cutting end (mm; ≤ 0 outside): [`depth`]'s value.
pub fn penetration(shape: &CutterShape, tip: &Vec3, axis: &Unit<Vec3>, p: &Vec3) -> f64 {
    depth(shape, tip, axis, p).depth
}

/// The largest depth any surface point of a cell can have over a span of the sweep: the
/// cell reaches `reach` from its point `p` (depth `d` at the span's middle, height `z` above
/// the tip plane there, normal `n`, zero if unknown) along the tangent plane and bends off it
/// by at most `κc²/2` (`c` its cover, `kappa` bounding the surface's normal curvature); over
/// the span the cutter moves relative to it by at most `spread` along each direction
/// (`spread(g)`, [`Sweep::spread`]). Two concave upper bounds, the smaller kept: the depth's
/// own supergradient, and the tip plane's (the cutting end lies above it, so its depth is at
/// most the height above it, with gradient the axis): beside and below the tool that one is
/// far tighter.
pub fn bound(
    d: &Depth,
    z: f64,
    axis: &Vec3,
    n: &Vec3,
    reach: &Reach,
    kappa: f64,
    spread: impl Fn(&Vec3) -> f64,
) -> Bounds {
    let c = reach.cover();
    let sag = 0.5 * kappa * c * c;
    // Without a normal the bend is not known: the whole cover, every way.
    if n.norm_squared() == 0.0 {
        let all = Bound::of(d.depth, c, spread(&Vec3::zeros()));
        return Bounds {
            own: all,
            plane: all,
        };
    }
    let own = Bound::of(
        d.depth,
        reach.along(&d.gradient) + d.gradient.dot(n).abs() * sag,
        spread(&d.gradient),
    );
    let plane = Bound::of(z, reach.along(axis) + axis.dot(n).abs() * sag, spread(axis));
    Bounds { own, plane }
}

/// The two upper bounds of the depth over a cell and a span of the sweep ([`bound`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub own: Bound,
    pub plane: Bound,
}

impl Bounds {
    /// The tighter of the two, mm.
    pub fn value(&self) -> f64 {
        self.own.value().min(self.plane.value())
    }

    /// Whether halving the span serves better than quartering the cell. The bound nearer to
    /// proving the pair clear is followed, the one whose extent and motion use the smaller
    /// share of its room (`tolerance` less its value at the point), and its larger part is
    /// split. A bound whose point lies beyond the tolerance cannot prove the pair clear at
    /// this pose however fine the cell: led by the tip plane's (a point 0.55 µm above it for
    /// a tolerance of 0.5 µm) a ball sliding along a trough split cells ten levels deep,
    /// 4¹⁰ of them per sample, where two halvings of the span cleared the pair.
    pub fn split_span(&self, tolerance: f64) -> bool {
        let share = |b: &Bound| (b.extent + b.motion) / (tolerance - b.at_point).max(0.0);
        let lead = if share(&self.plane) < share(&self.own) {
            &self.plane
        } else {
            &self.own
        };
        lead.motion > lead.extent
    }
}

/// An upper bound of the depth over a cell and a span of the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// Its value at the cell's point and the span's middle, mm.
    pub at_point: f64,
    /// What the cell's extent adds to the value at its point.
    pub extent: f64,
    /// What the cutter's motion over the span adds.
    pub motion: f64,
}

impl Bound {
    fn of(at_point: f64, extent: f64, motion: f64) -> Bound {
        Bound {
            at_point,
            extent,
            motion,
        }
    }

    /// The bound, mm.
    pub fn value(&self) -> f64 {
        self.at_point + self.extent + self.motion
    }
}

/// A surface point inside the cutting end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// How deep, mm.
    pub depth: f64,
    pub point: Vec3,
    /// Where along the sweep, `s ∈ [0, 1]` (a standing cutter: 0.5).
    pub at: f64,
}

/// The surface indexed for the rear check: lattice samples in a spatial grid, the surface
/// itself for the cells that need a closer look, and a bound of its normal curvature.
#[derive(Debug, Clone)]
pub struct RearIndex {
    surface: NurbsSurface,
    /// The face's region on the surface (`None`: the whole surface) and where each lattice
    /// cell lies against it, by node (`u` index × `v` count + `v` index), classified once.
    region: Option<(FaceRegion, Vec<RectSide>)>,
    /// The lattice's parameter lines (its samples live in `grid`).
    lines: SurfaceSamples,
    grid: PointGrid,
    /// Largest normal curvature, 1/mm (sampled, with [`CURVATURE_MARGIN`]).
    kappa: f64,
}

/// Parameter lines per direction on which the curvature bound is sampled.
const CURVATURE_SAMPLES: usize = 65;
/// Factor on the sampled curvature for what lies between the samples.
const CURVATURE_MARGIN: f64 = 1.5;

impl RearIndex {
    pub fn new(surface: &NurbsSurface, samples: SurfaceSamples, bucket: f64) -> RearIndex {
        RearIndex::within(surface, None, samples, bucket)
    }

    /// The index of the face on `surface` inside `region` (the whole surface for `None`):
    /// samples whose cell lies wholly outside it are left out.
    pub fn within(
        surface: &NurbsSurface,
        region: Option<&FaceRegion>,
        mut samples: SurfaceSamples,
        bucket: f64,
    ) -> RearIndex {
        let region = region.map(|r| {
            let nv = samples.v.len();
            let mut sides = vec![RectSide::Outside; samples.u.len() * nv];
            for s in &samples.samples {
                sides[s.node[0] as usize * nv + s.node[1] as usize] =
                    r.classify(samples.cell(s.node));
            }
            samples.samples.retain(|s| {
                sides[s.node[0] as usize * nv + s.node[1] as usize] != RectSide::Outside
            });
            (r.clone(), sides)
        });
        let (du, dv) = (surface.domain_u(), surface.domain_v());
        let at = |(lo, hi): (f64, f64), k: usize| {
            lo + (hi - lo) * k as f64 / (CURVATURE_SAMPLES - 1) as f64
        };
        let mut kappa = 0.0_f64;
        for i in 0..CURVATURE_SAMPLES {
            for j in 0..CURVATURE_SAMPLES {
                if let Some(k) = surface.principal_curvatures(at(du, i), at(dv, j)) {
                    kappa = kappa.max(k.k1.abs()).max(k.k2.abs());
                }
            }
        }
        RearIndex {
            surface: surface.clone(),
            region,
            kappa: kappa * CURVATURE_MARGIN,
            grid: PointGrid::new(std::mem::take(&mut samples.samples), bucket),
            lines: samples,
        }
    }

    pub fn len(&self) -> usize {
        self.grid.len()
    }

    pub fn is_empty(&self) -> bool {
        self.grid.is_empty()
    }

    /// A surface point more than `tolerance` inside the cutting end at `tip` along `axis`, if
    /// there is one (module comment; the search stops at the first found: a gouge is a gouge).
    pub fn first_penetration(
        &self,
        shape: &CutterShape,
        tip: &Vec3,
        axis: &Unit<Vec3>,
        tolerance: f64,
    ) -> Option<Penetration> {
        self.first_penetration_along(shape, &Sweep::still(tip, axis), tolerance)
    }

    /// A surface point more than `tolerance` inside the cutting end at some pose of `sweep`,
    /// if there is one. The branch and bound runs over cells and spans of the sweep at once:
    /// a (cell, span) pair whose bound ([`bound`]) exceeds the tolerance is split where its
    /// bound comes from, the span in halves when the motion dominates, the cell in quarters
    /// otherwise. A standing cutter has no motion and splits cells only.
    pub fn first_penetration_along(
        &self,
        shape: &CutterShape,
        sweep: &Sweep,
        tolerance: f64,
    ) -> Option<Penetration> {
        self.first_penetration_within(shape, CUTTING_END_RADII * shape.radius(), sweep, tolerance)
    }

    /// [`RearIndex::first_penetration_along`] for the solid reaching `height` above the tip
    /// ([`checked_height`]).
    pub fn first_penetration_within(
        &self,
        shape: &CutterShape,
        height: f64,
        sweep: &Sweep,
        tolerance: f64,
    ) -> Option<Penetration> {
        let big_r = shape.radius();
        let search = Search {
            index: self,
            shape,
            height,
            sweep,
            tolerance,
        };
        let whole = Span::new(sweep, 0.0, 1.0, 0);
        let mut hit = None;
        // The solid in pieces of two radii up the axis, each with its own box: a tall solid
        // on a leaning axis has a box far wider than the samples it can reach.
        let piece = CUTTING_END_RADII * big_r;
        let mut z0 = 0.0;
        while z0 < height && hit.is_none() {
            let z1 = (z0 + piece).min(height);
            let (lo, hi) = sweep.bounding_box_between(z0, z1, big_r);
            self.grid.visit_box(&lo, &hi, |s| {
                let (i, j) = (s.node[0] as usize, s.node[1] as usize);
                let (uv, side) = match &self.region {
                    None => (None, RectSide::Inside),
                    Some((_, sides)) => (
                        Some((self.lines.u[i], self.lines.v[j])),
                        sides[i * self.lines.v.len() + j],
                    ),
                };
                let patch = Patch {
                    point: s.point,
                    normal: s.normal,
                    reach: s.reach,
                    cell: None,
                    level: 0,
                    uv,
                    side,
                };
                hit = search.examine(&patch, s.node, &whole);
                hit.is_none()
            });
            z0 = z1;
        }
        hit
    }
}

/// Spans of the sweep are halved at most this often (2¹⁶ spans: 0.05 µm of a 3 mm chord).
const MAX_SPAN_LEVELS: usize = 16;

/// A piece of surface under test: a point of it, its normal (zero if unknown), how far the
/// piece reaches from the point, and its parameter cell once known (a lattice sample's cell
/// is looked up only when it must be split).
#[derive(Debug, Clone, Copy)]
struct Patch {
    point: Vec3,
    normal: Vec3,
    reach: Reach,
    cell: Option<[f64; 4]>,
    level: usize,
    /// The point's parameters (needed only on a trimmed face).
    uv: Option<(f64, f64)>,
    /// Where the cell lies against the face's region (`Inside` on an untrimmed face).
    side: RectSide,
}

/// A span `[s0, s1]` of the sweep and the cutter's pose at its middle (computed once, for
/// every cell examined over the span).
#[derive(Debug, Clone, Copy)]
struct Span {
    s0: f64,
    s1: f64,
    level: usize,
    tip: Vec3,
    axis: Unit<Vec3>,
}

impl Span {
    fn new(sweep: &Sweep, s0: f64, s1: f64, level: usize) -> Span {
        let (tip, axis) = sweep.pose(0.5 * (s0 + s1));
        Span {
            s0,
            s1,
            level,
            tip,
            axis,
        }
    }

    fn middle(&self) -> f64 {
        0.5 * (self.s0 + self.s1)
    }

    /// Its halves.
    fn halves(&self, sweep: &Sweep) -> [Span; 2] {
        let sm = self.middle();
        [
            Span::new(sweep, self.s0, sm, self.level + 1),
            Span::new(sweep, sm, self.s1, self.level + 1),
        ]
    }
}

/// One rear check under way: the index, the cutter and its motion.
struct Search<'a> {
    index: &'a RearIndex,
    shape: &'a CutterShape,
    /// Top of the checked solid above the tip.
    height: f64,
    sweep: &'a Sweep,
    tolerance: f64,
}

impl Search<'_> {
    /// Branch and bound over `patch` (lattice node `node`) and `span`.
    fn examine(&self, patch: &Patch, node: [u32; 2], span: &Span) -> Option<Penetration> {
        if patch.side == RectSide::Outside {
            return None;
        }
        let (tip, axis, h) = (span.tip, span.axis, 0.5 * (span.s1 - span.s0));
        let d = depth_to(self.shape, self.height, &tip, &axis, &patch.point);
        let cover = patch.reach.cover();
        // A point outside the face, in a cell across its trim: the face's part of the cell
        // lies within the cover of it, and the depth changes by at most the distance.
        let outside = match (patch.side, &self.index.region, patch.uv) {
            (RectSide::Across, Some((r, _)), Some((u, v))) => !r.contains(u, v),
            _ => false,
        };
        let counted = if outside { d.depth - cover } else { d.depth };
        if counted > self.tolerance {
            return Some(Penetration {
                depth: d.depth,
                point: patch.point,
                at: span.middle(),
            });
        }
        let z = (patch.point - tip).dot(&axis);
        // How far a point of the cell can lie from its sample: the cover, and the bend.
        let near = cover * (1.0 + 0.5 * self.index.kappa * cover);
        let spread = |g: &Vec3| {
            if g.norm_squared() == 0.0 {
                self.sweep.spread_any(&patch.point, &tip, near, h)
            } else {
                self.sweep.spread(g, &patch.point, &tip, near, h)
            }
        };
        let b = bound(
            &d,
            z,
            &axis,
            &patch.normal,
            &patch.reach,
            self.index.kappa,
            spread,
        );
        if b.value() <= self.tolerance {
            return None;
        }
        let cell_can_split = patch.level < MAX_LEVELS && cover > FINEST_COVER * self.tolerance;
        let span_can_split = span.level < MAX_SPAN_LEVELS && b.own.motion.max(b.plane.motion) > 0.0;
        if span_can_split && (b.split_span(self.tolerance) || !cell_can_split) {
            let [first, second] = span.halves(self.sweep);
            return self
                .examine(patch, node, &first)
                .or_else(|| self.examine(patch, node, &second));
        }
        if !cell_can_split {
            return None;
        }
        let [u0, u1, v0, v1] = patch.cell.unwrap_or_else(|| self.index.lines.cell(node));
        let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        for quarter in [
            [u0, um, v0, vm],
            [um, u1, v0, vm],
            [u0, um, vm, v1],
            [um, u1, vm, v1],
        ] {
            let (hu, hv) = (
                0.5 * (quarter[1] - quarter[0]),
                0.5 * (quarter[3] - quarter[2]),
            );
            let e = self.index.surface.derivs(quarter[0] + hu, quarter[2] + hv);
            let side = match (&self.index.region, patch.side) {
                (Some((r, _)), RectSide::Across) => r.classify(quarter),
                (_, side) => side,
            };
            let part = Patch {
                point: e.point,
                normal: e.normal().map_or(Vec3::zeros(), |n| n.into_inner()),
                reach: Reach::of(&e, hu, hv),
                cell: Some(quarter),
                level: patch.level + 1,
                uv: Some((quarter[0] + hu, quarter[2] + hv)),
                side,
            };
            if let Some(p) = self.examine(&part, node, span) {
                return Some(p);
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gouge::index::sample_surface;
    use proptest::prelude::*;

    /// The signed distance from `(rho, z)` to the cutting end's meridian section, by brute
    /// force over its boundary sampled every 10⁻⁴ mm (inside: positive).
    fn brute_depth(shape: &CutterShape, rho: f64, z: f64) -> f64 {
        let (big_r, r) = (shape.radius(), shape.corner_radius());
        let (r0, top) = (big_r - r, CUTTING_END_RADII * big_r);
        let mut boundary = Vec::new();
        let n = 40_000;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            boundary.push((r0 * t, 0.0)); // flat bottom
            let a = -std::f64::consts::FRAC_PI_2 * (1.0 - t); // corner arc, bottom to side
            boundary.push((r0 + r * a.cos(), r + r * a.sin()));
            boundary.push((big_r, r + (top - r) * t)); // side
            boundary.push((big_r * t, top)); // top
        }
        let dist = boundary
            .iter()
            .map(|&(x, y)| (rho - x).hypot(z - y))
            .fold(f64::INFINITY, f64::min);
        let bottom = if rho <= r0 {
            0.0
        } else if rho <= big_r {
            r - (r * r - (rho - r0) * (rho - r0)).sqrt()
        } else {
            f64::INFINITY
        };
        if z > bottom && z < top {
            dist
        } else {
            -dist
        }
    }

    #[test]
    fn the_checked_solid_reaches_up_the_flutes_and_a_shank_of_the_same_radius() {
        // Standard D6: flutes to 18 mm, shank r 3 from 18 to 30 — one cylinder to 30 mm.
        let ball = crate::cutter::Cutter::standard(CutterShape::Ball { radius: 3.0 });
        assert_eq!(checked_height(&ball), 30.0);
        // A wall beside the tool 20 mm up: inside the checked solid by 0.5 mm at the shank.
        let (tip, z) = (Vec3::zeros(), Unit::new_unchecked(Vec3::z()));
        let p = Vec3::new(2.5, 0.0, 20.0);
        assert!((depth_to(&ball.shape, 30.0, &tip, &z, &p).depth - 0.5).abs() < 1e-12);
        assert!(depth(&ball.shape, &tip, &z, &p).depth < 0.0);
        // A thinner shank stays the global check's: the solid ends with the flutes.
        let mut thin = ball;
        thin.shank.radius = 2.0;
        assert_eq!(checked_height(&thin), 18.0);
        // Stubby flutes below two radii: the cutting end's height.
        let mut stub = thin;
        stub.flute_length = 4.0;
        assert_eq!(checked_height(&stub), 6.0);
    }

    fn shapes() -> [CutterShape; 3] {
        [
            CutterShape::Flat { radius: 3.0 },
            CutterShape::BullNose {
                radius: 4.0,
                corner_radius: 1.0,
            },
            CutterShape::Ball { radius: 2.5 },
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The closed form is the signed distance to the section, and a concave function's
        /// supergradient: `depth(x) ≤ depth(p) + g·(x − p)` (what the bound stands on).
        #[test]
        fn depth_is_the_signed_distance_and_concave(
            which in 0usize..3,
            p in prop::array::uniform3(-6.0f64..6.0),
            q in prop::array::uniform3(-6.0f64..6.0),
            lean in 0.0f64..0.6,
        ) {
            let shape = shapes()[which];
            let tip = Vec3::new(0.3, -0.2, 1.0);
            let axis = Unit::new_normalize(Vec3::new(lean.sin(), 0.2 * lean, lean.cos()));
            let (p, q) = (Vec3::from(p) + Vec3::z() * 2.0, Vec3::from(q) + Vec3::z() * 2.0);
            let d = depth(&shape, &tip, &axis, &p);
            let rel = p - tip;
            let z = rel.dot(&axis);
            let rho = (rel - axis.into_inner() * z).norm();
            let want = brute_depth(&shape, rho, z);
            if z <= CUTTING_END_RADII * shape.radius() {
                prop_assert!((d.depth - want).abs() < 2e-4,
                    "{shape:?} at ρ {rho} z {z}: {} vs {want}", d.depth);
            } else {
                // Above the top face: an upper bound (the safe side).
                prop_assert!(d.depth >= want - 2e-4, "{shape:?} at ρ {rho} z {z}");
            }
            prop_assert!((d.gradient.norm() - 1.0).abs() < 1e-9);
            let e_q = depth(&shape, &tip, &axis, &q).depth;
            prop_assert!(e_q <= d.depth + d.gradient.dot(&(q - p)) + 1e-9);
        }
    }

    /// A flat D6 at 5° lead whose heel dips `dip` below the plane `z = 0` at `heel`, its heel
    /// pointing along −x (the crescent the dip cuts is 0.034 mm across for 3 µm).
    fn heel_pose(heel: Vec3, dip: f64) -> (Vec3, Unit<Vec3>) {
        let lead = 5f64.to_radians();
        let axis = Unit::new_normalize(Vec3::new(-lead.sin(), 0.0, lead.cos()));
        // The lowest rim point lies R along e1 = (−cos λ, 0, −sin λ) from the tip.
        let e1 = Vec3::new(-lead.cos(), 0.0, -lead.sin());
        (heel - Vec3::z() * dip - e1 * 3.0, axis)
    }

    #[test]
    fn a_heel_dipping_between_the_samples_is_found() {
        let surface = crate::testing::plane(20.0);
        let samples = sample_surface(&surface, 0.3).unwrap();
        // The heel half-way between two lattice columns: no sample lies in the crescent.
        let (i, j) = (30, 33);
        let x = 10.0 * (samples.u[i] + samples.u[i + 1]);
        let y = 20.0 * samples.v[j];
        let scan: Vec<Vec3> = samples.samples.iter().map(|s| s.point).collect();
        let index = RearIndex::new(&surface, samples, 6.0);
        let flat = CutterShape::Flat { radius: 3.0 };
        let tolerance = 0.0005;
        for dip in [0.003, 0.0015] {
            let (tip, axis) = heel_pose(Vec3::new(x, y, 0.0), dip);
            // The samples alone (session 5's scan) see nothing…
            let sampled = scan
                .iter()
                .map(|p| penetration(&flat, &tip, &axis, p))
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(sampled < tolerance, "{dip}: {sampled}");
            // …the branch and bound finds the crescent: its deepest point lies `dip·cos λ`
            // below the bottom where it meets the rim, less the rim's nearness.
            let hit = index
                .first_penetration(&flat, &tip, &axis, tolerance)
                .unwrap_or_else(|| panic!("{dip}: missed"));
            assert!(hit.depth > tolerance && hit.depth <= dip, "{dip}: {hit:?}");
            assert!((hit.point - Vec3::new(x, y, 0.0)).norm() < 0.6, "{hit:?}");
        }
        // Lifted clear by the tolerance, the same pose passes.
        let (tip, axis) = heel_pose(Vec3::new(x, y, 0.0), -tolerance);
        assert!(index
            .first_penetration(&flat, &tip, &axis, tolerance)
            .is_none());
    }

    /// A ridge along x, `z = −y²/200` for `|x|, |y| ≤ 10` (a quadratic Bézier in y).
    fn ridge() -> NurbsSurface {
        let mut points = Vec::new();
        for x in [-10.0, 10.0] {
            for (y, z) in [(-10.0, -0.5), (0.0, 0.5), (10.0, -0.5)] {
                points.push(Vec3::new(x, y, z));
            }
        }
        NurbsSurface::bspline(
            1,
            2,
            &points,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        )
        .unwrap()
    }

    /// A flat end's heel travelling across the ridge's crest 3/4 of the way along a chord: the
    /// ends and the middle are clear, the sweep is not (session 7's corner gouge in small).
    #[test]
    fn a_rim_sweeping_across_a_rise_between_the_checked_poses_is_found() {
        let surface = ridge();
        let index = RearIndex::new(&surface, sample_surface(&surface, 0.3).unwrap(), 6.0);
        let flat = CutterShape::Flat { radius: 3.0 };
        let tolerance = 0.0005;
        let dip = 0.004;
        let (tip_a, axis) = heel_pose(Vec3::new(0.0, -6.0, 0.0), dip);
        let (tip_b, _) = heel_pose(Vec3::new(0.0, 1.6, 0.0), dip);
        let sweep = Sweep::between((&tip_a, &axis), (&tip_b, &axis));
        for s in [0.0, 0.5, 1.0] {
            let (tip, axis) = sweep.pose(s);
            assert!(
                index
                    .first_penetration(&flat, &tip, &axis, tolerance)
                    .is_none(),
                "pose {s} gouges"
            );
        }
        let hit = index
            .first_penetration_along(&flat, &sweep, tolerance)
            .expect("the heel crossing the crest");
        assert!(hit.depth > tolerance && hit.depth <= dip + 1e-6, "{hit:?}");
        // On the crest, where the heel crosses it (s = 6/7.6), give or take the crescent.
        assert!(
            hit.point.y.abs() < 1.0 && hit.point.x.abs() < 0.5,
            "{hit:?}"
        );
        assert!((hit.at - 6.0 / 7.6).abs() < 0.15, "{hit:?}");
        // Lifted by the dip and the tolerance, the same sweep is clear.
        let lift = Vec3::z() * (dip + tolerance);
        let lifted = Sweep::between((&(tip_a + lift), &axis), (&(tip_b + lift), &axis));
        assert!(index
            .first_penetration_along(&flat, &lifted, tolerance)
            .is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]

        /// Over random chords with a turning axis above the free-form patch, every cutter, the
        /// sweep misses nothing that 400 standing checks along it find (they are exact to the
        /// tolerance each: a pose gouging by twice the tolerance must be reported), and what
        /// it reports lies that deep inside the cutter at the pose it names.
        #[test]
        fn the_sweep_finds_what_dense_poses_find(
            which in 0usize..3,
            start in prop::array::uniform2(0.15f64..0.85),
            travel in prop::array::uniform2(-0.1f64..0.1),
            leans in prop::array::uniform4(-0.3f64..0.3),
            sink in 0.0f64..0.05,
        ) {
            let surface = crate::testing::freeform(0.0);
            let index = RearIndex::new(&surface, sample_surface(&surface, 0.3).unwrap(), 10.0);
            let shape = shapes()[which];
            let tolerance = 0.0005;
            let pose = |uv: [f64; 2], lean: [f64; 2]| {
                let d = surface.derivs(uv[0], uv[1]);
                let n = d.normal().unwrap().into_inner();
                let axis = Unit::new_normalize(n + Vec3::new(lean[0], lean[1], 0.0));
                // Standing on the surface point, sunk a little so some chords gouge.
                (d.point - n * sink, axis)
            };
            let end = [start[0] + travel[0], start[1] + travel[1]];
            let (tip_a, axis_a) = pose(start, [leans[0], leans[1]]);
            let (tip_b, axis_b) = pose(end, [leans[2], leans[3]]);
            let sweep = Sweep::between((&tip_a, &axis_a), (&tip_b, &axis_b));
            let found = index.first_penetration_along(&shape, &sweep, tolerance);
            let dense = (0..=400).find_map(|k| {
                let (tip, axis) = sweep.pose(k as f64 / 400.0);
                index.first_penetration(&shape, &tip, &axis, 2.0 * tolerance)
            });
            if let Some(d) = dense {
                prop_assert!(found.is_some(), "missed {d:?}");
            }
            if let Some(f) = found {
                let (tip, axis) = sweep.pose(f.at);
                let depth = penetration(&shape, &tip, &axis, &f.point);
                prop_assert!(depth > tolerance && (depth - f.depth).abs() < 1e-12, "{f:?}");
            }
        }
    }

    #[test]
    fn penetration_of_simple_points() {
        let z = Vec3::z_axis();
        let tip = Vec3::zeros();
        let ball = CutterShape::Ball { radius: 3.0 };
        assert!((penetration(&ball, &tip, &z, &Vec3::new(0.0, 0.0, 1.0)) - 1.0).abs() < 1e-12);
        // On the sphere: zero; below the tip: outside.
        let on = Vec3::new(3.0 * 0.6, 0.0, 3.0 - 3.0 * 0.8);
        assert!(penetration(&ball, &tip, &z, &on).abs() < 1e-12);
        assert!(penetration(&ball, &tip, &z, &Vec3::new(0.0, 0.0, -0.1)) < 0.0);
        let flat = CutterShape::Flat { radius: 5.0 };
        assert!((penetration(&flat, &tip, &z, &Vec3::new(4.0, 0.0, 0.5)) - 0.5).abs() < 1e-12);
        assert!((penetration(&flat, &tip, &z, &Vec3::new(4.9, 0.0, 2.0)) - 0.1).abs() < 1e-12);
        let bull = CutterShape::BullNose {
            radius: 6.0,
            corner_radius: 2.0,
        };
        // Corner point at 45° on the torus, moved 0.1 inward.
        let c = Vec3::new(4.0, 0.0, 2.0);
        let dir = Vec3::new(1.0, 0.0, -1.0).normalize();
        let p = c + dir * 1.9;
        assert!((penetration(&bull, &tip, &z, &p) - 0.1).abs() < 1e-12);
    }
}
