//! Arbitrary bytes, read as (lossy) UTF-8, through the whole interpreter and through `check`.
//! Errors are expected; a panic, a hang or an out-of-memory is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tezgah_gcode::{canon::Discard, check, Config, Interpreter};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let mut interp = Interpreter::new(Config::default());
    let _ = interp.run(&text, &mut Discard);
    let _ = check(&text, Config::default());
});
