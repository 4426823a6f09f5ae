//! Differential test against LinuxCNC's standalone interpreter `rs274`.
//!
//! Random programs built from the words this interpreter supports are run through both `rs274`
//! and [`Interpreter::run`]; both must accept or both reject (with the same message), and the
//! motion calls (`Canon::is_motion`: traverses, feeds, arcs, dwells, feed rates) must agree in
//! name, count and every number (to 1e-4, the precision `rs274` prints).
//!
//! The oracle is found through `TEZGAH_RS274`, the path of the wrapper script that
//! `.ci/install-rs274` writes; the test is ignored by a plain `cargo test` and fails without it
//! when run (`--include-ignored`, as in `.ci/run`). Knobs for exploring:
//! `TEZGAH_ORACLE_CASES` (default 64) and `TEZGAH_ORACLE_SEED` (default a fixed seed, so that CI
//! runs the same programs every time).
//!
//! The generator keeps most programs valid: it tracks the distance mode, plane, units, feed mode
//! and, while it can, the current point, so that it can place arcs whose radius checks pass.
//! When an offset change makes the current point unknown, an arc is preceded by an absolute
//! `G0` to a known start.

mod support;

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};

use proptest::prelude::*;
use proptest::test_runner::{RngSeed, TestCaseError, TestError, TestRunner};
use tezgah_gcode::{Canon, Config, Interpreter, Origin, ToolTable};

/// Our own small tool table (offsets in inches, as the standalone `rs274` reads them).
const TOOL_TABLE: &str = "T1 P1 Z0.511 D0.125\nT2 P2 Z0.1 D0.0625\nT3 P3 Z1.273 D0.201\n";

const DEFAULT_CASES: u32 = 64;
const DEFAULT_SEED: u64 = 0x7e27_a600_0274_0001;

/// Absolute tolerance on every number of a motion call, plus a relative slack.
const ABS_TOL: f64 = 1e-4;
const REL_TOL: f64 = 1e-9;

/// Names of the calls `Canon::is_motion` selects, as `rs274` prints them.
const MOTION_CALLS: [&str; 6] = [
    "STRAIGHT_TRAVERSE",
    "STRAIGHT_FEED",
    "ARC_FEED",
    "NURBS_FEED",
    "DWELL",
    "SET_FEED_RATE",
];

const AXES: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];
const OFFSET_LETTERS: [char; 3] = ['I', 'J', 'K'];
const COORD_SYSTEMS: [&str; 9] = [
    "G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3",
];
const COMMENTS: [&str; 5] = [
    "(a comment)",
    "(MSG,hello from the oracle test)",
    "(msg, lower case message)",
    "; a semicolon comment",
    "(Tool change: 1/8 end mill)",
];
/// Blocks that are errors whatever the state (or nearly: a few depend on the plane).
const FAULTY: [&str; 14] = [
    "G91 G53 G0 X1",
    "G2 X10 Y10 R0.001",
    "G3 X1 Y1 I1 J1 K1",
    "G4",
    "G10 L2 P10 X1",
    "G0 X1 I1",
    "M3 M4",
    "G93 G1 X1",
    "T9",
    "F-1",
    "G94 G1 F0 X1",
    "G1 X1 Y2 Y3",
    "G0 X1 G92 Y1",
    "G2 X1 Y1",
];

/// Words that may ride along on a motion block.
const EXTRAS: [&str; 16] = [
    "S1000", "M3", "M4", "M5", "M7", "M8", "M9", "S2500 M3", "M48", "M49", "M50 P0", "M50",
    "M51 P0", "M52 P1", "M53 P0", "M53",
];

// ---------------------------------------------------------------------------------------------
// Program model

type Axes = [Option<f64>; 6];

/// Decoration of a block: line number, comment, extra words.
#[derive(Debug, Clone)]
struct Deco {
    n: Option<u32>,
    comment: Option<usize>,
    extra: Option<usize>,
}

#[derive(Debug, Clone)]
enum ToolLength {
    /// G43, with H1..H3 or (0) without H.
    Table(u8),
    /// G43.1 with Z…, X… or both.
    Dynamic { z: Option<f64>, x: Option<f64> },
    /// G49.
    Cancel,
}

#[derive(Debug, Clone)]
enum Item {
    /// G0 / G1 with axis words; `f` is written on G1 when asked for or needed.
    Line {
        rapid: bool,
        axes: Axes,
        f: f64,
        with_f: bool,
    },
    /// G2/G3 in radius format: the end is `start + d`, the radius `factor` × half the chord.
    ArcR {
        cw: bool,
        start: [f64; 3],
        d: (f64, f64),
        factor: f64,
        negative: bool,
        normal: Option<f64>,
        turns: Option<u32>,
        f: f64,
    },
    /// G2/G3 in centre format: centre at `radius` from the start in direction `center_angle`,
    /// end on the circle at `end_angle` (`None`: a full circle). `perturb` moves the end off
    /// the circle (for the radius check's error).
    ArcIjk {
        cw: bool,
        start: [f64; 3],
        radius: f64,
        center_angle: f64,
        end_angle: Option<f64>,
        normal: Option<f64>,
        turns: Option<u32>,
        a: Option<f64>,
        f: f64,
        perturb: Option<f64>,
    },
    Distance {
        incremental: bool,
    },
    Units {
        inches: bool,
    },
    /// 0 = G17, 1 = G18, 2 = G19.
    Plane(u8),
    FeedMode {
        inverse: bool,
    },
    Feed(f64),
    Dwell(f64),
    /// 0 = G61, 1 = G61.1, 2 = G64 (with P, and Q only with P).
    PathControl {
        mode: u8,
        p: Option<f64>,
        q: Option<f64>,
    },
    CoordSystem(usize),
    G10 {
        l20: bool,
        p: u8,
        axes: Axes,
        /// XY rotation R (degrees).
        r: Option<f64>,
    },
    /// G10 L1 / L10 / L11 (`l` = 1, 10, 11) of tool 1–3: X Y Z offsets and R (radius).
    ToolWrite {
        l: u8,
        tool: u8,
        xyz: [Option<f64>; 3],
        r: Option<f64>,
    },
    G92 {
        axes: Axes,
    },
    /// G92.1, G92.2, G92.3.
    G92x(u8),
    G52 {
        axes: Axes,
    },
    /// G28 / G30 with optional intermediate point.
    Home {
        g30: bool,
        axes: Axes,
    },
    /// G28.1 / G30.1.
    SetHome {
        g30: bool,
    },
    /// G53 G0 / G53 G1.
    Machine {
        rapid: bool,
        axes: Axes,
        f: f64,
    },
    Speed(f64),
    /// M3, M4, M5.
    Spindle(u8),
    /// M7, M8, M9.
    Coolant(u8),
    /// T… alone, T… M6 in one block, or T… then M6 on the next line.
    Tool {
        t: u8,
        change: u8,
    },
    ToolLength(ToolLength),
    /// A canned cycle: G98/G99, the cycle, X Y Z, R, L, P, Q (and I J K for G87).
    Cycle {
        retract: Option<bool>,
        code: usize,
        xyz: [Option<f64>; 3],
        r: Option<f64>,
        l: Option<u8>,
        p: Option<f64>,
        q: Option<f64>,
        ijk: [f64; 3],
    },
    /// `o<n> repeat [count]` around one incremental G1 (or G0), then back to the distance
    /// mode in force.
    Repeat {
        count: u8,
        rapid: bool,
        step: [f64; 3],
        f: f64,
    },
    /// `#<v> = [expression]` then a rapid to `X[#<v>]`: LinuxCNC's arithmetic, precedence and
    /// functions against ours.
    Expression(String),
    /// `o<name> call [a] [b]` of one of `SUBROUTINES`, defined after the program's M2.
    Call {
        sub: usize,
        args: [f64; 2],
    },
    /// A contour cut with cutter radius compensation: see [`CompContour`].
    Comp(CompContour),
    /// LinuxCNC's G5 (I J given or taken from the previous G5) or G5.1: X Y end words (one
    /// may be missing), sometimes a Z word (an error: splines stay in XY).
    Spline {
        quadratic: bool,
        ij: Option<(f64, f64)>,
        pq: (f64, f64),
        end: (Option<f64>, Option<f64>),
        z: Option<f64>,
        f: f64,
    },
    /// G5.2 with (X, Y, weight) control points and an optional order L, then G5.3. A weight
    /// of zero after the first point is an error both must report.
    Nurbs {
        points: Vec<(f64, f64, f64)>,
        order: Option<u8>,
        f: f64,
    },
    Comment(usize),
    /// A block both interpreters must reject (`FAULTY`), to compare the error texts.
    Faulty(usize),
    /// G0/G1 with polar words (`@` radius, `^` angle; at least one) and maybe Z, in G17.
    Polar {
        rapid: bool,
        radius: Option<f64>,
        theta: Option<f64>,
        z: Option<f64>,
        f: f64,
    },
    /// M70 (0), M71 (1), M72 (2) or M73 (3).
    Modes(u8),
}

