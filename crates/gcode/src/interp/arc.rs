//! Arc centres for G2/G3: from a centre offset (I J K) or a radius (R), in the arc's plane.
//!
//! Both follow LinuxCNC (`arc_data_ijk`, `arc_data_r`): the centre-format radius check uses its
//! absolute and relative tolerances, and for R format the centre lies to the right of the chord for
//! G2 with R > 0, to the left for G3, and a negative R takes the other centre, i.e. the arc of more
//! than 180°. Coordinates are (first, second) in-plane coordinates, in program units.

use crate::error::{ArcMismatch, ErrorKind};

/// Relative radius tolerance of centre-format arcs (LinuxCNC `SPIRAL_RELATIVE_TOLERANCE`).
pub const RELATIVE_TOLERANCE: f64 = 0.001;
/// Absolute radius tolerance of centre-format arcs in inches: 2·0.001·√2.
pub const ABS_TOLERANCE_INCH: f64 = 2.0 * 0.001 * std::f64::consts::SQRT_2;
/// Absolute radius tolerance of centre-format arcs in millimetres: 2·0.01·√2.
pub const ABS_TOLERANCE_MM: f64 = 2.0 * 0.01 * std::f64::consts::SQRT_2;
/// Centre-format radii below this are zero (LinuxCNC `RADIUS_TOLERANCE_INCH`, and in mm).
pub const ZERO_RADIUS_INCH: f64 = 0.00005;
pub const ZERO_RADIUS_MM: f64 = 0.00005 * 25.4;
/// How far a radius-format arc's half chord may exceed |R| (LinuxCNC `TOLERANCE_INCH`/`_MM`).
pub const REACH_INCH: f64 = 0.0002;
pub const REACH_MM: f64 = 0.002;
/// Slack in the R-format reachability test (LinuxCNC `TINY`).
const TINY: f64 = 1e-12;

/// Direction of an arc.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sense {
    /// G2.
    Clockwise,
    /// G3.
    CounterClockwise,
}

impl Sense {
    /// LinuxCNC's turn number: `-turns` for clockwise, `+turns` counter-clockwise.
    pub fn turn(self, turns: i32) -> i32 {
        match self {
            Sense::Clockwise => -turns,
            Sense::CounterClockwise => turns,
        }
    }
}

/// The tolerances that apply to an arc (they depend on the program's units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcTolerance {
    pub absolute: f64,
    pub relative: f64,
    pub zero_radius: f64,
    pub reach: f64,
}

impl ArcTolerance {
    pub fn for_units(inches: bool) -> Self {
        if inches {
            ArcTolerance {
                absolute: ABS_TOLERANCE_INCH,
                relative: RELATIVE_TOLERANCE,
                zero_radius: ZERO_RADIUS_INCH,
                reach: REACH_INCH,
            }
        } else {
            ArcTolerance {
                absolute: ABS_TOLERANCE_MM,
                relative: RELATIVE_TOLERANCE,
                zero_radius: ZERO_RADIUS_MM,
                reach: REACH_MM,
            }
        }
    }
}

