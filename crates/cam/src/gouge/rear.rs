//! Rear gouge: the whole cutting end against the surface. 001 §2.11b scans the shadow of a
//! flat tool's bottom behind the contact (Lo 1999, extended to the full bottom); here the
//! surface near the tool is tested against the solid of revolution of the cutting end — the
//! flat, torus or ball bottom and the flutes up to two tool radii — so the heel, the middle
//! of the bottom and the sides are all covered, for every cutter shape.
//!
//! Exact to the tolerance, not to the sample spacing: the cutting end is a convex solid (a
//! core cylinder grown by the corner radius, 001 §3.4's torus as a Minkowski sum), so the
//! signed depth of a point in it is concave and its gradient bounds it everywhere:
//! `e(x) ≤ e(p) + g·(x − p)` (a supergradient inequality). Over the surface near a sample
//! `p` (its lattice cell, at most `c` away, bending off its tangent plane by at most `κc²/2`)
//! that gives `e ≤ e(p) + |g_t|·c + |g_n|·κc²/2`; a cell whose bound exceeds the tolerance
//! is split in four and its quarters evaluated on the surface itself (branch and bound, down
//! to cells of [`FINEST_COVER`] of the tolerance). The closest point of the torus is closed
//! form (the point's axial plane, then the corner circle: Lee & Chang 1995 / 001 §3.4.3).
//! Session 5's scan of the samples alone missed heel contacts of 4–5 µm between its 0.3 mm
//! samples: the torus's tube curves by 1/r, the flat's rim is a corner.

use nalgebra::Unit;
use tezgah_geom::{NurbsSurface, Vec3};

use super::index::{PointGrid, Reach, SurfaceSamples};
use crate::cutter::CutterShape;

/// Height of the checked cutting end above the tip, in tool radii.
pub const CUTTING_END_RADII: f64 = 2.0;

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
        let dist = er.hypot(ez);
        (dist, (radial * er - a * ez) / dist)
    };
    let (depth, gradient) = (r - sd, -grad_sd);
    let top = CUTTING_END_RADII * big_r - z;
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

/// The largest depth any surface point of a cell can have: the cell reaches `reach` from
/// its point `p` (depth `d`, normal `n`, zero if unknown) along the tangent plane and bends
/// off it by at most `κc²/2` (`c` its cover, `kappa` bounding the surface's normal
/// curvature). Two concave upper bounds, the smaller kept: the depth's own supergradient, and
/// the tip plane's (the cutting end lies above it, so its depth is at most the height `z`
/// above it, with gradient the axis): beside and below the tool that one is far tighter.
pub fn bound(d: &Depth, z: f64, axis: &Vec3, n: &Vec3, reach: &Reach, kappa: f64) -> f64 {
    let c = reach.cover();
    let sag = 0.5 * kappa * c * c;
    let own = d.depth + reach.along(&d.gradient) + d.gradient.dot(n).abs() * sag;
    let plane = z + reach.along(axis) + axis.dot(n).abs() * sag;
    // Without a normal the bend is not known: the whole cover, every way.
    if n.norm_squared() == 0.0 {
        return d.depth + c;
    }
    own.min(plane)
}

/// A surface point inside the cutting end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// How deep, mm.
    pub depth: f64,
    pub point: Vec3,
}

/// The surface indexed for the rear check: lattice samples in a spatial grid, the surface
/// itself for the cells that need a closer look, and a bound of its normal curvature.
#[derive(Debug, Clone)]
pub struct RearIndex {
    surface: NurbsSurface,
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
    pub fn new(surface: &NurbsSurface, mut samples: SurfaceSamples, bucket: f64) -> RearIndex {
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
        let big_r = shape.radius();
        let top = tip + axis.into_inner() * (CUTTING_END_RADII * big_r);
        let (lo, hi) = (
            tip.inf(&top) - Vec3::repeat(big_r),
            tip.sup(&top) + Vec3::repeat(big_r),
        );
        let mut hit = None;
        self.grid.visit_box(&lo, &hi, |s| {
            let d = depth(shape, tip, axis, &s.point);
            if d.depth > tolerance {
                hit = Some(Penetration {
                    depth: d.depth,
                    point: s.point,
                });
                return false;
            }
            let z = (s.point - tip).dot(axis);
            if bound(&d, z, axis, &s.normal, &s.reach, self.kappa) <= tolerance {
                return true;
            }
            hit = self.split(self.lines.cell(s.node), shape, tip, axis, tolerance, 1);
            hit.is_none()
        });
        hit
    }

    /// Branch and bound over the quarters of the parameter cell `[u0, u1, v0, v1]`.
    fn split(
        &self,
        [u0, u1, v0, v1]: [f64; 4],
        shape: &CutterShape,
        tip: &Vec3,
        axis: &Unit<Vec3>,
        tolerance: f64,
        level: usize,
    ) -> Option<Penetration> {
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
            let d = self.surface.derivs(quarter[0] + hu, quarter[2] + hv);
            let e = depth(shape, tip, axis, &d.point);
            if e.depth > tolerance {
                return Some(Penetration {
                    depth: e.depth,
                    point: d.point,
                });
            }
            let reach = Reach::of(&d, hu, hv);
            let n = d.normal().map_or(Vec3::zeros(), |n| n.into_inner());
            let z = (d.point - tip).dot(axis);
            if level < MAX_LEVELS
                && reach.cover() > FINEST_COVER * tolerance
                && bound(&e, z, axis, &n, &reach, self.kappa) > tolerance
            {
                if let Some(p) = self.split(quarter, shape, tip, axis, tolerance, level + 1) {
                    return Some(p);
                }
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
