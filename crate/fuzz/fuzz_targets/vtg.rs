//! `vtg` on arbitrary input: a typed error or a sane output within its tolerance (see
//! `checks.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../checks.rs"]
mod checks;

fuzz_target!(|data: &[u8]| checks::vtg(data));
