//! Arbitrary bytes, read as (lossy) UTF-8, through the whole interpreter into moves and
//! through `check`. Errors are expected; a panic, a hang or an out-of-memory is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| tezgah_gcode::fuzzing::interpret(data));
