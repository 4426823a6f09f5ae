//! `tezgah cam`: surface → tool path (STEP import and strategies, `plan_surface`) → post for a
//! table-tilting machine → verifying dexel simulation → the program file and the report JSON.
//! A thin shell: every stage is a `tezgah-cam` library call.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use miette::{miette, IntoDiagnostic, Result, WrapErr};
use tezgah_cam::post::{post_with, FeedOutput, OutputForm, PartBox, PostOptions, Posted};
use tezgah_cam::region::FaceRegion;
use tezgah_cam::step::Face;
use tezgah_cam::strategy::{FeedDirection, Refusal};
use tezgah_cam::verify::{self, MachinedRegion, Verification, VerifyOptions, MAX_DEXELS};
use tezgah_cam::{
    Band, CheckFace, Cutter, CutterShape, Settings, StrategyKind, ToleranceShares, ToolAxis,
    ToolPath,
};
use tezgah_geom::{NurbsSurface, Vec3};
use tezgah_kinematics::{Kinematics, Machine};

use crate::cam_tool::{self, ToolSpec};

/// The command line of `tezgah cam` (README.md and docs/cam.md describe it).
#[derive(clap::Args)]
pub struct CamArgs {
    /// The surface (STEP file).
    pub surface: PathBuf,
    /// The cutter: ball:D, flat:D or bull:D:r (diameter D, corner radius r, mm), or auto: the
    /// largest ball end mill that fits the face's tightest concave curvature, from the tool
    /// table's ball end mills (--tool-table) or else the standard set.
    #[arg(long)]
    pub tool: String,
    /// zigzag, zigzag-oneway or iso-scallop.
    #[arg(long)]
    pub strategy: String,
    /// Largest scallop height, mm.
    #[arg(long)]
    pub scallop: f64,
    /// How far the machine's motion may run outside the exact cutter-location surface, mm
    /// (shared by chords, linearisation and blending; taken from the scallop budget).
    #[arg(long)]
    pub tolerance: f64,
    /// Lead angle: the tool tilted from the normal toward the feed, degrees. Default: 10° for
    /// a ball end mill (along the normal a ball cuts with its centre, where the cutting speed
    /// is zero: it rubs rather than cuts, and the finish suffers; at 10° the contact turns at
    /// R·sin 10° = 0.17 R from the axis), 0° for flat and bull-nose ends.
    #[arg(long = "lead", allow_hyphen_values = true)]
    pub lead_deg: Option<f64>,
    /// How far a ball end mill's axis may turn from the planned one (lead and tilt about
    /// the normal), degrees, so that the table turns little and slowly where the surface
    /// faces up (the pole, where C would otherwise spin): the ball's centre, and so the cut,
    /// stays. 0 keeps the planned axis.
    #[arg(long = "axis-cone", default_value_t = AXIS_CONE_DEG)]
    pub axis_cone_deg: f64,
    /// Tilt angle: the tool tilted from the normal across the feed, degrees.
    #[arg(long = "tilt", default_value_t = 0.0, allow_hyphen_values = true)]
    pub tilt_deg: f64,
    /// Cutting feed, mm/min (the tip's speed on the part).
    #[arg(long, default_value_t = 1000.0)]
    pub feed: f64,
    /// Write feeds in inverse time (G93): every block's F is 1/(its minutes at the feed on
    /// the part). The default with --joints, where a G94 feed would apply to the machine's
    /// X Y Z instead of the tip on the part.
    #[arg(long)]
    pub inverse_time: bool,
    /// Write feeds per minute (G94) even with --joints.
    #[arg(long, conflicts_with = "inverse_time")]
    pub feed_per_minute: bool,
    /// Write machine joints (G43, no tool-centre-point control) instead of G43.4 output.
    #[arg(long)]
    pub joints: bool,
    /// A table-tilting machine: built-in name or file (default table-ac).
    #[arg(long)]
    pub machine: Option<String>,
    /// The program to write.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Write the report JSON here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// A tool table in LinuxCNC's format (the tool's length).
    #[arg(long)]
    pub tool_table: Option<PathBuf>,
    /// The tool number for T and H words (default: the tool `--tool auto` chose from the
    /// table, else 1).
    #[arg(long)]
    pub tool_number: Option<u32>,
    /// How far the tool may reach into the file's other faces, mm (default: --tolerance).
    /// Faces that meet at a crease leave material the tool cannot reach without cutting into
    /// the face beside; this is how deep it may.
    #[arg(long = "check-tolerance", value_name = "MM")]
    pub check_tolerance: Option<f64>,
    /// The STEP `#id` of the face to machine (needed when the file has several faces).
    #[arg(long)]
    pub face: Option<u64>,
    /// The most the tool axis may lean from the part's +Z, degrees: contact points facing
    /// further away are left out (default: as far as the machine's tilt axis reaches).
    #[arg(long = "max-tilt")]
    pub max_tilt_deg: Option<f64>,
    /// The surface parameter the passes run along: u or v (the other is stepped over), or
    /// auto: v unless a v boundary is a single point (a sphere's pole), then u.
    #[arg(long = "feed-along", default_value = "auto")]
    pub feed_along: String,
    /// Dexel spacing of the verifying simulation, mm (default: a twentieth of the
    /// step-over; coarser is faster and widens the reported grid bound).
    #[arg(long = "verify-cell")]
    pub verify_cell_mm: Option<f64>,
}

