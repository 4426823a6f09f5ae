//! The interpreter: blocks in, canonical calls out, with LinuxCNC's semantics.
//!
//! It reads a program line by line (lexer → block reader), checks each block against the modal
//! rules, and executes its words in LinuxCNC's fixed order, sending canonical calls to a
//! [`CanonSink`]. [`Interpreter::run`] stops at the first error, as a controller must;
//! [`check`] goes on after an error to report every one (the pre-flight).

mod arc;
mod checks;
mod comments;
mod comp;
mod control;
mod cycles;
mod execute;
mod modes;
mod motion;
mod spline;
mod state;
mod system;
mod tcp;
mod tools;

pub use arc::{center_from_offset, center_from_radius, sweep, ArcTolerance, Sense};
pub use comp::CompError;
pub use control::{ControlLimits, LinePos, SubroutineFile, SubroutineLibrary};
pub use state::{rotate_xy as state_rotate_xy, State};

use tezgah_geom::Pose;

use crate::block::{AxisMask, Block};
use crate::canon::{Canon, CanonSink, Origin, Units};
use crate::error::{ErrorKind, GcodeError};
use crate::lexer::NormLine;
use crate::params::Params;
use crate::span::Span;
use crate::tooltable::ToolTable;

/// What the interpreter needs to know about the machine it runs for.
#[derive(Debug, Clone, Default)]
pub struct Config {
    pub tool_table: ToolTable,
    /// The machine's length units (LinuxCNC's external units): the tool table's offsets and
    /// the offsets and home points kept in parameters (`#5161…`, `#5211…`, `#5221…`) are in
    /// these, whatever G20/G21 is in force. LinuxCNC's standalone `rs274` uses inches.
    pub machine_units: Units,
    /// Guards against runaway loops and recursion.
    pub limits: ControlLimits,
    /// Subroutines in files of their own (`o<name> call` of a name the program lacks).
    pub subroutines: Option<std::sync::Arc<dyn SubroutineLibrary>>,
    /// A LinuxCNC INI file: its values are the read-only `#<_ini[section]name>` parameters.
    pub ini: Option<std::sync::Arc<crate::ini::IniFile>>,
    /// The parameter file the numbered parameters start from (LinuxCNC's `-v` file).
    pub parameters: Option<std::sync::Arc<crate::params::ParameterFile>>,
    /// Pocket index of the tool in the spindle when the program starts (0: none). LinuxCNC's
    /// standalone `rs274` starts with 1, so G10 writes to pocket 1 reach its spindle entry.
    pub start_pocket: usize,
    /// Tool-centre-point control whatever the program says (the machine file's
    /// `tcp = "always"`); read by [`crate::moves::program_moves`], not by the interpreter.
    pub tool_centre_point_always: bool,
    /// The program axes the machine has (LinuxCNC's axis mask): a word of another axis
    /// letter is refused when its line is read. Default all six, as `rs274`.
    pub axes: AxisMask,
    /// What reaching the end of the text without M2, M30 or a closing `%` does.
    pub missing_end: MissingEnd,
    /// Where G38.2–G38.5 find out whether and where the probe tripped.
    pub probe: ProbeModel,
}

/// What answers a probing move (G38.2–G38.5): the probe position (`#5061`…), whether it
/// tripped (`#5070`) and where the move stopped. The program after a probe depends on the
/// answer, so a run on a machine is driven by the executor's: the interpreter stops at a probe
/// it has no answer for ([`ErrorKind::ProbeAwaitsAnswer`]), the executor runs the moves so far
/// and the probe move, and interprets again with one answer more (see `docs/dialect.md`).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ProbeModel {
    /// Refused with [`ErrorKind::ProbeUnavailable`], after LinuxCNC's own checks.
    #[default]
    Unavailable,
    /// LinuxCNC's standalone `rs274`: the probe never trips (`#5070` = 0), `#5061`… hold the
    /// target, and the move stops 0.01 in (0.254 mm) short of it, as its canon layer reports.
    Rs274,
    /// The executor's answers to the program's probe moves so far, in order; the next probe
    /// move stops the pass with [`ErrorKind::ProbeAwaitsAnswer`].
    Answered(std::sync::Arc<[ProbeOutcome]>),
}

