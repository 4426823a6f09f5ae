//! Tracking metrics of a run on a drive, as Kelekçi (2021, ch. 5, eq. 5.1) reports them: per joint
//! the RMSE, MSE and largest |following error|, and the contour error — the distance of the
//! actual tool tip from the commanded *path*, not from the commanded point (a lag along the
//! path is no contour error). The executor feeds them one period at a time after the drive's
//! status comes back; nothing allocates per period.

use nalgebra::Vector3;
use tezgah_kinematics::pose::MAX_JOINTS;

use super::DriveStatus;

/// Per-joint following-error statistics (internal units: mm or rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointTracking {
    joints: usize,
    samples: u64,
    sum_sq: [f64; MAX_JOINTS],
    max_abs: [f64; MAX_JOINTS],
}

impl JointTracking {
    pub fn new(joints: usize) -> JointTracking {
        JointTracking {
            joints: joints.min(MAX_JOINTS),
            samples: 0,
            sum_sq: [0.0; MAX_JOINTS],
            max_abs: [0.0; MAX_JOINTS],
        }
    }

    /// Adds one period's following errors.
    pub fn record(&mut self, status: &DriveStatus) {
        self.samples += 1;
        for (i, e) in status
            .following_error
            .as_slice()
            .iter()
            .take(self.joints)
            .enumerate()
        {
            self.sum_sq[i] += e * e;
            self.max_abs[i] = self.max_abs[i].max(e.abs());
        }
    }

    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Mean squared error of `joint` (eq. 5.1: (1/n)Σe²); 0 before any sample.
    pub fn mse(&self, joint: usize) -> f64 {
        if self.samples == 0 || joint >= self.joints {
            return 0.0;
        }
        self.sum_sq[joint] / self.samples as f64
    }

    /// Root mean squared error of `joint` (eq. 5.1).
    pub fn rmse(&self, joint: usize) -> f64 {
        self.mse(joint).sqrt()
    }

    /// Largest |following error| of `joint`.
    pub fn max(&self, joint: usize) -> f64 {
        if joint >= self.joints {
            return 0.0;
        }
        self.max_abs[joint]
    }
}

/// Contour-error statistics (mm).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContourStats {
    pub samples: u64,
    pub rmse: f64,
    pub max: f64,
}

/// The distance of each actual tip from the polyline of commanded tips around it.
///
/// The actual tip at period k lags (or, with feed-forward, slightly leads) the commanded one,
/// so it is measured against the commanded polyline from k − H to k + H periods: the result is
/// given H periods late. Searching only this window keeps a neighbouring pass of the path (a
/// pocket's next lane) from counting as "the path"; H must exceed the lag in periods (the lag
/// is about 1/K_p without feed-forward: 8 ms at 20 Hz).
#[derive(Debug, Clone)]
pub struct ContourError {
    half_window: usize,
    /// Ring of (commanded, actual) tips, 2H + 1 long.
    ring: Vec<(Vector3<f64>, Vector3<f64>)>,
    pushed: u64,
    evaluated: u64,
    /// Tips measured before the last [`ContourError::restart_stats`].
    excluded: u64,
    sum_sq: f64,
    max: f64,
}

/// Default half-window, periods (100 ms at 1 ms).
pub const DEFAULT_HALF_WINDOW: usize = 100;

impl ContourError {
    /// A half-window of `half_window` periods (at least 1).
    pub fn new(half_window: usize) -> ContourError {
        let h = half_window.max(1);
        ContourError {
            half_window: h,
            ring: vec![(Vector3::zeros(), Vector3::zeros()); 2 * h + 1],
            pushed: 0,
            evaluated: 0,
            excluded: 0,
            sum_sq: 0.0,
            max: 0.0,
        }
    }

    /// Adds one period's commanded and actual tips (for a Cartesian machine, the first three
    /// joints; otherwise the forward kinematics of the commanded and measured joints).
    pub fn push(&mut self, commanded: Vector3<f64>, actual: Vector3<f64>) {
        let cap = self.ring.len() as u64;
        self.ring[(self.pushed % cap) as usize] = (commanded, actual);
        self.pushed += 1;
        if self.pushed > self.half_window as u64 {
            self.evaluate_next();
        }
    }

    /// Measures the tips still waiting for their window to fill and returns the statistics.
    pub fn finish(&mut self) -> ContourStats {
        while self.evaluated < self.pushed {
            self.evaluate_next();
        }
        self.stats()
    }

    /// Statistics of the tips measured so far.
    pub fn stats(&self) -> ContourStats {
        let n = self.evaluated - self.excluded;
        ContourStats {
            samples: n,
            rmse: if n == 0 {
                0.0
            } else {
                (self.sum_sq / n as f64).sqrt()
            },
            max: self.max,
        }
    }

