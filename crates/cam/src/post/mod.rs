//! Post-processor for table-tilting five-axis machines (`table-ac`, `table-bc`): turns a
//! [`ToolPath`] into G-code that `tezgah check` accepts and `tezgah run` executes. Comes after
//! the strategies; its output feeds the verifying simulation ([`crate::verify`]) and the CLI.
//!
//! Steps, one module each: [`clearance`] (the sphere the links run on), [`links`] (stations:
//! passes plus retract / link / plunge through that sphere), [`orient`] (both inverse solutions, the branch choice along the whole
//! path, the pole, C unwrapped), the joints through the kinematics crate (limits checked),
//! [`linearise`] (points inserted where the machine's motion strays from the path), [`emit`]
//! (the G-code text, feed per minute or inverse time), [`tryout`] (the text run through
//! tezgah's own interpreter, path builder and planner: refused there, refused here; else the
//! machine's cycle time).

pub mod clearance;
pub mod emit;
pub mod linearise;
pub mod links;
pub mod orient;
pub mod steer;
pub mod tryout;

use tezgah_geom::{Axis, Vec3};
use tezgah_kinematics::{Joints, Kinematics, KinematicsError, Machine, Model, Tool};

use crate::cutter::CutterShape;
use crate::toolpath::ToolPath;
use crate::verify::CutterPose;
use clearance::Clearance;
pub use clearance::PartBox;
use linearise::MachineMotion;
use links::{Motion, Station};
use orient::{Orienter, TableAngles};

/// What the program's X Y Z A C mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputForm {
    /// Tool-centre-point control (`G43.4 H<n>`): X Y Z are the tool tip in the part frame and
    /// the rotary words the table angles; the controller moves the tip straight.
    CentrePoint,
    /// No TCP (`G43 H<n>`): X Y Z are the tip in machine coordinates (the spindle stays
    /// vertical on a table-tilting machine, so the tool length only shifts Z, which G43 does),
    /// and the controller interpolates the joints.
    Joints,
}

/// How feeds are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedOutput {
    /// G94: F in mm/min, once per change.
    PerMinute,
    /// G93: every feed block carries F = 1/(its time in minutes), the time being the tip's
    /// travel on the part at the feed (a pure turn: its degrees at the feed as deg/min).
    InverseTime,
}

/// Everything the post needs besides the path and the machine.
#[derive(Debug, Clone, PartialEq)]
pub struct PostOptions {
    pub form: OutputForm,
    pub feed_output: FeedOutput,
    /// Cutting feed: the tip's speed on the part, mm/min.
    pub feed_mm_per_min: f64,
    /// Largest linearisation deviation allowed between output points, mm.
    pub tolerance_mm: f64,
    /// Tool number for `T… M6` and `H…`.
    pub tool_number: u32,
    /// The tool's length (tool table), mm: enters the machine's Z and its limit check.
    pub tool_length_mm: f64,
    /// A box holding the whole part, if known (else the box of the path's contact points and
    /// tips is used): the links keep clear of it.
    pub part: Option<PartBox>,
    /// Clearance between the tool's widest radius and the ball holding the part on the
    /// links, and the length of the plunge at the feed into each pass, mm.
    pub clearance_mm: f64,
    /// Spindle speed for `S… M3`, if any.
    pub spindle_rpm: Option<f64>,
    /// Largest number of halvings of one segment before the post gives up.
    pub max_halvings: u32,
    /// The controller's corner blending tolerance written as `G64 P…`, mm; `None` writes a
    /// bare `G64` (the controller's own default, which the tool path's band cannot count on).
    pub blend_mm: Option<f64>,
    /// A title for the header comment.
    pub title: String,
    /// A ball end mill's axis may be re-chosen within this cone about the planned one
    /// (degrees) so that the table's C moves little and slowly ([`steer`]); `None` keeps the
    /// planned axes. Other cutters keep theirs.
    pub ball_axis_cone_deg: Option<f64>,
    /// Run the written program through tezgah's runner ([`tryout`]): a program it refuses is
    /// an error, and the machine's cycle time comes with the stats. Off only where a caller
    /// needs the bare post (it costs one planning and interpolation of the program).
    pub tryout: bool,
}

