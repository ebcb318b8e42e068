//! What slicers say in comments: layer changes, feature types, and a few settings.
//!
//! Each slicer family marks layers and features its own way; this module maps all of them onto
//! one vocabulary. Only comment text is looked at, so a file without markers still parses; the
//! analysis then falls back to geometry (Z changes while extruding).

use serde::Serialize;

/// The family of layer-change marker a file uses. A file is counted by the first family seen,
/// so a file that writes both `;LAYER_CHANGE` and `;LAYER:n` is not counted twice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum LayerMarkerKind {
    /// PrusaSlicer, SuperSlicer, OrcaSlicer, Bambu, Creality Print: `;LAYER_CHANGE`.
    LayerChange,
    /// Cura, CuraEngine, ideaMaker, Creality Print 4: `;LAYER:n`.
    CuraLayer,
    /// Simplify3D: `; layer n, Z = z`.
    Simplify3d,
    /// KISSlicer: `; BEGIN_LAYER_OBJECT z=...`.
    KisSlicer,
    /// Kiri:Moto: `;; --- layer n (h @ z) ---`.
    KiriMoto,
}

/// A marker found in a comment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Marker<'a> {
    /// A layer starts here; the Z is given when the marker carries it.
    Layer {
        /// Marker family.
        kind: LayerMarkerKind,
        /// Z height written in the marker, if any.
        z: Option<f64>,
    },
    /// The following moves print this feature (name as written by the slicer).
    Feature(&'a str),
}

/// The canonical kind of a printed feature, mapped from every slicer's own names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum FeatureKind {
    /// Outer wall / external perimeter.
    OuterWall,
    /// Inner walls / perimeters / loops.
    InnerWall,
    /// Sparse (partial-density) infill: the region quietpath may regenerate.
    SparseInfill,
    /// Solid infill, including top and bottom skins.
    SolidInfill,
    /// Bridges.
    Bridge,
    /// Gap fill.
    GapFill,
    /// Support and support interface.
    Support,
    /// Skirt, brim, raft, prime lines and pillars.
    Adhesion,
    /// Custom G-code blocks (start/end), wipes, anything unnamed.
    Other,
}

/// Maps a slicer's feature name onto a [`FeatureKind`].
pub fn feature_kind(name: &str) -> FeatureKind {
    let n = name.trim().to_ascii_lowercase();
    let has = |s: &str| n.contains(s);
    if has("support") {
        FeatureKind::Support
    } else if has("skirt") || has("brim") || has("raft") || has("prime") {
        FeatureKind::Adhesion
    } else if has("bridge") {
        FeatureKind::Bridge
    } else if has("gap") {
        FeatureKind::GapFill
    } else if has("outer") || has("external") || n == "wall-outer" {
        FeatureKind::OuterWall
    } else if has("perimeter") || has("wall") || has("loop") || has("shell") {
        FeatureKind::InnerWall
    } else if has("solid") || has("skin") || has("top") || has("bottom") || has("ironing") {
        FeatureKind::SolidInfill
    } else if has("infill") || n == "fill" || has("sparse") {
        FeatureKind::SparseInfill
    } else {
        FeatureKind::Other
    }
}

fn parse_num(s: &[u8]) -> Option<f64> {
    let s = trim_ascii(s);
    let end = s
        .iter()
        .position(|b| !(b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+')))
        .unwrap_or(s.len());
    let v = fast_float2::parse::<f64, _>(&s[..end]).ok()?;
    v.is_finite().then_some(v)
}

fn trim_ascii(s: &[u8]) -> &[u8] {
    let start = s
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(s.len());
    let end = s
        .iter()
        .rposition(|b| !b.is_ascii_whitespace())
        .map_or(start, |e| e + 1);
    &s[start..end.max(start)]
}

fn after<'a>(s: &'a [u8], prefix: &str) -> Option<&'a [u8]> {
    s.strip_prefix(prefix.as_bytes())
}

