//! LinuxCNC's own interpreter tests (`tests/interp` of LinuxCNC), run through tezgah.
//!
//! The test data is not in this repository (it is GPL-2 test data): it is read at test time
//! from `$TEZGAH_LINUXCNC_INTERP`, or from `../shared/data/linuxcnc-interp` beside the
//! repository. Motion calls (and the feed rate in force) must equal LinuxCNC's expected output
//! within 1e-4; every `bad/` program in scope must fail with LinuxCNC's exact error text.
//! The lists below say which tests run and why the others do not yet. The tests are ignored by
//! a plain `cargo test` (`--include-ignored` runs them, as `.ci/run` does) and fail when the
//! data is not found.

mod support;

use std::path::{Path, PathBuf};

use tezgah_gcode::{Canon, Config, IniFile, Interpreter, Origin, ToolTable};

/// A folder test: its program, tool table, and whether `expected` keeps rs274's counter field
/// (LinuxCNC's script for the folder does or does not strip it with awk).
struct Run {
    folder: &'static str,
    program: &'static str,
    table: Option<&'static str>,
    counter: bool,
    /// LinuxCNC's script keeps only the MESSAGE lines.
    messages_only: bool,
    /// The folder's SUBROUTINE_PATH (from its test.ini), relative to the folder.
    subroutines: Option<&'static str>,
    /// rs274 runs with `-n 0`: it goes on after an error (as tezgah's pre-flight does).
    go_on: bool,
    /// The program must fail (LinuxCNC's script expects rs274 to exit with an error).
    fails: bool,
    /// The INI file `rs274 -i` reads (its `#<_ini[…]…>` values).
    ini: Option<&'static str>,
    /// The script keeps rs274's standard error (`2>&1`): `executing` first, and on an error
    /// its text and the offending line before the final resets.
    stderr: bool,
    /// The expected file was made by an rs274 older than 2.9, whose tool change prints
    /// `CHANGE_TOOL()` without the pocket and no `START_CHANGE()`: ours is compared in that form.
    old_tool_change: bool,
    /// The script's `sed 's/-0\.0000/0.0000/g'`.
    no_negative_zero: bool,
}

const fn run(folder: &'static str, program: &'static str) -> Run {
    Run {
        folder,
        program,
        table: None,
        counter: false,
        messages_only: false,
        subroutines: None,
        go_on: false,
        fails: false,
        old_tool_change: false,
        no_negative_zero: false,
        ini: None,
        stderr: false,
    }
}

