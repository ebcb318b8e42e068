//! Energy and carbon models: how much electricity a print takes and what it emits.
//!
//! The total follows the VTG paper (Wang et al., VTG eq. 16–17):
//! `E = E_servo + E_fuse + E_aux` and `m_CO₂ = f_e·E + f_m·m_material`, where
//!
//! - `E_servo`, the X/Y drives, is by default the thesis stepper model
//!   ([`thesis`], Somade 2023, thesis eq. 24–28, with the published regression coefficients or
//!   calibrated ones, see [`calibrate`]); for servo machines a physical model ([`servo`]) of
//!   kinetic energy, friction, copper losses and standby draw;
//! - `E_fuse` the heat that melts the filament ([`fuse`]);
//! - `E_aux` the heaters holding their targets, warming up, fans and electronics over the
//!   print's timeline ([`auxiliary`]).
//!
//! The stepper model is always computed (`thesis_j` in the report) so files can be compared by
//! it whatever the machine. Accumulation happens once per planned move, inside the analysis
//! pass: a few dozen flops, no allocation ([`Accumulator::planned`]).
//!
//! Per-layer and per-feature `energy_j` in the report are the `E_servo` of their moves (and of
//! dwells, for layers) plus a share of `E_aux` in proportion to their time (`aux_j / time_s`
//! per second). `E_fuse` is not spread over them. Features add up to `servo_j + aux_j` less
//! what dwells take (dwells belong to no feature); layers to `servo_j + aux_j` less what
//! happens before the first layer.
//!
//! Emission factors: electricity 0.475 kg CO₂/kWh, the world-average carbon intensity of
//! power generation in 2018 (IEA, *Global Energy & CO₂ Status Report 2019*); material factors
//! per material in [`fuse`].

pub mod auxiliary;
pub mod calibrate;
pub mod fuse;
pub mod servo;
pub mod thesis;

use serde::{Deserialize, Serialize};

use crate::machine::{FanEvent, Heater, TemperatureEvent};
use crate::plan::PlannedMove;
pub use auxiliary::{AuxPowers, AuxReport};
pub use calibrate::{fit, parse_csv, Calibration, CalibrationError, CsvRows, Observation};
pub use fuse::{FuseReport, Material, MaterialProperties, MaterialSource};
pub use servo::{ServoProfile, ServoReport};
pub use thesis::{ThesisCoefficients, ThesisReport};

/// Joules in a kilowatt-hour.
pub const J_PER_KWH: f64 = 3.6e6;
/// Default grid emission factor, kg CO₂ per kWh (IEA world average, 2018).
pub const DEFAULT_GRID_KG_PER_KWH: f64 = 0.475;
/// Default ambient temperature, °C.
pub const DEFAULT_AMBIENT_C: f64 = 25.0;
/// Default share of the heater's extra energy that reaches the filament.
pub const DEFAULT_HEATER_EFFICIENCY: f64 = 0.9;
/// Machine preset whose X/Y drives are servos (the physical model is used for it by default).
pub const SERVO_PRESET: &str = "vtg-ldam-servo";

/// Which model gives `E_servo`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum ServoModel {
    /// The physical model for the servo preset (`vtg-ldam-servo`), the thesis model otherwise.
    #[default]
    Auto,
    /// The thesis stepper regression.
    Thesis,
    /// The physical servo model with [`EnergyOptions::servo`].
    Physical,
}

