//! The smoothing path builder (G64): typed moves in, [`PathItem`]s out, with short G1 runs
//! compressed into C² splines ([`compress`]) and every remaining corner rounded by a G2 quintic
//! micro-spline ([`blend`]), all within the path tolerance. G61 and G61.1 pass through unblended.
//!
//! **Streaming, bounded memory.** [`Smoother`] pulls at most [`SmoothOptions::window`] moves at
//! a time, compresses and blends them, and holds back only the last piece (its end junction
//! depends on the next move). Memory is O(window) whatever the program's length; a compressed
//! run never spans two windows (the join of the two splines is then blended like any corner).
//!
//! **Tolerance budget** (ARCHITECTURE.md, "One tolerance budget"): with `ε` the tolerance in force,
//! compression keeps its splines within `compression_share·ε` (default 0.4) of the programmed
//! polyline, a blend stays within `blend_share·ε` (0.4) of the curves it joins, and the planner's
//! chord error gets the rest, at least [`CHORD_SHARE`]`·ε` (0.2). A blend next to a spline is
//! measured against the spline, so by the triangle inequality the path stays within
//! `(compression_share + blend_share)·ε` of the program, and the samples within `ε`.

mod axis;
pub mod blend;
pub(crate) mod bound;
mod compress;
mod error;
mod piece;

use std::collections::VecDeque;
use std::sync::Arc as Shared;

use tezgah_geom::{
    Arc, FeedMode, Line, Move, MoveKind, PathMode, Pose, StopKind, ToolControl, Vec3,
};

pub use blend::{Blend, End};
pub use error::PathError;

use crate::path::orient::{AxisBlend, AxisPath, GreatCircle, ProgramPoint, ToolAxisMap};
use crate::path::{Junction, PathItem, Segment, SegmentFeed};
use blend::{NoBlend, Placed};
use piece::{Geo, Mode, Piece};

/// The share of the tolerance left to the feed planner's chord error (and interpolation):
/// the planner must keep its chords within `CHORD_SHARE · segment.tolerance`.
pub const CHORD_SHARE: f64 = 0.2;

/// What the smoothing builder may do, and within what. Every field has a documented default.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothOptions {
    /// Path tolerance, mm, used until a `G64 P` gives one (the machine file's `tolerance_mm`).
    /// Default 0.01 mm.
    pub tolerance: f64,
    /// Compress runs of short G1 moves into splines (G64; `G05.1 Q1` will set the same flag).
    /// Default on.
    pub compress: bool,
    /// Longest G1 move (mm) counted as "short" for compression. Default 1 mm: CAM surfacing
    /// output is 0.05–0.5 mm; longer moves are the programmer's intent and are only blended.
    pub short_segment: f64,
    /// Largest turn (rad) between consecutive moves inside a compressed run; a sharper vertex
    /// ends the run and stays a corner (to be blended). Default 30°.
    pub compress_corner_angle: f64,
    /// Largest turn (rad) that is blended; sharper (near-reversal) corners stay `Corner`: the
    /// quintic's speed dips to `cos(φ/2)` at mid-blend (the line–line quintic), a cusp at 180°.
    /// Default 175°.
    pub blend_max_angle: f64,
    /// Share of the tolerance for compression. Default 0.4.
    pub compression_share: f64,
    /// Share of the tolerance for corner blends. Default 0.4.
    pub blend_share: f64,
    /// The angular tolerance (degrees; the machine file's `[path] axis_tolerance_deg`): under
    /// TCP with an [`Self::orientation`], the largest angle between the tool axis and the
    /// programmed one, of which a blend may take `1 − CHORD_SHARE`; otherwise the largest
    /// deviation of a rotary axis across a blend from its programmed value at the corner.
    /// Default 0.1°.
    pub angular_tolerance: f64,
    /// The machine's tool axis for the program angles (5-axis under TCP): with it, each move
    /// carries its tool axis on a great circle and blends carry it by the two-curve method
    /// ([`crate::path::orient`]); without it (and with TCP off) A B C run linearly.
    pub orientation: Option<Orientation>,
    /// Where the tool stands before the first move (work frame, mm and degrees).
    pub start: Pose,
    /// Moves read and processed at a time (bounded memory). Default 512.
    pub window: usize,
    /// Tool control before the program switches it (the machine file's `tcp`). Default TCP
    /// off.
    pub control: ToolControl,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        SmoothOptions {
            tolerance: 0.01,
            compress: true,
            short_segment: 1.0,
            compress_corner_angle: 30f64.to_radians(),
            blend_max_angle: 175f64.to_radians(),
            compression_share: 0.4,
            blend_share: 0.4,
            angular_tolerance: 0.1,
            start: Pose::ZERO,
            window: 512,
            control: ToolControl::OFF,
            orientation: None,
        }
    }
}

