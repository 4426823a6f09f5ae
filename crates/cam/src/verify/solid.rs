//! The cutter as a solid for the verifying simulation: every cutter (ball, flat, bull-nose,
//! with its flutes) is the set of points within the corner radius `r` of a core cylinder on
//! the axis — radius `R − r`, from `r` to the flute length above the tip. Its entry along a
//! dexel is the first root of a convex function, found by Newton from below; a ball's core is a
//! segment, its solid a capsule, entered in closed form.
//!
//! `φ(t) = dist(P + t·n, core) − r` is convex in `t` (the distance to a convex set is convex),
//! so Newton started left of the first root climbs to it monotonically (every tangent lies
//! under the graph) and a non-negative slope with `φ > 0` proves there is no root ahead.

use tezgah_geom::Vec3;

use crate::cutter::Cutter;

/// One placement of the cutter: tip and unit axis, part frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterPose {
    pub tip: Vec3,
    pub axis: Vec3,
}

/// The cutter's solid: core cylinder and corner radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutterSolid {
    /// Corner radius r (ball: R; flat: 0).
    pub corner: f64,
    /// Core radius R − r.
    pub core_radius: f64,
    /// Core from `corner` to this height above the tip (the flute length, at least `corner`).
    pub core_top: f64,
}

/// Newton's convergence: the distance function is 1-Lipschitz, so |φ| below this is the
/// entry to within this many mm.
const ROOT_TOLERANCE: f64 = 1e-10;
const MAX_STEPS: usize = 60;

impl CutterSolid {
    pub fn of(cutter: &Cutter) -> Self {
        let corner = cutter.shape.corner_radius();
        Self {
            corner,
            core_radius: cutter.shape.radius() - corner,
            core_top: cutter.flute_length.max(corner),
        }
    }

    /// Radius of a sphere about the tip that holds the whole solid.
    pub fn bound(&self) -> f64 {
        (self.core_radius + self.corner).hypot(self.core_top + self.corner)
    }

    /// Distance from `x` to the core, and its gradient (zero inside).
    #[inline]
    fn core_distance(&self, pose: &CutterPose, x: &Vec3) -> (f64, Vec3) {
        let rel = x - pose.tip;
        let z = rel.dot(&pose.axis);
        let w = rel - pose.axis * z;
        let rho = w.norm();
        let dz = if z < self.corner {
            z - self.corner
        } else if z > self.core_top {
            z - self.core_top
        } else {
            0.0
        };
        let dr = (rho - self.core_radius).max(0.0);
        // Millimetre lengths: no overflow for `hypot` to guard against, and it was 15 % of
        // `tezgah cam`'s time on the STEP free-form job (perf), most of it here.
        let d = (dz * dz + dr * dr).sqrt();
        if d == 0.0 {
            return (0.0, Vec3::zeros());
        }
        let mut g = pose.axis * (dz / d);
        if dr > 0.0 {
            g += w * (dr / (d * rho));
        }
        (d, g)
    }

    /// The first `t` in `[lo, hi]` where `p + t·n` is inside the cutter, if any (`lo` itself
    /// when the ray starts inside).
    #[inline]
    pub fn entry(&self, pose: &CutterPose, p: &Vec3, n: &Vec3, lo: f64, hi: f64) -> Option<f64> {
        self.entry_within(pose, p, n, lo, hi, self.corner)
    }

    /// The first `t` in `[lo, hi]` where `p + t·n` is within `reach` of the core (the cutter
    /// itself when `reach` is the corner radius; a thickened cutter, for bounds, beyond it).
    pub fn entry_within(
        &self,
        pose: &CutterPose,
        p: &Vec3,
        n: &Vec3,
        lo: f64,
        hi: f64,
        reach: f64,
    ) -> Option<f64> {
        if self.core_radius == 0.0 {
            let bottom = pose.tip + pose.axis * self.corner;
            let t = capsule_entry(
                &bottom,
                &pose.axis,
                self.core_top - self.corner,
                reach,
                p,
                n,
                lo,
            )?;
            return (t <= hi).then_some(t);
        }
        self.newton_entry(pose, p, n, lo, hi, reach)
    }