/// How the machine answered one probe move. Places are fractions of the move from its start
/// (0) to its programmed end (1): the move is straight in every coordinate system the
/// interpreter and the executor speak, so a fraction means the same point in both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProbeOutcome {
    /// The probe input changed at fraction `at`; the machine came to rest at `stopped`.
    Tripped { at: f64, stopped: f64 },
    /// The move ran to its end without the input changing.
    Completed,
    /// The input was already in the state the move looks for when it started (LinuxCNC
    /// refuses the move).
    AlreadyThere,
}

/// What the end of the text without M2, M30 or a closing `%` does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MissingEnd {
    /// The program ends as if its last line were followed by `M2` (LinuxCNC's milltask runs
    /// every move before it reports the missing end); [`Interpreter::missing_end`] keeps the
    /// error it would have been, for a warning.
    #[default]
    AsM2,
    /// An error, as LinuxCNC's standalone `rs274` reports it.
    Error,
}

impl Config {
    /// The configuration under which `canon` reproduces LinuxCNC's `rs274`.
    pub fn linuxcnc(tool_table: ToolTable) -> Self {
        Config {
            tool_table,
            machine_units: Units::Inches,
            limits: ControlLimits::default(),
            subroutines: None,
            ini: None,
            parameters: None,
            start_pocket: 1,
            tool_centre_point_always: false,
            axes: AxisMask::XYZABC,
            missing_end: MissingEnd::Error,
            probe: ProbeModel::Rs274,
        }
    }
}

/// Whether the program goes on after a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    Continue,
    /// M2/M30 or the closing `%`: nothing after this line is read.
    End,
    /// Control flow goes on at another line (a loop, a call, a return).
    Jump(LinePos),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Percent {
    /// Nothing read yet: a first line `%` opens percent mode.
    Unknown,
    Open,
    Off,
}

/// An RS274/NGC interpreter with its state, parameters and reusable line buffers.
#[derive(Debug, Clone)]
pub struct Interpreter {
    cfg: Config,
    state: State,
    params: Params,
    norm: NormLine,
    /// The block buffer, reused from line to line. Boxed so that lending it out while the
    /// block executes moves a pointer, not the block.
    block: Option<Box<Block>>,
    percent: Percent,
    ended: bool,
    /// Source line being executed, for the canonical calls' origin.
    origin: Origin,
    control: control::Control,
    /// Cutter radius compensation and the moves it holds back.
    comp: comp::CutterComp,
    /// M2/M30 ended a `%` program: the rest of the text should hold the closing `%`.
    closing_percent_sought: bool,
    /// Subroutine files loaded so far; file k of a [`LinePos`] is `files[k - 1]`.
    files: Vec<SubroutineFile>,
    /// What spline blocks carry from block to block (G5 tangent, open G5.2 and G6.2 NURBS).
    spline_memory: spline::SplineMemory,
    /// The program ran out of text without an end and was ended as by M2: the error that
    /// would have been ([`MissingEnd::AsM2`]).
    missing_end: Option<GcodeError>,
    /// What M70/M73 saved at each call level.
    saved_modes: modes::ModeStack,
    /// Probe moves run so far: the index of the next one's answer in
    /// [`ProbeModel::Answered`].
    probes: usize,
    /// The probe move the last line stopped at for want of an answer
    /// ([`Interpreter::answer_probe`] gives it one).
    pending_probe: Option<PendingProbe>,
}

/// A probe move waiting for the machine's answer: its G number ×10 and its ends.
#[derive(Debug, Clone, Copy)]
struct PendingProbe {
    g: u32,
    start: Pose,
    end: Pose,
}

/// Where in the source a line sits, for error spans.
#[derive(Debug, Clone, Copy, Default)]
pub struct LineRef<'a> {
    pub number: u32,
    pub text: &'a str,
    /// Byte offset of the line in the whole program.
    pub start: usize,
    /// Byte offset of the next line.
    pub end: usize,
    /// The text the line is in: 0 the program, k the k-th subroutine file loaded.
    pub file: u16,
}

impl LineRef<'_> {
    /// Where this line starts.
    pub fn pos(&self) -> LinePos {
        LinePos {
            file: self.file,
            start: self.start,
            number: self.number,
        }
    }

    /// Where the line after this one starts.
    pub fn next(&self) -> LinePos {
        LinePos {
            file: self.file,
            start: self.end,
            number: self.number + 1,
        }
    }

    pub fn span(&self, byte: usize) -> Span {
        Span::in_line(self.number, self.text, self.start, byte)
    }
}