impl SmoothOptions {
    /// The options a machine runs with: the builder's defaults, then what the machine file's
    /// `[path]` table sets, the tolerance in force, and the machine itself for the tool axis
    /// of the program angles (5-axis under TCP). `tezgah run`, `check --machine` and the
    /// executor all build their paths from these, so they follow the same path.
    pub fn for_machine(
        path: &tezgah_kinematics::machine::PathSettings,
        machine: &crate::plan::PlanMachine,
        tolerance: f64,
        start: Pose,
    ) -> SmoothOptions {
        let d = SmoothOptions::default();
        SmoothOptions {
            tolerance,
            start,
            control: machine.initial,
            orientation: Some(Orientation(Shared::new(machine.clone()))),
            angular_tolerance: path.axis_tolerance_deg.unwrap_or(d.angular_tolerance),
            blend_max_angle: path
                .blend_max_angle_deg
                .map_or(d.blend_max_angle, f64::to_radians),
            compress_corner_angle: path
                .compress_corner_angle_deg
                .map_or(d.compress_corner_angle, f64::to_radians),
            short_segment: path.short_segment_mm.unwrap_or(d.short_segment),
            ..d
        }
    }

    /// Check every field; the shares must leave at least [`CHORD_SHARE`] to the planner.
    pub fn validate(&self) -> Result<(), PathError> {
        let pos = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(PathError::Option { name, value: v })
            }
        };
        pos("tolerance", self.tolerance)?;
        pos("short_segment", self.short_segment)?;
        pos("compress_corner_angle", self.compress_corner_angle)?;
        pos("blend_max_angle", self.blend_max_angle)?;
        pos("compression_share", self.compression_share)?;
        pos("blend_share", self.blend_share)?;
        pos("angular_tolerance", self.angular_tolerance)?;
        let shares = self.compression_share + self.blend_share;
        if shares > 1.0 - CHORD_SHARE + 1e-12 {
            return Err(PathError::Option {
                name: "compression_share + blend_share",
                value: shares,
            });
        }
        if self.blend_max_angle > std::f64::consts::PI {
            return Err(PathError::Option {
                name: "blend_max_angle",
                value: self.blend_max_angle,
            });
        }
        if !self.start.0.iter().all(|c| c.is_finite()) {
            return Err(PathError::Option {
                name: "start",
                value: f64::NAN,
            });
        }
        Ok(())
    }
}

/// The machine's program-angle → tool-axis map, shared by the options (compared by identity).
#[derive(Debug, Clone)]
pub struct Orientation(pub Shared<dyn ToolAxisMap>);

impl PartialEq for Orientation {
    fn eq(&self, other: &Self) -> bool {
        Shared::ptr_eq(&self.0, &other.0)
    }
}

/// Build the whole smoothed path (collects [`Smoother`]).
pub fn build(
    moves: impl IntoIterator<Item = Move>,
    opts: &SmoothOptions,
) -> Result<Vec<PathItem>, PathError> {
    Smoother::new(moves.into_iter(), opts.clone())?.collect()
}

