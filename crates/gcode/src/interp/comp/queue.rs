//! The queue of compensated moves (LinuxCNC's `interp_queue`): a held move's end point is fixed
//! when the next move is known, and calls issued meanwhile wait behind it so the order of the
//! output is the order of the program.

use tezgah_geom::Pose;

use crate::canon::{Canon, CanonSink, Origin};
use crate::error::ErrorKind;

use super::super::Interpreter;
use super::{plane_axes, CompError};

/// A move or call waiting in the queue.
#[derive(Debug, Clone)]
pub(in crate::interp) enum Held {
    /// A call that does not move the tool.
    Call(Origin, Canon),
    /// A straight move; `direction` is the programmed direction in the compensation plane, to
    /// detect a move whose end is pulled back past its start.
    Straight {
        origin: Origin,
        rapid: bool,
        direction: [f64; 2],
        end: Pose,
    },
    /// An arc in the compensation plane.
    Arc(HeldArc),
}

/// An arc waiting in the queue, in the compensation plane's coordinates.
#[derive(Debug, Clone, Copy)]
pub(in crate::interp) struct HeldArc {
    pub origin: Origin,
    /// Programmed sweep (rad, + counter-clockwise); 0 for a corner arc, whose end never moves.
    pub sweep: f64,
    pub end: [f64; 2],
    pub center: [f64; 2],
    pub turn: i32,
    pub normal_end: f64,
    pub abc: [f64; 3],
}

impl Held {
    /// G20/G21 while held: lengths change unit (LinuxCNC's `qc_scale`).
    pub fn scale(&mut self, k: f64) {
        match self {
            Held::Call(..) => {}
            Held::Straight { end, .. } => *end = end.scale_linear(k),
            Held::Arc(a) => {
                for v in a.end.iter_mut().chain(a.center.iter_mut()) {
                    *v *= k;
                }
                a.normal_end *= k;
            }
        }
    }
}

/// Whether LinuxCNC holds a call of this kind behind queued moves (its `enqueue_*` calls);
/// every other call goes out at once.
pub(in crate::interp) fn is_held_kind(call: &Canon) -> bool {
    matches!(
        call,
        Canon::SetFeedRate(_)
            | Canon::Dwell(_)
            | Canon::SetFeedMode(_)
            | Canon::MistOn
            | Canon::MistOff
            | Canon::FloodOn
            | Canon::FloodOff
            | Canon::StartSpindle(_)
            | Canon::StopSpindle
            | Canon::SetSpindleMode(_)
            | Canon::SetSpindleSpeed(_)
            | Canon::OrientSpindle(_)
            | Canon::Comment(_)
    )
}

/// Signed angle (rad) swept from `start` to `end` about `center` by an arc of turn `turn`
/// (LinuxCNC's `find_turn`): in (0, 2π] plus full turns counter-clockwise, negative clockwise.
pub(super) fn find_turn(start: [f64; 2], center: [f64; 2], turn: i32, end: [f64; 2]) -> f64 {
    use std::f64::consts::TAU;
    if turn == 0 {
        return 0.0;
    }
    let mut alpha = (start[1] - center[1]).atan2(start[0] - center[0]);
    let mut beta = (end[1] - center[1]).atan2(end[0] - center[0]);
    if turn > 0 {
        if beta <= alpha {
            beta += TAU;
        }
        beta - alpha + f64::from(turn - 1) * TAU
    } else {
        if alpha <= beta {
            alpha += TAU;
        }
        beta - alpha + f64::from(turn + 1) * TAU
    }
}

impl Interpreter {
    /// Hold a move until the next one fixes its end.
    pub(super) fn hold(&mut self, held: Held) {
        self.comp.queue.push(held);
    }

    /// Send `call`, or hold it behind queued moves if it is of a kind LinuxCNC holds.
    pub(in crate::interp) fn emit_or_hold(&mut self, sink: &mut impl CanonSink, call: Canon) {
        if !self.comp.queue.is_empty() && is_held_kind(&call) {
            self.comp.queue.push(Held::Call(self.origin, call));
        } else {
            sink.call(self.origin, call);
        }
    }

    /// The first held item, if it is an arc (the corner rules depend on it).
    pub(super) fn held_arc(&self) -> Option<HeldArc> {
        match self.comp.queue.first() {
            Some(Held::Arc(a)) => Some(*a),
            _ => None,
        }
    }

    /// Send everything held, in order (LinuxCNC's `dequeue_canons`).
    pub(super) fn dequeue(&mut self, sink: &mut impl CanonSink) {
        self.comp.endpoint = None;
        for held in std::mem::take(&mut self.comp.queue) {
            match held {
                Held::Call(origin, call) => sink.call(origin, call),
                Held::Straight {
                    origin, rapid, end, ..
                } => sink.call(
                    origin,
                    if rapid {
                        Canon::StraightTraverse(end)
                    } else {
                        Canon::StraightFeed(end)
                    },
                ),
                Held::Arc(a) => sink.call(
                    a.origin,
                    Canon::ArcFeed {
                        first_end: a.end[0],
                        second_end: a.end[1],
                        first_axis: a.center[0],
                        second_axis: a.center[1],
                        rotation: a.turn,
                        axis_end: a.normal_end,
                        abc: a.abc,
                    },
                ),
            }
        }
    }

    /// Move the end of every held move to `to` (plane coordinates), refusing a move that would
    /// then run backwards or an arc that would sweep further than programmed (the tool would
    /// gouge), and send them; `to` is where the next move starts (LinuxCNC's
    /// `move_endpoint_and_flush`).
    pub(super) fn move_endpoint_and_flush(
        &mut self,
        to: [f64; 2],
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        if self.comp.queue.is_empty() {
            return Ok(());
        }
        let (a, b, _) = plane_axes(self.state.plane);
        let endpoint = self.comp.endpoint;
        let from = endpoint.unwrap_or([0.0; 2]);
        // How much further than programmed a moved arc may sweep (rad), as LinuxCNC 2.9 has it.
        let sweep_slack = if self.state.inches() { 0.001 } else { 0.0254 };
        for held in &mut self.comp.queue {
            match held {
                Held::Call(..) => {}
                Held::Arc(arc) => {
                    let r1 = (arc.end[0] - arc.center[0]).hypot(arc.end[1] - arc.center[1]);
                    let r2 = (to[0] - arc.center[0]).hypot(to[1] - arc.center[1]);
                    let sweep = find_turn(from, arc.center, arc.turn, to);
                    if (r1 - r2).abs() > 0.01 {
                        return Err(CompError::MismatchedRadii(r1, r2).into());
                    }
                    if arc.sweep != 0.0
                        && endpoint.is_some()
                        && sweep.abs() > arc.sweep.abs() + sweep_slack
                    {
                        return Err(CompError::ArcGouge.into());
                    }
                    arc.end = to;
                }
                Held::Straight {
                    rapid,
                    direction,
                    end,
                    ..
                } => {
                    let now = [to[0] - from[0], to[1] - from[1]];
                    let dot = direction[0] * now[0] + direction[1] * now[1];
                    if endpoint.is_some() && dot < 0.0 {
                        return Err(if *rapid {
                            CompError::TraverseGouge
                        } else {
                            CompError::FeedGouge
                        }
                        .into());
                    }
                    end.0[a] = to[0];
                    end.0[b] = to[1];
                }
            }
        }
        self.dequeue(sink);
        self.comp.endpoint = Some(to);
        Ok(())
    }
}
