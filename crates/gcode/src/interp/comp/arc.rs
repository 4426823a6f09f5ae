//! Compensated arcs (LinuxCNC's `convert_arc_comp1` and `_comp2`).
//!
//! A compensated arc is concentric with the programmed one, its radius one tool radius larger
//! (tool outside) or smaller (tool inside). As the entry move, the arc is bent so that it starts
//! at the tool and ends beside the programmed end. Later arcs meet the move before at a concave
//! corner (the move before is cut short), or go round a convex corner on an extra arc.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use tezgah_geom::Pose;

use crate::canon::CanonSink;
use crate::error::ErrorKind;

use super::super::arc::ArcTolerance;
use super::super::Interpreter;
use super::queue::{find_turn, Held, HeldArc};
use super::{angle_to, distance, plane_axes, polar, CompError, Side, CORNER_TOLERANCE};
use crate::reader::TOLERANCE_EQUAL;

/// A programmed arc, in the compensation plane's coordinates.
#[derive(Debug, Clone, Copy)]
pub(in crate::interp) struct ProgrammedArc {
    /// Programmed end: first, second, normal coordinate.
    pub end: [f64; 3],
    pub center: [f64; 2],
    /// + counter-clockwise turns, − clockwise.
    pub turn: i32,
    pub abc: [f64; 3],
}

impl ProgrammedArc {
    /// In the plane of `plane_axes`, from the end pose.
    pub fn new(axes: (usize, usize, usize), end: Pose, center: [f64; 2], turn: i32) -> Self {
        let (a, b, n) = axes;
        ProgrammedArc {
            end: [end.0[a], end.0[b], end.0[n]],
            center,
            turn,
            abc: [end.0[3], end.0[4], end.0[5]],
        }
    }

    fn end2(&self) -> [f64; 2] {
        [self.end[0], self.end[1]]
    }
}

impl Interpreter {
    /// A compensated G2/G3 whose programmed centre and turn are known.
    pub(in crate::interp) fn arc_comp(
        &mut self,
        arc: ProgrammedArc,
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        if self.comp.first_move {
            self.arc_entry(arc)
        } else {
            self.arc_after(arc, sink)
        }
    }

    /// The checks of an entry arc made before its centre is found: it must end outside the
    /// tool (`convert_arc_comp1`), and an R-format arc the tool runs inside must be larger than
    /// the tool (`arc_data_comp_r`).
    pub(in crate::interp) fn check_entry_arc(
        &self,
        end: Pose,
        radius_word: Option<f64>,
        turn: i32,
    ) -> Result<(), ErrorKind> {
        if !(self.comp.active() && self.comp.first_move) {
            return Ok(());
        }
        let (a, b, _) = plane_axes(self.state.plane);
        let c = self.comp_current();
        // As for entry lines, only shorter is refused (rs274 2.9 accepts equal).
        if distance([end.0[a], end.0[b]], [c[0], c[1]]) < self.comp.radius {
            return Err(CompError::EntryArcTooSmall.into());
        }
        self.check_tool_fits(radius_word.map(f64::abs), turn)
    }

    /// A centre-format entry arc the tool runs inside must be larger than the tool
    /// (`arc_data_comp_ijk`, checked after the centre).
    pub(in crate::interp) fn check_entry_arc_center(
        &self,
        start: [f64; 2],
        center: [f64; 2],
        turn: i32,
    ) -> Result<(), ErrorKind> {
        if !(self.comp.active() && self.comp.first_move) {
            return Ok(());
        }
        self.check_tool_fits(Some(distance(center, start)), turn)
    }

    fn check_tool_fits(&self, arc_radius: Option<f64>, turn: i32) -> Result<(), ErrorKind> {
        let inside = self.comp.side.is_some_and(|s| s.inside_arc(turn));
        match arc_radius {
            // rs274 2.9 refuses only a smaller arc: the tool may fill a hole of its size.
            Some(r) if inside && r < self.comp.radius => {
                Err(CompError::ToolNotSmallerThanArc.into())
            }
            _ => Ok(()),
        }
    }