impl PostOptions {
    /// Defaults for the rest: TCP output, feed per minute, tool 1 of length 0, 5 mm clearance.
    pub fn new(feed_mm_per_min: f64, tolerance_mm: f64) -> Self {
        Self {
            form: OutputForm::CentrePoint,
            feed_output: FeedOutput::PerMinute,
            feed_mm_per_min,
            tolerance_mm,
            tool_number: 1,
            tool_length_mm: 0.0,
            part: None,
            clearance_mm: 5.0,
            spindle_rpm: None,
            max_halvings: 24,
            blend_mm: None,
            title: String::new(),
            ball_axis_cone_deg: None,
            tryout: true,
        }
    }
}

/// Why a path could not be posted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PostError {
    #[error("the post-processor handles table-ac and table-bc machines, not {0}")]
    Machine(&'static str),
    #[error("{what} must be a finite number > 0, got {value}")]
    Option { what: &'static str, value: f64 },
    #[error("pass {pass} point {point}: tip or tool axis not finite, or the axis is zero")]
    BadLocation { pass: usize, point: usize },
    #[error("{}: the table turns where the tool is not clear of the part's bounding ball", place(*at))]
    Unclear { at: Option<(usize, usize)> },
    #[error("{}: {error}", place(*at))]
    Kinematics {
        at: Option<(usize, usize)>,
        error: KinematicsError,
    },
    #[error("{}: the machine's motion strays {deviation:.4} mm from the path after every halving (tolerance {tolerance} mm)", place(*at))]
    Linearisation {
        at: Option<(usize, usize)>,
        deviation: f64,
        tolerance: f64,
    },
    #[error("the tool path has no cutter locations")]
    Empty,
    #[error("tezgah's runner refuses the written program at {0}")]
    Refused(#[from] tryout::Refused),
}

fn place(at: Option<(usize, usize)>) -> String {
    match at {
        Some((p, i)) => format!("pass {p} point {i}"),
        None => "a link move".to_owned(),
    }
}

/// One output point: where the tool is, the angles chosen and the machine joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostedPoint {
    /// Tip, part frame, mm.
    pub tip: Vec3,
    /// Requested unit tool axis, part frame.
    pub axis: Vec3,
    pub angles: TableAngles,
    /// Machine joints (gauge point with the tool length, mm; tilt and C, rad).
    pub joints: Joints,
    /// How the tool gets here.
    pub motion: Motion,
    /// The (pass, point) of the tool path, or the one after an inserted point; `None` on links.
    pub source: Option<(usize, usize)>,
    /// Inserted by the linearisation check.
    pub inserted: bool,
}

/// Figures of a posted program.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PostStats {
    /// Tip travel on the part while cutting, mm.
    pub cutting_length_mm: f64,
    /// Tip travel on the part while plunging, mm.
    pub plunge_length_mm: f64,
    /// Tip travel on the part in rapid links, mm.
    pub rapid_length_mm: f64,
    /// (cutting + plunge length) / feed, s.
    pub feed_time_s: f64,
    /// Output points (motion blocks).
    pub points: usize,
    /// Points the linearisation check inserted.
    pub inserted: usize,
    /// Largest deviation of the machine's motion from the path left after insertion, mm.
    pub max_linearisation_mm: f64,
    /// The sphere the links run on (part frame).
    pub clearance: Option<Clearance>,
    /// Largest angle between a steered ball's axis and the planned one, degrees.
    pub max_axis_change_deg: f64,
    /// The machine's time for the program through tezgah's own planning, s (`None` without
    /// [`PostOptions::tryout`]).
    pub cycle_time_s: Option<f64>,
}

