//! The rotary angles of a table-tilting machine along a whole tool path: both inverse
//! solutions of every tool axis, the choice between them, the pole and the unwrap of C.
//! Called by the post-processor before the linear axes and the linearisation check.
//!
//! A tool axis away from the C axis has two solutions, (θ, C) with θ ≥ 0 and (−θ, C + π)
//! (Can, 2010, §3.4.6, eq. 3.32). Choosing per point by nearness to the
//! previous point (what the kinematics' `inverse` does) is greedy; here the branch sequence
//! is chosen for the whole path at once (a two-state Viterbi search, least total rotary travel
//! |Δθ| + |ΔC| within the tilt limits), so a path that crosses the pole flips the tilt's sign
//! and keeps C instead of spinning the table half a turn. Inside the pole cone C is undefined:
//! the previous C is kept and the tilt is the one nearest the axis in the plane it sweeps.
//! Finally C is unwrapped the shortest way within its limits.

use tezgah_geom::Vec3;
use tezgah_kinematics::angle::{unwrap_within, wrap_pi};
use tezgah_kinematics::trunnion::TiltAxis;
use tezgah_kinematics::{table_ac, table_bc, JointLimit, KinematicsError};

/// How far inside its limits a tilt is written, rad (0.0002°). The program carries 4 decimals,
/// which round a tilt by up to 0.00005°, and the runner recomputes the tilt from the tool axis
/// by inverse kinematics, with rounding of ~1e-12°: either puts a pose planned on the limit
/// just beyond it (A = 120.0000000000012° was refused against 120°). A pose needing up to this
/// much beyond the limit is moved inside it too: the tool axis then differs from the one asked
/// for by at most 0.0004°, 0.07 µm at a 10 mm reach — far below any tolerance the post keeps.
pub const LIMIT_MARGIN: f64 = 0.0002 * std::f64::consts::PI / 180.0;

/// Table angles of one output point, rad: the tilt (A on table-ac, B on table-bc) and C.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableAngles {
    pub tilt: f64,
    pub c: f64,
}

/// The orientation map of one trunnion with its rotary limits and pole cone.
#[derive(Debug, Clone)]
pub struct Orienter {
    pub tilt_axis: TiltAxis,
    pub tilt_limit: JointLimit,
    pub c_limit: JointLimit,
    /// Sine of the pole cone's half-angle: inside it C is held.
    pub pole_sin: f64,
}

/// Why no angles were found for a point.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientError {
    /// Index of the offending axis in the sequence given.
    pub index: usize,
    pub error: KinematicsError,
}

impl Orienter {
    /// The tool axis (part frame) the table angles produce.
    pub fn axis(&self, a: TableAngles) -> Vec3 {
        match self.tilt_axis {
            TiltAxis::X => table_ac::axis(a.tilt, a.c),
            TiltAxis::Y => table_bc::axis(a.tilt, a.c),
        }
    }

    /// True when the axis is inside the pole cone (C undefined there).
    pub fn at_pole(&self, k: &Vec3) -> bool {
        // Both trunnions turn C about the part's Z.
        k.x.hypot(k.y) <= self.pole_sin && k.z > 0.0
    }

    /// True when the great-circle arc from `a` to `b` (unit axes) comes inside the pole cone:
    /// only there may the angles change branch between the two points. Elsewhere a change of
    /// branch, (θ, C) → (−θ′, C′ + π), sends the linearly interpolated tilt through zero — the
    /// axis through the pole — while the path's axis passes the pole at the arc's distance
    /// from it, and no inserted point can shrink that: every split leaves one piece holding
    /// the change.
    pub fn arc_meets_pole(&self, a: &Vec3, b: &Vec3) -> bool {
        if self.at_pole(a) || self.at_pole(b) {
            return true;
        }
        let n = a.cross(b);
        let len = n.norm();
        if len < 1e-15 {
            return false;
        }
        let n = n / len;
        // The point of the arc's great circle nearest +Z lies along Z's projection on its
        // plane; it is at sin(distance) = |n_z| from the pole.
        let w = Vec3::z() - n * n.z;
        if w.norm() < 1e-15 {
            return false;
        }
        let inside = a.cross(&w).dot(&n) >= 0.0 && w.cross(b).dot(&n) >= 0.0;
        inside && n.z.abs() <= self.pole_sin
    }