/// Folders whose `expected` output this interpreter reproduces call for call.
const RUNS: &[Run] = &[
    run("fractional-linenumbers", "test.ngc"),
    run("g6164", "test.ngc"),
    run("g33.1", "g33.1.ngc"),
    run("unit-conversion", "test.ngc"),
    run("namedparam-bug424", "test.ngc"),
    run("g10/g10-l2-while-active", "test.ngc"),
    run("g10/g10-l20-while-active", "test.ngc"),
    Run {
        table: Some("test.tbl"),
        ..run("g10/g10-with-g92", "test.ngc")
    },
    Run {
        counter: true,
        ..run("g52/g52-g92-interaction", "g52-g92-interaction.ngc")
    },
    Run {
        counter: true,
        ..run("rotation/g28", "g28.ngc")
    },
    Run {
        counter: true,
        ..run("rotation/g53", "g53.ngc")
    },
    run("do-while-break", "test.ngc"),
    run("exists", "test.ngc"),
    run("return-value", "test.ngc"),
    run("subs-follow-main", "test.ngc"),
    Run {
        table: Some("test.tbl"),
        messages_only: true,
        ..run("machine-coord-params", "test.ngc")
    },
    run("flowsnake", "flowsnake.ngc"),
    run("oword-bug315", "test.ngc"),
    run("oword-bug315-p2", "test.ngc"),
    Run {
        subroutines: Some("subs"),
        ..run("sub-call-from-sub", "test.ngc")
    },
    Run {
        subroutines: Some("."),
        go_on: true,
        ..run("oword-unwind", "test.ngc")
    },
    Run {
        subroutines: Some("subs"),
        counter: true,
        fails: true,
        ..run("nested-sub-error", "test.ngc")
    },
    Run {
        subroutines: Some("subs"),
        counter: true,
        fails: true,
        ..run("nested-sub-in-file-error", "test.ngc")
    },
    run("m98m99/01-basics", "test.ngc"),
    run("m98m99/02-variables", "test.ngc"),
    run("m98m99/05-M98-loops", "test.ngc"),
    run("m98m99/07-nested-subs", "test.ngc"),
    run("m98m99/08-sub-follows-main", "test.ngc"),
    run("m98m99/10-M98-P001", "test.ngc"),
    // Its script expects rs274 to fail: the M98 looks for O1 up to the closing `%`.
    Run {
        counter: true,
        fails: true,
        ..run("m98m99/04-M98-but-no-sub", "test.ngc")
    },
    Run {
        counter: true,
        ..run("m98m99/14-o-expression-call", "test.ngc")
    },
    Run {
        table: Some("test.tbl"),
        messages_only: true,
        ..run("rotation/abs-pts", "test.ngc")
    },
    run("g81/g17/g98", "g17-g98-g81.ngc"),
    run("g81/g17/g99", "g17-g99-g81.ngc"),
    run("g81/g18/g98", "g18-g98-g81.ngc"),
    run("g81/g18/g99", "g18-g99-g81.ngc"),
    run("g81/g19/g98", "g19-g98-g81.ngc"),
    run("g81/g19/g99", "g19-g99-g81.ngc"),
    run("g84/g17/g98", "g17-g98-g84.ngc"),
    run("g84/g17/g99", "g17-g99-g84.ngc"),
    run("inverse-time-with-comp", "inverse.ngc"),
    Run {
        counter: true,
        fails: true,
        stderr: true,
        ..run("m98m99/03-error-M98-no-P-word", "test.ngc")
    },
    run("magic_comments/param_format_printing", "test.ngc"),
    Run {
        ini: Some("test.ini"),
        counter: true,
        fails: true,
        stderr: true,
        ..run("iniparam", "test.ngc")
    },
    Run {
        ini: Some("test.ini"),
        counter: true,
        fails: true,
        stderr: true,
        ..run("iniparam-failassign", "test.ngc")
    },
    Run {
        ini: Some("test.ini"),
        counter: true,
        fails: true,
        stderr: true,
        ..run("abort-hot-comment", "test.ngc")
    },
    // Its test.ini only sets SUBROUTINE_PATH=. (the folder).
    Run {
        subroutines: Some("."),
        counter: true,
        ..run("sequence-number", "test.ngc")
    },
    run("inside-corners", "test.ngc"),
    run("g64-r-planner", "test.ngc"),
    run("crazy-paths", "test.ngc"),
    Run {
        table: Some("test.tbl"),
        old_tool_change: true,
        ..run("cam-nisley", "cam.ngc")
    },
    Run {
        table: Some("test.tbl"),
        old_tool_change: true,
        no_negative_zero: true,
        ..run("g10/g10-l1-l10", "test.ngc")
    },
    Run {
        table: Some("test.tbl"),
        old_tool_change: true,
        no_negative_zero: true,
        ..run("g10/g10-l11", "test.ngc")
    },
];

