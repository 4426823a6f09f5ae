//! Look-ahead: segments are grouped, junction speeds chosen by a backward pass (the plan can
//! always stop by the end of the window) and a forward pass, and each group is timed by one
//! [`Profile`] from its entry to its exit speed.
//!
//! Why groups: a profile has zero acceleration at both ends, so one profile per short segment
//! would re-ramp the acceleration at every junction and a dense program could hardly speed up.
//! Consecutive segments whose limits are close (within [`PlanOptions::group_ratio`]) and whose
//! junctions allow it share one profile under the tightest of their limits; speed may pass many
//! junctions per period (no per-segment cap). Memory is bounded by `window × max_group`.

use std::collections::VecDeque;
use std::sync::Arc;

use super::joints::PlanMachine;
use super::limits::{
    analyse, cruise_limits, has_jump, inside_group, junction_cap, ladder, segment_limits_between,
    segment_top, Geometry, PlanOptions, SegmentLimits,
};
use super::PlanError;
use crate::path::{Junction, PathItem, Segment};
use crate::profile::{max_reachable_speed, max_start_speed, solve, solve_at_most, Limits, Profile};

/// A timed group of segments. The first may be entered, and the last left, part way along
/// (a long curved segment's speed steps, [`ladder`]): a segment's own path coordinate is the
/// piece's minus its offset.
#[derive(Debug, Clone)]
pub struct Piece {
    pub segments: Vec<Arc<Segment>>,
    /// Piece path coordinate where each segment's own coordinate is 0 (negative for a first
    /// segment entered part way), from 0 at the piece's start.
    pub offsets: Vec<f64>,
    /// Each segment's own path coordinate where the piece leaves it: its length (mm, or
    /// degrees for a rotary-only move), or less for a last segment left part way.
    pub lengths: Vec<f64>,
    pub profile: Profile,
    pub limits: Limits,
    /// Whether the piece ends before its last segment does.
    pub partial_end: bool,
}

impl Piece {
    /// Total path length.
    pub fn length(&self) -> f64 {
        self.offsets.last().copied().unwrap_or(0.0) + self.lengths.last().copied().unwrap_or(0.0)
    }

    /// What joins the piece to the next: its last segment's end junction, or smooth where
    /// the piece ends part way along it.
    pub fn end_junction(&self) -> Junction {
        match self.segments.last() {
            Some(s) if !self.partial_end => s.end,
            _ => Junction::Smooth,
        }
    }
}

/// What the planner emits, in program order.
#[derive(Debug, Clone)]
pub enum Planned {
    Motion(Box<Piece>),
    Dwell { seconds: f64, line: u32 },
    Stop { line: u32 },
}

/// Consecutive segments timed by one profile, each with its own path coordinate where the
/// profile enters and leaves it (the first may be entered, the last left, part way along).
struct Stretches {
    segments: Vec<Arc<Segment>>,
    starts: Vec<f64>,
    ends: Vec<f64>,
    /// Whether the last segment is left part way (a speed step follows on it).
    partial_end: bool,
}

impl Stretches {
    /// The stretch `range` of `seg` alone.
    fn one(seg: Arc<Segment>, range: (f64, f64), partial_end: bool) -> Stretches {
        Stretches {
            segments: vec![seg],
            starts: vec![range.0],
            ends: vec![range.1],
            partial_end,
        }
    }

    fn push(&mut self, seg: Arc<Segment>, range: (f64, f64)) {
        self.segments.push(seg);
        self.starts.push(range.0);
        self.ends.push(range.1);
    }

    fn length(&self) -> f64 {
        self.starts.iter().zip(&self.ends).map(|(a, b)| b - a).sum()
    }

    fn line(&self) -> u32 {
        self.segments.first().map_or(0, |s| line_of(s))
    }
}

struct Group {
    stretches: Stretches,
    length: f64,
    limits: Limits,
    end_cap: f64,
    /// Highest entry speed from which the rest of the window can still stop (backward pass):
    /// the bound the forward pass must respect; NaN until computed.
    backward: f64,
    /// Highest entry speed from which the end speed aimed at is reached in one ramp (at most
    /// `backward`): the entry speed the forward pass aims at; NaN until computed.
    aimed: f64,
}