    /// The first move after G41/G42 is an arc: it starts at the tool and ends one radius from
    /// the programmed end, on a circle through both (`convert_arc_comp1`).
    fn arc_entry(&mut self, arc: ProgrammedArc) -> Result<(), ErrorKind> {
        let side = self.comp.side.ok_or(CompError::Bug)?;
        let radius = self.comp.radius;
        let c = self.comp_current();
        let c2 = [c[0], c[1]];
        let end = arc.end2();
        let gamma = if side.inside_arc(arc.turn) {
            angle_to(end, arc.center)
        } else {
            angle_to(arc.center, end)
        };
        self.comp.first_move = false;
        self.set_comp_programmed(arc.end);
        let tool_end = polar(end, radius, gamma);
        // The new centre B: in the right triangle of the tool end A, B and the midpoint of
        // the chord from the tool start to A, on the line from A towards the programmed centre.
        let half_chord = distance(c2, tool_end) / 2.0;
        let ab = angle_to(tool_end, arc.center);
        let a_angle = angle_to(tool_end, c2) - ab;
        if a_angle.cos().abs() < TOLERANCE_EQUAL {
            return Err(CompError::ToolNotSmallerThanArc.into());
        }
        let center = polar(tool_end, half_chord / a_angle.cos(), ab);
        let tol = ArcTolerance::for_units(self.state.inches());
        if (distance(center, tool_end) - distance(center, c2)).abs() > tol.absolute {
            return Err(CompError::Bug.into());
        }
        self.hold(Held::Arc(HeldArc {
            origin: self.origin,
            sweep: find_turn(c2, center, arc.turn, tool_end),
            end: tool_end,
            center,
            turn: arc.turn,
            normal_end: arc.end[2],
            abc: arc.abc,
        }));
        self.set_comp_current([tool_end[0], tool_end[1], arc.end[2]], arc.abc);
        Ok(())
    }

    /// An arc after the entry move (`convert_arc_comp2`).
    fn arc_after(
        &mut self,
        arc: ProgrammedArc,
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        let side = self.comp.side.ok_or(CompError::Bug)?;
        let radius = self.comp.radius;
        let op = self.comp_programmed();
        let op2 = [op[0], op[1]];
        let c = self.comp_current();
        let end = arc.end2();
        let arc_radius = distance(arc.center, end);
        // theta: the normal of the move before at the corner; alpha: the arc's tangent there;
        // beta: the turn between them (0..π convex).
        let theta = angle_to(op2, [c[0], c[1]]) - side.normal_angle();
        let mut delta = angle_to(op2, arc.center);
        let alpha = if arc.turn > 0 {
            delta - FRAC_PI_2
        } else {
            delta + FRAC_PI_2
        };
        let mut beta = match side {
            Side::Left => theta - alpha,
            Side::Right => alpha - theta,
        };
        if beta > 1.5 * PI {
            beta -= TAU;
        } else if beta < -FRAC_PI_2 {
            beta += TAU;
        }
        let inside = side.inside_arc(arc.turn);
        let gamma = if inside {
            // Only a smaller arc is refused, as rs274 2.9 does (equal: the tool fills it).
            if arc_radius < radius {
                return Err(CompError::ToolNotSmallerThanArc.into());
            }
            angle_to(end, arc.center)
        } else {
            delta += PI;
            angle_to(arc.center, end)
        };
        let tool_end = polar(end, radius, gamma);
        let small = CORNER_TOLERANCE;
        // A tangent corner over the top of an arc (an "m" or "h") is concave for a tool
        // outside the new arc.
        let concave = beta < -small || beta > PI + small || ((beta - PI).abs() < small && !inside);
        if concave {
            let to = match self.held_arc() {
                None => line_arc_corner(arc, side, radius, theta, beta, arc_radius)?,
                Some(prev) => arc_arc_corner(prev, arc, side, radius, arc_radius)?,
            };
            self.move_endpoint_and_flush(to, sink)?;
        } else if beta > small {
            // Convex: an arc of the tool radius about the programmed corner first.
            let mid = polar(op2, radius, delta);
            self.dequeue(sink);
            self.hold(Held::Arc(HeldArc {
                origin: self.origin,
                sweep: 0.0,
                end: mid,
                center: op2,
                turn: side.corner_turn(),
                normal_end: c[2],
                abc: arc.abc,
            }));
            self.dequeue(sink);
            self.comp.endpoint = Some(mid);
        } else {
            self.dequeue(sink);
            self.comp.endpoint = Some([c[0], c[1]]);
        }
        self.hold(Held::Arc(HeldArc {
            origin: self.origin,
            sweep: find_turn(op2, arc.center, arc.turn, end),
            end: tool_end,
            center: arc.center,
            turn: arc.turn,
            normal_end: arc.end[2],
            abc: arc.abc,
        }));
        self.set_comp_programmed(arc.end);
        self.set_comp_current([tool_end[0], tool_end[1], arc.end[2]], arc.abc);
        Ok(())
    }
}

