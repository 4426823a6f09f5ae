//! The programmed path `verify` measures against: the program's own moves (lines, arcs,
//! helices, NURBS) as the interpreter emits them — work offsets and tool length applied, before
//! compression, blending or smoothing — laid end to end by arc length `σ`, so that a cursor
//! can follow the samples and measure each one against the program *near where it is*.

use std::sync::Arc as Shared;

use tezgah_geom::deviation::closest_point;
use tezgah_geom::{Arc, Curve, Move, MoveKind, Nurbs, Pose, ToolControl, Vec3};

use crate::path::deviation::arc_nearest;

/// Table steps per NURBS knot span for the `σ ↔ u` table (Gauss-Legendre per step).
const NURBS_STEPS_PER_SPAN: usize = 8;

/// Distances this close (mm) are a tie: the program passes the same point twice (a retrace,
/// a move back over the last), and the candidate nearer the expected `σ` wins.
const TIE_MM: f64 = 1e-9;

/// The geometry of one programmed move.
enum Geo {
    /// Start and unit direction (zero for a move that turns only rotary axes); `u = s`.
    Line { start: Vec3, dir: Vec3 },
    /// Constant parametric speed (circular arcs, helices, spirals): `u = s / length`.
    Arc(Arc),
    /// A NURBS move with its `(s, u)` table.
    Nurbs {
        curve: Shared<Nurbs>,
        table: Vec<(f64, f64)>,
    },
}

/// One programmed move, placed along the program.
struct Piece {
    geo: Geo,
    /// Arc length along the program at the piece's start, mm.
    start: f64,
    /// Arc length of the piece, mm.
    length: f64,
}

/// The nearest programmed point found for a query: distance (mm) and where it is (`σ`, mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    pub distance: f64,
    pub sigma: f64,
}

/// The program's tip path: every move's geometry in order, and where the tool control switches
/// to another reading of the program point (the take-up moves run there, outside the program).
pub struct ProgramPath {
    pieces: Vec<Piece>,
    /// `σ` of the switches between readings (TCP on/off, a new TCP tool length).
    switches: Vec<f64>,
    /// The moves' end points (and a start where the point is read anew), in order of `σ`.
    vertices: Vec<(f64, Vec3)>,
}

impl ProgramPath {
    /// The moves from `start` under the machine's `initial` tool control. Moves whose geometry
    /// cannot be built are skipped (the path builder reports them).
    pub fn new(start: Pose, initial: ToolControl, moves: &[Move]) -> Self {
        let mut pos = start;
        let mut control = initial;
        let mut sigma = 0.0;
        let mut pieces = Vec::new();
        let mut switches = Vec::new();
        let mut vertices: Vec<(f64, Vec3)> = vec![(0.0, Vec3::from(start.xyz()))];
        for m in moves {
            let (geo, length, end) = match &m.kind {
                &MoveKind::Rapid { end } | &MoveKind::Feed { end } => {
                    let (a, b) = (Vec3::from(pos.xyz()), Vec3::from(end.xyz()));
                    let length = (b - a).norm();
                    let dir = if length > 0.0 {
                        (b - a) / length
                    } else {
                        Vec3::zeros()
                    };
                    (Geo::Line { start: a, dir }, length, end)
                }
                MoveKind::Arc(a) => match Arc::from_move(&pos, a) {
                    Ok(arc) => {
                        let length = arc.length();
                        (Geo::Arc(arc), length, a.end)
                    }
                    Err(_) => continue,
                },
                MoveKind::Nurbs(n) => {
                    let table = arc_length_table(n.curve.as_ref());
                    let length = table.last().map_or(0.0, |t| t.0);
                    let geo = Geo::Nurbs {
                        curve: n.curve.clone(),
                        table,
                    };
                    (geo, length, n.end)
                }
                // Nothing moves: the next move starts from the point read anew.
                &MoveKind::ToolControl { control: c, at } => {
                    if !c.same_reading(&control) {
                        switches.push(sigma);
                        // The machine leaves the old reading's point by a take-up, which is
                        // not measured: the point is the new reading's from here.
                        if vertices.last().is_some_and(|v| v.0 == sigma) {
                            vertices.pop();
                        }
                    }
                    control = c;
                    pos = at;
                    continue;
                }
                _ => continue,
            };
            let from = Vec3::from(pos.xyz());
            if vertices.last().is_none_or(|v| v.1 != from) {
                vertices.push((sigma, from));
            }
            pieces.push(Piece {
                geo,
                start: sigma,
                length,
            });
            sigma += length;
            pos = end;
            let to = Vec3::from(pos.xyz());
            if vertices.last().is_none_or(|v| v.1 != to) {
                vertices.push((sigma, to));
            }
        }
        ProgramPath {
            pieces,
            switches,
            vertices,
        }
    }

