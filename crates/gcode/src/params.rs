//! The parameter store: numbered parameters `#1`–`#5601` and named ones `#<name>`.
//!
//! Numbered parameters that were never set read as zero, as in LinuxCNC. The interpreter keeps
//! its offsets in the reserved numbers (`#5221…` for G54, `#5211…` for G92, `#5161…` for G28,
//! …) so that a program can read them. Named parameters are local to the subroutine call that
//! sets them unless their name starts with `_` (global); the interpreter's own read-only
//! values (`#<_x>`, `#<_metric>`, `#<_line>`, …) are `system` values it refreshes per line.

use std::collections::HashMap;

/// One past the highest parameter number (LinuxCNC's `RS274NGC_MAX_PARAMETERS`).
pub const MAX_PARAMETERS: usize = 5602;

/// First parameter of the G28 home position (X); G30 follows at `G30_HOME`.
pub const G28_HOME: usize = 5161;
pub const G30_HOME: usize = 5181;
/// G92 offsets X…C.
pub const G92_OFFSET: usize = 5211;
/// 1 when G92 offsets are applied, 0 after G92.2.
pub const G92_ENABLED: usize = 5210;
/// The active coordinate system (1 = G54 … 9 = G59.3).
pub const COORD_SYSTEM: usize = 5220;
/// G54 offsets X…C, rotation R at +9; each further system is 20 further on.
pub const G54_OFFSET: usize = 5221;
/// Current position X…C in program coordinates (read-only for programs).
pub const CURRENT_POSITION: usize = 5420;
/// Where the last probing move (G38.x) found the probe: `#5061`…`#5069`, program
/// coordinates; `#5070` is 1 when it tripped.
pub const PROBE_POSITION: usize = 5061;
pub const PROBE_TRIPPED: usize = 5070;
/// Current position X…C in machine coordinates, as G53 names it (read-only for programs).
pub const MACHINE_POSITION: usize = 5021;

/// The first parameter of work-coordinate system `n` (1 = G54 … 9 = G59.3).
pub fn coord_system_base(n: usize) -> usize {
    G54_OFFSET + 20 * (n - 1)
}

/// Parameters a subroutine call gets from its arguments (`#1`…`#30`), restored on return.
pub const CALL_PARAMETERS: usize = 30;

/// A LinuxCNC parameter file (`.var`): `number value` lines in increasing order, the values
/// the numbered parameters start with (work offsets, G92 offsets, home positions, …).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParameterFile {
    values: Vec<(usize, f64)>,
}

/// A parameter file LinuxCNC would refuse, with the 1-based line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParameterFileError {
    #[error("line {0}: Parameter number out of range")]
    OutOfRange(usize),
    #[error("line {0}: Parameter file out of order")]
    OutOfOrder(usize),
}

impl ParameterFile {
    /// Read a parameter file. Lines that do not start with a number and a value are
    /// ignored, as LinuxCNC's `restore_parameters` ignores them.
    pub fn parse(text: &str) -> Result<ParameterFile, ParameterFileError> {
        let mut values: Vec<(usize, f64)> = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let mut fields = line.split_whitespace();
            let (Some(n), Some(v)) = (fields.next(), fields.next()) else {
                continue;
            };
            let (Ok(n), Ok(v)) = (n.parse::<i64>(), v.parse::<f64>()) else {
                continue;
            };
            if n <= 0 || n as usize >= MAX_PARAMETERS {
                return Err(ParameterFileError::OutOfRange(k + 1));
            }
            if values.last().is_some_and(|&(last, _)| last >= n as usize) {
                return Err(ParameterFileError::OutOfOrder(k + 1));
            }
            values.push((n as usize, v));
        }
        Ok(ParameterFile { values })
    }

    /// The `(number, value)` pairs, in increasing order.
    pub fn values(&self) -> &[(usize, f64)] {
        &self.values
    }
}

