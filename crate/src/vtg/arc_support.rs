//! Whether the firmware runs arcs, for VTG's `G2`/`G3` output: where it does, arcs are a
//! rewrite's cheapest way to stay within the file's line budget.

use serde::{Deserialize, Serialize};

use crate::analyze::{AnalyzeOptions, Report};
use crate::plan::JunctionModel;

/// Arcs in the output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum ArcsMode {
    /// Where the firmware runs them: a file that already has arcs; Marlin (its default
    /// configuration enables `ARC_SUPPORT`, and Prusa's firmware has them), RepRapFirmware,
    /// Smoothieware and Repetier-Firmware (its shipped configurations set `ARC_SUPPORT 1`);
    /// Klipper only with `[gcode_arcs]` in the printer config given (Klipper lacks them unless
    /// configured).
    #[default]
    Auto,
    /// Always.
    On,
    /// Never.
    Off,
}

impl ArcsMode {
    /// [`ArcsMode::resolve`] as `On` or `Off`.
    pub fn resolved(self, input: &[u8], report: &Report, options: &AnalyzeOptions) -> Self {
        if self.resolve(input, report, options) {
            ArcsMode::On
        } else {
            ArcsMode::Off
        }
    }

    /// The decision for `input` (analysed as `report`).
    pub fn resolve(self, input: &[u8], report: &Report, options: &AnalyzeOptions) -> bool {
        match self {
            ArcsMode::On => true,
            ArcsMode::Off => false,
            ArcsMode::Auto => {
                has_arcs(input)
                    || match &options.klipper_config {
                        Some(c) => c.arc_resolution.is_some(),
                        None => {
                            report.machine.junction_model != JunctionModel::Klipper
                                && arc_capable_flavor(report.file.flavor.as_deref())
                        }
                    }
            }
        }
    }
}

/// A flavour whose firmware runs `G2`/`G3` in its default build.
fn arc_capable_flavor(flavor: Option<&str>) -> bool {
    let Some(f) = flavor else { return false };
    let f = f.to_ascii_lowercase();
    ["marlin", "reprap", "rrf", "smoothie", "prusa", "repetier"]
        .iter()
        .any(|k| f.contains(k))
}

/// The file already has arc moves: its slicer (or ArcWelder) was set up for a firmware that
/// runs them.
fn has_arcs(input: &[u8]) -> bool {
    // Found by `memmem` and checked line by line from there: a byte-wise split of the 34 MB
    // corpus file's lines took 40 ms of `vtg`'s run on one thread.
    [b"G2", b"G3"].iter().any(|code| {
        memchr::memmem::find_iter(input, code).any(|at| {
            let line_start = memchr::memrchr(b'\n', &input[..at]).map_or(0, |i| i + 1);
            input[line_start..at].iter().all(u8::is_ascii_whitespace)
                && input.get(at + 2).is_none_or(|c| !c.is_ascii_digit())
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arcs_in_the_file() {
        assert!(has_arcs(b"G1 X1\nG2 X1 Y1 I1 J0\n"));
        assert!(has_arcs(b"G3"));
        assert!(!has_arcs(b"G1 X1\nG28\nG29\n"));
        assert!(has_arcs(b"G1 X1\n \tG3 X1 Y1 I1 J0\n"));
        assert!(!has_arcs(b"G1 X1 ; G2 X1\nM117 G3\n"));
    }

    proptest::proptest! {
        /// The search finds an arc exactly where reading every line does.
        #[test]
        fn the_search_agrees_with_reading_every_line(
            parts in proptest::collection::vec(
                proptest::sample::select(vec![
                    "G2", "G3", "G1", "G28", "2", " ", "\t", "\r", "\n", ";", "X1", "M117 ",
                ]),
                0..40,
            ),
        ) {
            let text: String = parts.concat();
            let every_line = text.as_bytes().split(|&b| b == b'\n').any(|l| {
                let l = l.trim_ascii_start();
                (l.starts_with(b"G2") || l.starts_with(b"G3"))
                    && l.get(2).is_none_or(|c| !c.is_ascii_digit())
            });
            proptest::prop_assert_eq!(has_arcs(text.as_bytes()), every_line, "{:?}", text);
        }
    }

    #[test]
    fn flavours() {
        assert!(arc_capable_flavor(Some("marlin2")));
        assert!(arc_capable_flavor(Some("RepRapFirmware")));
        assert!(arc_capable_flavor(Some("repetier")));
        assert!(!arc_capable_flavor(Some("teacup")));
        assert!(!arc_capable_flavor(Some("klipper")));
        assert!(!arc_capable_flavor(None));
    }
}
