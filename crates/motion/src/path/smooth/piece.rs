//! One programmed (or compressed) piece of the tool-tip path while the smoothing builder works
//! on it: its curve, the parameter range left after the blends either side trimmed it, and the
//! move's feed, rotary axes, line and mode. Becomes one [`Segment`] when emitted.

use std::sync::Arc as Shared;

use tezgah_geom::{Arc, ArcLengthMap, Curve, Line, Nurbs, PrebuiltArcLength, Trimmed, Vec3};

use crate::path::orient::{AxisPath, GreatCircle};
use crate::path::{Junction, Segment, SegmentFeed};

/// Arc-length tolerance for the pieces that need a map (splines, arcs of changing radius): far
/// below any path tolerance, so leg lengths and segment lengths are exact for the planner.
pub(crate) const MAP_TOLERANCE: f64 = 1e-9;

/// Largest ratio of span curvatures kept in one segment when a spline is cut for the planner.
const CURVATURE_RATIO: f64 = 2.0;
/// Curvature (1/mm) below which a span counts as flat for the cut (radius 50 mm).
const FLAT_CURVATURE: f64 = 0.02;

/// The path mode a piece was programmed under.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Mode {
    /// G61.1: stop at the end of every block.
    ExactStop,
    /// G61: corners sharp, passed at zero speed.
    ExactPath,
    /// G64: blend (and compress, if on) within the tolerance.
    Continuous,
}

/// The curve kinds a piece can be; one enum so a trimmed piece is `Trimmed<Geo>`.
#[derive(Debug, Clone)]
pub(crate) enum Geo {
    Line(Line),
    /// Boxed like splines: lines, the common case, then set the size of a piece.
    Arc(Box<Arc>),
    /// Shared: splines are rare next to lines, a small enum keeps pieces cheap to move, and
    /// the segments a spline is cut into (see [`Piece::curvature_chunks`]) share one curve.
    Spline(Shared<Nurbs>),
}

impl Curve for Geo {
    fn domain(&self) -> (f64, f64) {
        match self {
            Geo::Line(c) => c.domain(),
            Geo::Arc(c) => c.domain(),
            Geo::Spline(c) => c.domain(),
        }
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        match self {
            Geo::Line(c) => c.derivs(u),
            Geo::Arc(c) => c.derivs(u),
            Geo::Spline(c) => c.derivs(u),
        }
    }
    fn point(&self, u: f64) -> Vec3 {
        match self {
            Geo::Line(c) => c.point(u),
            Geo::Arc(c) => c.point(u),
            Geo::Spline(c) => c.point(u),
        }
    }
    // Forwarded so that a spline's arc-length quadrature evaluates first derivatives only
    // (the default would compute all three through `derivs`).
    fn d1(&self, u: f64) -> Vec3 {
        match self {
            Geo::Line(c) => c.d1(u),
            Geo::Arc(c) => c.d1(u),
            Geo::Spline(c) => c.d1(u),
        }
    }
    // Forwarded so that a spline's panel quadrature looks its knot span up once.
    fn speed_integral(&self, a: f64, b: f64) -> f64 {
        match self {
            Geo::Line(c) => c.speed_integral(a, b),
            Geo::Arc(c) => c.speed_integral(a, b),
            Geo::Spline(c) => c.speed_integral(a, b),
        }
    }
    // Forwarded so that the arc-length map can start evenly paced spline spans with fewer
    // panels (lines and arcs take no map, or run at constant speed).
    fn speed_ratio(&self, a: f64, b: f64) -> Option<f64> {
        match self {
            Geo::Spline(c) => c.speed_ratio(a, b),
            _ => None,
        }
    }
    // Forwarded for the interpolator's panel polynomial (the same span lookup).
    fn gauss_speeds(&self, a: f64, b: f64) -> [f64; 8] {
        match self {
            Geo::Line(c) => c.gauss_speeds(a, b),
            Geo::Arc(c) => c.gauss_speeds(a, b),
            Geo::Spline(c) => c.gauss_speeds(a, b),
        }
    }
    fn curvature(&self, u: f64) -> f64 {
        match self {
            Geo::Line(c) => c.curvature(u),
            Geo::Arc(c) => c.curvature(u),
            Geo::Spline(c) => c.curvature(u),
        }
    }
    fn breakpoints(&self) -> Vec<f64> {
        match self {
            Geo::Line(c) => c.breakpoints(),
            Geo::Arc(c) => c.breakpoints(),
            Geo::Spline(c) => c.breakpoints(),
        }
    }
    fn length(&self) -> f64 {
        match self {
            Geo::Line(c) => c.length(),
            Geo::Arc(c) => c.length(),
            Geo::Spline(c) => c.length(),
        }
    }
}

