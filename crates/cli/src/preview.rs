//! The panel's 3-D preview of a loaded program: its moves as polylines of tool-tip points
//! (mm, the frame of the status' `tip`), each with its kind, so the panel colours them as
//! Kelekçi (2021, ch. 4) does: lines, arcs and helices, G05.1-fitted runs, NURBS, rapids.

use serde::Serialize;
use tezgah_geom::{Arc, Curve, Move, MoveKind, Pose};

/// What a piece of the path is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Rapid,
    Line,
    Arc,
    /// A G1 run under `G05.1 Q1` (the planner may fit it with splines).
    Fitted,
    Nurbs,
}

/// Consecutive moves of one kind and line, as points.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Piece {
    pub kind: Kind,
    /// The source line (as the status' `executing_line` numbers it).
    pub line: u32,
    pub points: Vec<[f64; 3]>,
}

/// Points per curved move (arcs and NURBS): enough for a smooth picture, few enough for a
/// long program.
const SAMPLES: usize = 24;

/// The pieces of `moves` run from `start`; at most `max_points` points in all (a longer
/// program is cut short, and the flag says so).
pub fn pieces(start: Pose, moves: &[Move], max_points: usize) -> (Vec<Piece>, bool) {
    let mut out: Vec<Piece> = Vec::new();
    let mut pos = start;
    let mut fitted = false;
    let mut count = 0;
    let xyz = |p: &Pose| [p.0[0], p.0[1], p.0[2]];
    for m in moves {
        let (kind, points, end) = match &m.kind {
            MoveKind::Smoothing(on) => {
                fitted = *on;
                continue;
            }
            MoveKind::ToolControl { at, .. } => {
                pos = *at;
                continue;
            }
            MoveKind::Rapid { end } => (Kind::Rapid, vec![xyz(end)], *end),
            MoveKind::Feed { end } => (
                if fitted { Kind::Fitted } else { Kind::Line },
                vec![xyz(end)],
                *end,
            ),
            MoveKind::Arc(a) => match Arc::from_move(&pos, a) {
                Ok(arc) => (Kind::Arc, sample(&arc), a.end),
                Err(_) => (Kind::Arc, vec![xyz(&a.end)], a.end),
            },
            MoveKind::Nurbs(n) => (Kind::Nurbs, sample(n.curve.as_ref()), n.end),
            _ => continue,
        };
        count += points.len();
        if count > max_points {
            return (out, true);
        }
        match out.last_mut() {
            Some(p) if p.kind == kind && p.line == m.line => p.points.extend(points),
            _ => {
                let mut all = vec![xyz(&pos)];
                all.extend(points);
                out.push(Piece {
                    kind,
                    line: m.line,
                    points: all,
                })
            }
        }
        pos = end;
    }
    (out, false)
}

fn sample(curve: &(impl Curve + ?Sized)) -> Vec<[f64; 3]> {
    let (u0, u1) = curve.domain();
    (1..=SAMPLES)
        .map(|k| {
            let p = curve.point(u0 + (u1 - u0) * k as f64 / SAMPLES as f64);
            [p.x, p.y, p.z]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_gcode::{Config, Interpreter, MoveBuilder};

    fn moves(program: &str) -> Vec<Move> {
        let mut moves = Vec::new();
        {
            let mut builder = MoveBuilder::new(|m| moves.push(m));
            let mut interp = Interpreter::new(Config::default());
            interp.run(program, &mut builder).unwrap();
        }
        moves
    }

    #[test]
    fn pieces_carry_kinds_lines_and_points() {
        let m = moves(
            "G21 G90 G17\nG0 X10\nG1 Y10 F100\nG2 X20 Y0 I0 J-10\nG05.1 Q1\nG1 X25\nG1 X30\nM2\n",
        );
        let (p, cut) = pieces(Pose::ZERO, &m, 10_000);
        assert!(!cut);
        let kinds: Vec<(Kind, u32)> = p.iter().map(|p| (p.kind, p.line)).collect();
        assert_eq!(
            kinds,
            [
                (Kind::Rapid, 2),
                (Kind::Line, 3),
                (Kind::Arc, 4),
                (Kind::Fitted, 6),
                (Kind::Fitted, 7)
            ]
        );
        assert_eq!(p[0].points, [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]]);
        assert_eq!(p[1].points, [[10.0, 0.0, 0.0], [10.0, 10.0, 0.0]]);
        // The arc's points are on its circle (centre 10,0, radius 10) and end at 20,0.
        assert_eq!(p[2].points.len(), SAMPLES + 1);
        for q in &p[2].points {
            assert!(((q[0] - 10.0).hypot(q[1]) - 10.0).abs() < 1e-9, "{q:?}");
        }
        let last = p[2].points.last().unwrap();
        assert!((last[0] - 20.0).abs() < 1e-9 && last[1].abs() < 1e-9);
        assert_eq!(p[4].points, [[25.0, 0.0, 0.0], [30.0, 0.0, 0.0]]);
        let (p, cut) = pieces(Pose::ZERO, &m, 3);
        assert!(cut);
        assert_eq!(p.len(), 2);
    }
}
