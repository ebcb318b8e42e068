//! Lossless rewriting: no edits give the input back byte for byte, and so do the lines.
//! An edit built from the first input byte must leave every other line untouched.
//! The checks live in `checks.rs`, shared with `crate/tests/fuzz_regressions.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../checks.rs"]
mod checks;

fuzz_target!(|data: &[u8]| checks::rewrite(data));