/// Energy and carbon figures (see [`crate::energy`] for the models, their units and sources).
///
/// `total_j = servo_j + fuse_j + aux_j` (VTG eq. 16); `co2_g` is VTG eq. 17.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Energy {
    /// X/Y stepper energy by the thesis model (thesis eq. 28), J. Always computed.
    pub thesis_j: f64,
    /// Energy of the X/Y drives, `E_servo`, J (equal to `thesis_j` with the thesis model).
    pub servo_j: f64,
    /// Model that gave `servo_j`: `thesis` or `physical`.
    pub servo_model: ServoModel,
    /// Heat to melt the filament, `E_fuse`, J.
    pub fuse_j: f64,
    /// Heaters, fans and electronics over the print, `E_aux`, J.
    pub aux_j: f64,
    /// `E = E_servo + E_fuse + E_aux`, J.
    pub total_j: f64,
    /// The same in kWh.
    pub total_kwh: f64,
    /// Material mass the fuse and carbon figures use, g.
    pub material_g: f64,
    /// Carbon emission `f_e·E + f_m·m`, g CO₂.
    pub co2_g: f64,
    /// The thesis terms `A`, `B`, `C`, `H` and the coefficients used.
    pub thesis: ThesisReport,
    /// The physical servo model's parts, when it gave `servo_j`.
    pub physical_servo: Option<ServoReport>,
    /// How `fuse_j` was computed.
    pub fuse: FuseReport,
    /// `aux_j` by system.
    pub aux: AuxReport,
    /// `co2_g` by source and the factors used.
    pub co2: Co2Report,
}

/// Settings of the energy models; every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct EnergyOptions {
    /// Coefficients of the thesis model (default: the published ones).
    // In TS any of them may be left out (the struct has serde defaults); the reports carry it whole.
    #[cfg_attr(test, ts(type = "Partial<ThesisCoefficients>"))]
    pub thesis: ThesisCoefficients,
    /// Model of the X/Y drives.
    pub servo_model: ServoModel,
    /// Parameters of the physical servo model.
    pub servo: ServoProfile,
    /// Material (default: the file's `filament_type`, else PLA).
    pub material: Option<Material>,
    /// Properties replacing the material's built-in ones.
    #[cfg_attr(test, ts(type = "Partial<MaterialProperties> | null"))]
    pub material_properties: Option<MaterialProperties>,
    /// Ambient temperature, °C.
    pub ambient_c: f64,
    /// Share of the heater's extra energy that reaches the filament, 0..=1.
    pub heater_efficiency: f64,
    /// Auxiliary powers.
    pub aux: AuxPowers,
    /// Grid emission factor, kg CO₂ per kWh.
    pub grid_kg_co2_per_kwh: f64,
    /// Material emission factor, kg CO₂ per kg (default: the material's).
    pub material_kg_co2_per_kg: Option<f64>,
}

impl Default for EnergyOptions {
    fn default() -> Self {
        Self {
            thesis: ThesisCoefficients::default(),
            servo_model: ServoModel::Auto,
            servo: ServoProfile::default(),
            material: None,
            material_properties: None,
            ambient_c: DEFAULT_AMBIENT_C,
            heater_efficiency: DEFAULT_HEATER_EFFICIENCY,
            aux: AuxPowers::default(),
            grid_kg_co2_per_kwh: DEFAULT_GRID_KG_PER_KWH,
            material_kg_co2_per_kg: None,
        }
    }
}

impl EnergyOptions {
    /// Checks ranges; the reason names the fields.
    pub fn validate(&self) -> Result<(), &'static str> {
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        if !self.thesis.is_finite() {
            return Err("energy.thesis coefficients must be finite");
        }
        if !self.servo.is_valid() {
            return Err("energy.servo: masses, forces and powers must be non-negative, efficiency in (0, 1], regeneration in [0, 1]");
        }
        if self.material_properties.is_some_and(|p| !p.is_valid()) {
            return Err("energy.material_properties: values must be finite and non-negative, crystallinity in [0, 1]");
        }
        let efficiency_ok = self.heater_efficiency > 0.0 && self.heater_efficiency <= 1.0;
        if !self.ambient_c.is_finite() || !efficiency_ok {
            return Err("energy.ambient_c must be finite and energy.heater_efficiency in (0, 1]");
        }
        if !self.aux.is_valid() {
            return Err("energy.aux: powers and heat capacities must be non-negative");
        }
        if !nonneg(self.grid_kg_co2_per_kwh) || !self.material_kg_co2_per_kg.is_none_or(nonneg) {
            return Err("energy emission factors must be non-negative");
        }
        Ok(())
    }
}