fn value_after(s: &[u8], key: &str) -> Option<f64> {
    let at = s.windows(key.len()).position(|w| w == key.as_bytes())?;
    parse_num(&s[at + key.len()..])
}

/// Recognises a layer or feature marker in the text of a `;` comment (the bytes after `;`).
pub fn classify_comment(comment: &[u8]) -> Option<Marker<'_>> {
    let c = comment;
    let first = *c.first()?;
    // Fast reject: markers start with one of these bytes (after optional spaces/semicolons).
    if !matches!(first, b'L' | b'T' | b' ' | b';' | b'F') {
        return None;
    }
    if c == b"LAYER_CHANGE" {
        return Some(Marker::Layer {
            kind: LayerMarkerKind::LayerChange,
            z: None,
        });
    }
    if let Some(rest) = after(c, "LAYER:") {
        let rest = trim_ascii(rest);
        if !rest.is_empty() && rest.iter().all(|b| b.is_ascii_digit() || *b == b'-') {
            return Some(Marker::Layer {
                kind: LayerMarkerKind::CuraLayer,
                z: None,
            });
        }
        return None;
    }
    if let Some(rest) = after(c, "TYPE:") {
        return feature(rest);
    }
    if let Some(rest) = after(c, " FEATURE: ") {
        return feature(rest);
    }
    if let Some(rest) = after(c, " feature ") {
        return feature(rest);
    }
    if let Some(rest) = after(c, " layer ") {
        // Simplify3D: " layer 12, Z = 1.300"
        let digits = rest.iter().take_while(|b| b.is_ascii_digit()).count();
        if digits > 0 && rest[digits..].starts_with(b",") {
            let z = value_after(rest, "Z =");
            return Some(Marker::Layer {
                kind: LayerMarkerKind::Simplify3d,
                z,
            });
        }
        return None;
    }
    if let Some(rest) = after(c, " BEGIN_LAYER_OBJECT") {
        return Some(Marker::Layer {
            kind: LayerMarkerKind::KisSlicer,
            z: value_after(rest, "z="),
        });
    }
    if let Some(rest) = after(c, "; --- layer ") {
        return Some(Marker::Layer {
            kind: LayerMarkerKind::KiriMoto,
            z: value_after(rest, "@ "),
        });
    }
    if let Some(rest) = after(c, " '") {
        // KISSlicer: " 'Perimeter Path', 0.6 [feed mm/s], ..."
        let end = rest.iter().position(|&b| b == b'\'')?;
        let name = &rest[..end];
        if name.ends_with(b" Path") {
            return std::str::from_utf8(name).ok().map(Marker::Feature);
        }
    }
    None
}

fn feature(rest: &[u8]) -> Option<Marker<'_>> {
    let name = trim_ascii(rest);
    if name.is_empty() {
        return None;
    }
    std::str::from_utf8(name).ok().map(Marker::Feature)
}

/// Facts a slicer writes about itself and its settings in comments.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SlicerInfo {
    /// Slicer name and version, from the header.
    pub slicer: Option<String>,
    /// Firmware flavour as declared (`marlin2`, `klipper`, `reprap`...), lower case.
    pub flavor: Option<String>,
    /// Declared filament diameter, mm.
    pub filament_diameter_mm: Option<f64>,
    /// Declared layer height, mm.
    pub layer_height_mm: Option<f64>,
    /// Declared first layer height, mm.
    pub first_layer_height_mm: Option<f64>,
    /// Declared filament density, g/cm³.
    pub filament_density_g_cm3: Option<f64>,
}

