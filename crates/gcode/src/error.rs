//! Errors of the lexer, parser and interpreter, worded as LinuxCNC words them.
//!
//! The text of each kind is LinuxCNC's message where LinuxCNC has one, so that a programmer who
//! knows LinuxCNC recognises it and the `bad/` tests of LinuxCNC's suite can be compared word
//! for word. The [`Span`] says where in the program the error was found.

use crate::span::Span;

/// An error with the place in the program where it was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{kind}")]
pub struct GcodeError {
    pub kind: ErrorKind,
    pub span: Span,
    /// The subroutine file the error is in, when it is not in the program itself.
    pub file: Option<String>,
}

impl GcodeError {
    pub fn new(kind: ErrorKind, span: Span) -> Self {
        GcodeError {
            kind,
            span,
            file: None,
        }
    }
}

/// Details of a centre-format arc whose end is not on the circle through its start.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcMismatch {
    /// Letters of the two in-plane axes, e.g. ('X', 'Y').
    pub letters: (char, char),
    pub start: [f64; 2],
    pub center: [f64; 2],
    pub end: [f64; 2],
    pub r1: f64,
    pub r2: f64,
    pub abs_err: f64,
    pub rel_err: f64,
}

impl std::fmt::Display for ArcMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (a, b) = self.letters;
        write!(
            f,
            "start=({a}{:.4},{b}{:.4}) center=({a}{:.4},{b}{:.4}) end=({a}{:.4},{b}{:.4}) r1={:.4} r2={:.4}",
            self.start[0],
            self.start[1],
            self.center[0],
            self.center[1],
            self.end[0],
            self.end[1],
            self.r1,
            self.r2
        )
    }
}

