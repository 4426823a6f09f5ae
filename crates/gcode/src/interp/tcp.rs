//! G43.4 H<n>: Fanuc's tool-centre-point control, one of the tool-length codes (modal group 8
//! with G43, G43.1 and G49). Called from `execute`'s tool-length step; the motion stage reads
//! the switch from `SET_TOOL_CENTRE_POINT` (a call of tezgah's own: LinuxCNC 2.9 lacks G43.4).
//!
//! The interpreter treats the tool length of G43.4 as G43 H does (the program point is the
//! tool tip, so program coordinates shift by the offset); what changes is downstream: under
//! TCP the length acts along the tool axis, not as a Z offset.

use tezgah_geom::Pose;

use crate::block::Block;
use crate::canon::{Canon, CanonSink};
use crate::error::ErrorKind;

use super::execute::ExecError;
use super::Interpreter;

impl Interpreter {
    /// The tool offset that G43.4 puts in force: the H word's tool from the tool table. H is
    /// required (the length is what TCP needs) and must name a tool of the table.
    pub(super) fn centre_point_offset(&self, block: &Block, at: u32) -> Result<Pose, ExecError> {
        let Some(h) = block.word(b'h') else {
            return Err((ErrorKind::CentrePointMissingH, at));
        };
        let tool = h.value as i64;
        if tool < 1 {
            return Err((ErrorKind::ToolNotFound(tool), h.at));
        }
        self.table_offset(tool)
            .ok_or((ErrorKind::ToolNotFound(tool), h.at))
    }

    /// After a tool-length code: announce TCP on (with the length now in force) for G43.4, and
    /// off when another code of the group replaces a G43.4.
    pub(super) fn switch_centre_point(&mut self, on: bool, sink: &mut impl CanonSink) {
        if on {
            self.state.tool_centre_point = true;
            let length = self.state.tool_offset.z();
            self.emit(sink, Canon::SetToolCentrePoint(Some(length)));
        } else if self.state.tool_centre_point {
            self.state.tool_centre_point = false;
            self.emit(sink, Canon::SetToolCentrePoint(None));
        }
    }
}
