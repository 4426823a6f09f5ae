//! The motion of the cutter between two placed locations, as the rear check sees it: the tip
//! on the straight chord, the axis turning on the great circle between the two axes at a
//! constant rate (`tip(s) = a + sΔ`, `axis(s) = slerp(a, b, s)`, `s ∈ [0, 1]`). A standing
//! cutter is the sweep of length zero.
//!
//! The rear check bounds a point's depth over a span of `s` by its depth at the span's middle
//! and how far the point can move relative to the cutter over the span ([`Sweep::spread`]).

use nalgebra::{Rotation3, Unit};
use tezgah_geom::Vec3;

/// The cutter's motion along one chord.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    from: Vec3,
    /// Tip travel over the chord, `Δ = b − a`, mm.
    step: Vec3,
    axis_from: Unit<Vec3>,
    axis_to: Unit<Vec3>,
    /// The axis's turn over the chord, rad.
    turn: f64,
    /// Angular velocity per unit `s`: the turn about `a × b`, rad.
    spin: Vec3,
    /// `spin`'s direction (zero without a turn) and `|step|`: [`Sweep::spread`] asks for
    /// them for every cell and span of the rear check's search, so they are made once.
    spin_axis: Vec3,
    travel: f64,
}

impl Sweep {
    /// The cutter standing at `tip` along `axis`.
    pub fn still(tip: &Vec3, axis: &Unit<Vec3>) -> Sweep {
        Sweep::between((tip, axis), (tip, axis))
    }

    /// From `tip_a` along `axis_a` to `tip_b` along `axis_b`. Opposite axes have no one great
    /// circle: the axis then stays at `axis_a` (neighbouring locations never turn that far).
    pub fn between(
        (tip_a, axis_a): (&Vec3, &Unit<Vec3>),
        (tip_b, axis_b): (&Vec3, &Unit<Vec3>),
    ) -> Sweep {
        let cross = axis_a.cross(axis_b);
        let turn = cross.norm().atan2(axis_a.dot(axis_b));
        let spin = if cross.norm() > 0.0 {
            cross.normalize() * turn
        } else {
            Vec3::zeros()
        };
        let step = tip_b - tip_a;
        Sweep {
            from: *tip_a,
            step,
            axis_from: *axis_a,
            axis_to: *axis_b,
            turn,
            spin,
            spin_axis: spin.try_normalize(0.0).unwrap_or_else(Vec3::zeros),
            travel: step.norm(),
        }
    }

    /// Tip and axis at `s`.
    pub fn pose(&self, s: f64) -> (Vec3, Unit<Vec3>) {
        let turn = Rotation3::from_scaled_axis(self.spin * s);
        (self.from + self.step * s, turn * self.axis_from)
    }

    /// A box holding every point within `margin` of the segment from the tip to `height`
    /// up the axis, at every pose of the sweep: the ends' boxes, grown by how far the axis's
    /// arc strays from its chord (at most the turn, per unit of height).
    pub fn bounding_box(&self, height: f64, margin: f64) -> (Vec3, Vec3) {
        self.bounding_box_between(0.0, height, margin)
    }

