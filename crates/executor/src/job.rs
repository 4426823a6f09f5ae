//! A job: one stream of moves (a program, the rest of one from a restart line, or an MDI
//! block) turned into planned items on demand — path building, tool-control take-up, feed
//! planning — so the planner thread only works as far ahead as the ring needs. Feed override
//! above 100 % raises the feed of segments as they enter the planner (the plan is then capped
//! by every limit there); each planned piece remembers the factor it was planned with.

use std::collections::{HashMap, VecDeque};

use tezgah_geom::{Move, MoveKind, PathMode, Pose, StopKind, Vec3};
use tezgah_kinematics::Joints;
use tezgah_motion::path::smooth::{SmoothOptions, Smoother};
use tezgah_motion::plan::{PlanMachine, PlanOptions, Planned, Planner};
use tezgah_motion::takeup::TakeUp;
use tezgah_motion::{PathItem, SegmentFeed};

use crate::error::ExecError;

type Items = Smoother<std::vec::IntoIter<Move>>;

/// A planned item and the feed factor its segments were planned with (≥ 1).
pub struct PlannedItem {
    pub item: Planned,
    pub factor: f64,
}

/// Moves → planned items, pulled one at a time.
pub struct Job {
    items: Items,
    takeup: TakeUp,
    planner: Planner,
    finished: bool,
    /// Path length pushed so far with the factor each stretch was planned with.
    log: VecDeque<(f64, f64)>,
    pushed: f64,
    popped: f64,
    stops: HashMap<u32, StopKind>,
}

/// How a job is built.
#[derive(Debug, Clone)]
pub struct JobOptions {
    pub smooth: SmoothOptions,
    pub plan: PlanOptions,
    /// Stop at the end of every block (single block): the path is built in exact-stop mode.
    pub single_block: bool,
}

impl Job {
    /// A job from `moves`, starting at the machine's current pose and joints.
    pub fn new(
        moves: Vec<Move>,
        machine: &PlanMachine,
        options: &JobOptions,
        start: Pose,
        joints: Joints,
    ) -> Result<Job, ExecError> {
        let mut stops = HashMap::new();
        let mut moves = moves;
        for m in &mut moves {
            if let MoveKind::Stop(kind) = m.kind {
                stops.insert(m.line, kind);
            }
            if options.single_block {
                if let MoveKind::PathMode(mode) = &mut m.kind {
                    *mode = PathMode::ExactStop;
                }
            }
        }
        if options.single_block {
            moves.insert(
                0,
                Move {
                    line: moves.first().map_or(0, |m| m.line),
                    kind: MoveKind::PathMode(PathMode::ExactStop),
                },
            );
        }
        let smooth = SmoothOptions {
            start,
            control: machine.initial,
            ..options.smooth.clone()
        };
        let items = Smoother::new(moves.into_iter(), smooth).map_err(ExecError::Path)?;
        let tip = Vec3::from(start.xyz());
        let takeup = TakeUp::new(machine, (tip, [start.0[3], start.0[4], start.0[5]]), joints);
        let planner = Planner::new(machine.clone(), options.plan).map_err(ExecError::Plan)?;
        Ok(Job {
            items,
            takeup,
            planner,
            finished: false,
            log: VecDeque::new(),
            pushed: 0.0,
            popped: 0.0,
            stops,
        })
    }

    /// What kind of stop a `Planned::Stop` at `line` is.
    pub fn stop_kind(&self, line: u32) -> StopKind {
        self.stops.get(&line).copied().unwrap_or(StopKind::End)
    }

    fn push(&mut self, item: PathItem, factor: f64) -> Result<(), ExecError> {
        let item = match item {
            PathItem::Segment(mut seg) => {
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
                    let item = item.map_err(ExecError::Path)?;
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
