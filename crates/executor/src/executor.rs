//! The executor's non-real-time half: operating modes, commands and the re-timed sampling of
//! the plan into set-points. It runs on the planner thread (or a test's virtual clock): every
//! [`Executor::step`] produces the next period's set-point, which the thread pushes into the
//! ring. Feed override and hold act on the time scale ([`crate::scale`]) here, where samples
//! are produced, so a command reaches the machine after the ring's few periods. JOG, INC and
//! HOME ([`crate::manual`]) feed the same stream while idle; homing's offsets (drive minus
//! machine frame) are added to every set-point once found.

use std::sync::Arc;

use tezgah_gcode::interp::SubroutineLibrary;
use tezgah_geom::{Move, MoveKind, Pose, StopKind, Vec3};
use tezgah_kinematics::{Joints, Machine, TcpSwitch};
use tezgah_motion::cursor::{CursorPose, PieceCursor};
use tezgah_motion::plan::{PlanMachine, PlanOptions, Planned};
use tezgah_motion::prepare::{plan_options, prepare_from, PrepareError};
use tezgah_motion::{Junction, Limits, Segment};

use crate::command::{Command, Mode, PauseReason, ProbeReport, ProbeStatus, RunState, Status};
use crate::error::ExecError;
use crate::job::{self, BuiltPath, Job, PlannedItem};
use crate::manual::active::ManualMotion;
use crate::manual::{HomeSwitches, SimulatedSwitches};
use crate::mdi::Mdi;
use crate::overspeed::overspeed_limits;
use crate::program::{Origins, Program};
use crate::scale::{PieceView, TimeScale};
use crate::setpoint::{History, SetPoint};
use crate::speed_override::Override;

mod hold;
mod manual;
mod probing;

/// One produced period: the set-point and, for checks and displays, where the tip is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Produced {
    pub setpoint: SetPoint,
    /// Tool tip, workpiece frame, mm.
    pub tip: Vec3,
    /// A B C, degrees.
    pub rotary: [f64; 3],
    /// Path speed this period, mm/s (r times the plan's).
    pub feed: f64,
    /// Path coordinate run since the executor started (mm, degrees on rotary-only moves):
    /// monotone, so a hold and resume can be checked to lose and repeat nothing.
    pub path: f64,
}

/// Settings of the executor: the machine file's period and tolerance. The path and the plan
/// are made from them by motion's one entry point ([`tezgah_motion::prepare`]), as `tezgah
/// run` makes them, so the executor follows the path `run` plans.
#[derive(Debug, Clone)]
pub struct ExecOptions {
    pub period: f64,
    /// Path tolerance, mm (shared between smoothing and chord error by `prepare`).
    pub tolerance: f64,
}

impl ExecOptions {
    /// The machine file's period and tolerance (the machine itself is checked by
    /// [`Executor::new`]).
    pub fn for_machine(machine: &Machine) -> ExecOptions {
        ExecOptions {
            period: machine.motion.period_s,
            tolerance: machine.motion.tolerance_mm,
        }
    }

    /// The planner's options at this period ([`tezgah_motion::prepare::plan_options`]).
    pub fn plan(&self) -> PlanOptions {
        plan_options(self.period)
    }
}

enum Current {
    Piece {
        // Boxed: the cursor carries its arc-length panel's polynomial (`tezgah_geom`'s
        // `ArcLengthCursor`), which made this variant much the larger.
        cursor: Box<PieceCursor>,
        tau: f64,
        factor: f64,
        /// Its limits above the planned speed, if it may run faster (override > 100 %).
        fast: Option<Limits>,
    },
    Dwell {
        left: f64,
        line: u32,
    },
}

/// What advancing along the job met.
enum Event {
    Moving,
    Paused(PauseReason),
    Done,
}

