//! Live probing (G38.2–G38.5) in AUTO on the simulated probe. The program after a probe
//! depends on its answer, so a program that probes runs in parts: the interpreter stops at a
//! probe move it has no answer for ([`Program::awaits`]); the moves before it run as one job,
//! the probe move as a job of its own, during which the probe input is read once a period at
//! the tool tip (as a servo thread reads it). At the trip the machine stops along the line on
//! the feed hold's path stop (`hold.rs`, [`crate::stop::path_stop`]) under the piece's limits;
//! at rest the answer — trip and rest as fractions of the move — goes to the interpreter, which
//! reads the program again from its start with one answer more, and the moves after the probe
//! run as the next part from where the machine stands (each part pre-flighted when reached).
//! `tezgah run` plays the same hand-off offline (`tezgah_executor::probe_moves`).

use std::sync::Arc;

use tezgah_gcode::{Config, ProbeModel as Answers, ProbeOutcome};
use tezgah_geom::{MoveKind, Pose, Vec3};
use tezgah_motion::interpolate::Sample;

use super::{Event, Executor, Produced};
use crate::command::{Mode, ProbeReport, RunState};
use crate::error::ExecError;
use crate::probe::Seek;
use crate::probe_moves::{fraction_along, part, point_at, with_stops};
use crate::program::Program;

/// Where the moves after a probe come from.
pub(super) enum Source {
    /// A loaded program, read again from its start with the answers so far.
    Program { text: String, config: Config },
    /// An MDI block: its interpreter takes the answer; the probe was the block's motion.
    Mdi,
}

/// A program (or MDI block) that probes, as far as it has run.
pub(super) struct LiveProbe {
    source: Source,
    mode: Mode,
    answers: Vec<ProbeOutcome>,
    /// Each probe move run so far (its index in the moves) and where the machine came to rest.
    stops: Vec<(usize, Pose)>,
    /// The latest pass of the interpreter, probe moves ending at their rest points.
    program: Program,
    phase: Phase,
}

enum Phase {
    /// The moves before the probe move at this index (none: to the end) are running.
    Approach(Option<usize>),
    /// The probe move at `index` is running.
    Probing {
        index: usize,
        code: String,
        line: u32,
        seek: Seek,
        start: Pose,
        end: Pose,
        trip: Option<Trip>,
    },
}

/// Where the input changed: the tool tip (workpiece frame, mm) and the fraction of the move
/// the program point had reached.
#[derive(Debug, Clone, Copy)]
struct Trip {
    tip: Vec3,
    at: f64,
}

/// The moves' index where the first part of `program` ends: its probe move, or the end.
pub(super) fn first_cut(program: &Program) -> usize {
    match program.awaits {
        Some(_) => program.moves.len().saturating_sub(1),
        None => program.moves.len(),
    }
}

/// `config` with the executor's answers so far.
fn answered(config: &Config, answers: &[ProbeOutcome]) -> Config {
    Config {
        probe: Answers::Answered(Arc::from(answers)),
        ..config.clone()
    }
}

impl Executor {
    /// Starts a loaded program (`Mode::Auto`) or an MDI block's moves: whole, or the part
    /// before the probe move they end with.
    pub(super) fn start_program(
        &mut self,
        program: Program,
        mode: Mode,
        source: Source,
    ) -> Result<(), ExecError> {
        let Some(_) = program.awaits else {
            return self.start_job(program.moves, mode, &program.origins);
        };
        let cut = first_cut(&program);
        let moves = program.moves[..cut].to_vec();
        let origins = Arc::clone(&program.origins);
        self.start_job(moves, mode, &origins)?;
        self.live = Some(LiveProbe {
            source,
            mode,
            answers: Vec::new(),
            stops: Vec::new(),
            program,
            phase: Phase::Approach(Some(cut)),
        });
        Ok(())
    }

    /// Reads the probe input at the tool where it stands (each period produced); the first
    /// change a probe move waits for is its trip.
    pub(super) fn read_probe(&mut self) {
        let Some(model) = &self.probe_model else {
            return;
        };
        let sample = Sample {
            index: self.k,
            t: 0.0,
            line: self.pose.line,
            tip: self.pose.tip,
            rotary: self.pose.rotary,
            joints: self.pose.joints,
            feed: 0.0,
        };
        let Ok(tool) = self.probe_tool.pose(&sample, &self.passed) else {
            return;
        };
        self.probe_input = model.touches(&tool.tip);
        if let Some(LiveProbe {
            phase:
                Phase::Probing {
                    seek,
                    start,
                    end,
                    trip: trip @ None,
                    ..
                },
            ..
        }) = &mut self.live
        {
            if self.probe_input == (*seek == Seek::Contact) {
                let at = fraction_along(*start, *end, self.pose.tip).unwrap_or(0.0);
                *trip = Some(Trip { tip: tool.tip, at });
            }
        }
    }

    /// The probe has tripped: the piece in hand stops on the path.
    pub(super) fn probe_stopping(&self) -> bool {
        matches!(
            self.live,
            Some(LiveProbe {
                phase: Phase::Probing { trip: Some(_), .. },
                ..
            })
        )
    }

    /// Tripped and at rest: time for the answer.
    pub(super) fn probe_at_rest(&self) -> bool {
        self.probe_stopping() && self.hold.is_none() && self.scale.is_stopped()
    }

    /// A job event, with a program that probes going on to its next part at the end of one.
    pub(super) fn finish(&mut self, event: Event) -> Result<Option<Produced>, ExecError> {
        match event {
            Event::Done if self.live.is_some() && self.state != RunState::Aborting => {
                self.next_part()
            }
            other => Ok(self.finish_event(other)),
        }
    }

