//! Spline blocks: LinuxCNC's G5 (cubic), G5.1 (quadratic) and G5.2/G5.3 (NURBS), and Fanuc's
//! G06.2 NURBS block. Each ends in one `NURBS_FEED` canonical call carrying the whole curve in
//! program coordinates; [`crate::moves`] maps its control points to the machine frame.
//!
//! The LinuxCNC codes follow its 2.9 interpreter rule for rule (`convert_spline`,
//! `convert_nurbs`): XY only, I J P Q relative, the G5 start tangent defaulting to the mirror of
//! the previous G5's end tangent, G5.2 control points collected until G5.3 with LinuxCNC's
//! uniform clamped knots. G06.2 is Fanuc's format: `G06.2 P<order> K<knot> X Y Z R<weight>`,
//! one control point with one knot per line, then `order` lines of K alone.

use std::sync::Arc;

use tezgah_geom::basis::MAX_DEGREE;
use tezgah_geom::{Curve, FeedMode, Nurbs, Plane, Pose, Vec3};

use crate::block::Block;
use crate::canon::{Canon, CanonSink, NurbsDialect, NurbsFeed, Origin};
use crate::codes::ggroup;
use crate::error::ErrorKind;

use super::execute::Exec;
use super::motion::inverse_time_rate;
use super::Interpreter;

/// The G6.2 code (ten times 6.2).
pub(super) const G6_2: u32 = 62;

/// Fanuc's orders (ranks): 2 (linear) to 4 (cubic, the default).
const G62_ORDERS: std::ops::RangeInclusive<usize> = 2..=4;
const G62_DEFAULT_ORDER: usize = 4;

/// How far (program units) a G6.2 block's first control point may lie from the current point:
/// the resolution `canon` prints positions at, so a point that prints as the current point is it.
const FIRST_POINT_TOLERANCE: f64 = 1e-4;

/// What the spline blocks remember between blocks.
#[derive(Debug, Clone, Default)]
pub(super) struct SplineMemory {
    /// The start-tangent offset (I, J) of a G5 that gives none: minus the previous G5's P, Q
    /// (LinuxCNC's `cycle_i`, `cycle_j`; zero before any G5).
    g5_ij: [f64; 2],
    /// G5.2 control points (X, Y, weight) collected until G5.3, and the order.
    g52_points: Vec<[f64; 3]>,
    g52_order: usize,
    /// The G6.2 NURBS being read, if one is open.
    g62: Option<Box<G62Block>>,
}

/// A G6.2 NURBS while its lines are read.
#[derive(Debug, Clone)]
struct G62Block {
    /// Where the G6.2 word is: the move belongs to it, and the error when the NURBS is left
    /// unfinished names its line.
    origin: Origin,
    order: usize,
    points: Vec<[f64; 3]>,
    weights: Vec<f64>,
    knots: Vec<f64>,
    /// Lines of K alone read so far.
    closing: usize,
    /// The last control point with its A B C (incremental words are relative to it).
    cursor: Pose,
    /// Under G93, the G6.2 line's F: the NURBS takes `1/F` minutes.
    inverse_time: Option<f64>,
}

/// LinuxCNC's knot vector for `count` control points of order `k` (`knot_vector_creator`):
/// `k` zeros, then 1, 2, … one per inner point, then `k` copies of the last value — uniform
/// and clamped, so the curve starts and ends on its end control points.
fn linuxcnc_knots(count: usize, k: usize) -> Vec<f64> {
    let n = count - 1;
    (0..=n + k)
        .map(|i| {
            if i < k {
                0.0
            } else if i <= n {
                (i - k + 1) as f64
            } else {
                (n + 2 - k) as f64
            }
        })
        .collect()
}

/// Shortest decimal form of a program number for messages.
fn num(v: f64) -> String {
    format!("{v}")
}