    /// Both solutions away from the pole: branch 0 has tilt ≥ 0, branch 1 is (−tilt, C + π).
    pub fn solutions(&self, k: &Vec3) -> [TableAngles; 2] {
        let s = match self.tilt_axis {
            TiltAxis::X => table_ac::solutions(k),
            TiltAxis::Y => table_bc::solutions(k),
        };
        s.map(|(tilt, c)| TableAngles { tilt, c })
    }

    /// At the pole: C kept, the tilt nearest the axis.
    pub fn keeping_c(&self, k: &Vec3, c: f64) -> TableAngles {
        let tilt = match self.tilt_axis {
            TiltAxis::X => table_ac::tilt_keeping_c(k, c),
            TiltAxis::Y => table_bc::tilt_keeping_c(k, c),
        };
        TableAngles { tilt, c }
    }

    /// The tilt moved into its limits by whole turns, if any turn fits; a tilt within
    /// [`LIMIT_MARGIN`] of a limit (either side) is kept that margin inside it (a limit at
    /// zero excepted).
    fn tilt_in_limits(&self, tilt: f64) -> Option<f64> {
        let (lo, hi) = (self.tilt_limit.min, self.tilt_limit.max);
        let t = unwrap_within(tilt, tilt, lo - LIMIT_MARGIN, hi + LIMIT_MARGIN)?;
        if hi - lo <= 2.0 * LIMIT_MARGIN {
            return Some(0.5 * (lo + hi));
        }
        // A limit at zero (a machine that tilts one way only) is written exactly as A0 and
        // read back as exactly 0: the pole stays reachable.
        let inside = |limit: f64, sign: f64| {
            if limit == 0.0 {
                0.0
            } else {
                limit + sign * LIMIT_MARGIN
            }
        };
        Some(t.clamp(inside(lo, 1.0), inside(hi, -1.0)))
    }

    /// The candidates of one axis given the two states of the point before (for the pole).
    fn candidates(&self, k: &Vec3, before: [TableAngles; 2]) -> ([Option<TableAngles>; 2], bool) {
        if self.at_pole(k) {
            let c = before.map(|b| self.keeping_c(k, b.c));
            (c.map(|a| self.fit(a)), true)
        } else {
            (self.solutions(k).map(|a| self.fit(a)), false)
        }
    }

    fn fit(&self, a: TableAngles) -> Option<TableAngles> {
        self.tilt_in_limits(a.tilt)
            .map(|tilt| TableAngles { tilt, c: a.c })
    }