    /// At the end of a part: the probe move after the moves before it, or the answer after the
    /// probe move and the part after it. The machine is at rest: the period is a rest set-point.
    pub(super) fn next_part(&mut self) -> Result<Option<Produced>, ExecError> {
        let Some(live) = self.live.as_mut() else {
            return Ok(self.finish_event(Event::Done));
        };
        match &live.phase {
            Phase::Approach(None) => Ok(self.finish_event(Event::Done)),
            Phase::Approach(Some(index)) => {
                let index = *index;
                self.start_probe_move(index)?;
                Ok(Some(self.emit(true, 0.0)))
            }
            Phase::Probing { .. } => {
                self.answer(false)?;
                Ok(Some(self.emit(true, 0.0)))
            }
        }
    }

    /// Starts the probe move at `index` from where the machine stands, or answers at once when
    /// the input is already what the move waits for (LinuxCNC refuses the move).
    fn start_probe_move(&mut self, index: usize) -> Result<(), ExecError> {
        let start = self.program_pose();
        let Some(live) = self.live.as_mut() else {
            return Ok(());
        };
        let program = &live.program;
        let probe = &program.moves[index];
        let code = program.awaits.clone().unwrap_or_default();
        let (MoveKind::Feed { end }, Some(seek)) = (&probe.kind, Seek::of(&code)) else {
            return Err(ExecError::Gcode(format!(
                "G{code}: the probe move is not a straight feed"
            )));
        };
        let end = *end;
        let line = program.origins.keys().plain(probe.line);
        if Vec3::from(start.xyz()) == Vec3::from(end.xyz()) {
            return Err(ExecError::At {
                at: program.origins.at(probe.line),
                message: crate::probe::ProbeError::NoLinearTravel.to_string(),
            });
        }
        let moves = part(&program.moves, index, index + 1, start);
        let origins = Arc::clone(&program.origins);
        let phase = Phase::Probing {
            index,
            code,
            line,
            seek,
            start,
            end,
            trip: None,
        };
        // The input where the move starts, before it is waited for (no trip).
        self.read_probe();
        if let Some(live) = self.live.as_mut() {
            live.phase = phase;
        }
        if self.probe_input == (seek == Seek::Contact) {
            return self.answer(true);
        }
        self.part_job(moves, &origins)
    }

    /// Runs `moves` as the next part (a new job from where the machine stands, pre-flighted);
    /// a hold in progress at the part's start leaves it held.
    fn part_job(
        &mut self,
        moves: Vec<tezgah_geom::Move>,
        origins: &crate::program::Origins,
    ) -> Result<(), ExecError> {
        let holding = matches!(self.state, RunState::Holding | RunState::Held);
        let live = self.live.take();
        let mode = live.as_ref().map_or(Mode::Auto, |l| l.mode);
        self.built = None;
        // The path run in the part left stays counted (a stopped probe move ends mid-piece).
        self.done_length += self.s;
        self.s = 0.0;
        let started = self.start_job(moves, mode, origins);
        self.live = live;
        started?;
        if holding {
            self.state = RunState::Held;
        }
        Ok(())
    }

    /// The probe move's answer to the interpreter, which reads the program again; the part after
    /// the probe starts from the rest point. An interpreter error (G38.2 without contact, …)
    /// ends the program there with that error, the machine at rest. `already`: the input was
    /// what the move waits for before it started.
    fn answer(&mut self, already: bool) -> Result<(), ExecError> {
        let here = self.pose.tip;
        let Some(live) = self.live.as_mut() else {
            return Ok(());
        };
        let Phase::Probing {
            index,
            ref code,
            line,
            start,
            end,
            trip,
            ..
        } = live.phase
        else {
            return Ok(());
        };
        let (outcome, stopped) = match trip {
            Some(t) => {
                let rest = fraction_along(start, end, here).unwrap_or(t.at);
                (
                    ProbeOutcome::Tripped {
                        at: t.at,
                        stopped: rest,
                    },
                    point_at(start, end, rest),
                )
            }
            None if already => (ProbeOutcome::AlreadyThere, start),
            None => (ProbeOutcome::Completed, end),
        };
        self.probe_last = Some(ProbeReport {
            code: format!("G{code}"),
            line,
            tripped: trip.is_some(),
            trip_mm: trip.map(|t| [t.tip.x, t.tip.y, t.tip.z]),
            stopped: stopped.0,
        });
        live.answers.push(outcome);
        live.stops.push((index, stopped));
        let (text, config) = match &live.source {
            Source::Program { text, config } => (text.clone(), answered(config, &live.answers)),
            Source::Mdi => {
                // The block's motion was the probe: nothing after it moves.
                let answered = self.mdi.answer(outcome);
                self.drop_job();
                if let Err(e) = answered {
                    self.error = Some(e.to_string());
                }
                return Ok(());
            }
        };
        let mut pass = match Program::interpret(text, &config) {
            Ok(p) => p,
            Err(e) => {
                self.drop_job();
                self.error = Some(e.to_string());
                return Ok(());
            }
        };
        pass.moves = with_stops(std::mem::take(&mut pass.moves), &live.stops);
        let cut = first_cut(&pass);
        let next = pass.awaits.is_some().then_some(cut);
        let moves = part(&pass.moves, index + 1, cut, stopped);
        let origins = Arc::clone(&pass.origins);
        live.program = pass;
        live.phase = Phase::Approach(next);
        self.part_job(moves, &origins)
    }
}

impl LiveProbe {
    /// A probe move is in hand.
    pub(super) fn probing(&self) -> bool {
        matches!(self.phase, Phase::Probing { .. })
    }
}