enum Entry {
    Group(Group),
    Dwell { seconds: f64, line: u32 },
    Stop { line: u32 },
}

struct Open {
    stretches: Stretches,
    v: f64,
    a: f64,
    j: f64,
    last: Geometry,
    last_end_cap: f64,
}

impl Open {
    /// A group of one stretch `range` of `seg` (its own path coordinate) under `limits`.
    fn new(
        seg: Arc<Segment>,
        range: (f64, f64),
        limits: &Limits,
        geom: Geometry,
        end_cap: f64,
        partial_end: bool,
    ) -> Open {
        Open {
            stretches: Stretches::one(seg, range, partial_end),
            v: limits.max_velocity(),
            a: limits.max_acceleration(),
            j: limits.max_jerk(),
            last: geom,
            last_end_cap: end_cap,
        }
    }
}

/// The last segment pushed, held until the next one decides its end junction.
struct Held {
    seg: Segment,
    geom: Geometry,
    /// A jump at its start costs it a jerk reserve.
    jump: bool,
    /// The most it can be entered at: the cap of the junction at its start and the previous
    /// segment's top speed ([`SegmentLimits::top`]; 0 after a rest).
    start_cap: f64,
    /// Its top speed ([`SegmentLimits::top`]), once computed (a junction check needs it).
    top: Option<f64>,
}

/// The streaming planner: `push` path items, take [`Planned`] items with `pop`.
pub struct Planner {
    machine: PlanMachine,
    options: PlanOptions,
    pending: Option<Held>,
    open: Option<Open>,
    window: VecDeque<Entry>,
    out: VecDeque<Planned>,
    v_start: f64,
}

fn line_of(seg: &Segment) -> u32 {
    seg.line
}

impl Planner {
    pub fn new(machine: PlanMachine, options: PlanOptions) -> Result<Self, PlanError> {
        options.validate()?;
        Ok(Planner {
            machine,
            options,
            pending: None,
            open: None,
            window: VecDeque::new(),
            out: VecDeque::new(),
            v_start: 0.0,
        })
    }

    pub fn options(&self) -> &PlanOptions {
        &self.options
    }

    /// Takes one path item.
    pub fn push(&mut self, item: PathItem) -> Result<(), PlanError> {
        match item {
            PathItem::Segment(seg) => self.push_segment(seg),
            PathItem::Dwell { seconds, line } => {
                if !(seconds.is_finite() && seconds >= 0.0) {
                    return Err(PlanError::BadDwell { line, seconds });
                }
                self.end_here()?;
                self.window.push_back(Entry::Dwell { seconds, line });
                self.commit_full()
            }
            PathItem::Stop { line } => {
                self.end_here()?;
                self.window.push_back(Entry::Stop { line });
                self.commit_full()
            }
        }
    }

    /// End of the stream: plan everything to a stop.
    pub fn finish(&mut self) -> Result<(), PlanError> {
        self.end_here()?;
        while !self.window.is_empty() {
            self.commit_front()?;
        }
        Ok(())
    }

    /// The next planned item, if one is committed.
    pub fn pop(&mut self) -> Option<Planned> {
        self.out.pop_front()
    }