/// Emission figures (VTG eq. 17).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Co2Report {
    /// Grid factor used, kg CO₂ per kWh.
    pub grid_kg_per_kwh: f64,
    /// Material factor used, kg CO₂ per kg.
    pub material_kg_per_kg: f64,
    /// From electricity, g.
    pub energy_g: f64,
    /// From material, g.
    pub material_g: f64,
}

/// `m_CO₂ = f_e·E + f_m·m` (VTG eq. 17) in grams, from `energy_j` joules and `material_g` grams.
pub fn co2_g(energy_j: f64, material_g: f64, grid_kg_per_kwh: f64, material_kg_per_kg: f64) -> f64 {
    // kg/kWh × kWh = kg, × 1000 = g; kg/kg × g = g.
    grid_kg_per_kwh * energy_j / J_PER_KWH * 1000.0 + material_kg_per_kg * material_g
}

/// Per-move accumulation during the analysis pass, then the report.
#[derive(Debug, Clone)]
pub struct Accumulator {
    options: EnergyOptions,
    /// `Some` when `E_servo` comes from the physical model.
    physical: Option<ServoProfile>,
    terms: [f64; 4],
    accel_decel_s: f64,
    coast_s: f64,
    servo: ServoReport,
    material: Option<Material>,
}

impl Accumulator {
    /// An accumulator for a file planned with the machine profile `machine`.
    pub fn new(options: &EnergyOptions, machine: &str) -> Self {
        let physical = match options.servo_model {
            ServoModel::Physical => true,
            ServoModel::Thesis => false,
            ServoModel::Auto => machine == SERVO_PRESET,
        };
        Self {
            options: options.clone(),
            physical: physical.then_some(options.servo),
            terms: [0.0; 4],
            accel_decel_s: 0.0,
            coast_s: 0.0,
            servo: ServoReport::default(),
            material: None,
        }
    }

    /// A planned move; returns its `E_servo`, J.
    #[inline]
    pub fn planned(&mut self, pm: &PlannedMove) -> f64 {
        let (t, holds) = thesis::move_terms_and_holds(pm);
        for (acc, v) in self.terms.iter_mut().zip(t) {
            *acc += v;
        }
        let p = &pm.profile;
        let moving = 2.0 - holds;
        self.accel_decel_s += moving * (p.accel_s + p.decel_s);
        self.coast_s += moving * p.cruise_s;
        match &self.physical {
            None => self.options.thesis.energy_j(&t),
            Some(s) => s.add_move(pm, &mut self.servo),
        }
    }

    /// A dwell of `secs`; returns its `E_servo`, J.
    #[inline]
    pub fn dwell(&mut self, secs: f64) -> f64 {
        let t = thesis::dwell_terms(secs);
        self.terms[3] += t[3];
        match &self.physical {
            None => self.options.thesis.energy_j(&t),
            Some(s) => s.add_dwell(secs, &mut self.servo),
        }
    }

    /// The running sums (thesis terms, accelerating and coasting time, the physical servo
    /// energies), for carrying an accumulation from one wasm instance to another: the
    /// playground plans a file in a second worker and sends these back.
    pub fn running_sums(&self) -> [f64; 10] {
        let [a, b, c, h] = self.terms;
        let s = &self.servo;
        [
            a,
            b,
            c,
            h,
            self.accel_decel_s,
            self.coast_s,
            s.kinetic_j,
            s.friction_j,
            s.copper_j,
            s.standby_j,
        ]
    }

    /// Sets the running sums to those [`running_sums`](Self::running_sums) gave.
    pub fn set_running_sums(&mut self, sums: [f64; 10]) {
        let [a, b, c, h, accel_decel_s, coast_s, kinetic_j, friction_j, copper_j, standby_j] = sums;
        self.terms = [a, b, c, h];
        self.accel_decel_s = accel_decel_s;
        self.coast_s = coast_s;
        self.servo = ServoReport {
            kinetic_j,
            friction_j,
            copper_j,
            standby_j,
        };
    }

    /// The material the file names in its comments (`filament_type`), used unless the
    /// options name one.
    pub fn set_material_from_file(&mut self, material: Material) {
        self.material.get_or_insert(material);
    }

