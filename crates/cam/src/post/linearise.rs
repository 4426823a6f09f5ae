//! The linearisation check: between two output points the machine does not follow the tool
//! path's straight segment — with joint output it interpolates the joints, under
//! tool-centre-point control it moves the tip straight but interpolates the table angles, so
//! the tool axis leaves the great circle between the two axes. Each output segment is measured
//! against the path it stands for and halved (a point inserted on the path) until it is within
//! the tolerance. Runs after the angles are chosen, before the G-code is written.
//!
//! The measure: at interior samples, the tip's distance from the straight segment plus the
//! cutter's reach times the angle between the machine's axis and the path's axis at that place.
//! The reach `√(R² + r²)` (tool radius R, corner radius r) is the farthest any point of the
//! cutting end lies from the tip, so the sum bounds how far any cutting point strays.

use tezgah_geom::Vec3;
use tezgah_kinematics::segment::{distance_to_segment, slerp_axis};
use tezgah_kinematics::trunnion::Trunnion;
use tezgah_kinematics::{Joints, Kinematics, Tool};

use nalgebra::Unit;

use super::links::Motion;
use super::orient::{Orienter, TableAngles};
use super::{OutputForm, PostError, PostedPoint};

/// Interior samples per segment: the deviation of a short piece is close to a parabola in its
/// parameter, largest near the middle; five catch it with margin.
const SAMPLES: usize = 5;

/// The machine's motion between output points and the joints of new ones.
pub struct MachineMotion<'a> {
    pub model: &'a Trunnion,
    pub orienter: &'a Orienter,
    pub tool: Tool,
    pub form: OutputForm,
    /// Farthest point of the cutting end from the tip, mm.
    pub reach: f64,
}

