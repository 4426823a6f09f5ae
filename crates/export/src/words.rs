//! The words a joint-space controller still needs that are not motion: spindle, coolant, tool
//! and operator messages. Collected from the interpreter's canonical calls (a `CanonSink`
//! beside the move builder) with their place in the motion stream, so the writer can put each
//! back between the same two moves it stood between in the program.

use tezgah_gcode::canon::SpindleDir;
use tezgah_gcode::{Canon, CanonSink, Origin};
use tezgah_geom::{Move, MoveKind};

/// One carried-through word group, e.g. `M3`, `S12000`, `T2`, `M6`, `(MSG,…)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// How many motion calls (traverses, feeds, arcs, splines, dwells, stops) came before it.
    pub after_motions: usize,
    /// The source line (in its own file) and the file (0 = the program).
    pub line: u32,
    pub file: u16,
    /// The G-code text written.
    pub text: String,
}

/// A [`CanonSink`] that keeps the spindle, coolant, tool and message words of a program.
/// Give it to `gcode::sources::interpret` as its extra sink.
#[derive(Debug, Default)]
pub struct PassThrough {
    motions: usize,
    words: Vec<Word>,
}

impl PassThrough {
    pub fn new() -> Self {
        Self::default()
    }

    /// The words in program order.
    pub fn words(&self) -> &[Word] {
        &self.words
    }

    /// Each word with the index in `moves` of the first motion move after it (`moves.len()`
    /// after the last): the moves must be the same interpretation's, whose motion moves are
    /// the motion calls one for one (`gcode::moves::MoveBuilder`).
    pub fn placed(&self, moves: &[Move]) -> Vec<(usize, Word)> {
        let motion_index: Vec<usize> = moves
            .iter()
            .enumerate()
            .filter(|(_, m)| is_motion_move(&m.kind))
            .map(|(i, _)| i)
            .collect();
        self.words
            .iter()
            .map(|w| {
                let at = motion_index
                    .get(w.after_motions)
                    .copied()
                    .unwrap_or(moves.len());
                (at, w.clone())
            })
            .collect()
    }

    fn push(&mut self, origin: Origin, text: String) {
        // LinuxCNC's M9 is two calls (mist off, flood off): one word is enough.
        if let Some(last) = self.words.last() {
            if last.text == text
                && last.after_motions == self.motions
                && last.line == origin.line
                && last.file == origin.file
            {
                return;
            }
        }
        self.words.push(Word {
            after_motions: self.motions,
            line: origin.line,
            file: origin.file,
            text,
        });
    }
}

/// The canonical calls the move builder turns into a motion move (one each).
fn is_motion_call(call: &Canon) -> bool {
    matches!(
        call,
        Canon::StraightTraverse(_)
            | Canon::StraightFeed(_)
            | Canon::ArcFeed { .. }
            | Canon::NurbsFeed(_)
            | Canon::Dwell(_)
            | Canon::ProgramStop
            | Canon::OptionalProgramStop
            | Canon::PalletShuttle
            | Canon::ProgramEnd
            | Canon::Finish
    )
}

/// The moves those calls become.
fn is_motion_move(kind: &MoveKind) -> bool {
    matches!(
        kind,
        MoveKind::Rapid { .. }
            | MoveKind::Feed { .. }
            | MoveKind::Arc(_)
            | MoveKind::Nurbs(_)
            | MoveKind::Dwell { .. }
            | MoveKind::Stop(_)
    )
}

impl CanonSink for PassThrough {
    fn call(&mut self, origin: Origin, call: Canon) {
        let text = match &call {
            Canon::SetSpindleSpeed(rpm) => Some(format!("S{}", crate::write::number(*rpm, 4))),
            Canon::StartSpindle(SpindleDir::Clockwise) => Some("M3".to_owned()),
            Canon::StartSpindle(SpindleDir::CounterClockwise) => Some("M4".to_owned()),
            Canon::StopSpindle => Some("M5".to_owned()),
            Canon::MistOn => Some("M7".to_owned()),
            Canon::FloodOn => Some("M8".to_owned()),
            Canon::MistOff | Canon::FloodOff => Some("M9".to_owned()),
            Canon::SelectTool(t) => Some(format!("T{t}")),
            Canon::ChangeTool(_) => Some("M6".to_owned()),
            Canon::Message(m) => Some(format!("(MSG,{})", crate::write::comment_text(m))),
            _ => None,
        };
        // Line 0: the interpreter's own set-up and reset calls, not the program's.
        if let (Some(text), true) = (text, origin.line > 0) {
            self.push(origin, text);
        }
        // The words of the end's own line: M2 and M30 stop the spindle and coolant themselves.
        if matches!(call, Canon::ProgramEnd) {
            while self
                .words
                .last()
                .is_some_and(|w| (w.line, w.file) == (origin.line, origin.file))
            {
                self.words.pop();
            }
        }
        if is_motion_call(&call) {
            self.motions += 1;
        }
    }
}
