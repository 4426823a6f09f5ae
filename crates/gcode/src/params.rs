//! The parameter store: numbered parameters `#1`–`#5601` and named ones `#<name>`.
//!
//! Numbered parameters that were never set read as zero, as in LinuxCNC. The interpreter keeps
//! its offsets in the reserved numbers (`#5221…` for G54, `#5211…` for G92, `#5161…` for G28,
//! …) so that a program can read them.

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

/// The first parameter of work-coordinate system `n` (1 = G54 … 9 = G59.3).
pub fn coord_system_base(n: usize) -> usize {
    G54_OFFSET + 20 * (n - 1)
}

/// Numbered and named parameters.
#[derive(Debug, Clone)]
pub struct Params {
    numbered: Vec<f64>,
    named: HashMap<String, f64>,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            numbered: vec![0.0; MAX_PARAMETERS],
            named: HashMap::new(),
        }
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

    pub fn named(&self, name: &str) -> Option<f64> {
        self.named.get(name).copied()
    }

    pub fn set_named(&mut self, name: &str, v: f64) {
        if let Some(slot) = self.named.get_mut(name) {
            *slot = v;
        } else {
            self.named.insert(name.to_string(), v);
        }
    }
}
