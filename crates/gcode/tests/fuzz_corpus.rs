//! Replays the `interpret` fuzz target's seed inputs (`fuzz/seeds/interpret`: the named
//! regression inputs, two of which once hung the interpreter) as an ordinary test: every input
//! goes through the same calls as the fuzz target, and none may panic. Errors are fine.
//! The fuzzer's working corpus (`fuzz/corpus`) stays out of the repository.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/interpret")
}

#[test]
fn fuzz_corpus_never_panics() {
    let dir = corpus_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|entry| entry.expect("reading a corpus entry").path())
        .filter(|path| path.is_file())
        .collect();
    files.sort();
    assert!(
        files.len() >= 7,
        "the seed inputs in {} are missing: {files:?}",
        dir.display()
    );

    let mut panicked = Vec::new();
    for path in &files {
        let data =
            std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        if catch_unwind(AssertUnwindSafe(|| tezgah_gcode::fuzzing::interpret(&data))).is_err() {
            panicked.push(path.display().to_string());
        }
    }
    assert!(
        panicked.is_empty(),
        "{} of {} seed inputs panicked:\n{}",
        panicked.len(),
        files.len(),
        panicked.join("\n")
    );
}