/// Folders that need the full-dialect issue or are out of scope, with the reason.
#[allow(dead_code)]
const FOLDERS_NOT_YET: &[(&str, &str)] = &[
    ("g71-*, g72-*, g76", "lathe cycles, out of scope"),
    (
        "g84/g18/*, g84/g19/*",
        "LinuxCNC 2.9 feeds G84 in G18 along the G19 axes and in G19 along the G18 axes (its \
         tap would go in sideways); tezgah taps along the plane's normal, as G81 does there",
    ),
    ("m19", "spindle orientation"),
    (
        "m98m99/12-M99-endless-main-program",
        "M99 in the main program repeats it for ever (an expected failure in LinuxCNC's suite too)",
    ),
    ("mdi-oword-m66", "MDI and M66, no expected file"),
    (
        "oword-mdi-sub-update, subroutine-return",
        "MDI and a tool-change remap with a Python plug-in, no expected file",
    ),
    (
        "plug, pymove, python, python-self",
        "Python plug-ins, out of scope",
    ),
    (
        "value-returned",
        "Python plug-ins (PYTHON section of test.ini), out of scope",
    ),
];

/// `bad/` programs that need the full-dialect issue (canned cycles, cutter compensation,
/// O-words, M19), with the feature they need.
const BAD_NOT_YET: &[(&str, &str)] = &[("g64-m19-r-ambiguous.ngc", "M19 spindle orientation")];

/// Subroutine files `<name>.ngc` in one folder (the tests' SUBROUTINE_PATH).
#[derive(Debug)]
struct Folder(PathBuf);

impl tezgah_gcode::interp::SubroutineLibrary for Folder {
    fn source(&self, name: &str) -> Option<String> {
        std::fs::read_to_string(self.0.join(format!("{name}.ngc"))).ok()
    }
}

fn config(table: Option<&Path>) -> Config {
    let table = table.map_or_else(ToolTable::default, |p| {
        ToolTable::parse(&std::fs::read_to_string(p).unwrap()).unwrap()
    });
    Config::linuxcnc(table)
}

/// Our calls for a program, one string per call, as `rs274` prints them after its two fields.
fn our_calls(program: &str, cfg: Config) -> (Vec<String>, Result<(), tezgah_gcode::GcodeError>) {
    our_calls_printing(program, cfg, true)
}

/// [`our_calls`]; `awk_prints` drops the first field of `(PRINT,…)` text as LinuxCNC's
/// `awk '{$1=""; print}'` scripts do.
fn our_calls_printing(
    program: &str,
    cfg: Config,
    awk_prints: bool,
) -> (Vec<String>, Result<(), tezgah_gcode::GcodeError>) {
    let mut calls: Vec<(Origin, Canon)> = Vec::new();
    let result = Interpreter::new(cfg).run(program, &mut calls);
    // LinuxCNC's scripts drop the first field of every line with awk, also of the bare text
    // `(PRINT,…)` prints; ours loses it the same way.
    let mut out: Vec<String> = calls
        .iter()
        .map(|(_, c)| match c {
            // awk splits on blanks and joins the fields with one space.
            Canon::Print(_) if awk_prints => {
                let text = c.to_string();
                text.split_whitespace()
                    .skip(1)
                    .collect::<Vec<_>>()
                    .join(" ")
            }
            _ if awk_prints => c
                .to_string()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" "),
            _ => c.to_string(),
        })
        .collect();
    out.push("ON_RESET()".into());
    out.push("ON_RESET()".into());
    (out, result)
}

/// Expected lines without rs274's counter and `N…` fields. Lines without them (the bare text
/// of `(PRINT,…)`) are kept whole.
fn expected_calls(text: &str, has_counter: bool) -> Vec<String> {
    text.lines()
        .filter_map(|l| {
            let mut rest = l.trim_start();
            if has_counter {
                let digits =
                    rest.len() - rest.trim_start_matches(|c: char| c.is_ascii_digit()).len();
                if digits == 0 {
                    return Some(l.to_string());
                }
                rest = rest[digits..].trim_start();
            }
            if !rest.starts_with('N') {
                return Some(rest.to_string());
            }
            // The N field: `N.....` or `N` and digits, padded; `N1234567STRAIGHT_…` is glued.
            let call = rest[1..]
                .trim_start_matches(['.', '0', '1', '2', '3', '4', '5', '6', '7', '8', '9']);
            let call = call.trim_start();
            (!call.is_empty()).then(|| call.to_string())
        })
        .collect()
}

