//! Finishing strategies on one NURBS surface: the public entry [`plan`] turns a surface, a
//! [`Cutter`] and [`Settings`] into a [`ToolPath`] of cutter locations plus a report of what
//! the gouge checks corrected or refused. Iso-parametric zig-zag (one-way and two-way) lives in
//! `iso_parametric`, iso-scallop in `iso_scallop`; both step along their passes by the true
//! chord error (`forward_step`), size side steps by the exact scallop model (`scallop`) and place
//! every contact here (orientation, CC → CL, gouge checks and correction). With a
//! [`Band`] the placed passes are then held to one side of the exact cutter-location surface
//! (`band`).

mod band;
mod iso_parametric;
mod iso_scallop;
mod pole;
mod reach;
mod true_cusp;

use std::fmt;
use std::str::FromStr;

use nalgebra::Unit;
use rayon::prelude::*;
use tezgah_geom::{NurbsSurface, SurfaceDerivs, Vec3};

use crate::cutter::{Cutter, CutterShape};
use crate::effective_radius::LeadTilt;
use crate::error::{positive, CamError};
use crate::forward_step::{forward_steps, IsoLine, SurfacePath, UvPolyline};
use crate::gouge::local::{local_margin, surface_curvature, Curvature2};
use crate::gouge::{CheckFace, Gouge, GougeChecker, GougeSettings};
use crate::orientation::ContactFrame;
use crate::region::FaceRegion;
use crate::scallop::stepover_exact;
use crate::toolpath::{CutterLocation, Pass, ToolPath};

pub use band::{Band, ChordSag, ToleranceShares};
pub use iso_parametric::iso_parametric_side_step;

/// The finishing strategy, by `tezgah cam --strategy NAME`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrategyKind {
    /// Iso-parametric passes at a constant parametric side step, alternating direction.
    ZigZag,
    /// Iso-parametric passes all cut in the same direction (the tool links back between them).
    ZigZagOneWay,
    /// Each pass offset from the previous one so the scallop height equals the target,
    /// alternating direction.
    IsoScallop,
}

impl FromStr for StrategyKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "zigzag" => Ok(StrategyKind::ZigZag),
            "zigzag-oneway" => Ok(StrategyKind::ZigZagOneWay),
            "iso-scallop" => Ok(StrategyKind::IsoScallop),
            _ => Err(format!(
                "unknown strategy '{s}': expected zigzag, zigzag-oneway or iso-scallop"
            )),
        }
    }
}

impl fmt::Display for StrategyKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StrategyKind::ZigZag => "zigzag",
            StrategyKind::ZigZagOneWay => "zigzag-oneway",
            StrategyKind::IsoScallop => "iso-scallop",
        })
    }
}

/// Which surface parameter the passes run along (the feed); the other is stepped over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FeedDirection {
    /// Passes along `v` at increasing `u` (Can's, 2010, convention).
    #[default]
    AlongV,
    AlongU,
}

/// Samples along a boundary curve when [`FeedDirection::for_surface`] measures it.
const BOUNDARY_SAMPLES: usize = 32;

/// A boundary shorter than this fraction of the longest one is a point (a pole).
const DEGENERATE_BOUNDARY: f64 = 1e-6;

impl FeedDirection {
    /// The direction whose passes end on real boundary curves: passes along v end on the
    /// boundaries v = const, so if one of those is a single point (a latitude–longitude
    /// sphere's pole) the passes would all converge on it — crowded there and, for
    /// iso-scallop, fronts that cannot stay monotone in v — and the passes run along u
    /// instead (a sphere: parallels, each pole cut as a point). Along v otherwise.
    pub fn for_surface(surface: &NurbsSurface) -> FeedDirection {
        let (du, dv) = (surface.domain_u(), surface.domain_v());
        let length = |at: &dyn Fn(f64) -> Vec3| {
            (1..=BOUNDARY_SAMPLES)
                .map(|k| {
                    let (a, b) = (
                        (k - 1) as f64 / BOUNDARY_SAMPLES as f64,
                        k as f64 / BOUNDARY_SAMPLES as f64,
                    );
                    (at(b) - at(a)).norm()
                })
                .sum::<f64>()
        };
        let along_u_at = |v: f64| length(&|t| surface.point(du.0 + (du.1 - du.0) * t, v));
        let along_v_at = |u: f64| length(&|t| surface.point(u, dv.0 + (dv.1 - dv.0) * t));
        let v_ends = [along_u_at(dv.0), along_u_at(dv.1)];
        let u_ends = [along_v_at(du.0), along_v_at(du.1)];
        let longest = v_ends.iter().chain(&u_ends).fold(0.0_f64, |m, &x| m.max(x));
        // A NaN length (a surface that does not evaluate) counts as a point too.
        let point = |x: f64| x.is_nan() || x <= DEGENERATE_BOUNDARY * longest;
        if v_ends.iter().any(|&x| point(x)) && !u_ends.iter().any(|&x| point(x)) {
            FeedDirection::AlongU
        } else {
            FeedDirection::AlongV
        }
    }
}

/// How the tool axis stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolAxis {
    /// 3-axis: one fixed axis for the whole path (e.g. `+z`). Nothing can be corrected by
    /// tilting; gouging points are reported.
    Fixed(Vec3),
    /// 5-axis: the axis follows the surface normal, leaned `lead_deg` toward the feed and
    /// `tilt_deg` sideways. With `match_curvature`, flat and bull-nose cutters lean further
    /// where the cross-feed section is concave, so their effective radius fits it (Can, 2010,
    /// §3.4.7.2.2). Gouges are corrected by leaning further, up to `max_lead_deg`.
    Surface {
        lead_deg: f64,
        tilt_deg: f64,
        max_lead_deg: f64,
        match_curvature: bool,
    },
}