/// A unit between tokenising and blending.
#[derive(Debug)]
// Almost every token is a piece: boxing it would allocate once per move for nothing.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Tok {
    Piece(Piece),
    Dwell {
        seconds: f64,
        line: u32,
    },
    Stop {
        line: u32,
    },
    /// TCP switched (or its tool length changed): the machine stops before it, and nothing
    /// is compressed or blended across it.
    Control(ToolControl),
    /// Feed override allowed or locked (M48–M50): a stop, as `Control`, so that a planned
    /// piece is wholly one or the other.
    FeedOverride(bool),
}

/// The modal state the moves run under.
#[derive(Debug, Clone, Copy)]
struct Modal {
    pos: Pose,
    feed: Option<f64>,
    feed_mode: FeedMode,
    /// Programmed spindle speed (rev/min), for G95.
    spindle_rpm: f64,
    mode: Mode,
    tolerance: f64,
    control: ToolControl,
    feed_override: bool,
}

/// The streaming smoothing builder: an iterator of `Result<PathItem, PathError>`; after an
/// error it ends.
pub struct Smoother<I> {
    moves: I,
    opts: SmoothOptions,
    modal: Modal,
    pending: Option<Piece>,
    out: VecDeque<PathItem>,
    done: bool,
    /// Programmed moves folded into splines, and splines made (for reports).
    stats: Stats,
    /// The tool control of the segments being emitted (the tokens run ahead of it).
    control: ToolControl,
    /// Whether feed override acts on the segments being emitted.
    feed_override: bool,
}

/// Counts for reports and the compression ratio.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Motion moves read (G0, G1, G2/G3 that move).
    pub moves: usize,
    /// Moves replaced by splines.
    pub compressed_moves: usize,
    /// Splines made.
    pub splines: usize,
    /// Control points of those splines (the data a compressed run is reduced to).
    pub control_points: usize,
    /// Blends inserted.
    pub blends: usize,
    /// Junctions left as corners (G61, or where blending was impossible).
    pub corners: usize,
    /// Extra segments made by cutting splines where their curvature level changes.
    pub spline_cuts: usize,
    /// Largest corner deviation of a blend, mm (closed form for line–line, measured otherwise).
    pub max_blend_deviation: f64,
    /// Largest angle between a blend's tool axis and the programmed axis, degrees (5-axis).
    pub max_axis_deviation: f64,
}

impl<I: Iterator<Item = Move>> Smoother<I> {
    pub fn new(moves: I, opts: SmoothOptions) -> Result<Self, PathError> {
        opts.validate()?;
        Ok(Smoother {
            moves,
            modal: Modal {
                pos: opts.start,
                feed: None,
                feed_mode: FeedMode::UnitsPerMinute,
                spindle_rpm: 0.0,
                mode: Mode::Continuous,
                tolerance: opts.tolerance,
                control: opts.control,
                feed_override: true,
            },
            control: opts.control,
            feed_override: true,
            opts,
            pending: None,
            out: VecDeque::new(),
            done: false,
            stats: Stats::default(),
        })
    }