const MOTION: [&str; 5] = [
    "STRAIGHT_TRAVERSE(",
    "STRAIGHT_FEED(",
    "ARC_FEED(",
    "DWELL(",
    "SET_FEED_RATE(",
];

fn is_motion(call: &str) -> bool {
    MOTION.iter().any(|m| call.starts_with(m))
}

fn numbers(call: &str) -> Vec<f64> {
    call.split(['(', ')', ',', ' '])
        .filter_map(|t| t.parse().ok())
        .collect()
}

/// Compare the motion calls of two call lists numerically; `Err` describes the first mismatch.
fn compare_motion(ours: &[String], theirs: &[String]) -> Result<usize, String> {
    let a: Vec<&String> = ours.iter().filter(|c| is_motion(c)).collect();
    let b: Vec<&String> = theirs.iter().filter(|c| is_motion(c)).collect();
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        let name = |s: &str| s.split('(').next().unwrap_or("").to_string();
        let (nx, ny) = (numbers(x), numbers(y));
        let close = nx.len() == ny.len()
            && nx
                .iter()
                .zip(&ny)
                .all(|(p, q)| (p - q).abs() <= 1e-4 + 1e-9 * q.abs());
        if name(x) != name(y) || !close {
            return Err(format!("motion call {i}: ours {x} / LinuxCNC {y}"));
        }
    }
    if a.len() != b.len() {
        return Err(format!("{} motion calls, LinuxCNC {}", a.len(), b.len()));
    }
    Ok(a.len())
}

#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn good_programs_match_linuxcnc() {
    let dir = support::linuxcnc_interp();
    let mut checked = 0;
    for entry in std::fs::read_dir(dir.join("good")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "ngc") {
            continue;
        }
        let program = std::fs::read_to_string(&path).unwrap();
        let expected = std::fs::read_to_string(path.with_extension("ngc.expected")).unwrap();
        let (ours, result) = our_calls(&program, config(None));
        assert!(result.is_ok(), "{}: {result:?}", path.display());
        let theirs = expected_calls(&expected, true);
        assert_eq!(ours, theirs, "{}", path.display());
        checked += 1;
    }
    assert_eq!(checked, 6);
}

#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn bad_programs_fail_with_linuxcnc_text() {
    let dir = support::linuxcnc_interp();
    let (mut checked, mut total) = (0, 0);
    for entry in std::fs::read_dir(dir.join("bad")).unwrap() {
        let path = entry.unwrap().path();
        let file = path.file_name().unwrap().to_string_lossy().to_string();
        if !file.ends_with(".ngc") {
            continue;
        }
        total += 1;
        if BAD_NOT_YET.iter().any(|(f, _)| *f == file) {
            continue;
        }
        let program = std::fs::read_to_string(&path).unwrap();
        let first = program.lines().next().unwrap_or("");
        let want = if let Some(t) = first.strip_prefix(';') {
            t.to_string()
        } else {
            first
                .trim_start_matches('(')
                .trim_end_matches(')')
                .to_string()
        };
        let (_, result) = our_calls(&program, config(None));
        let err = result.expect_err(&file);
        assert_eq!(err.kind.to_string(), want, "{file}");
        checked += 1;
    }
    assert_eq!(
        checked + BAD_NOT_YET.len(),
        total,
        "every bad program runs or is listed"
    );
    assert!(checked >= 21);
}

/// rs274's output with its standard error merged in (`2>&1`): `executing` first, and on an
/// error its text and the offending line before the two `ON_RESET()` of the end.
fn with_stderr(
    calls: &mut Vec<String>,
    result: &Result<(), tezgah_gcode::GcodeError>,
    program: &str,
) {
    calls.insert(0, "executing".into());
    if let Err(e) = result {
        let at = calls.len() - 2;
        let line = program.lines().nth(e.span.line as usize - 1).unwrap_or("");
        calls.splice(at..at, [e.kind.to_string(), line.to_string()]);
    }
}