impl Interpreter {
    /// G5 and G5.1: one cubic or quadratic Bézier from the current point (LinuxCNC's
    /// `convert_spline`, its checks in its order).
    pub(super) fn spline(
        &mut self,
        block: &Block,
        g: u32,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        let s = &self.state;
        match s.feed_mode {
            FeedMode::UnitsPerMinute if s.feed_rate == 0.0 => {
                return Err((ErrorKind::ArcZeroFeed, at));
            }
            FeedMode::InverseTime if !block.has(b'f') => {
                return Err((ErrorKind::InverseTimeArcMissingF, at));
            }
            _ => {}
        }
        if s.plane != Some(Plane::XY) {
            return Err((ErrorKind::SplineNotXyPlane, at));
        }
        if let Some(w) = [b'z', b'a', b'b', b'c'].iter().find_map(|&c| block.word(c)) {
            return Err((ErrorKind::SplineOffPlaneMotion, w.at));
        }
        let start = s.pos;
        let (x0, y0) = (start.0[0], start.0[1]);
        let (i, j) = (block.get(b'i'), block.get(b'j'));
        let mut points = vec![[x0, y0]];
        if g == 51 {
            let (Some(i), Some(j)) = (i, j) else {
                return Err((ErrorKind::G51NeedsIJ, at));
            };
            points.push([x0 + i, y0 + j]);
            let end = self.find_ends(block).map_err(|k| (k, at))?;
            points.push([end.0[0], end.0[1]]);
        } else {
            let [i, j] = match (i, j) {
                (Some(i), Some(j)) => [i, j],
                (None, None) => self.spline_memory.g5_ij,
                _ => return Err((ErrorKind::G5IJBothOrNeither, at)),
            };
            points.push([x0 + i, y0 + j]);
            let end = self.find_ends(block).map_err(|k| (k, at))?;
            let (Some(p), Some(q)) = (block.get(b'p'), block.get(b'q')) else {
                return Err((ErrorKind::G5NeedsPQ, at));
            };
            points.push([end.0[0] + p, end.0[1] + q]);
            points.push([end.0[0], end.0[1]]);
        }
        let weighted: Vec<[f64; 3]> = points.iter().map(|&[x, y]| [x, y, 1.0]).collect();
        self.emit_linuxcnc_nurbs(&weighted, points.len(), at, sink)?;
        if g == 50 {
            // The next G5 without I and J starts along this one's end tangent.
            if let (Some(p), Some(q)) = (block.get(b'p'), block.get(b'q')) {
                self.spline_memory.g5_ij = [-p, -q];
            }
        }
        Ok(())
    }

    /// G5.2: one control point (or only the first point's weight); LinuxCNC's `convert_nurbs`.
    pub(super) fn nurbs_point(&mut self, block: &Block, at: u32) -> Exec {
        let (x, y) = (block.word(b'x'), block.word(b'y'));
        if let (Some(w), None) | (None, Some(w)) = (x, y) {
            return Err((ErrorKind::NurbsNeedsXY, w.at));
        }
        let bare = x.is_none();
        // LinuxCNC tests the list as the last G5.2 left it, before a new series clears it.
        let stale = !self.spline_memory.g52_points.is_empty();
        let p = block.word(b'p');
        let p_at = p.map_or(at, |w| w.at);
        let weight = p.map(|w| w.value);
        let positive = weight.is_some_and(|w| w > 0.0);
        if bare && positive && stale {
            return Err((ErrorKind::NurbsBareWeight, p_at));
        }
        // LinuxCNC lets a first line with X and Y go without P (its weight is then −1, which no
        // curve survives): tezgah asks for a positive weight on every control point.
        if (stale || !bare) && !positive {
            return Err((ErrorKind::NurbsWeight, p_at));
        }
        if self.state.feed_mode == FeedMode::UnitsPerMinute && self.state.feed_rate == 0.0 {
            return Err((ErrorKind::NurbsZeroFeed, at));
        }
        let order = match block.get(b'l') {
            // LinuxCNC keeps order 3 for any L of 3 or less, and truncates a fraction.
            Some(l) if l > 3.0 => {
                let order = l.min(1e9) as usize;
                if order > MAX_DEGREE + 1 {
                    let l_at = block.word(b'l').map_or(at, |w| w.at);
                    return Err((ErrorKind::NurbsOrderTooHigh(order, MAX_DEGREE + 1), l_at));
                }
                Some(order)
            }
            _ => None,
        };
        let end = match bare {
            true => None,
            false => Some(self.find_ends(block).map_err(|k| (k, at))?),
        };
        let series = self.state.motion == Some(52);
        let memory = &mut self.spline_memory;
        if !series {
            memory.g52_points.clear();
        }
        if memory.g52_points.is_empty() {
            let first_weight = match weight {
                Some(w) if bare && w > 0.0 => w,
                _ => 1.0,
            };
            let pos = self.state.pos;
            memory.g52_points.push([pos.0[0], pos.0[1], first_weight]);
            memory.g52_order = 3;
        }
        if let Some(order) = order {
            memory.g52_order = order;
        }
        if let (Some(end), Some(w)) = (end, weight) {
            memory.g52_points.push([end.0[0], end.0[1], w]);
        }
        Ok(())
    }

    /// G5.3: the collected G5.2 control points become one NURBS feed.
    pub(super) fn nurbs_end(&mut self, at: u32, sink: &mut impl CanonSink) -> Exec {
        if self.state.motion != Some(52) {
            return Err((ErrorKind::G53WithoutG52, at));
        }
        let points = std::mem::take(&mut self.spline_memory.g52_points);
        let order = self.spline_memory.g52_order;
        if points.len() < order {
            return Err((ErrorKind::NurbsTooFewPoints(order), at));
        }
        self.emit_linuxcnc_nurbs(&points, order, at, sink)
    }