    /// Arc length of the whole program, mm.
    pub fn length(&self) -> f64 {
        self.pieces.last().map_or(0.0, |p| p.start + p.length)
    }

    /// The programmed vertices (`σ`, point): where one move ends and the next begins.
    pub fn vertices(&self) -> &[(f64, Vec3)] {
        &self.vertices
    }

    /// The arc lengths from the start of the move before piece `i` to the end of the move
    /// after it: the moves around the current one.
    pub fn around(&self, i: usize) -> (f64, f64) {
        let n = self.pieces.len();
        if n == 0 {
            return (0.0, 0.0);
        }
        let (a, b) = (i.saturating_sub(1).min(n - 1), (i + 1).min(n - 1));
        (
            self.pieces[a].start,
            self.pieces[b].start + self.pieces[b].length,
        )
    }

    /// Whether a switch between readings of the program point lies in `[lo, hi]`.
    pub fn switch_within(&self, lo: f64, hi: f64) -> bool {
        let i = self.switches.partition_point(|&s| s < lo);
        self.switches.get(i).is_some_and(|&s| s <= hi)
    }

    /// The nearest point to `q` of the program between arc lengths `lo` and `hi` (the union of
    /// the moves' parts there: at a blended corner, both legs); of points as near (a retrace),
    /// the one nearest `expected`. `hint` is a piece index near the window (the last
    /// answer's), updated. Infinite distance for an empty program.
    pub fn nearest(
        &self,
        q: &Vec3,
        window: (f64, f64),
        expected: f64,
        hint: &mut usize,
    ) -> Nearest {
        let [n] = self.nearest_all([(q, expected)], window, hint);
        n
    }

    /// The distance from `q` to piece `i`'s part within `[lo, hi]` (`None` where there is
    /// none): an upper bound, within [`TIE_DISTANCE_MM`], of what [`ProgramPath::nearest`]
    /// finds over a window holding that part.
    pub fn piece_distance(&self, i: usize, q: &Vec3, (lo, hi): (f64, f64)) -> Option<f64> {
        let p = self.pieces.get(i)?;
        if p.start > hi || p.start + p.length < lo {
            return None;
        }
        let s0 = (lo - p.start).clamp(0.0, p.length);
        let s1 = (hi - p.start).clamp(0.0, p.length);
        Some(p.nearest(q, s0, s1).0)
    }

