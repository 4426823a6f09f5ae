//! What the `interpret` fuzz target does with one input, shared with the test that replays the
//! saved corpus, so the two can never drift apart.

use crate::canon::Discard;
use crate::interp::{check, ControlLimits};
use crate::{Config, Interpreter};

/// Run arbitrary bytes (read as lossy UTF-8) through the interpreter and the pre-flight, with
/// small loop and call limits so that a runaway program ends in an error quickly. Errors are
/// expected; only a panic or a hang is a bug.
pub fn interpret(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let cfg = Config {
        limits: ControlLimits {
            max_loop_iterations: 1_000,
            max_call_depth: 16,
        },
        ..Config::default()
    };
    let mut interp = Interpreter::new(cfg.clone());
    let _ = interp.run(&text, &mut Discard);
    let _ = check(&text, cfg);
}
