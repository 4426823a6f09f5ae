//! Feed hold (and abort) as a stop along the path: from the re-timed state where the command
//! meets the plan (ṡ, s̈), the time-optimal jerk-limited stop under the path limits of the piece
//! in hand (the one profile solver's velocity interface to speed 0, Kröger & Wahl's
//! velocity-to-zero case as Ruckig solves it), played along the same path; at rest the plan's time τ is found where the
//! stop ended, and resume re-times the plan from r = 0 there.
//!
//! A piece's limits hold for any speed up to its V, so the stop is admissible inside it. One
//! that runs past the piece's end continues into the next piece (if planned already) with a
//! new stop from the state at the junction under that piece's limits, provided the junction is
//! passed no faster than the plan passes it and the path acceleration there fits the
//! junction's reserve (the planner's own test for a junction inside one profile,
//! `inside_group`). Otherwise, or past two pieces, the time scale brakes r to 0 along the plan
//! (`scale.rs`), which slows for what lies ahead anyway.

use tezgah_motion::plan::limits::{analyse, inside_group};
use tezgah_motion::plan::{Piece, Planned};
use tezgah_motion::{Junction, Profile, State};

use super::{Current, Executor, Produced};
use crate::command::RunState;
use crate::error::ExecError;
use crate::job::PlannedItem;
use crate::scale::TimeScale;

/// A path stop in progress: its leg in the piece in hand and, if it crosses into the next
/// piece, the leg there.
#[derive(Debug, Clone, Copy)]
pub(super) struct Hold {
    first: Profile,
    /// Path coordinate in the piece where the first leg starts.
    s0: f64,
    /// The second leg and the time into the hold where it starts (the junction).
    second: Option<(Profile, f64)>,
    /// Time into the hold, s.
    t: f64,
    /// Whether the tool has passed into the second leg's piece.
    crossed: bool,
}

impl Hold {
    fn duration(&self) -> f64 {
        match self.second {
            Some((stop, at)) => at + stop.duration(),
            None => self.first.duration(),
        }
    }
}

/// Slack on the acceleration limit for rounding (the time scale keeps |s̈| ≤ A(1 + 1e-9)).
const SLACK: f64 = 1e-9;

/// The plan's time where it reaches path coordinate `s` at or after `from` (s non-decreasing:
/// the plan never runs backward), by bisection to the last bit.
fn time_at(profile: &Profile, s: f64, from: f64) -> f64 {
    let (mut lo, mut hi) = (from, profile.duration());
    if profile.state_at(hi).s <= s {
        return hi;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if profile.state_at(mid).s < s {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The time into `stop` where it has run `distance`, by bisection (s is non-decreasing).
fn time_to(stop: &Profile, distance: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, stop.duration());
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if stop.state_at(mid).s < distance {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

impl Executor {
    /// Starts a path stop if the state where the hold meets the plan allows one that ends
    /// inside the piece in hand or the next; false leaves the stop to the time scale.
    pub(super) fn begin_hold(&mut self) -> bool {
        let Some(Current::Piece { cursor, tau, .. }) = &self.current else {
            return false;
        };
        if self.scale.is_stopped() {
            return false;
        }
        let piece = cursor.piece();
        let st = piece.profile.state_at(*tau);
        let (r, rd) = (self.scale.r, self.scale.rate);
        let here = State {
            s: st.s,
            v: r * st.v,
            a: rd * st.v + r * r * st.a,
            j: 0.0,
        };
        let Some(first) = crate::stop::path_stop(&here, &piece.limits) else {
            return false;
        };
        let left = piece.length() - st.s;
        let second = if first.distance() < left {
            None
        } else {
            match self.second_leg(piece, &first, left) {
                Some(leg) => Some(leg),
                None => return false,
            }
        };
        self.hold = Some(Hold {
            first,
            s0: st.s,
            second,
            t: 0.0,
            crossed: false,
        });
        true
    }

    /// The leg in the next piece of a stop that reaches the end of `piece` after `left`.
    fn second_leg(&self, piece: &Piece, first: &Profile, left: f64) -> Option<(Profile, f64)> {
        let Some(PlannedItem {
            item: Planned::Motion(next),
            ..
        }) = &self.peeked
        else {
            return None;
        };
        let (last, head) = (piece.segments.last()?, next.segments.first()?);
        if piece.end_junction() == Junction::Stop {
            return None;
        }
        let at = time_to(first, left);
        let x = first.state_at(at);
        // No faster than the plan passes the junction (its cap holds up to that speed).
        if x.v > piece.profile.end().v * (1.0 + SLACK) {
            return None;
        }
        // A piece that ends part way along its segment (a speed step) meets the next inside
        // that segment, where nothing jumps; elsewhere the joint velocities may step.
        if !piece.partial_end {
            let (ga, gb) = (
                analyse(last, &self.machine).ok()?,
                analyse(head, &self.machine).ok()?,
            );
            if !inside_group(&ga, &gb, x.a.abs(), &self.machine, &self.options.plan()) {
                return None;
            }
        }
        let second = crate::stop::path_stop(&x, &next.limits)?;
        (second.distance() < next.length()).then_some((second, at))
    }

    /// One period of the path stop; at its end the plan's time is set where it stopped and
    /// the time scale waits at 0 (held, or resumed already, or the abort's end).
    pub(super) fn step_hold(&mut self) -> Result<Option<Produced>, ExecError> {
        let Some(mut hold) = self.hold else {
            return Ok(None);
        };
        hold.t += self.options.period;
        let x = match hold.second {
            Some((stop, at)) if hold.t >= at => {
                if !hold.crossed {
                    // Into the next piece (the peeked one becomes the piece in hand).
                    self.finish_piece()?;
                    self.fetch()?;
                    hold.crossed = true;
                }
                stop.state_at(hold.t - at)
            }
            _ => {
                let x = hold.first.state_at(hold.t);
                State {
                    s: hold.s0 + x.s,
                    ..x
                }
            }
        };
        self.sample_at(x.s)?;
        // The plan's time follows the tool (where resume starts), and the status' time scale
        // reads the stop's speed over the plan's there.
        if let Some(Current::Piece { cursor, tau, .. }) = self.current.as_mut() {
            let profile = &cursor.piece().profile;
            *tau = time_at(profile, x.s, *tau);
            let v = profile.state_at(*tau).v;
            self.scale.r = if v > 0.0 { x.v / v } else { 0.0 };
            self.scale.rate = 0.0;
        }
        if hold.t < hold.duration() {
            self.hold = Some(hold);
            return Ok(Some(self.emit(false, x.v)));
        }
        self.hold = None;
        self.scale = TimeScale::held();
        match self.state {
            RunState::Holding => self.state = RunState::Held,
            RunState::Aborting => self.drop_job(),
            // Resumed while stopping: the time scale starts from rest next period.
            _ => {}
        }
        Ok(Some(self.emit(true, 0.0)))
    }
}
