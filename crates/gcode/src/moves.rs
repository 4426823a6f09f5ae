//! From canonical calls to the typed moves the planner consumes (LinuxCNC's `emccanon` layer).
//!
//! Canonical calls speak program coordinates in program units and announce offsets apart;
//! moves are absolute, in mm and degrees, with work offsets, G92/G52, XY rotation and tool
//! length applied (`machine = g5x + R(p + g92) + tool`). Inverse-time feeds already arrive as
//! a rate per move, so the planner sees one feed unit: mm/min (or mm/rev under G95).
//!
//! Under tool-centre-point control (G43.4, or always on a machine that says so) the tool
//! length is not added along Z: moves carry the tool tip, and the length travels in a
//! [`MoveKind::ToolControl`] move, for the kinematics to apply along the tool axis.

use std::sync::Arc;

use tezgah_geom::{
    ArcMove, FeedMode, Move, MoveKind, NurbsMove, PathMode, Plane, Pose, StopKind, SyncedMove,
    ToolControl, Vec3,
};

use crate::canon::{Canon, CanonSink, ControlMode, NurbsFeed, Origin, Units};
use crate::interp::state_rotate_xy as rotate_xy;

/// A [`CanonSink`] that turns calls into [`Move`]s and hands them to `out`.
#[derive(Debug)]
pub struct MoveBuilder<F: FnMut(Move)> {
    out: F,
    units: Units,
    plane: Plane,
    g5x: Pose,
    g92: Pose,
    rotation: f64,
    tool: Pose,
    /// Tool length under TCP (mm), `None` with TCP off.
    centre_point: Option<f64>,
    /// TCP whatever the program says (machine file `tcp = "always"`); G43/G49 then only set
    /// the length. Announced before the first move.
    centre_point_always: bool,
    announced: bool,
    /// The line of a G43/G49 with TCP off whose length is still to be announced.
    length_pending: Option<u32>,
    /// The current point without the tool offset (`g5x + R(p + g92)`, mm): where the next
    /// move starts, in the coordinates of TCP; the tool is added to it with TCP off.
    tipless: Pose,
    /// G33/G33.1 in force: mm per spindle revolution.
    synced: Option<f64>,
}

impl<F: FnMut(Move)> MoveBuilder<F> {
    pub fn new(out: F) -> Self {
        MoveBuilder {
            out,
            units: Units::Millimeters,
            plane: Plane::XY,
            g5x: Pose::ZERO,
            g92: Pose::ZERO,
            rotation: 0.0,
            tool: Pose::ZERO,
            centre_point: None,
            centre_point_always: false,
            announced: false,
            length_pending: None,
            tipless: Pose::ZERO,
            synced: None,
        }
    }

    /// Tool-centre-point control from the start and whatever the program says (the machine
    /// file's `tcp = "always"`): G43 H then sets the TCP tool length, G49 zeroes it.
    pub fn centre_point_always(mut self) -> Self {
        self.centre_point_always = true;
        self.centre_point = Some(0.0);
        self
    }

    /// Machine position in mm of program point `p` (program units); remembers it as the
    /// current point.
    fn machine(&mut self, p: Pose) -> Pose {
        let tipless = self.tipless_of(p);
        self.tipless = tipless;
        self.with_tool(tipless)
    }

    /// Machine position in mm of program point `p` without any tool offset.
    fn tipless_of(&self, p: Pose) -> Pose {
        (self.g5x + rotate_xy(p + self.g92, self.rotation)).scale_linear(self.units.mm())
    }

    /// A tip-less point as the moves carry it: with the tool offset added when TCP is off.
    fn with_tool(&self, tipless: Pose) -> Pose {
        match self.centre_point {
            Some(_) => tipless,
            None => tipless + self.tool.scale_linear(self.units.mm()),
        }
    }

    /// Tells the path stage how the coordinates read from here on.
    fn announce(&mut self, line: u32) {
        self.announced = true;
        let control = match self.centre_point {
            Some(tool_length) => ToolControl::CentrePoint { tool_length },
            None => ToolControl::Joints {
                tool_length: self.tool.z() * self.units.mm(),
            },
        };
        let at = self.with_tool(self.tipless);
        self.push(line, MoveKind::ToolControl { control, at });
    }

    /// A NURBS call as a move: the interpreter's curve through the same affine map as an end
    /// point, which maps the curve exactly (weights and knots are unchanged by it).
    fn nurbs(&mut self, n: &NurbsFeed) -> MoveKind {
        let end = self.machine(n.end);
        let curve = n.curve.mapped(|p| {
            let q = self.with_tool(self.tipless_of(Pose([p.x, p.y, p.z, 0.0, 0.0, 0.0])));
            Vec3::from(q.xyz())
        });
        MoveKind::Nurbs(NurbsMove {
            curve: Arc::new(curve),
            end,
        })
    }

