//! `--plot DIR`: feed and each joint's velocity, acceleration and jerk over time, as SVG and
//! PNG, drawn with `plotters`.
//!
//! Without a font backend (none is enabled, to keep system libraries out of the build) the
//! plots carry no text: the file name says what is drawn (`x_velocity.svg`, …) and the
//! terminal prints the ranges.

use std::path::Path;

use plotters::prelude::*;
use tezgah_motion::interpolate::Sample;

/// The series to plot, decimated so a long program stays a few thousand points.
pub struct Trace {
    t: Vec<f64>,
    feed: Vec<f64>,
    /// joints[i] = positions in file units.
    joints: Vec<Vec<f64>>,
}

impl Trace {
    pub fn new(n: usize) -> Self {
        Trace {
            t: vec![],
            feed: vec![],
            joints: vec![vec![]; n],
        }
    }

    pub fn push(&mut self, s: &Sample, scales: &[f64]) {
        self.t.push(s.t);
        self.feed.push(s.feed);
        for (i, q) in s.joints.as_slice().iter().enumerate() {
            if let Some(v) = self.joints.get_mut(i) {
                v.push(q * scales[i]);
            }
        }
    }
}

fn diff(x: &[f64], h: f64) -> Vec<f64> {
    x.windows(2).map(|w| (w[1] - w[0]) / h).collect()
}

/// Largest-magnitude point per bucket keeps peaks visible after decimation.
fn decimate(t: &[f64], y: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = y.len().min(t.len());
    let step = n.div_ceil(max.max(1)).max(1);
    (0..n)
        .step_by(step)
        .map(|i| {
            let end = (i + step).min(n);
            let k = (i..end)
                .max_by(|&a, &b| y[a].abs().total_cmp(&y[b].abs()))
                .unwrap_or(i);
            (t[k], y[k])
        })
        .collect()
}

fn draw<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    pts: &[(f64, f64)],
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    area.fill(&WHITE).map_err(|e| e.to_string())?;
    let (t0, t1) = (
        pts.first().map_or(0.0, |p| p.0),
        pts.last().map_or(1.0, |p| p.0),
    );
    let lo = pts.iter().map(|p| p.1).fold(0.0f64, f64::min);
    let hi = pts.iter().map(|p| p.1).fold(0.0f64, f64::max);
    let pad = ((hi - lo) * 0.05).max(1e-9);
    let mut chart = ChartBuilder::on(&area)
        .margin(10)
        .build_cartesian_2d(t0..t1.max(t0 + 1e-9), (lo - pad)..(hi + pad))
        .map_err(|e| e.to_string())?;
    // Zero line.
    chart
        .draw_series(LineSeries::new([(t0, 0.0), (t1, 0.0)], &BLACK))
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), &BLUE))
        .map_err(|e| e.to_string())?;
    area.present().map_err(|e| e.to_string())?;
    Ok(())
}

/// Writes `feed` and `<joint>_{velocity,acceleration,jerk}` as .svg and .png; returns the count.
pub fn write_all(
    dir: &Path,
    trace: &Trace,
    names: &[String],
    period: f64,
) -> Result<usize, String> {
    let mut series: Vec<(String, Vec<f64>, &[f64])> =
        vec![("feed".into(), trace.feed.clone(), &trace.t[..])];
    for (i, q) in trace.joints.iter().enumerate() {
        let v = diff(q, period);
        let a = diff(&v, period);
        let j = diff(&a, period);
        let name = names.get(i).cloned().unwrap_or_else(|| format!("joint{i}"));
        series.push((format!("{name}_velocity"), v, &trace.t[1..]));
        series.push((format!("{name}_acceleration"), a, &trace.t[2..]));
        series.push((format!("{name}_jerk"), j, &trace.t[3..]));
    }
    let mut files = 0;
    for (name, y, t) in &series {
        let pts = decimate(t, y, 4000);
        let svg = dir.join(format!("{name}.svg"));
        draw(SVGBackend::new(&svg, (1000, 400)).into_drawing_area(), &pts)?;
        let png = dir.join(format!("{name}.png"));
        draw(
            BitMapBackend::new(&png, (1000, 400)).into_drawing_area(),
            &pts,
        )?;
        files += 2;
    }
    Ok(files)
}