/// `m98m99/06-error-mixed-sub-styles`: four programs that mix Fanuc and rs274ngc subroutine
/// styles, each stopped with LinuxCNC's message; the expected file holds their outputs in turn.
#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn mixed_subroutine_styles_fail_as_linuxcnc() {
    let dir = support::linuxcnc_interp();
    let base = dir.join("m98m99/06-error-mixed-sub-styles");
    let expected = std::fs::read_to_string(base.join("expected")).unwrap();
    let mut theirs = expected_calls(&expected, true).into_iter().peekable();
    for program in [
        "O...-called-with-O..._call.ngc",
        "O...-ended-with-O..._endsub.ngc",
        "O...-sub-called-with-M98.ngc",
        "O...-sub-ended-with-M99.ngc",
    ] {
        let text = std::fs::read_to_string(base.join(program)).unwrap();
        let (mut ours, result) = our_calls_printing(&text, config(None), false);
        assert!(result.is_err(), "{program} must fail");
        with_stderr(&mut ours, &result, &text);
        for call in ours {
            assert_eq!(theirs.next().as_deref(), Some(call.as_str()), "{program}");
        }
    }
    assert_eq!(theirs.next(), None, "every expected call was produced");
}

/// The calls of a program as the `awk '{$1=""; print}'` scripts leave them, without the final
/// resets (how many close the output depends on how rs274 stopped).
fn awk_calls(program: &str) -> (Vec<String>, Result<(), tezgah_gcode::GcodeError>) {
    let (mut calls, result) = our_calls_printing(program, config(None), true);
    while calls.last().is_some_and(|c| c == "ON_RESET()") {
        calls.pop();
    }
    (calls, result)
}

/// `m98m99/11-main-program-oword`: a main program titled with a number (`O1`), ended by M2,
/// M02, M30 or `%`, with an rs274ngc subroutine after it; the illegal variants stop where
/// LinuxCNC's output stops. The expected file holds the outputs under `Legal test NAME:` and
/// `Illegal test NAME:` headings.
#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn numbered_main_programs_run_as_linuxcnc() {
    let dir = support::linuxcnc_interp();
    let base = dir.join("m98m99/11-main-program-oword");
    let expected = std::fs::read_to_string(base.join("expected")).unwrap();
    let mut sections: Vec<(String, Vec<String>)> = Vec::new();
    for line in expected.lines() {
        if let Some(title) = line.strip_suffix(':').filter(|l| l.contains("test ")) {
            sections.push((title.to_string(), Vec::new()));
        } else if let Some((_, calls)) = sections.last_mut() {
            calls.extend(expected_calls(line, false));
        }
    }
    assert_eq!(sections.len(), 7);
    for (title, mut theirs) in sections {
        let (legal, name) = title.split_once(" test ").unwrap();
        let file = format!("test-{}-{name}.ngc", legal.to_lowercase());
        let text = std::fs::read_to_string(base.join(&file)).unwrap();
        let (ours, result) = awk_calls(&text);
        while theirs.last().is_some_and(|c| c == "ON_RESET()") {
            theirs.pop();
        }
        assert_eq!(ours, theirs, "{file}: {result:?}");
        if legal == "Legal" {
            assert!(result.is_ok(), "{file}: {result:?}");
        }
    }
}