/// The modes the writer tracks, as M70/M73 saved them.
#[derive(Debug, Clone, Copy)]
struct SavedModes {
    incremental: bool,
    plane: u8,
    inverse: bool,
    feed_set: bool,
    inches: bool,
    tool_offset: bool,
}

/// A closed-ish contour cut under G41/G42: vertices around a centre at increasing angles with
/// jittered radii (so both convex and concave corners occur), joined by lines or by R-format
/// arcs either way round; entry from outside, G40 and a straight exit.
#[derive(Debug, Clone)]
struct CompContour {
    left: bool,
    /// G18 (Z, X) instead of G17.
    xz: bool,
    /// `None`: D from the tool table (tool 1..3); `Some(d)`: G41.1/G42.1 with this diameter.
    /// (No D, or D0, would take the diameter of LinuxCNC's spindle slot, which the standalone
    /// `rs274` leaves uninitialised before an M6: its output then varies from run to run.)
    dynamic: Option<f64>,
    tool: u8,
    center: [f64; 2],
    radius: f64,
    /// (angle step in degrees, radius factor, joint): 0 line, 1 arc CCW, 2 arc CW.
    vertices: Vec<(f64, f64, u8)>,
    /// Arc radius over half the chord.
    bulge: f64,
    f: f64,
}

// ---------------------------------------------------------------------------------------------
// Rendering

/// Round to 4 decimals.
fn round4(v: f64) -> f64 {
    (v * 1e4).round() / 1e4
}