    fn push_segment(&mut self, mut seg: Segment) -> Result<(), PlanError> {
        // A block that only turns the tool under TCP is timed by the tool axis's turn.
        seg.tool_axis_travel = self.machine.tool_axis_sweep(&seg);
        let geom = analyse(&seg, &self.machine)?;
        if geom.length <= 0.0 {
            return Ok(());
        }
        let mut top_here = None;
        let (start_jump, start_cap) = match self.pending.take() {
            Some(mut held) => {
                // The junction's cap, whether it jumps, and the slower of the two segments'
                // top speeds there (how fast the junction can be passed at most).
                let (cap, jump, through) = match held.seg.end {
                    Junction::Corner | Junction::Stop => (0.0, false, 0.0),
                    Junction::Tangent | Junction::Smooth => {
                        let cap = junction_cap(&held.geom, &geom, &self.machine, &self.options);
                        let jump = has_jump(&held.geom, &geom, &self.machine);
                        // A jump that allows only a crawl is cheaper as a stop: no reserve
                        // is then kept on the two segments.
                        let before = held.top.unwrap_or_else(|| self.top(&held.seg, &held.geom));
                        let after = self.top(&seg, &geom);
                        held.top = Some(before);
                        top_here = Some(after);
                        let slower = before.min(after);
                        let floor = self.options.min_junction_share * slower;
                        if jump && cap < floor {
                            (0.0, false, 0.0)
                        } else {
                            (cap, jump, cap.min(slower))
                        }
                    }
                };
                let reserve = held.jump || jump;
                self.add(held, reserve, cap, through)?;
                (jump, through)
            }
            None => (false, 0.0),
        };
        self.pending = Some(Held {
            seg,
            geom,
            jump: start_jump,
            start_cap,
            top: top_here,
        });
        Ok(())
    }

    /// The motion stops here (dwell, stop, end): the held segment ends at speed 0.
    fn end_here(&mut self) -> Result<(), PlanError> {
        if let Some(held) = self.pending.take() {
            let reserve = held.jump;
            self.add(held, reserve, 0.0, 0.0)?;
        }
        if let Some(open) = self.open.take() {
            self.close(open, 0.0)?;
        }
        Ok(())
    }

    /// A segment's top speed ([`SegmentLimits::top`]).
    fn top(&self, seg: &Segment, geom: &Geometry) -> f64 {
        segment_top(seg, geom, &self.machine, &self.options)
    }

    /// Adds the held segment, `end_cap` the cap of its end junction and `end_speed` the most
    /// it can be left at (the cap, and the next segment's top speed).
    fn add(
        &mut self,
        held: Held,
        reserve: bool,
        end_cap: f64,
        end_speed: f64,
    ) -> Result<(), PlanError> {
        let Held {
            seg,
            geom,
            start_cap,
            ..
        } = held;
        let sl = segment_limits_between(
            &seg,
            &geom,
            &self.machine,
            &self.options,
            reserve,
            (start_cap, end_speed),
        )?;
        // With speed steps at its ends, the cruise only changes speed by the last step.
        let cruise = if may_step(&geom, &sl.limits, &self.machine, start_cap.min(end_speed)) {
            cruise_limits(&seg, &geom, &self.machine, &self.options, reserve)?
        } else {
            sl
        };
        let step = |from| {
            ladder(
                &geom,
                &self.machine,
                &self.options,
                reserve,
                &cruise.limits,
                from,
            )
        };
        let (up, down) = if may_step(&geom, &sl.limits, &self.machine, start_cap.min(end_speed)) {
            (step(start_cap), step(end_speed))
        } else {
            (vec![], vec![])
        };
        let seg = Arc::new(seg);
        if up.is_empty() && down.is_empty() {
            return self.add_span(seg, (0.0, geom.length), geom, sl, end_cap);
        }
        let sl = cruise;
        // Speed steps up at the start, the cruise, steps down at the end; each is a group of
        // its own (joined, they would share the smallest acceleration again).
        let climb: f64 = up.iter().chain(&down).map(|s| s.0).sum();
        let mut spans: Vec<(f64, Limits)> = up;
        spans.push((geom.length - climb, sl.limits));
        spans.extend(down.iter().rev().copied());
        let mut at = 0.0;
        let last = spans.len() - 1;
        for (k, (d, limits)) in spans.into_iter().enumerate() {
            let end = if k == last { geom.length } else { at + d };
            let cap = if k == last { end_cap } else { f64::INFINITY };
            self.open_anew(Open::new(
                seg.clone(),
                (at, end),
                &limits,
                geom,
                cap,
                k != last,
            ))?;
            at = end;
        }
        // The last step ends the segment: the next may join it only as any segment would.
        if end_cap <= 0.0 {
            if let Some(o) = self.open.take() {
                self.close(o, 0.0)?;
            }
        }
        Ok(())
    }