/// `m98m99/09-disable-fanuc-subs`: a Fanuc-style and an rs274ngc-style program, each run with
/// an INI file that allows Fanuc subprograms, one that refuses them (`DISABLE_FANUC_STYLE_SUB`)
/// and none. The expected file holds the six outputs under `program: …; INI: …` headings.
#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn fanuc_subprograms_can_be_disabled() {
    let dir = support::linuxcnc_interp();
    let base = dir.join("m98m99/09-disable-fanuc-subs");
    let expected = std::fs::read_to_string(base.join("expected")).unwrap();
    let mut sections: Vec<(String, Vec<String>)> = Vec::new();
    for line in expected.lines() {
        if let Some(title) = line.strip_prefix("program: ") {
            sections.push((title.to_string(), Vec::new()));
        } else if let Some((_, calls)) = sections.last_mut() {
            calls.extend(expected_calls(line, false));
        }
    }
    assert_eq!(sections.len(), 6);
    for (title, mut theirs) in sections {
        let (program, ini) = title.split_once("; INI: ").unwrap();
        let text = std::fs::read_to_string(base.join(format!("test-{program}.ngc"))).unwrap();
        let mut cfg = config(None);
        let ini_file = match ini {
            "fanuc" => Some("test-fanuc.ini"),
            "NO fanuc" => Some("test-no-fanuc.ini"),
            _ => None,
        };
        if let Some(f) = ini_file {
            let ini = IniFile::parse(&std::fs::read_to_string(base.join(f)).unwrap()).unwrap();
            cfg.ini = Some(std::sync::Arc::new(ini));
        }
        let (mut ours, result) = our_calls_printing(&text, cfg, false);
        with_stderr(&mut ours, &result, &text);
        for list in [&mut ours, &mut theirs] {
            while list.last().is_some_and(|c| c == "ON_RESET()") {
                list.pop();
            }
        }
        assert_eq!(ours, theirs, "{title}");
    }
}

/// `g52/g92-offset-persistence`: G92 offsets read from a parameter file (`rs274 -v`) apply
/// from the start, unless the INI file sets `DISABLE_G92_PERSISTENCE`, which also clears them
/// at the program's end. Three runs: persistence on by the INI file, by default, and off.
#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn g92_offsets_persist_as_the_ini_file_says() {
    let dir = support::linuxcnc_interp();
    let base = dir.join("g52/g92-offset-persistence");
    let expected = std::fs::read_to_string(base.join("expected")).unwrap();
    // Each run's output starts again at call number 1.
    let mut runs: Vec<Vec<String>> = Vec::new();
    for line in expected.lines() {
        if line.trim_start().starts_with("1 N") {
            runs.push(Vec::new());
        }
        if let Some(run) = runs.last_mut() {
            run.extend(expected_calls(line, true));
        }
    }
    let text = std::fs::read_to_string(base.join("g92_offsets.ngc")).unwrap();
    let vars = std::fs::read_to_string(base.join("g92_offsets.var.template")).unwrap();
    let vars = std::sync::Arc::new(tezgah_gcode::params::ParameterFile::parse(&vars).unwrap());
    let inis = [
        Some("persistent_g92_offset_true.ini"),
        None,
        Some("persistent_g92_offset_false.ini"),
    ];
    assert_eq!(runs.len(), inis.len());
    for (mut theirs, ini) in runs.into_iter().zip(inis) {
        let mut cfg = config(None);
        cfg.parameters = Some(vars.clone());
        if let Some(f) = ini {
            let ini = IniFile::parse(&std::fs::read_to_string(base.join(f)).unwrap()).unwrap();
            cfg.ini = Some(std::sync::Arc::new(ini));
        }
        let (mut ours, result) = our_calls_printing(&text, cfg, false);
        assert!(result.is_ok(), "{ini:?}: {result:?}");
        for list in [&mut ours, &mut theirs] {
            while list.last().is_some_and(|c| c == "ON_RESET()") {
                list.pop();
            }
        }
        assert_eq!(ours, theirs, "{ini:?}");
    }
}