impl Interpreter {
    pub fn new(cfg: Config) -> Self {
        let mut params = Params::default();
        params.set(crate::params::COORD_SYSTEM, 1.0);
        if let Some(ini) = cfg.ini.as_ref().filter(|ini| ini.ini_vars()) {
            params.set_ini(ini.clone());
        }
        let state = State {
            current_pocket: cfg.start_pocket,
            ..State::default()
        };
        let mut interp = Interpreter {
            cfg,
            state,
            params,
            norm: NormLine::default(),
            block: Some(Box::default()),
            percent: Percent::Unknown,
            ended: false,
            origin: Origin::default(),
            control: control::Control::default(),
            comp: comp::CutterComp::default(),
            closing_percent_sought: false,
            files: Vec::new(),
            spline_memory: Default::default(),
            missing_end: None,
            saved_modes: Default::default(),
            probes: 0,
            pending_probe: None,
        };
        interp.restore_parameters();
        interp
    }

    /// Start from the parameter file, if any: its active coordinate system (`#5220`) and
    /// offsets, and its G92 offsets unless the INI file's `DISABLE_G92_PERSISTENCE` clears them
    /// (LinuxCNC's `init`).
    fn restore_parameters(&mut self) {
        let Some(file) = self.cfg.parameters.clone() else {
            return;
        };
        for &(n, v) in file.values() {
            self.params.set(n, v);
        }
        let index = (self.params.get(crate::params::COORD_SYSTEM) + 0.0001) as usize;
        let index = if (1..=9).contains(&index) { index } else { 1 };
        self.params.set(crate::params::COORD_SYSTEM, index as f64);
        let (origin, rotation) = self.coordinate_system(index);
        self.state.origin_index = index;
        self.state.origin = origin;
        self.state.rotation = rotation;
        if self.g92_not_persistent() {
            self.clear_g92_parameters();
        }
        if self.params.get(crate::params::G92_ENABLED) != 0.0 {
            self.state.axis_offset = self.offset_params(crate::params::G92_OFFSET);
        }
    }

    /// Whether the INI file makes G92/G52 offsets last only one program run.
    fn g92_not_persistent(&self) -> bool {
        self.cfg.ini.as_ref().is_some_and(|ini| {
            ini.flag("RS274NGC", "DISABLE_G92_PERSISTENCE")
                .unwrap_or(false)
        })
    }

    /// `#5210…#5219` to zero.
    fn clear_g92_parameters(&mut self) {
        for n in crate::params::G92_ENABLED..crate::params::G92_ENABLED + 10 {
            self.params.set(n, 0.0);
        }
    }

    /// Answers the probe move the last line stopped at ([`ErrorKind::ProbeAwaitsAnswer`], one
    /// line at a time as MDI runs): `#5061`… and the position are set as if the line had had
    /// the answer, or LinuxCNC's error for it is returned. What the line held after its motion
    /// (a stop code) is not run. `false` when no probe waits.
    pub fn answer_probe(&mut self, outcome: ProbeOutcome) -> Result<bool, ErrorKind> {
        let Some(p) = self.pending_probe.take() else {
            return Ok(false);
        };
        self.apply_probe(p.g, p.start, p.end, outcome)
            .map(|()| true)
    }

