//! Piecewise-constant-jerk motion as a knot table: the time and state where each phase starts,
//! and the end. Every [`super::Profile`] (the planner's, and the executor's JOG, homing, stops
//! and holds) is such a table; this is its one integration and its one walk, so every consumer
//! replays exactly the same numbers.
//!
//! Within a phase of jerk j, from (s, v, a): v(τ) = v + aτ + jτ²/2,
//! s(τ) = s + vτ + aτ²/2 + jτ³/6 (exact for constant jerk).

use super::State;

/// A knot: the time (s) and the state there; the state's jerk is that of the phase starting
/// at the knot (0 at the end knot).
pub type Knot = (f64, State);

/// Integrates the phases (`durations[k]` ≥ 0 s at jerk `jerks[k]`) from `start` (its jerk is
/// ignored) into `knots`: knot k where phase k starts, the last knot the end (jerk 0).
/// `knots` is one longer than the phases; a shorter table keeps the phases that fit.
pub fn integrate(start: State, durations: &[f64], jerks: &[f64], knots: &mut [Knot]) {
    let Some((end, starts)) = knots.split_last_mut() else {
        return;
    };
    let (mut t, mut x) = (0.0, State { j: 0.0, ..start });
    for ((knot, &dt), &j) in starts.iter_mut().zip(durations).zip(jerks) {
        *knot = (t, State { j, ..x });
        x = advance(x, j, dt);
        t += dt;
    }
    *end = (t, State { j: 0.0, ..x });
}

/// The state at `t` on the table: exact on each phase (the last phase that starts at or
/// before `t`, so phases of zero duration are passed over); from the end knot on, the position
/// runs on at the end speed and the rest of the state is the end knot's (the tables here end
/// at zero acceleration); before the start (or NaN) it is `before()`, which the caller words
/// (the start state, with the jerk it chooses).
pub fn state_at(knots: &[Knot], t: f64, before: impl FnOnce() -> State) -> State {
    let Some(&(t_end, end)) = knots.last() else {
        return before();
    };
    if t >= t_end {
        return State {
            s: end.s + end.v * (t - t_end),
            ..end
        };
    }
    if t.is_nan() || t <= 0.0 {
        return before();
    }
    let phases = &knots[..knots.len() - 1];
    let k = (0..phases.len())
        .rev()
        .find(|&k| phases[k].0 <= t)
        .unwrap_or(0);
    match phases.get(k) {
        Some(&(t0, x)) => advance(x, x.j, t - t0),
        None => before(),
    }
}

/// Integrates a constant-jerk phase of length `dt` (the module comment's cubic).
pub fn advance(x: State, j: f64, dt: f64) -> State {
    State {
        s: x.s + dt * (x.v + dt * (0.5 * x.a + dt * j / 6.0)),
        v: x.v + dt * (x.a + 0.5 * dt * j),
        a: x.a + dt * j,
        j,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Walking the table lands on every knot and is continuous across it, for random
        /// phases (zero durations included).
        #[test]
        fn walk_is_continuous_through_the_knots(
            v0 in -100.0..100.0f64,
            a0 in -1000.0..1000.0f64,
            durations in proptest::collection::vec(prop_oneof![Just(0.0), 0.0..0.2f64], 5),
            jerks in proptest::collection::vec(-5e4..5e4f64, 5),
        ) {
            let start = State { s: 1.0, v: v0, a: a0, j: 0.0 };
            let mut knots = [(0.0, State::default()); 6];
            integrate(start, &durations, &jerks, &mut knots);
            let total: f64 = durations.iter().sum();
            prop_assert!((knots[5].0 - total).abs() <= 1e-15 * (1.0 + total));
            prop_assert_eq!(knots[5].1.j, 0.0);
            for &(t, x) in &knots[1..] {
                if t <= 0.0 {
                    continue;
                }
                let left = state_at(&knots, t * (1.0 - 1e-12), || start);
                let tol = 1e-6 * (1.0 + x.s.abs() + x.v.abs() + x.a.abs());
                prop_assert!((left.s - x.s).abs() < tol, "{left:?} {x:?}");
                prop_assert!((left.v - x.v).abs() < tol);
                prop_assert!((left.a - x.a).abs() < tol);
            }
            prop_assert_eq!(state_at(&knots, -1.0, || start), start);
            prop_assert_eq!(state_at(&knots, f64::NAN, || start), start);
        }
    }

    #[test]
    fn one_phase_is_the_cubic() {
        // s = 1 + 2t + 3t²/2 + 4t³/6 at t = 0.5: 1 + 1 + 0.375 + 0.083333…
        let start = State {
            s: 1.0,
            v: 2.0,
            a: 3.0,
            j: 0.0,
        };
        let mut knots = [(0.0, State::default()); 2];
        integrate(start, &[1.0], &[4.0], &mut knots);
        let x = state_at(&knots, 0.5, || start);
        assert!((x.s - (2.375 + 4.0 / 48.0)).abs() < 1e-15);
        assert!((x.v - (2.0 + 1.5 + 0.5)).abs() < 1e-15);
        assert!((x.a - 5.0).abs() < 1e-15 && x.j == 4.0);
        // After the end: on at the end speed 2 + 3 + 2 = 7, the end knot's a = 7 and jerk 0
        // otherwise (this phase does not end at rest in acceleration).
        let e = knots[1].1;
        let after = state_at(&knots, 3.0, || start);
        assert_eq!((after.v, after.a, after.j), (7.0, 7.0, 0.0));
        assert!((after.s - (e.s + 14.0)).abs() < 1e-12);
    }
}
