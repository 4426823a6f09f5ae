//! Compensated straight moves (LinuxCNC's `convert_straight_comp1` and `_comp2`).
//!
//! The entry move goes to the point one radius beside the programmed end, perpendicular to the
//! line from the start (the tool ends tangent to the new direction). Later lines end one radius
//! beside their programmed end; at the corner before them the previous move is cut short
//! (concave corner) or an arc about the programmed corner is added (convex corner, feeds only:
//! there is no arc traverse).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use tezgah_geom::Pose;

use crate::canon::CanonSink;
use crate::error::ErrorKind;

use super::super::Interpreter;
use super::queue::{Held, HeldArc};
use super::{plane_axes, polar, CompError, Side, CORNER_TOLERANCE};

impl Interpreter {
    /// A G0 or G1 to the programmed point `end` with compensation active.
    pub(in crate::interp) fn straight_comp(
        &mut self,
        rapid: bool,
        end: Pose,
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        let (a, b, n) = plane_axes(self.state.plane);
        let p = [end.0[a], end.0[b], end.0[n]];
        let abc = [end.0[3], end.0[4], end.0[5]];
        if self.comp.first_move {
            self.straight_entry(rapid, end, p, abc)
        } else {
            self.straight_after(rapid, end, p, abc, sink)
        }
    }

    /// The first move after G41/G42.
    fn straight_entry(
        &mut self,
        rapid: bool,
        end: Pose,
        p: [f64; 3],
        abc: [f64; 3],
    ) -> Result<(), ErrorKind> {
        let side = self.comp.side.ok_or(CompError::Bug)?;
        let radius = self.comp.radius;
        let c = self.comp_current();
        // rs274 2.9 refuses only a shorter move, whatever its message says: an entry exactly
        // one radius long (LinuxCNC's useful-subroutines.ngc, `g41 g0` onto the hole's edge)
        // ends with the tool centre on the start of the contour's normal.
        if (p[0] - c[0]).hypot(p[1] - c[1]) < radius {
            return Err(CompError::EntryMoveTooShort.into());
        }
        let alpha = (p[1] - c[1]).atan2(p[0] - c[0]) + side.normal_angle();
        let tool_end = polar([p[0], p[1]], radius, alpha);
        // The entry move is longer than the radius, so no later corner can reverse it.
        self.comp.endpoint = Some([c[0], c[1]]);
        self.hold_straight(rapid, alpha.cos(), alpha.sin(), end, tool_end);
        self.comp.first_move = false;
        self.set_comp_current([tool_end[0], tool_end[1], p[2]], abc);
        self.set_comp_programmed(p);
        Ok(())
    }

    /// Hold a straight move to `end` with its in-plane end replaced by `tool_end`.
    fn hold_straight(&mut self, rapid: bool, dx: f64, dy: f64, end: Pose, tool_end: [f64; 2]) {
        let (a, b, _) = plane_axes(self.state.plane);
        let mut end = end;
        end.0[a] = tool_end[0];
        end.0[b] = tool_end[1];
        self.hold(Held::Straight {
            origin: self.origin,
            rapid,
            direction: [dx, dy],
            end,
        });
    }