    fn push(&mut self, line: u32, kind: MoveKind) {
        (self.out)(Move { line, kind });
    }
}

impl<F: FnMut(Move)> CanonSink for MoveBuilder<F> {
    fn call(&mut self, origin: Origin, call: Canon) {
        let line = origin.line;
        if self.centre_point_always && !self.announced {
            // Set-up calls come before line 1; the switch is the program's from its start.
            self.announce(line.max(1));
        }
        if !matches!(
            call,
            Canon::UseToolLengthOffset(_) | Canon::SetToolCentrePoint(_)
        ) {
            if let Some(at) = self.length_pending.take() {
                self.announce(at);
            }
        }
        match call {
            Canon::UseLengthUnits(u) => self.units = u,
            Canon::SetG5xOffset { offset, .. } => self.g5x = offset,
            Canon::SetG92Offset(p) => self.g92 = p,
            Canon::SetXyRotation(r) => self.rotation = r,
            Canon::UseToolLengthOffset(p) => {
                // The tip stays put: the interpreter shifts the program point by the change
                // of offset, so the tip-less point shifts by it too.
                self.tipless = self.tipless - (p - self.tool).scale_linear(self.units.mm());
                self.tool = p;
                if self.centre_point_always {
                    self.centre_point = Some(p.z() * self.units.mm());
                    self.announce(line);
                } else if self.centre_point.is_none() {
                    // TCP off: the length is in the moves' Z already; announced (at the next
                    // call, unless G43.4 switches TCP on meanwhile) so that the tool tip can
                    // be read back from the joints (forward kinematics).
                    self.length_pending = Some(line);
                }
            }
            Canon::SetToolCentrePoint(length) if !self.centre_point_always => {
                self.length_pending = None;
                self.centre_point = length.map(|l| l * self.units.mm());
                self.announce(line);
            }
            Canon::SelectPlane(p) => self.plane = p.unwrap_or(self.plane),
            Canon::StraightTraverse(p) => {
                let end = self.machine(p);
                self.push(line, MoveKind::Rapid { end });
            }
            // A probe move is a feed toward its target; the machine stops short of it where
            // the probe trips, and whoever drives the run knows where (the program's next move
            // starts from there).
            Canon::StartSpeedFeedSync { feed_per_rev } => {
                self.synced = Some(feed_per_rev * self.units.mm());
            }
            Canon::StopSpeedFeedSync => self.synced = None,
            Canon::StraightFeed(p) if self.synced.is_some() => {
                let end = self.machine(p);
                let pitch = self.synced.unwrap_or(0.0);
                self.push(
                    line,
                    MoveKind::Synced(SyncedMove {
                        end,
                        pitch,
                        tap: None,
                    }),
                );
            }
            Canon::RigidTap { end, retract_scale } => {
                // The tap comes back to where it started: the current point stays.
                let here = self.tipless;
                let end = self.machine(end);
                self.tipless = here;
                let pitch = self.synced.unwrap_or(0.0);
                // LinuxCNC's motion takes a factor that is not positive as no factor.
                let scale = if retract_scale > 0.0 {
                    retract_scale
                } else {
                    1.0
                };
                let tap = Some(scale);
                self.push(line, MoveKind::Synced(SyncedMove { end, pitch, tap }));
            }
            Canon::StraightFeed(p) | Canon::StraightProbe(p) => {
                let end = self.machine(p);
                self.push(line, MoveKind::Feed { end });
            }
            Canon::ArcFeed {
                first_end,
                second_end,
                first_axis,
                second_axis,
                rotation,
                axis_end,
                abc,
            } => {
                let (i, j, k) = self.plane.axes();
                let mut end = Pose([0.0, 0.0, 0.0, abc[0], abc[1], abc[2]]);
                end.0[i] = first_end;
                end.0[j] = second_end;
                end.0[k] = axis_end;
                let mut center = end;
                center.0[i] = first_axis;
                center.0[j] = second_axis;
                // The end last: it is the current point afterwards.
                let center = self.machine(center);
                let end = self.machine(end);
                self.push(
                    line,
                    MoveKind::Arc(ArcMove {
                        plane: self.plane,
                        end,
                        center: [center.0[i], center.0[j]],
                        turn: rotation,
                    }),
                );
            }
            Canon::NurbsFeed(n) => {
                let kind = self.nurbs(&n);
                self.push(line, kind);
            }
            Canon::Dwell(seconds) => self.push(line, MoveKind::Dwell { seconds }),
            Canon::SetFeedRate(f) => {
                let value = f * self.units.mm();
                self.push(line, MoveKind::FeedRate { value });
            }
            Canon::SetSpindleSpeed(rpm) => self.push(line, MoveKind::SpindleSpeed { rpm }),
            Canon::SetFeedMode(m) => {
                let mode = if m == 1 {
                    FeedMode::UnitsPerRevolution
                } else {
                    FeedMode::UnitsPerMinute
                };
                self.push(line, MoveKind::FeedMode(mode));
            }
            Canon::SetSmoothing(on) => self.push(line, MoveKind::Smoothing(on)),
            Canon::EnableFeedOverride => self.push(line, MoveKind::FeedOverride(true)),
            Canon::DisableFeedOverride => self.push(line, MoveKind::FeedOverride(false)),
            Canon::SetMotionControlMode(m) => {
                let mode = match m {
                    ControlMode::ExactStop => PathMode::ExactStop,
                    ControlMode::ExactPath => PathMode::ExactPath,
                    ControlMode::Continuous(p) => PathMode::Continuous {
                        tolerance: (p > 0.0).then(|| p * self.units.mm()),
                    },
                };
                self.push(line, MoveKind::PathMode(mode));
            }
            Canon::ProgramStop => self.push(line, MoveKind::Stop(StopKind::Pause)),
            Canon::OptionalProgramStop => self.push(line, MoveKind::Stop(StopKind::OptionalPause)),
            Canon::PalletShuttle => self.push(line, MoveKind::Stop(StopKind::PalletPause)),
            Canon::ProgramEnd | Canon::Finish => self.push(line, MoveKind::Stop(StopKind::End)),
            _ => {}
        }
    }
}

