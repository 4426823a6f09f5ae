//! MDI: one block at a time through an interpreter that lives as long as the executor, so
//! modal state (units, G90/G91, feed, offsets) carries from block to block as on a control.

use std::sync::mpsc;

use tezgah_gcode::interp::{line_at, LinePos};
use tezgah_gcode::params::ParameterFile;
use tezgah_gcode::{Config, ErrorKind, Interpreter, MoveBuilder, ProbeOutcome, Units};
use tezgah_geom::{Move, Plane, Pose};

use crate::command::WorkState;

use crate::error::ExecError;

type Sink = MoveBuilder<Box<dyn FnMut(Move) + Send>>;

/// The MDI interpreter and the moves its last block made.
pub struct Mdi {
    interp: Interpreter,
    builder: Sink,
    moves: mpsc::Receiver<Move>,
    /// The machine's program axes: the words `sync` may write.
    axes: tezgah_gcode::AxisMask,
    /// Where the last block's probe move waits for its answer (for the answer's errors).
    probe_at: Option<tezgah_gcode::Span>,
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
            probe_at: None,
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

    /// `config` with the offsets MDI has set (G10, G92, G28.1/G30.1: the parameters LinuxCNC
    /// keeps between runs, #5161–#5390) in place of the ones it started with, so a program
    /// loaded after a zero-set runs in the zeroed frame.
    pub fn program_config(&self, config: &Config) -> Config {
        let kept = 5161..=5390;
        let params = self.interp.params();
        let mut text = String::new();
        let file = config.parameters.as_deref();
        let mut values: Vec<(usize, f64)> = file
            .map(|f| f.values())
            .unwrap_or_default()
            .iter()
            .copied()
            .filter(|(n, _)| !kept.contains(n))
            .collect();
        values.extend(kept.map(|n| (n, params.get(n))).filter(|&(_, v)| v != 0.0));
        values.sort_by_key(|&(n, _)| n);
        for (n, v) in values {
            text += &format!("{n} {v:?}\n");
        }
        let mut config = config.clone();
        // The text is made of valid numbers in increasing order: parsing cannot fail.
        if let Ok(file) = ParameterFile::parse(&text) {
            config.parameters = Some(std::sync::Arc::new(file));
        }
        config
    }

    /// The modal state and offsets, and `tip` (mm, machine frame) in the active work frame.
    pub fn work(&self, tip: [f64; 3]) -> WorkState {
        let st = self.interp.state();
        let mm = match st.units {
            Units::Inches => 25.4,
            _ => 1.0,
        };
        let xyz = |p: &Pose| [p.0[0] * mm, p.0[1] * mm, p.0[2] * mm];
        let (g5x, g92) = (xyz(&st.origin), xyz(&st.axis_offset));
        let (sin, cos) = (-st.rotation.to_radians()).sin_cos();
        let (dx, dy) = (tip[0] - g5x[0], tip[1] - g5x[1]);
        let position = [
            cos * dx - sin * dy - g92[0],
            sin * dx + cos * dy - g92[1],
            tip[2] - g5x[2] - g92[2],
        ];
        WorkState {
            coordinate_system: st.origin_index,
            g5x,
            rotation_deg: st.rotation,
            g92,
            tool: xyz(&st.tool_offset),
            inches: matches!(st.units, Units::Inches),
            incremental: st.incremental,
            plane: match st.plane {
                Some(Plane::XY) => 17,
                Some(Plane::ZX) => 18,
                Some(Plane::YZ) => 19,
                None => 0,
            },
            motion: st.motion,
            feed_rate: st.feed_rate,
            position,
        }
    }

    /// The machine's answer to the probe move the last block ended with ([`Mdi::block`]'s
    /// code): `#5061`… and the position set, or LinuxCNC's error at the block's G38 word.
    pub fn answer(&mut self, outcome: ProbeOutcome) -> Result<(), ExecError> {
        let span = self.probe_at.take().unwrap_or_default();
        self.interp
            .answer_probe(outcome)
            .map(|_| ())
            .map_err(|kind| ExecError::At {
                at: tezgah_gcode::sources::Located {
                    file: "MDI".into(),
                    span,
                },
                message: kind.to_string(),
            })
    }

    /// The moves of one block (line number 1), and the G-code (`38.2` …) of a probe move they
    /// end with that waits for the machine's answer ([`Mdi::answer`]). An error leaves the
    /// modal state as the interpreter leaves it after a failed block.
    pub fn block(&mut self, text: &str) -> Result<(Vec<Move>, Option<String>), ExecError> {
        if text.contains('\n') {
            return Err(ExecError::Gcode("an MDI block is one line".into()));
        }
        let line = line_at(text, LinePos::FIRST)
            .ok_or_else(|| ExecError::Gcode("empty MDI block".into()))?;
        // Placed as every interpreter error is: `MDI:1:col`.
        let awaits = match self.interp.execute_line(line, &mut self.builder) {
            Ok(_) => None,
            Err(e) => match e.kind {
                ErrorKind::ProbeAwaitsAnswer(code) => {
                    self.probe_at = Some(e.span);
                    Some(code)
                }
                kind => {
                    return Err(ExecError::At {
                        at: tezgah_gcode::sources::Located {
                            file: "MDI".into(),
                            span: e.span,
                        },
                        message: kind.to_string(),
                    })
                }
            },
        };
        Ok((self.moves.try_iter().collect(), awaits))
    }
}