    /// [`Self::entry_within`] by Newton on the convex `dist(p + t·n, core) − reach`, for any core.
    fn newton_entry(
        &self,
        pose: &CutterPose,
        p: &Vec3,
        n: &Vec3,
        lo: f64,
        hi: f64,
        reach: f64,
    ) -> Option<f64> {
        let mut t = lo;
        for _ in 0..MAX_STEPS {
            let x = p + n * t;
            let (d, g) = self.core_distance(pose, &x);
            let phi = d - reach;
            if phi <= ROOT_TOLERANCE {
                return Some(t);
            }
            let slope = g.dot(n);
            if slope >= 0.0 {
                return None;
            }
            t -= phi / slope;
            if t > hi {
                return None;
            }
        }
        Some(t)
    }
}

/// The first `t ≥ lo` where `p + t·n` lies within `radius` of the segment from `a` along the
/// unit `axis` for `length`: a capsule, the union of a finite cylinder and the spheres at its
/// ends, so its first entry is the earliest of theirs (a ray entering the cylinder through an
/// end disc is already inside that end's sphere, so only the mantle counts for the cylinder).
/// `lo` itself when the ray starts inside.
#[inline]
pub fn capsule_entry(
    a: &Vec3,
    axis: &Vec3,
    length: f64,
    radius: f64,
    p: &Vec3,
    n: &Vec3,
    lo: f64,
) -> Option<f64> {
    let o = p + n * lo;
    let w = o - a;
    let z = w.dot(axis);
    // Inside: the distance from the start to the segment is at most the radius.
    let zc = z.clamp(0.0, length);
    let r2 = radius * radius;
    if (w - axis * zc).norm_squared() <= r2 {
        return Some(lo);
    }
    let nn = n.norm_squared();
    let mut best = f64::INFINITY;
    // Mantle: |w⊥ + t·n⊥|² = radius², entered where the axial coordinate is on the segment.
    let nz = n.dot(axis);
    let (wp, np) = (w - axis * z, n - axis * nz);
    let qa = np.norm_squared();
    if qa > 1e-300 {
        let qb = wp.dot(&np);
        let qc = wp.norm_squared() - r2;
        let disc = qb * qb - qa * qc;
        if qc > 0.0 && disc >= 0.0 {
            let t = (-qb - disc.sqrt()) / qa;
            if t >= 0.0 && (0.0..=length).contains(&(z + t * nz)) {
                best = t;
            }
        }
    }
    // End spheres: |w_c + t·n|² = radius², from outside (the start is outside the capsule).
    for centre_z in [0.0, length] {
        let wc = w - axis * centre_z;
        let qb = wc.dot(n);
        let qc = wc.norm_squared() - r2;
        let disc = qb * qb - nn * qc;
        if disc >= 0.0 && nn > 0.0 {
            let t = (-qb - disc.sqrt()) / nn;
            if t >= 0.0 {
                best = best.min(t);
            }
        }
    }
    best.is_finite().then_some(lo + best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::{Cutter, CutterShape};

    #[test]
    fn entries_match_closed_forms() {
        // Ball R = 3 with its tip at the origin, axis +Z; rays straight up at offset d hit
        // the sphere at 3 − √(9 − d²).
        let ball = CutterSolid::of(&Cutter::standard(CutterShape::Ball { radius: 3.0 }));
        let pose = CutterPose {
            tip: Vec3::zeros(),
            axis: Vec3::z(),
        };
        for d in [0.0, 0.5, 1.0, 2.0, 2.9] {
            let t = ball
                .entry(&pose, &Vec3::new(d, 0.0, -1.0), &Vec3::z(), -5.0, 5.0)
                .unwrap();
            assert!(
                (t - 1.0 - (3.0 - (9.0_f64 - d * d).sqrt())).abs() < 1e-9,
                "{d}: {t}"
            );
        }
        // Beside the ball the flank cylinder is met from the side.
        let t = ball
            .entry(&pose, &Vec3::new(-10.0, 0.0, 6.0), &Vec3::x(), -1.0, 20.0)
            .unwrap();
        assert!((t - 7.0).abs() < 1e-9);
        assert!(ball
            .entry(&pose, &Vec3::new(3.5, 0.0, -1.0), &Vec3::z(), -5.0, 5.0)
            .is_none());
        // Bull-nose D = 10, r = 2: the flat part reaches radius 3, the torus beyond.
        let bull = CutterSolid::of(&Cutter::standard(CutterShape::BullNose {
            radius: 5.0,
            corner_radius: 2.0,
        }));
        let t = bull
            .entry(&pose, &Vec3::new(2.5, 0.0, -1.0), &Vec3::z(), -5.0, 5.0)
            .unwrap();
        assert!((t - 1.0).abs() < 1e-9);
        let t = bull
            .entry(&pose, &Vec3::new(4.0, 0.0, -1.0), &Vec3::z(), -5.0, 5.0)
            .unwrap();
        assert!(
            (t - 1.0 - (2.0 - (4.0_f64 - 1.0).sqrt())).abs() < 1e-9,
            "{t}"
        );
        // Flat D = 6: the end face, and nothing beyond the rim.
        let flat = CutterSolid::of(&Cutter::standard(CutterShape::Flat { radius: 3.0 }));
        let t = flat
            .entry(&pose, &Vec3::new(2.99, 0.0, -1.0), &Vec3::z(), -5.0, 5.0)
            .unwrap();
        assert!((t - 1.0).abs() < 1e-9);
        assert!(flat
            .entry(&pose, &Vec3::new(3.01, 0.0, -1.0), &Vec3::z(), -5.0, 5.0)
            .is_none());
        // A ray starting inside reports its start.
        assert_eq!(
            ball.entry(&pose, &Vec3::new(0.0, 0.0, 1.0), &Vec3::z(), 0.0, 5.0),
            Some(0.0)
        );
    }

    proptest::proptest! {
        /// The ball's closed-form capsule entry agrees with Newton on the distance to its
        /// core segment, for random poses, rays and thickenings.
        #[test]
        fn capsule_entry_matches_newton(
            tip in proptest::array::uniform3(-3.0..3.0f64),
            axis in proptest::array::uniform3(-1.0..1.0f64),
            p in proptest::array::uniform3(-8.0..8.0f64),
            n in proptest::array::uniform3(-1.0..1.0f64),
            lo in -4.0..0.0f64,
            extra in 0.0..2.0f64,
        ) {
            let axis = Vec3::from(axis);
            let n = Vec3::from(n);
            proptest::prop_assume!(axis.norm() > 0.1 && n.norm() > 0.1);
            let pose = CutterPose { tip: Vec3::from(tip), axis: axis.normalize() };
            let n = n.normalize();
            let ball = CutterSolid::of(&Cutter::standard(CutterShape::Ball { radius: 3.0 }));
            let p = Vec3::from(p);
            let reach = ball.corner + extra;
            let closed = ball.entry_within(&pose, &p, &n, lo, 20.0, reach);
            let newton = ball.newton_entry(&pose, &p, &n, lo, 20.0, reach);
            match (closed, newton) {
                (Some(a), Some(b)) => proptest::prop_assert!((a - b).abs() < 1e-7, "{a} {b}"),
                (None, None) => {}
                // A grazing ray may touch within the root tolerance on one side only.
                (a, b) => {
                    let t = a.or(b).unwrap();
                    let x = p + n * t;
                    let bottom = pose.tip + pose.axis * ball.corner;
                    let z = (x - bottom).dot(&pose.axis).clamp(0.0, ball.core_top - ball.corner);
                    let d = (x - bottom - pose.axis * z).norm();
                    proptest::prop_assert!((d - reach).abs() < 1e-6, "{a:?} {b:?} {d}");
                }
            }
        }
    }
}