/// The executor: modes, commands, the job in hand and its sampling.
pub struct Executor {
    machine: PlanMachine,
    /// The machine file (manual motion reads its joints and homing settings).
    machine_file: Machine,
    options: ExecOptions,
    gcode: tezgah_gcode::Config,
    program: Option<Program>,
    job: Option<Job>,
    current: Option<Current>,
    /// The planned item after the current one, taken early for the time scale's look-ahead.
    peeked: Option<PlannedItem>,
    /// The peeked piece's overspeed limits (worked out once, when it is peeked).
    peeked_fast: Option<Limits>,
    scale: TimeScale,
    /// A feed hold's (or abort's) stop along the path in progress.
    hold: Option<hold::Hold>,
    /// Periods the time scale could not verify within the limits (see `unchecked_periods`).
    unchecked: u64,
    mode: Mode,
    state: RunState,
    override_pct: f64,
    single_block: bool,
    optional_stop: bool,
    mdi: Mdi,
    /// The modal moves MDI blocks have made (feed, feed mode, path mode, …), last of each
    /// kind: every MDI job starts with them, as the interpreter's modal state carries over.
    mdi_modal: Vec<Move>,
    /// Where the MDI interpreter believes the machine is (the end of its last move).
    mdi_at: Pose,
    error: Option<String>,
    /// What the loaded program's interpretation warned of (a missing program end).
    warning: Option<String>,
    /// Where the tool is (the last sample, or a piece's exact end).
    pose: CursorPose,
    k: u64,
    /// The positions produced last (drive frame): each set-point's velocity and acceleration.
    history: History,
    /// Segments passed since the last set-point (for path checks).
    passed: Vec<Arc<Segment>>,
    /// Path length of the pieces finished, and where in the current one the tool is.
    done_length: f64,
    s: f64,
    /// JOG, INC or HOME in hand (no job then).
    manual: Option<ManualMotion>,
    /// The manual generator's last set-point (machine frame, exact velocity and acceleration):
    /// where a stop of it starts.
    last_manual: Option<SetPoint>,
    jog_override: Override,
    /// Drive (power-on) frame minus machine frame per joint: set-points are `joints + offset`.
    /// Zero until homing finds it.
    offset: Joints,
    homed: bool,
    switches: Box<dyn HomeSwitches + Send>,
    /// The loaded program's path, built and pre-flighted at load, until a job takes it.
    built: Option<BuiltPath>,
    /// The simulated probe G38 moves touch (machine file `[probe]`), if any.
    probe_model: Option<tezgah_kinematics::probe::ProbeModel>,
    /// The tool (its length in force) where the probe input is read.
    probe_tool: tezgah_motion::tool_pose::SampleTool,
    /// The probe input at the last set-point: in contact.
    probe_input: bool,
    probe_last: Option<ProbeReport>,
    /// A program that probes, running part by part.
    live: Option<probing::LiveProbe>,
    /// The loaded program's text and the configuration it was read with (a program that
    /// probes is read again after each answer).
    text: Option<(String, tezgah_gcode::Config)>,
}

fn sub(a: &Joints, b: &Joints, scale: f64) -> Joints {
    let mut out = *a;
    for (o, y) in out.as_mut_slice().iter_mut().zip(b.as_slice()) {
        *o = (*o - y) * scale;
    }
    out
}

fn add(a: &Joints, b: &Joints) -> Joints {
    let mut out = *a;
    for (o, y) in out.as_mut_slice().iter_mut().zip(b.as_slice()) {
        *o += y;
    }
    out
}

impl Executor {
    /// An executor for `machine` standing at program pose `start`.
    pub fn new(machine: &Machine, options: ExecOptions, start: Pose) -> Result<Self, ExecError> {
        let pm = PlanMachine::from_machine(machine).map_err(ExecError::Plan)?;
        let tip = Vec3::from(start.xyz());
        let rotary = [start.0[3], start.0[4], start.0[5]];
        let joints = pm
            .joints(pm.initial, &tip, &rotary, &Joints::zeros(pm.joint_count()))
            .map_err(|e| ExecError::Kinematics {
                line: 0,
                message: e.to_string(),
            })?;
        let gcode = tezgah_gcode::Config {
            tool_centre_point_always: machine.tcp == TcpSwitch::Always,
            axes: tezgah_gcode::AxisMask::of(machine.program_axes()),
            // With a probe, the interpreter stops at each probe move for the machine's answer.
            probe: match machine.probe {
                Some(_) => tezgah_gcode::ProbeModel::Answered(Arc::from([])),
                None => tezgah_gcode::ProbeModel::Unavailable,
            },
            ..tezgah_gcode::Config::default()
        };
        let n = pm.joint_count();
        let switches = SimulatedSwitches::new(machine, &Joints::zeros(n))?;
        let probe_tool = tezgah_motion::tool_pose::SampleTool::new(&pm);
        Ok(Executor {
            machine: pm,
            machine_file: machine.clone(),
            manual: None,
            last_manual: None,
            jog_override: Override::FULL,
            offset: Joints::zeros(n),
            homed: false,
            switches: Box::new(switches),
            built: None,
            probe_model: machine.probe.clone(),
            probe_tool,
            probe_input: false,
            probe_last: None,
            live: None,
            text: None,
            options,
            mdi: Mdi::new(gcode.clone()),
            mdi_modal: Vec::new(),
            mdi_at: Pose::ZERO,
            gcode,
            program: None,
            job: None,
            current: None,
            peeked: None,
            peeked_fast: None,
            scale: TimeScale::default(),
            hold: None,
            unchecked: 0,
            mode: Mode::Auto,
            state: RunState::Idle,
            override_pct: 100.0,
            single_block: false,
            optional_stop: false,
            error: None,
            warning: None,
            pose: CursorPose {
                line: 0,
                tip,
                rotary,
                joints,
            },
            k: 0,
            history: History::at_rest(joints),
            passed: Vec::new(),
            done_length: 0.0,
            s: 0.0,
        })
    }

