//! Angle helpers shared by the rotary models: wrapping, shortest unwrap next to the previous
//! joint value, and choosing a turn that respects limits. Used by `yzca` and the trunnions
//! when the inverse picks among solutions by continuity (Kelekçi, 2021, §5.3.1, eq. 5.5).

use std::f64::consts::{PI, TAU};

/// Wraps an angle into (−π, π].
#[inline]
pub fn wrap_pi(a: f64) -> f64 {
    // `rem_euclid` keeps the result in [0, 2π); shift so that π stays π and −π becomes π.
    let r = (a + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// The value congruent to `a` (mod 2π) nearest to `previous`: the endless-table unwrap of
/// Kelekçi (2021), eq. 5.5, in its general form, θᵢ = θᵢ₋₁ + wrap(θ_new − θᵢ₋₁).
/// 355° followed by 5° gives 365°.
#[inline]
pub fn unwrap_near(a: f64, previous: f64) -> f64 {
    let d = a - previous;
    // Fast path (the 1 ms loop): already the nearest turn, keep `a` bit for bit.
    if d.abs() <= PI {
        return a;
    }
    // Whole turns by truncation instead of a remainder (`fmod` cost more than the rest of a
    // trunnion inverse). The error is k·ulp(2π) ≈ k·1e-15 rad after k turns: 1e-9 rad
    // after a million turns of an endless table.
    if d.abs() < 1e15 {
        let k = (d * (1.0 / TAU)) as i64 as f64;
        let mut r = d - k * TAU;
        if r > PI {
            r -= TAU;
        } else if r <= -PI {
            r += TAU;
        }
        previous + r
    } else {
        previous + wrap_pi(d)
    }
}

/// The value congruent to `a` nearest to `previous` that lies inside `[min, max]`, or `None`.
///
/// Tries the shortest unwrap first and then one turn either way: with limits narrower than
/// two turns that covers every candidate that can be inside.
#[inline]
pub fn unwrap_within(a: f64, previous: f64, min: f64, max: f64) -> Option<f64> {
    let c0 = unwrap_near(a, previous);
    if c0 >= min && c0 <= max {
        return Some(c0);
    }
    // The shortest unwrap is out; the next-nearest turns are c0 ∓ 2π, nearest first.
    let (first, second) = if c0 > previous {
        (c0 - TAU, c0 + TAU)
    } else {
        (c0 + TAU, c0 - TAU)
    };
    if first >= min && first <= max {
        Some(first)
    } else if second >= min && second <= max {
        Some(second)
    } else {
        None
    }
}

/// Cephes' rational approximation of atan(t)/t − 1 on |t| ≤ 0.66: numerator and denominator
/// coefficients, shared by [`atan2`] and [`atan2_pair`].
const ATAN_P: [f64; 5] = [
    -8.750_608_600_031_904e-1,
    -1.615_753_718_733_365e1,
    -7.500_855_792_314_705e1,
    -1.228_866_684_490_136_2e2,
    -6.485_021_904_942_025e1,
];
const ATAN_Q: [f64; 5] = [
    2.485_846_490_142_306_3e1,
    1.650_270_098_316_988_6e2,
    4.328_810_604_912_903e2,
    4.853_903_996_359_137e2,
    1.945_506_571_482_614e2,
];
/// tan(3π/8), the bound of the steep reduction.
const T3P8: f64 = 2.414_213_562_373_095;
/// π/2 − fl(π/2), the bits of π/2 a double drops.
const MOREBITS: f64 = 6.123_233_995_736_766e-17;

/// The numerator polynomial of the rational, at z = t².
#[inline(always)]
fn atan_p(z: f64) -> f64 {
    let p = ATAN_P;
    (((p[0] * z + p[1]) * z + p[2]) * z + p[3]) * z + p[4]
}

/// The (monic) denominator polynomial of the rational, at z = t².
#[inline(always)]
fn atan_q(z: f64) -> f64 {
    let q = ATAN_Q;
    ((((z + q[0]) * z + q[1]) * z + q[2]) * z + q[3]) * z + q[4]
}

/// atan2 with the same accuracy as the C library's (checked against it to 1e-15 in the tests)
/// at a fraction of the cost: Cephes' `atan` (S. L. Moshier: rational approximation on
/// |t| ≤ 0.66 after reduction by tan(3π/8) and π/4), with the reduction applied to (y, x)
/// directly so no y/x is formed first (one division fewer), then the quadrant. The trunnion
/// and Y-Z-C-A inverses need two per pose, and libm's took a third of their time.
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() || !y.is_finite() {
        // zeros, infinities and NaN: the library's exact conventions
        return y.atan2(x);
    }
    let (ay, ax) = (y.abs(), x.abs());
    // atan(ay/ax) ∈ [0, π/2] = base + atan(t) with |t| ≤ 0.66
    let (base, t, extra) = if ay > T3P8 * ax {
        (std::f64::consts::FRAC_PI_2, -ax / ay, MOREBITS)
    } else if ay <= 0.66 * ax {
        (0.0, ay / ax, 0.0)
    } else {
        (
            std::f64::consts::FRAC_PI_4,
            (ay - ax) / (ay + ax),
            0.5 * MOREBITS,
        )
    };
    let z = t * t;
    let (p, q) = (atan_p(z), atan_q(z));
    let r = base + (t * (z * p / q) + t + extra);
    let r = if x < 0.0 { PI - r } else { r };
    if y.is_sign_negative() {
        -r
    } else {
        r
    }
}

/// Two atan2 at once, `[atan2(y[0], x[0]), atan2(y[1], x[1])]`: the tilt and the C angle that
/// every 5-axis inverse needs. The same Cephes rational as [`atan2`], written without
/// branches (each lane picks its reduction by selects) so that the two lanes run side by side
/// in one vector register: one division for the reduction and one for the rational serve both
/// angles. Arguments must be finite and not both zero in a lane (the models' unit tool axes
/// off the pole); a lane outside that falls back to the library.
#[inline(always)]
pub fn atan2_pair(y: [f64; 2], x: [f64; 2]) -> [f64; 2] {
    let ordinary = |i: usize| y[i].is_finite() && x[i].is_finite() && (y[i] != 0.0 || x[i] != 0.0);
    if !(ordinary(0) && ordinary(1)) {
        return [y[0].atan2(x[0]), y[1].atan2(x[1])];
    }
    let ay = [y[0].abs(), y[1].abs()];
    let ax = [x[0].abs(), x[1].abs()];
    let mut num = [0.0; 2];
    let mut den = [0.0; 2];
    let mut base = [0.0; 2];
    let mut extra = [0.0; 2];
    for i in 0..2 {
        let steep = ay[i] > T3P8 * ax[i];
        let flat = ay[i] <= 0.66 * ax[i];
        num[i] = if steep {
            -ax[i]
        } else if flat {
            ay[i]
        } else {
            ay[i] - ax[i]
        };
        den[i] = if steep {
            ay[i]
        } else if flat {
            ax[i]
        } else {
            ay[i] + ax[i]
        };
        base[i] = if steep {
            std::f64::consts::FRAC_PI_2
        } else if flat {
            0.0
        } else {
            std::f64::consts::FRAC_PI_4
        };
        extra[i] = if steep {
            MOREBITS
        } else if flat {
            0.0
        } else {
            0.5 * MOREBITS
        };
    }
    let t = [num[0] / den[0], num[1] / den[1]];
    let z = [t[0] * t[0], t[1] * t[1]];
    let mut out = [0.0; 2];
    let mut pz = [0.0; 2];
    let mut qz = [0.0; 2];
    for i in 0..2 {
        pz[i] = atan_p(z[i]);
        qz[i] = atan_q(z[i]);
    }
    let ratio = [pz[0] / qz[0], pz[1] / qz[1]];
    for i in 0..2 {
        let r = base[i] + (t[i] * (z[i] * ratio[i]) + t[i] + extra[i]);
        // x = −0 lands in the steep branch, where atan2 is ±π/2 either way.
        let r = if x[i] < 0.0 { PI - r } else { r };
        out[i] = if y[i].is_sign_negative() { -r } else { r };
    }
    out
}

/// Degrees to radians.
#[inline]
pub fn deg(a: f64) -> f64 {
    a.to_radians()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_range() {
        assert!((wrap_pi(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_pi(-PI) - PI).abs() < 1e-12);
        assert!((wrap_pi(0.5) - 0.5).abs() < 1e-15);
        assert!((wrap_pi(-0.5 - TAU) + 0.5).abs() < 1e-12);
    }

    /// Kelekçi (2021, §5.3.1): 0 … 355° then 5° is commanded as 365°.
    #[test]
    fn c_unwrap_355_to_5_is_365() {
        let c = unwrap_near(deg(5.0), deg(355.0));
        assert!((c.to_degrees() - 365.0).abs() < 1e-9, "{}", c.to_degrees());
        // and back down
        let c = unwrap_near(deg(355.0), deg(365.0));
        assert!((c.to_degrees() - 355.0).abs() < 1e-9);
    }

    /// The fast atan2 against the library's on a deterministic spread of arguments,
    /// including tiny, huge and axis-aligned ones.
    #[test]
    fn atan2_matches_libm() {
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut worst: f64 = 0.0;
        for i in 0..400_000 {
            let scale = 10f64.powi((i % 41) - 20);
            let (y, x) = (
                next() * scale,
                next() * if i % 7 == 0 { 1.0 } else { scale },
            );
            worst = worst.max((atan2(y, x) - y.atan2(x)).abs());
        }
        assert!(worst < 1e-15, "worst {worst:e}");
        for (y, x) in [
            (0.0, 0.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (1.0, f64::INFINITY),
            (f64::NAN, 1.0),
        ] {
            let (a, b) = (atan2(y, x), f64::atan2(y, x));
            assert!(a == b || (a.is_nan() && b.is_nan()), "{y} {x}: {a} vs {b}");
        }
        assert_eq!(atan2(1.0, -1.0), 0.75 * PI);
    }

    /// The pair against the library, lane by lane, including axis-aligned arguments.
    #[test]
    fn atan2_pair_matches_libm() {
        let mut state: u64 = 0x2545_F491_4F6C_DD1D;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            let scale = 10f64.powi((i % 21) - 10);
            let y = [next() * scale, next()];
            let x = [next(), next() * scale];
            let got = atan2_pair(y, x);
            for k in 0..2 {
                worst = worst.max((got[k] - y[k].atan2(x[k])).abs());
            }
        }
        assert!(worst < 1e-15, "worst {worst:e}");
        for (y, x) in [
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, -0.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (0.0, 1.0),
            (0.0, 0.0),
            (f64::NAN, 1.0),
        ] {
            let got = atan2_pair([y, 0.5], [x, -0.5]);
            let want = f64::atan2(y, x);
            assert!(
                got[0] == want || (got[0].is_nan() && want.is_nan()),
                "{y} {x}"
            );
            assert_eq!(got[1], f64::atan2(0.5, -0.5));
        }
    }

    #[test]
    fn unwrap_far_turns() {
        for turns in [1.0, 2.0, 7.0, -3.0, 1000.0, -123456.0] {
            for a in [-3.0, -1.0, 0.0, 0.5, 3.1] {
                let prev = 0.3 + turns * TAU;
                let got = unwrap_near(a, prev);
                assert!((got - prev).abs() <= PI + 1e-9, "{a} {prev} {got}");
                let k = ((got - a) / TAU).round();
                assert!(
                    (got - a - k * TAU).abs() < 1e-15 * (1.0 + turns.abs()) * 8.0,
                    "{a} {prev} {got}"
                );
            }
        }
    }

    #[test]
    fn unwrap_respects_limits() {
        // Limits [−200°, 200°], previous 170°, target −170°: shortest is 190° (inside).
        let c = unwrap_within(deg(-170.0), deg(170.0), deg(-200.0), deg(200.0)).unwrap();
        assert!((c.to_degrees() - 190.0).abs() < 1e-9);
        // Limits [−180°, 180°]: 190° is out, so go the long way to −170°.
        let c = unwrap_within(deg(-170.0), deg(170.0), deg(-180.0), deg(180.0)).unwrap();
        assert!((c.to_degrees() + 170.0).abs() < 1e-9);
        // Nothing inside a tiny window.
        assert!(unwrap_within(deg(90.0), 0.0, deg(-1.0), deg(1.0)).is_none());
    }
}
