//! The G-code text of a posted program: header, tool change and length compensation
//! (G43.4 for tool-centre-point output, G43 for joint output), one block per output point,
//! feeds per minute or in inverse time, and the end. Last step of the post-processor.

use std::fmt::Write as _;

use super::clearance::Clearance;
use super::linearise::MachineMotion;
use super::links::Motion;
use super::{FeedOutput, OutputForm, PostError, PostOptions, PostedPoint};

/// Decimals of lengths and angles: 0.1 µm and 0.0001°, far below any machining tolerance
/// (0.0001° at a 10 mm reach is 0.02 µm).
const DECIMALS: usize = 4;

/// A number with [`DECIMALS`] decimals, trailing zeros dropped, never `-0`.
pub fn number(x: f64) -> String {
    let mut s = format!("{x:.DECIMALS$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".into();
    }
    s
}

/// Inverse-time F: 1/minutes, to 6 significant digits at least.
fn inverse_time(minutes: f64) -> String {
    let f = 1.0 / minutes;
    let s = format!("{f:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_owned()
}

/// The words X Y Z <tilt> C of a point in the output form.
fn words(p: &PostedPoint, motion: &MachineMotion<'_>, letters: [char; 2]) -> String {
    let xyz = match motion.form {
        OutputForm::CentrePoint => p.tip,
        // The tip in machine coordinates: the gauge point less the tool length along Z.
        OutputForm::Joints => {
            nalgebra::Vector3::new(p.joints[0], p.joints[1], p.joints[2] - motion.tool.length)
        }
    };
    format!(
        "X{} Y{} Z{} {}{} {}{}",
        number(xyz.x),
        number(xyz.y),
        number(xyz.z),
        letters[0],
        number(p.angles.tilt.to_degrees()),
        letters[1],
        number(p.angles.c.to_degrees())
    )
}

/// A comment line; parentheses inside would nest (an error in LinuxCNC's dialect).
fn comment(out: &mut String, text: &str) {
    let _ = writeln!(out, "({})", text.replace(['(', ')'], " "));
}

/// The whole program.
pub fn program(
    points: &[PostedPoint],
    motion: &MachineMotion<'_>,
    options: &PostOptions,
    letters: [char; 2],
    sphere: &Clearance,
) -> Result<String, PostError> {
    let mut out = String::new();
    let tool = options.tool_number;
    let form = match motion.form {
        OutputForm::CentrePoint => "tool-centre-point output, G43.4: X Y Z = tip on the part",
        OutputForm::Joints => "joint output, G43: X Y Z = tip in machine coordinates",
    };
    let title = if options.title.is_empty() {
        "tezgah cam".to_owned()
    } else {
        format!("tezgah cam: {}", options.title)
    };
    comment(&mut out, &title);
    comment(
        &mut out,
        &format!("{form}, {}{} table angles", letters[0], letters[1]),
    );
    comment(
        &mut out,
        &format!(
            "feed {} mm/min, linearisation tolerance {} mm, links on the sphere R{} about X{} Y{} Z{} of the part",
            number(options.feed_mm_per_min),
            options.tolerance_mm,
            number(sphere.radius),
            number(sphere.centre.x),
            number(sphere.centre.y),
            number(sphere.centre.z)
        ),
    );
    // Blending rounds corners toward the inside of the polyline, i.e. into the material on a
    // convex part: an explicit `P` keeps it within the share the tool path's band allows.
    match options.blend_mm {
        Some(p) => {
            let _ = writeln!(out, "G21 G17 G90 G40 G94 G64 P{p}");
        }
        None => {
            let _ = writeln!(out, "G21 G17 G90 G40 G94 G64");
        }
    }
    let _ = writeln!(out, "T{tool} M6");
    if let Some(rpm) = options.spindle_rpm {
        let _ = writeln!(out, "S{} M3", number(rpm));
    }
    let Some(first) = points.first() else {
        return Err(PostError::Empty);
    };
    match motion.form {
        OutputForm::CentrePoint => {
            let _ = writeln!(out, "G43.4 H{tool}");
            // From wherever the machine is, up to the top of the clearance sphere at the
            // current orientation, then to its top with the tool vertical.
            let _ = writeln!(out, "G0 Z{}", number(first.tip.z));
        }
        OutputForm::Joints => {
            let _ = writeln!(out, "G43 H{tool}");
            let _ = writeln!(out, "G0 Z{}", number(first.joints[2] - motion.tool.length));
        }
    }
    let inverse = options.feed_output == FeedOutput::InverseTime;
    if inverse {
        let _ = writeln!(out, "G93");
    }
    let mut modal_feed = false;
    let mut last_g = "";
    let mut previous: Option<&PostedPoint> = None;
    for p in points {
        let g = match p.motion {
            Motion::Rapid => "G0",
            Motion::Plunge | Motion::Cut => "G1",
        };
        let mut line = String::new();
        if g != last_g || inverse {
            line.push_str(g);
            line.push(' ');
        }
        line.push_str(&words(p, motion, letters));
        if g == "G1" {
            if inverse {
                let prev = previous.unwrap_or(p);
                let length = (p.tip - prev.tip).norm();
                // A pure turn: its degrees at the feed read as deg/min (docs/path-and-feed.md).
                let amount = if length > 1e-9 {
                    length
                } else {
                    let turn = (p.angles.tilt - prev.angles.tilt)
                        .abs()
                        .max((p.angles.c - prev.angles.c).abs());
                    turn.to_degrees().max(1e-9)
                };
                let _ = write!(line, " F{}", inverse_time(amount / options.feed_mm_per_min));
            } else if !modal_feed {
                let _ = write!(line, " F{}", number(options.feed_mm_per_min));
                modal_feed = true;
            }
        }
        let _ = writeln!(out, "{line}");
        last_g = g;
        previous = Some(p);
    }
    if inverse {
        let _ = writeln!(out, "G94");
    }
    if options.spindle_rpm.is_some() {
        let _ = writeln!(out, "M5");
    }
    let _ = writeln!(out, "G49");
    let _ = writeln!(out, "M2");
    Ok(out)
}