impl SlicerInfo {
    /// Learns what it can from one comment (the bytes after `;`). Cheap for comments that say
    /// nothing of interest (thumbnails, free text).
    pub fn observe(&mut self, comment: &[u8]) {
        let c = trim_ascii(comment);
        if c.len() < 6 || c.len() > 4096 {
            return;
        }
        if self.slicer.is_none() {
            self.slicer = detect_slicer(c);
        }
        if self.flavor.is_none() {
            if let Some(v) = after(c, "FLAVOR:") {
                self.flavor = text(v).map(|s| s.to_ascii_lowercase());
            } else if let Some(v) = after(c, "gcode_flavor = ") {
                self.flavor = text(v).map(|s| s.to_ascii_lowercase());
            }
        }
        let set = |slot: &mut Option<f64>, v: Option<f64>| {
            if slot.is_none() {
                *slot = v.filter(|x| *x > 0.0);
            }
        };
        match c[0] {
            b'f' | b'F' => {
                if let Some(v) = after(c, "filament_diameter = ") {
                    set(&mut self.filament_diameter_mm, parse_num(v));
                } else if let Some(v) = after(c, "filament_density = ") {
                    set(&mut self.filament_density_g_cm3, parse_num(v));
                } else if let Some(v) = after(c, "first_layer_height = ") {
                    set(&mut self.first_layer_height_mm, parse_num(v));
                } else if let Some(v) = after(c, "filamentDiameters,") {
                    set(&mut self.filament_diameter_mm, parse_num(v));
                } else if let Some(v) = after(c, "filament_diameter_mm") {
                    set(&mut self.filament_diameter_mm, value_after(v, "= "));
                }
            }
            b'l' | b'L' => {
                if let Some(v) = after(c, "layer_height = ") {
                    set(&mut self.layer_height_mm, parse_num(v));
                } else if let Some(v) = after(c, "Layer height: ") {
                    set(&mut self.layer_height_mm, parse_num(v));
                } else if let Some(v) = after(c, "layerHeight,") {
                    set(&mut self.layer_height_mm, parse_num(v));
                } else if let Some(v) = after(c, "layer_height_mm") {
                    set(&mut self.layer_height_mm, value_after(v, "= "));
                }
            }
            b's' => {
                if let Some(v) = after(c, "sliceHeight = ") {
                    set(&mut self.layer_height_mm, parse_num(v));
                }
            }
            _ => {}
        }
    }
}

fn text(v: &[u8]) -> Option<String> {
    let v = trim_ascii(v);
    (!v.is_empty()).then(|| String::from_utf8_lossy(v).into_owned())
}