/// A piece of the path with its trim range `[u0, u1]`.
#[derive(Debug, Clone)]
pub(crate) struct Piece {
    pub geo: Geo,
    /// Arc-length map, only where arc length is not linear in the parameter.
    pub map: Option<Shared<ArcLengthMap>>,
    /// Length of the untrimmed curve, mm.
    pub full_length: f64,
    pub u0: f64,
    pub u1: f64,
    /// A B C at the untrimmed start and end (they move in proportion to arc length).
    pub rotary: [[f64; 3]; 2],
    /// First source line of the piece (a compressed spline reports its first move's line).
    pub line: u32,
    /// Feed of the untrimmed piece (inverse time is scaled to the trimmed length on emission).
    pub feed: SegmentFeed,
    pub tolerance: f64,
    pub mode: Mode,
    /// Number of programmed moves this piece stands for (1, or the run length of a spline).
    pub moves: usize,
    /// The tool axis along the untrimmed piece, in step with its arc length (5-axis under
    /// TCP; `None` where the rotary axes run linearly).
    pub axis: Option<GreatCircle>,
}

impl Piece {
    /// A piece over the whole curve; builds an arc-length map where one is needed.
    pub fn new(
        geo: Geo,
        rotary: [[f64; 3]; 2],
        line: u32,
        feed: SegmentFeed,
        tolerance: f64,
        mode: Mode,
    ) -> Self {
        let needs_map = match &geo {
            Geo::Line(_) => false,
            // A mismatch at rounding level keeps arc length linear in u to ~1e-12 relative.
            Geo::Arc(a) => (a.radius() - a.end_radius()).abs() > 1e-12 * a.radius(),
            Geo::Spline(_) => true,
        };
        let map = if needs_map {
            ArcLengthMap::new(&geo, MAP_TOLERANCE).ok().map(Shared::new)
        } else {
            None
        };
        let full_length = match &map {
            Some(m) => m.length(),
            None => geo.length(),
        };
        let (u0, u1) = geo.domain();
        Piece {
            geo,
            map,
            full_length,
            u0,
            u1,
            rotary,
            line,
            feed,
            tolerance,
            mode,
            moves: 1,
            axis: None,
        }
    }

    /// Fraction of the untrimmed length at parameter `u` (what the axis path runs on).
    pub fn fraction(&self, u: f64) -> f64 {
        let (a, b) = self.geo.domain();
        if u <= a {
            0.0
        } else if u >= b {
            1.0
        } else if self.full_length > 0.0 {
            self.s_at(u) / self.full_length
        } else {
            0.0
        }
    }

    /// The tool axis at parameter `u`, if the piece carries one.
    pub fn axis_at(&self, u: f64) -> Option<tezgah_geom::Vec3> {
        self.axis.map(|g| g.at(self.fraction(u)))
    }

    /// Arc length from the curve's start to `u`.
    pub fn s_at(&self, u: f64) -> f64 {
        match &self.map {
            Some(m) => m.s_at(&self.geo, u),
            None => {
                let (a, b) = self.geo.domain();
                if b > a {
                    (u - a) / (b - a) * self.full_length
                } else {
                    0.0
                }
            }
        }
    }

    /// Parameter at arc length `s` from the curve's start.
    pub fn u_at(&self, s: f64) -> f64 {
        let (a, b) = self.geo.domain();
        match &self.map {
            Some(m) => m.u_at(&self.geo, s),
            None => {
                if self.full_length > 0.0 {
                    a + (b - a) * (s / self.full_length).clamp(0.0, 1.0)
                } else {
                    a
                }
            }
        }
    }

    /// Length of the trimmed range, mm.
    pub fn length(&self) -> f64 {
        (self.s_at(self.u1) - self.s_at(self.u0)).max(0.0)
    }

    /// Rotary axes at parameter `u`, in proportion to arc length.
    pub fn rotary_at(&self, u: f64) -> [f64; 3] {
        let [r0, r1] = self.rotary;
        let (a, b) = self.geo.domain();
        if u <= a {
            return r0;
        }
        if u >= b {
            return r1;
        }
        let f = if self.full_length > 0.0 {
            self.s_at(u) / self.full_length
        } else {
            0.0
        };
        std::array::from_fn(|i| r0[i] + (r1[i] - r0[i]) * f)
    }

    /// Control points of a spline piece (0 for lines and arcs).
    pub fn control_points(&self) -> usize {
        match &self.geo {
            Geo::Spline(n) => n.control_points().len(),
            _ => 0,
        }
    }

