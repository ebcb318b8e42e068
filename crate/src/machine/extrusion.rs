//! Absolute or relative extrusion, when a file never says.
//!
//! Legacy Cura and Slic3r files print with absolute E (the firmware default) without writing
//! `M82`; Kiri:Moto files rely on a start macro to switch to relative E without writing `M83`.
//! Reading either the wrong way gives kilometres of filament or almost none. The values tell:
//! under absolute extrusion the E word of consecutive printing moves grows (it only falls on
//! retraction and after `G92 E0`), under relative extrusion it is a per-segment amount whose
//! successive values go up about as often as down.

use serde::Serialize;

use crate::gcode::{parse_line, Command, Lines};

/// Extrusion mode for E words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum ExtrusionMode {
    /// `M82`: E is a position.
    #[default]
    Absolute,
    /// `M83`: E is an amount per move.
    Relative,
}

/// Where the initial extrusion mode came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum ModeSource {
    /// The file writes `M82`/`M83` (or `G91`) before its first extrusion.
    Explicit,
    /// Inferred from the E values (see the module documentation).
    Inferred,
    /// Too few E values to tell: the firmware default (absolute) is used.
    Default,
}

/// The result of [`infer_extrusion_mode`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ExtrusionInference {
    /// Mode to start in.
    pub mode: ExtrusionMode,
    /// How it was decided.
    pub source: ModeSource,
    /// Printing moves whose E differed from the previous one.
    pub samples: u32,
    /// Of those, how many had a larger E than the previous one.
    pub increasing: u32,
}

/// Printing moves looked at before deciding.
pub const SAMPLES: u32 = 400;
/// Share of increasing E values above which a file is read as absolute.
pub const ABSOLUTE_SHARE: f64 = 0.8;
/// Fewer samples than this and the firmware default stands.
pub const MIN_SAMPLES: u32 = 8;

/// Decides the extrusion mode a file starts in, reading at most until [`SAMPLES`] printing
/// moves or the first explicit mode command.
pub fn infer_extrusion_mode(input: &[u8]) -> ExtrusionInference {
    let mut prev: Option<f64> = None;
    let mut samples = 0u32;
    let mut increasing = 0u32;
    for raw in Lines::new(input) {
        let Ok(line) = parse_line(raw.text) else {
            continue;
        };
        let Command::Code(code) = line.command else {
            continue;
        };
        match (code.letter, code.number) {
            (b'M', 82) | (b'M', 83) | (b'G', 91) if samples == 0 => {
                let mode = if code.number == 82 {
                    ExtrusionMode::Absolute
                } else {
                    ExtrusionMode::Relative
                };
                return ExtrusionInference {
                    mode,
                    source: ModeSource::Explicit,
                    samples,
                    increasing,
                };
            }
            (b'M', 82) | (b'M', 83) => break,
            (b'G', 92) => {
                if let Some(e) = line.params.get(b'E') {
                    prev = Some(e);
                }
            }
            (b'G', 0..=3) => {
                let Some(e) = line.params.get(b'E') else {
                    continue;
                };
                let moves_xy = line.params.has(b'X') || line.params.has(b'Y');
                if let (Some(p), true) = (prev, moves_xy) {
                    if (e - p).abs() > 1e-9 {
                        samples += 1;
                        if e > p {
                            increasing += 1;
                        }
                    }
                }
                prev = Some(e);
                if samples >= SAMPLES {
                    break;
                }
            }
            _ => {}
        }
    }
    let (mode, source) = if samples < MIN_SAMPLES {
        (ExtrusionMode::Absolute, ModeSource::Default)
    } else if f64::from(increasing) >= ABSOLUTE_SHARE * f64::from(samples) {
        (ExtrusionMode::Absolute, ModeSource::Inferred)
    } else {
        (ExtrusionMode::Relative, ModeSource::Inferred)
    };
    ExtrusionInference {
        mode,
        source,
        samples,
        increasing,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absolute_values_grow() {
        let mut s = String::from("G92 E0\n");
        for i in 1..50 {
            s += &format!("G1 X{} Y{} E{}\n", i % 7, i % 5, f64::from(i) * 0.37);
        }
        let inf = infer_extrusion_mode(s.as_bytes());
        assert_eq!(
            (inf.mode, inf.source),
            (ExtrusionMode::Absolute, ModeSource::Inferred)
        );
    }

    #[test]
    fn relative_values_wander() {
        let mut s = String::new();
        for i in 1..50 {
            s += &format!(
                "G1 X{} Y{} E{:.4}\n",
                i,
                i % 5,
                0.05 + 0.04 * (f64::from(i) * 2.3).sin()
            );
        }
        let inf = infer_extrusion_mode(s.as_bytes());
        assert_eq!(
            (inf.mode, inf.source),
            (ExtrusionMode::Relative, ModeSource::Inferred)
        );
    }

    #[test]
    fn explicit_mode_wins_and_few_samples_default() {
        let inf = infer_extrusion_mode(b"M83\nG1 X1 E1\nG1 X2 E2\n");
        assert_eq!(
            (inf.mode, inf.source),
            (ExtrusionMode::Relative, ModeSource::Explicit)
        );
        let inf = infer_extrusion_mode(b"G1 X1 E1\nG1 X2 E0.5\n");
        assert_eq!(
            (inf.mode, inf.source),
            (ExtrusionMode::Absolute, ModeSource::Default)
        );
    }
}
