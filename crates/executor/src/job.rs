//! A job: one stream of moves (a program, the rest of one from a restart line, or an MDI
//! block) made into the smooth path whole, once ([`BuiltPath`]: the pre-flight checks it
//! before anything moves, then the job takes it over), then into planned items on demand —
//! tool-control take-up, feed planning — so the planner thread only plans as far ahead as
//! the ring needs. Feed override above 100 % raises the feed of segments as they enter the
//! planner (the plan is then capped by every limit there); each planned piece remembers the
//! factor it was planned with.

use std::collections::{HashMap, VecDeque};

use tezgah_gcode::sources::LineKeys;
use tezgah_geom::{Move, MoveKind, PathMode, Pose, StopKind, Vec3};
use tezgah_kinematics::Joints;
use tezgah_motion::plan::{PlanMachine, PlanOptions, Planned, Planner};
use tezgah_motion::prepare::Prepared;
use tezgah_motion::takeup::TakeUp;
use tezgah_motion::{PathItem, SegmentFeed};

use crate::error::ExecError;

/// A planned item and the feed factor its segments were planned with (≥ 1).
pub struct PlannedItem {
    pub item: Planned,
    pub factor: f64,
}

/// Moves made into the whole smooth path from a start pose ([`tezgah_motion::prepare`]), and
/// the kinds of their stops. The executor loads whole programs, so the path is held whole:
/// built once, checked by the pre-flight, then handed to the [`Job`] that plans it (`tezgah
/// run` streams instead).
pub struct BuiltPath {
    items: Vec<PathItem>,
    stops: HashMap<u32, StopKind>,
    start: Pose,
    single_block: bool,
}

/// The kinds of the program's stops by line, and under single block (`single_block`) the
/// moves in exact-stop mode throughout, so that every block ends at rest.
pub fn exact_stops(
    mut moves: Vec<Move>,
    single_block: bool,
) -> (Vec<Move>, HashMap<u32, StopKind>) {
    let mut stops = HashMap::new();
    for m in &mut moves {
        if let MoveKind::Stop(kind) = m.kind {
            stops.insert(m.line, kind);
        }
        if single_block {
            if let MoveKind::PathMode(mode) = &mut m.kind {
                *mode = PathMode::ExactStop;
            }
        }
    }
    if single_block {
        moves.insert(
            0,
            Move {
                line: moves.first().map_or(0, |m| m.line),
                kind: MoveKind::PathMode(PathMode::ExactStop),
            },
        );
    }
    (moves, stops)
}

impl BuiltPath {
    /// The prepared path, the kinds of its stops, and whether it was built for single block.
    pub fn new(prepared: Prepared, stops: HashMap<u32, StopKind>, single_block: bool) -> BuiltPath {
        BuiltPath {
            items: prepared.items,
            stops,
            start: prepared.start,
            single_block,
        }
    }

    pub fn items(&self) -> &[PathItem] {
        &self.items
    }

    /// Gives the path plain line numbers (each in its own file), once the pre-flight has
    /// located its errors by the keyed ones the moves carried (`tezgah_gcode::sources`).
    pub fn plain_lines(&mut self, keys: &LineKeys) {
        if keys.is_plain() {
            return;
        }
        for item in &mut self.items {
            let line = item.line_mut();
            *line = keys.plain(*line);
        }
        self.stops = self
            .stops
            .drain()
            .map(|(line, kind)| (keys.plain(line), kind))
            .collect();
    }

    /// The pose the path starts from.
    pub fn start(&self) -> Pose {
        self.start
    }

    /// Built for single block (exact stop at every block end).
    pub fn single_block(&self) -> bool {
        self.single_block
    }
}

/// A built path → planned items, pulled one at a time.
pub struct Job {
    items: std::vec::IntoIter<PathItem>,
    takeup: TakeUp,
    planner: Planner,
    finished: bool,
    /// Path length pushed so far with the factor each stretch was planned with.
    log: VecDeque<(f64, f64)>,
    pushed: f64,
    popped: f64,
    stops: HashMap<u32, StopKind>,
}

impl Job {
    /// The job that plans `path`, the machine standing at its start with `joints`.
    pub fn new(
        path: BuiltPath,
        machine: &PlanMachine,
        plan: PlanOptions,
        joints: Joints,
    ) -> Result<Job, ExecError> {
        let start = path.start;
        let tip = Vec3::from(start.xyz());
        let takeup = TakeUp::new(machine, (tip, [start.0[3], start.0[4], start.0[5]]), joints);
        let planner = Planner::new(machine.clone(), plan).map_err(ExecError::Plan)?;
        Ok(Job {
            items: path.items.into_iter(),
            takeup,
            planner,
            finished: false,
            log: VecDeque::new(),
            pushed: 0.0,
            popped: 0.0,
            stops: path.stops,
        })
    }

    /// What kind of stop a `Planned::Stop` at `line` is.
    pub fn stop_kind(&self, line: u32) -> StopKind {
        self.stops.get(&line).copied().unwrap_or(StopKind::End)
    }

    fn push(&mut self, item: PathItem, factor: f64) -> Result<(), ExecError> {
        let item = match item {
            PathItem::Segment(mut seg) => {
                // A segment under M49 / `M50 P0` runs at its programmed feed.
                let factor = if seg.feed_override { factor } else { 1.0 };
                seg.feed = match seg.feed {
                    SegmentFeed::Feed(f) => SegmentFeed::Feed(f * factor),
                    SegmentFeed::InverseTime(t) => SegmentFeed::InverseTime(t / factor),
                    SegmentFeed::Rapid => SegmentFeed::Rapid,
                };
                self.pushed += seg.path_length();
                self.log.push_back((self.pushed, factor));
                PathItem::Segment(seg)
            }
            other => other,
        };
        self.planner.push(item).map_err(ExecError::Plan)
    }

    /// The next planned item, planning further with feed factor `factor` (≥ 1) where
    /// needed; `None` when the job is done.
    pub fn next(&mut self, factor: f64) -> Result<Option<PlannedItem>, ExecError> {
        loop {
            if let Some(item) = self.planner.pop() {
                let factor = self.factor_of(&item);
                return Ok(Some(PlannedItem { item, factor }));
            }
            if self.finished {
                return Ok(None);
            }
            match self.items.next() {
                Some(item) => {
                    if let Some(t) =
                        self.takeup
                            .before(&item)
                            .map_err(|e| ExecError::Kinematics {
                                line: e.line,
                                message: e.source.to_string(),
                            })?
                    {
                        self.push(t, factor)?;
                    }
                    self.push(item, factor)?;
                }
                None => {
                    self.planner.finish().map_err(ExecError::Plan)?;
                    self.finished = true;
                }
            }
        }
    }

    /// The largest factor among the segments a piece covers (so the re-timed speed never
    /// exceeds the override of any of them).
    fn factor_of(&mut self, item: &Planned) -> f64 {
        let Planned::Motion(piece) = item else {
            return 1.0;
        };
        let (from, to) = (self.popped, self.popped + piece.length());
        self.popped = to;
        let slack = 1e-9 * to.max(1.0);
        while self.log.front().is_some_and(|&(end, _)| end < from - slack) {
            self.log.pop_front();
        }
        let mut factor: f64 = 1.0;
        for &(end, f) in &self.log {
            factor = factor.max(f);
            if end >= to - slack {
                break;
            }
        }
        factor
    }
}
