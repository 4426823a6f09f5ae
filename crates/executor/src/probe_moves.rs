//! A probing program's moves between the interpreter and the machine: the probe move ends
//! where the machine came to rest, not at its target, and the moves between two probes run as
//! a part of their own from rest, with the settings (feed, modes, tool control) the moves
//! before them made. `tezgah run` cuts and joins its parts with these.

use tezgah_geom::{Move, MoveKind, Pose, Vec3};

/// The moves `[from, to)` preceded by the settings the moves before them made (feed, modes,
/// tool control), the tool-control switches among those placed at `start`.
pub fn part(moves: &[Move], from: usize, to: usize, start: Pose) -> Vec<Move> {
    let settings = moves[..from].iter().filter_map(|m| match m.kind {
        MoveKind::FeedRate { .. }
        | MoveKind::FeedMode(_)
        | MoveKind::SpindleSpeed { .. }
        | MoveKind::PathMode(_)
        | MoveKind::Smoothing(_)
        | MoveKind::FeedOverride(_) => Some(m.clone()),
        MoveKind::ToolControl { control, .. } => Some(Move {
            line: m.line,
            kind: MoveKind::ToolControl { control, at: start },
        }),
        _ => None,
    });
    settings.chain(moves[from..to].iter().cloned()).collect()
}

/// Where the machine stands before `moves[index]`.
pub fn position_before(moves: &[Move], index: usize) -> Pose {
    moves[..index]
        .iter()
        .rev()
        .find_map(|m| match &m.kind {
            MoveKind::Rapid { end } | MoveKind::Feed { end } => Some(*end),
            MoveKind::Arc(a) => Some(a.end),
            MoveKind::Nurbs(n) => Some(n.end),
            MoveKind::ToolControl { at, .. } => Some(*at),
            // A thread ends at its end; a rigid tap comes back to where it started.
            MoveKind::Synced(s) if s.tap.is_none() => Some(s.end),
            _ => None,
        })
        .unwrap_or(Pose::ZERO)
}

/// Each probe move (`stops`: its index and where the machine came to rest) ending at its rest
/// point. The move builder took the probe's target as the current point, so a tool-control
/// switch before the next motion (`at`, e.g. G43 right after a probe) moves by the same shift.
pub fn with_stops(mut moves: Vec<Move>, stops: &[(usize, Pose)]) -> Vec<Move> {
    for &(index, stopped) in stops {
        let Some(MoveKind::Feed { end }) = moves.get_mut(index).map(|m| &mut m.kind) else {
            continue;
        };
        let shift = stopped - *end;
        *end = stopped;
        for m in &mut moves[index + 1..] {
            match &mut m.kind {
                MoveKind::ToolControl { at, .. } => *at = *at + shift,
                MoveKind::Rapid { .. }
                | MoveKind::Feed { .. }
                | MoveKind::Arc(_)
                | MoveKind::Nurbs(_) => break,
                _ => {}
            }
        }
    }
    moves
}

/// The point at fraction `f` of the straight move from `a` to `b`, every coordinate.
pub fn point_at(a: Pose, b: Pose, f: f64) -> Pose {
    let mut p = a;
    for i in 0..6 {
        p.0[i] += f * (b.0[i] - a.0[i]);
    }
    p
}

/// Where `p` lies along the straight move from `a` to `b` in X Y Z, as a fraction of it (the
/// interpreter's measure of a probe answer); `None` for a move without X Y Z travel.
pub fn fraction_along(a: Pose, b: Pose, p: Vec3) -> Option<f64> {
    let (a, b) = (Vec3::from(a.xyz()), Vec3::from(b.xyz()));
    let d = b - a;
    let length2 = d.norm_squared();
    (length2 > 0.0).then(|| (p - a).dot(&d) / length2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tezgah_geom::ToolControl;

    fn pose(x: f64, z: f64) -> Pose {
        Pose([x, 0.0, z, 0.0, 0.0, 0.0])
    }

    fn moves() -> Vec<Move> {
        let control = ToolControl::Joints { tool_length: 1.0 };
        [
            MoveKind::FeedRate { value: 300.0 },
            MoveKind::Rapid {
                end: pose(10.0, 10.0),
            },
            MoveKind::Feed {
                end: pose(10.0, -20.0),
            },
            MoveKind::ToolControl {
                control,
                at: pose(10.0, -19.0),
            },
            MoveKind::Feed {
                end: pose(20.0, -2.0),
            },
            MoveKind::ToolControl {
                control,
                at: pose(20.0, -2.0),
            },
        ]
        .into_iter()
        .enumerate()
        .map(|(k, kind)| Move {
            line: k as u32 + 1,
            kind,
        })
        .collect()
    }

    #[test]
    fn the_probe_move_and_a_switch_after_it_move_to_the_rest_point() {
        let rest = point_at(pose(10.0, 10.0), pose(10.0, -20.0), 0.45);
        assert_eq!(rest, pose(10.0, -3.5));
        let m = with_stops(moves(), &[(2, rest)]);
        assert_eq!(m[2].kind, MoveKind::Feed { end: rest });
        // Shifted by rest − target = +16.5 in Z; the switch after the next motion is not.
        let at = |k: usize| match &m[k].kind {
            MoveKind::ToolControl { at, .. } => *at,
            _ => panic!(),
        };
        assert_eq!((at(3), at(5)), (pose(10.0, -2.5), pose(20.0, -2.0)));
        assert_eq!(position_before(&m, 4), pose(10.0, -2.5));
        assert_eq!(position_before(&m, 2), pose(10.0, 10.0));
        assert_eq!(position_before(&m, 0), Pose::ZERO);
    }

    #[test]
    fn a_part_carries_the_settings_before_it_to_its_start() {
        let start = pose(10.0, -3.5);
        let p = part(&moves(), 4, 5, start);
        let kinds: Vec<_> = p.iter().map(|m| (m.line, m.kind.clone())).collect();
        let control = ToolControl::Joints { tool_length: 1.0 };
        assert_eq!(
            kinds,
            [
                (1, MoveKind::FeedRate { value: 300.0 }),
                (4, MoveKind::ToolControl { control, at: start }),
                (
                    5,
                    MoveKind::Feed {
                        end: pose(20.0, -2.0)
                    }
                ),
            ]
        );
    }
}
