//! MDI: one block at a time through an interpreter that lives as long as the executor, so
//! modal state (units, G90/G91, feed, offsets) carries from block to block as on a control.

use std::sync::mpsc;

use tezgah_gcode::interp::{line_at, LinePos};
use tezgah_gcode::{Config, Interpreter, MoveBuilder, Units};
use tezgah_geom::{Move, Pose};

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

    /// Tells the interpreter the machine is at `pose` (machine coordinates, mm and degrees)
    /// after motion it did not make (AUTO, an abort): a `G53 G0` there, whose move (of zero
    /// length) is dropped; G90/G91 is restored, the motion mode is G0 afterwards.
    pub fn sync(&mut self, pose: &Pose) -> Result<(), ExecError> {
        let st = self.interp.state();
        let incremental = st.incremental;
        let scale = match st.units {
            Units::Inches => 1.0 / 25.4,
            _ => 1.0,
        };
        let p = &pose.0;
        let line = format!(
            "G90 G53 G0 X{:.9} Y{:.9} Z{:.9} A{:.9} B{:.9} C{:.9}",
            p[0] * scale,
            p[1] * scale,
            p[2] * scale,
            p[3],
            p[4],
            p[5]
        );
        self.block(&line)?;
        if incremental {
            self.block("G91")?;
        }
        Ok(())
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
