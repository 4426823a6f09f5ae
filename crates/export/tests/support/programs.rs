//! The programs exported in the tests: the sag case of Ayyıldız (2017, §5.4), a delta program of arcs and
//! helices, a five-axis program on table-ac, and random delta programs within reach.

use std::f64::consts::PI;

use proptest::prelude::*;
use tezgah_geom::Vec3;

/// Ayyıldız (2017, §5.4): the 100 mm XY diagonal, which sags 4.646 mm when only its end points
/// are converted.
pub const SAG: &str = "G21 G90 G94\nG0 X-31.654 Y-28.911 Z-0.2\nG1 X39.057 Y41.8 F1000\nM2\n";

/// A delta program of arcs and helices in three planes, with spindle and coolant words.
pub const DELTA_ARCS: &str = "G21 G90 G94 G61
S12000 M3
G0 X40 Y0 Z-10
G2 X40 Y0 I-40 J0 F1200
M8
G3 X0 Y40 Z-5 I-40 J0 F900
G1 X-30 Y10 Z0 F1500
G18 G2 X-10 Z0 I10 K0 F800
G17 G4 P0.5
M9 M5
M2
";

/// A five-axis program under TCP on table-ac: a tilting move, an arc, a turn of the tool axis
/// alone about the tip, TCP off again.
pub const TABLE_AC: &str = "G21 G90 G94 G61
T1 M6
G43.4 H1
G0 X10 Y5 Z20 A0 C0
G1 Z-3 F600
G1 X40 Y-10 A30 C60 F800
G2 X20 Y-30 I-20 J0 F700
G1 A10 C-90 F3600
G1 X0 Y0 Z5 A45 C120 F1000
G49
G0 Z100
M2
";

/// Tool 1 of the five-axis program.
pub const TABLE_AC_TOOLS: &str = "T1 P1 Z35.0 D6\n";

/// A random delta program within reach: lines and arcs (some helical), blended under G64.
pub fn delta_program() -> impl Strategy<Value = (String, f64)> {
    let point = (-60.0..60.0f64, -60.0..60.0f64, -30.0..10.0f64);
    let step = (
        0..3u8,
        point.clone(),
        (5.0..25.0f64, 0.0..2.0 * PI, -5.0..5.0f64),
        300.0..3000.0f64,
    );
    (
        point,
        prop::collection::vec(step, 2..7),
        prop::sample::select(vec![0.01, 0.05]),
    )
        .prop_map(|(start, steps, tol)| {
            let mut text = String::from("G21 G90 G94 G64\n");
            text += &format!("G0 X{:.4} Y{:.4} Z{:.4}\n", start.0, start.1, start.2);
            let mut at = Vec3::new(start.0, start.1, start.2);
            for (kind, p, (r, angle, rise), feed) in steps {
                if kind == 0 {
                    text += &format!("G1 X{:.4} Y{:.4} Z{:.4} F{feed:.1}\n", p.0, p.1, p.2);
                    at = Vec3::new(p.0, p.1, p.2);
                    continue;
                }
                // An arc about a centre r from here, kept inside the reach.
                let mut c = at.xy() + nalgebra::Vector2::new(r * angle.cos(), r * angle.sin());
                if c.norm() + r > 75.0 {
                    c *= (75.0 - r).max(0.0) / c.norm();
                }
                let r = (at.xy() - c).norm();
                let start_angle = (at.y - c.y).atan2(at.x - c.x);
                let end = c + nalgebra::Vector2::new(
                    r * (start_angle + angle).cos(),
                    r * (start_angle + angle).sin(),
                );
                let z = (at.z + rise).clamp(-30.0, 10.0);
                let g = if kind == 1 { "G2" } else { "G3" };
                text += &format!(
                    "{g} X{:.4} Y{:.4} Z{z:.4} I{:.4} J{:.4} F{feed:.1}\n",
                    end.x,
                    end.y,
                    c.x - at.x,
                    c.y - at.y
                );
                at = Vec3::new(end.x, end.y, z);
            }
            text += "M2\n";
            (text, tol)
        })
}

/// A random five-axis program under TCP on table-ac, blended under G64: lines that tilt (A in
/// 10–60°, away from the pole) and turn the table (C accumulating past ±180°, so the written C
/// must unwrap), and flat arcs.
pub fn table_ac_program() -> impl Strategy<Value = String> {
    let step = (
        0..3u8,
        (-40.0..40.0f64, -40.0..40.0f64, -20.0..10.0f64),
        (10.0..60.0f64, -90.0..90.0f64),
        (5.0..20.0f64, 0.3..2.5f64),
        300.0..3000.0f64,
    );
    prop::collection::vec(step, 2..6).prop_map(|steps| {
        let mut text = String::from("G21 G90 G94 G64\nG43.4 H1\nG0 X0 Y0 Z10 A20 C0\n");
        let (mut at, mut c) = (Vec3::new(0.0, 0.0, 10.0), 0.0);
        for (kind, p, (a, dc), (r, sweep), feed) in steps {
            if kind == 0 {
                c += dc;
                text += &format!(
                    "G1 X{:.4} Y{:.4} Z{:.4} A{a:.4} C{c:.4} F{feed:.1}\n",
                    p.0, p.1, p.2
                );
                at = Vec3::new(p.0, p.1, p.2);
                continue;
            }
            // A flat arc of radius r about a centre beside the current point.
            let centre = at.xy() + nalgebra::Vector2::new(-r, 0.0);
            let turn = if kind == 1 { -sweep } else { sweep };
            let end = centre + nalgebra::Vector2::new(r * turn.cos(), r * turn.sin());
            let g = if kind == 1 { "G2" } else { "G3" };
            text += &format!("{g} X{:.4} Y{:.4} I{:.4} J0 F{feed:.1}\n", end.x, end.y, -r);
            at = Vec3::new(end.x, end.y, at.z);
        }
        text + "M2\n"
    })
}
