//! Lossless rewriting: no edits give the input back byte for byte, and so do the lines.
//! An edit built from the first input byte must leave every other line untouched.
#![no_main]

use libfuzzer_sys::fuzz_target;
use quietpath::gcode::{apply_edits, Edit, Lines};

fuzz_target!(|data: &[u8]| {
    assert_eq!(
        apply_edits(data, &[]),
        data,
        "rewriting with no edits changed the input"
    );

    let mut concat = Vec::with_capacity(data.len());
    for raw in Lines::new(data) {
        concat.extend_from_slice(raw.text);
        concat.extend_from_slice(raw.terminator);
    }
    assert_eq!(concat, data, "lines do not concatenate to the input");

    // Replace one line (chosen by the first byte) with a fixed text; the other lines keep their
    // text, in order.
    let Some(&first) = data.first() else { return };
    let count = Lines::new(data).count() as u32;
    let target = u32::from(first) % count.max(1) + 1;
    let edits = [Edit {
        line: target,
        replacement: b"G1 X0".to_vec(),
    }];
    let out = apply_edits(data, &edits);
    let expected: Vec<&[u8]> = Lines::new(data)
        .map(|l| {
            if l.number == target {
                &b"G1 X0"[..]
            } else {
                l.text
            }
        })
        .collect();
    let got: Vec<&[u8]> = Lines::new(&out).map(|l| l.text).collect();
    assert_eq!(
        got, expected,
        "an edit of line {target} changed other lines"
    );
});