    /// Adds the stretch `range` of a segment (its own path coordinate) to the open group, or
    /// closes that group and opens a new one.
    fn add_span(
        &mut self,
        seg: Arc<Segment>,
        range: (f64, f64),
        geom: Geometry,
        sl: SegmentLimits,
        end_cap: f64,
    ) -> Result<(), PlanError> {
        let (v, a, j) = (
            sl.limits.max_velocity(),
            sl.limits.max_acceleration(),
            sl.limits.max_jerk(),
        );
        let r = self.options.group_ratio;
        let joins = |o: &Open| {
            let vg = o.v.min(v).min(o.last_end_cap);
            let close = |x: f64, y: f64, m: f64| m >= r * x.max(y);
            o.stretches.segments.len() < self.options.max_group
                && o.last_end_cap > 0.0
                && close(o.v, v, vg)
                && close(o.a, a, o.a.min(a))
                && close(o.j, j, o.j.min(j))
                && inside_group(&o.last, &geom, o.a.max(a), &self.machine, &self.options)
        };
        match self.open.take() {
            Some(mut o) if joins(&o) && !o.stretches.partial_end => {
                o.v = o.v.min(v).min(o.last_end_cap);
                o.a = o.a.min(a);
                o.j = o.j.min(j);
                o.stretches.push(seg, range);
                o.last = geom;
                o.last_end_cap = end_cap;
                self.open = Some(o);
            }
            other => {
                self.open = other;
                self.open_anew(Open::new(seg, range, &sl.limits, geom, end_cap, false))?;
            }
        }
        if end_cap <= 0.0 {
            if let Some(o) = self.open.take() {
                self.close(o, 0.0)?;
            }
        }
        Ok(())
    }

    /// Closes the open group at its last junction's cap and opens `o` in its place.
    fn open_anew(&mut self, o: Open) -> Result<(), PlanError> {
        if let Some(old) = self.open.replace(o) {
            let cap = old.last_end_cap;
            self.close(old, cap)?;
        }
        Ok(())
    }

    fn close(&mut self, o: Open, end_cap: f64) -> Result<(), PlanError> {
        let line = o.stretches.line();
        let limits = Limits::new(o.v, o.a, o.j).map_err(|e| PlanError::NoLimit {
            line,
            reason: e.to_string(),
        })?;
        let length = o.stretches.length();
        self.window.push_back(Entry::Group(Group {
            stretches: o.stretches,
            length,
            limits,
            end_cap,
            backward: f64::NAN,
            aimed: f64::NAN,
        }));
        self.commit_full()
    }

    fn commit_full(&mut self) -> Result<(), PlanError> {
        while self.window.len() > self.options.window {
            self.commit_front()?;
        }
        Ok(())
    }

    /// Backward pass from the window's end (where the plan stops), stopping early where the
    /// answer did not change since the last pass. Two speeds per group:
    ///
    /// * `backward`, the highest entry speed from which *some* end speed within the next
    ///   group's bound is reachable ([`max_start_speed`]). It only grows with that end speed,
    ///   so window growth only raises it: a speed the forward pass has already committed to
    ///   stays admissible when the window grows.
    /// * `aimed`, the highest entry speed from which the next group's aimed entry is reached in
    ///   one ramp ([`max_reachable_speed`] from it). A jerk-limited ramp gains less speed over
    ///   a distance the faster it starts, so this can fall when a later junction allows more;
    ///   but entering at `backward` where `aimed` is lower can leave only a speed far below the
    ///   next junction's (often rest), so the forward pass aims here and uses `backward` only
    ///   as the bound that keeps every committed speed reachable.
    fn backward(&mut self) -> Result<(), PlanError> {
        let (mut next, mut next_aimed) = (0.0, 0.0);
        for entry in self.window.iter_mut().rev() {
            match entry {
                Entry::Group(g) => {
                    let err = |e| PlanError::Profile {
                        line: g.stretches.line(),
                        source: e,
                    };
                    let cap = g.end_cap.min(g.limits.max_velocity());
                    let start = max_start_speed(cap.min(next), g.length, &g.limits).map_err(err)?;
                    let aimed = max_reachable_speed(cap.min(next_aimed), g.length, &g.limits)
                        .map_err(err)?
                        .min(start);
                    if start == g.backward && aimed == g.aimed {
                        break;
                    }
                    g.backward = start;
                    g.aimed = aimed;
                    next = start;
                    next_aimed = aimed;
                }
                _ => (next, next_aimed) = (0.0, 0.0),
            }
        }
        Ok(())
    }

