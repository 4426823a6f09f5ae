//! A cursor on one planned piece: the tool pose and joints at any path coordinate s, moving
//! forward only. The interpolator samples a piece on its own time grid; the executor samples
//! it at a re-timed path time (feed override, feed hold), so it needs the pose at an arbitrary
//! s — the same arithmetic as [`crate::interpolate`], one arc-length map per segment entered.

use std::sync::Arc;

use tezgah_geom::Vec3;
use tezgah_kinematics::Joints;

use crate::interpolate::{segment_pose, InterpolateError, Param};
use crate::path::Segment;
use crate::plan::{Piece, PlanMachine};

/// Where the tool is at one path coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CursorPose {
    /// 1-based source line of the segment the point lies on.
    pub line: u32,
    /// Tool tip, workpiece frame, mm.
    pub tip: Vec3,
    /// A B C, degrees.
    pub rotary: [f64; 3],
    /// Joints in internal units, machine-file order.
    pub joints: Joints,
}

/// Forward-only pose lookup on one piece.
pub struct PieceCursor {
    piece: Arc<Piece>,
    idx: usize,
    param: Param,
    /// Segments entered since [`PieceCursor::take_passed`] was last called, ending with the
    /// current one: a chord between two samples can run past short segments.
    passed: Vec<Arc<Segment>>,
}

impl PieceCursor {
    pub fn new(piece: Arc<Piece>) -> Self {
        let param = Param::new(&piece.segments[0]);
        let passed = vec![piece.segments[0].clone()];
        PieceCursor {
            piece,
            idx: 0,
            param,
            passed,
        }
    }

    pub fn piece(&self) -> &Arc<Piece> {
        &self.piece
    }

    /// The segments passed since the last call, the current one last (it stays for the next
    /// call: the next chord starts on it).
    pub fn passed(&self) -> &[Arc<Segment>] {
        &self.passed
    }

    /// Forgets the segments before the current one.
    pub fn clear_passed(&mut self) {
        if self.passed.len() > 1 {
            self.passed.drain(..self.passed.len() - 1);
        }
    }

    /// The pose at path coordinate `s` (clamped to the piece; a smaller `s` than a previous
    /// call stays on the current segment), joints nearest `previous`.
    pub fn pose(
        &mut self,
        machine: &PlanMachine,
        s: f64,
        previous: &Joints,
    ) -> Result<CursorPose, InterpolateError> {
        let piece = &self.piece;
        let s = s.clamp(0.0, piece.length());
        let before = self.idx;
        while self.idx + 1 < piece.segments.len() && s > piece.offsets[self.idx + 1] {
            self.idx += 1;
            self.passed.push(piece.segments[self.idx].clone());
        }
        if self.idx != before {
            self.param = Param::new(&piece.segments[self.idx]);
        }
        let seg = &piece.segments[self.idx];
        let (tip, rotary, joints) = segment_pose(
            machine,
            seg,
            &mut self.param,
            s - piece.offsets[self.idx],
            previous,
        )?;
        Ok(CursorPose {
            line: seg.line,
            tip,
            rotary,
            joints,
        })
    }
}
