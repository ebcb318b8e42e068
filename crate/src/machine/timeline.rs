//! The print's timeline of heater targets and fan speeds, as the report lists it and the
//! auxiliary energy model ([`crate::energy::auxiliary`]) integrates it.

use serde::Serialize;

use super::Heater;

/// A heater target set at some point of the print.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct TemperatureEvent {
    /// 1-based line.
    pub line: u32,
    /// Print time at that line, s.
    pub time_s: f64,
    /// Which heater.
    pub heater: Heater,
    /// Target, °C.
    pub target_c: f64,
    /// Whether the printer waits for it.
    pub wait: bool,
}

/// A fan speed set at some point of the print.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct FanEvent {
    /// 1-based line.
    pub line: u32,
    /// Print time at that line, s.
    pub time_s: f64,
    /// Fan index.
    pub index: u16,
    /// Speed, 0..=1.
    pub speed: f64,
}