/// A number with at most 4 decimals, trailing zeros dropped.
fn num(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

fn axis_words(axes: &Axes) -> String {
    let mut s = String::new();
    for (i, v) in axes.iter().enumerate() {
        if let Some(v) = v {
            s.push_str(&format!(" {}{}", AXES[i], num(*v)));
        }
    }
    s
}

/// In-plane axes (first, second) and normal axis of G17, G18, G19, as LinuxCNC orders them.
fn plane_axes(plane: u8) -> (usize, usize, usize) {
    match plane {
        0 => (0, 1, 2),
        1 => (2, 0, 1),
        _ => (1, 2, 0),
    }
}

/// The program text and the modal state the generator tracks while writing it.
struct Writer {
    text: String,
    incremental: bool,
    plane: u8,
    inverse: bool,
    /// A non-zero units-per-minute feed is in force.
    feed_set: bool,
    inches: bool,
    /// Current point in program coordinates, axis by axis while known.
    pos: [Option<f64>; 6],
    /// A G10 gave an XY rotation: M6 is no longer generated.
    rotation_used: bool,
    /// An M6 was written: tool length words are no longer generated.
    changed_tool: bool,
    /// A G43 or G43.1 is in force (not cancelled by G49).
    tool_offset: bool,
    /// A G43, G43.1 or G49 was written: no M6 from then on.
    tool_length_used: bool,
    /// A G5, G5.1 or G5.2 was written: no M6 from then on (see `Item::Tool`).
    spline_used: bool,
    /// O-word labels used so far (each loop gets its own).
    labels: u32,
    /// Which of `SUBROUTINES` the program calls (their bodies follow M2).
    used_subs: [bool; SUBROUTINES.len()],
    /// What the last M70/M73 saved (`None` before one, or after M71).
    saved_modes: Option<SavedModes>,
}

impl Writer {
    fn new() -> Self {
        Writer {
            text: String::new(),
            incremental: false,
            plane: 0,
            inverse: false,
            feed_set: false,
            inches: false,
            pos: [Some(0.0); 6],
            changed_tool: false,
            tool_offset: false,
            tool_length_used: false,
            spline_used: false,
            rotation_used: false,
            labels: 0,
            used_subs: [false; SUBROUTINES.len()],
            saved_modes: None,
        }
    }

    fn block(&mut self, deco: &Deco, words: &str) {
        if let Some(n) = deco.n {
            self.text.push_str(&format!("N{n} "));
        }
        self.text.push_str(words.trim_start());
        if let Some(c) = deco.comment {
            self.text.push(' ');
            self.text.push_str(COMMENTS[c]);
        }
        self.text.push('\n');
    }

    /// F word of a feed move: always in inverse time, else when asked or when none is in force.
    fn feed_word(&mut self, f: f64, with_f: bool) -> String {
        if self.inverse {
            format!(" F{}", num(f))
        } else if with_f || !self.feed_set {
            self.feed_set = true;
            format!(" F{}", num(f))
        } else {
            String::new()
        }
    }

    /// Forget the current point (after an offset change).
    fn forget(&mut self) {
        self.pos = [None; 6];
    }

    fn xyz(&self) -> Option<[f64; 3]> {
        Some([self.pos[0]?, self.pos[1]?, self.pos[2]?])
    }

    fn move_to(&mut self, axes: &Axes) {
        for (i, v) in axes.iter().enumerate() {
            if let Some(v) = v {
                self.pos[i] = if self.incremental {
                    self.pos[i].map(|p| p + v)
                } else {
                    Some(*v)
                };
            }
        }
    }

    /// The current point, after an absolute G0 to `start` if it is not known. Returns the
    /// point and the distance word the arc block must carry to restore G91.
    fn arc_start(&mut self, start: [f64; 3]) -> ([f64; 3], &'static str) {
        if let Some(p) = self.xyz() {
            return (p, "");
        }
        let prefix = if self.incremental { "G90 " } else { "" };
        self.text.push_str(&format!(
            "{prefix}G0 X{} Y{} Z{}\n",
            num(start[0]),
            num(start[1]),
            num(start[2])
        ));
        self.set_xyz(start);
        (start, if self.incremental { "G91 " } else { "" })
    }

    fn set_xyz(&mut self, p: [f64; 3]) {
        for (i, v) in p.into_iter().enumerate() {
            self.pos[i] = Some(v);
        }
    }

    /// `G2|G3` with the in-plane end words and the optional helix word. The end `e` is put on
    /// the 4-decimal grid the program is written in (increments under G91) and left as the
    /// interpreter will read it, the normal axis included.
    #[allow(clippy::too_many_arguments)]
    fn arc_head(
        &self,
        deco: &Deco,
        restore: &str,
        cw: bool,
        (a, b, n): (usize, usize, usize),
        normal: Option<f64>,
        s: [f64; 3],
        e: &mut [f64; 3],
    ) -> String {
        let (wa, wb) = if self.incremental {
            let w = (round4(e[a] - s[a]), round4(e[b] - s[b]));
            (e[a], e[b]) = (s[a] + w.0, s[b] + w.1);
            w
        } else {
            (e[a], e[b]) = (round4(e[a]), round4(e[b]));
            (e[a], e[b])
        };
        let mut words = format!(
            "{}{restore}G{} {}{} {}{}",
            Self::extra(deco),
            if cw { 2 } else { 3 },
            AXES[a],
            num(wa),
            AXES[b],
            num(wb)
        );
        if let Some(v) = normal {
            words.push_str(&format!(" {}{}", AXES[n], num(v)));
            e[n] = if self.incremental { s[n] + v } else { v };
        }
        words
    }

    /// Write a [`CompContour`]; the program is absolute afterwards, in the contour's plane.
    fn comp_contour(&mut self, c: &CompContour, deco: &Deco) {
        self.incremental = false;
        self.plane = if c.xz { 1 } else { 0 };
        let (a, b, _) = plane_axes(self.plane);
        let at = |angle_deg: f64, factor: f64| {
            let (s, co) = angle_deg.to_radians().sin_cos();
            let r = c.radius * factor;
            [round4(c.center[0] + r * co), round4(c.center[1] + r * s)]
        };
        let point = |p: [f64; 2]| format!("{}{} {}{}", AXES[a], num(p[0]), AXES[b], num(p[1]));
        let outside = at(0.0, 1.6);
        let plane = if c.xz { "G18" } else { "G17" };
        self.block(deco, &format!("G90 {plane} G0 {}", point(outside)));
        let g = if c.left { 41 } else { 42 };
        let on = match (c.dynamic, c.tool) {
            (Some(d), _) => format!("G{g}.1 D{}", num(d)),
            (None, t) => format!("G{g} D{t}"),
        };
        self.text.push_str(&format!(
            "{on}
"
        ));
        let mut angle = 0.0;
        let mut here = at(angle, c.vertices[0].1);
        let feed = self.feed_word(c.f, true);
        self.text.push_str(&format!(
            "G1 {}{feed}
",
            point(here)
        ));
        for &(step, factor, joint) in &c.vertices[1..] {
            angle += step;
            let next = at(angle, factor);
            let feed = self.feed_word(c.f, false);
            if joint == 0 || next == here {
                self.text.push_str(&format!(
                    "G1 {}{feed}
",
                    point(next)
                ));
            } else {
                let half = (next[0] - here[0]).hypot(next[1] - here[1]) / 2.0;
                let r = (half * c.bulge * 1e4).ceil() / 1e4;
                let g = if joint == 1 { 3 } else { 2 };
                self.text.push_str(&format!(
                    "G{g} {} R{}{feed}
",
                    point(next),
                    num(r)
                ));
            }
            here = next;
        }
        self.text.push_str(
            "G40
",
        );
        let exit = at(angle, 1.8);
        let feed = self.feed_word(c.f, false);
        self.text.push_str(&format!(
            "G1 {}{feed}
",
            point(exit)
        ));
        // The compensated tool ends beside the programmed point: only the plane's axes
        // and the exit are known exactly.
        self.forget();
        self.pos[a] = Some(exit[0]);
        self.pos[b] = Some(exit[1]);
    }

    fn extra(deco: &Deco) -> String {
        deco.extra
            .map_or(String::new(), |e| format!("{} ", EXTRAS[e]))
    }

    fn item(&mut self, item: &Item, deco: &Deco) {
        match item {
            Item::Line {
                rapid,
                axes,
                f,
                with_f,
            } => {
                let mut words = format!("{}G{}", Self::extra(deco), if *rapid { 0 } else { 1 });
                words.push_str(&axis_words(axes));
                if !*rapid {
                    words.push_str(&self.feed_word(*f, *with_f));
                }
                self.block(deco, &words);
                self.move_to(axes);
            }
            Item::ArcR {
                cw,
                start,
                d,
                factor,
                negative,
                normal,
                turns,
                f,
            } => {
                let (a, b, n) = plane_axes(self.plane);
                let (s, restore) = self.arc_start(*start);
                let (mut da, db) = *d;
                if da.hypot(db) < 0.01 {
                    da += 1.0;
                }
                let mut e = s;
                e[a] += da;
                e[b] += db;
                let mut words = self.arc_head(deco, restore, *cw, (a, b, n), *normal, s, &mut e);
                let half = (e[a] - s[a]).hypot(e[b] - s[b]) / 2.0;
                // Rounded up, so that the radius always reaches.
                let mut r = (half * factor * 1e4).ceil() / 1e4;
                if *negative {
                    r = -r;
                }
                words.push_str(&format!(" R{}", num(r)));
                if let Some(p) = turns {
                    words.push_str(&format!(" P{p}"));
                }
                words.push_str(&self.feed_word(*f, false));
                self.block(deco, &words);
                self.set_xyz(e);
            }
            Item::ArcIjk {
                cw,
                start,
                radius,
                center_angle,
                end_angle,
                normal,
                turns,
                a: a_word,
                f,
                perturb,
            } => {
                let (a, b, n) = plane_axes(self.plane);
                let (s, restore) = self.arc_start(*start);
                let (sin, cos) = center_angle.sin_cos();
                let o = [round4(radius * cos), round4(radius * sin)];
                let c = [s[a] + o[0], s[b] + o[1]];
                let r = o[0].hypot(o[1]);
                let mut e = s;
                // Without an end angle, a full circle: the end is the start.
                if let Some(phi) = end_angle {
                    let (sin, cos) = phi.sin_cos();
                    e[a] = c[0] + r * cos;
                    e[b] = c[1] + r * sin;
                }
                if let Some(dp) = perturb {
                    e[a] += dp;
                }
                let mut words = self.arc_head(deco, restore, *cw, (a, b, n), *normal, s, &mut e);
                if let Some(v) = a_word {
                    words.push_str(&format!(" A{}", num(*v)));
                }
                // A zero offset may be left out.
                for (k, &axis) in [a, b].iter().enumerate() {
                    if o[k] != 0.0 {
                        words.push_str(&format!(" {}{}", OFFSET_LETTERS[axis], num(o[k])));
                    }
                }
                if let Some(p) = turns {
                    words.push_str(&format!(" P{p}"));
                }
                let chord = (e[a] - s[a]).hypot(e[b] - s[b]);
                if self.inverse && chord > 0.0 && chord < 1e-6 {
                    // Deliberate: an end a rounding error away from the start (X-53.0708 after
                    // X-26.8929 plus incremental X-26.1779) is a full circle to tezgah's `sweep`
                    // (angles within 1e-12) but an almost empty arc to LinuxCNC's
                    // find_arc_length (full only when the angles are exactly equal), and only
                    // the inverse-time feed rate shows it. tezgah keeps one answer for the rate and
                    // the motion: the full circle. Not generated.
                    return;
                }
                words.push_str(&self.feed_word(*f, false));
                self.block(deco, &words);
                self.set_xyz(e);
                if let Some(v) = a_word {
                    self.pos[3] = if self.incremental {
                        self.pos[3].map(|p| p + v)
                    } else {
                        Some(*v)
                    };
                }
            }
            Item::Distance { incremental } => {
                self.block(deco, if *incremental { "G91" } else { "G90" });
                self.incremental = *incremental;
            }
            Item::Units { inches } => {
                // Deliberate: on G20/G21 LinuxCNC re-reads the tool length offset from its canon
                // layer. The standalone rs274's canon returns it unconverted (`G43 H1 / G20`
                // leaves 12.9794 "inches" of offset; a later G43/G49/G53 shifts by that), while
                // milltask's canon converts it, as tezgah does. No unit change under a tool
                // length offset.
                if self.tool_offset {
                    return;
                }
                self.block(deco, if *inches { "G20" } else { "G21" });
                if *inches != self.inches {
                    let k = if *inches { 1.0 / 25.4 } else { 25.4 };
                    for p in self.pos.iter_mut().take(3) {
                        *p = p.map(|v| v * k);
                    }
                    self.inches = *inches;
                }
            }
            Item::Plane(p) => {
                self.block(deco, ["G17", "G18", "G19"][*p as usize]);
                self.plane = *p;
            }
            Item::FeedMode { inverse } => {
                self.block(deco, if *inverse { "G93" } else { "G94" });
                self.inverse = *inverse;
                if !inverse {
                    // G94 sets the feed rate to zero.
                    self.feed_set = false;
                }
            }
            Item::Feed(f) => {
                self.block(deco, &format!("F{}", num(*f)));
                if !self.inverse {
                    self.feed_set = true;
                }
            }
            Item::Dwell(p) => self.block(deco, &format!("G4 P{}", num(*p))),
            Item::PathControl { mode, p, q } => {
                let words = match mode {
                    0 => "G61".to_string(),
                    1 => "G61.1".to_string(),
                    _ => {
                        let mut w = "G64".to_string();
                        if let Some(p) = p {
                            w.push_str(&format!(" P{}", num(*p)));
                            if let Some(q) = q {
                                w.push_str(&format!(" Q{}", num(*q)));
                            }
                        }
                        w
                    }
                };
                self.block(deco, &words);
            }
            Item::CoordSystem(i) => {
                self.block(deco, COORD_SYSTEMS[*i]);
                self.forget();
            }
            Item::G10 { l20, p, axes, r } => {
                let r = if self.changed_tool { &None } else { r };
                self.rotation_used |= r.is_some();
                let l = if *l20 { 20 } else { 2 };
                let r = r.map_or(String::new(), |r| format!(" R{}", num(r)));
                self.block(deco, &format!("G10 L{l} P{p}{}{r}", axis_words(axes)));
                self.forget();
            }
            Item::ToolWrite { l, tool, xyz, r } => {
                let mut words = format!("G10 L{l} P{tool}");
                for (k, v) in xyz.iter().enumerate() {
                    if let Some(v) = v {
                        words.push_str(&format!(" {}{}", AXES[k], num(*v)));
                    }
                }
                match r {
                    Some(r) => words.push_str(&format!(" R{}", num(*r))),
                    None if xyz.iter().all(Option::is_none) => words.push_str(" Z0"),
                    None => {}
                }
                self.block(deco, &words);
            }
            Item::G92 { axes } => {
                self.block(deco, &format!("G92{}", axis_words(axes)));
                self.forget();
            }
            Item::G92x(k) => {
                self.block(deco, &format!("G92.{k}"));
                self.forget();
            }
            Item::G52 { axes } => {
                self.block(deco, &format!("G52{}", axis_words(axes)));
                self.forget();
            }
            Item::Home { g30, axes } => {
                let g = if *g30 { "G30" } else { "G28" };
                self.block(deco, &format!("{g}{}", axis_words(axes)));
                self.forget();
            }
            Item::SetHome { g30 } => {
                self.block(deco, if *g30 { "G30.1" } else { "G28.1" });
            }
            Item::Machine { rapid, axes, f } => {
                // G53 needs absolute distance mode.
                let mut words = if self.incremental {
                    "G90 ".to_string()
                } else {
                    String::new()
                };
                self.incremental = false;
                words.push_str(&format!("G53 G{}", if *rapid { 0 } else { 1 }));
                words.push_str(&axis_words(axes));
                if !*rapid {
                    words.push_str(&self.feed_word(*f, false));
                }
                self.block(deco, &words);
                self.forget();
            }
            Item::Speed(s) => self.block(deco, &format!("S{}", num(*s))),
            Item::Spindle(m) => self.block(deco, &format!("M{m}")),
            Item::Coolant(m) => self.block(deco, &format!("M{m}")),
            Item::Tool { t, change } => {
                // Deliberate: after M6 the standalone rs274 re-reads the current point from its
                // canon layer, whose point does not follow tool length offset changes (G43,
                // G43.1, G49 move the program point without a motion), so `G43 H1 / G1 X1 F1 /
                // G49 / T1 M6 / G53 G1 X1` ends at Z-12.9794 in rs274 and Z0 in tezgah. tezgah
                // does not copy that: a program has tool length words or M6, not both (no M6
                // after G43/G43.1/G49 here, no G43/G43.1/G49 after M6 below).
                // The same re-read loses an XY rotation's effect on the point, so no M6 once a
                // G10 has given a rotation either (and no rotation after M6, below). Nor once a
                // spline was made: rs274's canon prints NURBS_FEED without moving its point.
                let change = if self.tool_length_used || self.rotation_used || self.spline_used {
                    &0
                } else {
                    change
                };
                match change {
                    0 => self.block(deco, &format!("T{t}")),
                    1 => self.block(deco, &format!("T{t} M6")),
                    _ => {
                        self.block(deco, &format!("T{t}"));
                        self.text.push_str("M6\n");
                    }
                }
                if *change != 0 {
                    self.changed_tool = true;
                }
            }
            Item::ToolLength(tl) => {
                // Not after an M6: the standalone rs274 re-reads the position after a tool
                // change in a way tezgah deliberately does not copy.
                if self.changed_tool {
                    return;
                }
                self.tool_length_used = true;
                let words = match tl {
                    ToolLength::Table(0) => "G43".to_string(),
                    ToolLength::Table(h) => format!("G43 H{h}"),
                    ToolLength::Dynamic { z, x } => {
                        let mut words = "G43.1".to_string();
                        for (letter, v) in [("Z", z), ("X", x)] {
                            if let Some(v) = v {
                                words.push_str(&format!(" {letter}{}", num(*v)));
                            }
                        }
                        words
                    }
                    ToolLength::Cancel => "G49".to_string(),
                };
                self.block(deco, &words);
                self.tool_offset = !matches!(tl, ToolLength::Cancel);
                self.forget();
            }
            Item::Cycle {
                retract,
                code,
                xyz,
                r,
                l,
                p,
                q,
                ijk,
            } => {
                // LinuxCNC 2.9 feeds G74/G84 along the wrong axes outside G17 (see linuxcnc.rs).
                let code = match CYCLES[*code] {
                    "G74" | "G84" if self.plane != 0 => "G81",
                    c => c,
                };
                let mut words = Self::extra(deco);
                if let Some(old) = retract {
                    words.push_str(if *old { "G98 " } else { "G99 " });
                }
                words.push_str(code);
                for (letter, v) in ["X", "Y", "Z"].iter().zip(xyz) {
                    if let Some(v) = v {
                        words.push_str(&format!(" {letter}{}", num(*v)));
                    }
                }
                let extra = [("R", *r), ("L", l.map(f64::from)), ("P", *p), ("Q", *q)];
                for (letter, v) in extra {
                    if let Some(v) = v {
                        words.push_str(&format!(" {letter}{}", num(v)));
                    }
                }
                if code == "G87" {
                    for (letter, v) in ["I", "J", "K"].iter().zip(ijk) {
                        words.push_str(&format!(" {letter}{}", num(*v)));
                    }
                }
                self.block(deco, &words);
                self.forget();
            }
            Item::Repeat {
                count,
                rapid,
                step,
                f,
            } => {
                self.labels += 1;
                let label = 900 + self.labels;
                self.block(deco, &format!("o{label} repeat [{count}]"));
                let g = if *rapid { 0 } else { 1 };
                let feed = if *rapid {
                    String::new()
                } else {
                    self.feed_word(*f, true)
                };
                self.text.push_str(&format!(
                    "G91 G{g} X{} Y{} Z{}{feed}\n",
                    num(step[0]),
                    num(step[1]),
                    num(step[2])
                ));
                self.text.push_str(&format!("o{label} endrepeat\n"));
                if !self.incremental {
                    self.text.push_str("G90\n");
                }
                self.forget();
            }
            Item::Comp(c) => self.comp_contour(c, deco),
            Item::Expression(e) => {
                self.block(deco, &format!("#<v> = {e}"));
                let prefix = if self.incremental { "G90 " } else { "" };
                self.text.push_str(&format!("{prefix}G0 X[#<v>]\n"));
                if self.incremental {
                    self.text.push_str("G91\n");
                }
                self.forget();
            }
            Item::Call { sub, args } => {
                let (name, _) = SUBROUTINES[*sub];
                self.used_subs[*sub] = true;
                self.block(
                    deco,
                    &format!("o<{name}> call [{}] [{}]", num(args[0]), num(args[1])),
                );
                // The bodies move in G91 and leave G90: restore the caller's mode.
                if self.incremental {
                    self.text.push_str("G91\n");
                }
                // The returned value (0 unless the subroutine returns one) moves X.
                let prefix = if self.incremental { "G90 " } else { "" };
                self.text.push_str(&format!("{prefix}G0 X[#<_value>]\n"));
                if self.incremental {
                    self.text.push_str("G91\n");
                }
                self.forget();
            }
            Item::Spline {
                quadratic,
                ij,
                pq,
                end,
                z,
                f,
            } => {
                // Mostly select G17 first: outside it every spline is an error.
                let g17 = if self.plane != 0 && pq.0 >= -15.0 {
                    self.plane = 0;
                    "G17 "
                } else {
                    ""
                };
                let mut words = format!(
                    "{}{g17}G{}",
                    Self::extra(deco),
                    if *quadratic { "5.1" } else { "5" }
                );
                let axes: Axes = [end.0, end.1, *z, None, None, None];
                words.push_str(&axis_words(&axes));
                if let Some((i, j)) = ij {
                    words.push_str(&format!(" I{} J{}", num(*i), num(*j)));
                }
                if !*quadratic {
                    words.push_str(&format!(" P{} Q{}", num(pq.0), num(pq.1)));
                }
                words.push_str(&self.feed_word(*f, false));
                self.block(deco, &words);
                self.move_to(&axes);
                self.spline_used = true;
            }
            Item::Nurbs { points, order, f } => {
                for (k, (x, y, w)) in points.iter().enumerate() {
                    let mut words = format!("X{} Y{} P{}", num(*x), num(*y), num(*w));
                    if k == 0 {
                        words = format!("G5.2 {words}");
                        if let Some(l) = order {
                            words.push_str(&format!(" L{l}"));
                        }
                        words.push_str(&self.feed_word(*f, false));
                    }
                    self.block(deco, &words);
                }
                self.block(deco, "G5.3");
                self.spline_used = true;
                // Every point is relative to the start under G91: the end is the last one.
                if let Some(&(x, y, _)) = points.last() {
                    self.move_to(&[Some(x), Some(y), None, None, None, None]);
                }
            }
            Item::Comment(c) => self.block(deco, COMMENTS[*c]),
            Item::Faulty(k) => self.block(deco, FAULTY[*k]),
            Item::Polar {
                rapid,
                radius,
                theta,
                z,
                f,
            } => {
                // Polar words only in G17 (elsewhere both refuse them: tested in `dialect`).
                let plane = if self.plane != 0 { "G17 " } else { "" };
                self.plane = 0;
                let mut words = format!("{}{plane}G{}", Self::extra(deco), u8::from(!rapid));
                if let Some(r) = radius {
                    words.push_str(&format!(" @{}", num(*r)));
                }
                if let Some(t) = theta {
                    words.push_str(&format!(" ^{}", num(*t)));
                }
                if let Some(z) = z {
                    words.push_str(&format!(" Z{}", num(*z)));
                }
                if !*rapid {
                    words.push_str(&self.feed_word(*f, false));
                }
                self.block(deco, &words);
                // The polar end is not tracked: arcs after it start with an absolute G0.
                self.pos[0] = None;
                self.pos[1] = None;
                if let Some(z) = z {
                    self.pos[2] = if self.incremental {
                        self.pos[2].map(|p| p + z)
                    } else {
                        Some(*z)
                    };
                }
            }
            Item::Modes(m) => {
                let now = SavedModes {
                    incremental: self.incremental,
                    plane: self.plane,
                    inverse: self.inverse,
                    feed_set: self.feed_set,
                    inches: self.inches,
                    tool_offset: self.tool_offset,
                };
                match (m, self.saved_modes) {
                    (1, _) => {
                        self.block(deco, "M71");
                        self.saved_modes = None;
                    }
                    (2, Some(saved)) => {
                        // A restored G43/G49, or units changed under a tool length offset,
                        // meet the deliberate differences noted at `Item::Units`.
                        if saved.tool_offset != now.tool_offset
                            || (saved.inches != now.inches && now.tool_offset)
                        {
                            return;
                        }
                        self.block(deco, "M72");
                        self.incremental = saved.incremental;
                        self.plane = saved.plane;
                        self.inverse = saved.inverse;
                        self.feed_set = saved.feed_set;
                        self.inches = saved.inches;
                        self.forget();
                    }
                    // M72 with nothing saved would end the program: save instead.
                    _ => {
                        self.block(deco, if *m == 3 { "M73" } else { "M70" });
                        self.saved_modes = Some(now);
                    }
                }
            }
        }
    }
}

/// Subroutines the generated programs call, defined after M2 (LinuxCNC finds them by reading
/// on): arguments, locals, a loop, return values through `return` and `endsub`.
const SUBROUTINES: [(&str, &str); 3] = [
    ("step", "#<d> = [#1 + #2]\nG91 G0 X#<d> Y[#2]\nG90\n"),
    ("ret", "o101 if [#1 GT #2]\no<ret> return [#1 - #2]\no101 endif\n"),
    (
        "walk",
        "#3 = 0\no102 while [#3 LT 3]\nG91 G0 X[#1 / 3] Z[#2 / 3]\n#3 = [#3 + 1]\no102 endwhile\nG90\n",
    ),
];

fn render(items: &[(Item, Deco)]) -> String {
    let mut w = Writer::new();
    for (item, deco) in items {
        w.item(item, deco);
    }
    w.text.push_str("M2\n");
    for (used, (name, body)) in w.used_subs.iter().zip(SUBROUTINES) {
        if *used {
            let end = if name == "ret" { " [#1 * 2]" } else { "" };
            w.text
                .push_str(&format!("o<{name}> sub\n{body}o<{name}> endsub{end}\n"));
        }
    }
    w.text
}

// ---------------------------------------------------------------------------------------------
// Strategies

/// A number with 4 decimals in [-max, max].
fn value(max: f64) -> impl Strategy<Value = f64> {
    let m = (max * 1e4) as i64;
    (-m..=m).prop_map(|v| v as f64 / 1e4)
}

fn positive(min: f64, max: f64) -> impl Strategy<Value = f64> {
    ((min * 1e4) as i64..=(max * 1e4) as i64).prop_map(|v| v as f64 / 1e4)
}

/// Axis words: X Y Z often, A B C sometimes; at least one.
fn axes() -> impl Strategy<Value = Axes> {
    let linear = || proptest::option::weighted(0.5, value(60.0));
    let rotary = || proptest::option::weighted(0.1, value(360.0));
    (linear(), linear(), linear(), rotary(), rotary(), rotary()).prop_map(|(x, y, z, a, b, c)| {
        let mut axes = [x, y, z, a, b, c];
        if axes.iter().all(Option::is_none) {
            axes[0] = Some(1.0);
        }
        axes
    })
}

/// Axis words that may all be missing (G28/G30).
/// The canned cycles the generator writes.
const CYCLES: [&str; 11] = [
    "G81", "G82", "G83", "G73", "G85", "G89", "G86", "G88", "G87", "G84", "G74",
];

fn cycle() -> impl Strategy<Value = Item> {
    let word = |max: f64| proptest::option::weighted(0.8, value(max));
    (
        proptest::option::of(any::<bool>()),
        0..CYCLES.len(),
        [word(20.0), word(20.0), word(20.0)],
        proptest::option::weighted(0.9, value(20.0)),
        proptest::option::weighted(0.2, 1u8..=3),
        proptest::option::weighted(0.5, positive(0.0, 2.0)),
        proptest::option::weighted(0.5, positive(0.1, 5.0)),
        [value(3.0), value(3.0), value(10.0)],
    )
        .prop_map(|(retract, code, xyz, r, l, p, q, ijk)| Item::Cycle {
            retract,
            code,
            xyz,
            r,
            l,
            p,
            q,
            ijk,
        })
}

/// A bracketed expression over numbers, the binary operators and the unary functions.
fn expression() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        value(100.0).prop_map(num),
        positive(0.0, 2.0).prop_map(num),
        Just("#<_x>".to_string()),
    ];
    let tree = leaf.prop_recursive(3, 12, 2, |inner| {
        // No `**`: it makes numbers so large (1e15 degrees) that COS and SIN of them differ in
        // the argument reduction, the last bits of the degree conversion blown up.
        let ops = [
            "+", "-", "*", "/", "MOD", "EQ", "NE", "GT", "GE", "LT", "LE", "AND", "OR", "XOR",
        ];
        // No TAN: at its pole (TAN[90]) both sides return a huge number from the last bits
        // of the degree-to-radian conversion, and these differ.
        let funcs = [
            "ABS", "COS", "SIN", "SQRT", "FIX", "FUP", "ROUND", "EXP", "LN", "ACOS", "ASIN",
        ];
        // ROUND's argument is kept within ±10⁶: LinuxCNC rounds through a C `int`, undefined
        // beyond ±2³¹ (x86 gives −2147483648), where tezgah rounds the double.
        let call = |f: &str, a: String| match f {
            "ROUND" => format!("ROUND[[{a}] MOD 1000000]"),
            _ => format!("{f}[{a}]"),
        };
        prop_oneof![
            (inner.clone(), 0..ops.len(), inner.clone())
                .prop_map(move |(a, o, b)| format!("{a} {} {b}", ops[o])),
            (0..funcs.len(), inner.clone()).prop_map(move |(f, a)| call(funcs[f], a)),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("ATAN[{a}]/[{b}]")),
            inner.prop_map(|a| format!("[{a}]")),
        ]
    });
    tree.prop_map(|t| format!("[{t}]"))
}

