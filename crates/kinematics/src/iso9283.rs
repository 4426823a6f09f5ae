//! ISO 9283 pose accuracy (AP) and pose repeatability (RP) from repeated measurements of
//! commanded poses, as Ayyıldız (2017, eqs 3.16–3.19) reports them. A report-side tool:
//! it reads a CSV of commanded and attained positions and knows nothing of machines.

use std::collections::BTreeMap;

use nalgebra::Vector3;
use thiserror::Error;

/// One measurement: the pose it belongs to, what was commanded and where the tool was.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    /// Pose label (e.g. `P1`).
    pub pose: String,
    /// Commanded position, mm.
    pub commanded: Vector3<f64>,
    /// Attained (measured) position, mm.
    pub attained: Vector3<f64>,
}

/// AP and RP of one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseResult {
    /// Pose label.
    pub pose: String,
    /// Number of measurements n.
    pub n: usize,
    /// Commanded position.
    pub commanded: Vector3<f64>,
    /// Barycentre of the attained positions (eq. 3.17).
    pub mean: Vector3<f64>,
    /// AP = |mean − commanded| (eq. 3.16), mm.
    pub ap: f64,
    /// l̄, mean distance of the attained positions from their barycentre, mm.
    pub l_mean: f64,
    /// S_l, sample standard deviation of those distances (n − 1), mm (eq. 3.19).
    pub s_l: f64,
    /// RP = l̄ + 3·S_l (eq. 3.18), mm.
    pub rp: f64,
}

/// All poses, in order of first appearance, with the means over poses the thesis reports.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Per pose.
    pub poses: Vec<PoseResult>,
    /// Mean AP over poses, mm.
    pub mean_ap: f64,
    /// Mean RP over poses, mm.
    pub mean_rp: f64,
}

/// Why measurements could not be evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Iso9283Error {
    /// The header lacks a column.
    #[error("CSV header lacks column `{0}` (needs pose, cmd_x, cmd_y, cmd_z, x, y, z)")]
    MissingColumn(&'static str),
    /// A field is not a number or a row is short.
    #[error("CSV line {line}: {reason}")]
    BadRow {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A pose has fewer than two measurements (S_l needs n − 1 > 0).
    #[error("pose `{0}` has fewer than 2 measurements")]
    TooFew(String),
    /// The rows of one pose disagree on the commanded position.
    #[error("pose `{0}` has different commanded positions")]
    CommandedDiffers(String),
    /// No measurements at all.
    #[error("no measurements")]
    Empty,
}

/// Reads `pose,cmd_x,cmd_y,cmd_z,x,y,z` (columns found by name, any order, extra columns
/// such as `cycle` ignored; blank lines and lines starting with `#` skipped).
pub fn parse_csv(text: &str) -> Result<Vec<Measurement>, Iso9283Error> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((_, header)) = lines.next() else {
        return Err(Iso9283Error::Empty);
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    const NAMES: [&str; 7] = ["pose", "cmd_x", "cmd_y", "cmd_z", "x", "y", "z"];
    let mut idx = [0usize; 7];
    for (slot, name) in idx.iter_mut().zip(NAMES) {
        *slot = cols
            .iter()
            .position(|c| *c == name)
            .ok_or(Iso9283Error::MissingColumn(name))?;
    }
    let mut out = Vec::new();
    for (i, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        let get = |k: usize| -> Result<f64, Iso9283Error> {
            let s = f.get(idx[k]).ok_or_else(|| Iso9283Error::BadRow {
                line: i + 1,
                reason: format!("missing `{}`", NAMES[k]),
            })?;
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| Iso9283Error::BadRow {
                    line: i + 1,
                    reason: format!("`{}` = `{s}` is not a finite number", NAMES[k]),
                })
        };
        let pose = f.get(idx[0]).ok_or_else(|| Iso9283Error::BadRow {
            line: i + 1,
            reason: "missing `pose`".into(),
        })?;
        out.push(Measurement {
            pose: (*pose).to_owned(),
            commanded: Vector3::new(get(1)?, get(2)?, get(3)?),
            attained: Vector3::new(get(4)?, get(5)?, get(6)?),
        });
    }
    Ok(out)
}

/// Evaluates AP and RP per pose (Ayyıldız, 2017, eqs 3.16–3.19).
pub fn evaluate(measurements: &[Measurement]) -> Result<Report, Iso9283Error> {
    if measurements.is_empty() {
        return Err(Iso9283Error::Empty);
    }
    let mut order: Vec<&str> = Vec::new();
    let mut groups: BTreeMap<&str, Vec<&Measurement>> = BTreeMap::new();
    for m in measurements {
        let g = groups.entry(m.pose.as_str()).or_default();
        if g.is_empty() {
            order.push(m.pose.as_str());
        } else if g[0].commanded != m.commanded {
            return Err(Iso9283Error::CommandedDiffers(m.pose.clone()));
        }
        g.push(m);
    }
    let mut poses = Vec::with_capacity(order.len());
    for name in order {
        let g = &groups[name];
        let n = g.len();
        if n < 2 {
            return Err(Iso9283Error::TooFew(name.to_owned()));
        }
        let nf = n as f64;
        let mean = g.iter().map(|m| m.attained).sum::<Vector3<f64>>() / nf;
        let commanded = g[0].commanded;
        let l: Vec<f64> = g.iter().map(|m| (m.attained - mean).norm()).collect();
        let l_mean = l.iter().sum::<f64>() / nf;
        let s_l = (l.iter().map(|x| (x - l_mean).powi(2)).sum::<f64>() / (nf - 1.0)).sqrt();
        poses.push(PoseResult {
            pose: name.to_owned(),
            n,
            commanded,
            mean,
            ap: (mean - commanded).norm(),
            l_mean,
            s_l,
            rp: l_mean + 3.0 * s_l,
        });
    }
    let k = poses.len() as f64;
    Ok(Report {
        mean_ap: poses.iter().map(|p| p.ap).sum::<f64>() / k,
        mean_rp: poses.iter().map(|p| p.rp).sum::<f64>() / k,
        poses,
    })
}
