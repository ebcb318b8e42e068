//! The whole input through `analyze`, lenient and strict: no panic, lenient analysis only refuses
//! non-text input, and strict analysis, when it accepts a file, agrees with lenient analysis.
//! The checks live in `checks.rs`, shared with `crate/tests/fuzz_regressions.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../checks.rs"]
mod checks;

fuzz_target!(|data: &[u8]| checks::analyze(data));
