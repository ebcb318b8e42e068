//! Infill patterns, generated inside a region with the original infill's line spacing.
//!
//! `spacing` is always the spacing of an equivalent **rectilinear** infill (length per area
//! = 1/spacing); each pattern scales its own pitch so its length per area, and so its density
//! and material, stay the same: grid lines `2S` apart (two families), triangles and
//! tri-hexagon `3S` (three families), curves `S` (one loop or turn per `S`; the octagram's
//! star turns `1.9 S`, since each is about 1.9 times as long as a circle).

pub(crate) mod curves;
pub(crate) mod lines;

use serde::{Deserialize, Serialize};

use super::geom::{rotate, Path, Region};

/// An infill pattern.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "InfillPattern"))]
#[serde(rename_all = "snake_case")]
pub enum Pattern {
    /// Parallel lines, turned 90° every layer (PrusaSlicer's and Cura's "lines").
    Rectilinear,
    /// Two crossing families at 90°, the same every layer.
    Grid,
    /// Three families at 60° through common points.
    Triangles,
    /// Three families at 60°, one shifted half a pitch (kagome: triangles and hexagons).
    TriHexagon,
    /// Loops following the region's outline inwards.
    Concentric,
    /// The Hilbert space-filling curve.
    Hilbert,
    /// An Archimedean spiral drawn with chords.
    ArchimedeanChords,
    /// A spiral of eight-pointed stars.
    OctagramSpiral,
    /// Cross-line: the Sierpiński space-filling curve (what Cura's "cross" infill is built on).
    CrossLine,
}

impl Pattern {
    /// Every pattern.
    pub const ALL: [Pattern; 9] = [
        Pattern::Rectilinear,
        Pattern::Grid,
        Pattern::Triangles,
        Pattern::TriHexagon,
        Pattern::Concentric,
        Pattern::Hilbert,
        Pattern::ArchimedeanChords,
        Pattern::OctagramSpiral,
        Pattern::CrossLine,
    ];
    /// The five patterns of the thesis's DOE (Table 4).
    pub const THESIS: [Pattern; 5] = [
        Pattern::Rectilinear,
        Pattern::Concentric,
        Pattern::Hilbert,
        Pattern::ArchimedeanChords,
        Pattern::OctagramSpiral,
    ];

    /// The snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Pattern::Rectilinear => "rectilinear",
            Pattern::Grid => "grid",
            Pattern::Triangles => "triangles",
            Pattern::TriHexagon => "tri_hexagon",
            Pattern::Concentric => "concentric",
            Pattern::Hilbert => "hilbert",
            Pattern::ArchimedeanChords => "archimedean_chords",
            Pattern::OctagramSpiral => "octagram_spiral",
            Pattern::CrossLine => "cross_line",
        }
    }

    /// Parses a name (snake_case, or with dashes; "line" and "lines" name rectilinear).
    pub fn parse(s: &str) -> Option<Pattern> {
        let s = s.trim().to_ascii_lowercase().replace('-', "_");
        match s.as_str() {
            "line" | "lines" => return Some(Pattern::Rectilinear),
            "trihexagon" => return Some(Pattern::TriHexagon),
            "archimedean" => return Some(Pattern::ArchimedeanChords),
            "octagram" => return Some(Pattern::OctagramSpiral),
            "cross" | "crossline" => return Some(Pattern::CrossLine),
            _ => {}
        }
        Pattern::ALL.into_iter().find(|p| p.name() == s)
    }

    /// Whether the pattern is made of straight line families (rows for a zigzag).
    pub fn is_lines(self) -> bool {
        matches!(
            self,
            Pattern::Rectilinear | Pattern::Grid | Pattern::Triangles | Pattern::TriHexagon
        )
    }

    /// Pitch factor against rectilinear spacing (see the module docs).
    fn pitch(self) -> f64 {
        match self {
            Pattern::Grid => 2.0,
            Pattern::Triangles | Pattern::TriHexagon => 3.0,
            // Measured: a star turn is about 1.9 times as long as a circle of the same radius.
            Pattern::OctagramSpiral => 1.9,
            _ => 1.0,
        }
    }
}

/// The pattern's pieces in `region` (part frame), in the order the linker should walk them:
/// rows of segments for line patterns (one `Vec` per row), curve pieces one per `Vec` for the
/// others. `angle_deg` turns the pattern; `layer` picks the 90° alternation of rectilinear.
pub(crate) fn generate(
    region: &Region,
    pattern: Pattern,
    angle_deg: f64,
    spacing: f64,
    layer: usize,
) -> Vec<Vec<Path>> {
    let pitch = pattern.pitch() * spacing;
    if pitch.is_nan() || pitch <= 1e-3 || !angle_deg.is_finite() {
        return Vec::new();
    }
    let rows = |angles: &[(f64, f64)]| -> Vec<Vec<Path>> {
        angles
            .iter()
            .flat_map(|&(a, off)| lines::family(region, angle_deg + a, pitch, off * pitch))
            .map(|row| row.into_iter().map(|s| s.to_vec()).collect())
            .collect()
    };
    match pattern {
        Pattern::Rectilinear => {
            let a = if layer % 2 == 1 { 90.0 } else { 0.0 };
            rows(&[(a, 0.5)])
        }
        Pattern::Grid => rows(&[(0.0, 0.5), (90.0, 0.5)]),
        Pattern::Triangles => rows(&[(0.0, 0.0), (60.0, 0.0), (120.0, 0.0)]),
        Pattern::TriHexagon => rows(&[(0.0, 0.0), (60.0, 0.0), (120.0, 0.5)]),
        Pattern::Concentric
        | Pattern::Hilbert
        | Pattern::ArchimedeanChords
        | Pattern::OctagramSpiral
        | Pattern::CrossLine => {
            // Build upright in a frame turned by -angle, then turn back.
            let back = super::geom::cos_sin_deg(angle_deg);
            let fwd = (back.0, -back.1);
            let o = [0.0, 0.0];
            let turned: Region = region
                .iter()
                .map(|c| c.iter().map(|&p| rotate(p, o, fwd)).collect())
                .collect();
            let pieces = match pattern {
                // Loops follow the outline whatever the angle.
                Pattern::Concentric => {
                    return curves::concentric(region, pitch)
                        .into_iter()
                        .map(|p| vec![p])
                        .collect()
                }
                Pattern::Hilbert => curves::hilbert(&turned, pitch),
                Pattern::ArchimedeanChords => curves::archimedean(&turned, pitch),
                Pattern::CrossLine => curves::sierpinski(&turned, pitch),
                _ => curves::octagram(&turned, pitch),
            };
            pieces
                .into_iter()
                .map(|p| vec![p.into_iter().map(|q| rotate(q, o, back)).collect()])
                .collect()
        }
    }
}