fn maybe_axes() -> impl Strategy<Value = Axes> {
    prop_oneof![Just([None; 6]), axes()]
}

fn start() -> impl Strategy<Value = [f64; 3]> {
    (value(40.0), value(40.0), value(40.0)).prop_map(|(x, y, z)| [x, y, z])
}

fn feed() -> impl Strategy<Value = f64> {
    positive(0.5, 3000.0)
}

fn turns() -> impl Strategy<Value = Option<u32>> {
    proptest::option::weighted(0.2, 1u32..=3)
}

fn deco() -> impl Strategy<Value = Deco> {
    (
        proptest::option::weighted(0.2, 0u32..100_000),
        proptest::option::weighted(0.1, 0..COMMENTS.len()),
        proptest::option::weighted(0.1, 0..EXTRAS.len()),
    )
        .prop_map(|(n, comment, extra)| Deco { n, comment, extra })
}

fn item() -> impl Strategy<Value = Item> {
    let line = (any::<bool>(), axes(), feed(), proptest::bool::weighted(0.2)).prop_map(
        |(rapid, axes, f, with_f)| Item::Line {
            rapid,
            axes,
            f,
            with_f,
        },
    );
    let arc_r = (
        any::<bool>(),
        start(),
        (value(20.0), value(20.0)),
        prop_oneof![1 => Just(1.0), 4 => (10_000u32..=40_000).prop_map(|k| k as f64 / 1e4)],
        any::<bool>(),
        proptest::option::weighted(0.3, value(10.0)),
        turns(),
        feed(),
    )
        .prop_map(
            |(cw, start, d, factor, negative, normal, turns, f)| Item::ArcR {
                cw,
                start,
                d,
                factor,
                negative,
                normal,
                turns,
                f,
            },
        );
    let angle = || (0u32..3600).prop_map(|d| (d as f64 / 10.0).to_radians());
    let arc_ijk = (
        any::<bool>(),
        start(),
        positive(0.05, 20.0),
        angle(),
        proptest::option::weighted(0.9, angle()),
        proptest::option::weighted(0.3, value(10.0)),
        turns(),
        proptest::option::weighted(0.1, value(90.0)),
        feed(),
        proptest::option::weighted(0.03, positive(0.5, 2.0)),
    )
        .prop_map(
            |(cw, start, radius, center_angle, end_angle, normal, turns, a, f, perturb)| {
                Item::ArcIjk {
                    cw,
                    start,
                    radius,
                    center_angle,
                    end_angle,
                    normal,
                    turns,
                    a,
                    f,
                    perturb,
                }
            },
        );
    let tool_length = prop_oneof![
        (0u8..=3).prop_map(ToolLength::Table),
        (value(5.0), value(2.0), 0u8..3).prop_map(|(z, x, which)| ToolLength::Dynamic {
            z: (which != 1).then_some(z),
            x: (which != 0).then_some(x),
        }),
        Just(ToolLength::Cancel),
    ];
    let valid = prop_oneof![
        12 => line,
        5 => arc_r,
        6 => arc_ijk,
        3 => any::<bool>().prop_map(|incremental| Item::Distance { incremental }),
        2 => any::<bool>().prop_map(|inches| Item::Units { inches }),
        3 => (0u8..3).prop_map(Item::Plane),
        2 => any::<bool>().prop_map(|inverse| Item::FeedMode { inverse }),
        2 => feed().prop_map(Item::Feed),
        1 => positive(0.0, 2.0).prop_map(Item::Dwell),
        1 => (
            0u8..3,
            proptest::option::of(positive(0.0, 1.0)),
            proptest::option::of(positive(0.0, 1.0))
        )
            .prop_map(|(mode, p, q)| Item::PathControl { mode, p, q }),
        2 => (0..COORD_SYSTEMS.len()).prop_map(Item::CoordSystem),
        2 => (
            any::<bool>(),
            0u8..=9,
            axes(),
            proptest::option::weighted(0.3, value(90.0))
        )
            .prop_map(|(l20, p, axes, r)| Item::G10 { l20, p, axes, r }),
        1 => (
            prop_oneof![Just(1u8), Just(10), Just(11)],
            1u8..=3,
            [
                proptest::option::weighted(0.5, value(3.0)),
                proptest::option::weighted(0.5, value(3.0)),
                proptest::option::weighted(0.5, value(3.0))
            ],
            proptest::option::weighted(0.3, positive(0.0, 0.5))
        )
            .prop_map(|(l, tool, xyz, r)| Item::ToolWrite { l, tool, xyz, r }),
        1 => axes().prop_map(|axes| Item::G92 { axes }),
        1 => (1u8..=3).prop_map(Item::G92x),
        1 => axes().prop_map(|axes| Item::G52 { axes }),
        1 => (any::<bool>(), maybe_axes()).prop_map(|(g30, axes)| Item::Home { g30, axes }),
        1 => any::<bool>().prop_map(|g30| Item::SetHome { g30 }),
        1 => (any::<bool>(), axes(), feed()).prop_map(|(rapid, axes, f)| Item::Machine {
            rapid,
            axes,
            f
        }),
        1 => positive(0.0, 10_000.0).prop_map(Item::Speed),
        1 => prop_oneof![Just(3u8), Just(4), Just(5)].prop_map(Item::Spindle),
        1 => prop_oneof![Just(7u8), Just(8), Just(9)].prop_map(Item::Coolant),
        1 => (1u8..=3, 0u8..3).prop_map(|(t, change)| Item::Tool { t, change }),
        2 => tool_length.prop_map(Item::ToolLength),
        2 => cycle(),
        1 => (1u8..=4, any::<bool>(), [value(3.0), value(3.0), value(3.0)], feed()).prop_map(
            |(count, rapid, step, f)| Item::Repeat {
                count,
                rapid,
                step,
                f
            }
        ),
        2 => expression().prop_map(Item::Expression),
        2 => (0..SUBROUTINES.len(), [value(20.0), value(20.0)])
            .prop_map(|(sub, args)| Item::Call { sub, args }),
        1 => (0..COMMENTS.len()).prop_map(Item::Comment),
        3 => comp_contour().prop_map(Item::Comp),
        3 => spline(),
        2 => nurbs(),
        2 => (
            any::<bool>(),
            proptest::option::weighted(0.7, value(20.0)),
            proptest::option::weighted(0.7, value(360.0)),
            proptest::option::weighted(0.3, value(5.0)),
            feed(),
        )
            .prop_map(|(rapid, radius, theta, z, f)| Item::Polar {
                rapid,
                radius,
                // At least one polar word.
                theta: if radius.is_none() { theta.or(Some(45.0)) } else { theta },
                z,
                f,
            }),
        2 => (0u8..4).prop_map(Item::Modes),
    ];
    // About one program in twelve ends early on an error.
    prop_oneof![
        250 => valid,
        1 => (0..FAULTY.len()).prop_map(Item::Faulty),
    ]
}