/// A posted program: its points, text and figures.
#[derive(Debug, Clone)]
pub struct Posted {
    pub points: Vec<PostedPoint>,
    pub program: String,
    pub stats: PostStats,
    /// The program's letters for the tilt and C (A C or B C).
    pub rotary_letters: [char; 2],
    /// How the program was written, with the tool it was posted for (for [`Posted::sweep`]).
    pub form: OutputForm,
    pub tool: Tool,
    /// The cutter's reach from its tip, mm ([`reach`]).
    pub reach: f64,
}

/// The cutter's reach from its tip: `√(R² + r²)`, the farthest point of the cutting end.
pub fn reach(path: &ToolPath) -> f64 {
    let s = path.cutter.shape;
    s.radius().hypot(s.corner_radius())
}

fn positive(what: &'static str, value: f64) -> Result<f64, PostError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PostError::Option { what, value })
    }
}

/// Posts `path` for `machine` (table-ac or table-bc). A steered ball's axes
/// ([`PostOptions::ball_axis_cone_deg`]) are not checked against the part: see [`post_with`].
pub fn post(
    path: &ToolPath,
    machine: &Machine,
    options: &PostOptions,
) -> Result<Posted, PostError> {
    post_with(path, machine, options, &|_, _| true)
}

/// [`post`], with `clear(tip, axis)` saying whether the cutter standing there is clear of the
/// part (the strategy's gouge checks): a pass whose steered ball would not be keeps its
/// planned axes ([`steer::steer`]).
pub fn post_with(
    path: &ToolPath,
    machine: &Machine,
    options: &PostOptions,
    clear: &(dyn Fn(&Vec3, &Vec3) -> bool + Sync),
) -> Result<Posted, PostError> {
    let feed = positive("the feed", options.feed_mm_per_min)?;
    let tolerance = positive("the tolerance", options.tolerance_mm)?;
    if let Some(p) = options.blend_mm {
        positive("the blending tolerance", p)?;
    }
    if !(options.clearance_mm.is_finite() && options.clearance_mm >= 0.0) {
        return Err(PostError::Option {
            what: "the clearance",
            value: options.clearance_mm,
        });
    }
    if !(options.tool_length_mm.is_finite()) {
        return Err(PostError::Option {
            what: "the tool length",
            value: options.tool_length_mm,
        });
    }
    let model = match &machine.kinematics {
        Model::TableAc(t) | Model::TableBc(t) => t,
        other => return Err(PostError::Machine(other.type_name())),
    };
    let letters = match machine.tcp_axes().ok().as_deref() {
        Some([Axis::B, Axis::C]) => ['B', 'C'],
        _ => ['A', 'C'],
    };
    // Validate and normalise the path's locations.
    let mut path = path.clone();
    for (p, pass) in path.passes.iter_mut().enumerate() {
        for (i, cl) in pass.points.iter_mut().enumerate() {
            let n = cl.axis.norm();
            if !(cl.tip.iter().all(|x| x.is_finite()) && n.is_finite() && n > 1e-12) {
                return Err(PostError::BadLocation { pass: p, point: i });
            }
            cl.axis /= n;
        }
    }
    if path.contact_count() == 0 {
        return Err(PostError::Empty);
    }
    let reach = reach(&path);
    let limits = model.joint_limits();
    let orienter = Orienter {
        tilt_axis: model.tilt_axis(),
        tilt_limit: limits[3].clone(),
        c_limit: limits[4].clone(),
        // C is held inside the cone whose axis error costs at most half the tolerance at
        // the cutter's reach.
        pole_sin: (0.5 * tolerance / reach).min(1.0),
    };
    let mut steered = None;
    if let (Some(cone), CutterShape::Ball { radius }) =
        (options.ball_axis_cone_deg, path.cutter.shape)
    {
        let cone = positive("the axis cone", cone)?.min(90.0).to_radians();
        let s = steer::steer(
            &mut path,
            &orienter,
            cone,
            radius,
            steer::max_step(radius, tolerance),
            clear,
        );
        steered = Some(s);
    }
    let tool = Tool::with_length(options.tool_length_mm);
    let motion = MachineMotion {
        model,
        orienter: &orienter,
        tool,
        form: options.form,
        reach,
    };

    let sphere = Clearance::around(&path, options.part.as_ref(), options.clearance_mm)
        .map_err(|_| PostError::Empty)?;
    let stations = links::stations(&path, &sphere, options.clearance_mm);
    let axes: Vec<Vec3> = stations.iter().map(|s| s.axis).collect();
    let home = TableAngles { tilt: 0.0, c: 0.0 };
    let angles = orienter
        .choose(&axes, home)
        .map_err(|e| PostError::Kinematics {
            at: stations[e.index].place,
            error: e.error,
        })?;
    let mut points = Vec::with_capacity(stations.len());
    let mut previous = machine.home();
    for (s, a) in stations.iter().zip(&angles) {
        let joints = motion
            .joints(&s.tip, *a, &previous)
            .map_err(|e| PostError::Kinematics {
                at: s.place,
                error: e,
            })?;
        previous = joints;
        points.push(point(s, *a, joints));
    }
    let (points, worst, inserted) = motion.refine(points, tolerance, options.max_halvings)?;
    let (points, at_pole) = through_the_pole(points, &motion, tolerance)?;
    let (points, turns) = pole_turns(points, &motion)?;
    let inserted = inserted + at_pole + turns;
    check_clear(&points, &motion, &sphere)?;

    let mut stats = PostStats {
        max_axis_change_deg: steered.map_or(0.0, |s| s.max_change.to_degrees()),
        points: points.len(),
        inserted,
        max_linearisation_mm: worst,
        clearance: Some(sphere),
        ..PostStats::default()
    };
    for w in points.windows(2) {
        let d = (w[1].tip - w[0].tip).norm();
        match w[1].motion {
            Motion::Cut => stats.cutting_length_mm += d,
            Motion::Plunge => stats.plunge_length_mm += d,
            Motion::Rapid => stats.rapid_length_mm += d,
        }
    }
    stats.feed_time_s = 60.0 * (stats.cutting_length_mm + stats.plunge_length_mm) / feed;
    let program = emit::program(&points, &motion, options, letters, &sphere)?;
    if options.tryout {
        let run = tryout::tryout(
            &program,
            machine,
            options.tool_number,
            options.tool_length_mm,
        )?;
        stats.cycle_time_s = Some(run.cycle_time_s);
    }
    Ok(Posted {
        points,
        program,
        stats,
        rotary_letters: letters,
        form: options.form,
        tool,
        reach,
    })
}