/// Where the compensated line before meets the compensated arc `arc` at a concave corner.
fn line_arc_corner(
    arc: ProgrammedArc,
    side: Side,
    radius: f64,
    theta: f64,
    beta: f64,
    arc_radius: f64,
) -> Result<[f64; 2], ErrorKind> {
    let toward = arc_radius * (beta - FRAC_PI_2).sin();
    let angle = if side.inside_arc(arc.turn) {
        let from_center = arc_radius - radius;
        let l = (toward + radius) / from_center;
        if !(-1.0..=1.0).contains(&l) {
            return Err(CompError::ArcGouge.into());
        }
        if arc.turn > 0 {
            theta + l.asin()
        } else {
            theta - l.asin()
        }
    } else {
        let from_center = arc_radius + radius;
        let l = (toward - radius) / from_center;
        if !(-1.0..=1.0).contains(&l) {
            return Err(CompError::ArcGouge.into());
        }
        if arc.turn > 0 {
            theta + PI - l.asin()
        } else {
            theta + PI + l.asin()
        }
    };
    let from_center = if side.inside_arc(arc.turn) {
        arc_radius - radius
    } else {
        arc_radius + radius
    };
    Ok(polar(arc.center, from_center, angle))
}

/// Where the compensated arc `prev` (held) meets the compensated arc `arc` at a concave corner:
/// the intersection of the two offset circles on the side of the corner.
fn arc_arc_corner(
    prev: HeldArc,
    arc: ProgrammedArc,
    side: Side,
    radius: f64,
    arc_radius: f64,
) -> Result<[f64; 2], ErrorKind> {
    let old_radius = distance(prev.center, prev.end);
    let new_radius = if side.inside_arc(arc.turn) {
        arc_radius - radius
    } else {
        arc_radius + radius
    };
    let centers = distance(prev.center, arc.center);
    if old_radius == 0.0 || centers == 0.0 {
        return Err(CompError::ArcArcSameCenter.into());
    }
    // Law of cosines in the triangle of the two centres and the meeting point.
    let a =
        (old_radius.powi(2) + centers.powi(2) - new_radius.powi(2)) / (2.0 * old_radius * centers);
    if !(-1.0..=1.0).contains(&a) {
        return Err(CompError::ArcArcGouge.into());
    }
    let pullback = a.acos();
    let toward = angle_to(prev.center, arc.center);
    let plus = side.inside_arc(prev.turn) == (arc.turn > 0);
    let dir = if plus {
        toward + pullback
    } else {
        toward - pullback
    };
    Ok(polar(prev.center, old_radius, dir))
}