fn comp_contour() -> impl Strategy<Value = CompContour> {
    let vertex = (
        20.0f64..=120.0,
        prop_oneof![3 => Just(1.0), 2 => 0.7f64..=1.3],
        prop_oneof![3 => Just(0u8), 1 => Just(1u8), 1 => Just(2u8)],
    );
    (
        (any::<bool>(), any::<bool>()),
        proptest::option::weighted(0.4, positive(0.1, 4.0)),
        1u8..=3,
        (value(20.0), value(20.0)),
        positive(8.0, 30.0),
        proptest::collection::vec(vertex, 2..=7),
        prop_oneof![Just(1.0), 1.05f64..=3.0],
        feed(),
    )
        .prop_map(
            |((left, xz), dynamic, tool, (cx, cy), radius, vertices, bulge, f)| CompContour {
                left,
                xz,
                dynamic,
                tool,
                center: [cx, cy],
                radius,
                vertices: vertices
                    .into_iter()
                    .map(|(s, k, j)| ((s * 10.0).round() / 10.0, (k * 100.0).round() / 100.0, j))
                    .collect(),
                bulge,
                f,
            },
        )
}

/// G5 or G5.1 with words drawn so that most blocks are valid.
fn spline() -> impl Strategy<Value = Item> {
    let pair = || (value(20.0), value(20.0));
    (
        any::<bool>(),
        proptest::option::weighted(0.7, pair()),
        pair(),
        (
            proptest::option::weighted(0.9, value(40.0)),
            proptest::option::weighted(0.9, value(40.0)),
        ),
        proptest::option::weighted(0.01, value(10.0)),
        feed(),
    )
        .prop_map(|(quadratic, ij, pq, mut end, z, f)| {
            if end.0.is_none() && end.1.is_none() {
                end.0 = Some(1.0);
            }
            // G5.1 needs both I and J; leave them out only rarely there.
            let ij = if quadratic {
                ij.or(Some((1.0, 0.5)))
            } else {
                ij
            };
            Item::Spline {
                quadratic,
                ij,
                pq,
                end,
                z,
                f,
            }
        })
}