/// Where the tilt changes sign between two neighbouring points (the axis passes by or through
/// the pole between them), a point exactly at the pole is put between them, with the C of the
/// first. A hair of C difference (0.0002° seen, and 1.3° at a tilt of 0.08°) sends the
/// machine's axis by the pole at a hair's distance, where its azimuth — and C following it —
/// swings half a turn in no distance; with C exactly held the axis's great circle passes
/// through the pole to rounding, and a sample landing 1e-10 rad from it takes its azimuth
/// from the rounding. The runner refuses either move as passing through a singular pose
/// (`joint 0 jumps by 84.89` in issue 23). At the pole point the runner holds C exactly. Through the pole point the axis passes the pole itself:
/// up to it C is held (one meridian plane), there the table turns to the next C with the tool
/// standing (the axis on the C axis does not move), and from it C is held again. The points
/// are placed only where the axis there strays from the path's by at most `tolerance` at the
/// cutter's reach.
fn through_the_pole(
    points: Vec<PostedPoint>,
    motion: &MachineMotion<'_>,
    tolerance: f64,
) -> Result<(Vec<PostedPoint>, usize), PostError> {
    let mut out: Vec<PostedPoint> = Vec::with_capacity(points.len());
    let mut added = 0;
    for b in points {
        if let Some(a) = out.last().copied() {
            let (ta, tb) = (a.angles.tilt, b.angles.tilt);
            if ta * tb < 0.0 {
                let f = ta.abs() / (ta.abs() + tb.abs());
                let (ua, ub) = (
                    nalgebra::Unit::new_normalize(a.axis),
                    nalgebra::Unit::new_normalize(b.axis),
                );
                let near = tezgah_kinematics::segment::slerp_axis(&ua, &ub, f)
                    .is_ok_and(|k| k.angle(&Vec3::z_axis()) * motion.reach <= tolerance);
                if near {
                    let tip = a.tip + (b.tip - a.tip) * f;
                    let mut previous = a.joints;
                    let turns: &[f64] = if a.angles.c == b.angles.c {
                        &[a.angles.c]
                    } else {
                        &[a.angles.c, b.angles.c]
                    };
                    for &c in turns {
                        let angles = TableAngles { tilt: 0.0, c };
                        let joints = motion.joints(&tip, angles, &previous).map_err(|e| {
                            PostError::Kinematics {
                                at: b.source,
                                error: e,
                            }
                        })?;
                        previous = joints;
                        out.push(PostedPoint {
                            tip,
                            axis: Vec3::z(),
                            angles,
                            joints,
                            motion: b.motion,
                            source: b.source,
                            inserted: true,
                        });
                        added += 1;
                    }
                }
            }
        }
        out.push(b);
    }
    Ok((out, added))
}

