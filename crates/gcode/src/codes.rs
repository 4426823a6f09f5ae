//! The G and M codes LinuxCNC knows and the modal group each belongs to.
//!
//! G codes are kept as ten times their number (G43.1 = 431), as LinuxCNC keeps them, so that
//! the decimal codes compare exactly.

/// Modal groups of G codes (LinuxCNC numbering).
pub mod ggroup {
    pub const NON_MODAL: usize = 0;
    pub const MOTION: usize = 1;
    pub const PLANE: usize = 2;
    pub const DISTANCE: usize = 3;
    pub const ARC_DISTANCE: usize = 4;
    pub const FEED_MODE: usize = 5;
    pub const UNITS: usize = 6;
    pub const CUTTER_COMP: usize = 7;
    pub const TOOL_LENGTH: usize = 8;
    pub const RETRACT: usize = 10;
    pub const COORD_SYSTEM: usize = 12;
    pub const PATH_CONTROL: usize = 13;
    pub const SPINDLE_MODE: usize = 14;
    pub const LATHE_DIAMETER: usize = 15;
    pub const COUNT: usize = 16;
}

/// Modal groups of M codes (LinuxCNC numbering).
pub mod mgroup {
    pub const STOP: usize = 4;
    pub const IO: usize = 5;
    pub const TOOL_CHANGE: usize = 6;
    pub const SPINDLE: usize = 7;
    pub const COOLANT: usize = 8;
    pub const OVERRIDE: usize = 9;
    pub const USER: usize = 10;
    /// M98/M99, Fanuc-style subprogram call and return.
    pub const SUBPROGRAM: usize = 11;
    pub const COUNT: usize = 12;
}

/// The modal group of G code `g10` (ten times the code), if LinuxCNC knows it.
pub fn g_group(g10: u32) -> Option<usize> {
    use ggroup::*;
    Some(match g10 {
        40 | 100 | 280 | 281 | 300 | 301 | 520 | 530 | 920 | 921 | 922 | 923 => NON_MODAL,
        0
        | 10
        | 20
        | 30
        | 50
        | 51
        | 52
        | 53
        | 62
        | 330
        | 331
        | 382..=385
        | 700
        | 710
        | 720
        | 730
        | 740
        | 760
        | 800
        | 810
        | 820
        | 830
        | 840
        | 850
        | 860
        | 870
        | 880
        | 890 => MOTION,
        170 | 171 | 180 | 181 | 190 | 191 => PLANE,
        900 | 910 => DISTANCE,
        901 | 911 => ARC_DISTANCE,
        930 | 940 | 950 => FEED_MODE,
        200 | 210 => UNITS,
        400 | 410 | 411 | 420 | 421 => CUTTER_COMP,
        430 | 431 | 432 | 434 | 490 => TOOL_LENGTH,
        980 | 990 => RETRACT,
        540 | 550 | 560 | 570 | 580 | 590 | 591 | 592 | 593 => COORD_SYSTEM,
        610 | 611 | 640 => PATH_CONTROL,
        960 | 970 => SPINDLE_MODE,
        70 | 80 => LATHE_DIAMETER,
        _ => return None,
    })
}

/// The modal group of M code `m`, if LinuxCNC knows it.
pub fn m_group(m: i64) -> Option<usize> {
    use mgroup::*;
    Some(match m {
        0 | 1 | 2 | 30 | 60 => STOP,
        62..=68 => IO,
        6 | 61 => TOOL_CHANGE,
        // M70–M73 share the spindle's group in LinuxCNC (`M3 M70` is two of one group).
        3 | 4 | 5 | 19 | 70..=73 => SPINDLE,
        7..=9 => COOLANT,
        48..=53 => OVERRIDE,
        98 | 99 => SUBPROGRAM,
        100..=199 => USER,
        _ => return None,
    })
}

/// Human form of a G code kept as ten times its number: 431 → "G43.1".
pub fn g_name(g10: u32) -> String {
    if g10 % 10 == 0 {
        format!("G{}", g10 / 10)
    } else {
        format!("G{}.{}", g10 / 10, g10 % 10)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups() {
        assert_eq!(g_group(431), Some(ggroup::TOOL_LENGTH));
        assert_eq!(g_group(434), Some(ggroup::TOOL_LENGTH));
        assert_eq!(g_name(434), "G43.4");
        assert_eq!(g_group(592), Some(ggroup::COORD_SYSTEM));
        assert_eq!(g_group(12), None);
        assert_eq!(g_group(815), None);
        assert_eq!(g_group(830), Some(ggroup::MOTION));
        assert_eq!(m_group(30), Some(mgroup::STOP));
        assert_eq!(m_group(200), None);
        assert_eq!(g_name(591), "G59.1");
    }
}