    pub fn state(&self) -> &State {
        &self.state
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Subroutine file `file` of an [`Origin`] or a [`LinePos`] (1 the first loaded), once the
    /// interpreter has loaded it; `None` for 0, the program itself.
    pub fn subroutine_file(&self, file: u16) -> Option<&SubroutineFile> {
        usize::from(file)
            .checked_sub(1)
            .and_then(|k| self.files.get(k))
    }

    /// Whether M2/M30 or the closing `%` has been reached.
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// When the text ended without M2, M30 or a closing `%` and the program was ended as by
    /// M2 ([`MissingEnd::AsM2`]): the error LinuxCNC reports there, at the end of the last line.
    pub fn missing_end(&self) -> Option<&GcodeError> {
        self.missing_end.as_ref()
    }

    /// The calls LinuxCNC makes before the first block (its `rs274` prints them all).
    pub fn start(&mut self, sink: &mut impl CanonSink) {
        self.origin = Origin::default();
        let o = self.origin;
        sink.call(o, Canon::UseLengthUnits(self.state.units));
        sink.call(
            o,
            Canon::SetG5xOffset {
                index: self.state.origin_index as u8,
                offset: self.state.origin,
            },
        );
        sink.call(o, Canon::SetG92Offset(self.state.axis_offset));
        sink.call(o, Canon::SetXyRotation(self.state.rotation));
        sink.call(o, Canon::SetFeedReference);
        sink.call(o, Canon::OnReset);
    }

    /// Interpret a whole program; stops at the first error. Calls [`Self::start`] first.
    pub fn run(&mut self, program: &str, sink: &mut impl CanonSink) -> Result<(), GcodeError> {
        self.start(sink);
        let mut failure = None;
        self.drive(program, sink, |e| {
            failure = Some(e);
            false
        });
        failure.map_or(Ok(()), Err)
    }

    /// Read and execute the program from its first line, following jumps into and out of
    /// subroutine files, until it ends. Each error goes to `on_error`, which says whether to
    /// go on with the next line (the pre-flight) or stop (a run). Reaching the end of the text
    /// without M2/M30 or `%` is an error too, as in LinuxCNC.
    fn drive(
        &mut self,
        program: &str,
        sink: &mut impl CanonSink,
        mut on_error: impl FnMut(GcodeError) -> bool,
    ) {
        let mut at = LinePos::FIRST;
        // The last line of the program read (for the error at its end).
        let mut last = None;
        loop {
            let file = self.file_text(at.file);
            let text = file.as_deref().unwrap_or(program);
            let Some(line) = line_at(text, at) else {
                break;
            };
            if line.file == 0 {
                last = Some(line.pos());
            }
            at = line.next();
            let result = self.execute_line(line, sink);
            match result.map_err(|e| self.in_file(e, line.file)) {
                Ok(Flow::Continue) => {}
                Ok(Flow::Jump(to)) => at = to,
                Ok(Flow::End) => {
                    if line.file == 0 {
                        self.seek_closing_percent(program, at, sink);
                    }
                    return;
                }
                Err(e) => {
                    if !on_error(e) {
                        return;
                    }
                    // Going on after an error inside subroutines: leave them all, as
                    // LinuxCNC unwinds a failed call, and go on after the outermost call.
                    if let Some(to) = self.unwind_calls() {
                        at = to;
                    }
                }
            }
        }
        let last = last.and_then(|p| line_at(program, p)).unwrap_or_default();
        if let Err(e) = self.finish(last, sink) {
            on_error(e);
        }
    }

    /// The text of subroutine file `file` (`None` for the program itself).
    fn file_text(&self, file: u16) -> Option<std::sync::Arc<str>> {
        self.subroutine_file(file).map(|f| f.text.clone())
    }

    /// Name the subroutine file an error comes from.
    fn in_file(&self, mut e: GcodeError, file: u16) -> GcodeError {
        if let Some(f) = self.subroutine_file(file) {
            e.file = Some(f.file_name());
        }
        e
    }

    /// After M2/M30 in a `%` program: note it when no line from `after` on starts with `%`
    /// (LinuxCNC's comment, made after `PROGRAM_END`).
    pub fn seek_closing_percent(
        &mut self,
        program: &str,
        after: LinePos,
        sink: &mut impl CanonSink,
    ) {
        if !std::mem::take(&mut self.closing_percent_sought) {
            return;
        }
        let mut at = after;
        while let Some(line) = line_at(program, at) {
            if line.text.trim_start().starts_with('%') {
                return;
            }
            at = line.next();
        }
        self.comment_call(sink, "percent sign missing from end of file".into());
    }

    /// The end of the text was reached without M2/M30 or closing `%`: an error, as in LinuxCNC's
    /// `rs274`, or (as its milltask runs every move first) the program ends as if `M2` followed
    /// its last line, as `cfg.missing_end` says.
    pub fn finish(&mut self, last: LineRef, sink: &mut impl CanonSink) -> Result<(), GcodeError> {
        if self.ended {
            return Ok(());
        }
        if let Some(kind) = self.control.unfinished() {
            return Err(GcodeError::new(kind, last.span(last.text.len())));
        }
        let kind = if self.percent == Percent::Open || last.number == 0 {
            ErrorKind::NoClosingPercent
        } else {
            ErrorKind::NoProgramEnd
        };
        let error = GcodeError::new(kind, last.span(last.text.len()));
        if self.cfg.missing_end == MissingEnd::Error {
            return Err(error);
        }
        self.missing_end = Some(error);
        // The `M2` stands just past the last line, as the last line's.
        let m2 = LineRef {
            text: "M2",
            start: last.end,
            file: 0,
            ..last
        };
        self.execute_line(m2, sink).map(|_| ())
    }

    /// Read, check and execute one line.
    pub fn execute_line(
        &mut self,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Result<Flow, GcodeError> {
        if self.ended {
            return Ok(Flow::End);
        }
        self.pending_probe = None;
        let mut block = self.block.take().unwrap_or_default();
        let result = self.read_and_execute(&mut block, line, sink);
        self.block = Some(block);
        result
    }

    fn read_and_execute(
        &mut self,
        block: &mut Block,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Result<Flow, GcodeError> {
        self.norm
            .lex(line.text)
            .map_err(|(kind, byte)| GcodeError::new(kind, line.span(byte)))?;
        if let Some(flow) = self.percent_line(line)? {
            if flow == Flow::End {
                // The closing `%` ends the text: a skip still looking for its O-word fails
                // (after FINISH, as rs274 reports it).
                if let Some(label) = self.control.skip_label() {
                    sink.call(Origin::default(), Canon::Finish);
                    let kind = ErrorKind::SkippedPastPercent(label);
                    return Err(GcodeError::new(kind, line.span(0)));
                }
                // Moves cutter compensation still holds are not lost at the closing `%`
                // (LinuxCNC drops them; only M0/M1/M2/M30 release them there).
                self.flush_comp(sink)
                    .map_err(|kind| GcodeError::new(kind, line.span(0)))?;
                sink.call(Origin::default(), Canon::Finish);
            }
            return Ok(flow);
        }
        if self.control.skipping() {
            return self.skipped_line(line, sink);
        }
        if self.norm.mentions_parameters {
            self.publish_system_values(line.number);
        }
        let Self {
            norm, params, cfg, ..
        } = self;
        let to_span = |norm: &NormLine, idx: usize| {
            let byte = norm.at().get(idx).map_or(line.text.len(), |&b| b as usize);
            line.span(byte)
        };
        let live = block
            .read(norm, params, cfg.axes)
            .map_err(|(kind, idx)| GcodeError::new(kind, to_span(norm, idx)))?;
        if !live {
            return Ok(Flow::Continue);
        }
        self.origin = Origin {
            line: line.number,
            n: block.n,
            file: line.file,
        };
        self.control.next_line = Some(line.next());
        if let Some(o) = block.o.take() {
            let at = o.at as usize;
            let flow = self
                .o_word(&o, line, sink)
                .map_err(|(kind, _)| GcodeError::new(kind, line.span(at)));
            return flow;
        }
        self.execute_block(block, line, sink)
    }

    /// Handle `%` lines (after lexing, which finds the `%`). `Some(flow)` when the line was
    /// a percent line.
    #[inline]
    fn percent_line(&mut self, line: LineRef) -> Result<Option<Flow>, GcodeError> {
        // Almost every line: no `%` in it, and the program's first line already seen.
        if self.norm.percent.is_none() && self.percent != Percent::Unknown {
            return Ok(None);
        }
        self.percent_line_slow(line)
    }

    /// [`Interpreter::percent_line`] for a line with a `%` or the program's first line.
    fn percent_line_slow(&mut self, line: LineRef) -> Result<Option<Flow>, GcodeError> {
        let percent_at = self.norm.percent;
        let is_percent = percent_at.is_some() && line.text.trim() == "%";
        if self.percent == Percent::Unknown {
            self.percent = if is_percent {
                Percent::Open
            } else {
                Percent::Off
            };
            if is_percent {
                return Ok(Some(Flow::Continue));
            }
        } else if is_percent && self.percent == Percent::Open {
            self.ended = true;
            return Ok(Some(Flow::End));
        }
        match percent_at {
            // A `%` anywhere else, outside comments, is not G-code.
            Some(at) => Err(GcodeError::new(ErrorKind::BadCharacter('%'), line.span(at))),
            None => Ok(None),
        }
    }

    /// Apply a block's parameter assignments (after the whole line was read, as LinuxCNC).
    #[inline]
    fn assign_parameters(&mut self, block: &Block) -> Result<(), (ErrorKind, u32)> {
        if block.assignments.is_empty() {
            return Ok(());
        }
        self.assign_parameters_slow(block)
    }

    /// [`Interpreter::assign_parameters`] for a block that has assignments.
    fn assign_parameters_slow(&mut self, block: &Block) -> Result<(), (ErrorKind, u32)> {
        for a in &block.assignments {
            match &a.target {
                crate::reader::ParamRef::Numbered(n) => self.params.set(*n, a.value),
                crate::reader::ParamRef::Named(name) if self.params.is_read_only(name) => {
                    return Err((ErrorKind::ReadOnlyParameter(name.clone()), a.at));
                }
                crate::reader::ParamRef::Named(name) => self.params.set_named(name, a.value),
            }
        }
        Ok(())
    }

    /// Whether the INI file refuses Fanuc-style subprograms.
    fn fanuc_subs_disabled(&self) -> bool {
        self.cfg
            .ini
            .as_ref()
            .is_some_and(|ini| ini.fanuc_subs_disabled())
    }

    /// Send a call, or hold it behind moves that cutter compensation holds back.
    fn emit(&mut self, sink: &mut impl CanonSink, call: Canon) {
        self.emit_or_hold(sink, call);
    }

    /// Program units per machine unit: a length in the machine's units (tool table,
    /// parameters) times this is in the program's units (LinuxCNC's `USER_TO_PROGRAM_LEN`).
    fn program_per_machine_unit(&self) -> f64 {
        self.cfg.machine_units.mm() / self.state.units.mm()
    }

    /// Machine units per program unit (LinuxCNC's `PROGRAM_TO_USER_LEN`).
    fn machine_per_program_unit(&self) -> f64 {
        self.state.units.mm() / self.cfg.machine_units.mm()
    }

    /// A pose in the machine's units in the program's units (angles are not lengths).
    fn to_program_units(&self, p: Pose) -> Pose {
        p.scale_linear(self.program_per_machine_unit())
    }

    /// A pose in the program's units in the machine's.
    fn to_machine_units(&self, p: Pose) -> Pose {
        p.scale_linear(self.machine_per_program_unit())
    }

    /// Six offset parameters from `base` on, in program units.
    fn offset_params(&self, base: usize) -> Pose {
        self.to_program_units(Pose(self.params.get6(base)))
    }

    /// Store an offset given in program units in the six parameters from `base` on.
    fn set_offset_params(&mut self, base: usize, p: Pose) {
        let stored = self.to_machine_units(p);
        self.params.set6(base, stored.0);
    }

    /// Tool offsets of `tool` from the table, in program units.
    fn table_offset(&self, number: i64) -> Option<Pose> {
        let offset = self.cfg.tool_table.get(number)?.offset;
        Some(self.to_program_units(offset))
    }
}

/// The line that starts at `at`, if the program goes on that far (lines end with `\n` or
/// `\r\n`).
pub fn line_at(program: &str, at: LinePos) -> Option<LineRef<'_>> {
    let start = at.start;
    let rest = program.as_bytes().get(start..).filter(|r| !r.is_empty())?;
    let len = memchr_newline(rest);
    let text = &program[start..start + len];
    Some(LineRef {
        file: at.file,
        number: at.number,
        text: text.strip_suffix('\r').unwrap_or(text),
        start,
        end: start + (len + 1).min(rest.len()),
    })
}

fn memchr_newline(s: &[u8]) -> usize {
    memchr::memchr(b'\n', s).unwrap_or(s.len())
}

/// The pre-flight stops after this many errors.
pub const MAX_CHECK_ERRORS: usize = 100;

/// Pre-flight: interpret the whole program and collect every error instead of stopping at the
/// first. After an error, interpretation goes on with the next line from the state the failed
/// block left (the words executed before the failing one keep their effect, as in LinuxCNC).
pub fn check(program: &str, cfg: Config) -> Vec<GcodeError> {
    check_into(program, cfg, &mut crate::canon::Discard)
}

/// [`check`], sending the calls of the blocks that pass to `sink` (for summaries).
pub fn check_into(program: &str, cfg: Config, sink: &mut impl CanonSink) -> Vec<GcodeError> {
    Interpreter::new(cfg).check(program, sink)
}

impl Interpreter {
    /// [`check_into`] on this interpreter, which keeps what the program loaded (its subroutine
    /// files, for error reports) and its final state. With no error, `sink` has received
    /// exactly the calls [`Interpreter::run`] sends, so one pass serves the check and the moves.
    pub fn check(&mut self, program: &str, sink: &mut impl CanonSink) -> Vec<GcodeError> {
        self.start(sink);
        let mut errors = Vec::new();
        self.drive(program, sink, |e| {
            // After a runaway loop or recursion, or enough errors, going on tells nothing more
            // (and a loop whose counting line fails would go on for ever).
            let hopeless = matches!(
                e.kind,
                ErrorKind::RunawayLoop(..) | ErrorKind::CallsTooDeep(_)
            );
            errors.push(e);
            !hopeless && errors.len() < MAX_CHECK_ERRORS
        });
        errors
    }
}
