//! What the `interpret` fuzz target does with one input, shared with the test that replays the
//! saved corpus, so the two can never drift apart.

use crate::interp::{check, ControlLimits};
use crate::moves::program_moves;
use crate::Config;

/// Run arbitrary bytes (read as lossy UTF-8) through the interpreter into moves (NURBS mapped to
/// the machine frame included) and through the pre-flight, with small loop and call limits so
/// that a runaway program ends in an error quickly. Errors are expected; only a panic or a
/// hang is a bug.
pub fn interpret(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let cfg = Config {
        limits: ControlLimits {
            max_loop_iterations: 1_000,
            max_call_depth: 16,
        },
        ..Config::default()
    };
    let _ = program_moves(&text, cfg.clone());
    let _ = check(&text, cfg);
}