/// Link stations on the clearance sphere whose axis leans less than this (rad, 1°) from the
/// C axis are moved onto it: there the tool is clear of the part whatever its axis (the moves
/// are checked again by [`check_clear`]), and an axis a hair from the pole is where C would
/// swing.
const LINK_POLE: f64 = std::f64::consts::PI / 180.0;

/// The moves that touch the pole made as the runner takes them without a jump: a link
/// station within [`LINK_POLE`] of the pole is put on it; a point on the pole takes the C of
/// the point before (at the pole C does not move the axis, so the move arrives along one
/// meridian plane); and before leaving the pole toward another C the table turns there with
/// the tool standing. Arriving or leaving toward another C, the axis's great circle leaves the
/// pole at an azimuth other than the programmed C, and the runner's walk along it jumps.
fn pole_turns(
    points: Vec<PostedPoint>,
    motion: &MachineMotion<'_>,
) -> Result<(Vec<PostedPoint>, usize), PostError> {
    let at = |p: &PostedPoint, angles: TableAngles, previous: &Joints| {
        motion
            .joints(&p.tip, angles, previous)
            .map_err(|e| PostError::Kinematics {
                at: p.source,
                error: e,
            })
    };
    let n = points.len();
    let mut out: Vec<PostedPoint> = Vec::with_capacity(n);
    let mut added = 0;
    for i in 0..n {
        let mut b = points[i];
        let Some(a) = out.last().copied() else {
            out.push(b);
            continue;
        };
        let station = i + 1 < n
            && a.motion == Motion::Rapid
            && b.motion == Motion::Rapid
            && points[i + 1].motion == Motion::Rapid
            && b.axis.angle(&points[i + 1].axis) > STILL_AXIS
            && b.axis.angle(&a.axis) > STILL_AXIS;
        if station && b.angles.tilt != 0.0 && b.angles.tilt.abs() <= LINK_POLE {
            b.angles.tilt = 0.0;
            b.axis = Vec3::z();
        }
        if b.angles.tilt == 0.0 && b.angles.c != a.angles.c {
            b.angles.c = a.angles.c;
        }
        if a.angles.tilt == 0.0 && b.angles.tilt != 0.0 && b.angles.c != a.angles.c {
            let angles = TableAngles {
                tilt: 0.0,
                c: b.angles.c,
            };
            let turn = PostedPoint {
                angles,
                joints: at(&a, angles, &a.joints)?,
                motion: b.motion,
                source: b.source,
                inserted: true,
                ..a
            };
            out.push(turn);
            added += 1;
        }
        let previous = out.last().map_or(b.joints, |p| p.joints);
        b.joints = at(&b, b.angles, &previous)?;
        out.push(b);
    }
    Ok((out, added))
}