/// `m98m99/13-named-program`: `O<name>` and `O42` titles before the program body.
#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn named_programs_run_as_linuxcnc() {
    let dir = support::linuxcnc_interp();
    let base = dir.join("m98m99/13-named-program");
    let expected = std::fs::read_to_string(base.join("expected")).unwrap();
    let mut theirs = expected_calls(&expected, true).into_iter();
    for file in ["test-named.ngc", "test-numbered.ngc"] {
        let text = std::fs::read_to_string(base.join(file)).unwrap();
        let (ours, result) = our_calls_printing(&text, config(None), false);
        assert!(result.is_ok(), "{file}: {result:?}");
        for call in ours {
            assert_eq!(theirs.next().as_deref(), Some(call.as_str()), "{file}");
        }
    }
    assert_eq!(theirs.next(), None, "every expected call was produced");
}

#[test]
#[ignore = "needs LinuxCNC's interpreter tests: set TEZGAH_LINUXCNC_INTERP (see .ci/run)"]
fn folder_tests_match_linuxcnc() {
    let dir = support::linuxcnc_interp();
    let only = std::env::var("TEZGAH_ONLY").ok();
    for r in RUNS
        .iter()
        .filter(|r| only.as_deref().is_none_or(|o| o == r.folder))
    {
        let folder = r.folder;
        let base = dir.join(folder);
        let text = std::fs::read_to_string(base.join(r.program)).unwrap();
        let expected = std::fs::read_to_string(base.join("expected")).unwrap();
        let table = r.table.map(|t| base.join(t));
        let mut cfg = config(table.as_deref());
        if let Some(ini) = r.ini {
            let text = std::fs::read_to_string(base.join(ini)).unwrap();
            cfg.ini = Some(std::sync::Arc::new(IniFile::parse(&text).unwrap()));
        }
        if let Some(dir) = r.subroutines {
            cfg.subroutines = Some(std::sync::Arc::new(Folder(base.join(dir))));
        }
        let (mut ours, result) = if r.go_on {
            let mut calls: Vec<(Origin, Canon)> = Vec::new();
            tezgah_gcode::check_into(&text, cfg, &mut calls);
            let out = calls.iter().map(|(_, c)| c.to_string()).collect();
            (out, Ok(()))
        } else {
            our_calls_printing(&text, cfg, !r.counter)
        };
        assert_eq!(result.is_err(), r.fails, "{folder}: {result:?}");
        if r.stderr {
            with_stderr(&mut ours, &result, &text);
        }
        // How many ON_RESET() close the output depends on how rs274 was started.
        let mut theirs = expected_calls(&expected, r.counter);
        for list in [&mut ours, &mut theirs] {
            while list.last().is_some_and(|c| c == "ON_RESET()") {
                list.pop();
            }
        }
        if r.messages_only {
            // The script: `awk '/MESSAGE/ …' | sed 's/-0\.0000/0.0000/g'`.
            ours.retain(|c| c.starts_with("MESSAGE("));
            theirs.retain(|c| c.starts_with("MESSAGE("));
            for c in &mut ours {
                *c = c.replace("-0.0000", "0.0000");
            }
        }
        if r.old_tool_change {
            ours.retain(|c| c != "START_CHANGE()");
            for c in &mut ours {
                if c.starts_with("CHANGE_TOOL(") {
                    *c = "CHANGE_TOOL()".into();
                }
            }
        }
        if r.no_negative_zero {
            for c in &mut ours {
                *c = c.replace("-0.0000", "0.0000");
            }
        }
        if let Err(e) = compare_motion(&ours, &theirs) {
            panic!("{folder}: {e}");
        }
        // Beyond motion, every call LinuxCNC makes must be ours too, in order.
        assert_eq!(
            ours.len(),
            theirs.len(),
            "{folder}: call counts differ\nours: {ours:#?}\ntheirs: {theirs:#?}"
        );
        for (a, b) in ours.iter().zip(&theirs) {
            let same = a == b
                || (is_motion(a)
                    && compare_motion(std::slice::from_ref(a), std::slice::from_ref(b)).is_ok());
            assert!(same, "{folder}: ours {a} / LinuxCNC {b}");
        }
    }
}