    /// One XY NURBS at the current Z from (X, Y, weight) points with LinuxCNC's knots; the
    /// current point moves to the last control point.
    fn emit_linuxcnc_nurbs(
        &mut self,
        points: &[[f64; 3]],
        order: usize,
        at: u32,
        sink: &mut impl CanonSink,
    ) -> Exec {
        let mut end = self.state.pos;
        let z = end.0[2];
        let xyz: Vec<[f64; 3]> = points.iter().map(|p| [p[0], p[1], z]).collect();
        let weights: Vec<f64> = points.iter().map(|p| p[2]).collect();
        let knots = linuxcnc_knots(points.len(), order);
        let curve = build(order, &xyz, &weights, knots).map_err(|e| (e, at))?;
        let last = xyz[xyz.len() - 1];
        end.0[0] = last[0];
        end.0[1] = last[1];
        self.emit(
            sink,
            Canon::NurbsFeed(Box::new(NurbsFeed {
                dialect: NurbsDialect::LinuxCnc,
                curve: Arc::new(curve),
                end,
            })),
        );
        self.state.pos = end;
        Ok(())
    }

    /// Whether a block may come while a G6.2 NURBS is open: only its own lines (and lines with
    /// no words at all, such as comments) may.
    pub(super) fn g62_guard(&self, block: &Block, motion: Option<u32>) -> Exec {
        let Some(open) = &self.spline_memory.g62 else {
            return Ok(());
        };
        let continues = motion == Some(G6_2) && block.g(ggroup::MOTION).is_none();
        let wordless = block.has_no_letter_words()
            && block.g.iter().all(Option::is_none)
            && block.m_count == 0;
        if continues || wordless {
            return Ok(());
        }
        let at = block.g[ggroup::MOTION].map_or(0, |c| c.at);
        Err((
            ErrorKind::G62Unfinished(open.origin.line, open.closing, open.order),
            at,
        ))
    }

    /// A G6.2 line: the G6.2 block itself, a control point line or a closing knot line.
    pub(super) fn g62_line(&mut self, block: &Block, at: u32, sink: &mut impl CanonSink) -> Exec {
        let k = block.word(b'k');
        if block.g(ggroup::MOTION) == Some(G6_2) {
            return self.g62_open(block, at);
        }
        let Some(mut open) = self.spline_memory.g62.take() else {
            let at = k.map_or(at, |w| w.at);
            return Err((ErrorKind::G62StrayKnot, at));
        };
        if let Some(p) = block.word(b'p') {
            return Err((ErrorKind::G62OrderRepeated, p.at));
        }
        let result = if block.has_axis_words() {
            if open.closing > 0 {
                Err((ErrorKind::G62PointAfterKnots, at))
            } else {
                self.g62_point(block, &mut open, at)
            }
        } else {
            // K alone: a closing knot.
            match k {
                Some(k) => push_knot(&mut open, k.value, k.at).map(|()| open.closing += 1),
                None => Err((ErrorKind::G62KnotMissing, at)),
            }
        };
        result?;
        if open.closing == open.order {
            return self.g62_close(*open, at, sink);
        }
        self.spline_memory.g62 = Some(open);
        Ok(())
    }

    /// The G6.2 block: order, feed checks and the first control point (the current point).
    fn g62_open(&mut self, block: &Block, at: u32) -> Exec {
        let order = match block.word(b'p') {
            None => G62_DEFAULT_ORDER,
            Some(p) => {
                let order = p.value as usize;
                if p.value.fract() != 0.0 || p.value < 0.0 || !G62_ORDERS.contains(&order) {
                    return Err((ErrorKind::G62Order(num(p.value)), p.at));
                }
                order
            }
        };
        match self.state.feed_mode {
            FeedMode::UnitsPerMinute if self.state.feed_rate == 0.0 => {
                return Err((ErrorKind::NurbsZeroFeed, at));
            }
            FeedMode::InverseTime if !block.has(b'f') => {
                return Err((ErrorKind::G62InverseTimeMissingF, at));
            }
            _ => {}
        }
        let start = self.state.pos;
        let mut open = G62Block {
            origin: Origin {
                n: None,
                ..self.origin
            },
            order,
            points: Vec::new(),
            weights: Vec::new(),
            knots: Vec::new(),
            closing: 0,
            cursor: start,
            inverse_time: (self.state.feed_mode == FeedMode::InverseTime)
                .then(|| block.get(b'f'))
                .flatten(),
        };
        self.g62_point(block, &mut open, at)?;
        let first = open.points[0];
        let off = (0..3)
            .map(|i| (first[i] - start.0[i]).abs())
            .fold(0.0, f64::max);
        if off > FIRST_POINT_TOLERANCE {
            let here = format!("X{:.4} Y{:.4} Z{:.4}", start.0[0], start.0[1], start.0[2]);
            let axis_at = first_axis_at(block).unwrap_or(at);
            return Err((ErrorKind::G62FirstPoint(here), axis_at));
        }
        // The curve starts exactly where the tool is.
        open.points[0] = [start.0[0], start.0[1], start.0[2]];
        self.spline_memory.g62 = Some(Box::new(open));
        Ok(())
    }

