//! `E_fuse` (VTG eq. 16): the heat that melts the filament,
//! `E_fuse = m·(c_p·(T_print − T_ambient) + χ·ΔH_f) / η_heater`.
//!
//! `c_p` is an average over the range from room to printing temperature (the specific heat of
//! these polymers rises from about 1.2–1.4 J/(g·K) in the glass to about 1.8–2.1 J/(g·K) in
//! the melt), `χ·ΔH_f` the latent heat of the crystalline fraction (zero for amorphous
//! polymers), and `η_heater` the share of the extra heater energy that ends up in the filament
//! (the rest heats the block and the air). Material values below are representative handbook
//! values (±20 %), not measurements of a particular filament:
//!
//! - specific heats: J. E. Mark (ed.), *Physical Properties of Polymers Handbook*, 2nd ed.,
//!   Springer 2007, and the ATHAS data bank (B. Wunderlich); for PLA also M. Pyda, R. C. Bopp,
//!   B. Wunderlich, "Heat capacity of poly(lactic acid)", *J. Chem. Thermodyn.* 36 (2004)
//!   731–742;
//! - heat of fusion of 100 % crystalline PLA, 93 J/g: E. W. Fischer, H. J. Sterzel,
//!   G. Wegner, *Kolloid-Z. u. Z. Polymere* 251 (1973) 980–990; commercial printing PLA is
//!   mostly amorphous, taken here as 10 % crystalline;
//! - PETG (glycol-modified PET) and ABS are amorphous: no latent heat;
//! - cradle-to-gate emission factors (for VTG eq. 17): PLA 0.5–2 kg CO₂e/kg depending on plant
//!   and generation (E. T. H. Vink et al., *Polym. Degrad. Stab.* 80 (2003) 403–419: about
//!   1.8; NatureWorks' 2014 Ingeo eco-profile: about 0.6), 2.0 used, the conservative end as
//!   suggested for this project; PET about 2.2 and ABS about 3.3 kg CO₂e/kg (PlasticsEurope
//!   eco-profiles).

use serde::{Deserialize, Serialize};

/// A filament material with built-in properties.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "lowercase")]
pub enum Material {
    /// Polylactic acid (the default).
    #[default]
    Pla,
    /// Glycol-modified polyethylene terephthalate.
    Petg,
    /// Acrylonitrile butadiene styrene.
    Abs,
}

/// What `E_fuse` and the material part of VTG eq. 17 need to know about a material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct MaterialProperties {
    /// Mean specific heat from room to printing temperature, J/(g·K).
    pub specific_heat_j_gk: f64,
    /// Heat of fusion of the fully crystalline polymer, J/g (0 for amorphous polymers).
    pub heat_of_fusion_j_g: f64,
    /// Crystalline fraction of the filament, 0..=1.
    pub crystallinity: f64,
    /// Printing temperature used when the file sets no hotend temperature, °C.
    pub print_temp_c: f64,
    /// Cradle-to-gate emission factor of the material, kg CO₂e per kg.
    pub co2_kg_per_kg: f64,
}

impl Default for MaterialProperties {
    fn default() -> Self {
        Material::Pla.properties()
    }
}

impl MaterialProperties {
    /// Latent heat to melt the crystalline fraction, J/g.
    pub fn latent_heat_j_g(&self) -> f64 {
        self.heat_of_fusion_j_g * self.crystallinity
    }

    /// Whether every value is finite and in range.
    pub fn is_valid(&self) -> bool {
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        nonneg(self.specific_heat_j_gk)
            && nonneg(self.heat_of_fusion_j_g)
            && (0.0..=1.0).contains(&self.crystallinity)
            && self.print_temp_c.is_finite()
            && nonneg(self.co2_kg_per_kg)
    }
}