/// The most `--max-tilt` can say: the tool axis straight down. By default the machine's tilt
/// range decides (table-ac: 120°, past a vertical face into undercuts): the links retract
/// along the tool axis to a clearance sphere and turn the table only there, which is safe
/// for any tilt.
pub const MAX_TILT_DEG: f64 = 180.0;

/// The default lead of a ball end mill, degrees (`--lead`): off the normal the contact leaves
/// the ball's centre, where the cutting speed is zero.
pub const BALL_LEAD_DEG: f64 = 10.0;

/// The default `--axis-cone`, degrees: off. Steered at the default lead, the wavy patch's
/// program measured 0.0053 mm of gouge at its edge (h 0.1) and was posted again unsteered;
/// at lead 0 a 10° cone takes the table's spinning away (docs/cam.md).
pub const AXIS_CONE_DEG: f64 = 0.0;

/// The lead: the one given, else [`BALL_LEAD_DEG`] for a ball end mill (`--tool auto` picks
/// one) and 0 for flat and bull-nose ends.
fn lead(spec: &ToolSpec, given: Option<f64>) -> f64 {
    given.unwrap_or(match spec {
        ToolSpec::Given(CutterShape::Ball { .. }) | ToolSpec::Auto => BALL_LEAD_DEG,
        ToolSpec::Given(_) => 0.0,
    })
}

/// Whether feeds are written in inverse time: asked for, or by default without
/// tool-centre-point control (`--joints`), where the controller would apply a G94 feed to the
/// machine's X Y Z.
fn inverse_time(args: &CamArgs) -> bool {
    args.inverse_time || (args.joints && !args.feed_per_minute)
}

/// What the strategy is asked for.
pub struct PlanRequest {
    pub strategy: StrategyKind,
    pub scallop_mm: f64,
    /// The strategy's chord tolerance, mm.
    pub tolerance_mm: f64,
    /// How far the tool may reach into the part's other faces, mm (`--tolerance`).
    pub neighbour_tolerance_mm: f64,
    /// The one-sided band (`None`: chords straddle the exact CL surface).
    pub band: Option<Band>,
    pub lead_deg: f64,
    pub tilt_deg: f64,
    /// The most the tool axis may lean from +Z, degrees.
    pub max_tilt_deg: f64,
    /// The parameter the passes run along (`None`: chosen for the surface).
    pub direction: Option<FeedDirection>,
}