impl MachineMotion<'_> {
    /// Tip and axis (part frame) a fraction `t` of the way from `a` to `b`, as the machine moves.
    pub fn pose_at(
        &self,
        a: &PostedPoint,
        b: &PostedPoint,
        t: f64,
    ) -> Result<(Vec3, Vec3), PostError> {
        match self.form {
            OutputForm::CentrePoint => {
                let tip = a.tip + (b.tip - a.tip) * t;
                let angles = TableAngles {
                    tilt: a.angles.tilt + (b.angles.tilt - a.angles.tilt) * t,
                    c: a.angles.c + (b.angles.c - a.angles.c) * t,
                };
                Ok((tip, self.orienter.axis(angles)))
            }
            OutputForm::Joints => {
                let q = a.joints.lerp(&b.joints, t);
                let pose =
                    self.model
                        .forward(&q, &self.tool)
                        .map_err(|e| PostError::Kinematics {
                            at: b.source,
                            error: e,
                        })?;
                Ok((pose.tip, pose.axis.into_inner()))
            }
        }
    }

    /// The largest deviation of the machine's motion from `a`–`b` at the interior samples.
    pub fn deviation(&self, a: &PostedPoint, b: &PostedPoint) -> Result<f64, PostError> {
        let (ua, ub) = (Unit::new_normalize(a.axis), Unit::new_normalize(b.axis));
        let chord = b.tip - a.tip;
        let len2 = chord.norm_squared();
        let mut worst: f64 = 0.0;
        for k in 1..=SAMPLES {
            let t = k as f64 / (SAMPLES + 1) as f64;
            let (tip, axis) = self.pose_at(a, b, t)?;
            let (d, off) = distance_to_segment(&tip, &a.tip, &b.tip);
            // The path's axis where the tip is closest (the sample's own fraction when the
            // segment is a pure turn).
            let s = if len2 > 0.0 {
                ((tip - off - a.tip).dot(&chord) / len2).clamp(0.0, 1.0)
            } else {
                t
            };
            let ideal = slerp_axis(&ua, &ub, s).map_err(|e| PostError::Kinematics {
                at: b.source,
                error: e,
            })?;
            let angle = axis.angle(&ideal.into_inner());
            worst = worst.max(d + self.reach * angle);
        }
        Ok(worst)
    }

    /// The point halfway along the path from `a` to `b`, with its angles and joints.
    pub fn midpoint(&self, a: &PostedPoint, b: &PostedPoint) -> Result<PostedPoint, PostError> {
        let err = |e| PostError::Kinematics {
            at: b.source,
            error: e,
        };
        let (ua, ub) = (Unit::new_normalize(a.axis), Unit::new_normalize(b.axis));
        let axis = slerp_axis(&ua, &ub, 0.5).map_err(err)?.into_inner();
        let tip = (a.tip + b.tip) * 0.5;
        let angles = self
            .orienter
            .between(&axis, a.angles, b.angles)
            .map_err(err)?;
        let joints = self.joints(&tip, angles, &a.joints).map_err(err)?;
        Ok(PostedPoint {
            tip,
            axis,
            angles,
            joints,
            motion: b.motion,
            source: b.source,
            inserted: true,
        })
    }

    /// Machine joints (tool length included) for a part-frame tip at table angles; every
    /// joint limit checked.
    pub fn joints(
        &self,
        tip: &Vec3,
        angles: TableAngles,
        previous: &Joints,
    ) -> Result<Joints, tezgah_kinematics::KinematicsError> {
        self.model.tcp_inverse(
            tip,
            &Joints::new([angles.tilt, angles.c]),
            &self.tool,
            previous,
        )
    }

    /// `points` with points inserted wherever a segment strays more than `tolerance` from the
    /// path (rapid links excepted); returns the largest deviation left and the number
    /// inserted.
    pub fn refine(
        &self,
        points: Vec<PostedPoint>,
        tolerance: f64,
        max_halvings: u32,
    ) -> Result<(Vec<PostedPoint>, f64, usize), PostError> {
        let mut out: Vec<PostedPoint> = Vec::with_capacity(points.len());
        let mut worst: f64 = 0.0;
        let mut inserted = 0;
        let mut iter = points.into_iter();
        let Some(first) = iter.next() else {
            return Ok((out, 0.0, 0));
        };
        out.push(first);
        for next in iter {
            // Leaving the pole for a point of another C: C is free at the pole, so the table
            // turns there first, the tool standing still on the part (the turn is then halved
            // like any move; without it, every half would still hold the whole turn).
            let a = *out.last().unwrap_or(&first);
            if self.orienter.at_pole(&a.axis) && (next.angles.c - a.angles.c).abs() > 1e-12 {
                let angles = self.orienter.keeping_c(&a.axis, next.angles.c);
                let joints =
                    self.joints(&a.tip, angles, &a.joints)
                        .map_err(|e| PostError::Kinematics {
                            at: next.source,
                            error: e,
                        })?;
                let turn = PostedPoint {
                    angles,
                    joints,
                    motion: next.motion,
                    source: next.source,
                    inserted: true,
                    ..a
                };
                inserted += 1;
                self.halve_into(
                    &mut out,
                    turn,
                    tolerance,
                    max_halvings,
                    &mut worst,
                    &mut inserted,
                )?;
            }
            self.halve_into(
                &mut out,
                next,
                tolerance,
                max_halvings,
                &mut worst,
                &mut inserted,
            )?;
        }
        Ok((out, worst, inserted))
    }

    /// Appends `next` to `out`, halving the segment from `out`'s last point until every piece
    /// is within `tolerance`.
    fn halve_into(
        &self,
        out: &mut Vec<PostedPoint>,
        next: PostedPoint,
        tolerance: f64,
        max_halvings: u32,
        worst: &mut f64,
        inserted: &mut usize,
    ) -> Result<(), PostError> {
        // A rapid move (a link: retract, move on the clearance sphere, approach) stands for no
        // path on the part: the machine's own motion is what it is meant to be. Its clearance
        // is checked on that motion after posting (`check_clear`); moves at one axis are
        // straight anyway. Halving it toward great-circle axes would only add points, and
        // past 90° of tilt the great circle between two reachable axes can leave the limits.
        if next.motion == Motion::Rapid {
            out.push(next);
            return Ok(());
        }
        {
            // Depth-first halving: a stack of pending ends with their depth.
            let mut stack = vec![(next, 0u32)];
            while let Some((b, depth)) = stack.pop() {
                // `out` holds at least the path's first point (refine pushes it first).
                let Some(&a) = out.last() else {
                    out.push(b);
                    continue;
                };
                let d = self.deviation(&a, &b)?;
                if d <= tolerance {
                    *worst = worst.max(d);
                    out.push(b);
                    continue;
                }
                if depth >= max_halvings {
                    return Err(PostError::Linearisation {
                        at: b.source,
                        deviation: d,
                        tolerance,
                    });
                }
                let m = self.midpoint(&a, &b)?;
                *inserted += 1;
                stack.push((b, depth + 1));
                stack.push((m, depth + 1));
            }
        }
        Ok(())
    }
}