    /// The energy report for a print of `time_s` seconds laying `material_g` grams.
    pub fn finish(
        &self,
        time_s: f64,
        material_g: f64,
        temperatures: &[TemperatureEvent],
        fans: &[FanEvent],
    ) -> Energy {
        let o = &self.options;
        let [a, b, c, h] = self.terms;
        let e_wms = o.thesis.energy_wms(&self.terms);
        let thesis_j = e_wms * 1e-3;
        let (servo_j, servo_model, physical_servo) = match &self.physical {
            None => (thesis_j, ServoModel::Thesis, None),
            Some(_) => (self.servo.total_j(), ServoModel::Physical, Some(self.servo)),
        };
        let (material, material_source) = match (o.material, self.material) {
            (Some(m), _) => (m, MaterialSource::Option),
            (None, Some(m)) => (m, MaterialSource::File),
            (None, None) => (Material::Pla, MaterialSource::Default),
        };
        let properties = o
            .material_properties
            .unwrap_or_else(|| material.properties());
        let print_temp_c = temperatures
            .iter()
            .filter(|t| matches!(t.heater, Heater::Hotend(_)) && t.target_c > o.ambient_c)
            .map(|t| t.target_c)
            .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))))
            .unwrap_or(properties.print_temp_c);
        let material_g = material_g.max(0.0);
        let fuse_j = fuse::fuse_energy_j(
            material_g,
            &properties,
            print_temp_c,
            o.ambient_c,
            o.heater_efficiency,
        );
        let aux = auxiliary::aux_energy(&o.aux, o.ambient_c, temperatures, fans, time_s);
        let aux_j = aux.total_j();
        let total_j = servo_j + fuse_j + aux_j;
        let material_kg_per_kg = o.material_kg_co2_per_kg.unwrap_or(properties.co2_kg_per_kg);
        let co2 = Co2Report {
            grid_kg_per_kwh: o.grid_kg_co2_per_kwh,
            material_kg_per_kg,
            energy_g: co2_g(total_j, 0.0, o.grid_kg_co2_per_kwh, 0.0),
            material_g: co2_g(0.0, material_g, 0.0, material_kg_per_kg),
        };
        Energy {
            thesis_j,
            servo_j,
            servo_model,
            fuse_j,
            aux_j,
            total_j,
            total_kwh: total_j / J_PER_KWH,
            material_g,
            co2_g: co2.energy_g + co2.material_g,
            thesis: ThesisReport {
                a,
                b,
                c,
                h,
                coefficients: o.thesis,
                e_wms,
                accel_decel_s: self.accel_decel_s,
                coast_s: self.coast_s,
            },
            physical_servo,
            fuse: FuseReport {
                material,
                material_source,
                properties,
                print_temp_c,
                ambient_c: o.ambient_c,
                heater_efficiency: o.heater_efficiency,
            },
            aux,
            co2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn co2_by_hand() {
        // 3.6 MJ = 1 kWh at 0.475 kg/kWh: 475 g; 50 g of PLA at 2 kg/kg: 100 g.
        assert!((co2_g(3.6e6, 50.0, 0.475, 2.0) - 575.0).abs() < 1e-9);
    }

    #[test]
    fn options_round_trip_and_validate() {
        let o = EnergyOptions::default();
        assert!(o.validate().is_ok());
        let json = serde_json::to_string(&o).expect("json");
        let back: EnergyOptions = serde_json::from_str(&json).expect("parse");
        assert_eq!(back, o);
        let partial: EnergyOptions =
            serde_json::from_str(r#"{"material":"petg","thesis":{"k_h":0}}"#).expect("partial");
        assert_eq!(partial.material, Some(Material::Petg));
        assert_eq!(partial.thesis.k_c, ThesisCoefficients::PUBLISHED.k_c);
        assert_eq!(partial.thesis.k_h, 0.0);
        let bad = EnergyOptions {
            heater_efficiency: 0.0,
            ..EnergyOptions::default()
        };
        assert!(bad.validate().is_err());
    }
}