/// Numbered and named parameters.
#[derive(Debug, Clone)]
pub struct Params {
    numbered: Vec<f64>,
    /// `#<_name>` parameters, shared by the whole program.
    globals: HashMap<String, f64>,
    /// `#<name>` parameters of each active call level; the main program is level 0.
    locals: Vec<HashMap<String, f64>>,
    /// Read-only values the interpreter publishes (`#<_x>`, `#<_feed>`, …).
    pub system: SystemValues,
    /// The INI file whose values are `#<_ini[section]name>` (read-only).
    ini: Option<std::sync::Arc<crate::ini::IniFile>>,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            numbered: vec![0.0; MAX_PARAMETERS],
            globals: HashMap::new(),
            locals: vec![HashMap::new()],
            system: SystemValues::default(),
            ini: None,
        }
    }
}

/// The interpreter's state as LinuxCNC's predefined named parameters show it. Lengths are in
/// program units, angles in degrees, flags 1 or 0.
#[derive(Debug, Clone, Default)]
pub struct SystemValues {
    /// `#<_line>`: the line being executed (1-based).
    pub line: f64,
    /// `#<_x>` … `#<_c>`: the current point in program coordinates.
    pub position: [f64; 6],
    /// `#<_abs_x>` … `#<_abs_c>`: the current point in machine coordinates.
    pub machine_position: [f64; 6],
    pub motion_mode: f64,
    pub plane: f64,
    pub metric: f64,
    pub absolute: f64,
    pub ijk_absolute: f64,
    pub inverse_time: f64,
    pub units_per_minute: f64,
    pub units_per_rev: f64,
    pub coord_system: f64,
    pub tool_offset: f64,
    pub feed: f64,
    pub rpm: f64,
    pub spindle_on: f64,
    pub spindle_cw: f64,
    pub mist: f64,
    pub flood: f64,
    pub selected_tool: f64,
    /// Pocket (tool-table P) of the selected tool, −1 before any T.
    pub selected_pocket: f64,
    /// Tool in the spindle (#5400) and its pocket.
    pub current_tool: f64,
    pub current_pocket: f64,
    /// 400 (G40), 410 (G41, G41.1) or 420 (G42, G42.1).
    pub ccomp: f64,
    /// G99 in force (else G98).
    pub retract_r_plane: f64,
    /// G7 in force (else G8).
    pub lathe_diameter: f64,
    pub feed_override: f64,
    pub speed_override: f64,
    pub adaptive_feed: f64,
    pub feed_hold: f64,
    pub call_level: f64,
    pub value: f64,
    pub value_returned: f64,
}

impl SystemValues {
    /// The value of predefined parameter `name` (lower case, with its `_`), if it is one.
    pub fn get(&self, name: &str) -> Option<f64> {
        let axis = |prefix: &str| {
            let letter = name.strip_prefix(prefix)?;
            let i = ["x", "y", "z", "a", "b", "c"]
                .iter()
                .position(|&l| l == letter)?;
            Some(i)
        };
        if let Some(i) = axis("_abs_") {
            return Some(self.machine_position[i]);
        }
        if let Some(i) = axis("_") {
            return Some(self.position[i]);
        }
        Some(match name {
            "_line" => self.line,
            "_motion_mode" => self.motion_mode,
            "_plane" => self.plane,
            "_metric" => self.metric,
            "_imperial" => 1.0 - self.metric,
            "_absolute" => self.absolute,
            "_incremental" => 1.0 - self.absolute,
            "_ijk_absolute_mode" => self.ijk_absolute,
            "_inverse_time" => self.inverse_time,
            "_units_per_minute" => self.units_per_minute,
            "_units_per_rev" => self.units_per_rev,
            "_coord_system" => self.coord_system,
            "_tool_offset" => self.tool_offset,
            "_feed" => self.feed,
            "_rpm" => self.rpm,
            "_spindle_on" => self.spindle_on,
            "_spindle_cw" => self.spindle_cw,
            "_mist" => self.mist,
            "_flood" => self.flood,
            "_selected_tool" => self.selected_tool,
            "_selected_pocket" => self.selected_pocket,
            "_current_tool" => self.current_tool,
            "_current_pocket" => self.current_pocket,
            "_ccomp" => self.ccomp,
            "_retract_r_plane" => self.retract_r_plane,
            "_retract_old_z" => 1.0 - self.retract_r_plane,
            // tezgah has no constant surface speed (G96): always G97.
            "_spindle_rpm_mode" => 1.0,
            "_spindle_css_mode" => 0.0,
            "_lathe_diameter_mode" => self.lathe_diameter,
            "_lathe_radius_mode" => 1.0 - self.lathe_diameter,
            "_speed_override" => self.speed_override,
            "_feed_override" => self.feed_override,
            "_adaptive_feed" => self.adaptive_feed,
            "_feed_hold" => self.feed_hold,
            // U V W are not driven: they never leave 0.
            "_u" | "_v" | "_w" => 0.0,
            // No plug-in layer: never inside a remap, and one interpreter (rs274's reading).
            "_remap_level" | "_task" => 0.0,
            "_call_level" => self.call_level,
            "_value" => self.value,
            "_value_returned" => self.value_returned,
            "_vmajor" => 2.0,
            "_vminor" => 9.0,
            _ => return None,
        })
    }
}

