//! Shared helpers of the path tests: program builders and the checks every built path must
//! pass (continuity at Smooth joints, exact corner and end points, no NaN).
#![allow(dead_code)]

use tezgah_geom::{ArcMove, Curve, Move, MoveKind, PathMode, Plane, Pose, Vec3};
use tezgah_motion::path::{Junction, PathItem, Segment};

pub fn feed(line: u32, mm_min: f64) -> Move {
    Move {
        line,
        kind: MoveKind::FeedRate { value: mm_min },
    }
}

pub fn g1(line: u32, p: Vec3) -> Move {
    Move {
        line,
        kind: MoveKind::Feed {
            end: Pose::new(p.x, p.y, p.z, 0.0, 0.0, 0.0),
        },
    }
}

pub fn g1a(line: u32, p: Vec3, a: f64) -> Move {
    Move {
        line,
        kind: MoveKind::Feed {
            end: Pose::new(p.x, p.y, p.z, a, 0.0, 0.0),
        },
    }
}

pub fn arc_xy(line: u32, end: Vec3, center: [f64; 2], turn: i32) -> Move {
    Move {
        line,
        kind: MoveKind::Arc(ArcMove {
            plane: Plane::XY,
            end: Pose::new(end.x, end.y, end.z, 0.0, 0.0, 0.0),
            center,
            turn,
        }),
    }
}

pub fn mode(line: u32, m: PathMode) -> Move {
    Move {
        line,
        kind: MoveKind::PathMode(m),
    }
}

pub fn segments(items: &[PathItem]) -> Vec<&Segment> {
    items
        .iter()
        .filter_map(|i| match i {
            PathItem::Segment(s) => Some(s),
            _ => None,
        })
        .collect()
}

pub fn start_point(s: &Segment) -> Vec3 {
    s.curve.point(s.curve.domain().0)
}
pub fn end_point(s: &Segment) -> Vec3 {
    s.curve.point(s.curve.domain().1)
}

/// Unit tangent and curvature vector at `u`.
pub fn frame(c: &dyn Curve, u: f64) -> (Vec3, Vec3) {
    let [_, d1, d2, _] = c.derivs(u);
    let s = d1.norm();
    let t = d1 / s;
    (t, (d2 - t * d2.dot(&t)) / (s * s))
}

/// Every check that holds for any built path; returns a description of the first failure.
/// `vertices` are the programmed end points (start first).
pub fn check_path(items: &[PathItem], vertices: &[Vec3]) -> Result<(), String> {
    let segs = segments(items);
    for (i, s) in segs.iter().enumerate() {
        let (a, b) = s.curve.domain();
        if !(a.is_finite() && b.is_finite() && a <= b) {
            return Err(format!("segment {i}: domain {a} {b}"));
        }
        if !(s.length.is_finite() && s.length >= 0.0) {
            return Err(format!("segment {i}: length {}", s.length));
        }
        for k in 0..=8 {
            let u = a + (b - a) * k as f64 / 8.0;
            if s.curve
                .derivs(u)
                .iter()
                .flat_map(|v| v.iter())
                .any(|c| !c.is_finite())
            {
                return Err(format!("segment {i}: non-finite at u={u}"));
            }
        }
        // The planner times `length`: it must be the curve's arc length.
        let len = tezgah_geom::ArcLengthMap::new(s.curve.as_ref(), 1e-10)
            .map(|m| m.length())
            .unwrap_or(f64::NAN);
        if (len - s.length).abs() > 1e-8 * (1.0 + len) {
            return Err(format!(
                "segment {i}: length {} but arc length {len}",
                s.length
            ));
        }
        if s.rotary.iter().flatten().any(|c| !c.is_finite()) {
            return Err(format!("segment {i}: rotary NaN"));
        }
    }
    for (i, w) in segs.windows(2).enumerate() {
        let (s, t) = (w[0], w[1]);
        // The rotary axes never jump, at any kind of joint.
        let jump = |k: usize| (s.rotary[1][k] - t.rotary[0][k]).abs();
        if (0..3).any(|k| jump(k) > 1e-9 * (1.0 + s.rotary[1][k].abs())) {
            return Err(format!(
                "joint {i}: rotary jump {:?} {:?}",
                s.rotary[1], t.rotary[0]
            ));
        }
        let (pe, ps) = (end_point(s), start_point(t));
        let scale = 1.0 + pe.norm();
        match s.end {
            Junction::Smooth | Junction::Tangent => {
                if (pe - ps).norm() > 1e-9 * scale {
                    return Err(format!("joint {i}: gap {}", (pe - ps).norm()));
                }
                if s.length > 0.0 && t.length > 0.0 {
                    let (ta, ka) = frame(s.curve.as_ref(), s.curve.domain().1);
                    let (tb, kb) = frame(t.curve.as_ref(), t.curve.domain().0);
                    if (ta - tb).norm() > 1e-9 {
                        return Err(format!(
                            "joint {i} ({:?}): tangent jump {}",
                            s.end,
                            (ta - tb).norm()
                        ));
                    }
                    if s.end == Junction::Smooth {
                        let ks = ka
                            .norm()
                            .max(kb.norm())
                            .max(1.0 / s.length.min(t.length).max(1e-300));
                        if (ka - kb).norm() > 1e-9 * ks {
                            return Err(format!(
                                "joint {i}: curvature jump {} (κ {} {})",
                                (ka - kb).norm(),
                                ka.norm(),
                                kb.norm()
                            ));
                        }
                    }
                }
            }
            Junction::Corner | Junction::Stop => {
                // A corner is a programmed vertex, exactly, and the next segment starts there.
                if pe != ps {
                    return Err(format!("joint {i}: corner gap {:?} {:?}", pe, ps));
                }
                if !vertices.contains(&pe) {
                    return Err(format!(
                        "joint {i}: corner {pe:?} is not a programmed vertex"
                    ));
                }
            }
        }
    }
    if let (Some(first), Some(last)) = (segs.first(), segs.last()) {
        if start_point(first) != vertices[0] {
            return Err(format!(
                "start {:?} != {:?}",
                start_point(first),
                vertices[0]
            ));
        }
        let end = *vertices.last().unwrap();
        if end_point(last) != end {
            return Err(format!("end {:?} != {:?}", end_point(last), end));
        }
        if last.end != Junction::Stop {
            return Err("last segment does not stop".into());
        }
    }
    Ok(())
}