/// The face of a STEP file to machine: the one `--face` names, or the file's only face.
fn pick_face(path: &Path, model: &tezgah_cam::step::StepModel, id: Option<u64>) -> Result<Face> {
    let ids = || {
        model
            .faces
            .iter()
            .map(|f| format!("#{}", f.id))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let face = match id {
        Some(id) => model
            .faces
            .iter()
            .find(|f| f.id == id)
            .cloned()
            .ok_or_else(|| miette!("{}: no face #{id}; its faces are {}", path.display(), ids()))?,
        None => match model.faces.as_slice() {
            [one] => one.clone(),
            [] => return Err(miette!("{}: the file has no face", path.display())),
            _ => {
                return Err(miette!(
                    "{}: the file has {} faces ({}); choose one with --face ID",
                    path.display(),
                    model.faces.len(),
                    ids()
                ))
            }
        },
    };
    Ok(face)
}

/// Samples per parameter for the face area in the report (a 0.3 % figure on the plate
/// fixture: its trim's length times a cell's diagonal).
const AREA_SAMPLES: usize = 400;

/// Samples per parameter of each face for the part's box.
const BOX_SAMPLES: usize = 64;

/// A box holding every face of the model: each surface sampled on a 65 × 65 grid, grown by
/// 1 mm for what falls between samples (the links add their clearance on top).
fn part_box(model: &tezgah_cam::step::StepModel) -> Option<PartBox> {
    let mut points = Vec::new();
    for face in &model.faces {
        let s = &face.surface;
        let (du, dv) = (s.domain_u(), s.domain_v());
        for i in 0..=BOX_SAMPLES {
            for j in 0..=BOX_SAMPLES {
                let u = du.0 + (du.1 - du.0) * i as f64 / BOX_SAMPLES as f64;
                let v = dv.0 + (dv.1 - dv.0) * j as f64 / BOX_SAMPLES as f64;
                points.push(s.point(u, v));
            }
        }
    }
    PartBox::of_points(&points).map(|b| b.grown(1.0))
}

/// What the strategy planned on a face of a STEP file.
struct Planned {
    surface: NurbsSurface,
    path: ToolPath,
    /// A box around every face of the file: the part the links keep clear of.
    part: Option<PartBox>,
    /// The parameter the passes run along.
    direction: FeedDirection,
    /// A trimmed face's region in (u, v) (`None`: the whole surface).
    region: Option<FaceRegion>,
    /// How far the normal may lean from +Z where the path machines the face: the tilt limit
    /// less the cutter's nominal lean (`Settings::reach_normal_tilt_deg`).
    reach_normal_tilt_deg: f64,
    /// The part's other faces.
    neighbours: Vec<NeighbourFace>,
    /// The face's outside is the side `S_u × S_v` points to.
    outward_is_su_x_sv: bool,
}

/// The face of a STEP file to machine and its trim, the part's other faces (kept out of the
/// cutter's way) and a box around every face (the part the links keep clear of).
struct PartFaces {
    face: Face,
    region: Option<FaceRegion>,
    neighbours: Vec<NeighbourFace>,
    part: Option<PartBox>,
}

/// The face of the STEP file at `path` to machine (`--face`, or its only face), its other
/// faces and the part's box; every trim followed to `trim_mm`, once for all that use it.
fn read_face(path: &Path, id: Option<u64>, trim_mm: f64) -> Result<PartFaces> {
    let model = tezgah_cam::step::read_file(path).into_diagnostic()?;
    let part = part_box(&model);
    let face = pick_face(path, &model, id)?;
    // A trimmed face is machined within its loops.
    let region = face
        .uv_region(trim_mm)
        .map_err(|e| miette!("{}: {e}", path.display()))?;
    let others = model
        .faces
        .into_iter()
        .filter(|f| f.id != face.id)
        .collect();
    Ok(PartFaces {
        face,
        region,
        neighbours: neighbours(path, others, trim_mm),
        part,
    })
}

/// Another face of the part: its `#id`, which side is its outside, and its surface within its
/// trim as the gouge checks and the verification see it.
#[derive(Debug, Clone)]
pub struct NeighbourFace {
    pub id: u64,
    pub outward_is_su_x_sv: bool,
    pub check: CheckFace,
}

/// The part's other faces as the gouge checks see them: each surface within its trim. A face
/// whose trim cannot be followed is checked whole (more than the face: it can only refuse
/// more), with a note.
fn neighbours(path: &Path, others: Vec<Face>, trim_mm: f64) -> Vec<NeighbourFace> {
    others
        .into_iter()
        .map(|f| {
            let region = f.uv_region(trim_mm).unwrap_or_else(|e| {
                eprintln!(
                    "note: {}: face #{}'s trim cannot be followed ({e}); the gouge checks keep \
                     the tool off its whole surface",
                    path.display(),
                    f.id
                );
                None
            });
            NeighbourFace {
                id: f.id,
                outward_is_su_x_sv: f.same_sense,
                check: CheckFace {
                    surface: f.surface,
                    region,
                },
            }
        })
        .collect()
}

/// The face's surface and the tool path the strategy plans on it. Gouging contact points the
/// strategy could not correct are left out of the path and listed here.
fn plan_surface(
    path: &Path,
    PartFaces {
        face,
        region,
        neighbours,
        part,
    }: PartFaces,
    cutter: Cutter,
    request: &PlanRequest,
) -> Result<Planned> {
    let mut settings = Settings::new(request.strategy, request.scallop_mm, request.tolerance_mm);
    if let ToolAxis::Surface {
        lead_deg, tilt_deg, ..
    } = &mut settings.axis
    {
        (*lead_deg, *tilt_deg) = (request.lead_deg, request.tilt_deg);
    }
    // Cut the face's outside: the side its orientation says the material is not.
    settings.reverse_normal = !face.same_sense;
    settings.max_axis_tilt_deg = Some(request.max_tilt_deg);
    settings.direction = request
        .direction
        .unwrap_or_else(|| FeedDirection::for_surface(&face.surface));
    settings.band = request.band;
    settings.region = region;
    // The other faces go to the planner and come back with the plan (no copy of their
    // surfaces).
    let (known, checks): (Vec<_>, Vec<_>) = neighbours
        .into_iter()
        .map(|n| ((n.id, n.outward_is_su_x_sv), n.check))
        .unzip();
    settings.neighbours = checks;
    if !settings.neighbours.is_empty() {
        eprintln!(
            "note: the tool is kept out of the part's {} other faces too",
            settings.neighbours.len()
        );
    }
    if request.band.is_some() {
        // The rear check accepts penetrations up to its depth tolerance: keep that within
        // issue 7's 1 µm.
        settings.gouge.depth_tolerance = 0.5 * GOUGE_LIMIT_MM;
    }
    // The other faces are kept clear to within the check tolerance: where one meets the face
    // at a concave crease, cutting the face to its edge reaches into it (0.073 mm into the
    // lofted blade's #876 from #17 with a D6 ball).
    settings.gouge.neighbour_depth_tolerance = request.neighbour_tolerance_mm;
    let plan = tezgah_cam::plan(&face.surface, &cutter, &settings).into_diagnostic()?;
    let gouges = plan.refused.iter().filter(|r| r.refusal.is_gouge()).count();
    let count = |what: Refusal| plan.refused.iter().filter(|r| r.refusal == what).count();
    let out_of_reach = count(Refusal::OutOfReach);
    let outside = count(Refusal::OutsideFace);
    let no_normal = plan.refused.len() - gouges - out_of_reach - outside;
    if gouges > 0 {
        eprintln!(
            "warning: {gouges} contact points would gouge and were left out (passes split \
             there); {} were corrected",
            plan.corrected
        );
    }
    if out_of_reach > 0 {
        eprintln!(
            "note: {out_of_reach} contact points face more than {}° away from +Z, beyond what \
             the machine reaches from above (--max-tilt), and were left out",
            request.max_tilt_deg
        );
    }
    if let Some(region) = &settings.region {
        eprintln!(
            "note: face #{} is trimmed: machined within its {} loops, {outside} contact points \
             beyond them left out and the passes ended on the trim",
            face.id,
            region.loops().len()
        );
    }
    if no_normal > 0 {
        eprintln!(
            "note: {no_normal} contact points lie where the surface has no normal (a \
             degenerate edge or pole) and were left out"
        );
    }
    if plan.path.contact_count() == 0 {
        return Err(miette!(
            "{}: no contact point is left to machine ({} refused)",
            path.display(),
            plan.refused.len()
        ));
    }
    Ok(Planned {
        surface: face.surface,
        path: plan.path,
        part,
        direction: settings.direction,
        reach_normal_tilt_deg: settings
            .reach_normal_tilt_deg(&cutter.shape)
            .unwrap_or(request.max_tilt_deg),
        region: settings.region,
        neighbours: known
            .into_iter()
            .zip(settings.neighbours)
            .map(|((id, outward_is_su_x_sv), check)| NeighbourFace {
                id,
                outward_is_su_x_sv,
                check,
            })
            .collect(),
        outward_is_su_x_sv: face.same_sense,
    })
}

fn positive(name: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(miette!("{name} must be a finite number > 0, got {v}"))
    }
}

