//! The clearance sphere the post-processor's links run on: a ball holding the part (and the
//! path), and around it a sphere a clearance plus the tool's widest radius further out. Passes
//! are left and entered along the tool axis through that sphere, the tool moves between
//! passes on it and the table turns only there, where the whole tool stands clear of the
//! part's ball. Used by [`super::links`]; checked again on the machine's motion in [`super::post`].
//!
//! Why this works for any tilt, a vertical face (90°) or an undercut the tilt axis reaches
//! (table-ac: 120°) included: the tool leaves along its axis, so at the exit the outward radial
//! lies within 90° of the axis. On the sphere the link axes are the radials leaned toward +Z
//! no further than the tilt of the passes on either side ([`Clearance::link_axis`]), and the
//! link runs at linearly changing latitude and longitude, so the radials' tilts stay between
//! those of its ends: the link axis stays within 90° of the radial (the tool points away from
//! the part) and the link never asks the tilt axis for more than the cutting does. A safe
//! *plane* cannot do that: the retract along an axis tilted θ runs `tan θ` times the height
//! sideways, and never reaches the plane at 90°.

use tezgah_geom::Vec3;

use crate::toolpath::ToolPath;

/// An axis-aligned box holding the part, part frame, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartBox {
    pub min: Vec3,
    pub max: Vec3,
}

impl PartBox {
    /// The smallest box holding `points`; `None` if there are none or one is not finite.
    pub fn of_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Option<PartBox> {
        let mut out: Option<PartBox> = None;
        for p in points {
            if !p.iter().all(|x| x.is_finite()) {
                return None;
            }
            out = Some(match out {
                None => PartBox { min: *p, max: *p },
                Some(b) => PartBox {
                    min: b.min.inf(p),
                    max: b.max.sup(p),
                },
            });
        }
        out
    }