    /// Leaves out of the statistics every tip pushed so far (a warm-up), keeping them as the
    /// path the later tips are measured against.
    pub fn restart_stats(&mut self) {
        // tips pushed but not yet measured (the last H) belong to the warm-up too
        self.excluded = self.pushed;
        self.sum_sq = 0.0;
        self.max = 0.0;
    }

    fn evaluate_next(&mut self) {
        let cap = self.ring.len() as u64;
        let k = self.evaluated;
        let h = self.half_window as u64;
        let first = k.saturating_sub(h);
        let last = (k + h).min(self.pushed - 1);
        let p = self.ring[(k % cap) as usize].1;
        let at = |i: u64| self.ring[(i % cap) as usize].0;
        let mut best = (p - at(first)).norm_squared();
        for i in first..last {
            best = best.min(segment_distance_sq(&p, &at(i), &at(i + 1)));
        }
        self.evaluated += 1;
        if self.evaluated > self.excluded {
            self.sum_sq += best;
            self.max = self.max.max(best.sqrt());
        }
    }
}

impl Default for ContourError {
    fn default() -> Self {
        ContourError::new(DEFAULT_HALF_WINDOW)
    }
}

/// Squared distance from `p` to the segment [a, b].
fn segment_distance_sq(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = b - a;
    let len_sq = d.norm_squared();
    let t = if len_sq > 0.0 {
        ((p - a).dot(&d) / len_sq).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + d * t)).norm_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_kinematics::Joints;

    #[test]
    fn rmse_and_max_follow_eq_5_1() {
        let mut t = JointTracking::new(2);
        for e in [1.0, -2.0, 2.0] {
            t.record(&DriveStatus {
                position: Joints::zeros(2),
                following_error: Joints::new([e, 0.5]),
                fault: None,
            });
        }
        assert_eq!(t.samples(), 3);
        assert!((t.mse(0) - 3.0).abs() < 1e-15);
        assert!((t.rmse(0) - 3f64.sqrt()).abs() < 1e-15);
        assert_eq!(t.max(0), 2.0);
        assert!((t.rmse(1) - 0.5).abs() < 1e-15);
        assert_eq!(t.rmse(5), 0.0);
    }

    #[test]
    fn a_lag_along_the_path_is_no_contour_error() {
        // Actual = commanded 5 periods late on a straight line: following error 5·v·Ts, contour 0.
        let mut c = ContourError::new(20);
        let dir = Vector3::new(3.0, 4.0, 0.0) / 5.0;
        for k in 0..300 {
            let s = |k: i64| dir * (0.05 * k.max(0) as f64);
            c.push(s(k), s(k - 5));
        }
        let st = c.finish();
        assert_eq!(st.samples, 300);
        assert!(st.max < 1e-12, "{}", st.max);
    }

    #[test]
    fn a_circle_lagging_inside_has_its_radial_error() {
        // Commanded on radius R, actual on radius R − δ and 3 periods behind: contour error δ
        // up to the chord sag of the commanded polyline, R(1 − cos(Δθ/2)).
        let (r, delta, dtheta) = (10.0, 0.002, 0.01);
        let mut c = ContourError::new(10);
        for k in 0..2000 {
            let th = k as f64 * dtheta;
            let lag = (k as f64 - 3.0).max(0.0) * dtheta;
            c.push(
                Vector3::new(r * th.cos(), r * th.sin(), 1.0),
                Vector3::new((r - delta) * lag.cos(), (r - delta) * lag.sin(), 1.0),
            );
        }
        let st = c.finish();
        let sag = r * (1.0 - (dtheta / 2.0).cos());
        assert!(
            st.max <= delta + 1e-12 && st.max >= delta - sag - 1e-12,
            "{}",
            st.max
        );
        assert!(st.rmse <= delta + 1e-12 && st.rmse >= delta - sag - 1e-12);
    }

    #[test]
    fn the_window_ignores_a_neighbouring_pass() {
        // Two parallel lanes 1 mm apart, joined at the end: the actual tip 0.7 mm off lane one
        // toward lane two is 0.7 mm off its path, though 0.3 mm from the other lane.
        let mut c = ContourError::new(10);
        let mut pts = Vec::new();
        for k in 0..100 {
            pts.push(Vector3::new(k as f64 * 0.1, 0.0, 0.0));
        }
        for k in (0..100).rev() {
            pts.push(Vector3::new(k as f64 * 0.1, 1.0, 0.0));
        }
        for (k, p) in pts.iter().enumerate() {
            let off = if k < 100 { 0.7 } else { -0.7 };
            c.push(*p, p + Vector3::new(0.0, off, 0.0));
        }
        let st = c.finish();
        assert!((st.max - 0.7).abs() < 1e-12, "{}", st.max);
    }
}