/// Planning settings. [`Settings::new`] gives 5-axis along the normal with curvature
/// matching, feed along `v`, a 5 mm forward-step cap and the default gouge checks.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub strategy: StrategyKind,
    /// Target scallop height `h`, mm.
    pub scallop: f64,
    /// Chord tolerance between contact points, mm.
    pub tolerance: f64,
    pub axis: ToolAxis,
    pub direction: FeedDirection,
    /// Longest move between contact points, mm.
    pub max_step: f64,
    /// The surface's `S_u × S_v` points into the material: cut the other side.
    pub reverse_normal: bool,
    /// 5-axis only: the most the lead may change between consecutive cutter locations
    /// (degrees; Jun 2003, cited by Can 2010, keeps orientation changes ≤ 5° per step). Where a
    /// correction or curvature matching jumps further, the neighbours are leaned further too
    /// (never less: leaning more keeps a flat or bull-nose cutter clear of local gouges, and
    /// every raised location is checked again). Raising the lead shrinks a flat or bull-nose
    /// cutter's effective radius, so the scallop there grows a little. `None`: no limit.
    pub max_lead_change_deg: Option<f64>,
    /// The most the tool axis may lean from the part's +Z, degrees: what a table-tilting
    /// machine reaches (its C axis is the part's Z; the tilt axis' range bounds the lean).
    /// Contact points whose axis would lean further
    /// are left out as [`Refusal::OutOfReach`] and their passes split there — on a closed
    /// surface (a sphere) this machines the cap that faces the spindle. `None`: no limit.
    pub max_axis_tilt_deg: Option<f64>,
    pub gouge: GougeSettings,
    /// The one-sided tolerance band (ARCHITECTURE.md, "One tolerance budget"): `Some` shifts every
    /// cutter location out of the material by its chords' inward sag plus [`Band::motion`] (chords
    /// sagging more than `tolerance` either way are halved first), so the motion between the
    /// emitted points never cuts into the part, and plans side steps for
    /// `scallop − band.outward(tolerance)` so the scallop stays within `scallop`. `None`: the
    /// locations touch the surface exactly and chords straddle it (the contact-point chord
    /// error within `tolerance`).
    pub band: Option<Band>,
    /// A trimmed face's region in (u, v): contact points outside it are left out as
    /// [`Refusal::OutsideFace`], passes that cross its boundary end on it, and its loops are
    /// cut as passes of their own (the strip along the trim). `None`: the whole domain.
    /// The gouge checks see the face only inside it: beyond the trim the surface is not
    /// the part.
    pub region: Option<FaceRegion>,
    /// The part's other faces (a wall beside the floor, the faces round a hole): the rear and
    /// global gouge checks keep the cutter, shank and holder out of them as out of the face
    /// itself, so a contact whose cutter would cut into one is corrected or refused.
    pub neighbours: Vec<CheckFace>,
}

impl Settings {
    /// How far the outward normal may lean from +Z where the path still machines the face,
    /// degrees: [`Settings::max_axis_tilt_deg`] less the cutter's nominal lean from the
    /// normal (its lead and tilt, at least [`MIN_RIM_LEAN_DEG`] for flat and bull-nose ends).
    /// Inside it the cutter at its nominal stance leans at most the limit whichever way it
    /// feeds, so the reach edge is traced there and the face is judged out to it. Traced
    /// where the normal itself reaches the limit, the edge pass lost every point whose axis
    /// leaned past it (on the sphere patch at 5° lead along the parallels: all of them), and
    /// the strip beside it was left to the last regular pass.
    /// Curvature matching and gouge corrections lean further where they must; a point they
    /// take past the limit is refused as out of reach. `None` without a limit.
    pub fn reach_normal_tilt_deg(&self, shape: &CutterShape) -> Option<f64> {
        let limit = self.max_axis_tilt_deg?;
        let lean = match self.axis {
            ToolAxis::Fixed(_) => 0.0,
            ToolAxis::Surface {
                lead_deg, tilt_deg, ..
            } => {
                let nominal =
                    LeadTilt::new(lead_deg.to_radians(), tilt_deg.to_radians()).inclination();
                match shape {
                    CutterShape::Ball { .. } => nominal,
                    _ => nominal.max(MIN_RIM_LEAN_DEG.to_radians()),
                }
            }
        };
        Some((limit - lean.to_degrees()).max(0.0))
    }

    pub fn new(strategy: StrategyKind, scallop: f64, tolerance: f64) -> Settings {
        Settings {
            strategy,
            scallop,
            tolerance,
            axis: ToolAxis::Surface {
                lead_deg: 0.0,
                tilt_deg: 0.0,
                max_lead_deg: 30.0,
                match_curvature: true,
            },
            direction: FeedDirection::AlongV,
            max_step: 5.0,
            reverse_normal: false,
            max_lead_change_deg: None,
            max_axis_tilt_deg: None,
            gouge: GougeSettings::default(),
            band: None,
            region: None,
            neighbours: Vec::new(),
        }
    }