    /// Table angles for every axis of `axes` (unit vectors, part frame), starting from the
    /// machine at `start`: the branch sequence of least rotary travel within the tilt limits
    /// that changes branch only where the path passes through the pole cone
    /// ([`Orienter::arc_meets_pole`]; a change elsewhere is taken only when the tilt limits
    /// leave no other way, and then the linearisation check reports it), C held at the pole,
    /// C unwrapped the shortest way within its limits.
    pub fn choose(
        &self,
        axes: &[Vec3],
        start: TableAngles,
    ) -> Result<Vec<TableAngles>, OrientError> {
        if axes.is_empty() {
            return Ok(Vec::new());
        }
        let step =
            |a: &TableAngles, b: &TableAngles| (b.tilt - a.tilt).abs() + wrap_pi(b.c - a.c).abs();
        // Viterbi over the two branches: cost, state values and back pointers per point.
        let mut states: Vec<[Option<TableAngles>; 2]> = Vec::with_capacity(axes.len());
        let mut back: Vec<[usize; 2]> = Vec::with_capacity(axes.len());
        // Cost: (changes of branch off the pole, rotary travel), compared in that order.
        let mut cost = [(0u32, 0.0_f64); 2];
        let mut before = [start, start];
        for (i, k) in axes.iter().enumerate() {
            let (cand, pole) = self.candidates(k, before);
            let mut next_cost = [(u32::MAX, f64::INFINITY); 2];
            let off_pole_pair = i > 0 && !pole && !self.at_pole(&axes[i - 1]);
            let switch_ok = !off_pole_pair || self.arc_meets_pole(&axes[i - 1], k);
            let mut ptr = [0usize; 2];
            for (s, c) in cand.iter().enumerate() {
                let Some(c) = c else { continue };
                for p in 0..2 {
                    // A pole state holds the C of its own predecessor only.
                    if pole && p != s {
                        continue;
                    }
                    let prev = if i == 0 {
                        Some(start)
                    } else {
                        states[i - 1][p]
                    };
                    let Some(prev) = prev else { continue };
                    if cost[p].1.is_infinite() {
                        continue;
                    }
                    let bad = u32::from(off_pole_pair && p != s && !switch_ok);
                    let total = (cost[p].0 + bad, cost[p].1 + step(&prev, c));
                    if total.0 < next_cost[s].0
                        || (total.0 == next_cost[s].0 && total.1 < next_cost[s].1)
                    {
                        next_cost[s] = total;
                        ptr[s] = p;
                    }
                }
            }
            if next_cost.iter().all(|c| !c.1.is_finite()) {
                let tilt = if pole {
                    self.keeping_c(k, before[0].c).tilt
                } else {
                    self.solutions(k)[0].tilt
                };
                return Err(OrientError {
                    index: i,
                    error: self.tilt_limit.violation(3, tilt),
                });
            }
            let values = [0, 1].map(|s| {
                if next_cost[s].1.is_finite() {
                    cand[s]
                } else {
                    None
                }
            });
            before = [0, 1].map(|s| values[s].or(values[1 - s]).unwrap_or(before[s]));
            states.push(values);
            back.push(ptr);
            cost = next_cost;
        }
        // Back-track the cheapest end state.
        let mut s = if cost[0] <= cost[1] { 0 } else { 1 };
        let mut chosen = vec![start; axes.len()];
        for i in (0..axes.len()).rev() {
            // Finite cost implies the state holds a value.
            chosen[i] = states[i][s].unwrap_or(start);
            s = back[i][s];
        }
        // Shortest unwrap of C, within its limits.
        let mut previous_c = start.c;
        for (i, a) in chosen.iter_mut().enumerate() {
            a.c = unwrap_within(a.c, previous_c, self.c_limit.min, self.c_limit.max).ok_or(
                OrientError {
                    index: i,
                    error: self.c_limit.violation(4, a.c),
                },
            )?;
            previous_c = a.c;
        }
        Ok(chosen)
    }