    pub fn period(&self) -> f64 {
        self.options.period
    }

    /// The home switches homing reads (by default the machine file's, simulated, with the
    /// power-on frame equal to the machine frame).
    pub fn set_switches(&mut self, switches: Box<dyn HomeSwitches + Send>) {
        self.switches = switches;
    }

    /// Subroutines in files of their own (`o<name> call` of a name the program lacks), for
    /// loaded programs and MDI, as `--subroutine-path` gives `tezgah run`. Set before the
    /// first MDI block: the MDI interpreter starts afresh with it.
    pub fn with_subroutines(mut self, library: Arc<dyn SubroutineLibrary>) -> Self {
        self.gcode.subroutines = Some(library);
        self.mdi = Mdi::new(self.gcode.clone());
        self
    }

    /// The joints as the drives see them (power-on frame): the status' joints plus the
    /// homing offsets. A real-time side starts from these.
    pub fn drive_joints(&self) -> Joints {
        add(&self.pose.joints, &self.offset)
    }

    /// Drive (power-on) frame minus machine frame per joint, internal units (zero before
    /// homing).
    pub fn homing_offsets(&self) -> Joints {
        self.offset
    }

    pub fn is_homed(&self) -> bool {
        self.homed
    }

    pub fn state(&self) -> RunState {
        self.state
    }

    /// The machine as the planner sees it.
    pub fn machine(&self) -> &PlanMachine {
        &self.machine
    }

    /// The path limits (speed, acceleration, jerk along the path) of the piece in hand.
    pub fn path_limits(&self) -> Option<tezgah_motion::Limits> {
        match &self.current {
            Some(Current::Piece { cursor, .. }) => Some(cursor.piece().limits),
            _ => None,
        }
    }

    /// Periods the time scale found no r̈ that passes its exact check (|s̈| ≤ A, |s⃛| ≤ J over
    /// the whole period) and braked regardless: a diagnostic, zero in every test run.
    pub fn unchecked_periods(&self) -> u64 {
        self.unchecked
    }

    /// The segments the tool passed since the previous set-point, ending with its own.
    pub fn passed(&self) -> &[Arc<Segment>] {
        &self.passed
    }

    /// The loaded program's moves.
    pub fn program_moves(&self) -> Option<&[Move]> {
        self.program.as_ref().map(|p| &p.moves[..])
    }

    pub fn status(&self) -> Status {
        Status {
            mode: self.mode,
            state: self.state,
            line: self.pose.line,
            executing_line: 0,
            underruns: 0,
            late_worst_s: 0.0,
            late_over_half: 0,
            index: self.k,
            feed_override_percent: self.override_pct,
            single_block: self.single_block,
            optional_stop: self.optional_stop,
            program_loaded: self.program.is_some(),
            homed: self.homed,
            jog_override_percent: self.jog_override.percent(),
            joints: self.pose.joints.as_slice().to_vec(),
            measured: Vec::new(),
            tip: [self.pose.tip.x, self.pose.tip.y, self.pose.tip.z],
            time_scale: self.scale.r,
            error: self.error.clone(),
            work: self
                .mdi
                .work([self.pose.tip.x, self.pose.tip.y, self.pose.tip.z]),
            warning: self.warning.clone(),
            probe: ProbeStatus {
                fitted: self.probe_model.is_some(),
                input: self.probe_input,
                probing: self.live.as_ref().is_some_and(|l| l.probing()),
                last: self.probe_last.clone(),
            },
        }
    }

