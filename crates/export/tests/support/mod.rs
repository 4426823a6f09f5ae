//! The exported program read back and measured: interpreted by tezgah's own G-code crate as
//! joint moves (each letter a joint, G93 times as a controller computes them), then pushed
//! through the machine's forward kinematics at fine steps and compared with the built path.
#![allow(dead_code)]

pub mod programs;

use tezgah_export::write::Header;
use tezgah_export::{export, AxisLetters, Block, Exported, PassThrough};
use tezgah_gcode::sources::{interpret, Pass, Sources};
use tezgah_gcode::{AxisMask, Canon, CanonSink, Config, Interpreter, Origin, ToolTable};
use tezgah_geom::{ArcLengthMap, Curve, Pose, ToolControl, Vec3};
use tezgah_kinematics::{Joints, Kinematics, Machine, TcpSwitch, Tool};
use tezgah_motion::path::smooth::CHORD_SHARE;
use tezgah_motion::plan::PlanMachine;
use tezgah_motion::{PathItem, Segment};

/// Joint-linear samples per read-back move.
pub const FINE: usize = 64;
/// What printing joints to 1e-5 mm / 1e-6° may add to the tip's distance, mm.
pub const PRINT_SLACK: f64 = 1e-4;

pub struct Case {
    pub machine: Machine,
    pub letters: AxisLetters,
    pub exported: Exported,
    pub text: String,
    /// The tool table the program was read with (the written T words need it too).
    pub tools: String,
}

/// Interprets `program` for `machine` (as `tezgah export` does) and exports it.
pub fn export_program(program: &str, machine: &str, tools: &str, tolerance: f64) -> Case {
    let machine = Machine::builtin(machine).unwrap();
    let config = Config {
        tool_table: ToolTable::parse(tools).unwrap(),
        tool_centre_point_always: machine.tcp == TcpSwitch::Always,
        axes: AxisMask::of(machine.program_axes()),
        ..Config::default()
    };
    let mut words = PassThrough::new();
    let done = interpret(
        Sources::new("case.ngc", program.to_owned()),
        config,
        Pass::Run,
        |_| None,
        &mut words,
    );
    assert!(done.errors.is_empty(), "{:?}", done.errors);
    let placed = words.placed(&done.moves);
    let exported = export(done.moves, &placed, &machine, tolerance, &|k| k).unwrap();
    let letters = AxisLetters::for_machine(&machine).unwrap();
    let header = Header {
        program: "case.ngc",
        machine: &machine.name,
        mapping: letters.describe(&machine),
        budget: exported.summary.budget,
    };
    let text = tezgah_export::write::program(&exported.blocks, &letters, &header);
    Case {
        machine,
        letters,
        exported,
        text,
        tools: tools.to_owned(),
    }
}

/// One move of the written program as a controller reads it.
#[derive(Debug, Clone)]
pub struct ReadMove {
    pub rapid: bool,
    /// Joints (mm, rad) at the end.
    pub joints: Joints,
    /// Minutes at the G93 feed (0 for a rapid).
    pub minutes: f64,
    pub n: Option<i64>,
}

struct Reader<'a> {
    letters: &'a AxisLetters,
    rate: f64,
    at: Pose,
    moves: Vec<ReadMove>,
    words: Vec<String>,
}

impl Reader<'_> {
    fn joints(&self, p: &Pose) -> Joints {
        let mut q = Joints::zeros(self.letters.letters.len());
        for ((v, l), k) in q
            .as_mut_slice()
            .iter_mut()
            .zip(&self.letters.letters)
            .zip(&self.letters.scale)
        {
            let i = "XYZABC".find(*l).expect("letters within X Y Z A B C");
            *v = p.0[i] / k;
        }
        q
    }
}

impl CanonSink for Reader<'_> {
    fn call(&mut self, origin: Origin, call: Canon) {
        match call {
            Canon::SetFeedRate(r) => self.rate = r,
            Canon::StraightTraverse(p) | Canon::StraightFeed(p) => {
                let rapid = matches!(call, Canon::StraightTraverse(_));
                // LinuxCNC's inverse-time length: X Y Z if they move, else A B C.
                let d: Vec<f64> = (0..6).map(|i| p.0[i] - self.at.0[i]).collect();
                let linear = d[..3].iter().any(|v| v.abs() > 1e-7);
                let range = if linear { 0..3 } else { 3..6 };
                let length = d[range].iter().map(|v| v * v).sum::<f64>().sqrt();
                let minutes = if rapid { 0.0 } else { length / self.rate };
                self.moves.push(ReadMove {
                    rapid,
                    joints: self.joints(&p),
                    minutes,
                    n: origin.n,
                });
                self.at = p;
            }
            Canon::ArcFeed { .. } | Canon::NurbsFeed(_) => panic!("a curve in a joint program"),
            Canon::StartSpindle(_) | Canon::FloodOn | Canon::MistOn | Canon::StopSpindle => {
                self.words.push(format!("{call}"))
            }
            _ => {}
        }
    }
}