/// Interpret a whole program into moves (stops at the first error).
pub fn program_moves(program: &str, cfg: crate::Config) -> Result<Vec<Move>, crate::GcodeError> {
    // About one move a line: reserving for them saves the vector's copies as it grows (a
    // tenth of a millisecond on a dense program of 7 000 lines).
    let lines = memchr::memchr_iter(b'\n', program.as_bytes()).count() + 1;
    let mut moves = Vec::with_capacity(lines);
    let always = cfg.tool_centre_point_always;
    let mut builder = MoveBuilder::new(|m| moves.push(m));
    if always {
        builder = builder.centre_point_always();
    }
    crate::Interpreter::new(cfg).run(program, &mut builder)?;
    Ok(moves)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Config;

    fn moves(program: &str) -> Vec<Move> {
        program_moves(program, Config::default()).unwrap()
    }

    #[test]
    fn offsets_units_and_lines_reach_the_moves() {
        let m = moves("G20\nG10 L2 P1 X1\nG92 X0\nG0 X1 Y2\nG1 X2 F10\nM2\n");
        let rapid = m
            .iter()
            .find(|m| matches!(m.kind, MoveKind::Rapid { .. }))
            .unwrap();
        assert_eq!(rapid.line, 4);
        let MoveKind::Rapid { end } = rapid.kind else {
            unreachable!()
        };
        // G54 X1 puts the start at X-1; G92 X0 there makes g92 = -1; program X1 is then
        // machine 1 + (1 - 1) = 1 in = 25.4 mm.
        assert!((end.x() - 25.4).abs() < 1e-9, "{end:?}");
        assert!((end.y() - 50.8).abs() < 1e-9);
        let feed = m.iter().find_map(|m| match m.kind {
            MoveKind::FeedRate { value } if value > 0.0 => Some(value),
            _ => None,
        });
        assert_eq!(feed, Some(254.0));
    }

    #[test]
    fn arcs_keep_plane_and_centre() {
        let m = moves("G18 G2 X10 Z0 I5 K0 F100\nM2\n");
        let arc = m.iter().find_map(|m| match m.kind {
            MoveKind::Arc(a) => Some(a),
            _ => None,
        });
        let arc = arc.unwrap();
        assert_eq!(arc.plane, Plane::ZX);
        assert_eq!(arc.center, [0.0, 5.0]); // (Z, X)
        assert_eq!(arc.end.x(), 10.0);
        assert_eq!(arc.turn, -1);
    }

    #[test]
    fn tool_length_is_added() {
        let m = moves("G43.1 Z5\nG0 Z0\nM2\n");
        let MoveKind::Rapid { end } = m
            .iter()
            .find(|m| matches!(m.kind, MoveKind::Rapid { .. }))
            .unwrap()
            .kind
        else {
            unreachable!()
        };
        assert_eq!(end.z(), 5.0);
    }
}