impl Material {
    /// Built-in properties (sources in the module docs).
    pub fn properties(self) -> MaterialProperties {
        match self {
            Material::Pla => MaterialProperties {
                specific_heat_j_gk: 1.7,
                heat_of_fusion_j_g: 93.0,
                crystallinity: 0.1,
                print_temp_c: 210.0,
                co2_kg_per_kg: 2.0,
            },
            Material::Petg => MaterialProperties {
                specific_heat_j_gk: 1.6,
                heat_of_fusion_j_g: 0.0,
                crystallinity: 0.0,
                print_temp_c: 240.0,
                co2_kg_per_kg: 2.2,
            },
            Material::Abs => MaterialProperties {
                specific_heat_j_gk: 1.7,
                heat_of_fusion_j_g: 0.0,
                crystallinity: 0.0,
                print_temp_c: 245.0,
                co2_kg_per_kg: 3.3,
            },
        }
    }

    /// The material a slicer's `filament_type` names (`PLA`, `PETG`, `PET`, `ABS`), if known.
    pub fn from_name(name: &str) -> Option<Material> {
        let n = name.trim();
        if n.eq_ignore_ascii_case("pla") {
            Some(Material::Pla)
        } else if n.eq_ignore_ascii_case("petg") || n.eq_ignore_ascii_case("pet") {
            Some(Material::Petg)
        } else if n.eq_ignore_ascii_case("abs") {
            Some(Material::Abs)
        } else {
            None
        }
    }

    /// The material named by a slicer comment (the bytes after `;`), such as PrusaSlicer's
    /// `filament_type = PETG` (the first extruder's, for `PLA;PETG`). Cheap for other comments.
    pub fn from_comment(comment: &[u8]) -> Option<Material> {
        const KEY: &[u8] = b"filament_type = ";
        let c = comment.trim_ascii_start();
        if c.first() != Some(&b'f') || !c.starts_with(KEY) {
            return None;
        }
        let rest = &c[KEY.len()..];
        let first = rest.split(|&b| b == b';').next().unwrap_or(rest);
        Material::from_name(std::str::from_utf8(first).ok()?)
    }
}

/// Where the material came from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum MaterialSource {
    /// Given in the options.
    Option,
    /// Named in the file (`filament_type`).
    File,
    /// Not given: PLA.
    #[default]
    Default,
}

/// `E_fuse` of `mass_g` grams heated from `ambient_c` to `print_temp_c`, J.
pub fn fuse_energy_j(
    mass_g: f64,
    props: &MaterialProperties,
    print_temp_c: f64,
    ambient_c: f64,
    heater_efficiency: f64,
) -> f64 {
    let heat_per_g =
        props.specific_heat_j_gk * (print_temp_c - ambient_c).max(0.0) + props.latent_heat_j_g();
    mass_g.max(0.0) * heat_per_g / heater_efficiency
}

/// How `E_fuse` was computed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct FuseReport {
    /// Material.
    pub material: Material,
    /// Where the material came from.
    pub material_source: MaterialSource,
    /// Properties used.
    pub properties: MaterialProperties,
    /// Printing temperature used (the highest hotend target in the file, else the
    /// material's), °C.
    pub print_temp_c: f64,
    /// Ambient temperature, °C.
    pub ambient_c: f64,
    /// Share of the heater's extra energy that reaches the filament.
    pub heater_efficiency: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pla_by_hand() {
        // 10 g of PLA from 25 to 215 °C: 10·(1.7·190 + 9.3) = 3323 J, over 0.9.
        let e = fuse_energy_j(10.0, &Material::Pla.properties(), 215.0, 25.0, 0.9);
        assert!((e - 3323.0 / 0.9).abs() < 1e-9, "{e}");
    }

    #[test]
    fn names_from_comments() {
        assert_eq!(
            Material::from_comment(b" filament_type = PETG"),
            Some(Material::Petg)
        );
        assert_eq!(
            Material::from_comment(b" filament_type = ABS;PLA"),
            Some(Material::Abs)
        );
        assert_eq!(Material::from_comment(b" filament_type = FLEX"), None);
        assert_eq!(Material::from_comment(b" fill_density = 20%"), None);
    }
}