    /// [`Sweep::bounding_box`] of the piece of the axis from `z0` to `z1` above the tip.
    pub fn bounding_box_between(&self, z0: f64, z1: f64, margin: f64) -> (Vec3, Vec3) {
        let grow = Vec3::repeat(margin + z1.abs().max(z0.abs()) * self.turn);
        let (a, b) = (self.axis_from.into_inner(), self.axis_to.into_inner());
        let ends = [
            self.from + a * z0,
            self.from + a * z1,
            self.from + self.step + b * z0,
            self.from + self.step + b * z1,
        ];
        let (lo, hi) = ends[1..]
            .iter()
            .fold((ends[0], ends[0]), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        (lo - grow, hi + grow)
    }

    /// The most `g·(q_x(s) − q_x(s_m))` can be, for `|s − s_m| ≤ h` and every point `x`
    /// within `near` of `p`, where `q_x(s)` is `x` in the frame of the cutter at `s` and `g`
    /// a unit vector of that frame at `s_m` (expressed in the world; `tip` is the tip at
    /// `s_m`). Taylor to second order with the remainder bounded: in the frame of `s_m`,
    /// `f(σ) = g(σ)·(y − σΔ)` with `y = x − tip` and `g(σ)` turning at rate `θ` about `k`;
    /// `f'(0) = g·(−Δ − ω × y)`, which differs from its value at `p` by at most `θ·near`, and
    /// `f'' = −θ²(cos φ·g⊥·(y − σΔ) + sin φ·(k × g)·(y − σΔ)) + 2θ sin φ·g⊥·Δ
    /// − 2θ cos φ·(k × g)·Δ`. The last term keeps its sign: rolling over a convex surface the
    /// surface point falls away from the cutter, and the bound says so. Zero for a standing
    /// cutter.
    pub fn spread(&self, g: &Vec3, p: &Vec3, tip: &Vec3, near: f64, h: f64) -> f64 {
        if h == 0.0 {
            return 0.0;
        }
        let y = p - tip;
        let (k, theta, travel) = (self.spin_axis, self.turn, self.travel);
        let slope = g.dot(&(-self.step - self.spin.cross(&y))).abs() + theta * near;
        let roll = k.cross(g).dot(&self.step);
        let coriolis = if roll < 0.0 {
            -2.0 * theta * roll
        } else {
            -2.0 * theta * roll * (theta * h).min(std::f64::consts::PI).cos()
        };
        let bend = theta * theta * (y.norm() + near + 3.0 * h * travel) + coriolis;
        Self::parabola_max(slope, bend, h)
    }

    /// `spread` for every direction `g` at once.
    pub fn spread_any(&self, p: &Vec3, tip: &Vec3, near: f64, h: f64) -> f64 {
        if h == 0.0 {
            return 0.0;
        }
        let y = p - tip;
        let (theta, travel) = (self.turn, self.travel);
        let slope = (self.step + self.spin.cross(&y)).norm() + theta * near;
        let bend = theta * theta * (y.norm() + near + 3.0 * h * travel) + 2.0 * theta * travel;
        Self::parabola_max(slope, bend, h)
    }

    /// The largest `t·slope + t²·bend/2` for `0 ≤ t ≤ h` (`slope ≥ 0`).
    fn parabola_max(slope: f64, bend: f64, h: f64) -> f64 {
        if bend < 0.0 && slope < -bend * h {
            slope * slope / (-2.0 * bend)
        } else {
            h * slope + 0.5 * h * h * bend
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn unit(v: [f64; 3]) -> Option<Unit<Vec3>> {
        Unit::try_new(Vec3::from(v), 1e-3)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The bound holds against the motion itself: a point fixed in the world, seen from
        /// the cutter, moves along `g` no more than `spread` says over the span.
        #[test]
        fn spread_bounds_the_relative_motion(
            a in prop::array::uniform3(-1.0f64..1.0),
            b in prop::array::uniform3(-1.0f64..1.0),
            tip_b in prop::array::uniform3(-4.0f64..4.0),
            p in prop::array::uniform3(-8.0f64..8.0),
            off in prop::array::uniform3(-0.3f64..0.3),
            g in prop::array::uniform3(-1.0f64..1.0),
            sm in 0.0f64..1.0,
            h in 0.0f64..0.5,
            t in -1.0f64..1.0,
        ) {
            let (Some(a), Some(b), Some(g)) = (unit(a), unit(b), unit(g)) else {
                return Ok(());
            };
            let tip_a = Vec3::new(0.5, -0.3, 0.2);
            let sweep = Sweep::between((&tip_a, &a), (&Vec3::from(tip_b), &b));
            let (tip_m, axis_m) = sweep.pose(sm);
            let (p, x) = (Vec3::from(p), Vec3::from(p) + Vec3::from(off));
            let cover = Vec3::from(off).norm();
            let s = sm + t * h;
            let (tip_s, axis_s) = sweep.pose(s);
            // The frame of the cutter at s: the rotation taking axis_m to axis_s about the
            // sweep's spin (the cutter is round, so only that turn matters).
            let rot = nalgebra::Rotation3::rotation_between(&axis_m, &axis_s)
                .unwrap_or_else(nalgebra::Rotation3::identity);
            let q = |xw: &Vec3, tip: &Vec3, r: &nalgebra::Rotation3<f64>| r.inverse() * (xw - tip);
            let moved = g.dot(&(q(&x, &tip_s, &rot) - q(&x, &tip_m, &nalgebra::Rotation3::identity())));
            let bound = sweep.spread(&g, &p, &tip_m, cover, h);
            prop_assert!(moved <= bound + 1e-9, "moved {moved} > spread {bound}");
            prop_assert!(bound <= sweep.spread_any(&p, &tip_m, cover, h) + 1e-12);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        /// With `g` across the point's relative velocity the first order vanishes and the
        /// bound is the second order alone (the turning frame's pull, signed): it still holds
        /// at every one of 64 poses over the span.
        #[test]
        fn the_second_order_bound_holds_where_the_first_vanishes(
            b in prop::array::uniform3(-1.0f64..1.0),
            tip_b in prop::array::uniform3(-4.0f64..4.0),
            p in prop::array::uniform3(-8.0f64..8.0),
            g in prop::array::uniform3(-1.0f64..1.0),
            sm in 0.0f64..1.0,
            h in 0.0f64..0.5,
        ) {
            let a = Vec3::z_axis();
            let (Some(b), Some(g)) = (unit(b), unit(g)) else {
                return Ok(());
            };
            let tip_a = Vec3::zeros();
            let sweep = Sweep::between((&tip_a, &a), (&Vec3::from(tip_b), &b));
            let (tip_m, axis_m) = sweep.pose(sm);
            let p = Vec3::from(p);
            let velocity = -sweep.step - sweep.spin.cross(&(p - tip_m));
            let Some(v) = velocity.try_normalize(1e-9) else {
                return Ok(());
            };
            let Some(g) = Unit::try_new(g.into_inner() - v * v.dot(&g), 1e-3) else {
                return Ok(());
            };
            let bound = sweep.spread(&g, &p, &tip_m, 0.0, h);
            for k in 0..=64 {
                let s = sm + h * (2.0 * k as f64 / 64.0 - 1.0);
                let (tip_s, axis_s) = sweep.pose(s);
                let rot = nalgebra::Rotation3::rotation_between(&axis_m, &axis_s)
                    .unwrap_or_else(nalgebra::Rotation3::identity);
                let moved = g.dot(&(rot.inverse() * (p - tip_s) - (p - tip_m)));
                prop_assert!(moved <= bound + 1e-9, "σ {}: moved {moved} > {bound}", s - sm);
            }
        }
    }

    #[test]
    fn a_standing_cutter_does_not_spread() {
        let sweep = Sweep::still(&Vec3::new(1.0, 2.0, 3.0), &Vec3::z_axis());
        let p = Vec3::new(4.0, 0.0, 1.0);
        assert_eq!(sweep.spread_any(&p, &Vec3::zeros(), 0.5, 0.5), 0.5 * 0.0);
        assert_eq!(sweep.pose(0.7).0, Vec3::new(1.0, 2.0, 3.0));
    }
}
