//! Angle helpers shared by the rotary models: wrapping, shortest unwrap next to the previous
//! joint value, and choosing a turn that respects limits. Used by `yzca` and the trunnions
//! when the inverse picks among solutions by continuity (reference 000 §2.9, eq. 5.5).

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
/// reference 000 eq. 5.5 in its general form, θᵢ = θᵢ₋₁ + wrap(θ_new − θᵢ₋₁).
/// 355° followed by 5° gives 365°.
#[inline]
pub fn unwrap_near(a: f64, previous: f64) -> f64 {
    let d = a - previous;
    // Fast path (the 1 ms loop): already the nearest turn, keep `a` bit for bit.
    if d.abs() <= PI {
        a
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

    /// Reference 000 §5 item 17: 0 … 355° then 5° is commanded as 365°.
    #[test]
    fn c_unwrap_355_to_5_is_365() {
        let c = unwrap_near(deg(5.0), deg(355.0));
        assert!((c.to_degrees() - 365.0).abs() < 1e-9, "{}", c.to_degrees());
        // and back down
        let c = unwrap_near(deg(355.0), deg(365.0));
        assert!((c.to_degrees() - 355.0).abs() < 1e-9);
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