/// Longest boundary link between two lines of a family, in pitches: a wall at 10° to the
/// lines still links them (pitch / sin 10° = 5.8 pitches), as PrusaSlicer's connected infill
/// links along the perimeter.
const LINK_PITCHES: f64 = 6.0;

/// The pieces of a line pattern (`is_lines`) linked into zigzag chains family by family:
/// neighbouring lines joined along the region's boundary where the boundary between their
/// ends is at most `LINK_PITCHES` pitches long ([`lines::chains`]). Other patterns: no chains.
pub(crate) fn chains(
    region: &Region,
    pattern: Pattern,
    angle_deg: f64,
    spacing: f64,
    layer: usize,
) -> Vec<Path> {
    let pitch = pattern.pitch() * spacing;
    if pitch.is_nan() || pitch <= 1e-3 || !angle_deg.is_finite() {
        return Vec::new();
    }
    let families: &[(f64, f64)] = match pattern {
        Pattern::Rectilinear if layer % 2 == 1 => &[(90.0, 0.5)],
        Pattern::Rectilinear => &[(0.0, 0.5)],
        Pattern::Grid => &[(0.0, 0.5), (90.0, 0.5)],
        Pattern::Triangles => &[(0.0, 0.0), (60.0, 0.0), (120.0, 0.0)],
        Pattern::TriHexagon => &[(0.0, 0.0), (60.0, 0.0), (120.0, 0.5)],
        _ => &[],
    };
    families
        .iter()
        .flat_map(|&(a, off)| {
            lines::chains(
                region,
                angle_deg + a,
                pitch,
                off * pitch,
                LINK_PITCHES * pitch,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infill::geom::path_len;

    #[test]
    fn names_round_trip() {
        for p in Pattern::ALL {
            assert_eq!(Pattern::parse(p.name()), Some(p));
        }
        assert_eq!(Pattern::parse("Line"), Some(Pattern::Rectilinear));
        assert_eq!(Pattern::parse("nope"), None);
    }

    #[test]
    fn every_pattern_has_about_the_same_length_per_area() {
        let sq: Region = vec![vec![[0.0, 0.0], [40.0, 0.0], [40.0, 40.0], [0.0, 40.0]]];
        for p in Pattern::ALL {
            for angle in [0.0, 30.0, 45.0] {
                let len: f64 = generate(&sq, p, angle, 2.0, 0)
                    .iter()
                    .flatten()
                    .map(|q| path_len(q))
                    .sum();
                // 1600 mm² / 2 mm = 800 mm of lines; the curves differ by their ends.
                assert!(len > 640.0 && len < 960.0, "{p:?} at {angle}: {len}");
            }
        }
    }
}

#[cfg(all(test, not(target_arch = "wasm32")))]
mod props {
    use super::*;
    use crate::infill::geom::inside_tol;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Every point of every pattern lies in the region (a rectangle with a square hole),
        /// whatever the angle, size and spacing.
        #[test]
        fn pieces_stay_in_the_region(
            w in 8.0f64..60.0,
            h in 8.0f64..60.0,
            hole in 0.1f64..0.4,
            angle in -180.0f64..180.0,
            spacing in 0.8f64..4.0,
            k in 0usize..9,
        ) {
            let (hx, hy) = (w * hole, h * hole);
            let region: Region = vec![
                vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]],
                vec![
                    [w / 2.0 - hx, h / 2.0 - hy],
                    [w / 2.0 - hx, h / 2.0 + hy],
                    [w / 2.0 + hx, h / 2.0 + hy],
                    [w / 2.0 + hx, h / 2.0 - hy],
                ],
            ];
            let p = Pattern::ALL[k];
            // Linked chains too: their boundary links follow the region's edges.
            let linked = chains(&region, p, angle, spacing, 1);
            for piece in generate(&region, p, angle, spacing, 1).iter().flatten().chain(&linked) {
                for w2 in piece.windows(2) {
                    let mid = [0.5 * (w2[0][0] + w2[1][0]), 0.5 * (w2[0][1] + w2[1][1])];
                    for q in [w2[0], w2[1], mid] {
                        prop_assert!(inside_tol(&region, q, 1e-3), "{p:?} {q:?}");
                    }
                }
            }
        }
    }
}