    /// The trimmed range `[u0, u1]` cut into parameter ranges of similar curvature: for a
    /// spline, consecutive knot spans stay together while the largest span curvature of the
    /// group is at most [`CURVATURE_RATIO`] times the smallest (curvatures below
    /// [`FLAT_CURVATURE`] count as that floor); lines and arcs stay whole. This is Kelekçi's
    /// (2021, §3.3.1, eq. 3.33) split of a NURBS at its curvature peaks, done at knots so every cut
    /// is C².
    pub fn curvature_chunks(&self) -> Vec<(f64, f64)> {
        let Geo::Spline(c) = &self.geo else {
            return vec![(self.u0, self.u1)];
        };
        let mut cuts = vec![self.u0];
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        let bps = c.breakpoints();
        let inside: Vec<f64> = bps
            .into_iter()
            .filter(|&u| u > self.u0 && u < self.u1)
            .chain(std::iter::once(self.u1))
            .collect();
        let mut a = self.u0;
        for &b in &inside {
            // The span's curvature at its ends and three inner points: a cubic span's
            // curvature varies slowly enough for grouping (a cut in the wrong place only
            // costs a little speed, never tolerance).
            let k = (0..=4)
                .map(|i| c.curvature(a + (b - a) * i as f64 / 4.0))
                .fold(FLAT_CURVATURE, f64::max);
            let (nlo, nhi) = (lo.min(k), hi.max(k));
            if nhi > CURVATURE_RATIO * nlo && a > self.u0 {
                cuts.push(a);
                (lo, hi) = (k, k);
            } else {
                (lo, hi) = (nlo, nhi);
            }
            a = b;
        }
        cuts.push(self.u1);
        cuts.windows(2).map(|w| (w[0], w[1])).collect()
    }

    /// Whether the tip moves at all.
    pub fn moves_tip(&self) -> bool {
        self.full_length > 0.0
    }

    /// Unit tangent and curvature vector (in arc length) at `u`; `None` where the curve
    /// stands still.
    pub fn frame(&self, u: f64) -> Option<(Vec3, Vec3)> {
        frame(&self.geo, u)
    }

    /// The segment for the trimmed range, ending with `end`.
    pub fn into_segment(self, end: Junction) -> Segment {
        let length = self.length();
        let (a, b) = self.geo.domain();
        let whole = self.u0 <= a && self.u1 >= b;
        let rotary = if whole {
            self.rotary
        } else {
            [self.rotary_at(self.u0), self.rotary_at(self.u1)]
        };
        let axis = self.axis.map(|g| {
            AxisPath::Rotate(if whole {
                g
            } else {
                g.part(self.fraction(self.u0), self.fraction(self.u1))
            })
        });
        let feed = match self.feed {
            SegmentFeed::InverseTime(t) if self.full_length > 0.0 => {
                SegmentFeed::InverseTime(t * length / self.full_length)
            }
            f => f,
        };
        // The piece's arc-length map travels with the curve: the interpolator reuses it
        // instead of building one per segment (`Curve::prebuilt_arc_length`).
        let map = self.map.map(|m| {
            let start = m.s_at(&self.geo, self.u0);
            (m, start)
        });
        let curve: Box<dyn Curve + Send + Sync> = if whole {
            Mapped::boxed(self.geo, map)
        } else {
            match Trimmed::new(self.geo.clone(), self.u0, self.u1) {
                Ok(t) => Mapped::boxed(t, map),
                // u0 <= u1 always holds (blends never overlap); keep the curve if not.
                Err(_) => Mapped::boxed(self.geo, map),
            }
        };
        Segment {
            curve,
            length,
            rotary,
            line: self.line,
            feed,
            end,
            tolerance: self.tolerance,
            // The builder stamps the control and override switch in force when it emits it.
            control: tezgah_geom::ToolControl::OFF,
            feed_override: true,
            tool_axis_travel: None,
            axis,
        }
    }
}

/// The whole curve a segment's curve is (a part of): where the piece's map is built.
trait Whole: Curve + Send + Sync + 'static {
    fn whole(&self) -> &Geo;
}

impl Whole for Geo {
    fn whole(&self) -> &Geo {
        self
    }
}

impl Whole for Trimmed<Geo> {
    fn whole(&self) -> &Geo {
        self.inner()
    }
}

/// A segment's curve with the piece's arc-length map (over the whole curve) and the arc
/// length at the segment's start: every `Curve` method is the curve's own, bit for bit, and
/// `prebuilt_arc_length` hands the map on.
struct Mapped<C> {
    curve: C,
    map: Shared<ArcLengthMap>,
    start: f64,
}

impl<C: Whole> Mapped<C> {
    /// The curve boxed, with the map where the piece has one.
    fn boxed(curve: C, map: Option<(Shared<ArcLengthMap>, f64)>) -> Box<dyn Curve + Send + Sync> {
        match map {
            Some((map, start)) => Box::new(Mapped { curve, map, start }),
            None => Box::new(curve),
        }
    }
}