    /// A straight move after the entry move: the corner with the move before it first.
    fn straight_after(
        &mut self,
        rapid: bool,
        end: Pose,
        p: [f64; 3],
        abc: [f64; 3],
        sink: &mut impl CanonSink,
    ) -> Result<(), ErrorKind> {
        let c = self.comp_current();
        let op = self.comp_programmed();
        let direction = [p[0] - op[0], p[1] - op[1]];
        if p[0] == op[0] && p[1] == op[1] {
            // No motion in the plane: the tool stays beside the programmed point.
            self.hold_straight(rapid, direction[0], direction[1], end, [c[0], c[1]]);
            self.set_comp_current([c[0], c[1], p[2]], abc);
            self.set_comp_programmed(p);
            return Ok(());
        }
        let side = self.comp.side.ok_or(CompError::Bug)?;
        let radius = self.comp.radius;
        // theta: from the programmed corner to the tool; alpha: the new direction; beta: the
        // turn at the corner, measured so that 0..π is convex, outside it concave.
        let mut theta = (c[1] - op[1]).atan2(c[0] - op[0]);
        let mut alpha = direction[1].atan2(direction[0]);
        let beta = match side {
            Side::Left => {
                if theta < alpha {
                    theta += TAU;
                }
                theta - alpha - FRAC_PI_2
            }
            Side::Right => {
                if alpha < theta {
                    alpha += TAU;
                }
                alpha - theta - FRAC_PI_2
            }
        };
        let gamma = side.normal_angle();
        let tool_end = polar([p[0], p[1]], radius, alpha + gamma);
        let mid = polar([op[0], op[1]], radius, alpha + gamma);
        let small = CORNER_TOLERANCE;
        // Over the top of an arc into a line (an "h"): stay on this side, not loop round.
        let h_shape = beta > PI - small
            && self
                .held_arc()
                .is_some_and(|arc| side.other().inside_arc(arc.turn));
        let concave = beta < -small || beta > PI + small || h_shape;
        if !concave && beta > small {
            // Convex corner: close the move before at the current point, then go round the
            // programmed corner on an arc of the tool radius.
            self.move_endpoint_and_flush([c[0], c[1]], sink)?;
            if rapid {
                // No arc traverse exists; a straight one keeps most of the rapid parallel
                // to the programmed one.
                let (a, b, _) = plane_axes(self.state.plane);
                let mut corner = self.state.pos;
                corner.0[a] = mid[0];
                corner.0[b] = mid[1];
                corner.0[3..].copy_from_slice(&abc);
                self.hold(Held::Straight {
                    origin: self.origin,
                    rapid: true,
                    direction: [0.0; 2],
                    end: corner,
                });
            } else {
                self.hold(Held::Arc(HeldArc {
                    origin: self.origin,
                    sweep: 0.0,
                    end: mid,
                    center: [op[0], op[1]],
                    turn: side.corner_turn(),
                    normal_end: c[2],
                    abc,
                }));
            }
            self.dequeue(sink);
            self.comp.endpoint = Some(mid);
        } else if concave {
            let to = match self.held_arc() {
                None => {
                    // Line into line: pull the previous end back along its direction.
                    let half_corner = (beta + PI) / 2.0;
                    if half_corner == 0.0 {
                        return Err(CompError::ZeroDegreeCorner.into());
                    }
                    let retreat = radius / half_corner.tan();
                    polar([c[0], c[1]], retreat, theta + gamma)
                }
                Some(prev) => arc_line_corner(prev, side, radius, op, direction)?,
            };
            self.move_endpoint_and_flush(to, sink)?;
        } else {
            // Straight on, or a line tangent to the arc before.
            self.dequeue(sink);
            self.comp.endpoint = Some([c[0], c[1]]);
        }
        self.hold_straight(rapid, direction[0], direction[1], end, tool_end);
        self.set_comp_current([tool_end[0], tool_end[1], p[2]], abc);
        self.set_comp_programmed(p);
        Ok(())
    }
}

/// Where the compensated arc `prev` (held) meets the compensated line that leaves the
/// programmed point `op` in `direction`, at a concave corner.
fn arc_line_corner(
    prev: HeldArc,
    side: Side,
    radius: f64,
    op: [f64; 3],
    direction: [f64; 2],
) -> Result<[f64; 2], ErrorKind> {
    let old_radius = (prev.center[1] - prev.end[1]).hypot(prev.center[0] - prev.end[0]);
    let base = direction[1].atan2(direction[0]);
    let theta = if prev.turn > 0 {
        base + FRAC_PI_2
    } else {
        base - FRAC_PI_2
    };
    let phi = (prev.center[1] - op[1]).atan2(prev.center[0] - op[0]);
    let inside = side.inside_arc(prev.turn);
    let programmed_radius = if inside {
        old_radius + radius
    } else {
        old_radius - radius
    };
    // Distance from the old centre to the new line, perpendicular to it.
    let d = programmed_radius * (theta - phi).cos();
    let d2 = if inside { d - radius } else { d + radius };
    let l = d2 / old_radius;
    if !(-1.0..=1.0).contains(&l) {
        return Err(CompError::ArcLineGouge.into());
    }
    let flip = (prev.turn > 0) != inside;
    let angle = if flip { l.acos() } else { -l.acos() } + theta + PI;
    Ok([
        prev.center[0] + old_radius * angle.cos(),
        prev.center[1] + old_radius * angle.sin(),
    ])
}