/// C's `%.4g`: four significant digits, trailing zeros removed, exponent form outside 1e-5..1e4.
pub fn format_g4(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let exp = v.abs().log10().floor() as i32;
    if !(-5..4).contains(&exp) {
        let s = format!("{v:.3e}");
        // Rust prints `2.857e-6`; C prints `2.857e-06`.
        let (mantissa, e) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = trim_zeros(mantissa);
        let e: i32 = e.parse().unwrap_or(0);
        let sign = if e < 0 { '-' } else { '+' };
        return format!("{mantissa}e{sign}{:02}", e.abs());
    }
    let decimals = (3 - exp).max(0) as usize;
    trim_zeros(&format!("{v:.decimals$}")).to_string()
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// What went wrong. The display text is LinuxCNC's wording.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ErrorKind {
    // --- lexical ---
    #[error("Unclosed comment found")]
    UnclosedComment,
    #[error("Nested comment found")]
    NestedComment,
    #[error("Bad character '{0}' used")]
    BadCharacter(char),
    #[error("bad number format (conversion failed) parsing '{0}'")]
    BadNumberFormat(String),
    #[error("No characters found in reading real value")]
    NoCharactersInRealValue,
    #[error("Non integer value for integer")]
    NonIntegerValue,
    #[error("Multiple {0} words on one line")]
    MultipleWords(char),
    #[error("Unknown word starting with {0}")]
    UnknownWord(char),
    #[error("E word with no G70, G76, M66, M67 or M68 to use it")]
    EWordUnused,
    #[error("Bad format unsigned integer")]
    BadLineNumber,
    #[error("File ended with no percent sign")]
    NoClosingPercent,
    #[error("File ended with no percent sign or program end")]
    NoProgramEnd,
    #[error("bad number format (trailing characters) parsing '{0}'")]
    TrailingCharacters(String),

    // --- words ---
    #[error("G-code out of range")]
    GCodeOutOfRange,
    #[error("Negative g code used")]
    NegativeGCode,
    #[error("Unknown g code used")]
    UnknownGCode,
    #[error("Two g codes used from same modal group")]
    TwoGCodesSameGroup,
    #[error("Negative m code used")]
    NegativeMCode,
    #[error("Unknown m code used: M{0}")]
    UnknownMCode(i64),
    #[error("M-code greater than 199: M{0}")]
    MCodeTooBig(i64),
    #[error("Two m codes used from same modal group")]
    TwoMCodesSameGroup,
    #[error("Too many m codes on line")]
    TooManyMCodes,
    #[error("Negative f word used")]
    NegativeFeed,
    #[error("Negative spindle speed used")]
    NegativeSpindleSpeed,
    #[error("Negative tool id (tool not found)")]
    NegativeTool,
    #[error("Negative l word used")]
    NegativeL,

    // --- expressions and parameters ---
    #[error("Unclosed expression")]
    UnclosedExpression,
    #[error("Unknown operation")]
    UnknownOperation,
    #[error("Unknown operation name starting with {0}")]
    UnknownOperationName(char),
    #[error("Attempt to divide by zero")]
    DivisionByZero,
    #[error("Negative argument to sqrt")]
    SqrtOfNegative,
    #[error("Zero or negative argument to ln")]
    LogOfNonPositive,
    #[error("Argument to acos out of range")]
    AcosOutOfRange,
    #[error("Argument to asin out of range")]
    AsinOutOfRange,
    #[error("Attempt to raise negative to non integer power")]
    NegativePower,
    #[error("Left bracket missing after slash with atan")]
    AtanMissingBracket,
    #[error("Slash missing after first atan argument")]
    AtanMissingSlash,
    #[error("Left bracket missing after unary operation name")]
    UnaryMissingBracket,
    #[error("Parameter number out of range")]
    ParameterOutOfRange,
    #[error("Equal sign missing in parameter setting")]
    EqualSignMissing,
    #[error("Named parameter not terminated")]
    NamedParameterNotTerminated,
    #[error("Expected # reading parameter")]
    ExpectedHash,
    #[error("Expected ] reading bracketed parameter")]
    ExpectedCloseBracket,
    #[error("Named parameter #<{0}> not defined")]
    NamedParameterNotDefined(String),

    // --- block rules ---
    #[error("All axes missing with motion code")]
    AllAxesMissingWithMotion,
    #[error("All axes missing with g52 or g92")]
    AllAxesMissingWithG92,
    #[error("Cannot use axis values with g80")]
    AxisValuesWithG80,
    #[error("Cannot use two g codes that both use axis values")]
    TwoGCodesUseAxes,
    #[error("Cannot use axis values without a g code that uses them")]
    AxisValuesWithoutGCode,
    #[error("Cannot put an a in canned cycle")]
    AInCannedCycle,
    #[error("Cannot put a b in canned cycle")]
    BInCannedCycle,
    #[error("Cannot put a c in canned cycle")]
    CInCannedCycle,
    #[error("D word with no G41, G41.1, G42, G42.1, G71, G71.1, G71.2 or G96 to use it")]
    DWordUnused,
    #[error("H word with no G43 or G76 to use it")]
    HWordUnused,
    #[error("I word with no G2, G3, G5, G5.1, G10, G33.1, G76, or G87 to use it")]
    IWordUnused,
    #[error("J word with no G2, G3, G5, G5.1, G10, G76 or G87 to use it")]
    JWordUnused,
    #[error("K word with no G2, G3, G33, G33.1, G76, or G87 to use it")]
    KWordUnused,
    #[error("L word with no G10, cutter compensation, canned cycle, digital/analog input, M98 or NURBS code")]
    LWordUnused,
    #[error("P word with no G2 G3 G4 G10 G64 G5 G5.2 G76 G82 G86 G88 G89 or M50 M51 M52 M53 M62 M63 M64 M65 M66 M98 or user M code to use it")]
    PWordUnused,
    #[error("Q word with no G5, G10, G64, G73, G76, G83, M19, M66, M67, M68 or user M code that uses it")]
    QWordUnused,
    #[error("R word with no g code that uses it")]
    RWordUnused,
    #[error("Dwell time missing with g4")]
    DwellTimeMissing,
    #[error("Must use g0 or g1 with g53")]
    G53NeedsG0OrG1,
    #[error("Cannot use g53 incremental")]
    G53Incremental,

    #[error("Calculation resulted in 'not a number'")]
    NotANumber,
    #[error("Calculation resulted in 'infinity'")]
    Infinity,

    // --- canned cycles ---
    #[error("Cannot feed with zero feed rate")]
    CycleZeroFeed,
    #[error("Cannot use inverse time feed with canned cycles")]
    CycleInverseTime,
    #[error("R clearance plane unspecified in cycle")]
    CycleRMissing,
    #[error("Cannot do zero repeats of cycle")]
    CycleZeroRepeats,
    #[error("{0} value unspecified in {1} plane canned cycle")]
    CycleNormalMissing(char, &'static str),
    #[error("R less than {0} in cycle in {1} plane")]
    CycleRBelowBottom(char, &'static str),
    #[error("Dwell time p word missing with g{0}")]
    CycleDwellMissing(u32),
    #[error("Q word missing with g{0}")]
    CycleQMissing(u32),
    #[error("Negative or zero q value used")]
    CycleQNotPositive,
    #[error("{0} word missing with g87")]
    CycleG87WordMissing(char),
    #[error("Spindle not turning in G{0}")]
    CycleSpindleStopped(u32),
    #[error("Spindle turning {which} in G{0}", which = if *.1 { "counterclockwise" } else { "clockwise" })]
    CycleSpindleWrongWay(u32, bool),
    #[error("Spindle not turning in g{0}")]
    CycleSpindleNeeded(u32),

    // --- O-words ---
    #[error("Unknown control word after O-word: {0}")]
    UnknownOKeyword(String),
    #[error("O-word label missing")]
    OLabelMissing,
    #[error("Words other than comments on an O-word line")]
    WordsAfterOWord,
    #[error("Nested subroutine definition")]
    NestedSubroutine,
    #[error("line:{0} sub: o|{1}| found in illegal location")]
    SubInIllegalLocation(u32, String),
    #[error("line:{0} redefining sub: o|{1}| already defined")]
    SubRedefined(u32, String),
    #[error("L{0} repeats of the cycle are more than {1}")]
    TooManyRepeats(u32, u64),
    #[error("G{0} with Q{1} would make more than {2} pecks")]
    TooManyPecks(u32, f64, u64),
    #[error("Failed to find sub 'O{0}' before EOF")]
    SkippedPastPercent(String),
    #[error("Unable to find subroutine o{0}")]
    SubroutineNotFound(String),
    #[error("{0} o{1} without a matching start")]
    UnmatchedOWord(&'static str, String),
    #[error("End of file while looking for o{0} {1}")]
    OWordTargetMissing(String, &'static str),
    #[error("Loop o{0} ran more than {1} times")]
    RunawayLoop(String, u64),
    #[error("Subroutine calls nested deeper than {0}")]
    CallsTooDeep(usize),
    #[error("G05.1 needs Q1 (smoothing on) or Q0 (off)")]
    SmoothingQ,
    #[error("Found 'm98' code with no P-word")]
    M98WithoutP,
    #[error("DISABLE_FANUC_STYLE_SUB set in INI file, but found m{0}")]
    FanucSubsDisabled(u32),
    #[error("DISABLE_FANUC_STYLE_SUB disabled in INI file, but found bare O-word")]
    FanucProgramDisabled,
    #[error("Fanuc 'O....' subroutine must be called with 'M98'")]
    FanucSubNeedsM98,
    #[error("'O.... sub' subroutine must be called with 'O.... call'")]
    NgcSubNeedsCall,
    #[error("Fanuc 'O....' subroutine definition must end with 'M99'")]
    FanucSubNeedsM99,
    #[error("'O.... endsub' or 'O.... return' must follow 'O.... sub' subroutine definition")]
    NgcSubEndedByM99,
    #[error("M99 outside a subprogram (an endlessly repeated main program) is not supported")]
    M99InMain,
    #[error("{0} needs a [value]")]
    OWordNeedsValue(&'static str),

    // --- G10 and offsets ---
    #[error("Line with G10 does not have L0, L1, L10, L11, L2, or L20")]
    G10MissingL,
    #[error("P value out of range with G10 L{0}")]
    G10PToolOutOfRange(i64),
    #[error("G10 L1 without offsets has no effect")]
    G10L1NoOffsets,
    #[error("G10 L0 not allowed with loaded tool <{0}>")]
    G10L0ToolLoaded(i64),
    #[error("Q number in G10 is not an integer")]
    G10QNotInteger,
    #[error("Invalid tool orientation")]
    InvalidToolOrientation,
    #[error("P value not an integer with G10")]
    G10PNotInteger,
    #[error("P value out of range (0-9) with G10 L{0}")]
    G10POutOfRange(i64),
    #[error("R not allowed in G10 L20")]
    G10L20Rotation,
    #[error("Cannot assign to read-only parameter #<{0}>")]
    ReadOnlyParameter(String),
    /// `(ABORT,…)`: the program stops with the comment's text, parameters filled in.
    #[error("{0}")]
    Abort(String),
    #[error(transparent)]
    CutterComp(#[from] crate::interp::CompError),
    #[error("Requested tool {0} not found in the tool table")]
    ToolNotFound(i64),
    #[error("H word missing with G43.4")]
    CentrePointMissingH,

    // --- motion ---
    #[error("Cannot do g1 with zero feed rate")]
    G1ZeroFeed,
    #[error("Cannot make arc with zero feed rate")]
    ArcZeroFeed,
    #[error("F word missing with inverse time g1 move")]
    InverseTimeG1MissingF,
    #[error("F word missing with inverse time arc move")]
    InverseTimeArcMissingF,
    #[error("R i j k words all missing for arc")]
    ArcMissingRIJK,
    #[error("Mixed radius ijk format for arc")]
    ArcMixedFormat,
    #[error("{0} word given for arc in {1} plane")]
    ArcWrongOffsetWord(char, &'static str),
    #[error("{0} and {1} words missing for arc in {2} plane")]
    ArcMissingEndWords(char, char, &'static str),
    #[error("Radius to end of arc differs from radius to start: {0} abs_err={abs} rel_err={rel:.4}%", abs = format_g4(.0.abs_err), rel = .0.rel_err * 100.0)]
    ArcRadiusMismatch(Box<ArcMismatch>),
    #[error("Zero-radius arc: {0}")]
    ZeroRadiusArc(Box<ArcMismatch>),
    #[error("Arc radius too small to reach end point")]
    ArcRadiusTooSmall,
    #[error("Current point same as end point of arc")]
    ArcEndIsStart,
    #[error("P value should be 1 or greater with G2 or G3")]
    ArcTurnsBelowOne,
    #[error("P value not an integer with M19 G2 or G3")]
    ArcTurnsNotInteger,
    #[error("{0} word missing in absolute center arc")]
    ArcAbsoluteCenterMissing(char),
    #[error("Cannot feed with zero spindle speed in feed per rev mode")]
    ZeroSpindleFeedPerRev,
    #[error("Need non-negative Q-word to specify tool number with M61")]
    M61NeedsQ,
    #[error("{0} is not supported yet")]
    Unsupported(String),
    // --- probing (G38.2–G38.5) ---
    #[error("Cannot probe with cutter radius comp on")]
    ProbeWithComp,
    #[error("Cannot probe with zero feed rate")]
    ProbeZeroFeed,
    #[error("Cannot probe with feed per rev mode")]
    ProbeFeedPerRev,
    #[error("Start point too close to probe point")]
    ProbeStartAtTarget,
    /// tezgah's own: no probe to answer (`Config::probe`).
    #[error(
        "G{0} probing needs a probe: a machine file's [probe] (`tezgah run`, `serve`, MDI) or \
         `tezgah run --probe`; `check` does not probe"
    )]
    ProbeUnavailable(String),
    /// tezgah's own: a pass driven by the executor reached a probe move it has no answer for
    /// yet (`ProbeModel::Answered`); the executor runs the moves so far and answers.
    #[error("G{0} probe move awaits the machine's answer")]
    ProbeAwaitsAnswer(String),
    /// LinuxCNC's motion controller, when G38.2 or G38.4 reaches its end.
    #[error("G38.2 move finished without making contact.")]
    ProbeNoContact,
    #[error("G38.4 move finished without breaking contact.")]
    ProbeStillInContact,
    #[error("Probe is already tripped when starting G38.2 or G38.3 move")]
    ProbeAlreadyTripped,
    #[error("Probe is already clear when starting G38.4 or G38.5 move")]
    ProbeAlreadyClear,
    // --- spindle-synchronised motion (G33, G33.1) ---
    #[error("K word missing with g33/g33.1")]
    SyncMissingK,
    #[error("F word used with a g33/g33.1")]
    SyncWithF,
    /// `Spindle not turning in G33` / `… G33.1`.
    #[error("Spindle not turning in {0}")]
    SyncSpindleStopped(&'static str),
    /// tezgah's own: LinuxCNC sends the compensated moves without synchronisation.
    #[error("G33/G33.1 with cutter radius compensation is not supported")]
    SyncWithComp,
    // --- polar coordinates (`@` radius, `^` angle) ---
    #[error("Cannot use polar coordinate except in G17 plane")]
    PolarNotXyPlane,
    #[error("Cannot specify both polar coordinate and {0} word")]
    PolarWithAxisWord(char),
    #[error("Polar coordinates can only be used for motion")]
    PolarWithoutMotion,
    #[error("Cannot use polar coordinates with G53")]
    PolarWithG53,
    #[error("Must specify angle in polar coordinate if at the origin")]
    PolarAngleAtOrigin,
    #[error("Incremental motion with polar coordinates is indeterminate when at the origin")]
    PolarIncrementalAtOrigin,
    #[error("G91 motion with polar coordinates is indeterminate when at the origin")]
    PolarG91AtOrigin,
    #[error("Cannot restore context from invalid stack frame - missing M70/M73?")]
    RestoreWithoutContext,
    /// LinuxCNC prints the (still empty) command text here.
    #[error("M7x: restore_settings G20/G21 failed: ''")]
    RestoreUnitsFailed,
    #[error("M7x: restore_settings failed executing: '{0}': {1}")]
    RestoreFailed(String, String),

    // --- splines: LinuxCNC's G5, G5.1, G5.2/G5.3 (its wording) ---
    #[error("Splines must be in the XY plane")]
    SplineNotXyPlane,
    #[error("Splines may not have motion in Z, A, B, or C")]
    SplineOffPlaneMotion,
    #[error("Must specify both I and J with G5.1")]
    G51NeedsIJ,
    #[error("Must specify both I and J, or neither")]
    G5IJBothOrNeither,
    #[error("Must specify both P and Q with G5")]
    G5NeedsPQ,
    #[error("You must specify both X and Y coordinates for Control Points")]
    NurbsNeedsXY,
    #[error("Can specify P without X and Y only for the first control point")]
    NurbsBareWeight,
    #[error("Must specify positive weight P for every Control Point")]
    NurbsWeight,
    #[error("Cannot make a NURBS with 0 feedrate")]
    NurbsZeroFeed,
    #[error("Cannot use G5.3 without G5.2 first")]
    G53WithoutG52,
    #[error("You must specify a number of control points at least equal to the order L = {0}")]
    NurbsTooFewPoints(usize),
    /// tezgah's own: the curve layer evaluates NURBS up to a fixed degree.
    #[error("NURBS order L{0} is above the highest order tezgah evaluates ({1})")]
    NurbsOrderTooHigh(usize, usize),

    // --- Fanuc's G06.2 NURBS block (tezgah's own wording) ---
    #[error("G6.2 order P{0} must be 2, 3 or 4 (P4 = cubic, the default)")]
    G62Order(String),
    #[error("G6.2 control point without its knot: every control point line needs a K word")]
    G62KnotMissing,
    #[error("G6.2 weight R{0} must be positive")]
    G62Weight(String),
    #[error("G6.2 knots must not decrease: K{0} follows K{1}")]
    G62KnotDecreasing(String, String),
    #[error("G6.2 knots must be clamped: the {0} {1} knots must be equal (order P{2})")]
    G62NotClamped(&'static str, usize, usize),
    #[error("G6.2 order P{0} needs at least {0} control points; the NURBS has {1}")]
    G62TooFewPoints(usize, usize),
    #[error("G6.2 first control point must be the current point ({0})")]
    G62FirstPoint(String),
    #[error("G6.2 NURBS begun on line {0} is unfinished: it has {1} of its {2} closing knot lines (K alone); a NURBS of n control points and order P needs n + P knots")]
    G62Unfinished(u32, usize, usize),
    #[error("G6.2 control point after the closing knot lines (K alone) began")]
    G62PointAfterKnots,
    #[error("G6.2 line with no open NURBS: a NURBS ends with its P-th line of K alone (too many knots?); start another with G6.2")]
    G62StrayKnot,
    #[error("F word missing with inverse time G6.2 move")]
    G62InverseTimeMissingF,
    #[error("G6.2 order P may be given only on the G6.2 line")]
    G62OrderRepeated,
    #[error("NURBS is not a valid curve: {0}")]
    NurbsInvalid(String),
}