    /// One control point line: K, X Y Z (A B C), R.
    fn g62_point(&self, block: &Block, open: &mut G62Block, at: u32) -> Exec {
        let Some(k) = block.word(b'k') else {
            return Err((ErrorKind::G62KnotMissing, at));
        };
        let weight = match block.word(b'r') {
            None => 1.0,
            Some(r) if r.value > 0.0 => r.value,
            Some(r) => return Err((ErrorKind::G62Weight(num(r.value)), r.at)),
        };
        push_knot(open, k.value, k.at)?;
        // Absolute words, or increments from the previous control point.
        let mut p = open.cursor;
        for (i, word) in block.axis_words().into_iter().enumerate() {
            if let Some(v) = word {
                p.0[i] = if self.state.incremental {
                    p.0[i] + v
                } else {
                    v
                };
            }
        }
        open.points.push([p.0[0], p.0[1], p.0[2]]);
        open.weights.push(weight);
        open.cursor = p;
        Ok(())
    }

    /// The last closing knot: check the whole NURBS and send it.
    fn g62_close(&mut self, open: G62Block, at: u32, sink: &mut impl CanonSink) -> Exec {
        let (order, knots) = (open.order, open.knots.as_slice());
        let n = open.points.len();
        if n < order {
            return Err((ErrorKind::G62TooFewPoints(order, n), at));
        }
        let first = &knots[..order];
        if first.iter().any(|&k| k != first[0]) {
            return Err((ErrorKind::G62NotClamped("first", order, order), at));
        }
        let last = &knots[knots.len() - order..];
        if last.iter().any(|&k| k != last[0]) {
            return Err((ErrorKind::G62NotClamped("last", order, order), at));
        }
        let curve = build(order, &open.points, &open.weights, open.knots).map_err(|e| (e, at))?;
        let end = open.cursor;
        // The move belongs to the G6.2 line that began it, where samples and reports point.
        let origin = open.origin;
        if let Some(f) = open.inverse_time {
            // As a G1 or G2 under G93: the rate that runs the curve's length in 1/F minutes.
            let rate = inverse_time_rate(f, curve.length());
            self.state.feed_rate = rate;
            sink.call(origin, Canon::SetFeedRate(rate));
        }
        sink.call(
            origin,
            Canon::NurbsFeed(Box::new(NurbsFeed {
                dialect: NurbsDialect::Fanuc,
                curve: Arc::new(curve),
                end,
            })),
        );
        self.state.pos = end;
        Ok(())
    }
}

/// Append a knot, which must not be smaller than the one before.
fn push_knot(open: &mut G62Block, k: f64, at: u32) -> Exec {
    if let Some(&prev) = open.knots.last() {
        if k < prev {
            return Err((ErrorKind::G62KnotDecreasing(num(k), num(prev)), at));
        }
    }
    open.knots.push(k);
    Ok(())
}

/// The curve in program coordinates and units, built once: the curve layer's checks (finite
/// values, knot multiplicities, a non-empty domain) are the block's, and the call carries it.
fn build(
    order: usize,
    points: &[[f64; 3]],
    weights: &[f64],
    knots: Vec<f64>,
) -> Result<Nurbs, ErrorKind> {
    let pts: Vec<Vec3> = points.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    Nurbs::new(order - 1, &pts, weights, knots).map_err(|e| ErrorKind::NurbsInvalid(e.to_string()))
}

/// Byte offset of a block's first axis word.
fn first_axis_at(block: &Block) -> Option<u32> {
    crate::block::AXIS_LETTERS
        .iter()
        .filter_map(|&c| block.word(c))
        .map(|w| w.at)
        .min()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linuxcnc_knots_are_uniform_and_clamped() {
        // A cubic Bézier (G5): 4 points of order 4.
        assert_eq!(
            linuxcnc_knots(4, 4),
            [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]
        );
        // G5.2 with 5 points of order 3: one inner knot per extra point.
        assert_eq!(
            linuxcnc_knots(5, 3),
            [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0]
        );
    }
}