/// Requested axes closer than this (rad) count as one: the limit normals at a pole differ
/// by ~10⁻⁸ with the side they are taken from.
const STILL_AXIS: f64 = 1e-6;

/// Samples per link move checked for clearance while the table turns.
const CLEAR_SAMPLES: usize = 8;

/// Every move that turns the tool, off the cutting (a link), keeps the whole tool outside
/// the part's ball at every sample as the machine moves it. Moves between two stations of
/// the same axis (retract, approach, C turned at the pole; [`STILL_AXIS`]) do not turn the
/// tool: the table may move there only within the linearisation tolerance, checked already.
fn check_clear(
    points: &[PostedPoint],
    motion: &MachineMotion<'_>,
    sphere: &Clearance,
) -> Result<(), PostError> {
    for w in points.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let turn = (b.angles.tilt - a.angles.tilt).abs() + (b.angles.c - a.angles.c).abs();
        if b.motion != Motion::Rapid || turn <= 1e-12 || a.axis.angle(&b.axis) <= STILL_AXIS {
            continue;
        }
        for k in 0..=CLEAR_SAMPLES {
            let (tip, axis) = motion.pose_at(a, b, k as f64 / CLEAR_SAMPLES as f64)?;
            if !sphere.is_clear(&tip, &axis) {
                return Err(PostError::Unclear { at: b.source });
            }
        }
    }
    Ok(())
}

fn point(s: &Station, angles: TableAngles, joints: Joints) -> PostedPoint {
    PostedPoint {
        tip: s.tip,
        axis: s.axis,
        angles,
        joints,
        motion: s.motion,
        source: s.source,
        inserted: false,
    }
}

impl Posted {
    /// The cutter's poses along the program as the machine moves it, no point of the cutting
    /// end moving more than `spacing` between consecutive poses: what the verifying
    /// simulation sweeps. `machine` is the one the program was posted for.
    pub fn sweep(&self, machine: &Machine, spacing: f64) -> Result<Vec<CutterPose>, PostError> {
        let spacing = positive("the sweep spacing", spacing)?;
        let model = match &machine.kinematics {
            Model::TableAc(t) | Model::TableBc(t) => t,
            other => return Err(PostError::Machine(other.type_name())),
        };
        let limits = model.joint_limits();
        let orienter = Orienter {
            tilt_axis: model.tilt_axis(),
            tilt_limit: limits[3].clone(),
            c_limit: limits[4].clone(),
            pole_sin: 0.0,
        };
        let reach = self.reach;
        let motion = MachineMotion {
            model,
            orienter: &orienter,
            tool: self.tool,
            form: self.form,
            reach,
        };
        let mut out = Vec::new();
        if let Some(p) = self.points.first() {
            out.push(CutterPose {
                tip: p.tip,
                axis: orienter.axis(p.angles),
            });
        }
        for w in self.points.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            // The axis turns at most |Δtilt| + |ΔC| (rad) on the way, whatever the form.
            let turn = (b.angles.tilt - a.angles.tilt).abs() + (b.angles.c - a.angles.c).abs();
            let span = (b.tip - a.tip).norm() + reach * turn;
            let n = ((span / spacing).ceil() as usize).clamp(1, 1_000_000);
            for k in 1..=n {
                let (tip, axis) = motion.pose_at(a, b, k as f64 / n as f64)?;
                out.push(CutterPose { tip, axis });
            }
        }
        Ok(out)
    }
}