/// The tool length of `number` in the tool table (0 without a table).
fn tool_length(table: Option<&Path>, number: u32) -> Result<f64> {
    let Some(path) = table else { return Ok(0.0) };
    let table = crate::library::load_tool_table(Some(path))?;
    table
        .get(i64::from(number))
        .map(|t| t.offset.z())
        .ok_or_else(|| miette!("tool {number} is not in {}", path.display()))
}

pub fn cam(args: CamArgs) -> Result<ExitCode> {
    // Everything the command line can get wrong is refused before any work.
    let spec = ToolSpec::parse(&args.tool)?;
    let scallop = positive("--scallop", args.scallop)?;
    let tolerance = positive("--tolerance", args.tolerance)?;
    if tolerance >= scallop {
        return Err(miette!(
            "--tolerance {tolerance} must be below --scallop {scallop}: the motion may run up to \
             the tolerance outside the exact path, which raises the scallop by as much, so the \
             side steps are planned for the scallop minus the tolerance"
        ));
    }
    let feed = positive("--feed", args.feed)?;
    if !(args.axis_cone_deg.is_finite() && (0.0..90.0).contains(&args.axis_cone_deg)) {
        return Err(miette!(
            "--axis-cone must be an angle in [0°, 90°), got {}",
            args.axis_cone_deg
        ));
    }
    let lead_deg = lead(&spec, args.lead_deg);
    for (name, v) in [("--lead", lead_deg), ("--tilt", args.tilt_deg)] {
        if !(v.is_finite() && v.abs() < 90.0) {
            return Err(miette!("{name} must be an angle in (−90°, 90°), got {v}"));
        }
    }
    let strategy: StrategyKind = args
        .strategy
        .parse()
        .map_err(|e| miette!("--strategy {}: {e}", args.strategy))?;
    let direction = match args.feed_along.as_str() {
        "v" => Some(FeedDirection::AlongV),
        "u" => Some(FeedDirection::AlongU),
        "auto" => None,
        other => return Err(miette!("--feed-along must be u, v or auto, got {other}")),
    };
    let machine = crate::run::load_machine(Some(args.machine.as_deref().unwrap_or("table-ac")))?;
    if !matches!(
        machine.kinematics,
        tezgah_kinematics::Model::TableAc(_) | tezgah_kinematics::Model::TableBc(_)
    ) {
        return Err(miette!(
            "--machine {}: the post-processor handles table-ac and table-bc machines, not {}",
            machine.name,
            machine.kinematics.type_name()
        ));
    }
    // The machine's tilt reaches either sign (the two inverse solutions), so its range is
    // the larger limit's size.
    let reach_deg = machine
        .kinematics
        .joint_limits()
        .get(3)
        .map(|l| l.min.abs().max(l.max.abs()).to_degrees())
        .unwrap_or(MAX_TILT_DEG);
    let max_tilt_deg = match args.max_tilt_deg {
        Some(t) if t.is_finite() && t > 0.0 && t <= MAX_TILT_DEG => t,
        Some(t) => {
            return Err(miette!(
                "--max-tilt must be an angle in (0°, 180°], got {t}"
            ))
        }
        None => MAX_TILT_DEG.min(reach_deg),
    };
    if let Some(c) = args.verify_cell_mm {
        positive("--verify-cell", c)?;
    }
    // One guarantee (ARCHITECTURE.md, "One tolerance budget"), one-sided: the machine's motion runs
    // between the exact cutter-location surface and the tolerance outside it. Chords get half,
    // linearisation and blending an eighth each (`ToleranceShares`).
    let shares = ToleranceShares::of(tolerance);
    // Trims are followed to a quarter of the chord tolerance.
    let faces = read_face(&args.surface, args.face, 0.25 * shares.chord)?;
    let (shape, tool_number) = match spec {
        ToolSpec::Given(shape) => (shape, args.tool_number.unwrap_or(1)),
        ToolSpec::Auto => {
            let table = match args.tool_table.as_deref() {
                Some(p) => Some((p, crate::library::load_tool_table(Some(p))?)),
                None => None,
            };
            let pick = cam_tool::choose(
                &faces.face,
                faces.region.as_ref(),
                table.as_ref().map(|(p, t)| (*p, t)),
            )?;
            println!("tool auto: {} — {}", pick.shape, pick.why);
            (pick.shape, args.tool_number.or(pick.number).unwrap_or(1))
        }
    };
    let length = tool_length(args.tool_table.as_deref(), tool_number)?;
    let cutter = Cutter::standard(shape);
    let request = PlanRequest {
        strategy,
        scallop_mm: scallop,
        tolerance_mm: shares.chord,
        neighbour_tolerance_mm: match args.check_tolerance {
            Some(t) => positive("--check-tolerance", t)?,
            None => tolerance,
        },
        band: Some(shares.band()),
        lead_deg,
        tilt_deg: args.tilt_deg,
        max_tilt_deg,
        direction,
    };
    let Planned {
        surface,
        path,
        part,
        direction,
        region: face_region,
        reach_normal_tilt_deg,
        neighbours,
        outward_is_su_x_sv,
    } = plan_surface(&args.surface, faces, cutter, &request)?;
    let options = PostOptions {
        form: if args.joints {
            OutputForm::Joints
        } else {
            OutputForm::CentrePoint
        },
        feed_output: if inverse_time(&args) {
            FeedOutput::InverseTime
        } else {
            FeedOutput::PerMinute
        },
        tool_number,
        tool_length_mm: length,
        part,
        title: format!(
            "{} {} {} scallop {} mm",
            args.surface.display(),
            shape,
            args.strategy,
            scallop
        ),
        blend_mm: Some(shares.blend),
        ball_axis_cone_deg: (args.axis_cone_deg > 0.0).then_some(args.axis_cone_deg),
        ..PostOptions::new(feed, shares.linearisation)
    };
    // The program is judged on everything it is meant to machine: the whole face, less what
    // leans beyond the machine's reach (out to the planner's reach edge).
    let region = MachinedRegion::Reachable {
        max_tilt_deg: reach_normal_tilt_deg,
    };
    let judged = Judged {
        region,
        face: face_region.as_ref(),
        outward_is_su_x_sv,
        neighbours: &neighbours,
        check_tolerance_mm: request.neighbour_tolerance_mm,
    };
    let mut done = finish(
        &surface,
        &path,
        &machine,
        &options,
        args.verify_cell_mm,
        judged,
    )?;
    if !done.verified(scallop) && options.ball_axis_cone_deg.is_some() {
        // The steered axes are held to the strategy's gouge checks at the locations, not over
        // the motion between them: a steered program that is not verified is posted again
        // with the planned axes (a known gap: issue 23's wavy patch at lead 10°, h 0.1).
        eprintln!(
            "note: with the ball's axis steered the program is not verified (gouge {:.4} mm, \
             scallop {:.4} mm); posting it with the planned axes",
            done.verification.gouge_depth_mm, done.verification.max_scallop_mm
        );
        let planned = PostOptions {
            ball_axis_cone_deg: None,
            ..options.clone()
        };
        done = finish(
            &surface,
            &path,
            &machine,
            &planned,
            args.verify_cell_mm,
            judged,
        )?;
    }
    std::fs::write(&args.output, &done.posted.program)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", args.output.display()))?;
    let mut json = report_json(&args, &machine, &path, &done, scallop, tool_number);
    if face_region.is_some() {
        json["machined_region"]["kind"] =
            "trimmed face (inside its loops) within the tilt reach".into();
    }
    json["face"] = serde_json::json!({
        "trimmed": face_region.is_some(),
        "loops": face_region.as_ref().map_or(0, |r| r.loops().len()),
        "area_mm2": tezgah_cam::region::surface_area(&surface, face_region.as_ref(), AREA_SAMPLES),
    });
    json["feed_along"] = serde_json::json!(match direction {
        FeedDirection::AlongU => "u",
        FeedDirection::AlongV => "v",
    });
    if let Some(p) = &args.report {
        crate::library::write_json(p, &json)?;
    }
    summary(&args, &done, scallop);
    Ok(if done.verified(scallop) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// The deepest gouge a verified program may leave (issue 7: "no gouge deeper than 1 µm"), mm.
pub const GOUGE_LIMIT_MM: f64 = 0.001;

/// A posted program and its verification.
pub struct Finished {
    pub posted: Posted,
    pub verification: Verification,
    pub step_over_mm: f64,
    /// The same cut over the part's other faces where the tool comes near them.
    pub neighbours: NeighbourCheck,
}

/// What the simulation found on the part's other faces.
#[derive(Debug, Clone, Default)]
pub struct NeighbourCheck {
    /// Faces the tool came near (simulated).
    pub simulated: usize,
    /// Of all of them: the deepest cut into one, mm, the face's `#id` and where.
    pub deepest_mm: f64,
    pub deepest_on: Option<(u64, Vec3)>,
    /// The largest grid bound among them, mm.
    pub grid_bound_mm: f64,
    /// Their dexel spacing, mm (the largest, where a face's grid had to grow to fit).
    pub cell_mm: f64,
    /// How deep the tool may reach into them (`--check-tolerance`), mm.
    pub limit_mm: f64,
}

impl Finished {
    /// Issue 7's check: the measured scallop within the target (measured heights may exceed
    /// the true ones by the sweep bound, so that much over is allowed), no gouge deeper than
    /// [`GOUGE_LIMIT_MM`], and every dexel of the region cut. The grid bound (how much the
    /// sampled maxima may miss) is reported beside it, kept small by the cell size.
    pub fn verified(&self, scallop: f64) -> bool {
        let v = &self.verification;
        v.gouge_depth_mm <= GOUGE_LIMIT_MM
            && v.max_scallop_mm - v.sweep_bound_mm <= scallop
            && v.uncut == 0
            && self.neighbours.deepest_mm <= self.neighbours.limit_mm
    }
}

/// What the verification judges: the machined region (reach) and, for a trimmed face, the
/// face's (u, v) region within it.
#[derive(Debug, Clone, Copy)]
pub struct Judged<'a> {
    pub region: MachinedRegion,
    pub face: Option<&'a FaceRegion>,
    /// The machined face's outside is the side `S_u × S_v` points to.
    pub outward_is_su_x_sv: bool,
    /// The part's other faces: the cut is simulated over them too, for gouges only, their
    /// dexels ending where the machined face bounds the material (less the check tolerance).
    pub neighbours: &'a [NeighbourFace],
    pub check_tolerance_mm: f64,
}

/// Post `path` and simulate the cut along the program as the machine moves it over `region`:
/// dexels every twentieth of the step-over (coarser where the grid would not fit in memory),
/// poses close enough that the sweep error is a tenth of the tolerance.
pub fn finish(
    surface: &NurbsSurface,
    path: &ToolPath,
    machine: &Machine,
    options: &PostOptions,
    cell_mm: Option<f64>,
    judged: Judged,
) -> Result<Finished> {
    // A steered ball's flutes, shank and holder are held to the strategy's gouge checks
    // over the face and the part's other faces.
    let mut faces: Vec<(&NurbsSurface, Option<&FaceRegion>)> = vec![(surface, judged.face)];
    faces.extend(
        judged
            .neighbours
            .iter()
            .map(|n| (&n.check.surface, n.check.region.as_ref())),
    );
    let gouge = tezgah_cam::gouge::GougeSettings {
        depth_tolerance: 0.5 * GOUGE_LIMIT_MM,
        neighbour_depth_tolerance: judged.check_tolerance_mm,
        ..tezgah_cam::gouge::GougeSettings::default()
    };
    let checker = match options.ball_axis_cone_deg {
        Some(_) => Some(
            tezgah_cam::gouge::GougeChecker::of_faces(&faces, &path.cutter, gouge)
                .into_diagnostic()?,
        ),
        None => None,
    };
    let clear = |tip: &Vec3, axis: &Vec3| checker.as_ref().is_none_or(|c| c.clear(tip, axis));
    let posted = post_with(path, machine, options, &clear).into_diagnostic()?;
    let step_over = verify::step_over(path).unwrap_or(2.0 * path.cutter.shape.radius());
    let rho = match path.cutter.shape.corner_radius() {
        r if r > 0.0 => r,
        _ => path.cutter.shape.radius(),
    };
    // δ²/(8ρ) = tolerance/10.
    let circle = (0.8 * rho * options.tolerance_mm).sqrt();
    // A flat end's rim adds δ·tan θ (θ its largest lean from the normal) to the sweep bound:
    // that share is kept within the tolerance too, down to a twentieth of the circle's δ.
    let lean = path
        .passes
        .iter()
        .flat_map(|p| &p.points)
        .map(|c| (c.axis.dot(&c.normal) / (c.axis.norm() * c.normal.norm())).clamp(-1.0, 1.0))
        .map(f64::acos)
        .filter(|a| a.is_finite())
        .fold(0.0, f64::max);
    let spacing = if path.cutter.shape.corner_radius() == 0.0 && lean > 0.0 {
        circle.min((options.tolerance_mm / lean.tan()).max(circle / 20.0))
    } else {
        circle
    };
    let mut verify_options = VerifyOptions {
        cell_mm: cell_mm.unwrap_or(step_over / 20.0),
        sweep_spacing_mm: spacing,
        region: judged.region,
    };
    let poses = posted.sweep(machine, spacing).into_diagnostic()?;
    // A surface whose parametric speed varies (STEP fits often run 5:1) needs its dexel grid
    // at the largest speed everywhere; when that exceeds the simulation's memory guard the
    // cell grows to fit under it (the grid bound, reported, grows with it).
    let mut tries = 0;
    let verification = loop {
        match verify::simulate_on(surface, path, &poses, &verify_options, judged.face) {
            Err(verify::VerifyError::TooFine(count)) if tries < 4 => {
                tries += 1;
                verify_options.cell_mm *= (count as f64 / (0.95 * MAX_DEXELS as f64)).sqrt();
            }
            other => break other.into_diagnostic()?,
        }
    };
    let neighbours = check_neighbours(surface, path, &poses, &verify_options, &judged)?;
    Ok(Finished {
        posted,
        verification,
        step_over_mm: step_over,
        neighbours,
    })
}

/// The cut simulated over each of the part's other faces the tool comes near, at the face's
/// verification cell (grown like it where a face's grid would not fit in memory).
fn check_neighbours(
    surface: &NurbsSurface,
    path: &ToolPath,
    poses: &[verify::CutterPose],
    options: &VerifyOptions,
    judged: &Judged,
) -> Result<NeighbourCheck> {
    let mut out = NeighbourCheck {
        limit_mm: judged.check_tolerance_mm,
        ..NeighbourCheck::default()
    };
    // A cut as deep as the limit under the cutter's corner (radius ρ) is 2√(2ρ·limit) wide:
    // cells a quarter of that see it at two nodes at least, so the other faces need not be
    // sampled as finely as the machined face's 1 µm gouge limit asks (a flat end's sharp rim
    // keeps the face's cell).
    let rho = path.cutter.shape.corner_radius();
    let seen = 0.5 * (2.0 * rho * judged.check_tolerance_mm).sqrt();
    let cell = options.cell_mm.max(seen);
    let machined = verify::Bounded {
        by: verify::Bounding {
            surface,
            outward_is_su_x_sv: judged.outward_is_su_x_sv,
            face: judged.face,
        },
        margin: judged.check_tolerance_mm,
    };
    for n in judged.neighbours {
        let mut options = VerifyOptions {
            cell_mm: cell,
            ..*options
        };
        let mut tries = 0;
        let found = loop {
            let neighbour = verify::Bounding {
                surface: &n.check.surface,
                outward_is_su_x_sv: n.outward_is_su_x_sv,
                face: n.check.region.as_ref(),
            };
            match verify::simulate_neighbour(neighbour, machined, path, poses, &options) {
                Err(verify::VerifyError::TooFine(count)) if tries < 4 => {
                    tries += 1;
                    options.cell_mm *= (count as f64 / (0.95 * MAX_DEXELS as f64)).sqrt();
                }
                other => break other.into_diagnostic()?,
            }
        };
        let Some(v) = found else { continue };
        out.simulated += 1;
        out.cell_mm = out.cell_mm.max(v.cell_mm);
        out.grid_bound_mm = out.grid_bound_mm.max(v.grid_bound_mm);
        if v.gouge_depth_mm > out.deepest_mm {
            out.deepest_mm = v.gouge_depth_mm;
            out.deepest_on = v.gouge_at.map(|(_, p)| (n.id, p));
        }
    }
    Ok(out)
}

fn report_json(
    args: &CamArgs,
    machine: &Machine,
    path: &ToolPath,
    done: &Finished,
    scallop: f64,
    tool_number: u32,
) -> serde_json::Value {
    let s = &done.posted.stats;
    let v = &done.verification;
    let at = |x: &Option<((f64, f64), tezgah_geom::Vec3)>| {
        x.map(|((u, vv), p)| serde_json::json!({"u": u, "v": vv, "x": p.x, "y": p.y, "z": p.z}))
    };
    serde_json::json!({
        "surface": args.surface.display().to_string(),
        "tool": path.cutter.shape.to_string(),
        "tool_number": tool_number,
        "strategy": args.strategy,
        "machine": machine.name,
        "output": if args.joints { "joints" } else { "tcp" },
        "feed_mm_per_min": args.feed,
        "inverse_time": inverse_time(args),
        "tolerance_mm": args.tolerance,
        "scallop_target_mm": scallop,
        "passes": path.passes.len(),
        "cc_points": path.contact_count(),
        "step_over_mm": done.step_over_mm,
        "path_length_mm": s.cutting_length_mm,
        "plunge_length_mm": s.plunge_length_mm,
        "rapid_length_mm": s.rapid_length_mm,
        "machining_time_s": s.feed_time_s,
        "cycle_time_s": s.cycle_time_s,
        "max_axis_change_deg": s.max_axis_change_deg,
        "cycle_over_path_time": s.cycle_time_s.map(|c| c / s.feed_time_s),
        "output_points": s.points,
        "inserted_points": s.inserted,
        "max_linearisation_mm": s.max_linearisation_mm,
        "clearance_sphere": s.clearance.map(|c| serde_json::json!({
            "centre": [c.centre.x, c.centre.y, c.centre.z],
            "radius_mm": c.radius,
            "part_radius_mm": c.part_radius,
        })),
        "max_scallop_mm": v.max_scallop_mm,
        "max_scallop_at": at(&v.max_scallop_at),
        "gouge_depth_mm": v.gouge_depth_mm,
        "gouge_at": at(&v.gouge_at),
        "machined_region": region_json(v),
        "verification": {
            "cell_mm": v.cell_mm,
            "dexels": v.dexels,
            "poses": v.poses,
            "uncut_dexels": v.uncut,
            "grid_bound_mm": v.grid_bound_mm,
            "sweep_bound_mm": v.sweep_bound_mm,
        },
        "gouge_limit_mm": GOUGE_LIMIT_MM,
        "other_faces": {
            "simulated": done.neighbours.simulated,
            "deepest_gouge_mm": done.neighbours.deepest_mm,
            "deepest_on_face": done.neighbours.deepest_on.map(|(id, _)| id),
            "deepest_at": done.neighbours.deepest_on.map(|(_, p)| [p.x, p.y, p.z]),
            "grid_bound_mm": done.neighbours.grid_bound_mm,
            "cell_mm": done.neighbours.cell_mm,
            "limit_mm": done.neighbours.limit_mm,
        },
        "planned_scallop_mm": scallop - args.tolerance,
        "verified": done.verified(scallop),
    })
}

/// The region the verification judged, as the report states it.
fn region_json(v: &Verification) -> serde_json::Value {
    let (kind, tilt) = match v.region {
        MachinedRegion::ContactBox => ("contact box", None),
        MachinedRegion::Reachable { max_tilt_deg } => {
            ("whole face within the tilt reach", Some(max_tilt_deg))
        }
    };
    serde_json::json!({
        "kind": kind,
        "max_normal_tilt_deg": tilt,
        "u": [v.region_u.0, v.region_u.1],
        "v": [v.region_v.0, v.region_v.1],
        "dexels": v.dexels,
    })
}

fn summary(args: &CamArgs, done: &Finished, scallop: f64) {
    let s = &done.posted.stats;
    let v = &done.verification;
    println!(
        "{} → {}: {} points ({} inserted), path {:.1} mm, {:.1} s at F{}, links {:.1} mm",
        args.surface.display(),
        args.output.display(),
        s.points,
        s.inserted,
        s.cutting_length_mm,
        s.feed_time_s,
        args.feed,
        s.rapid_length_mm
    );
    if let Some(c) = s.cycle_time_s {
        println!(
            "cycle on {}: {c:.1} s through tezgah's planning of the program ({:.2} × path/feed)",
            args.machine.as_deref().unwrap_or("table-ac"),
            c / s.feed_time_s
        );
    }
    println!(
        "verified on {} dexels (cell {:.4} mm): max scallop {:.4} mm (target {scallop}), \
         gouge {:.4} mm (limit {GOUGE_LIMIT_MM}), bounds −{:.4}/+{:.4} mm, uncut {}",
        v.dexels,
        v.cell_mm,
        v.max_scallop_mm,
        v.gouge_depth_mm,
        v.grid_bound_mm,
        v.sweep_bound_mm,
        v.uncut
    );
    let n = &done.neighbours;
    if n.simulated > 0 {
        println!(
            "other faces: {} near the tool simulated, deepest cut into one {:.4} mm{} (limit {})",
            n.simulated,
            n.deepest_mm,
            n.deepest_on
                .map_or(String::new(), |(id, _)| format!(" on #{id}")),
            n.limit_mm
        );
    }
    if !done.verified(scallop) {
        eprintln!("verification FAILED: the program is written but does not meet the targets");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_cam::{CutterLocation, CutterShape, Pass};
    use tezgah_geom::Vec3;

    /// The plane z = 0 over 12 × 10 mm, and a ball R = 1.5 zig-zag with 10° of lead.
    fn plane_job(step: f64) -> (NurbsSurface, ToolPath) {
        let (w, h) = (12.0, 10.0);
        let pts = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, h, 0.0),
            Vec3::new(w, 0.0, 0.0),
            Vec3::new(w, h, 0.0),
        ];
        let s = NurbsSurface::bspline(
            1,
            1,
            &pts,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
        )
        .unwrap();
        let r = 1.5;
        let lead = 10f64.to_radians();
        let n = (w / step).round() as usize;
        let passes = (0..=n)
            .map(|i| {
                let u = i as f64 / n as f64;
                let mut pts: Vec<CutterLocation> = (0..=10)
                    .map(|j| {
                        let v = j as f64 / 10.0;
                        let contact = s.point(u, v);
                        let axis = Vec3::new(0.0, lead.sin(), lead.cos());
                        CutterLocation {
                            tip: contact + Vec3::z() * r - axis * r,
                            axis,
                            contact,
                            normal: Vec3::z(),
                            uv: (u, v),
                        }
                    })
                    .collect();
                if i % 2 == 1 {
                    pts.reverse();
                }
                Pass { points: pts }
            })
            .collect();
        let path = ToolPath {
            cutter: Cutter::standard(CutterShape::Ball { radius: r }),
            passes,
        };
        (s, path)
    }

    #[derive(clap::Parser)]
    struct Line {
        #[command(flatten)]
        args: CamArgs,
    }

    fn args(extra: &[&str]) -> CamArgs {
        use clap::Parser;
        let base = [
            "tezgah-cam",
            "s.stp",
            "--tool",
            "ball:6",
            "--strategy",
            "zigzag",
        ];
        let rest = ["--scallop", "0.1", "--tolerance", "0.01", "-o", "o.ngc"];
        let all: Vec<&str> = base.iter().chain(&rest).chain(extra).copied().collect();
        Line::try_parse_from(all).unwrap().args
    }

    #[test]
    fn joint_output_defaults_to_inverse_time() {
        assert!(!inverse_time(&args(&[])));
        assert!(inverse_time(&args(&["--inverse-time"])));
        assert!(inverse_time(&args(&["--joints"])));
        assert!(!inverse_time(&args(&["--joints", "--feed-per-minute"])));
        // Both at once is a contradiction clap refuses.
        use clap::Parser;
        let both = [
            "t",
            "s.stp",
            "--tool",
            "ball:6",
            "--strategy",
            "zigzag",
            "--scallop",
            "0.1",
            "--tolerance",
            "0.01",
            "-o",
            "o.ngc",
            "--inverse-time",
            "--feed-per-minute",
        ];
        assert!(Line::try_parse_from(both).is_err());
        // A ball leans 10° unless told, a flat end not; the axis cone is off.
        let a = args(&[]);
        assert_eq!(a.axis_cone_deg, AXIS_CONE_DEG);
        let ball = ToolSpec::parse("ball:6").unwrap();
        assert_eq!(lead(&ball, a.lead_deg), 10.0);
        assert_eq!(lead(&ball, args(&["--lead", "-3"]).lead_deg), -3.0);
        assert_eq!(lead(&ToolSpec::parse("flat:6").unwrap(), None), 0.0);
        assert_eq!(lead(&ToolSpec::Auto, None), 10.0);
    }

    #[test]
    fn finish_posts_and_verifies_a_plane_job() {
        let machine = Machine::builtin("table-ac").unwrap();
        let (surface, path) = plane_job(1.0);
        let options = PostOptions::new(1000.0, 0.01);
        let region = MachinedRegion::Reachable {
            max_tilt_deg: 120.0,
        };
        let judged = Judged {
            region,
            face: None,
            outward_is_su_x_sv: true,
            neighbours: &[],
            check_tolerance_mm: 0.01,
        };
        let done = finish(&surface, &path, &machine, &options, None, judged).unwrap();
        let v = &done.verification;
        // h = R − √(R² − (s/2)²) for R = 1.5, s = 1.
        let h = 1.5 - (2.25_f64 - 0.25).sqrt();
        assert!(
            v.max_scallop_mm <= h + v.sweep_bound_mm && v.max_scallop_mm >= h - v.grid_bound_mm,
            "{v:?}"
        );
        assert!(v.gouge_depth_mm < 1e-6, "{v:?}");
        assert!(done.verified(h + v.grid_bound_mm));
        assert!(
            !done.verified(h - v.grid_bound_mm - v.sweep_bound_mm - 1e-4),
            "a scallop above the target fails"
        );
        assert!((done.posted.stats.cutting_length_mm - path.cutting_length()).abs() < 1e-9);
    }
}
