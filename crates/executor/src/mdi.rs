//! MDI: one block at a time through an interpreter that lives as long as the executor, so
//! modal state (units, G90/G91, feed, offsets) carries from block to block as on a control.

use std::sync::mpsc;

use tezgah_gcode::interp::{line_at, LinePos};
use tezgah_gcode::{Config, Interpreter, MoveBuilder};
use tezgah_geom::Move;

use crate::error::ExecError;

type Sink = MoveBuilder<Box<dyn FnMut(Move) + Send>>;

/// The MDI interpreter and the moves its last block made.
pub struct Mdi {
    interp: Interpreter,
    builder: Sink,
    moves: mpsc::Receiver<Move>,
}

impl Mdi {
    pub fn new(config: Config) -> Mdi {
        let (tx, rx) = mpsc::channel();
        let always = config.tool_centre_point_always;
        let mut builder: Sink = MoveBuilder::new(Box::new(move |m| {
            // The receiver lives as long as the sender: sending cannot fail.
            let _ = tx.send(m);
        }));
        if always {
            builder = builder.centre_point_always();
        }
        let mut interp = Interpreter::new(config);
        interp.start(&mut builder);
        let mdi = Mdi {
            interp,
            builder,
            moves: rx,
        };
        while mdi.moves.try_recv().is_ok() {}
        mdi
    }

    /// The moves of one block (line number 1). An error leaves the modal state as the
    /// interpreter leaves it after a failed block.
    pub fn block(&mut self, text: &str) -> Result<Vec<Move>, ExecError> {
        if text.contains('\n') {
            return Err(ExecError::Gcode("an MDI block is one line".into()));
        }
        let line = line_at(text, LinePos::FIRST)
            .ok_or_else(|| ExecError::Gcode("empty MDI block".into()))?;
        self.interp
            .execute_line(line, &mut self.builder)
            .map_err(|e| ExecError::Gcode(e.to_string()))?;
        Ok(self.moves.try_iter().collect())
    }
}
