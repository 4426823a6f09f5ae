//! Properties of the profile solver on random moves, without an oracle: limits held at samples,
//! end state reached, position monotone (v ≥ 0), duration above simple lower bounds; reachable
//! speeds are accepted back; no input, however bad, panics.

use proptest::prelude::*;
use tezgah_motion::profile::{
    max_reachable_speed, min_reachable_speed, min_stopping_distance, solve, speed_change_distance,
    speed_change_time, Limits, ProfileError,
};

/// Limits over several decades, start/end speeds as fractions of V (often exactly 0 or V), and
/// a distance relative to the move's natural scale.
fn move_case() -> impl Strategy<Value = (f64, f64, f64, Limits)> {
    let frac = prop_oneof![Just(0.0), Just(1.0), 0.0..=1.0f64];
    (
        -0.5..3.0f64,
        0.5..4.5f64,
        1.5..6.5f64,
        frac.clone(),
        frac,
        -4.0..2.0f64,
    )
        .prop_map(|(lv, la, lj, f0, f1, ld)| {
            let limits = Limits::new(10f64.powf(lv), 10f64.powf(la), 10f64.powf(lj)).unwrap();
            let vmax = limits.max_velocity();
            let (v0, v1) = (f0 * vmax, f1 * vmax);
            let scale = speed_change_distance(v0, v1, &limits).unwrap()
                + speed_change_distance(0.0, vmax, &limits).unwrap();
            (scale * 10f64.powf(ld), v0, v1, limits)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn solved_profiles_hold_limits_and_reach_the_end(case in move_case()) {
        let (distance, v0, v1, l) = case;
        let (vm, am, jm) = (l.max_velocity(), l.max_acceleration(), l.max_jerk());
        match solve(distance, v0, v1, &l) {
            Ok(p) => {
                let t_end = p.duration();
                let mut last_s = 0.0;
                for i in 0..=64 {
                    let x = p.state_at(t_end * i as f64 / 64.0);
                    prop_assert!(x.v <= vm * (1.0 + 1e-9) && x.v >= -1e-9 * vm, "{x:?}");
                    prop_assert!(x.a.abs() <= am * (1.0 + 1e-9), "{x:?}");
                    prop_assert!(x.j.abs() <= jm * (1.0 + 1e-9), "{x:?}");
                    prop_assert!(x.s >= last_s - 1e-12 * distance, "position went back: {x:?}");
                    last_s = x.s;
                }
                let e = p.state_at(t_end);
                prop_assert!((e.s - distance).abs() <= 1e-9 * distance, "{e:?}");
                prop_assert!((e.v - v1).abs() <= 1e-9 * vm, "{e:?}");
                prop_assert!(e.a.abs() <= 1e-9 * am, "{e:?}");
                // Lower bounds: never faster than V, never a faster speed change than the
                // time-optimal ramp (which itself is ≥ |Δv|/A).
                let slack = 1.0 - 1e-12;
                prop_assert!(t_end >= distance / vm * slack);
                let ramp = speed_change_time(v0, v1, &l).unwrap();
                prop_assert!(t_end >= ramp * slack);
                prop_assert!(ramp >= (v1 - v0).abs() / am * slack);
                prop_assert!(p.durations().iter().all(|d| *d >= 0.0));
            }
            Err(ProfileError::EndSpeedUnreachable { reachable, .. }) => {
                // Neither a single ramp nor a stop-and-go fits in the distance ...
                let direct = speed_change_distance(v0, v1, &l).unwrap();
                let stop_go = min_stopping_distance(v0, &l).unwrap()
                    + speed_change_distance(0.0, v1, &l).unwrap();
                prop_assert!(distance < direct && distance < stop_go);
                // ... and the reported speed is reachable, on v0's side of the request.
                prop_assert!(solve(distance, v0, reachable, &l).is_ok());
                if v1 > v0 {
                    prop_assert!(reachable >= v0 && reachable < v1);
                } else {
                    prop_assert!(reachable <= v0 && reachable > v1);
                }
            }
            Err(e) => prop_assert!(false, "unexpected {e}"),
        }
    }

    #[test]
    fn reachable_speed_bounds_are_tight(case in move_case()) {
        let (distance, v0, _, l) = case;
        let vm = l.max_velocity();
        let up = max_reachable_speed(v0, distance, &l).unwrap();
        prop_assert!(up >= v0 && up <= vm);
        prop_assert!(solve(distance, v0, up, &l).is_ok());
        let above = up + 1e-6 * vm;
        if above <= vm {
            let r = solve(distance, v0, above, &l);
            let unreachable = matches!(r, Err(ProfileError::EndSpeedUnreachable { .. }));
            prop_assert!(unreachable, "{above} should be out of reach");
        }
        let down = min_reachable_speed(v0, distance, &l).unwrap();
        prop_assert!(down <= v0 && down >= 0.0);
        prop_assert!(solve(distance, v0, down, &l).is_ok());
        let below = down - 1e-6 * vm;
        if below >= 0.0 {
            // Just below the braking bound only a stop-and-go could still fit.
            let stop_go = min_stopping_distance(v0, &l).unwrap()
                + speed_change_distance(0.0, below, &l).unwrap();
            prop_assert!(solve(distance, v0, below, &l).is_ok() == (stop_go <= distance));
        }
    }

    #[test]
    fn bad_input_is_a_named_error_not_a_panic(
        d in prop::num::f64::ANY,
        v0 in prop::num::f64::ANY,
        v1 in prop::num::f64::ANY,
        lv in prop::num::f64::ANY,
        la in prop::num::f64::ANY,
        lj in prop::num::f64::ANY,
    ) {
        if let Ok(l) = Limits::new(lv, la, lj) {
            let r = solve(d, v0, v1, &l);
            let valid = d.is_finite() && d >= 0.0
                && (0.0..=lv).contains(&v0) && (0.0..=lv).contains(&v1);
            if !valid {
                let named = matches!(r, Err(ProfileError::Distance(_) | ProfileError::Speed { .. }));
                prop_assert!(named, "{r:?}");
            }
            let _ = max_reachable_speed(v0, d, &l);
            let _ = min_reachable_speed(v0, d, &l);
            let _ = min_stopping_distance(v0, &l);
        }
    }
}

#[test]
fn degenerate_moves() {
    let l = Limits::new(50.0, 1000.0, 20000.0).unwrap();
    // Nothing to do.
    let p = solve(0.0, 0.0, 0.0, &l).unwrap();
    assert_eq!((p.duration(), p.distance()), (0.0, 0.0));
    let p = solve(0.0, 20.0, 20.0, &l).unwrap();
    assert_eq!((p.duration(), p.distance()), (0.0, 0.0));
    // A speed change needs distance.
    assert!(matches!(
        solve(0.0, 0.0, 10.0, &l),
        Err(ProfileError::EndSpeedUnreachable { reachable, .. }) if reachable == 0.0
    ));
    // Pure cruise at V.
    let p = solve(10.0, 50.0, 50.0, &l).unwrap();
    assert!((p.duration() - 0.2).abs() < 1e-15 && p.durations()[3] == 0.2);
    // From a low speed to a high one in less than a single ramp's distance: stopping first is
    // shorter (time grows like √Δv), so the profile slows down, then speeds up.
    let direct = speed_change_distance(0.1, 40.0, &l).unwrap();
    let stop_go =
        min_stopping_distance(0.1, &l).unwrap() + speed_change_distance(0.0, 40.0, &l).unwrap();
    assert!(stop_go < direct);
    let p = solve(0.5 * (stop_go + direct), 0.1, 40.0, &l).unwrap();
    assert!(p.jerks()[0] < 0.0 && (p.end().v - 40.0).abs() < 1e-9);
    // Limits are validated by name.
    assert!(Limits::new(1.0, f64::NAN, 1.0).is_err());
    assert!(matches!(
        solve(1.0, 60.0, 0.0, &l),
        Err(ProfileError::Speed { value, .. }) if value == 60.0
    ));
    assert!(matches!(
        solve(-1.0, 0.0, 0.0, &l),
        Err(ProfileError::Distance(_))
    ));
}