fn hypot(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Centre of a centre-format arc, checking that the end lies on the circle through the start.
/// `letters` are the in-plane axis letters, for the error text.
pub fn center_from_offset(
    start: [f64; 2],
    end: [f64; 2],
    center: [f64; 2],
    tol: ArcTolerance,
    letters: (char, char),
) -> Result<[f64; 2], ErrorKind> {
    let r1 = hypot(center, start);
    let r2 = hypot(center, end);
    let mismatch = |abs_err: f64, rel_err: f64| {
        Box::new(ArcMismatch {
            letters,
            start,
            center,
            end,
            r1,
            r2,
            abs_err,
            rel_err,
        })
    };
    if r1 < tol.zero_radius || r2 < tol.zero_radius {
        return Err(ErrorKind::ZeroRadiusArc(mismatch(0.0, 0.0)));
    }
    let abs_err = (r1 - r2).abs();
    let rel_err = abs_err / r1.max(r2);
    if abs_err > 100.0 * tol.absolute || (abs_err > tol.absolute && rel_err > tol.relative) {
        return Err(ErrorKind::ArcRadiusMismatch(mismatch(abs_err, rel_err)));
    }
    Ok(center)
}

/// Centre of a radius-format arc. A negative `radius` selects the arc of more than 180°.
pub fn center_from_radius(
    start: [f64; 2],
    end: [f64; 2],
    radius: f64,
    sense: Sense,
    tol: ArcTolerance,
) -> Result<[f64; 2], ErrorKind> {
    if start == end {
        return Err(ErrorKind::ArcEndIsStart);
    }
    let abs_radius = radius.abs();
    let mid = [(start[0] + end[0]) / 2.0, (start[1] + end[1]) / 2.0];
    let mut half = hypot(mid, end);
    if half - abs_radius > tol.reach {
        return Err(ErrorKind::ArcRadiusTooSmall);
    }
    if half / abs_radius > 1.0 - TINY {
        half = abs_radius; // a half circle, within rounding
    }
    let chord_angle = (end[1] - start[1]).atan2(end[0] - start[0]);
    // Clockwise with R > 0 (or counter-clockwise with R < 0): the centre is right of the chord.
    let right = (sense == Sense::Clockwise) == (radius > 0.0);
    let theta = if right {
        chord_angle - std::f64::consts::FRAC_PI_2
    } else {
        chord_angle + std::f64::consts::FRAC_PI_2
    };
    let offset = abs_radius * (half / abs_radius).asin().cos();
    Ok([mid[0] + offset * theta.cos(), mid[1] + offset * theta.sin()])
}

/// Swept angle in radians (0, 2π·turns] of an arc from `start` to `end` about `center`.
pub fn sweep(start: [f64; 2], end: [f64; 2], center: [f64; 2], sense: Sense, turns: u32) -> f64 {
    use std::f64::consts::TAU;
    let a0 = (start[1] - center[1]).atan2(start[0] - center[0]);
    let a1 = (end[1] - center[1]).atan2(end[0] - center[0]);
    let d = match sense {
        Sense::CounterClockwise => a1 - a0,
        Sense::Clockwise => a0 - a1,
    };
    let mut d = d.rem_euclid(TAU);
    if d <= 1e-12 {
        d += TAU; // a full circle
    }
    d + TAU * (turns.max(1) - 1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    const MM: ArcTolerance = ArcTolerance {
        absolute: ABS_TOLERANCE_MM,
        relative: RELATIVE_TOLERANCE,
        zero_radius: ZERO_RADIUS_MM,
        reach: REACH_MM,
    };

    fn close(a: [f64; 2], b: [f64; 2], tol: f64) {
        assert!(hypot(a, b) < tol, "{a:?} != {b:?}");
    }

    /// Kelekçi (2021), example (2.21): `G17 G02 X9.019 Y2.975 R5` from (0.24, 1.53).
    #[test]
    fn golden_arc_2_21() {
        let (s, e) = ([0.24, 1.53], [9.019, 2.975]);
        let c = center_from_radius(s, e, 5.0, Sense::Clockwise, MM).unwrap();
        close(c, [5.0, 0.0], 2e-3);
        let th = sweep(s, e, c, Sense::Clockwise, 1);
        assert!(
            (th.to_degrees() - 125.674).abs() < 5e-3,
            "{}",
            th.to_degrees()
        );
        assert!((5.0 * th - 10.9672).abs() < 5e-4);
        let c = center_from_radius(s, e, -5.0, Sense::Clockwise, MM).unwrap();
        close(c, [4.2588, 4.5048], 1e-4);
        let th = sweep(s, e, c, Sense::Clockwise, 1);
        assert!((th.to_degrees() - 234.326).abs() < 5e-3);
        assert!((5.0 * th - 20.4488).abs() < 5e-4);
    }

    /// Kelekçi (2021), example (3.25): `G02 X9.019 Y2.975 R14.976` from (0.2407, 1.533).
    #[test]
    fn golden_arc_3_25() {
        let (s, e) = ([0.2407, 1.533], [9.019, 2.975]);
        let c = center_from_radius(s, e, 14.976, Sense::Clockwise, MM).unwrap();
        close(c, [6.9479, -11.8571], 1e-4);
        let th = sweep(s, e, c, Sense::Clockwise, 1);
        assert!((th.to_degrees() - 34.5558).abs() < 1e-4);
        assert!((14.976 * th - 9.03222).abs() < 1e-5);
    }

    /// Kelekçi (2021), example (2.24): helix `G17 G03 X14.94 Y1.749 Z2 R14.976` from (14.32, 5.66).
    #[test]
    fn golden_helix_2_24() {
        let (s, e) = ([14.32, 5.66], [14.94, 1.749]);
        let c = center_from_radius(s, e, 14.976, Sense::CounterClockwise, MM).unwrap();
        close(c, [29.2915, 6.0287], 1e-4);
        let th = sweep(s, e, c, Sense::CounterClockwise, 1);
        assert!((th.to_degrees() - 15.194).abs() < 1e-3);
        assert!((14.976 * th - 3.9715).abs() < 1e-4);
        let c = center_from_radius(s, e, -14.976, Sense::CounterClockwise, MM).unwrap();
        close(c, [-0.0315, 1.3803], 1e-4);
        let th = sweep(s, e, c, Sense::CounterClockwise, 1);
        assert!((th.to_degrees() - 344.806).abs() < 1e-3);
        assert!((14.976 * th - 90.1255).abs() < 1e-3);
    }

    #[test]
    fn radius_check_regions() {
        // Small radius: fails just above the absolute tolerance.
        let bad = center_from_offset(
            [0.0, 0.0],
            [50.0, 0.0],
            [25.0 - 0.0101 * 2f64.sqrt(), 0.0],
            MM,
            ('X', 'Y'),
        );
        let msg = bad.unwrap_err().to_string();
        assert_eq!(msg, "Radius to end of arc differs from radius to start: start=(X0.0000,Y0.0000) center=(X24.9857,Y0.0000) end=(X50.0000,Y0.0000) r1=24.9857 r2=25.0143 abs_err=0.02857 rel_err=0.1142%");
        assert!(center_from_offset(
            [0.0, 0.0],
            [50.0, 0.0],
            [25.0 - 0.0099 * 2f64.sqrt(), 0.0],
            MM,
            ('X', 'Y')
        )
        .is_ok());
    }

    #[test]
    fn full_circle_sweep() {
        let th = sweep([1.0, 0.0], [1.0, 0.0], [0.0, 0.0], Sense::Clockwise, 1);
        assert!((th - std::f64::consts::TAU).abs() < 1e-12);
        let th = sweep(
            [1.0, 0.0],
            [0.0, 1.0],
            [0.0, 0.0],
            Sense::CounterClockwise,
            3,
        );
        assert!((th - (std::f64::consts::FRAC_PI_2 + 2.0 * std::f64::consts::TAU)).abs() < 1e-12);
    }
}