    /// Counts so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Turn one move into a token (or nothing: modal changes, moves that go nowhere).
    fn tokenise(&mut self, mv: Move) -> Result<Option<Tok>, PathError> {
        let line = mv.line;
        let m = &mut self.modal;
        let (geo, end) = match &mv.kind {
            &MoveKind::FeedRate { value } => {
                m.feed = Some(value);
                return Ok(None);
            }
            &MoveKind::FeedMode(f) => {
                m.feed_mode = f;
                return Ok(None);
            }
            &MoveKind::SpindleSpeed { rpm } => {
                m.spindle_rpm = rpm;
                return Ok(None);
            }
            &MoveKind::PathMode(p) => {
                match p {
                    PathMode::ExactStop => m.mode = Mode::ExactStop,
                    PathMode::ExactPath => m.mode = Mode::ExactPath,
                    PathMode::Continuous { tolerance } => {
                        m.mode = Mode::Continuous;
                        let t = tolerance.unwrap_or(self.opts.tolerance);
                        if !(t.is_finite() && t > 0.0) {
                            return Err(PathError::Tolerance { line, value: t });
                        }
                        m.tolerance = t;
                    }
                }
                return Ok(None);
            }
            // Fanuc's G05.1 Q1/Q0 switches compression of short moves on and off.
            &MoveKind::Smoothing(on) => {
                self.opts.compress = on;
                return Ok(None);
            }
            &MoveKind::ToolControl { control, at } => {
                if control == m.control && at == m.pos {
                    return Ok(None);
                }
                if !at.0.iter().all(|c| c.is_finite()) {
                    return Err(PathError::Curve {
                        line,
                        source: tezgah_geom::CurveError::NotFinite,
                    });
                }
                // Nothing moves: the next move starts from the same point read the new way.
                m.control = control;
                m.pos = at;
                return Ok(Some(Tok::Control(control)));
            }
            &MoveKind::FeedOverride(on) => {
                if on == m.feed_override {
                    return Ok(None);
                }
                m.feed_override = on;
                return Ok(Some(Tok::FeedOverride(on)));
            }
            &MoveKind::Dwell { seconds } => return Ok(Some(Tok::Dwell { seconds, line })),
            MoveKind::Synced(_) => return Err(PathError::Synced { line }),
            &MoveKind::Stop(StopKind::Pause)
            | &MoveKind::Stop(StopKind::OptionalPause)
            | &MoveKind::Stop(StopKind::PalletPause)
            | &MoveKind::Stop(StopKind::End) => return Ok(Some(Tok::Stop { line })),
            &MoveKind::Rapid { end } | &MoveKind::Feed { end } => {
                let l = Line::new(Vec3::from(m.pos.xyz()), Vec3::from(end.xyz()))
                    .map_err(|source| PathError::Curve { line, source })?;
                (Geo::Line(l), end)
            }
            MoveKind::Arc(a) => {
                let arc = Arc::from_move(&m.pos, a)
                    .map_err(|source| PathError::Curve { line, source })?;
                (Geo::Arc(Box::new(arc)), a.end)
            }
            // A programmed NURBS is one piece: compression takes only lines, so it is never
            // refitted, and its ends are blended or cornered like an arc's.
            MoveKind::Nurbs(n) => (Geo::Spline(n.curve.clone()), n.end),
        };
        if !end.0.iter().all(|c| c.is_finite()) {
            return Err(PathError::Curve {
                line,
                source: tezgah_geom::CurveError::NotFinite,
            });
        }
        let rotary = [
            [m.pos.0[3], m.pos.0[4], m.pos.0[5]],
            [end.0[3], end.0[4], end.0[5]],
        ];
        let feed = match mv.kind {
            MoveKind::Rapid { .. } => SegmentFeed::Rapid,
            _ => {
                let v = m.feed.unwrap_or(0.0);
                if !(v.is_finite() && v > 0.0) {
                    return Err(PathError::Feed { line, value: v });
                }
                SegmentFeed::programmed(m.feed_mode, v, m.spindle_rpm)
                    .ok_or(PathError::FeedPerRevolution { line })?
            }
        };
        let axis = match (&self.opts.orientation, m.control) {
            (Some(map), control @ ToolControl::CentrePoint { .. }) => {
                let from = ProgramPoint {
                    tip: Vec3::from(m.pos.xyz()),
                    rotary: rotary[0],
                };
                let to = ProgramPoint {
                    tip: Vec3::from(end.xyz()),
                    rotary: rotary[1],
                };
                let v = map.0.axis(control, &from.tip, &from.rotary);
                let u = if rotary[0] == rotary[1] {
                    v
                } else {
                    map.0.axis(control, &to.tip, &to.rotary)
                };
                // Out of reach: the planner reports it with its line. A reversal (no common
                // normal), or a move the axis alone cannot describe (see
                // `ToolAxisMap::follows`), keeps its angles linear.
                match (v, u) {
                    (Some(v), Some(u)) => GreatCircle::new(v, u).ok().filter(|g| {
                        rotary[0] == rotary[1] || map.0.follows(control, &from, &to, g)
                    }),
                    _ => None,
                }
            }
            _ => None,
        };
        m.pos = end;
        let mut piece = Piece::new(geo, rotary, line, feed, m.tolerance, m.mode);
        piece.axis = axis;
        if !piece.moves_tip() && rotary[0] == rotary[1] {
            // Goes nowhere: nothing to run.
            return Ok(None);
        }
        if !piece.full_length.is_finite() {
            return Err(PathError::Curve {
                line,
                source: tezgah_geom::CurveError::NotFinite,
            });
        }
        self.stats.moves += 1;
        Ok(Some(Tok::Piece(piece)))
    }

