//! Tool-table writes by the program (G10 L1, L10, L11) and the parameters that describe the
//! tool in the spindle (`#5400` number, `#5401…#5409` offsets, `#5410` diameter, `#5411…#5413`
//! lathe fields), as LinuxCNC's `convert_setup_tool` and `set_tool_parameters` keep them.
//!
//! LinuxCNC keeps the tool in the spindle as entry 0 of its table, a copy made at M6; a write to
//! the entry of that tool's pocket is copied there too. Table values are in the machine's units.

use tezgah_geom::Pose;

use crate::block::Block;
use crate::canon::{Canon, CanonSink};
use crate::error::ErrorKind;
use crate::params;
use crate::tooltable::Tool;

use super::execute::Exec;
use super::state::rotate_xy;
use super::Interpreter;

/// `#5400`: number of the tool in the spindle; `#5401…` follow.
const TOOL_PARAMETERS: usize = 5400;

/// Words of a G10 L1/L10/L11 that change the table.
const TOOL_WORDS: [u8; 13] = [
    b'x', b'y', b'z', b'a', b'b', b'c', b'u', b'v', b'w', b'r', b'q', b'i', b'j',
];

impl Interpreter {
    /// G10 L1 (offsets as given), L10 (offsets such that the current point reads as given in
    /// the active system, with this tool) and L11 (the same in G59.3, ignoring G92).
    pub(super) fn write_tool_table(
        &mut self,
        block: &Block,
        l: i64,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        let p = block.get(b'p').unwrap_or(-1.0);
        let number = (p + 0.5) as i64;
        let Some(mut tool) = self.cfg.tool_table.get(number).cloned() else {
            return Err((ErrorKind::ToolNotFound(number), at));
        };
        if !TOOL_WORDS.iter().any(|&w| block.has(w)) {
            return Err((ErrorKind::G10L1NoOffsets, at));
        }
        if l == 1 {
            let words = block.axis_words();
            let given = Pose(words.map(|w| w.unwrap_or(0.0)));
            let named = words.map(|w| w.is_some());
            set_named(&mut tool.offset, self.to_machine_units(given), named);
        } else {
            self.touch_off(block, l == 11, &mut tool);
        }
        if let Some(r) = block.get(b'r') {
            tool.diameter = r * 2.0 * self.machine_per_program_unit();
        }
        if let Some(i) = block.get(b'i') {
            tool.front_angle = i;
        }
        if let Some(j) = block.get(b'j') {
            tool.back_angle = j;
        }
        if let Some(q) = block.get(b'q') {
            let rounded = (q + 0.5) as i32;
            if (f64::from(rounded) - q).abs() >= 0.0001 {
                return Err((ErrorKind::G10QNotInteger, at));
            }
            if rounded > 9 {
                return Err((ErrorKind::InvalidToolOrientation, at));
            }
            tool.orientation = rounded;
        }
        let index = tool.row;
        self.emit(sink, table_entry(index, &tool));
        if index == self.state.current_pocket {
            self.state.spindle_slot = tool.clone();
            self.emit(sink, table_entry(0, &tool));
        }
        if let Some(row) = self.cfg.tool_table.get_mut(number) {
            *row = tool;
        }
        self.publish_tool_parameters();
        Ok(())
    }

    /// L10/L11: the offsets that make the current point (spindle, without tool length) read as
    /// the block's coordinates in the destination system (LinuxCNC's
    /// `find_current_in_system_without_tlo`); X and Y are turned by that system's rotation.
    fn touch_off(&self, block: &Block, to_fixture: bool, tool: &mut Tool) {
        let s = &self.state;
        let system = if to_fixture { 9 } else { s.origin_index };
        let base = params::coord_system_base(system);
        let rotation = self.params.get(base + 9);
        let spindle = s.to_machine(s.pos) + s.tool_offset;
        let mut t = rotate_xy(spindle - self.offset_params(base), -rotation);
        if !to_fixture && self.params.get(params::G92_ENABLED) != 0.0 {
            t = t - self.offset_params(params::G92_OFFSET);
        }
        let words = block.axis_words();
        let old = rotate_xy(self.to_program_units(tool.offset), -rotation);
        // In the system's frame: the named axis from the touch-off, the other kept.
        let (x, y) = match (words[0], words[1]) {
            (Some(x), Some(y)) => (t.0[0] - x, t.0[1] - y),
            (Some(x), None) => (t.0[0] - x, old.0[1]),
            (None, Some(y)) => (old.0[0], t.0[1] - y),
            (None, None) => (old.0[0], old.0[1]),
        };
        let xy = rotate_xy(Pose([x, y, 0.0, 0.0, 0.0, 0.0]), rotation);
        let mut fresh = Pose([xy.0[0], xy.0[1], 0.0, 0.0, 0.0, 0.0]);
        for (i, word) in words.iter().enumerate().skip(2) {
            if let Some(v) = *word {
                fresh.0[i] = t.0[i] - v;
            }
        }
        // X and Y change together (the rotation mixes them) when either is touched off.
        let mut named = words.map(|w| w.is_some());
        let xy_named = named[0] || named[1];
        named[0] = xy_named;
        named[1] = xy_named;
        set_named(&mut tool.offset, self.to_machine_units(fresh), named);
    }

    /// `#5400…#5413` from the spindle's entry, zero when no tool is in it.
    pub(super) fn publish_tool_parameters(&mut self) {
        let slot = &self.state.spindle_slot;
        let values: [f64; 14] = if slot.number <= 0 {
            [0.0; 14]
        } else {
            let o = slot.offset.0;
            [
                slot.number as f64,
                o[0],
                o[1],
                o[2],
                o[3],
                o[4],
                o[5],
                0.0,
                0.0,
                0.0,
                slot.diameter,
                slot.front_angle,
                slot.back_angle,
                f64::from(slot.orientation),
            ]
        };
        for (k, v) in values.into_iter().enumerate() {
            self.params.set(TOOL_PARAMETERS + k, v);
        }
    }
}

/// The `named` axes of `offset` take their value from `value`; the others are kept.
fn set_named(offset: &mut Pose, value: Pose, named: [bool; 6]) {
    for (i, &n) in named.iter().enumerate() {
        if n {
            offset.0[i] = value.0[i];
        }
    }
}

fn table_entry(index: usize, tool: &Tool) -> Canon {
    Canon::SetToolTableEntry {
        index,
        tool: tool.number,
        offset: tool.offset,
        diameter: tool.diameter,
        front_angle: tool.front_angle,
        back_angle: tool.back_angle,
        orientation: tool.orientation,
    }
}