    /// [`ProgramPath::nearest`] for several points over one window in one pass over its
    /// pieces (a sample's tip and its chord's midpoint); `hint` follows the first point.
    pub fn nearest_all<const N: usize>(
        &self,
        queries: [(&Vec3, f64); N],
        (lo, hi): (f64, f64),
        hint: &mut usize,
    ) -> [Nearest; N] {
        let mut best = [Nearest {
            distance: f64::INFINITY,
            sigma: lo.max(0.0),
        }; N];
        if self.pieces.is_empty() {
            return best;
        }
        let mut i = (*hint).min(self.pieces.len() - 1);
        while i > 0 && self.pieces[i].start > lo {
            i -= 1;
        }
        while i + 1 < self.pieces.len() && self.pieces[i].start + self.pieces[i].length < lo {
            i += 1;
        }
        let mut best_i = i;
        // A candidate farther than this from a query (squared) can neither beat its best
        // nor tie with it, and is passed over without its square root: a sample's window
        // holds a handful of moves, most of them clearly farther than the nearest.
        let mut reach = [f64::INFINITY; N];
        while i < self.pieces.len() && self.pieces[i].start <= hi {
            let p = &self.pieces[i];
            let s0 = (lo - p.start).clamp(0.0, p.length);
            let s1 = (hi - p.start).clamp(0.0, p.length);
            for (k, (q, expected)) in queries.iter().enumerate() {
                let (d, s) = match &p.geo {
                    // Lines, nearly every move of a dense program, inline: the square root
                    // only for a candidate within reach.
                    Geo::Line { start, dir } => {
                        let s = (*q - start).dot(dir).clamp(s0, s1);
                        let d2 = (start + dir * s - *q).norm_squared();
                        if d2 > reach[k] {
                            continue;
                        }
                        (d2.sqrt(), s)
                    }
                    _ => p.nearest(q, s0, s1),
                };
                let sigma = p.start + s;
                let b = &mut best[k];
                let tie = (d - b.distance).abs() <= TIE_MM
                    && (sigma - expected).abs() < (b.sigma - expected).abs();
                if d < b.distance - TIE_MM || tie {
                    *b = Nearest {
                        distance: d.min(b.distance),
                        sigma,
                    };
                    reach[k] = beyond_reach(b.distance);
                    if k == 0 {
                        best_i = i;
                    }
                }
            }
            i += 1;
        }
        *hint = best_i;
        best
    }
}

/// Distances this close (mm) are a tie for [`ProgramPath::nearest`]: what it returns is at
/// most this much over the distance from any one candidate in its window.
pub const TIE_DISTANCE_MM: f64 = TIE_MM;

/// The squared distance beyond which a candidate is farther than `best + TIE_MM` for certain
/// (with a margin for the rounding of the square and its root): such a candidate can neither
/// beat `best` nor tie with it.
fn beyond_reach(best: f64) -> f64 {
    let r = (best + 2.0 * TIE_MM) * (1.0 + 1e-9);
    r * r
}

impl Piece {
    /// Distance from `q` to the piece's part `s ∈ [s0, s1]` and the `s` where it is reached.
    fn nearest(&self, q: &Vec3, s0: f64, s1: f64) -> (f64, f64) {
        match &self.geo {
            Geo::Line { start, dir } => {
                let s = (q - start).dot(dir).clamp(s0, s1);
                ((start + dir * s - q).norm(), s)
            }
            Geo::Arc(a) => {
                let (u0, u1) = (s0 / self.length, s1 / self.length);
                let (d, u) = arc_nearest(a, q, u0, u1).unwrap_or_else(|| {
                    // Helices and spirals: no closed form; a sample per 22.5° of the part
                    // starts the refinement in the right basin.
                    let turns = a.sweep().abs() * (u1 - u0);
                    let n = (turns / (std::f64::consts::PI / 8.0)).ceil() as usize;
                    let c = closest_point(a, q, u0, u1, n.clamp(4, 256));
                    (c.distance, c.u)
                });
                (d, u * self.length)
            }
            Geo::Nurbs { curve, table } => {
                // Span by span: over a whole neighbour, samples spread over the domain can
                // start the refinement in the wrong basin.
                let (u0, u1) = (param_at(table, s0), param_at(table, s1));
                let mut cuts = vec![u0];
                cuts.extend(
                    curve
                        .breakpoints()
                        .into_iter()
                        .filter(|&b| b > u0 && b < u1),
                );
                cuts.push(u1);
                let c = cuts
                    .windows(2)
                    .map(|w| closest_point(curve.as_ref(), q, w[0], w[1], 8))
                    .min_by(|a, b| a.distance.total_cmp(&b.distance))
                    .unwrap_or(tezgah_geom::deviation::Deviation {
                        distance: (curve.point(u0) - q).norm(),
                        u: u0,
                    });
                (c.distance, length_at(table, c.u))
            }
        }
    }
}