    /// Read and process one window; returns false at the end of input.
    fn fill(&mut self) -> Result<bool, PathError> {
        let mut toks = Vec::with_capacity(self.opts.window.min(4096));
        let mut read = 0;
        let mut more = true;
        while read < self.opts.window.max(1) {
            match self.moves.next() {
                Some(mv) => {
                    read += 1;
                    if let Some(t) = self.tokenise(mv)? {
                        toks.push(t);
                    }
                }
                None => {
                    more = false;
                    break;
                }
            }
        }
        if self.opts.compress {
            let before = toks.len();
            toks = compress::compress(
                toks,
                self.opts.short_segment,
                self.opts.compress_corner_angle,
                self.opts.compression_share,
            );
            for t in &toks {
                if let Tok::Piece(p) = t {
                    if p.moves > 1 {
                        self.stats.splines += 1;
                        self.stats.control_points += p.control_points();
                        self.stats.compressed_moves += p.moves;
                    }
                }
            }
            debug_assert!(toks.len() <= before);
        }
        for t in toks {
            match t {
                Tok::Piece(mut b) => {
                    if let Some(a) = self.pending.take() {
                        self.join(a, &mut b);
                    }
                    self.pending = Some(b);
                }
                Tok::Dwell { seconds, line } => {
                    self.flush(Junction::Stop);
                    self.out.push_back(PathItem::Dwell { seconds, line });
                }
                Tok::Stop { line } => {
                    self.flush(Junction::Stop);
                    self.out.push_back(PathItem::Stop { line });
                }
                Tok::Control(control) => {
                    self.flush(Junction::Stop);
                    self.control = control;
                }
                Tok::FeedOverride(on) => {
                    self.flush(Junction::Stop);
                    self.feed_override = on;
                }
            }
        }
        if !more {
            self.flush(Junction::Stop);
        }
        Ok(more)
    }

    /// Emit a piece ending with `end`. A spline goes out as several segments, cut at its knots
    /// where its curvature level changes ([`Piece::curvature_chunks`]): the planner limits the
    /// speed of a segment by the largest curvature anywhere in it, so one tight spot must not
    /// slow a whole compressed row. The cuts are C² (inside a cubic spline), so they are
    /// `Smooth` junctions.
    fn emit(&mut self, a: Piece, end: Junction) {
        let chunks = a.curvature_chunks();
        let n = chunks.len();
        for (i, (u0, u1)) in chunks.into_iter().enumerate() {
            if i + 1 == n {
                let mut last = a;
                last.u0 = u0;
                self.push_segment(last.into_segment(end));
                return;
            }
            let mut part = a.clone();
            part.u0 = u0;
            part.u1 = u1;
            self.stats.spline_cuts += 1;
            self.push_segment(part.into_segment(Junction::Smooth));
        }
    }

    fn flush(&mut self, end: Junction) {
        if let Some(a) = self.pending.take() {
            self.emit(a, end);
        }
    }

    /// Out with a segment, under the tool control and feed override switch in force.
    fn push_segment(&mut self, mut seg: Segment) {
        seg.control = self.control;
        seg.feed_override = self.feed_override;
        self.out.push_back(PathItem::Segment(seg));
    }

