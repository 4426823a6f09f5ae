//! Slack: the time a plan spends below the programmed feed with no joint within
//! [`NEAR_LIMIT`] of any of its limits — what the plan leaves on the table — and the time at
//! each fraction of the feed. Joint ratios are the replay's finite differences at the period.

use crate::path::{Segment, SegmentFeed};

/// A joint at or above this share of a limit (velocity, acceleration or jerk) is "at" it.
pub const NEAR_LIMIT: f64 = 0.9;

/// Histogram bins: `[0, 10 %)`, …, `[90 %, 100 %)` of the nominal speed, then `≥ 100 %`.
pub const BINS: usize = 11;

/// A sample at or above this share of its nominal speed is at the feed (cruise at the feed
/// reads back within rounding of it).
const AT_FEED: f64 = 1.0 - 1e-9;

/// Where the time went, seconds (one period per sample).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Slack {
    /// Below the nominal speed with every joint below [`NEAR_LIMIT`] of every limit.
    pub slack: f64,
    /// On a segment (the histogram's total).
    pub moving: f64,
    /// In dwells (no segment: standing still as programmed, neither slack nor in the
    /// histogram).
    pub dwell: f64,
    /// Time at each fraction of the nominal speed ([`BINS`]).
    pub histogram: [f64; BINS],
}

impl Slack {
    /// The slack as a share of `cycle` seconds (0 for an empty cycle).
    pub fn share(&self, cycle: f64) -> f64 {
        if cycle > 0.0 {
            self.slack / cycle
        } else {
            0.0
        }
    }

    /// Counts one sample of `period` s at path speed `speed` on `seg` (`None`: a dwell), the
    /// worst joint ratio `worst` (peak/limit over v, a, j) and the largest velocity ratio
    /// `velocity`.
    pub(crate) fn push(
        &mut self,
        period: f64,
        seg: Option<&Segment>,
        speed: f64,
        worst: f64,
        velocity: f64,
    ) {
        let Some(seg) = seg else {
            self.dwell += period;
            return;
        };
        self.moving += period;
        let f = fraction(seg, speed, velocity);
        let bin = if f >= AT_FEED {
            BINS - 1
        } else {
            ((f * 10.0).floor().max(0.0) as usize).min(BINS - 2)
        };
        self.histogram[bin] += period;
        if f < AT_FEED && worst < NEAR_LIMIT {
            self.slack += period;
        }
    }
}

/// The sample's speed over its segment's nominal speed: the programmed feed (G94/G95), the
/// segment's length over its time (G93), and for a rapid the speed at which the first joint
/// reaches its velocity limit moving as it does — the largest joint velocity ratio itself.
fn fraction(seg: &Segment, speed: f64, velocity: f64) -> f64 {
    let nominal = match seg.feed {
        SegmentFeed::Feed(f) => f,
        SegmentFeed::InverseTime(t) if t > 0.0 => seg.path_length() / t,
        SegmentFeed::InverseTime(_) => f64::INFINITY,
        SegmentFeed::Rapid => return velocity,
    };
    if nominal > 0.0 {
        speed / nominal
    } else {
        f64::INFINITY
    }
}