    fn state_name(&self) -> &'static str {
        match self.state {
            RunState::Idle => "idle",
            RunState::Running => match self.mode {
                Mode::Jog => "jogging",
                Mode::Inc => "moving an increment",
                Mode::Home => "homing",
                Mode::Auto | Mode::Mdi => "running",
            },
            RunState::Holding => "holding",
            RunState::Held => "held",
            RunState::Paused { .. } => "paused",
            RunState::Aborting => "aborting",
            RunState::Fault => "in fault",
        }
    }

    fn busy(&self, command: &'static str) -> ExecError {
        ExecError::Busy {
            command,
            state: self.state_name(),
        }
    }

    /// The tool's pose in the coordinates of the moves (mm, degrees).
    fn program_pose(&self) -> Pose {
        let p = &self.pose;
        Pose::new(
            p.tip.x,
            p.tip.y,
            p.tip.z,
            p.rotary[0],
            p.rotary[1],
            p.rotary[2],
        )
    }

    /// Builds the whole path of `moves` from `start` and checks every segment's joints
    /// against reach and limits from where the joints stand (motion's [`prepare_from`]), so
    /// a program that would leave the machine's work space is refused before anything moves;
    /// the job then plans that same path. Errors name the place `origins` gives the moves'
    /// lines; the path returned carries plain line numbers.
    fn preflight(
        &self,
        moves: Vec<Move>,
        start: Pose,
        origins: &Origins,
    ) -> Result<BuiltPath, ExecError> {
        let (moves, stops) = job::exact_stops(moves, self.single_block);
        let prepared = prepare_from(
            moves,
            &self.machine_file,
            self.options.tolerance,
            start,
            Some(self.pose.joints),
        )
        .map_err(|e| match e {
            PrepareError::Path(e) => origins.path_error(e),
            PrepareError::Preflight(e) => origins.preflight_error(&e),
            PrepareError::Machine(e) => ExecError::Plan(e),
            PrepareError::Start(e) => ExecError::Machine(format!("the start pose: {e}")),
        })?;
        let mut path = BuiltPath::new(prepared, stops, self.single_block);
        path.plain_lines(origins.keys());
        Ok(path)
    }

    /// AUTO and MDI wait for homing if the machine file asks.
    fn check_homed(&self, command: &'static str) -> Result<(), ExecError> {
        if self.machine_file.motion.home_required && !self.homed {
            return Err(ExecError::NotHomed { command });
        }
        Ok(())
    }

    fn start_job(
        &mut self,
        moves: Vec<Move>,
        mode: Mode,
        origins: &Origins,
    ) -> Result<(), ExecError> {
        let start = self.program_pose();
        // The loaded program's path was built and checked at load; again if the machine
        // moved since or single block changed (it builds another path).
        // (MDI leaves it for the program.)
        let single_block = self.single_block;
        let fits = |b: &mut BuiltPath| {
            mode == Mode::Auto && b.start().0 == start.0 && b.single_block() == single_block
        };
        let built = match self.built.take_if(fits) {
            Some(b) => b,
            None => self.preflight(moves, start, origins)?,
        };
        let job = Job::new(built, &self.machine, self.options.plan(), self.pose.joints)?;
        self.job = Some(job);
        self.current = None;
        self.peeked = None;
        self.hold = None;
        self.mode = mode;
        self.state = RunState::Running;
        self.scale = TimeScale::held();
        Ok(())
    }

    /// Takes one command; a refused command changes nothing.
    pub fn command(&mut self, command: Command) -> Result<(), ExecError> {
        let result = self.apply(command);
        if let Err(e) = &result {
            self.error = Some(e.to_string());
        }
        result
    }

    fn apply(&mut self, command: Command) -> Result<(), ExecError> {
        match command {
            Command::Load { program } => {
                if self.state != RunState::Idle {
                    return Err(self.busy("load"));
                }
                let config = self.mdi.program_config(&self.gcode);
                let text = program;
                let program = Program::interpret(text.clone(), &config)?;
                self.warning = (!program.warnings.is_empty()).then(|| program.warnings.join("\n"));
                let here = self.program_pose();
                // A program that probes: its part before the first probe move.
                let first = program.moves[..probing::first_cut(&program)].to_vec();
                self.built = Some(self.preflight(first, here, &program.origins)?);
                self.program = Some(program);
                self.text = Some((text, config));
                self.mode = Mode::Auto;
                Ok(())
            }
            Command::CycleStart | Command::Resume => match self.state {
                RunState::Idle => {
                    self.check_homed("cycle start")?;
                    let program = self.program.clone().ok_or(ExecError::NoProgram)?;
                    let (text, config) = self.text.clone().unwrap_or_default();
                    let source = probing::Source::Program { text, config };
                    self.start_program(program, Mode::Auto, source)
                }
                RunState::Held | RunState::Paused { .. } | RunState::Holding => {
                    self.state = RunState::Running;
                    Ok(())
                }
                RunState::Running if self.manual.is_some() => Err(self.busy("cycle start")),
                RunState::Running => Ok(()),
                _ => Err(self.busy("cycle start")),
            },
            Command::FeedHold if self.manual.is_some() => {
                self.stop_manual();
                Ok(())
            }
            Command::FeedHold => match self.state {
                RunState::Running => {
                    self.state = RunState::Holding;
                    Ok(())
                }
                RunState::Holding | RunState::Held | RunState::Paused { .. } => Ok(()),
                _ => Err(self.busy("feed hold")),
            },
            Command::Abort => {
                match self.state {
                    RunState::Running if self.manual.is_some() => self.stop_manual(),
                    RunState::Running | RunState::Holding => self.state = RunState::Aborting,
                    RunState::Aborting => {}
                    _ => self.drop_job(),
                }
                self.error = None;
                Ok(())
            }
            Command::FeedOverride { percent } => {
                self.override_pct = Override::new(percent)?.percent();
                Ok(())
            }
            Command::SingleBlock { on } => {
                self.single_block = on;
                Ok(())
            }
            Command::OptionalStop { on } => {
                self.optional_stop = on;
                Ok(())
            }
            Command::Mdi { block } => {
                if self.state != RunState::Idle {
                    return Err(self.busy("MDI"));
                }
                self.check_homed("MDI")?;
                let here = self.program_pose();
                if here.0 != self.mdi_at.0 {
                    self.mdi.sync(&here)?;
                    self.mdi_at = here;
                }
                let (moves, awaits) = self.mdi.block(&block)?;
                if let Some(end) = moves.iter().rev().find_map(|m| move_end(&m.kind)) {
                    self.mdi_at = end;
                }
                let mut job = self.mdi_modal.clone();
                let mut modal = self.mdi_modal.clone();
                for m in moves {
                    if is_modal(&m.kind) {
                        let d = std::mem::discriminant(&m.kind);
                        modal.retain(|k| std::mem::discriminant(&k.kind) != d);
                        modal.push(m.clone());
                    }
                    job.push(m);
                }
                // A block the pre-flight refuses leaves the modal moves as they were (the
                // interpreter's position is re-synchronised before the next block anyway).
                let program = Program {
                    moves: job,
                    origins: Arc::new(Origins::mdi(&block)),
                    warnings: Vec::new(),
                    awaits,
                };
                self.start_program(program, Mode::Mdi, probing::Source::Mdi)?;
                self.mdi_modal = modal;
                Ok(())
            }
            Command::RestartFrom { line } => {
                if self.state != RunState::Idle {
                    return Err(self.busy("restart"));
                }
                self.check_homed("restart")?;
                let program = self.program.as_ref().ok_or(ExecError::NoProgram)?;
                if let Some(code) = &program.awaits {
                    // Where each probe stopped is known only by running the program from its
                    // start.
                    return Err(ExecError::Gcode(format!(
                        "a program that probes (G{code}) runs from its start only"
                    )));
                }
                let moves = restart_moves(&program.moves, line)?;
                let origins = Arc::clone(&program.origins);
                // A restart starts elsewhere than the program: built and checked whole.
                self.built = None;
                self.start_job(moves, Mode::Auto, &origins)
            }
            Command::Jog {
                joint,
                direction,
                speed,
            } => self.jog(joint, direction, speed),
            Command::JogStop => self.jog_stop(),
            Command::JogOverride { percent } => self.jog_override(percent),
            Command::Increment {
                joint,
                direction,
                step,
            } => self.increment(joint, direction, step),
            Command::Home => self.home(),
        }
    }

    fn drop_job(&mut self) {
        // The path run so far stays counted.
        self.done_length += self.s;
        self.s = 0.0;
        self.job = None;
        self.current = None;
        self.peeked = None;
        self.manual = None;
        self.last_manual = None;
        self.hold = None;
        self.live = None;
        self.state = RunState::Idle;
        self.scale = TimeScale::held();
    }

    /// The real-time side halted (underrun or drive fault) at `joints` (drive frame, as
    /// commanded): the job is lost.
    pub fn fault(&mut self, drive: Joints, message: &str) {
        let joints = sub(&drive, &self.offset, 1.0);
        // A job error that caused the halt stays the message.
        let job_failed = self.state == RunState::Fault;
        self.drop_job();
        self.state = RunState::Fault;
        if !job_failed {
            self.error = Some(message.to_owned());
        }
        // The joints are the truth now; the tip follows where the model says (an underrun
        // stop leaves the path by a little).
        if let Ok(p) = tezgah_kinematics::Kinematics::forward(
            &self.machine.model,
            &joints,
            &tezgah_kinematics::Tool::default(),
        ) {
            self.pose.tip = p.tip;
        }
        self.pose.joints = joints;
        self.history = History::at_rest(drive);
    }

    /// The time scale wanted: the override's, or the plan's own where the program locked the
    /// override (M49, `M50 P0`, tapping).
    fn target(&self, factor: f64, overridable: bool) -> f64 {
        match self.state {
            // The probe tripped: the time scale brakes where the path stop could not start.
            RunState::Running if self.probe_stopping() => 0.0,
            // Above 1 only as far as the pieces' overspeed limits allow (the time scale caps it).
            RunState::Running if overridable => self.override_pct / 100.0 / factor,
            // Its feeds were planned as programmed (`Job` applies no factor to them).
            RunState::Running => 1.0,
            _ => 0.0,
        }
    }

    /// The next period's set-point; `None` when nothing moves (idle, held, paused).
    pub fn step(&mut self) -> Result<Option<Produced>, ExecError> {
        if !matches!(
            self.state,
            RunState::Running | RunState::Holding | RunState::Aborting
        ) {
            return Ok(None);
        }
        if self.manual.is_some() {
            return self.step_manual();
        }
        match self.advance_one() {
            Ok(p) => Ok(p),
            Err(e) => {
                // A job that fails mid-way (a pose out of reach: the program's pre-flight
                // catches only what the interpreter sees) produces nothing more: the
                // real-time side meets an empty ring while moving, an underrun, and brings
                // the joints to rest jerk-limited — never the jump a rest set-point here
                // would be.
                self.drop_job();
                self.state = RunState::Fault;
                self.error = Some(e.to_string());
                Ok(None)
            }
        }
    }

    fn advance_one(&mut self) -> Result<Option<Produced>, ExecError> {
        let ts = self.options.period;
        if self.passed.len() > 1 {
            self.passed.drain(..self.passed.len() - 1);
        }
        // A probe that tripped and came to rest answers; the program goes on from there.
        if self.probe_at_rest() && self.state != RunState::Aborting {
            return self.next_part();
        }
        if self.current.is_none() {
            if let Some(ev) = self.fetch()? {
                return self.finish(ev);
            }
        }
        // A hold (or a probe's trip) stops along the path where it can (a stop begun runs to
        // its end).
        let stopping =
            matches!(self.state, RunState::Holding | RunState::Aborting) || self.probe_stopping();
        if self.hold.is_some() || (stopping && self.begin_hold()) {
            return self.step_hold();
        }
        // The time scale moves with the plan's state where the tool is.
        let (factor, overridable) = match &self.current {
            Some(Current::Piece { factor, cursor, .. }) => (*factor, overridable(cursor.piece())),
            _ => (1.0, true),
        };
        let target = self.target(factor, overridable);
        if matches!(self.current, Some(Current::Piece { .. })) && self.peeked.is_none() {
            // The scale looks into the next piece (its limits may be lower).
            let factor = (self.override_pct / 100.0).max(1.0);
            if let Some(job) = self.job.as_mut() {
                self.peeked = job.next(factor)?;
            }
            self.peeked_fast = match &self.peeked {
                Some(PlannedItem {
                    item: Planned::Motion(p),
                    ..
                }) => self.fast_limits(p),
                _ => None,
            };
        }
        let next = match &self.peeked {
            Some(PlannedItem {
                item: Planned::Motion(p),
                ..
            }) => Some(PieceView {
                profile: &p.profile,
                limits: &p.limits,
                fast: self.peeked_fast,
            }),
            _ => None,
        };
        let dtau = match &self.current {
            Some(Current::Piece {
                cursor, tau, fast, ..
            }) => {
                let p = cursor.piece();
                let current = PieceView {
                    profile: &p.profile,
                    limits: &p.limits,
                    fast: *fast,
                };
                let adv = self.scale.step(target, current, next, *tau, ts);
                self.unchecked += u64::from(!adv.checked);
                adv.dtau
            }
            _ => {
                // Standing still (a dwell): r may jump, nothing moves. A dwell is wall time
                // (override does not stretch it, as on LinuxCNC); a hold or an abort stops it.
                self.scale.r = target.min(1.0);
                self.scale.rate = 0.0;
                if target > 0.0 {
                    ts
                } else {
                    0.0
                }
            }
        };
        let event = self.advance(dtau)?;
        if let Event::Moving = event {
            if self.scale.is_stopped() {
                match self.state {
                    RunState::Holding => {
                        self.state = RunState::Held;
                        return Ok(Some(self.emit(true, 0.0)));
                    }
                    RunState::Aborting => {
                        self.drop_job();
                        return Ok(Some(self.emit(true, 0.0)));
                    }
                    _ => {}
                }
            }
            let feed = match &self.current {
                Some(Current::Piece { cursor, tau, .. }) => {
                    self.scale.r * cursor.piece().profile.state_at(*tau).v
                }
                _ => 0.0,
            };
            self.sample()?;
            return Ok(Some(self.emit(false, feed)));
        }
        self.finish(event)
    }

    fn finish_event(&mut self, event: Event) -> Option<Produced> {
        match event {
            Event::Moving => None,
            Event::Paused(reason) => {
                self.state = if self.state == RunState::Aborting {
                    self.drop_job();
                    RunState::Idle
                } else {
                    RunState::Paused { reason }
                };
                self.scale = TimeScale::held();
                Some(self.emit(true, 0.0))
            }
            Event::Done => {
                self.drop_job();
                Some(self.emit(true, 0.0))
            }
        }
    }

    /// Takes the next planned item as current; an event if the job pauses or ends there.
    fn fetch(&mut self) -> Result<Option<Event>, ExecError> {
        let factor = (self.override_pct / 100.0).max(1.0);
        loop {
            let Some(job) = self.job.as_mut() else {
                return Ok(Some(Event::Done));
            };
            let (next, fast) = match self.peeked.take() {
                // Its limits above the plan were worked out when it was peeked.
                Some(p) => (Some(p), Some(self.peeked_fast.take())),
                None => (job.next(factor)?, None),
            };
            let Some(PlannedItem { item, factor }) = next else {
                return Ok(Some(Event::Done));
            };
            match item {
                Planned::Motion(piece) => {
                    let fast = fast.unwrap_or_else(|| self.fast_limits(&piece));
                    let cursor = Box::new(PieceCursor::new(Arc::from(piece)));
                    self.current = Some(Current::Piece {
                        cursor,
                        tau: 0.0,
                        factor,
                        fast,
                    });
                    return Ok(None);
                }
                Planned::Dwell { seconds, line } => {
                    self.current = Some(Current::Dwell {
                        left: seconds,
                        line,
                    });
                    return Ok(None);
                }
                Planned::Stop { line } => {
                    self.pose.line = line;
                    match job.stop_kind(line) {
                        StopKind::Pause | StopKind::PalletPause => {
                            return Ok(Some(Event::Paused(PauseReason::ProgramStop)))
                        }
                        StopKind::OptionalPause if self.optional_stop => {
                            return Ok(Some(Event::Paused(PauseReason::OptionalStop)))
                        }
                        _ => {}
                    }
                }
            }
        }
    }

    /// Moves `dtau` of planned time along the job.
    fn advance(&mut self, mut left: f64) -> Result<Event, ExecError> {
        loop {
            if self.current.is_none() {
                if let Some(ev) = self.fetch()? {
                    return Ok(ev);
                }
            }
            match self.current.as_mut() {
                Some(Current::Piece { cursor, tau, .. }) => {
                    let d = cursor.piece().profile.duration();
                    if *tau + left < d {
                        *tau += left;
                        return Ok(Event::Moving);
                    }
                    left -= d - *tau;
                    *tau = d;
                    let stop = self.finish_piece()?;
                    if stop
                        && self.single_block
                        && self.mode == Mode::Auto
                        && self.state == RunState::Running
                    {
                        return Ok(Event::Paused(PauseReason::SingleBlock));
                    }
                }
                Some(Current::Dwell { left: dl, line }) => {
                    self.pose.line = *line;
                    if left < *dl {
                        *dl -= left;
                        return Ok(Event::Moving);
                    }
                    left -= *dl;
                    self.current = None;
                }
                None => return Ok(Event::Done),
            }
        }
    }

    /// A piece's limits above its planned speed ([`crate::overspeed`]); worked out once per
    /// piece, when it is peeked or taken, so an override raised later reaches it too.
    fn fast_limits(&self, piece: &tezgah_motion::plan::Piece) -> Option<Limits> {
        overridable(piece)
            .then(|| overspeed_limits(piece, &self.machine, &self.options.plan()))
            .flatten()
    }

    /// Leaves the piece in hand at its exact end (every segment passed on the way counted);
    /// whether the path stops there.
    fn finish_piece(&mut self) -> Result<bool, ExecError> {
        let Some(Current::Piece { cursor, .. }) = self.current.as_mut() else {
            return Ok(false);
        };
        let end = cursor.piece().length();
        self.pose = cursor.pose(&self.machine, end, &self.pose.joints)?;
        self.done_length += end;
        self.s = 0.0;
        self.passed.extend(cursor.passed().iter().cloned());
        let stop = cursor.piece().end_junction() == Junction::Stop;
        self.current = None;
        Ok(stop)
    }

    /// The pose at the current path time.
    fn sample(&mut self) -> Result<(), ExecError> {
        if let Some(Current::Piece { cursor, tau, .. }) = &self.current {
            let s = cursor.piece().profile.state_at(*tau).s;
            self.sample_at(s)?;
        }
        Ok(())
    }

    /// The pose at path coordinate `s` of the piece in hand.
    fn sample_at(&mut self, s: f64) -> Result<(), ExecError> {
        if let Some(Current::Piece { cursor, .. }) = self.current.as_mut() {
            self.s = s.clamp(0.0, cursor.piece().length());
            self.pose = cursor.pose(&self.machine, s, &self.pose.joints)?;
            // Segments passed inside this piece (its cursor keeps the current one).
            for seg in cursor.passed() {
                if !self.passed.last().is_some_and(|p| Arc::ptr_eq(p, seg)) {
                    self.passed.push(seg.clone());
                }
            }
            cursor.clear_passed();
        }
        Ok(())
    }

    /// The set-point at the current pose; velocity and acceleration from the positions
    /// produced ([`History`]), zero when `rest` (a stop is exact, and the real-time side must
    /// see the machine at rest to idle without calling it an underrun).
    fn emit(&mut self, rest: bool, feed: f64) -> Produced {
        let q = add(&self.pose.joints, &self.offset);
        self.emit_at(q, rest, feed)
    }

    /// The set-point at drive-frame joints `q`.
    fn emit_at(&mut self, q: Joints, rest: bool, feed: f64) -> Produced {
        let (k, line) = (self.k, self.pose.line);
        let setpoint = if rest {
            self.history.rest(k, line, q)
        } else {
            self.history.setpoint(k, line, q, self.options.period)
        };
        self.produced(setpoint, feed)
    }

    /// `setpoint` produced at path speed `feed`: the counter moves on; where the tool is goes
    /// with it.
    fn produced(&mut self, setpoint: SetPoint, feed: f64) -> Produced {
        self.read_probe();
        self.k += 1;
        Produced {
            setpoint,
            tip: self.pose.tip,
            rotary: self.pose.rotary,
            feed,
            path: self.done_length + self.s,
        }
    }
}