/// `(s, u)` at every knot span's ends and `NURBS_STEPS_PER_SPAN` steps inside, by Gauss
/// quadrature of the speed (geom's `Curve::speed_integral`).
fn arc_length_table<C: Curve + ?Sized>(c: &C) -> Vec<(f64, f64)> {
    let (a, b) = c.domain();
    let mut cuts = vec![a];
    cuts.extend(c.breakpoints().into_iter().filter(|&x| x > a && x < b));
    cuts.push(b);
    let mut table = vec![(0.0, a)];
    let mut s = 0.0;
    for w in cuts.windows(2) {
        for k in 1..=NURBS_STEPS_PER_SPAN {
            let (p, q) = (
                w[0] + (w[1] - w[0]) * (k - 1) as f64 / NURBS_STEPS_PER_SPAN as f64,
                w[0] + (w[1] - w[0]) * k as f64 / NURBS_STEPS_PER_SPAN as f64,
            );
            s += c.speed_integral(p, q);
            table.push((s, q));
        }
    }
    table
}

/// Linear interpolation in a monotone table, by the first (`by_s`) or second column.
fn interpolate(table: &[(f64, f64)], x: f64, by_s: bool) -> f64 {
    let key = |e: &(f64, f64)| if by_s { e.0 } else { e.1 };
    let val = |e: &(f64, f64)| if by_s { e.1 } else { e.0 };
    let i = table.partition_point(|e| key(e) < x);
    if i == 0 {
        return val(&table[0]);
    }
    if i >= table.len() {
        return val(&table[table.len() - 1]);
    }
    let (a, b) = (&table[i - 1], &table[i]);
    let w = key(b) - key(a);
    let f = if w > 0.0 { (x - key(a)) / w } else { 0.0 };
    val(a) + f * (val(b) - val(a))
}

fn param_at(table: &[(f64, f64)], s: f64) -> f64 {
    interpolate(table, s, true)
}