/// A G5.2 … G5.3 series of 1 to 7 points.
fn nurbs() -> impl Strategy<Value = Item> {
    let point = || {
        (
            value(40.0),
            value(40.0),
            prop_oneof![80 => positive(0.1, 5.0), 1 => Just(0.0)],
        )
    };
    // Mostly enough points for the order (the start point counts as one).
    let count = prop_oneof![1 => 1usize..=2, 8 => 3usize..=7];
    (
        count.prop_flat_map(move |n| proptest::collection::vec(point(), n)),
        proptest::option::weighted(0.5, 2u8..=5),
        feed(),
    )
        .prop_map(|(mut points, order, f)| {
            // The first line's weight must be positive for tezgah (rs274 takes any).
            if points[0].2 == 0.0 {
                points[0].2 = 1.0;
            }
            Item::Nurbs { points, order, f }
        })
}

fn program() -> impl Strategy<Value = Vec<(Item, Deco)>> {
    proptest::collection::vec((item(), deco()), 5..=40)
}

// ---------------------------------------------------------------------------------------------
// Running both interpreters

/// What one interpreter made of a program.
#[derive(Debug)]
struct Outcome {
    /// Every call, one per line, in `rs274`'s format.
    calls: Vec<String>,
    /// The error message, if the program was rejected.
    error: Option<String>,
}

