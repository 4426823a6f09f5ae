//! `--plot DIR`: feed and each joint's velocity, acceleration and jerk over time, as SVG and
//! PNG, drawn with `plotters`: a title, axes with units and tick labels, and the joint's
//! limits as red lines at ±the limit.
//!
//! Text is laid out and drawn by plotters' pure-Rust `ab_glyph` backend with DejaVu Sans
//! bundled in the binary (`assets/fonts`, its licence alongside) and registered at run time,
//! so no system font library is needed.

use std::path::Path;
use std::sync::OnceLock;

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

/// DejaVu Sans (Bitstream Vera licence, `assets/fonts/DejaVuSans-LICENSE.txt`).
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Registers the bundled font as plotters' `sans-serif`, once.
fn font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
                .map_err(|_| "the bundled font DejaVu Sans could not be read".to_owned())
        })
        .clone()
}

/// A joint as plotted: its name, unit and limits (velocity, acceleration, jerk).
pub struct JointInfo {
    pub name: String,
    /// "mm" or "deg".
    pub unit: &'static str,
    pub limits: [f64; 3],
}

/// One plot: what is drawn and how it is labelled.
struct Plot<'a> {
    title: String,
    /// The y axis' label with its unit.
    y_label: String,
    /// Drawn at ±limit when finite.
    limit: Option<f64>,
    pts: &'a [(f64, f64)],
}

fn draw<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    plot: &Plot,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let pts = plot.pts;
    area.fill(&WHITE).map_err(|e| e.to_string())?;
    let (t0, t1) = (
        pts.first().map_or(0.0, |p| p.0),
        pts.last().map_or(1.0, |p| p.0),
    );
    let mut lo = pts.iter().map(|p| p.1).fold(0.0f64, f64::min);
    let mut hi = pts.iter().map(|p| p.1).fold(0.0f64, f64::max);
    let limit = plot.limit.filter(|l| l.is_finite() && *l > 0.0);
    if let Some(l) = limit {
        lo = lo.min(-l);
        hi = hi.max(l);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    let mut chart = ChartBuilder::on(&area)
        .caption(&plot.title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(t0..t1.max(t0 + 1e-9), (lo - pad)..(hi + pad))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(&plot.y_label)
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 15))
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(|e| e.to_string())?;
    // Zero line.
    chart
        .draw_series(LineSeries::new([(t0, 0.0), (t1, 0.0)], &BLACK))
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), &BLUE))
        .map_err(|e| e.to_string())?
        .label(plot.title.split(" — ").next().unwrap_or(""))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE));
    if let Some(l) = limit {
        for y in [l, -l] {
            chart
                .draw_series(LineSeries::new([(t0, y), (t1, y)], RED.stroke_width(2)))
                .map_err(|e| e.to_string())?;
        }
        chart
            .draw_series(std::iter::once(PathElement::new([(t0, l), (t0, l)], RED)))
            .map_err(|e| e.to_string())?
            .label(format!("limit ±{}", tick(l)))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| e.to_string())?;
    area.present().map_err(|e| e.to_string())?;
    Ok(())
}

/// A tick label: short, in scientific notation only for very large or small values.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e6).contains(&a) {
        format!("{v:.1e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

/// Writes `feed` and `<joint>_{velocity,acceleration,jerk}` as .svg and .png, titled with
/// `program`; returns the count.
pub fn write_all(
    dir: &Path,
    trace: &Trace,
    joints: &[JointInfo],
    period: f64,
    program: &str,
) -> Result<usize, String> {
    font()?;
    struct Series<'a> {
        file: String,
        title: String,
        y_label: String,
        limit: Option<f64>,
        y: Vec<f64>,
        t: &'a [f64],
    }
    let mut series = vec![Series {
        file: "feed".into(),
        title: format!("Feed — {program}"),
        y_label: "path speed (mm/s)".into(),
        limit: None,
        y: trace.feed.clone(),
        t: &trace.t[..],
    }];
    let t = |k: usize| trace.t.get(k..).unwrap_or(&[]);
    for (i, q) in trace.joints.iter().enumerate() {
        let v = diff(q, period);
        let a = diff(&v, period);
        let j = diff(&a, period);
        let (name, unit, limits) = match joints.get(i) {
            Some(info) => (info.name.clone(), info.unit, info.limits),
            None => (format!("joint{i}"), "units", [f64::NAN; 3]),
        };
        for (k, (what, y, power)) in [
            ("velocity", v, "/s"),
            ("acceleration", a, "/s²"),
            ("jerk", j, "/s³"),
        ]
        .into_iter()
        .enumerate()
        {
            series.push(Series {
                file: format!("{name}_{what}"),
                title: format!("{} {what} — {program}", name.to_uppercase()),
                y_label: format!("{what} ({unit}{power})"),
                limit: Some(limits[k]),
                y,
                t: t(k + 1),
            });
        }
    }
    let mut files = 0;
    for s in &series {
        let pts = decimate(s.t, &s.y, 4000);
        let plot = Plot {
            title: s.title.clone(),
            y_label: s.y_label.clone(),
            limit: s.limit,
            pts: &pts,
        };
        let svg = dir.join(format!("{}.svg", s.file));
        draw(
            SVGBackend::new(&svg, (1000, 400)).into_drawing_area(),
            &plot,
        )?;
        let png = dir.join(format!("{}.png", s.file));
        draw(
            BitMapBackend::new(&png, (1000, 400)).into_drawing_area(),
            &plot,
        )?;
        files += 2;
    }
    Ok(files)
}
