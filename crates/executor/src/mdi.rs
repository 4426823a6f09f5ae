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
    /// The machine's program axes: the words `sync` may write.
    axes: tezgah_gcode::AxisMask,
}

impl Mdi {
    pub fn new(config: Config) -> Mdi {
        let (tx, rx) = mpsc::channel();
        let always = config.tool_centre_point_always;
        let axes = config.axes;
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
            axes,
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
        // Only the machine's axes: another letter is a bad character (LinuxCNC's axis mask).
        let mut line = "G90 G53 G0".to_owned();
        for axis in tezgah_geom::Axis::ALL {
            if self.axes.has(axis) {
                let k = if axis.is_linear() { scale } else { 1.0 };
                let letter = b"XYZABC"[axis.index()] as char;
                line.push_str(&format!(" {letter}{:.9}", pose.0[axis.index()] * k));
            }
        }
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
        // Placed as every interpreter error is: `MDI:1:col`.
        self.interp
            .execute_line(line, &mut self.builder)
            .map_err(|e| ExecError::At {
                at: tezgah_gcode::sources::Located {
                    file: "MDI".into(),
                    span: e.span,
                },
                message: e.kind.to_string(),
            })?;
        Ok(self.moves.try_iter().collect())
    }
}