impl Outcome {
    fn motion(&self) -> Vec<&str> {
        self.calls
            .iter()
            .map(String::as_str)
            .filter(|c| MOTION_CALLS.contains(&call_name(c)))
            .collect()
    }

    fn report(&self) -> String {
        let mut s = self.calls.join("\n");
        s.push_str(&format!("\n=> {}", self.error.as_deref().unwrap_or("ok")));
        s
    }
}

fn call_name(call: &str) -> &str {
    call.split('(').next().unwrap_or(call).trim()
}

fn run_rs274(rs274: &Path, dir: &Path, table: &Path, program: &Path) -> Outcome {
    let mut trouble = String::new();
    // A crash (or a kill from outside) is not a rejection: try again, then give up loudly.
    for _ in 0..3 {
        let out = Command::new(rs274)
            .arg("-t")
            .arg(table)
            .arg("-g")
            .arg(program)
            .current_dir(dir)
            .stdin(Stdio::null())
            .output()
            .unwrap_or_else(|e| panic!("cannot run {}: {e}", rs274.display()));
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let calls = stdout
            .lines()
            .filter_map(|l| {
                // "   12 N..... CALL(...)": drop the call number and the N field.
                let mut fields = l.trim_start().splitn(3, char::is_whitespace);
                let _number = fields.next()?;
                let _n = fields.next()?;
                Some(fields.next()?.trim().to_string())
            })
            .collect();
        if out.status.success() {
            return Outcome { calls, error: None };
        }
        // "executing", the message, then the offending line.
        let lines: Vec<&str> = stderr.lines().filter(|l| *l != "executing").collect();
        if out.status.code() == Some(1) && lines.len() >= 2 {
            let error = Some(lines[lines.len() - 2].to_string());
            return Outcome { calls, error };
        }
        trouble = format!("{}; stderr: {stderr:?}", out.status);
    }
    panic!(
        "{} failed on {}: {trouble}",
        rs274.display(),
        program.display()
    );
}

