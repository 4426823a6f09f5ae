//! O-word control flow: subroutines, conditionals and loops, as LinuxCNC runs them.
//!
//! The interpreter reads a program line by line. A jump back (a loop, a return) goes to a line
//! position recorded when that line was met; a jump forward (a false `if`, a `break`, a
//! subroutine definition, a call to a subroutine defined further on) is a skip: lines are read
//! without being executed until the O-word sought turns up, as LinuxCNC does.

use std::collections::HashMap;
use std::sync::Arc;

use crate::block::{read_o_word, OKeyword, OLabel, OWord};
use crate::canon::CanonSink;
use crate::error::{ErrorKind, GcodeError};
use crate::params::CALL_PARAMETERS;
use crate::reader::Reader;

use super::execute::Exec;
use super::{Flow, Interpreter, LineRef};

/// Where a line starts: the text it is in (0 = the program, k = the k-th subroutine file
/// loaded), its byte offset there and its 1-based number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinePos {
    pub file: u16,
    pub start: usize,
    pub number: u32,
}

impl LinePos {
    /// The first line of a program.
    pub const FIRST: LinePos = LinePos {
        file: 0,
        start: 0,
        number: 1,
    };

    /// The first line of subroutine file `file`.
    pub fn start_of(file: u16) -> LinePos {
        LinePos {
            file,
            ..LinePos::FIRST
        }
    }
}

/// Limits that turn a runaway program into an error instead of a hang.
#[derive(Debug, Clone, Copy)]
pub struct ControlLimits {
    /// Passes any one loop may make (counted from the loop's start).
    pub max_loop_iterations: u64,
    /// Subroutine calls that may be active at once.
    pub max_call_depth: usize,
}

impl Default for ControlLimits {
    fn default() -> Self {
        ControlLimits {
            max_loop_iterations: 10_000_000,
            max_call_depth: 64,
        }
    }
}

/// An active subroutine call.
#[derive(Debug, Clone)]
struct Frame {
    return_to: LinePos,
    saved: [f64; CALL_PARAMETERS],
    /// Loops open when the call was made; the callee's are dropped on return.
    loops: usize,
    /// A Fanuc-style M98 call: parameters are shared, not saved, and the body runs L times.
    fanuc: Option<FanucCall>,
}

/// The repeat state of an M98 call.
#[derive(Debug, Clone, Copy)]
struct FanucCall {
    body: LinePos,
    passes_left: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LoopKind {
    While,
    Do,
    Repeat,
}

/// An open loop.
#[derive(Debug, Clone)]
struct Loop {
    label: OLabel,
    kind: LoopKind,
    /// The `while`, `do` or `repeat` line.
    start: LinePos,
    /// The line after it.
    body: LinePos,
    /// Passes left (`repeat`).
    remaining: f64,
    iterations: u64,
}

/// What a skip looks for.
#[derive(Debug, Clone)]
enum Skip {
    /// The `endsub` of a definition met in passing.
    Definition(OLabel),
    /// After a false `if`/`elseif`: a true `elseif`, an `else` or the `endif`.
    Branch(OLabel),
    /// After a branch ran: the `endif`.
    PastIf(OLabel),
    /// After a false `while`, a zero `repeat` or a `break`: the loop's end.
    PastLoop(OLabel, LoopKind),
    /// `continue` in a `do` loop: its closing `while`, which is then executed.
    DoCondition(OLabel),
    /// A call to a subroutine not met yet: its `sub` line.
    Call {
        label: OLabel,
        args: Vec<f64>,
        return_to: LinePos,
    },
    /// An M98 call to a subprogram not met yet: its `O<n>` line.
    FanucCall {
        label: OLabel,
        passes: u32,
        return_to: LinePos,
    },
}

/// The control-flow state of a running program.
#[derive(Debug, Clone, Default)]
pub struct Control {
    /// Where each subroutine met so far begins (the line after its `sub`).
    subs: HashMap<OLabel, LinePos>,
    frames: Vec<Frame>,
    loops: Vec<Loop>,
    skip: Option<Skip>,
    /// Fanuc-style subprograms met so far (the line after their `O<n>`).
    programs: HashMap<OLabel, LinePos>,
    /// The line after the one executing (where an M98 returns to).
    pub(super) next_line: Option<LinePos>,
}

impl Control {
    /// The error to report when the program ends in the middle of a skip.
    pub fn unfinished(&self) -> Option<ErrorKind> {
        Some(match self.skip.as_ref()? {
            Skip::Call { label, .. } | Skip::FanucCall { label, .. } => {
                ErrorKind::SubroutineNotFound(label.to_string())
            }
            Skip::Definition(l) => ErrorKind::OWordTargetMissing(l.to_string(), "endsub"),
            Skip::Branch(l) | Skip::PastIf(l) => {
                ErrorKind::OWordTargetMissing(l.to_string(), "endif")
            }
            Skip::PastLoop(l, _) | Skip::DoCondition(l) => {
                ErrorKind::OWordTargetMissing(l.to_string(), "end of loop")
            }
        })
    }

