//! `tezgah cam --tool auto`: the cutter chosen for the face before planning — the largest ball
//! end mill that fits the face's tightest concave curvature (Can, 2010, §3.4.7.2, via
//! `tezgah_cam::select`), from the tool table's ball end mills or else the standard set.

use std::path::Path;

use miette::{miette, IntoDiagnostic, Result};
use tezgah_cam::region::FaceRegion;
use tezgah_cam::select::{propose, tightest_concave_radius, STANDARD_DIAMETERS};
use tezgah_cam::step::Face;
use tezgah_cam::CutterShape;
use tezgah_gcode::ToolTable;

/// Parameter lattice (per direction) on which the face's principal curvatures are sampled.
const CURVATURE_LATTICE: usize = 64;
/// The ball must stay this fraction below the tightest sampled concave radius: the lattice
/// sees the curvature only at its nodes, and the strategy refuses any point where the ball's
/// radius exceeds the local one (a local gouge), splitting the pass there.
const FIT_MARGIN: f64 = 0.05;
/// Most lead a flat end mill may need to fit (Can's `S_max`, 2010, §3.4.7.2), for the alternative
/// noted.
const MAX_FLAT_LEAD_DEG: f64 = 20.0;

/// What `--tool` asks for: a cutter given by its SPEC, or `auto`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolSpec {
    Given(CutterShape),
    Auto,
}

impl ToolSpec {
    pub fn parse(spec: &str) -> Result<ToolSpec> {
        if spec == "auto" {
            Ok(ToolSpec::Auto)
        } else {
            Ok(ToolSpec::Given(spec.parse().into_diagnostic()?))
        }
    }
}

/// The chosen cutter, its number in the tool table (when chosen from one) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolPick {
    pub shape: CutterShape,
    pub number: Option<u32>,
    pub why: String,
}

/// A tool table's ball end mills: LinuxCNC tables carry no shape, so a tool counts as a ball
/// when its comment says so ("3 mm ball end mill").
fn table_balls(table: &ToolTable) -> Vec<(u32, f64)> {
    table
        .iter()
        .filter(|t| t.comment.to_lowercase().contains("ball"))
        .filter(|t| t.diameter.is_finite() && t.diameter > 0.0)
        .filter_map(|t| u32::try_from(t.number).ok().map(|n| (n, t.diameter)))
        .collect()
}

/// The largest ball of the table (`Some((file, table))`) or of the standard set that fits
/// `face` (machined on its outside, as the strategy cuts it) — on a trimmed face, within its
/// `region`.
pub fn choose(
    face: &Face,
    region: Option<&FaceRegion>,
    table: Option<(&Path, &ToolTable)>,
) -> Result<ToolPick> {
    let rho = tightest_concave_radius(&face.surface, region, CURVATURE_LATTICE, !face.same_sense);
    let (set, source): (Vec<f64>, String) = match table {
        Some((path, table)) => {
            let balls = table_balls(table);
            if balls.is_empty() {
                return Err(miette!(
                    "--tool auto: {} has no ball end mill (a tool counts as one when its \
                     comment says \"ball\")",
                    path.display()
                ));
            }
            let source = format!("the ball end mills of {}", path.display());
            (balls.iter().map(|b| b.1).collect(), source)
        }
        None => (
            STANDARD_DIAMETERS.to_vec(),
            "the standard set (tezgah_cam::select)".to_owned(),
        ),
    };
    let fit = rho.map(|r| r * (1.0 - FIT_MARGIN));
    let proposal = propose(fit, &set, MAX_FLAT_LEAD_DEG).into_diagnostic()?;
    let Some(diameter) = proposal.ball else {
        return Err(miette!(
            "--tool auto: no ball end mill of {source} fits: the tightest concave radius is \
             {:.3} mm, so a ball must be below {:.3} mm in diameter",
            rho.unwrap_or(f64::INFINITY),
            2.0 * fit.unwrap_or(f64::INFINITY)
        ));
    };
    let number = table.and_then(|(_, t)| {
        table_balls(t)
            .into_iter()
            .find(|b| b.1 == diameter)
            .map(|b| b.0)
    });
    let mut why = match rho {
        Some(r) => format!(
            "the largest ball of {source} below twice the tightest concave radius {r:.3} mm \
             less {:.0} % (diameter < {:.3} mm)",
            100.0 * FIT_MARGIN,
            2.0 * r * (1.0 - FIT_MARGIN)
        ),
        None => format!("the surface is nowhere concave: the largest ball of {source}"),
    };
    if let Some(flat) = proposal.flat {
        if flat.diameter > diameter {
            why.push_str(&format!(
                "; a flat end mill of {} mm at {:.1}° lead would also fit (--tool flat:{} \
                 --lead {:.1})",
                flat.diameter, flat.lead_deg, flat.diameter, flat.lead_deg
            ));
        }
    }
    Ok(ToolPick {
        shape: CutterShape::Ball {
            radius: 0.5 * diameter,
        },
        number,
        why,
    })
}
