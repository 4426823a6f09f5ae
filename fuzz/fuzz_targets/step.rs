//! Arbitrary bytes through STEP input: the Part 21 parser, units, the face walk and every
//! surface and curve mapper. Errors are expected; a panic, a hang or an out-of-memory is a bug.
//! Seeds: the OpenCascade fixtures, `cargo fuzz run step corpus/step ../crates/cam/tests/fixtures`
//! (the working corpus `fuzz/corpus/step` is not committed).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| tezgah_cam::step::fuzz(data));