fn length_at(table: &[(f64, f64)], u: f64) -> f64 {
    interpolate(table, u, false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_geom::{ArcMove, Plane};

    fn feed(line: u32, x: f64, y: f64) -> Move {
        Move {
            line,
            kind: MoveKind::Feed {
                end: Pose([x, y, 0.0, 0.0, 0.0, 0.0]),
            },
        }
    }

    /// An L: the nearest point of a point inside the corner is on either leg within the
    /// window, and a window that holds only the first leg measures from it alone.
    #[test]
    fn the_window_restricts_the_union() {
        let moves = [feed(1, 10.0, 0.0), feed(2, 10.0, 10.0)];
        let p = ProgramPath::new(Pose::ZERO, ToolControl::OFF, &moves);
        assert_eq!(p.length(), 20.0);
        let q = Vec3::new(9.0, 0.5, 0.0);
        let mut h = 0;
        let n = p.nearest(&q, (0.0, 20.0), 10.0, &mut h);
        assert!((n.distance - 0.5).abs() < 1e-15 && (n.sigma - 9.0).abs() < 1e-15);
        // Near the second leg's start.
        let q = Vec3::new(9.8, 3.0, 0.0);
        let n = p.nearest(&q, (5.0, 20.0), 10.0, &mut h);
        assert!((n.distance - 0.2).abs() < 1e-12 && (n.sigma - 13.0).abs() < 1e-12);
        // Only the first leg up to σ = 9: the distance to (9, 0).
        let n = p.nearest(&q, (0.0, 9.0), 5.0, &mut h);
        assert!((n.distance - (0.64f64 + 9.0).sqrt()).abs() < 1e-12, "{n:?}");
    }

    /// A full circle of radius 5: the closed form gives the radial distance and the angle,
    /// and a window over a quarter of it the distance to the nearer end otherwise.
    /// Up 2 mm and back down the same line: at the bottom both ends are 0 away, and the one
    /// the samples are heading for wins.
    #[test]
    fn a_retrace_is_followed_forward() {
        let up = Move {
            line: 1,
            kind: MoveKind::Rapid {
                end: Pose([0.0, 0.0, 2.0, 0.0, 0.0, 0.0]),
            },
        };
        let p = ProgramPath::new(Pose::ZERO, ToolControl::OFF, &[up, feed(2, 0.0, 0.0)]);
        let (q, mut h) = (Vec3::zeros(), 0);
        assert_eq!(p.nearest(&q, (0.0, 4.0), 3.9, &mut h).sigma, 4.0);
        assert_eq!(p.nearest(&q, (0.0, 4.0), 0.1, &mut h).sigma, 0.0);
    }

    /// A helix of three turns (radius 5, 2 mm a turn): a point 0.3 mm outside the second turn
    /// is 0.3 mm from the whole move, but from the first turn alone at least the pitch less
    /// that away — the window keeps the other turns out.
    #[test]
    fn a_helix_is_measured_within_the_window() {
        let helix = Move {
            line: 2,
            kind: MoveKind::Arc(ArcMove {
                plane: Plane::XY,
                end: Pose([5.0, 0.0, -6.0, 0.0, 0.0, 0.0]),
                center: [0.0, 0.0],
                turn: 3,
            }),
        };
        let p = ProgramPath::new(Pose::ZERO, ToolControl::OFF, &[feed(1, 5.0, 0.0), helix]);
        let turn = (std::f64::consts::TAU * 5.0).hypot(2.0);
        assert!(
            (p.length() - 5.0 - 3.0 * turn).abs() < 1e-9,
            "{}",
            p.length()
        );
        // Half way round the second turn: (-5, 0, -3), pushed out to radius 5.3.
        let q = Vec3::new(-5.3, 0.0, -3.0);
        let mut h = 0;
        let n = p.nearest(&q, (5.0, p.length()), 5.0 + 1.5 * turn, &mut h);
        assert!((n.distance - 0.3).abs() < 1e-9, "{n:?}");
        assert!((n.sigma - (5.0 + 1.5 * turn)).abs() < 1e-6, "{n:?}");
        let n = p.nearest(&q, (5.0, 5.0 + turn), 5.0, &mut h);
        assert!(n.distance > 2.0 - 0.3, "{n:?}");
    }

    #[test]
    fn arcs_in_closed_form() {
        let moves = [
            feed(1, 5.0, 0.0),
            Move {
                line: 2,
                kind: MoveKind::Arc(ArcMove {
                    plane: Plane::XY,
                    end: Pose([5.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
                    center: [0.0, 0.0],
                    turn: 1,
                }),
            },
        ];
        let p = ProgramPath::new(Pose::ZERO, ToolControl::OFF, &moves);
        let quarter = 2.5 * std::f64::consts::PI;
        assert!((p.length() - 5.0 - 4.0 * quarter).abs() < 1e-9);
        let q = Vec3::new(0.0, 6.0, 0.0);
        let mut h = 0;
        let n = p.nearest(&q, (5.0, 5.0 + 4.0 * quarter), 5.0, &mut h);
        assert!((n.distance - 1.0).abs() < 1e-12, "{n:?}");
        assert!((n.sigma - (5.0 + quarter)).abs() < 1e-9, "{n:?}");
        // The part after the first quarter only: the nearest is its start (0, 5).
        let n = p.nearest(&q, (5.0 + quarter, 5.0 + 2.0 * quarter), 5.0, &mut h);
        assert!((n.distance - 1.0).abs() < 1e-9, "{n:?}");
        let n = p.nearest(&q, (5.0 + 2.0 * quarter, 5.0 + 3.0 * quarter), 5.0, &mut h);
        assert!((n.distance - (25.0f64 + 36.0).sqrt()).abs() < 1e-9, "{n:?}");
    }
}
