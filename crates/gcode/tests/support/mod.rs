//! The oracles of the differential tests. Each test that needs one is `#[ignore]`d with the
//! reason, so a plain `cargo test` lists it as ignored; `.ci/run` runs them with
//! `--include-ignored`, and a test run without its oracle fails here instead of passing untested.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// LinuxCNC's standalone interpreter: the wrapper script `.ci/install-rs274` writes, named by
/// `$TEZGAH_RS274`.
pub fn rs274() -> PathBuf {
    let Some(path) = std::env::var_os("TEZGAH_RS274").map(PathBuf::from) else {
        panic!(
            "TEZGAH_RS274 is not set: this test compares against LinuxCNC's rs274; install it \
             with .ci/install-rs274 and export the path it prints last"
        );
    };
    assert!(
        path.is_file(),
        "TEZGAH_RS274={} is not a file (see .ci/install-rs274)",
        path.display()
    );
    path
}

/// LinuxCNC's interpreter tests (`tests/interp` of LinuxCNC; GPL-2 data, not in this
/// repository): `$TEZGAH_LINUXCNC_INTERP`, or `shared/data/linuxcnc-interp` beside the
/// repository.
pub fn linuxcnc_interp() -> PathBuf {
    let set = std::env::var_os("TEZGAH_LINUXCNC_INTERP").map(PathBuf::from);
    let candidates = [
        set.clone(),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/linuxcnc-interp")),
        Some(PathBuf::from("/work/shared/data/linuxcnc-interp")),
    ];
    candidates
        .into_iter()
        .flatten()
        .find(|p| p.join("good").is_dir())
        .unwrap_or_else(|| {
            panic!(
                "LinuxCNC's interpreter test data not found (TEZGAH_LINUXCNC_INTERP = {set:?}, \
                 nor ../shared/data/linuxcnc-interp beside the repository): set \
                 TEZGAH_LINUXCNC_INTERP to a copy of LinuxCNC's tests/interp"
            )
        })
}