fn detect_slicer(c: &[u8]) -> Option<String> {
    let s = std::str::from_utf8(c).ok()?;
    let take = |from: usize| Some(s[from..].trim().trim_end_matches(',').to_string());
    if let Some(i) = s.find("generated by ") {
        let rest = &s[i + 13..];
        let name = rest.split(" on ").next().unwrap_or(rest);
        return Some(name.trim().to_string());
    }
    if let Some(i) = s.find("Generated with ") {
        return take(i + 15);
    }
    if s.starts_with("Generated by Kiri:Moto") {
        return take(13);
    }
    if s.starts_with("Simplify3D(R) Version") || s.starts_with("KISSlicer") {
        return take(0);
    }
    if s.starts_with("ideaMaker") {
        return Some(s.split(',').next().unwrap_or(s).trim().to_string());
    }
    if let Some(v) = s.strip_prefix("Creality Print Version : V") {
        return Some(format!("Creality Print {}", v.trim()));
    }
    if s.contains("created with FullControl") {
        return Some("FullControl".to_string());
    }
    if let Some(v) = s.strip_prefix("Sliced by ") {
        return Some(v.trim().to_string());
    }
    if s.starts_with("CURA_PROFILE_STRING") {
        return Some("Cura (legacy 15.x)".to_string());
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(c: &str) -> Option<LayerMarkerKind> {
        match classify_comment(c.as_bytes()) {
            Some(Marker::Layer { kind, .. }) => Some(kind),
            _ => None,
        }
    }

    #[test]
    fn layer_markers_of_every_dialect() {
        assert_eq!(layer("LAYER_CHANGE"), Some(LayerMarkerKind::LayerChange));
        assert_eq!(layer("LAYER:12"), Some(LayerMarkerKind::CuraLayer));
        assert_eq!(layer("LAYER:-2"), Some(LayerMarkerKind::CuraLayer));
        assert_eq!(
            layer(" layer 3, Z = 0.900"),
            Some(LayerMarkerKind::Simplify3d)
        );
        assert_eq!(
            layer(" BEGIN_LAYER_OBJECT z=0.263 z_thickness=0.263"),
            Some(LayerMarkerKind::KisSlicer)
        );
        assert_eq!(
            layer("; --- layer 0 (0.250 @ 0.255) ---"),
            Some(LayerMarkerKind::KiriMoto)
        );
        // Look-alikes that are not markers.
        assert_eq!(layer("LAYER_COUNT:100"), None);
        assert_eq!(layer(" layer_height = 0.2"), None);
        assert_eq!(layer("   layerHeight,0.10000"), None);
        assert_eq!(layer("AFTER_LAYER_CHANGE"), None);
    }

    #[test]
    fn marker_z_values() {
        assert_eq!(
            classify_comment(b" layer 3, Z = 0.900"),
            Some(Marker::Layer {
                kind: LayerMarkerKind::Simplify3d,
                z: Some(0.9)
            })
        );
        assert_eq!(
            classify_comment(b"; --- layer 1 (0.200 @ 0.45) ---"),
            Some(Marker::Layer {
                kind: LayerMarkerKind::KiriMoto,
                z: Some(0.45)
            })
        );
    }

    #[test]
    fn features_map_to_kinds() {
        let kind = |c: &str| match classify_comment(c.as_bytes()) {
            Some(Marker::Feature(n)) => Some(feature_kind(n)),
            _ => None,
        };
        assert_eq!(
            kind("TYPE:External perimeter"),
            Some(FeatureKind::OuterWall)
        );
        assert_eq!(kind("TYPE:WALL-INNER"), Some(FeatureKind::InnerWall));
        assert_eq!(kind("TYPE:FILL"), Some(FeatureKind::SparseInfill));
        assert_eq!(
            kind("TYPE:Internal infill"),
            Some(FeatureKind::SparseInfill)
        );
        assert_eq!(kind("TYPE:Sparse infill"), Some(FeatureKind::SparseInfill));
        assert_eq!(
            kind("TYPE:Internal solid infill"),
            Some(FeatureKind::SolidInfill)
        );
        assert_eq!(kind("TYPE:SKIN"), Some(FeatureKind::SolidInfill));
        assert_eq!(kind(" FEATURE: Outer wall"), Some(FeatureKind::OuterWall));
        assert_eq!(kind(" feature solid layer"), Some(FeatureKind::SolidInfill));
        assert_eq!(kind(" feature support"), Some(FeatureKind::Support));
        assert_eq!(
            kind(" 'Stacked Sparse Infill Path', 1.2 [feed mm/s]"),
            Some(FeatureKind::SparseInfill)
        );
        assert_eq!(kind(" 'Loop Path'"), Some(FeatureKind::InnerWall));
        assert_eq!(kind("TYPE:Skirt/Brim"), Some(FeatureKind::Adhesion));
        assert_eq!(kind("TYPE:Bridge infill"), Some(FeatureKind::Bridge));
    }

    #[test]
    fn slicer_settings() {
        let mut info = SlicerInfo::default();
        for c in [
            " generated by PrusaSlicer 2.6.1+MacOS-x64 on 2023-10-01 at 10:00:00 UTC",
            " filament_diameter = 1.75,1.75",
            " layer_height = 0.2",
            " gcode_flavor = marlin2",
        ] {
            info.observe(c.as_bytes());
        }
        assert_eq!(info.slicer.as_deref(), Some("PrusaSlicer 2.6.1+MacOS-x64"));
        assert_eq!(info.filament_diameter_mm, Some(1.75));
        assert_eq!(info.layer_height_mm, Some(0.2));
        assert_eq!(info.flavor.as_deref(), Some("marlin2"));
    }
}