impl Params {
    /// Whether `n` is a valid parameter number.
    pub fn in_range(n: i64) -> bool {
        (1..MAX_PARAMETERS as i64).contains(&n)
    }

    /// The value of parameter `n` (which must be in range).
    pub fn get(&self, n: usize) -> f64 {
        self.numbered[n]
    }

    pub fn set(&mut self, n: usize, v: f64) {
        self.numbered[n] = v;
    }

    /// Six consecutive parameters starting at `base`, as an X…C array.
    pub fn get6(&self, base: usize) -> [f64; 6] {
        std::array::from_fn(|i| self.numbered[base + i])
    }

    pub fn set6(&mut self, base: usize, v: [f64; 6]) {
        self.numbered[base..base + 6].copy_from_slice(&v);
    }

    /// The value of `#<name>`: a predefined value, an INI value, a global, or a local of the
    /// current call.
    pub fn named(&self, name: &str) -> Option<f64> {
        if name.starts_with('_') {
            return self
                .system
                .get(name)
                .or_else(|| self.ini_value(name))
                .or_else(|| self.globals.get(name).copied());
        }
        self.locals.last()?.get(name).copied()
    }

    /// Make `ini`'s values the `#<_ini[section]name>` parameters.
    pub fn set_ini(&mut self, ini: std::sync::Arc<crate::ini::IniFile>) {
        self.ini = Some(ini);
    }

    fn ini_value(&self, name: &str) -> Option<f64> {
        self.ini.as_ref()?.parameter(name)
    }

    /// Whether a program may not assign `#<name>` (a predefined or INI value).
    pub fn is_read_only(&self, name: &str) -> bool {
        name.starts_with('_') && (self.system.get(name).is_some() || self.ini_value(name).is_some())
    }

    pub fn set_named(&mut self, name: &str, v: f64) {
        let map = if name.starts_with('_') {
            &mut self.globals
        } else {
            match self.locals.last_mut() {
                Some(map) => map,
                None => return,
            }
        };
        if let Some(slot) = map.get_mut(name) {
            *slot = v;
        } else {
            map.insert(name.to_string(), v);
        }
    }

    /// Enter a subroutine: a fresh set of locals and `#1`…`#30` from `args` (the rest zero).
    /// Returns the caller's `#1`…`#30`, to be given back to [`Self::leave_call`].
    pub fn enter_call(&mut self, args: &[f64]) -> [f64; CALL_PARAMETERS] {
        let saved = std::array::from_fn(|i| self.numbered[i + 1]);
        for i in 0..CALL_PARAMETERS {
            self.numbered[i + 1] = args.get(i).copied().unwrap_or(0.0);
        }
        self.locals.push(HashMap::new());
        self.system.call_level = (self.locals.len() - 1) as f64;
        saved
    }

    /// Leave a subroutine: drop its locals and restore the caller's `#1`…`#30`.
    pub fn leave_call(&mut self, saved: [f64; CALL_PARAMETERS]) {
        self.numbered[1..=CALL_PARAMETERS].copy_from_slice(&saved);
        if self.locals.len() > 1 {
            self.locals.pop();
        }
        self.system.call_level = (self.locals.len() - 1) as f64;
    }
}