    /// Decide the junction between `a` and `b`, blending where allowed; emits `a` (and the
    /// blend) and trims `b`'s start.
    fn join(&mut self, mut a: Piece, b: &mut Piece) {
        if a.mode == Mode::ExactStop {
            self.emit(a, Junction::Stop);
            return;
        }
        let blendable = a.mode == Mode::Continuous
            && b.mode == Mode::Continuous
            && feeds_compatible(a.feed, b.feed);
        // Where the program's own line runs into its own tangent arc no compression deviation
        // is spent, so the blend may take that share too (blend + chord within ε): a longer
        // blend spreads the curvature jump thinner, and the speed through it rises with the
        // cube root of its length. (At a turn a longer blend is slower: its crawl is longer.)
        let exact = |p: &Piece| matches!(p.geo, Geo::Line(_) | Geo::Arc(_));
        let blend_share = if exact(&a) && exact(b) && blend::tangent(&a, b) {
            self.opts.blend_share + self.opts.compression_share
        } else {
            self.opts.blend_share
        };
        let share = blend_share * a.tolerance.min(b.tolerance);
        let max_angle = if blendable {
            self.opts.blend_max_angle
        } else {
            // Only the tangent test: every real turn stays a corner.
            0.0
        };
        // 5-axis: the tool axis (or, without one, the rotary axes running linearly) must stay
        // within the angular tolerance across the blend: shorten the legs until it does.
        let mut placed =
            blend::place(&a, b, share, max_angle).map(|p| (self.orientation(&a, b, &p), p));
        if let Ok((None, _)) = &placed {
            // Without a blend the junction is what it is: a corner, or a tangent junction
            // whose curvature jumps.
            placed = Err(match blend::place(&a, b, share, 0.0) {
                Err(e) => e,
                Ok(_) => NoBlend::Corner,
            });
            let mut s = share;
            for _ in 0..20 {
                s *= 0.5;
                match blend::place(&a, b, s, max_angle) {
                    Ok(q) => {
                        if let Some(o) = self.orientation(&a, b, &q) {
                            placed = Ok((Some(o), q));
                            break;
                        }
                    }
                    Err(e) => {
                        placed = Err(e);
                        break;
                    }
                }
            }
        }
        match placed {
            Ok((fit, p)) => {
                let rotary = [a.rotary_at(p.ua), b.rotary_at(p.ub)];
                let axis = fit.and_then(|(blend, deviation)| {
                    self.stats.max_axis_deviation =
                        self.stats.max_axis_deviation.max(deviation.to_degrees());
                    blend.map(AxisPath::Blend)
                });
                let feed = blend_feed(&a, b, p.ua, p.ub);
                let seg = Segment {
                    curve: Box::new(p.curve),
                    length: p.length,
                    rotary,
                    line: a.line,
                    feed,
                    end: Junction::Smooth,
                    tolerance: a.tolerance.min(b.tolerance),
                    control: self.control,
                    feed_override: self.feed_override,
                    tool_axis_travel: None,
                    axis,
                };
                a.u1 = p.ua;
                b.u0 = p.ub;
                self.stats.blends += 1;
                self.stats.max_blend_deviation = self.stats.max_blend_deviation.max(p.deviation);
                self.emit(a, Junction::Smooth);
                self.push_segment(seg);
            }
            Err(NoBlend::Tangent { same_curvature }) => {
                // The tip runs on smoothly; the axis (or the rotary axes) may change its rate
                // here, which the planner must see as a tangent junction.
                let end = if same_curvature && orientation_continues(&a, b) {
                    Junction::Smooth
                } else {
                    Junction::Tangent
                };
                self.emit(a, end);
            }
            Err(NoBlend::Corner) => {
                self.stats.corners += 1;
                self.emit(a, Junction::Corner);
            }
        }
    }

