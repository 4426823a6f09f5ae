//! The predefined named parameters (`#<_x>`, `#<_metric>`, `#<_line>`, …) and the position
//! parameters (`#5021…`, `#5420…`): the interpreter's state as a program reads it, refreshed
//! before each line is read (LinuxCNC's "predefined named parameters", all read-only).

use tezgah_geom::{FeedMode, Plane};

use crate::canon::{SpindleDir, Units};
use crate::params;

use super::Interpreter;

fn flag(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

impl Interpreter {
    pub(super) fn publish_system_values(&mut self, line: u32) {
        let s = &self.state;
        let v = &mut self.params.system;
        v.line = f64::from(line);
        v.position = s.pos.0;
        v.machine_position = (s.to_machine(s.pos) + s.tool_offset).0;
        v.motion_mode = s.motion.map_or(800.0, f64::from);
        v.plane = match s.plane {
            Some(Plane::XY) => 170.0,
            Some(Plane::ZX) => 180.0,
            Some(Plane::YZ) => 190.0,
            None => 171.0,
        };
        v.metric = flag(s.units == Units::Millimeters);
        v.absolute = flag(!s.incremental);
        v.ijk_absolute = flag(!s.ijk_incremental);
        v.inverse_time = flag(s.feed_mode == FeedMode::InverseTime);
        v.units_per_minute = flag(s.feed_mode == FeedMode::UnitsPerMinute);
        v.units_per_rev = flag(s.feed_mode == FeedMode::UnitsPerRevolution);
        // G54 → 540 … G59 → 590, G59.1 → 591 … G59.3 → 593.
        v.coord_system = match s.origin_index {
            i @ 1..=6 => 530.0 + 10.0 * i as f64,
            i => 584.0 + i as f64,
        };
        v.tool_offset = flag(s.tool_offset != tezgah_geom::Pose::ZERO);
        v.feed = s.feed_rate;
        v.rpm = s.speed;
        v.spindle_on = flag(s.spindle.is_some());
        v.spindle_cw = flag(s.spindle == Some(SpindleDir::Clockwise));
        v.mist = flag(s.mist);
        v.flood = flag(s.flood);
        // rs274 2.9 reads 0 before any T (its documentation says −1).
        v.selected_tool = s.selected_tool.map_or(0.0, |t| t as f64);
        let pocket_of_row = |row: usize| {
            if row == 0 {
                s.spindle_slot.pocket
            } else {
                self.cfg
                    .tool_table
                    .iter()
                    .find(|t| t.row == row)
                    .map_or(0, |t| t.pocket)
            }
        };
        v.selected_pocket = s.selected_tool.map_or(-1.0, |t| {
            let row = self
                .cfg
                .tool_table
                .get(t)
                .filter(|_| t != 0)
                .map_or(0, |t| t.row);
            pocket_of_row(row) as f64
        });
        v.current_tool = s.spindle_slot.number.max(0) as f64;
        v.current_pocket = pocket_of_row(s.current_pocket) as f64;
        v.ccomp = match self.comp.side {
            None => 400.0,
            Some(super::comp::Side::Left) => 410.0,
            Some(super::comp::Side::Right) => 420.0,
        };
        v.retract_r_plane = flag(s.retract_r_plane);
        v.lathe_diameter = flag(s.lathe_diameter);
        v.feed_override = flag(s.switches.feed_override);
        v.speed_override = flag(s.switches.speed_override);
        v.adaptive_feed = flag(s.switches.adaptive_feed);
        v.feed_hold = flag(s.switches.feed_hold);
        let (pos, machine) = (v.position, v.machine_position);
        self.params.set6(params::CURRENT_POSITION, pos);
        self.params.set6(params::MACHINE_POSITION, machine);
    }
}