/// The written program interpreted by tezgah's interpreter: its moves and spindle/coolant
/// calls.
pub fn read_back(case: &Case) -> (Vec<ReadMove>, Vec<String>) {
    let mut reader = Reader {
        letters: &case.letters,
        rate: 0.0,
        at: Pose::ZERO,
        moves: vec![],
        words: vec![],
    };
    let config = Config {
        tool_table: ToolTable::parse(&case.tools).unwrap(),
        ..Config::default()
    };
    let mut interp = Interpreter::new(config);
    interp.run(&case.text, &mut reader).unwrap();
    (reader.moves, reader.words)
}

/// The export's motion blocks (G0/G1) in order with what they realise.
pub fn motion_blocks(case: &Case) -> Vec<&Block> {
    case.exported
        .blocks
        .iter()
        .filter(|b| matches!(b, Block::Rapid { .. } | Block::Feed { .. }))
        .collect()
}

pub fn segment(case: &Case, i: usize) -> &Segment {
    match &case.exported.path[i] {
        PathItem::Segment(s) => s,
        other => panic!("item {i} is {other:?}"),
    }
}

/// The program point (tip, mm) the joints put the tool at under `control`: the forward
/// kinematics, or where the joints are the program axes (TCP off on a trunnion), the joints.
fn program_point(pm: &PlanMachine, q: &Joints, control: ToolControl) -> Vec3 {
    match control {
        ToolControl::Joints { .. } if pm.map_for(control).is_some() => {
            pm.joint_mode_point(q).unwrap().0
        }
        ToolControl::Joints { .. } => pm.model.forward(q, &Tool::default()).unwrap().tip,
        ToolControl::CentrePoint { tool_length } => {
            pm.model
                .forward(q, &Tool::with_length(tool_length))
                .unwrap()
                .tip
        }
    }
}

/// What the read-back shows.
#[derive(Debug, Default)]
pub struct Measured {
    /// Largest distance of the joint-linear tip from the built path, over its budget
    /// (CHORD_SHARE of the segment's tolerance).
    pub worst_ratio: f64,
    pub worst_mm: f64,
    /// Where the path carries a tool axis: the largest angle of the joint-linear tool axis
    /// from the path's axis at the same fraction of the move, over its budget (CHORD_SHARE of
    /// the angular tolerance).
    pub worst_axis_ratio: f64,
    /// Feed blocks checked and the largest relative difference of a block's G93 time from
    /// its piece's length (or rotary share) at the programmed feed.
    pub feed_blocks: usize,
    pub worst_time_error: f64,
    /// Minutes of every G1 block per segment index.
    pub minutes: Vec<(usize, f64)>,
}

