//! The tool of each sample as the machine holds it: tool tip and unit tool axis in the
//! workpiece frame, by forward kinematics of the sample's joints with the tool length in force.
//! Sits after the interpolator beside [`crate::verify`]: `verify` compares the program-space
//! point (`Sample::tip`), this gives the physical tool, which the samples CSV prints.
//!
//! With TCP on the two agree (the joints are the inverse of the program tip). With TCP off on a
//! machine whose rotaries orient the tool, the program axes are joints and the tip is where the
//! table or head puts the tool, not the program's X Y Z; and with TCP off anywhere the moves
//! carry G43's length in Z (the gauge point), which the forward kinematics take off again.

use std::sync::Arc;

use tezgah_kinematics::{Kinematics, KinematicsError, Model, Tool, ToolPose};

use crate::interpolate::Sample;
use crate::path::Segment;
use crate::plan::PlanMachine;

/// Follows the tool length in force along the samples and gives each sample's tool pose.
#[derive(Debug, Clone)]
pub struct SampleTool {
    model: Model,
    /// The length of the last segment seen (dwells and the final row have none of their own).
    length: f64,
}

impl SampleTool {
    /// Before the first sample: the machine's initial tool control, no tool length.
    pub fn new(machine: &PlanMachine) -> Self {
        SampleTool {
            model: machine.model.clone(),
            length: machine.initial.tool_length(),
        }
    }

    /// The tool pose of `sample`, which lies on the last of `passed` (the interpolator's sink
    /// arguments; none while standing still, when the length of the last segment stays).
    /// The tool length is G43.4's under TCP and G43's with TCP off (0 after G49): the tip is
    /// that far from the gauge point along the tool axis.
    pub fn pose(
        &mut self,
        sample: &Sample,
        passed: &[Arc<Segment>],
    ) -> Result<ToolPose, KinematicsError> {
        if let Some(seg) = passed.last() {
            self.length = seg.control.tool_length();
        }
        self.model
            .forward(&sample.joints, &Tool::with_length(self.length))
    }
}