fn run_ours(program: &str) -> Outcome {
    let table = ToolTable::parse(TOOL_TABLE).expect("tool table");
    let mut interp = Interpreter::new(Config::linuxcnc(table));
    let mut calls: Vec<(Origin, Canon)> = Vec::new();
    let result = interp.run(program, &mut calls);
    Outcome {
        calls: calls.iter().map(|(_, c)| c.to_string()).collect(),
        error: result.err().map(|e| e.kind.to_string()),
    }
}

/// The numbers of a call, or the token itself where it is not a number.
fn tokens(call: &str) -> Vec<Result<f64, &str>> {
    let args = call
        .split_once('(')
        .map_or("", |(_, rest)| rest.trim_end().trim_end_matches(')'));
    args.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().map_err(|_| t))
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= ABS_TOL + REL_TOL * a.abs().max(b.abs())
}

/// Why two motion calls differ, if they do.
fn compare_call(theirs: &str, ours: &str) -> Option<String> {
    if call_name(theirs) != call_name(ours) {
        return Some("different calls".into());
    }
    let (t, o) = (tokens(theirs), tokens(ours));
    if t.len() != o.len() {
        return Some("different argument counts".into());
    }
    for (k, (a, b)) in t.iter().zip(&o).enumerate() {
        let same = match (a, b) {
            (Ok(a), Ok(b)) => close(*a, *b),
            (Err(a), Err(b)) => a == b,
            _ => false,
        };
        if !same {
            return Some(format!("argument {} differs", k + 1));
        }
    }
    None
}

/// Why the outcomes differ, if they do.
fn compare(theirs: &Outcome, ours: &Outcome) -> Option<String> {
    match (&theirs.error, &ours.error) {
        (None, Some(e)) => return Some(format!("only tezgah rejects: {e}")),
        (Some(e), None) => return Some(format!("only rs274 rejects: {e}")),
        (Some(a), Some(b)) if a != b => {
            return Some(format!("different errors:\n  rs274:  {a}\n  tezgah: {b}"))
        }
        _ => {}
    }
    let (t, o) = (theirs.motion(), ours.motion());
    for (k, (a, b)) in t.iter().zip(&o).enumerate() {
        if let Some(why) = compare_call(a, b) {
            return Some(format!(
                "motion call {} ({why}):\n  rs274:  {a}\n  tezgah: {b}",
                k + 1
            ));
        }
    }
    if t.len() != o.len() {
        return Some(format!(
            "{} motion calls from rs274, {} from tezgah",
            t.len(),
            o.len()
        ));
    }
    None
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    match std::env::var(name) {
        Ok(v) => v
            .parse()
            .unwrap_or_else(|_| panic!("{name}={v} is not a valid value")),
        Err(_) => default,
    }
}

#[test]
#[ignore = "needs LinuxCNC's rs274: set TEZGAH_RS274 (see .ci/install-rs274)"]
fn agrees_with_rs274() {
    let rs274 = support::rs274();
    let dir = std::env::temp_dir().join(format!("tezgah-oracle-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let table = dir.join("tool.tbl");
    std::fs::write(&table, TOOL_TABLE).expect("write tool table");

    let cases = env_or("TEZGAH_ORACLE_CASES", DEFAULT_CASES);
    let seed = env_or("TEZGAH_ORACLE_SEED", DEFAULT_SEED);
    let config = ProptestConfig {
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        max_shrink_iters: 4096,
        ..ProptestConfig::with_cases(cases)
    };
    let mut runner = TestRunner::new(config);
    let counter = AtomicUsize::new(0);
    let rejected = AtomicUsize::new(0);
    let motions = AtomicUsize::new(0);
    let nurbs = AtomicUsize::new(0);
    let result = runner.run(&program(), |items| {
        let text = render(&items);
        let k = counter.fetch_add(1, Ordering::Relaxed);
        let path = dir.join(format!("case-{k}.ngc"));
        std::fs::write(&path, &text).expect("write program");
        let theirs = run_rs274(&rs274, &dir, &table, &path);
        let _ = std::fs::remove_file(&path);
        let ours = run_ours(&text);
        if theirs.error.is_some() {
            rejected.fetch_add(1, Ordering::Relaxed);
        }
        motions.fetch_add(theirs.motion().len(), Ordering::Relaxed);
        let splines = theirs
            .motion()
            .into_iter()
            .filter(|c| call_name(c) == "NURBS_FEED");
        nurbs.fetch_add(splines.count(), Ordering::Relaxed);
        match compare(&theirs, &ours) {
            None => Ok(()),
            Some(why) => Err(TestCaseError::fail(format!(
                "{why}\n--- program ---\n{text}--- rs274 ---\n{}\n--- tezgah ---\n{}",
                theirs.report(),
                ours.report()
            ))),
        }
    });
    let _ = std::fs::remove_dir_all(&dir);
    match result {
        Ok(()) => eprintln!(
            "rs274 and tezgah agree on {} random programs (seed {seed:#x}): {} motion calls \
             compared ({} NURBS_FEED), {} programs rejected by both",
            counter.load(Ordering::Relaxed),
            motions.load(Ordering::Relaxed),
            nurbs.load(Ordering::Relaxed),
            rejected.load(Ordering::Relaxed)
        ),
        Err(TestError::Fail(why, _)) => panic!("tezgah disagrees with rs274: {why}"),
        Err(TestError::Abort(why)) => panic!("aborted: {why}"),
    }
}