/// Reads the written program back and measures every move: joints as the export meant them,
/// the joint-linear tip within budget of its piece at [`FINE`] steps, each segment's last
/// move ending on the segment's end point, and each feed block's time.
pub fn measure(case: &Case) -> Measured {
    let pm = PlanMachine::from_machine(&case.machine).unwrap();
    let alpha = case.machine.path.axis_tolerance_deg.unwrap_or(0.1);
    let axis_budget = CHORD_SHARE * alpha.to_radians();
    let (read, _) = read_back(case);
    let blocks = motion_blocks(case);
    assert_eq!(read.len(), blocks.len(), "moves read back vs written");
    let mut m = Measured::default();
    let mut prev = pm
        .joints(
            pm.initial,
            &Vec3::zeros(),
            &[0.0; 3],
            &Joints::zeros(pm.joint_count()),
        )
        .unwrap();
    let mut per_segment: Vec<(usize, f64)> = vec![];
    for (k, (r, b)) in read.iter().zip(&blocks).enumerate() {
        let (joints, piece, minutes) = match b {
            Block::Rapid { joints, piece, .. } => (joints, *piece, None),
            Block::Feed {
                joints,
                piece,
                minutes,
                ..
            } => (joints, Some(*piece), Some(*minutes)),
            _ => unreachable!(),
        };
        for (g, w) in r.joints.as_slice().iter().zip(joints.as_slice()) {
            assert!((g - w).abs() < 1e-5, "block {k}: read {g}, written {w}");
        }
        assert_eq!(r.rapid, minutes.is_none(), "block {k}");
        if let Some(p) = piece {
            let seg = segment(case, p.segment);
            let budget = CHORD_SHARE * seg.tolerance;
            let (u0, u1) = p.u;
            let lengths =
                (!seg.rotary_only()).then(|| ArcLengthMap::new(&*seg.curve, 1e-10).unwrap());
            for j in 0..=FINE {
                let t = j as f64 / FINE as f64;
                let q = prev.lerp(&r.joints, t);
                let tip = program_point(&pm, &q, seg.control);
                let d = if seg.rotary_only() {
                    (tip - seg.curve.point(u0)).norm()
                } else {
                    tezgah_geom::deviation::closest_point(&*seg.curve, &tip, u0, u1, 16).distance
                };
                // The tool axis against the path's at the same fraction of the move (the
                // tip's nearest point is no reference where a blend turns the axis fast).
                if let (Some(path), ToolControl::CentrePoint { tool_length }) =
                    (seg.axis, seg.control)
                {
                    let got = pm
                        .model
                        .forward(&q, &Tool::with_length(tool_length))
                        .unwrap()
                        .axis;
                    let s = p.s.0 + (p.s.1 - p.s.0) * t;
                    let u = u0 + (u1 - u0) * s;
                    let f = match &lengths {
                        // The chord's arc length, in step with the tip along it.
                        Some(map) => {
                            let (a, b) = (map.s_at(&*seg.curve, u0), map.s_at(&*seg.curve, u1));
                            (a + (b - a) * s) / map.length()
                        }
                        None => s,
                    };
                    let angle = got.angle(&path.at(u, f.min(1.0)));
                    assert!(
                        angle <= axis_budget + 1e-6,
                        "block {k} (line {:?}) at t = {t}: tool axis {angle} rad off, budget {axis_budget}",
                        r.n
                    );
                    m.worst_axis_ratio = m.worst_axis_ratio.max(angle / axis_budget);
                }
                assert!(
                    d <= budget + PRINT_SLACK,
                    "block {k} (line {:?}) at t = {t}: {d} mm from the path, budget {budget}",
                    r.n
                );
                m.worst_mm = m.worst_mm.max(d);
                m.worst_ratio = m.worst_ratio.max(d / budget);
            }
            // A segment's last move ends on the segment's end: no part of it is skipped.
            let last_of_segment = blocks
                .get(k + 1)
                .is_none_or(|next| piece_of(next).is_none_or(|q| q.segment != p.segment));
            if last_of_segment {
                let end = seg.curve.point(seg.curve.domain().1);
                let tip = program_point(&pm, &r.joints, seg.control);
                assert!(
                    (tip - end).norm() < PRINT_SLACK,
                    "segment {} ends at {tip:?}, not {end:?}",
                    p.segment
                );
            }
            if let Some(want) = minutes {
                m.feed_blocks += 1;
                let err = (r.minutes - want).abs() / want;
                m.worst_time_error = m.worst_time_error.max(err);
                // The block's own share of its segment at the programmed feed.
                let v = match seg.feed {
                    tezgah_motion::SegmentFeed::Feed(v) => v * 60.0,
                    other => panic!("{other:?}"),
                };
                if !seg.rotary_only() {
                    let expected = p.length / v;
                    let e = (r.minutes - expected).abs() / expected;
                    m.worst_time_error = m.worst_time_error.max(e);
                }
                match per_segment.last_mut() {
                    Some((s, t)) if *s == p.segment => *t += r.minutes,
                    _ => per_segment.push((p.segment, r.minutes)),
                }
            }
        }
        prev = r.joints;
    }
    m.minutes = per_segment;
    m
}

fn piece_of(b: &Block) -> Option<tezgah_export::Piece> {
    match b {
        Block::Rapid { piece, .. } => *piece,
        Block::Feed { piece, .. } => Some(*piece),
        _ => None,
    }
}

/// Minutes of the read-back G1 blocks per source line (the N word).
pub fn minutes_per_line(case: &Case) -> std::collections::BTreeMap<i64, f64> {
    let mut out = std::collections::BTreeMap::new();
    for r in read_back(case).0.iter().filter(|r| !r.rapid) {
        *out.entry(r.n.expect("every block numbered")).or_insert(0.0) += r.minutes;
    }
    out
}