    fn validate(&self) -> Result<(), CamError> {
        positive("scallop", self.scallop)?;
        positive("tolerance", self.tolerance)?;
        positive("max_step", self.max_step)?;
        if let Some(rate) = self.max_lead_change_deg {
            positive("max_lead_change", rate)?;
        }
        if let Some(band) = self.band {
            band.validate()?;
            let planned = self.scallop - band.outward(self.tolerance);
            if planned <= 0.0 || planned.is_nan() {
                return Err(CamError::Setting {
                    name: "tolerance band (chord tolerance + 2 × band motion)",
                    want: "below the scallop height, which it is taken from",
                    got: band.outward(self.tolerance),
                });
            }
        }
        if let Some(t) = self.max_axis_tilt_deg {
            if !(t.is_finite() && (0.0..=180.0).contains(&t)) {
                return Err(CamError::Setting {
                    name: "max_axis_tilt",
                    want: "an angle from +Z in 0..=180 degrees",
                    got: t,
                });
            }
        }
        let angle = |name, x: f64, lo: f64, hi: f64| {
            if x.is_finite() && x >= lo && x <= hi {
                Ok(())
            } else {
                Err(CamError::Setting {
                    name,
                    want: "an angle within its range (degrees; lead 0..=89, tilt −89..=89)",
                    got: x,
                })
            }
        };
        match self.axis {
            ToolAxis::Fixed(a) => {
                if !(a.iter().all(|c| c.is_finite()) && a.norm() > 0.0) {
                    return Err(CamError::Setting {
                        name: "axis",
                        want: "a finite non-zero vector",
                        got: a.norm(),
                    });
                }
            }
            ToolAxis::Surface {
                lead_deg,
                tilt_deg,
                max_lead_deg,
                ..
            } => {
                angle("lead", lead_deg, 0.0, 89.0)?;
                angle("tilt", tilt_deg, -89.0, 89.0)?;
                angle("max_lead", max_lead_deg, lead_deg, 89.0)?;
            }
        }
        Ok(())
    }
}

/// A contact point the planner could not emit, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refusal {
    /// The cutter gouges here at every orientation tried.
    Gouge(Gouge),
    /// The surface has no normal here (a degenerate point).
    NoNormal,
    /// The fixed tool axis points into the surface here.
    AxisBelowSurface,
    /// The tool axis would lean further from +Z than [`Settings::max_axis_tilt_deg`]: the
    /// machine cannot reach this point from above (not a gouge).
    OutOfReach,
    /// The contact point lies outside the trimmed face ([`Settings::region`]): not part of
    /// what is machined (not a gouge).
    OutsideFace,
}

impl Refusal {
    /// True for a point beyond the machined region (out of reach or outside the face):
    /// passes end on that region's edge.
    pub fn is_beyond(&self) -> bool {
        matches!(self, Refusal::OutOfReach | Refusal::OutsideFace)
    }

    /// True for a gouge where the tool meets the part away from the contact (rear or global:
    /// a wall beside the face, the surface behind the heel).
    pub fn is_interference(&self) -> bool {
        matches!(self, Refusal::Gouge(Gouge::Interference { .. }))
    }

    /// True for a gouge (the cutter would cut into the part here), false for a point the
    /// machine cannot reach or where the surface has no normal.
    pub fn is_gouge(&self) -> bool {
        matches!(self, Refusal::Gouge(_) | Refusal::AxisBelowSurface)
    }
}

/// One refused contact point: where, and why. The pass is split around it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GougeReport {
    pub uv: (f64, f64),
    pub contact: Vec3,
    pub refusal: Refusal,
}

/// The planner's result: the tool path, the contact points it refused, and how many points it
/// corrected by leaning the tool further than the nominal orientation.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    pub path: ToolPath,
    pub refused: Vec<GougeReport>,
    pub corrected: usize,
}

/// Plans a finishing tool path of `cutter` over `surface` (the public entry of the CAM
/// strategies). Errors are bad settings or cutter, or a search that failed; gouges are not
/// errors but corrected (5-axis) or listed in [`Plan::refused`] with their pass split there.
pub fn plan(
    surface: &NurbsSurface,
    cutter: &Cutter,
    settings: &Settings,
) -> Result<Plan, CamError> {
    settings.validate()?;
    validate_cutter(cutter)?;
    // The band's outward width comes off the scallop the side steps are sized for.
    let banded;
    let settings = match settings.band {
        Some(band) => {
            banded = Settings {
                scallop: settings.scallop - band.outward(settings.tolerance),
                ..settings.clone()
            };
            &banded
        }
        None => settings,
    };
    let ctx = Context::new(surface, cutter, settings)?;
    let paths = match settings.strategy {
        StrategyKind::ZigZag | StrategyKind::ZigZagOneWay => iso_parametric::passes(&ctx)?,
        StrategyKind::IsoScallop => iso_scallop::passes(&ctx)?,
    };
    let one_way = settings.strategy == StrategyKind::ZigZagOneWay;
    let results: Vec<PassResult> = paths
        .par_iter()
        .enumerate()
        .map(|(k, path)| ctx.run_pass(path, !one_way && k % 2 == 1))
        .collect::<Result<_, _>>()?;
    let mut plan = Plan {
        path: ToolPath {
            cutter: *cutter,
            passes: Vec::new(),
        },
        refused: Vec::new(),
        corrected: 0,
    };
    let out_of_reach = results
        .iter()
        .flat_map(|r| &r.refused)
        .any(|f| f.refusal == Refusal::OutOfReach);
    // Where passes ran out of reach, the edge of the reach is cut too: the strip between the
    // last reachable pass and the edge would otherwise keep up to a side step's scallop.
    let edges: Vec<PassResult> = if out_of_reach {
        ctx.reach_edges()
            .par_iter()
            .map(|edge| ctx.run_pass(&PassPath::Poly(edge.clone()), false))
            .collect::<Result<_, _>>()?
    } else {
        Vec::new()
    };
    // A trimmed face's loops are cut too: passes end on the trim, but where the trim runs
    // along the passes the strip between the last pass and it would keep up to a side step.
    let trims: Vec<PassResult> = match &settings.region {
        Some(region) => region
            .loops()
            .par_iter()
            .map(|l| {
                let mut points = l.clone();
                points.push(l[0]);
                ctx.run_pass(&PassPath::Poly(UvPolyline { points }), false)
            })
            .collect::<Result<_, _>>()?,
        None => Vec::new(),
    };
    for r in results.into_iter().chain(edges).chain(trims) {
        plan.path.passes.extend(r.passes);
        plan.refused.extend(r.refused);
        plan.corrected += r.corrected;
    }
    Ok(plan)
}

