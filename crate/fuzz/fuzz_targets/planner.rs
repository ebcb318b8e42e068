//! The motion planner on arbitrary motion (bytes decoded as moves, feeds, junction model and
//! preset): speeds continuous and within limits, times finite and additive. See `checks.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../checks.rs"]
mod checks;

fuzz_target!(|data: &[u8]| checks::planner(data));