    fn commit_front(&mut self) -> Result<(), PlanError> {
        self.backward()?;
        let Some(front) = self.window.pop_front() else {
            return Ok(());
        };
        let g = match front {
            Entry::Dwell { seconds, line } => {
                self.v_start = 0.0;
                self.out.push_back(Planned::Dwell { seconds, line });
                return Ok(());
            }
            Entry::Stop { line } => {
                self.v_start = 0.0;
                self.out.push_back(Planned::Stop { line });
                return Ok(());
            }
            Entry::Group(g) => g,
        };
        let (next_start, next_aimed) = match self.window.front() {
            Some(Entry::Group(n)) => (n.backward, n.aimed),
            _ => (0.0, 0.0),
        };
        let line = g.stretches.line();
        let err = |source| PlanError::Profile { line, source };
        let v0 = self.v_start.min(g.limits.max_velocity());
        let cap = g.end_cap.min(g.limits.max_velocity()).max(0.0);
        let up = max_reachable_speed(v0, g.length, &g.limits).map_err(err)?;
        let profile = match solve(g.length, v0, cap.min(next_aimed).min(up), &g.limits) {
            Ok(p) => p,
            // The aimed speed is out of reach (rounding, or the window grew since this entry
            // speed was committed and the aim fell). v0 is at most this group's `backward`,
            // so some end speed up to the next group's `backward` is reachable: the junction
            // speed is lowered to the highest such, never raised.
            Err(_) => solve_at_most(g.length, v0, cap.min(next_start), &g.limits).map_err(err)?,
        };
        self.v_start = profile.end().v.max(0.0);
        let Stretches {
            segments,
            starts,
            ends,
            partial_end,
        } = g.stretches;
        let mut offsets = Vec::with_capacity(starts.len());
        let mut acc = 0.0;
        for (a, b) in starts.iter().zip(&ends) {
            offsets.push(acc - a);
            acc += b - a;
        }
        self.out.push_back(Planned::Motion(Box::new(Piece {
            segments,
            offsets,
            lengths: ends,
            profile,
            limits: g.limits,
            partial_end,
        })));
        Ok(())
    }
}

/// Whether a curved segment entered or left at `slowest` may get speed steps
/// ([`ladder`]): it must be entered or left below the highest step, and long enough that
/// the first step — to 55 % of its speed at no more than the straight line's acceleration —
/// takes at most an eighth of it. A quick test before the steps are worked out.
fn may_step(geom: &Geometry, limits: &Limits, machine: &PlanMachine, slowest: f64) -> bool {
    let v = limits.max_velocity();
    if !geom.curved() || geom.rotary_only || slowest >= 0.97 * v {
        return false;
    }
    let straight = (0..machine.joint_count().min(geom.g1.len()))
        .filter(|&i| geom.g1[i] > 0.0)
        .map(|i| machine.max_acceleration[i] / geom.g1[i])
        .fold(f64::INFINITY, f64::min);
    let first = 0.55 * v;
    first * first / (2.0 * straight) <= geom.length / 8.0
}

/// Plans a whole list of path items.
pub fn plan_all(
    items: impl IntoIterator<Item = PathItem>,
    machine: PlanMachine,
    options: PlanOptions,
) -> Result<Vec<Planned>, PlanError> {
    let mut p = Planner::new(machine, options)?;
    let mut out = Vec::new();
    for item in items {
        p.push(item)?;
        while let Some(x) = p.pop() {
            out.push(x);
        }
    }
    p.finish()?;
    while let Some(x) = p.pop() {
        out.push(x);
    }
    Ok(out)
}