fn validate_cutter(cutter: &Cutter) -> Result<(), CamError> {
    let (big_r, r) = (cutter.shape.radius(), cutter.shape.corner_radius());
    let ok = big_r.is_finite()
        && big_r > 0.0
        && r.is_finite()
        && r >= 0.0
        && r <= big_r
        && cutter.flute_length.is_finite()
        && [cutter.shank, cutter.holder].iter().all(|c| {
            [c.radius, c.from, c.length]
                .iter()
                .all(|x| x.is_finite() && *x >= 0.0)
        });
    if ok {
        Ok(())
    } else {
        Err(CamError::Cutter(format!("{:?}", cutter)))
    }
}

/// One pass to cut: an iso-parametric line or a polyline in the parameter plane.
#[derive(Debug, Clone, PartialEq)]
enum PassPath {
    Iso(IsoLine),
    Poly(UvPolyline),
}

impl SurfacePath for PassPath {
    fn range(&self) -> (f64, f64) {
        match self {
            PassPath::Iso(p) => p.range(),
            PassPath::Poly(p) => p.range(),
        }
    }
    fn uv(&self, t: f64) -> (f64, f64) {
        match self {
            PassPath::Iso(p) => p.uv(t),
            PassPath::Poly(p) => p.uv(t),
        }
    }
}

/// The surface's parameters as (side, feed).
#[derive(Debug, Clone, Copy)]
struct Axes {
    along_v: bool,
    side: (f64, f64),
    feed: (f64, f64),
}

impl Axes {
    fn uv(&self, s: f64, f: f64) -> (f64, f64) {
        if self.along_v {
            (s, f)
        } else {
            (f, s)
        }
    }
    fn sf(&self, (u, v): (f64, f64)) -> (f64, f64) {
        if self.along_v {
            (u, v)
        } else {
            (v, u)
        }
    }
}

/// Geometry at one contact point.
struct Local {
    d: SurfaceDerivs,
    frame: ContactFrame,
    curvature: Curvature2,
}

/// How far into the domain (fraction of the parameter range) the limit derivatives on a
/// degenerate edge are taken: the normal there is off by about this angle times the range
/// (a sphere: 3·10⁻⁸ rad), far below any tolerance, while the derivatives stay well defined.
const LIMIT_NUDGE: f64 = 1e-8;

/// Curvature matching leaves this relative margin: `r_e ≤ (1 − margin)·ρ`.
const MATCH_MARGIN: f64 = 0.05;
/// The least lean of a flat or bull-nose end from the surface normal, degrees. Standing
/// exactly along the normal its flat bottom lies in the tangent plane and the contact may be
/// anywhere on the rim; a hair off the normal it is where the hair points. The chord checks
/// interpolate axes between locations and meet normals a hair different, so at zero lean the
/// contact (and the tip, by up to 2(R − r)) jumps across the rim between a location and its
/// chord: the motion lifts off the cut. Half a degree keeps the rim contact on the feed side
/// while the normal turns by far less between neighbouring checks (second order in the chord).
const MIN_RIM_LEAN_DEG: f64 = 0.5;
/// Bisections of a side step against the true silhouette (the bracket shrinks by 2⁻³⁰).
const SILHOUETTE_BISECTIONS: usize = 30;
/// A gouge's correction raises the lead by bisection to within this, degrees.
const CORRECTION_RESOLUTION_DEG: f64 = 0.5;

struct Context<'a> {
    surface: &'a NurbsSurface,
    cutter: &'a Cutter,
    settings: &'a Settings,
    axes: Axes,
    checker: GougeChecker,
    fixed_axis: Option<Unit<Vec3>>,
}

/// A contact point to place: its parameters and the path's direction there (in `(u, v)`).
#[derive(Debug, Clone, Copy)]
struct Contact {
    uv: (f64, f64),
    tangent: (f64, f64),
}

/// A placed cutter location and the lead it stands at.
struct Placed {
    location: CutterLocation,
    corrected: bool,
    lead: f64,
}

struct PassResult {
    passes: Vec<Pass>,
    refused: Vec<GougeReport>,
    corrected: usize,
}

