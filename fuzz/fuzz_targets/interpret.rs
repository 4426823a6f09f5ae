//! Arbitrary bytes, read as (lossy) UTF-8, through the whole interpreter and through `check`.
//! Errors are expected; a panic, a hang or an out-of-memory is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tezgah_gcode::{canon::Discard, check, interp::ControlLimits, Config, Interpreter};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    // Small loop and call limits: a runaway loop must end in an error, quickly.
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
});