    /// This box grown by `margin` on every side.
    pub fn grown(&self, margin: f64) -> PartBox {
        let m = Vec3::repeat(margin);
        PartBox {
            min: self.min - m,
            max: self.max + m,
        }
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &PartBox) -> PartBox {
        PartBox {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    fn corners(&self) -> impl Iterator<Item = Vec3> + '_ {
        (0..8).map(move |k| {
            Vec3::new(
                if k & 1 == 0 { self.min.x } else { self.max.x },
                if k & 2 == 0 { self.min.y } else { self.max.y },
                if k & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }
}

/// Largest angle between consecutive link stations on the sphere, rad (the stations are
/// pushed out so the chords between them stay on or outside it).
const MAX_STEP: f64 = 10.0 * std::f64::consts::PI / 180.0;

/// The part's ball and the link sphere around it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearance {
    /// Centre of both spheres: the middle of the part's box.
    pub centre: Vec3,
    /// Radius of the ball holding the part box, every tip and every contact point, mm.
    pub part_radius: f64,
    /// The tool's widest radius (cutting end, shank or holder), mm.
    pub tool_radius: f64,
    /// Radius of the link sphere: part radius + tool radius + clearance, mm.
    pub radius: f64,
}

/// Why a clearance could not be set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NoGeometry;

impl Clearance {
    /// The spheres around `part` (the path's contact points and tips when `None`) and the
    /// path, with `clearance` mm between the tool's widest radius and the part's ball.
    pub fn around(
        path: &ToolPath,
        part: Option<&PartBox>,
        clearance: f64,
    ) -> Result<Clearance, NoGeometry> {
        let points: Vec<Vec3> = path
            .passes
            .iter()
            .flat_map(|p| &p.points)
            .flat_map(|c| [c.tip, c.contact])
            .collect();
        let of_path = PartBox::of_points(&points).ok_or(NoGeometry)?;
        let all = match part {
            Some(b) => b.union(&of_path),
            None => of_path,
        };
        let centre = (all.min + all.max) * 0.5;
        // The box's corners bound every point inside it.
        let part_radius = all
            .corners()
            .map(|p| (p - centre).norm())
            .fold(0.0, f64::max);
        let c = &path.cutter;
        let tool_radius = c.shape.radius().max(c.shank.radius).max(c.holder.radius);
        Ok(Clearance {
            centre,
            part_radius,
            tool_radius,
            radius: part_radius + tool_radius + clearance,
        })
    }

    /// The highest point of the link sphere.
    pub fn top(&self) -> Vec3 {
        self.centre + Vec3::z() * self.radius
    }

    /// Where the line from `tip` along `axis` (unit) leaves the link sphere.
    pub fn exit(&self, tip: &Vec3, axis: &Vec3) -> Vec3 {
        let d = tip - self.centre;
        // |d + λ a|² = ρ²: λ² + 2 (a·d) λ + |d|² − ρ² = 0, the larger root.
        let b = axis.dot(&d);
        let disc = (b * b - d.norm_squared() + self.radius * self.radius).max(0.0);
        let lambda = (-b + disc.sqrt()).max(0.0);
        tip + axis * lambda
    }

    /// The whole tool — every point within its widest radius of the ray from `tip` along
    /// `axis` (unit) — lies outside the part's ball.
    pub fn is_clear(&self, tip: &Vec3, axis: &Vec3) -> bool {
        self.clear_by(tip, axis, 0.0)
    }

    /// [`Self::is_clear`] with `margin` mm to spare.
    pub fn clear_by(&self, tip: &Vec3, axis: &Vec3, margin: f64) -> bool {
        let d = tip - self.centre;
        let along = axis.dot(&d);
        // The ray's closest point to the centre: the tip itself when the ray points away.
        let nearest = if along >= 0.0 {
            d.norm()
        } else {
            (d - axis * along).norm()
        };
        nearest >= self.part_radius + self.tool_radius + margin
    }

    /// The tool axis of a link station at `at` on the sphere: the outward radial direction,
    /// leaned toward +Z until it is at most `max_tilt` (rad) from it. It stays within 90° of
    /// the radial — the tool points away from the part — while the radial leans less than
    /// `max_tilt` + 90° (true on every link, see the module's note).
    pub fn link_axis(&self, at: &Vec3, max_tilt: f64) -> Vec3 {
        let r = (at - self.centre).normalize();
        let tilt = r.z.clamp(-1.0, 1.0).acos();
        if tilt <= max_tilt {
            return r;
        }
        let horizontal = Vec3::new(r.x, r.y, 0.0);
        let h = horizontal.norm();
        // Straight below the centre every direction of lean is as good.
        let toward = if h < 1e-12 { Vec3::x() } else { horizontal / h };
        toward * max_tilt.sin() + Vec3::z() * max_tilt.cos()
    }

    /// Points on (or just outside) the link sphere from `from` to `to` (both on it), not
    /// counting `from`, ending with `to`: latitude and longitude (about the centre, from +Z)
    /// change linearly, the longitude the short way, no two points more than [`MAX_STEP`]
    /// apart. Each interior point sits at `ρ / cos(step)`: the chord from an end on the
    /// sphere to its neighbour then runs along the end's tangent plane at worst, and the
    /// chords between interior points dip to `ρ cos(step/2) / cos(step) ≥ ρ`, so every
    /// chord stays outside the sphere.
    pub fn traverse(&self, from: &Vec3, to: &Vec3) -> Vec<Vec3> {
        let polar = |p: &Vec3| {
            let d = p - self.centre;
            let n = d.norm().max(1e-300);
            ((d.z / n).clamp(-1.0, 1.0).acos(), d.y.atan2(d.x))
        };
        let ((t0, p0), (t1, p1)) = (polar(from), polar(to));
        let tau = std::f64::consts::TAU;
        let mut dp = (p1 - p0).rem_euclid(tau);
        if dp > std::f64::consts::PI {
            dp -= tau;
        }
        let dt = t1 - t0;
        // The arc between two points of the route is at most |Δθ| + sin θ_max |Δφ| long.
        let widest =
            if (t0 - std::f64::consts::FRAC_PI_2) * (t1 - std::f64::consts::FRAC_PI_2) < 0.0 {
                1.0
            } else {
                t0.sin().max(t1.sin())
            };
        let length = dt.abs() + widest * dp.abs();
        if length < 1e-12 {
            return vec![*to];
        }
        // At least one interior point: the chord between two points of the sphere dips in.
        let n = ((length / MAX_STEP).ceil() as usize).max(2);
        let step = length / n as f64;
        let lift = self.radius / step.cos();
        let mut out = Vec::with_capacity(n);
        for k in 1..n {
            let s = k as f64 / n as f64;
            let (t, p) = (t0 + dt * s, p0 + dp * s);
            let w = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            out.push(self.centre + w * lift);
        }
        out.push(*to);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cutter::{Cutter, CutterShape};
    use crate::toolpath::{CutterLocation, Pass};
    use proptest::prelude::*;

    fn path_at(points: &[(Vec3, Vec3)]) -> ToolPath {
        ToolPath {
            cutter: Cutter::standard(CutterShape::Ball { radius: 3.0 }),
            passes: vec![Pass {
                points: points
                    .iter()
                    .map(|&(tip, axis)| CutterLocation {
                        tip,
                        axis,
                        contact: tip,
                        normal: axis,
                        uv: (0.0, 0.0),
                    })
                    .collect(),
            }],
        }
    }

    #[test]
    fn sphere_sits_under_the_part_and_holds_it_with_the_tool() {
        let part = PartBox {
            min: Vec3::new(-20.0, -20.0, 0.0),
            max: Vec3::new(20.0, 20.0, 50.0),
        };
        let path = path_at(&[(Vec3::new(23.0, 0.0, 10.0), Vec3::x())]);
        let c = Clearance::around(&path, Some(&part), 5.0).unwrap();
        // Box widened to x ≤ 23 by the tip: centre (1.5, 0, 25), corners 21.5, 20, 25 away.
        assert!((c.centre - Vec3::new(1.5, 0.0, 25.0)).norm() < 1e-12);
        let far = (21.5f64 * 21.5 + 400.0 + 625.0).sqrt();
        assert!((c.part_radius - far).abs() < 1e-12, "{c:?}");
        // The D6 stock tool's holder has radius 2·D = 12.
        assert_eq!(c.tool_radius, 12.0);
        assert!((c.radius - (far + 17.0)).abs() < 1e-12);
    }

    #[test]
    fn a_horizontal_retract_leaves_sideways_and_is_clear_there() {
        let path = path_at(&[(Vec3::new(23.0, 0.0, 10.0), Vec3::x())]);
        let c = Clearance::around(&path, None, 5.0).unwrap();
        let e = c.exit(&Vec3::new(23.0, 0.0, 10.0), &Vec3::x());
        assert!(((e - c.centre).norm() - c.radius).abs() < 1e-9);
        assert!((e.z - 10.0).abs() < 1e-12 && e.x > 23.0);
        // Its radial leans below the horizontal: the link axis stops at the cap, 90°.
        let a = c.link_axis(&e, std::f64::consts::FRAC_PI_2);
        assert!(a.z.abs() < 1e-12 && c.is_clear(&e, &a), "{a:?}");
        assert!(c.is_clear(&e, &Vec3::x()));
        // Pointing back through the part it is not.
        assert!(!c.is_clear(&e, &-Vec3::x()));
    }

    proptest! {
        /// Any two exits of tools tilted up to 120° (table-ac's reach): every station of the
        /// link between them lies on or outside the sphere, its axis keeps the tool clear of
        /// the part and leans no more than the larger of the two tilts, and the chords between
        /// stations stay outside the sphere too.
        #[test]
        fn links_stay_clear_and_within_the_tilt(
            t1 in proptest::array::uniform3(-30.0f64..30.0),
            t2 in proptest::array::uniform3(-30.0f64..30.0),
            a1 in (0.0f64..=120.0, -180.0f64..180.0),
            a2 in (0.0f64..=120.0, -180.0f64..180.0),
        ) {
            let axis = |(tilt, c): (f64, f64)| {
                let (t, c) = (tilt.to_radians(), c.to_radians());
                Vec3::new(t.sin() * c.sin(), t.sin() * c.cos(), t.cos())
            };
            let (ax1, ax2) = (axis(a1), axis(a2));
            let (p1, p2) = (Vec3::from(t1), Vec3::from(t2));
            let path = path_at(&[(p1, ax1), (p2, ax2)]);
            let c = Clearance::around(&path, None, 5.0).unwrap();
            let cap = a1.0.max(a2.0).to_radians();
            let (e1, e2) = (c.exit(&p1, &ax1), c.exit(&p2, &ax2));
            prop_assert!(c.is_clear(&e1, &ax1) && c.is_clear(&e2, &ax2));
            let mut stations = vec![e1];
            stations.extend(c.traverse(&e1, &e2));
            prop_assert!((stations.last().unwrap() - e2).norm() < 1e-12);
            for w in stations.windows(2) {
                for k in 0..=10 {
                    let p = w[0] + (w[1] - w[0]) * (k as f64 / 10.0);
                    prop_assert!((p - c.centre).norm() >= c.radius * (1.0 - 1e-12));
                }
                prop_assert!((w[1] - c.centre).angle(&(w[0] - c.centre)) <= MAX_STEP + 1e-9);
                // The link's axes turn between stations clear of the part too.
                let (b0, b1) = (c.link_axis(&w[0], cap), c.link_axis(&w[1], cap));
                for k in 0..=10 {
                    let t = k as f64 / 10.0;
                    let p = w[0] + (w[1] - w[0]) * t;
                    let a = (b0 * (1.0 - t) + b1 * t).normalize();
                    prop_assert!(c.is_clear(&p, &a), "{p:?} {a:?}");
                }
            }
            for s in &stations {
                let a = c.link_axis(s, cap);
                prop_assert!(c.is_clear(s, &a), "{s:?} {a:?}");
                prop_assert!(a.z.acos() <= cap + 1e-9);
            }
        }
    }
}