impl<'a> Context<'a> {
    fn new(
        surface: &'a NurbsSurface,
        cutter: &'a Cutter,
        settings: &'a Settings,
    ) -> Result<Self, CamError> {
        let along_v = settings.direction == FeedDirection::AlongV;
        let (du, dv) = (surface.domain_u(), surface.domain_v());
        let axes = if along_v {
            Axes {
                along_v,
                side: du,
                feed: dv,
            }
        } else {
            Axes {
                along_v,
                side: dv,
                feed: du,
            }
        };
        let fixed_axis = match settings.axis {
            ToolAxis::Fixed(a) => Some(Unit::new_normalize(a)),
            ToolAxis::Surface { .. } => None,
        };
        let faces: Vec<_> = std::iter::once((surface, settings.region.as_ref()))
            .chain(
                settings
                    .neighbours
                    .iter()
                    .map(|f| (&f.surface, f.region.as_ref())),
            )
            .collect();
        Ok(Context {
            surface,
            cutter,
            settings,
            axes,
            checker: GougeChecker::of_faces(&faces, cutter, settings.gouge)?,
            fixed_axis,
        })
    }

    fn shape(&self) -> &CutterShape {
        &self.cutter.shape
    }

    /// True when (u, v) is on the face: inside its trim ([`Settings::region`]), or anywhere
    /// on an untrimmed one.
    fn on_face(&self, u: f64, v: f64) -> bool {
        self.settings
            .region
            .as_ref()
            .is_none_or(|r| r.contains(u, v))
    }

    /// Frame and curvature at `(u, v)` for a path running along `tangent_uv`.
    fn local(&self, u: f64, v: f64, tangent_uv: (f64, f64)) -> Option<Local> {
        self.local_of(self.derivs(u, v), tangent_uv)
    }

    /// The surface's derivatives at `(u, v)`; on a degenerate edge (a pole, where one
    /// parameter's derivative vanishes and the normal with it) those of the limit from inside:
    /// the point itself with the derivatives a hair ([`LIMIT_NUDGE`] of the range) into the
    /// domain across that edge, where the normal is defined. On a sphere's pole that is the
    /// pole's normal to within the nudge's angle; the gouge checks stand guard where a
    /// degenerate point has no single limit (an apex).
    fn derivs(&self, u: f64, v: f64) -> SurfaceDerivs {
        let d = self.surface.derivs(u, v);
        if d.normal().is_some() {
            return d;
        }
        let inward = |x: f64, (lo, hi): (f64, f64)| {
            let e = LIMIT_NUDGE * (hi - lo);
            if x - lo < hi - x {
                x + e
            } else {
                x - e
            }
        };
        let (du, dv) = (self.surface.domain_u(), self.surface.domain_v());
        // The parameter whose derivative vanished runs along the edge; step across it.
        let (nu, nv) = if d.su.norm() <= d.sv.norm() {
            (u, inward(v, dv))
        } else {
            (inward(u, du), v)
        };
        let near = self.surface.derivs(nu, nv);
        if near.normal().is_none() {
            return d;
        }
        SurfaceDerivs {
            point: d.point,
            ..near
        }
    }

    /// [`Self::local`] from derivatives already evaluated.
    fn local_of(&self, d: SurfaceDerivs, tangent_uv: (f64, f64)) -> Option<Local> {
        let n = d.normal()?;
        let n = if self.settings.reverse_normal { -n } else { n };
        let tangent = d.su * tangent_uv.0 + d.sv * tangent_uv.1;
        let frame = ContactFrame::new(n, tangent)?;
        let curvature = surface_curvature(&d, &frame)?;
        Some(Local {
            d,
            frame,
            curvature,
        })
    }

    /// The orientation before gouge correction: the settings' lead and tilt, leaned further
    /// for curvature matching; `None` when a fixed axis points into the surface.
    fn nominal_angles(&self, local: &Local) -> Option<LeadTilt> {
        match self.settings.axis {
            ToolAxis::Fixed(_) => local.frame.lead_tilt(&self.fixed_axis?),
            ToolAxis::Surface {
                lead_deg,
                tilt_deg,
                max_lead_deg,
                match_curvature,
            } => {
                let mut lead = lead_deg.to_radians();
                let max_lead = max_lead_deg.to_radians();
                let k = local.curvature.tt;
                if match_curvature && k > 0.0 && !matches!(self.shape(), CutterShape::Ball { .. }) {
                    let need = self
                        .shape()
                        .matching_lead((1.0 - MATCH_MARGIN) / k)
                        .unwrap_or(max_lead);
                    lead = lead.max(need.min(max_lead));
                }
                let tilt = tilt_deg.to_radians();
                let min_lean = MIN_RIM_LEAN_DEG.to_radians();
                if !matches!(self.shape(), CutterShape::Ball { .. }) && lead.hypot(tilt) < min_lean
                {
                    lead = (min_lean * min_lean - tilt * tilt).sqrt().min(max_lead);
                }
                Some(LeadTilt::new(lead, tilt))
            }
        }
    }

    fn axis_for(&self, frame: &ContactFrame, angles: LeadTilt) -> Unit<Vec3> {
        self.fixed_axis.unwrap_or_else(|| frame.axis(angles))
    }

    /// The side step (mm, a chord across the feed) that leaves the target scallop at this
    /// point with the nominal orientation, capped at the tool radius (beyond it the osculating
    /// circle no longer describes a flat or bull-nose profile). `None` where the cutter gouges
    /// locally at the nominal orientation.
    fn side_step(&self, local: &Local) -> Option<f64> {
        let angles = self.nominal_angles(local)?;
        let r_e = self.shape().effective_radius(angles);
        let w = stepover_exact(r_e, local.curvature.tt, self.settings.scallop)?;
        Some(self.fit_silhouette(local, angles, w.min(self.shape().radius())))
    }