    pub fn skipping(&self) -> bool {
        self.skip.is_some()
    }

    /// The label a skip looks for, if one is under way.
    pub fn skip_label(&self) -> Option<String> {
        Some(match self.skip.as_ref()? {
            Skip::Call { label, .. } | Skip::FanucCall { label, .. } => label.to_string(),
            Skip::Definition(l)
            | Skip::Branch(l)
            | Skip::PastIf(l)
            | Skip::PastLoop(l, _)
            | Skip::DoCondition(l) => l.to_string(),
        })
    }
}

impl Control {
    /// How deep in calls the program is (0: the program itself, LinuxCNC's `call_level`).
    pub(super) fn call_level(&self) -> usize {
        self.frames.len()
    }
}

impl Interpreter {
    /// A line met while skipping: only an O-word matching the skip's target counts.
    pub(super) fn skipped_line(
        &mut self,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Result<Flow, GcodeError> {
        let text = self.norm.text();
        // An N word may stand before the O-word.
        let mut i = 0;
        if text.first() == Some(&b'n') {
            i = 1 + text[1..]
                .iter()
                .take_while(|c| c.is_ascii_digit() || **c == b'.')
                .count();
        }
        if text.get(i) != Some(&b'o') {
            return Ok(Flow::Continue);
        }
        let at = self.norm.at().get(i).copied().unwrap_or(0);
        let mut r = Reader::new(text, i, &self.params);
        let Ok(o) = read_o_word(&mut r, at, false) else {
            // Malformed control lines are reported when they execute, not when skipped.
            return Ok(Flow::Continue);
        };
        let span = |kind| GcodeError::new(kind, line.span(at as usize));
        let skip = self.control.skip.clone();
        let matches = |l: &OLabel| *l == o.label;
        match (skip, o.keyword) {
            (Some(Skip::Definition(_)), OKeyword::Sub) => {
                return Err(span(ErrorKind::NestedSubroutine));
            }
            (Some(Skip::Definition(l)), OKeyword::EndSub) if matches(&l) => {
                self.control.skip = None;
            }
            (Some(Skip::Branch(l)), OKeyword::ElseIf) if matches(&l) => {
                // Its condition decides; read the line again, this time evaluating.
                let o = self.read_control_line(line)?;
                if self.condition(&o).map_err(|(k, _)| span(k))? {
                    self.control.skip = None;
                }
            }
            (Some(Skip::Branch(l)), OKeyword::Else | OKeyword::EndIf)
            | (Some(Skip::PastIf(l)), OKeyword::EndIf)
                if matches(&l) =>
            {
                self.control.skip = None;
            }
            (Some(Skip::PastLoop(l, kind)), k)
                if matches(&l)
                    && matches!(
                        (kind, k),
                        (LoopKind::While, OKeyword::EndWhile)
                            | (LoopKind::Do, OKeyword::While)
                            | (LoopKind::Repeat, OKeyword::EndRepeat)
                    ) =>
            {
                self.control.skip = None;
            }
            (Some(Skip::DoCondition(l)), OKeyword::While) if matches(&l) => {
                self.control.skip = None;
                let o = self.read_control_line(line)?;
                return self.o_word(&o, line, sink).map_err(|(k, _)| span(k));
            }
            // The two styles do not mix: the definition must be of the call's kind.
            (Some(Skip::Call { label, .. }), OKeyword::Program) if matches(&label) => {
                return Err(span(ErrorKind::FanucSubNeedsM98));
            }
            (Some(Skip::FanucCall { label, .. }), OKeyword::Sub) if matches(&label) => {
                return Err(span(ErrorKind::NgcSubNeedsCall));
            }
            (
                Some(Skip::FanucCall {
                    label,
                    passes,
                    return_to,
                }),
                OKeyword::Program,
            ) if matches(&label) => {
                self.control.skip = None;
                self.control.programs.insert(label, line.next());
                self.enter_fanuc(line.next(), passes, return_to)
                    .map_err(|(k, _)| span(k))?;
            }
            (
                Some(Skip::Call {
                    label,
                    args,
                    return_to,
                }),
                OKeyword::Sub,
            ) if matches(&label) => {
                self.control.skip = None;
                self.control.subs.insert(label, line.next());
                self.enter_call(&args, return_to)
                    .map_err(|(k, _)| span(k))?;
            }
            _ => {}
        }
        Ok(Flow::Continue)
    }

    /// Read the current (lexed) control line in full, its bracketed values evaluated.
    fn read_control_line(&mut self, line: LineRef) -> Result<OWord, GcodeError> {
        let mut block = self.block.take().unwrap_or_default();
        let read = block.read(&self.norm, &self.params, self.cfg.axes);
        let o = block.o.take();
        self.block = Some(block);
        let at = |idx: usize| {
            let byte = self
                .norm
                .at()
                .get(idx)
                .map_or(line.text.len(), |&b| b as usize);
            line.span(byte)
        };
        read.map_err(|(kind, idx)| GcodeError::new(kind, at(idx)))?;
        o.ok_or_else(|| GcodeError::new(ErrorKind::OLabelMissing, at(0)))
    }

    /// The condition of `if`, `elseif` or `while`: its value is true unless zero.
    fn condition(&self, o: &OWord) -> Exec<bool> {
        let v = o
            .args
            .first()
            .ok_or((ErrorKind::OWordNeedsValue(o.keyword.name()), o.at))?;
        Ok(*v != 0.0)
    }

    /// Execute an O-word line (not skipping).
    pub(super) fn o_word(
        &mut self,
        o: &OWord,
        line: LineRef,
        sink: &mut impl CanonSink,
    ) -> Exec<Flow> {
        let label = &o.label;
        let unmatched = |what| (ErrorKind::UnmatchedOWord(what, label.to_string()), o.at);
        match o.keyword {
            // A program number (`O1000`, `O<name>`): LinuxCNC goes on executing through it at
            // the top level, so a Fanuc-style subprogram belongs after M2/M30. It is noted so
            // that a later M98 finds it.
            OKeyword::Program if self.fanuc_subs_disabled() => {
                return Err((ErrorKind::FanucProgramDisabled, o.at));
            }
            OKeyword::Program => {
                self.control.programs.insert(label.clone(), line.next());
            }
            // Subroutines are defined at the program's level, never inside another's body.
            OKeyword::Sub if !self.control.frames.is_empty() => {
                return Err((ErrorKind::NestedSubroutine, o.at));
            }
            // A definition met again in the program's flow (after a call jumped to it from
            // before, with no M2 between): LinuxCNC's "illegal location" and redefinition errors.
            OKeyword::Sub => {
                if let Some(&body) = self.control.subs.get(label) {
                    let kind = if body == line.next() {
                        ErrorKind::SubInIllegalLocation(line.number, label.to_string())
                    } else {
                        ErrorKind::SubRedefined(line.number, label.to_string())
                    };
                    return Err((kind, o.at));
                }
                self.control.subs.insert(label.clone(), line.next());
                self.control.skip = Some(Skip::Definition(label.clone()));
            }
            OKeyword::EndSub | OKeyword::Return => {
                if self
                    .control
                    .frames
                    .last()
                    .is_some_and(|f| f.fanuc.is_some())
                {
                    return Err((ErrorKind::FanucSubNeedsM99, o.at));
                }
                let frame = self.control.frames.pop().ok_or_else(|| {
                    unmatched(if o.keyword == OKeyword::Return {
                        "return"
                    } else {
                        "endsub"
                    })
                })?;
                let value = o.args.first().copied();
                self.params.system.value = value.unwrap_or(0.0);
                self.params.system.value_returned = if value.is_some() { 1.0 } else { 0.0 };
                self.params.leave_call(frame.saved);
                self.control.loops.truncate(frame.loops);
                // M73 in the subroutine: its modes are restored on return.
                let level = self.control.frames.len() + 1;
                if let Some(saved) = self.saved_modes.leave(level) {
                    self.restore_modes(&saved, line, sink)
                        .map_err(|kind| (kind, o.at))?;
                }
                return Ok(Flow::Jump(frame.return_to));
            }
            OKeyword::Call => match self.control.subs.get(label).copied() {
                Some(body) => {
                    self.enter_call(&o.args, line.next())?;
                    return Ok(Flow::Jump(body));
                }
                None => {
                    // A subroutine not met yet: from its own file if the library has one (read
                    // from its first line, skipping to the `sub`), else further on in this text.
                    let file = self.load_subroutine_file(label);
                    // A subroutine file holds its one subroutine: nothing further on in it
                    // may be called (LinuxCNC's rule).
                    if file.is_none() && line.file != 0 {
                        return Err((ErrorKind::SubroutineNotFound(label.to_string()), o.at));
                    }
                    self.control.skip = Some(Skip::Call {
                        label: label.clone(),
                        args: o.args.clone(),
                        return_to: line.next(),
                    });
                    if let Some(file) = file {
                        return Ok(Flow::Jump(LinePos::start_of(file)));
                    }
                }
            },
            OKeyword::If => {
                if !self.condition(o)? {
                    self.control.skip = Some(Skip::Branch(label.clone()));
                }
            }
            // Met after a branch that ran: the rest of the `if` is passed over.
            OKeyword::ElseIf | OKeyword::Else => {
                self.control.skip = Some(Skip::PastIf(label.clone()));
            }
            OKeyword::EndIf => {}
            OKeyword::Do => self.open_loop(label, LoopKind::Do, line, 0.0),
            OKeyword::While => return self.while_line(o, line),
            OKeyword::EndWhile => {
                let l = self
                    .innermost_loop(label, LoopKind::While)
                    .ok_or_else(|| unmatched("endwhile"))?;
                let start = l.start;
                // Loops opened inside and never closed end here: the head runs again as the
                // same loop (its passes counted by the guard, the stack not growing).
                self.unwind_to_loop(label);
                return Ok(Flow::Jump(start));
            }
            OKeyword::Repeat => {
                let n = o
                    .args
                    .first()
                    .copied()
                    .ok_or((ErrorKind::OWordNeedsValue("repeat"), o.at))?;
                self.open_loop(label, LoopKind::Repeat, line, n.round());
                if n.round() <= 0.0 {
                    self.control.loops.pop();
                    self.control.skip = Some(Skip::PastLoop(label.clone(), LoopKind::Repeat));
                }
            }
            OKeyword::EndRepeat => return self.repeat_again(label, o.at),
            OKeyword::Break => {
                let kind = self
                    .unwind_to_loop(label)
                    .ok_or_else(|| unmatched("break"))?;
                self.control.loops.pop();
                self.control.skip = Some(Skip::PastLoop(label.clone(), kind));
            }
            OKeyword::Continue => {
                let kind = self
                    .unwind_to_loop(label)
                    .ok_or_else(|| unmatched("continue"))?;
                match kind {
                    LoopKind::While => {
                        let start = self.control.loops.last().map(|l| l.start);
                        return Ok(start.map_or(Flow::Continue, Flow::Jump));
                    }
                    LoopKind::Repeat => return self.repeat_again(label, o.at),
                    LoopKind::Do => {
                        self.control.skip = Some(Skip::DoCondition(label.clone()));
                    }
                }
            }
        }
        Ok(Flow::Continue)
    }

    fn open_loop(&mut self, label: &OLabel, kind: LoopKind, line: LineRef, remaining: f64) {
        self.control.loops.push(Loop {
            label: label.clone(),
            kind,
            start: line.pos(),
            body: line.next(),
            remaining,
            iterations: 0,
        });
    }

    /// The innermost open loop of `kind` labelled `label`.
    fn innermost_loop(&self, label: &OLabel, kind: LoopKind) -> Option<&Loop> {
        self.control
            .loops
            .iter()
            .rev()
            .find(|l| l.label == *label && l.kind == kind)
    }

    /// Close the loops inside the one labelled `label`; that one stays open. Its kind, if any.
    fn unwind_to_loop(&mut self, label: &OLabel) -> Option<LoopKind> {
        let i = self.control.loops.iter().rposition(|l| l.label == *label)?;
        self.control.loops.truncate(i + 1);
        Some(self.control.loops[i].kind)
    }

    /// One more pass of the innermost loop, unless the guard says it runs away.
    fn count_pass(&mut self, at: u32) -> Exec {
        let limit = self.cfg.limits.max_loop_iterations;
        if let Some(l) = self.control.loops.last_mut() {
            l.iterations += 1;
            if l.iterations > limit {
                return Err((ErrorKind::RunawayLoop(l.label.to_string(), limit), at));
            }
        }
        Ok(())
    }

    /// `while`: the head of a `while` loop, or the end of a `do` loop.
    fn while_line(&mut self, o: &OWord, line: LineRef) -> Exec<Flow> {
        let label = &o.label;
        // The loop this line belongs to may have loops left open inside it: they end here.
        let own = self.control.loops.iter().rposition(|l| {
            l.label == *label
                && (l.kind == LoopKind::Do || (l.kind == LoopKind::While && l.start == line.pos()))
        });
        if let Some(i) = own {
            self.control.loops.truncate(i + 1);
        }
        let top = self.control.loops.last();
        let closes_do = top.is_some_and(|l| l.label == *label && l.kind == LoopKind::Do);
        let again = top.is_some_and(|l| l.label == *label && l.start == line.pos());
        let go_on = self.condition(o)?;
        if closes_do {
            if go_on {
                self.count_pass(o.at)?;
                let body = self.control.loops.last().map(|l| l.body);
                return Ok(body.map_or(Flow::Continue, Flow::Jump));
            }
            self.control.loops.pop();
            return Ok(Flow::Continue);
        }
        if again {
            self.count_pass(o.at)?;
        } else {
            self.open_loop(label, LoopKind::While, line, 0.0);
        }
        if !go_on {
            self.control.loops.pop();
            self.control.skip = Some(Skip::PastLoop(label.clone(), LoopKind::While));
        }
        Ok(Flow::Continue)
    }

    /// `endrepeat` (or `continue` in a `repeat`): the next pass, or out of the loop.
    fn repeat_again(&mut self, label: &OLabel, at: u32) -> Exec<Flow> {
        let is_top = self
            .control
            .loops
            .last()
            .is_some_and(|l| l.label == *label && l.kind == LoopKind::Repeat);
        if !is_top {
            return Err((
                ErrorKind::UnmatchedOWord("endrepeat", label.to_string()),
                at,
            ));
        }
        self.count_pass(at)?;
        let Some(l) = self.control.loops.last_mut() else {
            return Ok(Flow::Continue);
        };
        l.remaining -= 1.0;
        if l.remaining > 0.0 {
            return Ok(Flow::Jump(l.body));
        }
        self.control.loops.pop();
        Ok(Flow::Continue)
    }

    /// M98 P… L… (call a Fanuc-style subprogram L times) and M99 (its end).
    pub(super) fn subprogram(
        &mut self,
        block: &crate::block::Block,
        m: u32,
        at: u32,
    ) -> Exec<Flow> {
        let return_to = self.control.next_line.unwrap_or(LinePos::FIRST);
        if m == 98 {
            let p = block.get(b'p').unwrap_or(0.0).round() as i64;
            let label = OLabel::Number(p);
            let passes = block.get(b'l').map_or(1, |l| l.max(0.0).round() as u32);
            if passes == 0 {
                return Ok(Flow::Continue);
            }
            return match self.control.programs.get(&label).copied() {
                Some(body) => {
                    self.enter_fanuc(body, passes, return_to)?;
                    Ok(Flow::Jump(body))
                }
                None => {
                    self.control.skip = Some(Skip::FanucCall {
                        label,
                        passes,
                        return_to,
                    });
                    Ok(Flow::Continue)
                }
            };
        }
        let Some(frame) = self.control.frames.last_mut() else {
            return Err((ErrorKind::M99InMain, at));
        };
        let Some(fanuc) = frame.fanuc.as_mut() else {
            return Err((ErrorKind::NgcSubEndedByM99, at));
        };
        fanuc.passes_left -= 1;
        if fanuc.passes_left > 0 {
            let body = fanuc.body;
            self.count_pass(at)?;
            return Ok(Flow::Jump(body));
        }
        let return_to = frame.return_to;
        let loops = frame.loops;
        self.control.frames.pop();
        self.control.loops.truncate(loops);
        Ok(Flow::Jump(return_to))
    }

    /// Start an M98 call: parameters stay as they are (Fanuc subprograms share them).
    fn enter_fanuc(&mut self, body: LinePos, passes: u32, return_to: LinePos) -> Exec {
        let depth = self.cfg.limits.max_call_depth;
        if self.control.frames.len() >= depth {
            return Err((ErrorKind::CallsTooDeep(depth), 0));
        }
        self.control.frames.push(Frame {
            return_to,
            saved: [0.0; CALL_PARAMETERS],
            loops: self.control.loops.len(),
            fanuc: Some(FanucCall {
                body,
                passes_left: passes,
            }),
        });
        Ok(())
    }

    /// Leave every active call (after an error inside one): the callers' parameters come back
    /// and control flow resumes after the outermost call, which is returned.
    pub(super) fn unwind_calls(&mut self) -> Option<LinePos> {
        let mut resume = None;
        while let Some(frame) = self.control.frames.pop() {
            if frame.fanuc.is_none() {
                self.params.leave_call(frame.saved);
            }
            self.control.loops.truncate(frame.loops);
            resume = Some(frame.return_to);
        }
        if resume.is_some() {
            self.control.skip = None;
        }
        resume
    }

    /// Load the file that defines subroutine `label` from the configured library, once; its
    /// index among the loaded texts.
    fn load_subroutine_file(&mut self, label: &OLabel) -> Option<u16> {
        let OLabel::Name(name) = label else {
            return None;
        };
        if let Some(i) = self.files.iter().position(|f| f.name == *name) {
            return Some(i as u16 + 1);
        }
        let text = self.cfg.subroutines.as_ref()?.source(name)?;
        self.files.push(SubroutineFile {
            name: name.clone(),
            text: text.into(),
        });
        u16::try_from(self.files.len()).ok()
    }

    /// Start a call: the caller's `#1`…`#30` are kept, the arguments take their place.
    fn enter_call(&mut self, args: &[f64], return_to: LinePos) -> Exec {
        let depth = self.cfg.limits.max_call_depth;
        if self.control.frames.len() >= depth {
            return Err((ErrorKind::CallsTooDeep(depth), 0));
        }
        let saved = self.params.enter_call(args);
        self.params.system.value = 0.0;
        self.params.system.value_returned = 0.0;
        self.control.frames.push(Frame {
            return_to,
            saved,
            loops: self.control.loops.len(),
            fanuc: None,
        });
        self.saved_modes.enter(self.control.frames.len());
        Ok(())
    }
}

/// Where subroutines that live in their own files come from (LinuxCNC's `SUBROUTINE_PATH`):
/// `o<name> call` of a subroutine not defined in the program asks for the text of `name`.
/// The library, not the interpreter, knows about files.
pub trait SubroutineLibrary: std::fmt::Debug + Send + Sync {
    /// The text of the file that defines subroutine `name` (lower case), if there is one.
    fn source(&self, name: &str) -> Option<String>;

    /// Where that file was read from, for reports to name it (else they say `<name>.ngc`).
    fn path(&self, _name: &str) -> Option<std::path::PathBuf> {
        None
    }
}

/// A subroutine file the interpreter has loaded.
#[derive(Debug, Clone)]
pub struct SubroutineFile {
    /// The subroutine's name (the file is `<name>.ngc`).
    pub name: String,
    pub text: Arc<str>,
}

impl SubroutineFile {
    /// The file's name, `<name>.ngc`, as errors in it name it.
    pub fn file_name(&self) -> String {
        format!("{}.ngc", self.name)
    }
}