    /// The angles for one extra axis between two chosen neighbours (a point the linearisation
    /// inserts): the candidate nearest the interpolated neighbours, C held at the pole and
    /// unwrapped next to `from`.
    pub fn between(
        &self,
        k: &Vec3,
        from: TableAngles,
        to: TableAngles,
    ) -> Result<TableAngles, KinematicsError> {
        let mid = TableAngles {
            tilt: 0.5 * (from.tilt + to.tilt),
            c: 0.5 * (from.c + to.c),
        };
        // At the pole C is free: halfway between the neighbours' (already unwrapped) C, so
        // that halving a turn of C made there converges.
        let cands: Vec<TableAngles> = if self.at_pole(k) {
            vec![self.keeping_c(k, mid.c)]
        } else {
            self.solutions(k).to_vec()
        };
        let mut best: Option<(f64, TableAngles)> = None;
        for c in cands {
            let Some(mut c) = self.fit(c) else { continue };
            c.c = unwrap_within(c.c, mid.c, self.c_limit.min, self.c_limit.max)
                .ok_or_else(|| self.c_limit.violation(4, c.c))?;
            let d = (c.tilt - mid.tilt).abs() + (c.c - mid.c).abs();
            if best.is_none_or(|(b, _)| d < b) {
                best = Some((d, c));
            }
        }
        best.map(|(_, c)| c).ok_or_else(|| {
            let t = self.solutions(k)[0].tilt;
            self.tilt_limit.violation(3, t)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;
    use tezgah_kinematics::JointKind;

    fn ac(tilt_min_deg: f64, tilt_max_deg: f64) -> Orienter {
        Orienter {
            tilt_axis: TiltAxis::X,
            tilt_limit: JointLimit::new(
                "a",
                JointKind::Rotary,
                tilt_min_deg.to_radians(),
                tilt_max_deg.to_radians(),
            ),
            c_limit: JointLimit::endless("c"),
            pole_sin: 1e-6,
        }
    }

    const ZERO: TableAngles = TableAngles { tilt: 0.0, c: 0.0 };

    fn deg(a: &TableAngles) -> (f64, f64) {
        (a.tilt.to_degrees(), a.c.to_degrees())
    }

    #[test]
    fn reference_t11_both_branches() {
        // Can (2010), eq. 3.32: n = (0, −0.5, 0.86603) has (30°, 180°) and (−30°, 0°).
        let o = ac(-90.0, 90.0);
        let k = Vec3::new(0.0, -0.5, 0.75_f64.sqrt());
        let [b0, b1] = o.solutions(&k);
        assert!((deg(&b0).0 - 30.0).abs() < 1e-9 && (deg(&b0).1.abs() - 180.0).abs() < 1e-9);
        assert!((deg(&b1).0 + 30.0).abs() < 1e-9 && deg(&b1).1.abs() < 1e-9);
        // From the home position the A ≤ 0 branch needs no turn of C: it is chosen.
        let got = o.choose(&[k], ZERO).unwrap();
        assert!((deg(&got[0]).0 + 30.0).abs() < 1e-9 && deg(&got[0]).1.abs() < 1e-9);
        // With A limited to ≥ −20° only branch 0 is left.
        let got = ac(-20.0, 120.0).choose(&[k], ZERO).unwrap();
        assert!((deg(&got[0]).0 - 30.0).abs() < 1e-9);
        assert!((o.axis(got[0]) - k).norm() < 1e-12);
    }

    #[test]
    fn crossing_the_pole_flips_the_tilt_and_keeps_c() {
        // A great circle through the pole in the Y-Z plane: the axis tilts from +Y to −Y.
        let o = ac(-60.0, 120.0);
        let axes: Vec<Vec3> = (-10..=10)
            .map(|i| {
                let t = (i as f64 * 3.0).to_radians();
                Vec3::new(0.0, t.sin(), t.cos())
            })
            .collect();
        let got = o.choose(&axes, ZERO).unwrap();
        for (a, k) in got.iter().zip(&axes) {
            assert!((o.axis(*a) - k).norm() < 1e-9);
            assert_eq!(a.c, got[0].c, "C never moves");
        }
        let travel: f64 = got.windows(2).map(|w| (w[1].tilt - w[0].tilt).abs()).sum();
        assert!((travel.to_degrees() - 60.0).abs() < 1e-9);
        // When the negative tilt is not allowed the table turns half a turn at the pole,
        // once, and every axis is still reproduced.
        let got = ac(0.0, 120.0).choose(&axes, ZERO).unwrap();
        for (a, k) in got.iter().zip(&axes) {
            assert!((o.axis(*a) - k).norm() < 1e-9);
            assert!(a.tilt >= 0.0);
        }
        let c_travel: f64 = got.windows(2).map(|w| (w[1].c - w[0].c).abs()).sum();
        assert!((c_travel - PI).abs() < 1e-9, "{c_travel}");
    }

    #[test]
    fn passing_beside_the_pole_keeps_the_branch_and_turns_c() {
        // The axis sweeps past the pole at 0.75° (the free-form patch's pass 42 near its hill
        // top): switching branch would send the tilt through zero, 0.75° off the path, which
        // no inserted point can mend; the branch is kept and C turns about half a turn.
        let o = Orienter {
            pole_sin: (0.005 / 3.0_f64).min(1.0) * 0.5,
            ..ac(-30.0, 120.0)
        };
        let miss = 0.75f64.to_radians();
        let axes: Vec<Vec3> = (-6..=6)
            .map(|i| {
                let t = (i as f64 * 1.2).to_radians();
                Vec3::new(t.sin(), miss.sin(), t.cos() * miss.cos()).normalize()
            })
            .collect();
        assert!(!o.arc_meets_pole(&axes[5], &axes[6]));
        let got = o.choose(&axes, ZERO).unwrap();
        for (a, k) in got.iter().zip(&axes) {
            assert!((o.axis(*a) - k).norm() < 1e-9);
        }
        let signs: Vec<bool> = got.iter().map(|a| a.tilt > 0.0).collect();
        assert!(signs.iter().all(|&s| s == signs[0]), "{got:?}");
        let turn = (got[12].c - got[0].c).abs().to_degrees();
        assert!(turn > 150.0 && turn < 180.0, "{turn}");
        // Through the pole itself the branch changes and C stays.
        let through: Vec<Vec3> = (-6..=6)
            .map(|i| {
                let t = (i as f64 * 1.2 + 0.5).to_radians();
                Vec3::new(t.sin(), 0.0, t.cos())
            })
            .collect();
        assert!(o.arc_meets_pole(&through[5], &through[6]));
        let got = o.choose(&through, ZERO).unwrap();
        assert!(
            got.windows(2).all(|w| (w[0].c - w[1].c).abs() < 1e-9),
            "{got:?}"
        );
    }

    #[test]
    fn c_unwraps_the_shortest_way_and_past_a_turn() {
        // The axis circles the pole twice at 30°: C grows continuously to 720°.
        let o = ac(-30.0, 120.0);
        let axes: Vec<Vec3> = (0..=96)
            .map(|i| {
                let c = (i as f64 * 7.5).to_radians();
                table_ac::axis(30f64.to_radians(), c)
            })
            .collect();
        let got = o.choose(&axes, ZERO).unwrap();
        for w in got.windows(2) {
            assert!((w[1].c - w[0].c - 7.5f64.to_radians()).abs() < 1e-9);
        }
        assert!((got.last().unwrap().c.to_degrees() - 720.0).abs() < 1e-6);
    }

    #[test]
    fn at_the_pole_c_is_held() {
        let o = ac(-30.0, 120.0);
        let start = TableAngles { tilt: 0.2, c: 1.0 };
        let got = o.choose(&[Vec3::z(), Vec3::z()], start).unwrap();
        assert!(got.iter().all(|a| a.c == 1.0 && a.tilt == 0.0));
    }

    #[test]
    fn a_tilt_on_the_limit_is_written_inside_it() {
        let o = ac(-30.0, 120.0);
        // An axis needing exactly 120°, a rounding hair past it, and half the margin past it.
        for extra in [0.0, 1e-14, 0.5 * LIMIT_MARGIN] {
            let k = table_ac::axis(120f64.to_radians() + extra, 0.4);
            let got = o.choose(&[k], ZERO).unwrap();
            let deg = got[0].tilt.to_degrees();
            assert!((deg - 119.9998).abs() < 1e-9, "{deg}");
            // As the program writes it (4 decimals) it is inside the limit too.
            assert!(format!("{deg:.4}").parse::<f64>().unwrap() < 120.0);
            assert!((o.axis(got[0]) - k).norm() <= 2.0 * LIMIT_MARGIN);
        }
        // Further beyond: refused as before.
        let k = table_ac::axis(120f64.to_radians() + 2.0 * LIMIT_MARGIN, 0.4);
        assert!(o.choose(&[k], ZERO).is_err());
    }

    #[test]
    fn unreachable_tilt_is_an_error_naming_the_point() {
        let o = ac(-30.0, 30.0);
        let k = table_ac::axis(60f64.to_radians(), 0.3);
        let err = o.choose(&[Vec3::z(), k], ZERO).unwrap_err();
        assert_eq!(err.index, 1);
        assert!(err.error.to_string().contains('a'), "{}", err.error);
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;
        use tezgah_kinematics::trunnion::Trunnion;
        use tezgah_kinematics::{Joints, Kinematics, Tolerances, Tool, ToolPose};

        /// A smooth random walk of tool axes within 80° of the C axis.
        fn walk(start: (f64, f64), steps: &[(f64, f64)]) -> Vec<Vec3> {
            let (mut t, mut c) = start;
            steps
                .iter()
                .map(|(dt, dc)| {
                    t = (t + dt).clamp(-1.4, 1.4);
                    c += dc;
                    table_ac::axis(t, c)
                })
                .collect()
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(200))]

            /// Every chosen pair reproduces its axis, stays in the tilt limits, C moves
            /// continuously, and the whole-path choice never travels more than the per-point
            /// nearest choice of the kinematics crate.
            #[test]
            fn chosen_angles_reproduce_axes_and_beat_greedy(
                start in (-1.0f64..1.0, -3.0f64..3.0),
                steps in proptest::collection::vec((-0.08f64..0.08, -0.3f64..0.3), 2..60),
                lo in -100.0f64..0.0,
            ) {
                let o = ac(lo, 120.0);
                let axes = walk(start, &steps);
                let got = match o.choose(&axes, ZERO) {
                    Ok(g) => g,
                    // Only a tilt beyond the limits may refuse.
                    Err(e) => {
                        let k = axes[e.index];
                        let need = k.x.hypot(k.y).atan2(k.z);
                        prop_assert!(need > 120f64.to_radians() && need > -lo.to_radians());
                        return Ok(());
                    }
                };
                let mut last = ZERO;
                for (a, k) in got.iter().zip(&axes) {
                    // Within the limit margin's axis error of the axis asked for.
                    prop_assert!((o.axis(*a) - k).norm() < 2.0 * LIMIT_MARGIN + 1e-9);
                    prop_assert!(o.tilt_limit.contains(a.tilt));
                    prop_assert!((a.c - last.c).abs() <= PI + 1e-9);
                    last = *a;
                }
                let travel = |v: &[(f64, f64)]| -> f64 {
                    let mut prev = (0.0, 0.0);
                    let mut sum = 0.0;
                    for &(t, c) in v {
                        sum += (t - prev.0).abs() + (c - prev.1).abs();
                        prev = (t, c);
                    }
                    sum
                };
                let limits = vec![
                    JointLimit::unlimited("x", tezgah_kinematics::JointKind::Linear),
                    JointLimit::unlimited("y", tezgah_kinematics::JointKind::Linear),
                    JointLimit::unlimited("z", tezgah_kinematics::JointKind::Linear),
                    o.tilt_limit.clone(),
                    o.c_limit.clone(),
                ];
                let greedy_model = Trunnion::new(
                    TiltAxis::X,
                    nalgebra::Vector3::zeros(),
                    nalgebra::Vector3::zeros(),
                    limits,
                    Tolerances::default(),
                )
                .unwrap();
                let mut q = Joints::zeros(5);
                let mut greedy = Vec::new();
                for k in &axes {
                    match greedy_model.inverse(&ToolPose::new(nalgebra::Vector3::zeros(), *k), &Tool::default(), &q) {
                        Ok(next) => {
                            q = next;
                            greedy.push((q[3], q[4]));
                        }
                        Err(_) => return Ok(()),
                    }
                }
                let ours: Vec<(f64, f64)> = got.iter().map(|a| (a.tilt, a.c)).collect();
                // A change of branch (the tilt's sign) between two axes off the pole is only
                // made where the arc between them passes through the pole cone (branch 0
                // always fits here, so nothing forces one).
                let bad_switch = |v: &[(f64, f64)]| {
                    (1..v.len()).any(|i| {
                        let (a, b) = (axes[i - 1], axes[i]);
                        !o.at_pole(&a) && !o.at_pole(&b) && v[i - 1].0 * v[i].0 < 0.0
                            && !o.arc_meets_pole(&a, &b)
                    })
                };
                prop_assert!(!bad_switch(&ours));
                // Among sequences that can be linearised, ours travels least.
                if !bad_switch(&greedy) {
                    prop_assert!(travel(&ours) <= travel(&greedy) + 1e-9, "{} > {}", travel(&ours), travel(&greedy));
                }
            }
        }
    }
}