    /// `w`, shrunk (bisection) until the cusp on the cutter's true silhouette across the feed
    /// is within the target (`silhouette`): a flat or bull-nose profile rises faster than its
    /// osculating circle away from the contact. A ball's profile is its circle.
    fn fit_silhouette(&self, local: &Local, angles: LeadTilt, w: f64) -> f64 {
        if matches!(self.shape(), CutterShape::Ball { .. }) {
            return w;
        }
        let a = self.axis_for(&local.frame, angles).into_inner();
        let (n, t) = (
            local.frame.normal.into_inner(),
            local.frame.cross.into_inner(),
        );
        let (h, kappa, len) = (
            self.settings.scallop,
            local.curvature.tt,
            self.cutter.flute_length,
        );
        let cusp = |w: f64| crate::silhouette::cusp(self.shape(), len, &a, &n, &t, kappa, w);
        if cusp(w) <= h {
            return w;
        }
        let (mut lo, mut hi) = (0.0, w);
        for _ in 0..SILHOUETTE_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if cusp(mid) <= h {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// Places the cutter at the contact `(u, v)` on a path running along `tangent_uv`, leaning
    /// it at least `min_lead` (radians, 5-axis) and further while it gouges.
    fn place(
        &self,
        u: f64,
        v: f64,
        tangent_uv: (f64, f64),
        min_lead: f64,
    ) -> Result<Placed, GougeReport> {
        let d = self.derivs(u, v);
        let contact = d.point;
        let refuse = |refusal| GougeReport {
            uv: (u, v),
            contact,
            refusal,
        };
        if !self.on_face(u, v) {
            return Err(refuse(Refusal::OutsideFace));
        }
        let local = self
            .local_of(d, tangent_uv)
            .ok_or_else(|| refuse(Refusal::NoNormal))?;
        let mut angles = self
            .nominal_angles(&local)
            .ok_or_else(|| refuse(Refusal::AxisBelowSurface))?;
        let shape = self.shape();
        let mut corrected = false;
        if self.fixed_axis.is_none() && min_lead > angles.lead {
            angles.lead = min_lead;
            corrected = true;
        }
        // cos of the largest lean from +Z (the axis' z component may not fall below it).
        let min_axis_z = self
            .settings
            .max_axis_tilt_deg
            .map(|t| t.to_radians().cos() - 1e-12);
        // The cutter at `angles`: placed, or why not.
        let stand = |angles: LeadTilt| -> Result<CutterLocation, Refusal> {
            let axis = self.axis_for(&local.frame, angles);
            if min_axis_z.is_some_and(|z| axis.z < z) {
                return Err(Refusal::OutOfReach);
            }
            let margin = local_margin(shape, &local.frame, &axis, &local.curvature);
            if margin < -1e-9 {
                return Err(Refusal::Gouge(Gouge::Local { margin }));
            }
            let tip = shape.tip_for_contact(&local.d.point, &local.frame, &axis);
            match self.checker.check(&tip, &axis) {
                Some(g) => Err(Refusal::Gouge(g)),
                None => Ok(CutterLocation {
                    tip,
                    axis: axis.into_inner(),
                    contact: local.d.point,
                    normal: local.frame.normal.into_inner(),
                    uv: (u, v),
                }),
            }
        };
        let problem = match stand(angles) {
            Ok(location) => {
                return Ok(Placed {
                    location,
                    corrected,
                    lead: angles.lead,
                })
            }
            Err(problem) => problem,
        };
        // A ball's local gouge does not depend on its lean; a fixed axis cannot lean; the
        // machine's reach is not a gouge.
        let ball_local = matches!(shape, CutterShape::Ball { .. })
            && matches!(problem, Refusal::Gouge(Gouge::Local { .. }));
        let max_lead = match self.settings.axis {
            ToolAxis::Surface { max_lead_deg, .. } if !ball_local => max_lead_deg.to_radians(),
            _ => return Err(refuse(problem)),
        };
        if matches!(problem, Refusal::OutOfReach) || max_lead <= angles.lead {
            return Err(refuse(problem));
        }
        // Raise the lead: the largest allowed must clear, then bisection between the nominal
        // (gouging) and the clearing lead keeps the lowest clearing one found (each kept lead
        // is checked, so the gouge-free leads need not form an interval).
        let at = |lead: f64| stand(LeadTilt { lead, ..angles });
        let mut best = match at(max_lead) {
            Ok(location) => (max_lead, location),
            Err(_) => return Err(refuse(problem)),
        };
        let mut low = angles.lead;
        while best.0 - low > CORRECTION_RESOLUTION_DEG.to_radians() {
            let mid = 0.5 * (low + best.0);
            match at(mid) {
                Ok(location) => best = (mid, location),
                Err(_) => low = mid,
            }
        }
        Ok(Placed {
            location: best.1,
            corrected: true,
            lead: best.0,
        })
    }

    /// Steps along `path` by the chord error and places the cutter at every contact point;
    /// `reverse` cuts it from its end to its start. Refused points split the pass.
    fn run_pass(&self, path: &impl SurfacePath, reverse: bool) -> Result<PassResult, CamError> {
        let (t0, t1) = path.range();
        let h = (t1 - t0) * 1e-6;
        // The lead and tilt are measured from the pass's direction on the part, not from the
        // way it is cut, for a ball: it cuts the same leaning either way along the feed (its
        // lead keeps the contact off the centre, where the cutting speed is zero, whether it
        // leads or trails), so a zig-zag return keeps the outward pass's axis and the table
        // does not turn over at every link (issue 23: +20–70 % cycle with the lead flipping).
        // Other shapes lead on every pass: their heels and rims cut where they lean.
        let trails = matches!(self.shape(), CutterShape::Ball { .. });
        let sign = if reverse && !trails { -1.0 } else { 1.0 };
        let contact_at = |t: f64| {
            let (a, b) = (path.uv((t - h).max(t0)), path.uv((t + h).min(t1)));
            Contact {
                uv: path.uv(t),
                tangent: (sign * (b.0 - a.0), sign * (b.1 - a.1)),
            }
        };
        let mut ts = match self.turn_about_pole(path, |t| contact_at(t).tangent) {
            Some(turn) => turn,
            None => forward_steps(
                self.surface,
                path,
                self.settings.tolerance,
                self.settings.max_step,
                None,
            )?,
        };
        if reverse {
            ts.reverse();
        }
        let mut out = PassResult {
            passes: Vec::new(),
            refused: Vec::new(),
            corrected: 0,
        };
        let mut placed: Vec<Result<Placed, GougeReport>> = ts
            .iter()
            .map(|&t| {
                let c = contact_at(t);
                self.place(c.uv.0, c.uv.1, c.tangent, 0.0)
            })
            .collect();
        self.end_on_reach(&mut ts, &mut placed, &contact_at);
        if self.settings.band.is_some() {
            self.refine_chords(path, &mut ts, &mut placed, contact_at);
        }
        let contacts: Vec<Contact> = ts.iter().map(|&t| contact_at(t)).collect();
        if let (Some(rate), None) = (self.settings.max_lead_change_deg, self.fixed_axis) {
            self.limit_lead_change(&contacts, &mut placed, rate.to_radians());
        }
        if let Some(band) = self.settings.band {
            self.clear_chords(path, &ts, &contacts, &mut placed, band);
            self.shift_outward(path, &ts, &mut placed, band);
        }
        let mut current = Pass::default();
        for item in placed {
            match item {
                Ok(p) => {
                    out.corrected += usize::from(p.corrected);
                    current.points.push(p.location);
                }
                Err(report) => {
                    out.refused.push(report);
                    self.close_pass(&mut out.passes, std::mem::take(&mut current));
                }
            }
        }
        self.close_pass(&mut out.passes, current);
        Ok(out)
    }

    /// Ends the pieces of a pass on the edge of the reach or of the face, or where the cutter
    /// would begin to cut into the part (a wall beside the face): between a placed contact
    /// and a neighbour refused as beyond it ([`Refusal::is_beyond`]) or as an interference
    /// gouge, the last placeable contact is added.
    fn end_on_reach(
        &self,
        ts: &mut Vec<f64>,
        placed: &mut Vec<Result<Placed, GougeReport>>,
        contact_at: &impl Fn(f64) -> Contact,
    ) {
        // The refusal of each contact refused as beyond the edge or as an interference.
        let away: Vec<Option<Refusal>> = placed
            .iter()
            .map(|p| match p {
                Err(r) if r.refusal.is_beyond() || r.refusal.is_interference() => Some(r.refusal),
                _ => None,
            })
            .collect();
        if away.iter().all(Option::is_none) {
            return;
        }
        let ok: Vec<bool> = placed.iter().map(|p| p.is_ok()).collect();
        let place_at = |t: f64| {
            let c = contact_at(t);
            self.place(c.uv.0, c.uv.1, c.tangent, 0.0)
        };
        let n = ts.len();
        let mut new_ts = Vec::with_capacity(n + 4);
        let mut new_placed = Vec::with_capacity(n + 4);
        let toward = |j: usize| away[j].as_ref().map(|r| (ts[j], r));
        for (i, item) in std::mem::take(placed).into_iter().enumerate() {
            if let (true, Some(out)) = (ok[i], i.checked_sub(1).and_then(toward)) {
                if let Some((t, p)) = self.reach_end(ts[i], out, place_at) {
                    new_ts.push(t);
                    new_placed.push(Ok(p));
                }
            }
            new_ts.push(ts[i]);
            new_placed.push(item);
            if let (true, Some(out)) = (ok[i], (i + 1 < n).then(|| toward(i + 1)).flatten()) {
                if let Some((t, p)) = self.reach_end(ts[i], out, place_at) {
                    new_ts.push(t);
                    new_placed.push(Ok(p));
                }
            }
        }
        *ts = new_ts;
        *placed = new_placed;
    }

    /// Keeps a pass of two or more locations, with its run-out when the band is on: along
    /// the feed into the last contact from the latest one apart from it (none for a turn
    /// about a pole, whose contacts are all one point).
    fn close_pass(&self, passes: &mut Vec<Pass>, mut pass: Pass) {
        let [.., _, last] = pass.points.as_slice() else {
            return;
        };
        if self.settings.band.is_some() {
            let apart = (pass.points.iter().rev())
                .find(|p| (p.contact - last.contact).norm() > pole::SAME_POINT);
            if let Some(extra) = apart.and_then(|prev| self.run_out(prev, last)) {
                pass.points.push(extra);
            }
        }
        passes.push(pass);
    }

    /// Raises leads so consecutive placed locations differ by at most `rate` (radians): each
    /// lead becomes at least its neighbours' minus `rate` (a forward and a backward sweep), and
    /// raised locations are placed again (kept as they were if that fails). A few rounds, as a
    /// re-placement may lean further than asked to clear a gouge.
    fn limit_lead_change(
        &self,
        contacts: &[Contact],
        placed: &mut [Result<Placed, GougeReport>],
        rate: f64,
    ) {
        for _ in 0..4 {
            let leads: Vec<Option<f64>> = placed
                .iter()
                .map(|p| p.as_ref().ok().map(|p| p.lead))
                .collect();
            let mut target = leads.clone();
            for i in 1..target.len() {
                if let (Some(prev), Some(here)) = (target[i - 1], target[i]) {
                    target[i] = Some(here.max(prev - rate));
                }
            }
            for i in (0..target.len().saturating_sub(1)).rev() {
                if let (Some(next), Some(here)) = (target[i + 1], target[i]) {
                    target[i] = Some(here.max(next - rate));
                }
            }
            let mut changed = false;
            for (i, (want, have)) in target.iter().zip(&leads).enumerate() {
                if let (Some(want), Some(have)) = (want, have) {
                    if *want > have + 1e-12 {
                        let c = contacts[i];
                        if let Ok(p) = self.place(c.uv.0, c.uv.1, c.tangent, *want) {
                            placed[i] = Ok(p);
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn passes_run_along_the_poles_not_into_them() {
        // The patch of the tests has four real boundaries: along v. A surface whose v = 0
        // boundary is one point (a fan of lines from the origin) runs along u.
        let patch = crate::testing::sphere(30.0);
        assert_eq!(FeedDirection::for_surface(&patch), FeedDirection::AlongV);
        let pts = [
            Vec3::zeros(),
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::zeros(),
            Vec3::new(0.0, 10.0, 0.0),
        ];
        let fan = NurbsSurface::bspline(
            1,
            1,
            &pts,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
        )
        .unwrap();
        assert_eq!(FeedDirection::for_surface(&fan), FeedDirection::AlongU);
    }

    use super::*;

    #[test]
    fn strategy_names_round_trip_and_bad_ones_are_refused() {
        for name in ["zigzag", "zigzag-oneway", "iso-scallop"] {
            assert_eq!(name.parse::<StrategyKind>().unwrap().to_string(), name);
        }
        assert!("spiral".parse::<StrategyKind>().is_err());
    }

    #[test]
    fn contacts_beyond_the_axis_tilt_limit_are_left_out_as_out_of_reach() {
        // Sphere R 30 between latitudes 10° and 60°: normals 30°…80° from +Z. With the axis
        // along the normal and at most 50° of lean, the band below latitude 40° is left out.
        let (r, limit) = (30.0, 50.0_f64);
        let surface = crate::testing::sphere(r);
        let cutter = Cutter::standard(CutterShape::Ball { radius: 3.0 });
        for kind in [StrategyKind::ZigZag, StrategyKind::IsoScallop] {
            let mut settings = Settings::new(kind, 0.2, 0.01);
            settings.max_axis_tilt_deg = Some(limit);
            let p = plan(&surface, &cutter, &settings).unwrap();
            let cos = limit.to_radians().cos();
            assert!(p.path.contact_count() > 100, "{kind}");
            for cl in p.path.passes.iter().flat_map(|q| &q.points) {
                assert!(cl.axis.normalize().z >= cos - 1e-9, "{kind}: {cl:?}");
            }
            assert!(!p.refused.is_empty(), "{kind}");
            for f in &p.refused {
                assert_eq!(f.refusal, Refusal::OutOfReach, "{kind}");
                assert!(!f.refusal.is_gouge());
                // Out of reach means the normal leans more than the limit: below z = r cos 50°.
                assert!(f.contact.z < r * cos + 1e-6, "{kind}: {f:?}");
            }
            // The kept part reaches down to the limit: passes that cross it end on it, and
            // the edge (the parallel at latitude 40°) is cut as a pass of its own.
            let on_edge = |c: &CutterLocation| (c.contact.z - r * cos).abs() < 1e-6;
            assert!(
                p.path.passes.iter().any(|q| q.points.iter().all(on_edge)),
                "{kind}: no pass along the edge"
            );
            for q in &p.path.passes {
                let (a, b) = (&q.points[0], &q.points[q.points.len() - 1]);
                // Every pass ends on the edge or on the patch's own boundary.
                for c in [a, b] {
                    let boundary = [c.uv.0, c.uv.1]
                        .iter()
                        .any(|x| *x < 1e-9 || *x > 1.0 - 1e-9);
                    assert!(on_edge(c) || boundary, "{kind}: pass ends at {c:?}");
                }
            }
        }
        let mut bad = Settings::new(StrategyKind::ZigZag, 0.2, 0.01);
        bad.max_axis_tilt_deg = Some(f64::NAN);
        assert!(bad.validate().is_err());
    }

    #[test]
    fn settings_out_of_range_are_refused() {
        let base = Settings::new(StrategyKind::ZigZag, 0.01, 0.01);
        assert!(base.validate().is_ok());
        let mut s = base.clone();
        s.max_step = 0.0;
        assert!(s.validate().is_err());
        for (lead, tilt, max) in [(-1.0, 0.0, 30.0), (10.0, 95.0, 30.0), (40.0, 0.0, 30.0)] {
            let mut s = base.clone();
            s.axis = ToolAxis::Surface {
                lead_deg: lead,
                tilt_deg: tilt,
                max_lead_deg: max,
                match_curvature: true,
            };
            assert!(s.validate().is_err(), "{lead} {tilt} {max}");
        }
        let mut s = base;
        s.gouge.rear_spacing = f64::NAN;
        let surface = crate::testing::plane(10.0);
        let cutter = Cutter::standard(CutterShape::Ball { radius: 1.0 });
        assert!(plan(&surface, &cutter, &s).is_err());
    }
}
