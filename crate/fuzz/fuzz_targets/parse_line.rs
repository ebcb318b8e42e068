//! Every line of the input through `parse_line`: no panic, finite values, sane error columns.
#![no_main]

use libfuzzer_sys::fuzz_target;
use quietpath::gcode::{parse_line, Lines};

fuzz_target!(|data: &[u8]| {
    for raw in Lines::new(data) {
        match parse_line(raw.text) {
            Ok(line) => {
                for (letter, value) in line.params.iter() {
                    if let Some(v) = value {
                        assert!(
                            v.is_finite(),
                            "word {} = {v} in {:?}",
                            letter as char,
                            raw.text
                        );
                    }
                }
            }
            Err(e) => {
                assert!(e.column >= 1, "column 0: {e:?}");
                assert!(
                    e.column as usize <= raw.text.len() + 1,
                    "column past the end: {e:?}"
                );
            }
        }
    }
});
