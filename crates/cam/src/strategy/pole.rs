//! A pass along a degenerate edge — a pole, where every contact of the pass is one point — cut
//! as a turn about it. The side steps and the true-cusp check model the pass next to a pole as
//! its neighbours are: at each parameter along the edge a cutter at the pole leaning along that
//! parameter's feed direction. A flat or bull-nose end leaning one way covers only the side it
//! leans toward (its rim rises from the contact on the other), so one location at the pole is
//! not that pass: it left 0.49 mm against a 0.3 mm target 1.3 mm from a sphere's pole. Here the
//! pass keeps the contact at the pole and turns the lean with the feed direction, sampled so the
//! tip's circle is followed within the tolerance. A ball's cut at a point does not depend on its
//! lean, so its pole stays one location.

use super::{Context, SurfacePath};
use crate::cutter::CutterShape;

/// Samples along the edge that detect it (the contacts all within [`SAME_POINT`]) and measure
/// how far the lean turns.
const EDGE_SAMPLES: usize = 64;
/// Contacts this close (mm) are one point.
pub(super) const SAME_POINT: f64 = 1e-7;

impl Context<'_> {
    /// The parameters of a turn about the pole when `path` runs along a degenerate edge and the
    /// cutter is not a ball: each interval of [`EDGE_SAMPLES`] split so the tip moves along its
    /// circle about the contact in chords whose sagitta is within the tolerance. `None` for any
    /// other pass.
    pub(super) fn turn_about_pole(
        &self,
        path: &impl SurfacePath,
        tangent_at: impl Fn(f64) -> (f64, f64),
    ) -> Option<Vec<f64>> {
        if matches!(self.shape(), CutterShape::Ball { .. }) {
            return None;
        }
        let (t0, t1) = path.range();
        let ts: Vec<f64> = (0..=EDGE_SAMPLES)
            .map(|k| t0 + (t1 - t0) * k as f64 / EDGE_SAMPLES as f64)
            .collect();
        let points: Vec<_> = ts
            .iter()
            .map(|&t| {
                let (u, v) = path.uv(t);
                self.surface.point(u, v)
            })
            .collect();
        if !points.iter().all(|p| (p - points[0]).norm() <= SAME_POINT) {
            return None;
        }
        // The tip's offset from the contact at each sample (nominal orientation).
        let offsets: Vec<_> = ts
            .iter()
            .map(|&t| {
                let (u, v) = path.uv(t);
                let local = self.local(u, v, tangent_at(t))?;
                let standing = self.standing(&local)?;
                Some(standing.tip - local.d.point)
            })
            .collect::<Option<_>>()?;
        let tolerance = self.settings.tolerance;
        let mut out = vec![t0];
        for (k, w) in offsets.windows(2).enumerate() {
            let radius = w[0].norm().max(w[1].norm());
            let turned = w[0].angle(&w[1]);
            // Chord of a circle of radius ρ with sagitta ε subtends 2·acos(1 − ε/ρ).
            let per_chord = 2.0 * (1.0 - (tolerance / radius).min(1.0)).acos();
            let pieces = (turned / per_chord).ceil().max(1.0) as usize;
            for j in 1..=pieces {
                out.push(ts[k] + (ts[k + 1] - ts[k]) * j as f64 / pieces as f64);
            }
        }
        Some(out)
    }
}