/// The moves that run a program from source line `line`: every modal move before it (feed,
/// feed mode, path mode, smoothing, spindle speed, tool control), a rapid to where the line
/// starts, then the program from the line on.
pub fn restart_moves(program: &[Move], line: u32) -> Result<Vec<Move>, ExecError> {
    let first = program
        .iter()
        .position(|m| m.line >= line && is_motion(&m.kind))
        .ok_or(ExecError::NoSuchLine(line))?;
    let mut out = Vec::new();
    let mut start = None;
    for m in &program[..first] {
        if let Some(end) = move_end(&m.kind) {
            start = Some(end);
        } else if is_modal(&m.kind) {
            out.push(m.clone());
        }
    }
    if let Some(end) = start {
        out.push(Move {
            line,
            kind: MoveKind::Rapid { end },
        });
        // Exactly there before the line runs (a dwell ends the path in a stop).
        out.push(Move {
            line,
            kind: MoveKind::Dwell { seconds: 0.0 },
        });
    }
    out.extend(program[first..].iter().cloned());
    Ok(out)
}

/// Whether the feed override acts on a piece (the path builders stop where the program
/// switches it, so a piece is wholly one or the other).
fn overridable(piece: &tezgah_motion::plan::Piece) -> bool {
    piece.segments.iter().all(|s| s.feed_override)
}

fn is_motion(kind: &MoveKind) -> bool {
    matches!(
        kind,
        MoveKind::Rapid { .. } | MoveKind::Feed { .. } | MoveKind::Arc(_) | MoveKind::Nurbs(_)
    )
}

/// Moves that change a mode the path builder keeps (they move nothing).
fn is_modal(kind: &MoveKind) -> bool {
    matches!(
        kind,
        MoveKind::FeedRate { .. }
            | MoveKind::FeedMode(_)
            | MoveKind::SpindleSpeed { .. }
            | MoveKind::PathMode(_)
            | MoveKind::Smoothing(_)
            | MoveKind::FeedOverride(_)
            | MoveKind::ToolControl { .. }
    )
}

/// Where a motion move ends.
fn move_end(kind: &MoveKind) -> Option<Pose> {
    match kind {
        MoveKind::Rapid { end } | MoveKind::Feed { end } => Some(*end),
        MoveKind::Arc(a) => Some(a.end),
        MoveKind::Nurbs(n) => Some(n.end),
        _ => None,
    }
}
