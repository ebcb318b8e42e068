//! Every line of the input through `parse_line`: no panic, finite values, sane error columns.
//! The checks live in `checks.rs`, shared with `crate/tests/fuzz_regressions.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../checks.rs"]
mod checks;

fuzz_target!(|data: &[u8]| checks::parse_line(data));