    /// The orientation side of a placed blend, `None` if it leaves the angular tolerance: the
    /// two-curve axis blend and its deviation (rad) where both pieces carry a tool axis,
    /// otherwise no axis blend and the rotary axes' deviation at mid-blend (degrees → rad).
    fn orientation(&self, a: &Piece, b: &Piece, p: &Placed) -> Option<Fit> {
        let tolerance = self.opts.angular_tolerance;
        // A move with linear angles next to one carrying its axis: the two meet only at the
        // programmed point (a blend would start the axis from where each left it).
        if a.axis.is_some() != b.axis.is_some() {
            return None;
        }
        if a.axis.is_some() && b.axis.is_some() {
            let blend = axis::blend(a, b, p)?;
            let deviation = axis::deviation(a, b, p, &blend);
            return (deviation <= (1.0 - CHORD_SHARE) * tolerance.to_radians())
                .then_some((Some(blend), deviation));
        }
        let corner = a.rotary[1];
        let (ra, rb) = (a.rotary_at(p.ua), b.rotary_at(p.ub));
        let deviation = (0..3)
            .map(|i| (corner[i] - 0.5 * (ra[i] + rb[i])).abs())
            .fold(0.0, f64::max);
        (deviation <= tolerance).then_some((None, 0.0))
    }
}

/// The orientation side of a blend that fits: the axis blend (none where the rotary axes run
/// linearly) and its deviation from the programmed axis, rad.
type Fit = (Option<AxisBlend>, f64);

/// Whether the orientation's rate of change by arc length (and, for the tool axis, its second
/// derivative) is the same on both sides of a tangent junction, to 1e-9 relative.
fn orientation_continues(a: &Piece, b: &Piece) -> bool {
    let same = |x: Vec3, y: Vec3| (x - y).norm() <= 1e-9 * x.norm().max(y.norm()).max(1e-12);
    match (a.axis, b.axis) {
        (Some(ga), Some(gb)) => {
            let ([a1, a2], [b1, b2]) = (ga.derivatives(1.0), gb.derivatives(0.0));
            let (la, lb) = (a.full_length, b.full_length);
            same(a1 / la, b1 / lb) && same(a2 / (la * la), b2 / (lb * lb))
        }
        _ => {
            let rate = |p: &Piece| {
                let [r0, r1] = p.rotary;
                Vec3::new(r1[0] - r0[0], r1[1] - r0[1], r1[2] - r0[2]) / p.full_length
            };
            same(rate(a), rate(b))
        }
    }
}

/// Blending across a change between inverse time and a feed rate would mix two timing rules.
fn feeds_compatible(a: SegmentFeed, b: SegmentFeed) -> bool {
    matches!(a, SegmentFeed::InverseTime(_)) == matches!(b, SegmentFeed::InverseTime(_))
}

/// The blend runs at the lower of the two feeds (a rapid next to a feed takes the feed); in
/// inverse time it takes the time of the two legs it replaces.
fn blend_feed(a: &Piece, b: &Piece, ua: f64, ub: f64) -> SegmentFeed {
    match (a.feed, b.feed) {
        (SegmentFeed::InverseTime(ta), SegmentFeed::InverseTime(tb)) => {
            let la = a.full_length - a.s_at(ua);
            let lb = b.s_at(ub);
            SegmentFeed::InverseTime(ta * la / a.full_length + tb * lb / b.full_length)
        }
        (SegmentFeed::Feed(x), SegmentFeed::Feed(y)) => SegmentFeed::Feed(x.min(y)),
        (SegmentFeed::Feed(x), _) | (_, SegmentFeed::Feed(x)) => SegmentFeed::Feed(x),
        _ => SegmentFeed::Rapid,
    }
}

impl<I: Iterator<Item = Move>> Iterator for Smoother<I> {
    type Item = Result<PathItem, PathError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(item) = self.out.pop_front() {
                return Some(Ok(item));
            }
            if self.done {
                return None;
            }
            match self.fill() {
                Ok(more) => self.done = !more,
                Err(e) => {
                    self.done = true;
                    self.out.clear();
                    return Some(Err(e));
                }
            }
        }
    }
}
