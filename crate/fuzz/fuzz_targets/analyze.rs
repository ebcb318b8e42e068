//! The whole input through `analyze`, lenient and strict: no panic, lenient analysis only refuses
//! non-text input, and strict analysis, when it accepts a file, agrees with lenient analysis.
#![no_main]

use libfuzzer_sys::fuzz_target;
use quietpath::analyze::{analyze, AnalyzeOptions};
use quietpath::ErrorKind;

fuzz_target!(|data: &[u8]| {
    let lenient = analyze(data, &AnalyzeOptions::default());
    let strict = analyze(
        data,
        &AnalyzeOptions {
            strict: true,
            ..AnalyzeOptions::default()
        },
    );
    match &lenient {
        Ok(report) => {
            let json = serde_json::to_string(report).expect("a report always serialises");
            if let Ok(strict) = &strict {
                let strict_json =
                    serde_json::to_string(strict).expect("a report always serialises");
                assert_eq!(
                    json, strict_json,
                    "strict and lenient reports differ on a file strict mode accepts"
                );
            }
        }
        Err(e) => {
            assert!(
                matches!(e.kind, ErrorKind::Utf16),
                "lenient analysis failed: {e}"
            );
            assert!(strict.is_err(), "strict accepted what lenient refused");
        }
    }
});