impl<C: Whole> Curve for Mapped<C> {
    fn domain(&self) -> (f64, f64) {
        self.curve.domain()
    }
    fn derivs(&self, u: f64) -> [Vec3; 4] {
        self.curve.derivs(u)
    }
    fn point(&self, u: f64) -> Vec3 {
        self.curve.point(u)
    }
    fn d1(&self, u: f64) -> Vec3 {
        self.curve.d1(u)
    }
    fn speed(&self, u: f64) -> f64 {
        self.curve.speed(u)
    }
    fn speed_integral(&self, a: f64, b: f64) -> f64 {
        self.curve.speed_integral(a, b)
    }
    fn gauss_speeds(&self, a: f64, b: f64) -> [f64; 8] {
        self.curve.gauss_speeds(a, b)
    }
    fn curvature(&self, u: f64) -> f64 {
        self.curve.curvature(u)
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.curve.breakpoints()
    }
    fn speed_ratio(&self, a: f64, b: f64) -> Option<f64> {
        self.curve.speed_ratio(a, b)
    }
    fn length(&self) -> f64 {
        self.curve.length()
    }
    fn prebuilt_arc_length(&self) -> Option<PrebuiltArcLength<'_>> {
        Some(PrebuiltArcLength {
            map: &self.map,
            curve: self.curve.whole(),
            start: self.start,
        })
    }
}

/// Unit tangent `t = C'/|C'|` and curvature vector `κn = (C'' − (C''·t)t)/|C'|²` at `u`.
pub(crate) fn frame<C: Curve + ?Sized>(c: &C, u: f64) -> Option<(Vec3, Vec3)> {
    let [_, d1, d2, _] = c.derivs(u);
    let speed = d1.norm();
    if !(speed > 0.0 && speed.is_finite()) {
        return None;
    }
    let t = d1 / speed;
    let k = (d2 - t * d2.dot(&t)) / (speed * speed);
    Some((t, k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interpolate::Param;

    /// A cubic spline piece of uneven parametric speed, trimmed at both ends as blends leave
    /// it: its segment hands on the piece's map (start = arc length at the trim), the curve
    /// is unchanged, and the interpolator's `s → point` on it is the segment's own arc length
    /// to within the map tolerance (checked against a map built on the segment at 1e-12), with
    /// the point `C(u)`.
    #[test]
    fn trimmed_spline_segment_carries_the_piece_map() {
        let pts = [
            [0.0, 0.0, 0.0],
            [3.0, 0.5, 0.1],
            [5.0, 4.0, 0.0],
            [12.0, 5.0, -0.2],
            [13.0, 11.0, 0.0],
            [20.0, 10.0, 0.3],
        ]
        .map(|p| Vec3::new(p[0], p[1], p[2]));
        let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0];
        let nurbs = Nurbs::new(3, &pts, &[1.0; 6], knots).unwrap();
        let mut piece = Piece::new(
            Geo::Spline(Shared::new(nurbs)),
            [[0.0; 3]; 2],
            1,
            SegmentFeed::Feed(600.0),
            0.01,
            Mode::Continuous,
        );
        let map = piece.map.clone().expect("a spline piece has a map");
        piece.u0 = 0.2;
        piece.u1 = 2.7;
        let start = map.s_at(&piece.geo, 0.2);
        let seg = piece.clone().into_segment(Junction::Smooth);
        let pre = seg
            .curve
            .prebuilt_arc_length()
            .expect("the map is handed on");
        assert!(
            std::ptr::eq(pre.map, &*map),
            "the piece's own map, not a copy"
        );
        assert_eq!(pre.start, start);
        assert_eq!(seg.curve.domain(), (0.2, 2.7));
        for k in 0..=20 {
            let u = 0.2 + 2.5 * k as f64 / 20.0;
            assert_eq!(seg.curve.point(u), pre.curve.point(u));
            assert_eq!(seg.curve.point(u), piece.geo.point(u));
        }
        let fine = ArcLengthMap::new(&*seg.curve, 1e-12).unwrap();
        assert!((fine.length() - seg.length).abs() <= 2e-9);
        let mut param = Param::new(&seg);
        for k in 0..400 {
            let s = seg.length * k as f64 / 400.0;
            let (u, point) = param.at(&seg, s);
            assert!((fine.s_at(&*seg.curve, u) - s).abs() <= 2e-9, "s = {s}");
            // The cursor may take C(u) from its Newton step's Taylor series: rounding apart.
            assert!((point - piece.geo.point(u)).norm() <= 1e-12 * (1.0 + point.norm()));
        }
    }
}
