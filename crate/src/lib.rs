//! # quietpath
//!
//! Quieter, cheaper 3D-printer toolpaths. quietpath reads real G-code from every common slicer,
//! models how the machine moves, vibrates and spends energy, and rewrites the toolpath to
//! suppress vibration and save energy.
//!
//! The crate is one core with thin front ends: the `quietpath` command-line tool (native, behind
//! the default `cli` feature) and a WebAssembly binding (`wasm` module, compiled only for
//! `wasm32`). Both return the same serde types, so a report is the same JSON wherever it comes
//! from. A library user who does not want the command line's dependencies turns the default
//! features off:
//!
//! ```toml
//! [dependencies]
//! quietpath = { version = "0.1", default-features = false }
//! ```
//!
//! Every entry point takes the file as bytes and an options struct whose `Default` is what the
//! command line does without flags; errors are [`Error`]s with a line and column. How each
//! capability works, with the equations of the papers it follows, is in the repository's
//! `docs/method/`.
//!
//! ## Analyze: time, filament, energy, layers
//!
//! [`analyze()`] reads the file in one streaming pass through a firmware-faithful motion planner
//! and the energy models ([`Report`]).
//!
//! ```
//! let gcode = b"G21\nG90\nM83\nG1 X10 Y0 E0.5 F1200\nG1 X10 Y10 E0.5\n";
//! let report = quietpath::analyze(gcode, &Default::default()).unwrap();
//! assert_eq!(report.moves, 2);
//! assert!((report.filament_mm - 1.0).abs() < 1e-12);
//! assert!((report.distance_mm - 20.0).abs() < 1e-12);
//! assert!(report.time_s > 1.0); // 20 mm at 20 mm/s, plus acceleration
//! ```
//!
//! ## Path extraction: every move with its layer, feature and timing
//!
//! [`path::extract`] keeps every move of the file; with `plan = true` each gets the planner's
//! start time, duration and speed profile.
//!
//! ```
//! let gcode = b";LAYER_CHANGE\n;Z:0.2\nG1 Z0.2 F600\n;TYPE:External perimeter\n\
//!               M83\nG1 X20 Y0 E1 F1800\nG1 X20 Y20 E1\n";
//! let path = quietpath::path::extract(gcode, &Default::default(), true).unwrap();
//! assert_eq!(path.moves.len(), 3);
//! let last = path.moves.last().unwrap();
//! assert_eq!(last.line, 7);
//! let timing = last.timing.unwrap();
//! assert!((timing.start_s + timing.duration_s - path.time_s).abs() < 1e-9);
//! ```
//!
//! ## Energy: the thesis stepper model, calibration, CO₂
//!
//! Every report carries the energy of the print ([`analyze::Energy`]: stepper or servo, melting,
//! heaters and fans, CO₂). [`energy::fit`] calibrates the thesis model's coefficients from
//! measured energies (ordinary least squares without intercept, as `quietpath calibrate`).
//!
//! ```
//! use quietpath::energy::{fit, Observation};
//!
//! let gcode = b"M83\nG1 X50 Y0 E2 F3000\nG1 X50 Y30 E1\n";
//! let report = quietpath::analyze(gcode, &Default::default()).unwrap();
//! let e = &report.energy;
//! assert!(e.thesis_j > 0.0 && e.total_j >= e.servo_j + e.fuse_j);
//!
//! // Rows generated from known coefficients come back exactly.
//! let k = [0.13, 0.12, 70.0, 800.0];
//! let rows: Vec<Observation> = (1..=8)
//!     .map(|i| {
//!         let x = i as f64;
//!         let (a, b, c, h) = (1e4 * x, 3e3 * x * x, x * x * x, 9.0 - x);
//!         let e = k[0] * a + k[1] * b + k[2] * c + k[3] * h;
//!         Observation { row: i, a, b, c, h, e }
//!     })
//!     .collect();
//! let fit = fit(&rows).unwrap();
//! assert!((fit.k_c - 70.0).abs() < 1e-6 && fit.r2 > 0.999_999);
//! ```
//!
//! ## Dynamics and vibration
//!
//! [`dynamics::vibration`] simulates the X and Y drives (a lumped-mass model after the VTG
//! paper) along the planned motion: natural frequencies, the deviation of the table from the
//! commanded path, per-layer amplitude and the acceleration spectrum.
//!
//! ```
//! use quietpath::dynamics::{vibration, VibrationOptions};
//!
//! let gcode = b"M83\nG1 X20 Y0 E1 F3000\nG1 X20 Y20 E1\nG1 X0 Y20 E1\nG1 X0 Y0 E1\n";
//! let report = vibration(gcode, &VibrationOptions::default()).unwrap();
//! assert!(!report.natural_frequencies_hz.is_empty());
//! assert!(report.deviation_mm.max >= report.deviation_mm.mean);
//! ```
//!
//! ## Vibration-suppressed toolpaths (VTG)
//!
//! [`vtg::vtg`] rounds the sharp corners of the printing paths within a tolerance and rewrites
//! the file; the report compares the two (the VTG paper's Tables 1 and 2).
//!
//! ```
//! use quietpath::vtg::{vtg, VtgOptions};
//!
//! let mut gcode = String::from("M83\n;TYPE:External perimeter\nG1 X0 Y0 F3000\n");
//! for _ in 0..3 {
//!     gcode.push_str("G1 X20 Y0 E1\nG1 X20 Y20 E1\nG1 X0 Y20 E1\nG1 X0 Y0 E1\n");
//! }
//! // Rounding a square's corners takes more lines than its four vertices: allowed here. By
//! // default the file gains no lines, and corners that would add them stay sharp.
//! let options = VtgOptions {
//!     tolerance_mm: 0.1,
//!     dynamics: false,
//!     allow_more_lines_pct: 1000.0,
//!     ..Default::default()
//! };
//! let report = vtg(gcode.as_bytes(), &options).unwrap();
//! assert!(report.max_deviation_mm <= 0.1);
//! assert!(report.table1.n_turning.after < report.table1.n_turning.before);
//! assert!(!report.output.is_empty()); // the rewritten G-code
//! ```
//!
//! ## Infill regeneration
//!
//! [`infill::infill`] replaces the sparse infill with other patterns, angles and part
//! rotations, costs every candidate on the whole file and keeps the cheapest.
//!
//! ```
//! use quietpath::infill::{infill, InfillOptions, Pattern};
//!
//! // Five layers of a 20 mm square: an outer wall and rectilinear infill along X.
//! let mut g = String::from("M83\nG21\nG90\n");
//! for layer in 1..=5 {
//!     let z = 0.2 * layer as f64;
//!     g += &format!(";LAYER_CHANGE\n;Z:{z:.1}\nG1 Z{z:.1} F600\n;TYPE:External perimeter\n");
//!     g += "G0 X0 Y0 F6000\nG1 X20 Y0 E0.8 F1800\nG1 X20 Y20 E0.8\nG1 X0 Y20 E0.8\nG1 X0 Y0 E0.8\n";
//!     g += ";TYPE:Internal infill\n";
//!     for i in 0..9 {
//!         let y = 2.0 + 2.0 * i as f64;
//!         let (x0, x1) = if i % 2 == 0 { (0.5, 19.5) } else { (19.5, 0.5) };
//!         g += &format!("G0 X{x0} Y{y}\nG1 X{x1} Y{y} E0.76\n");
//!     }
//! }
//! let options = InfillOptions {
//!     patterns: vec![Pattern::Rectilinear, Pattern::Concentric],
//!     angles_deg: vec![0.0, 90.0],
//!     ..Default::default()
//! };
//! let report = infill(g.as_bytes(), &options).unwrap();
//! assert_eq!(report.candidates.len(), 4);
//! assert!(report.candidates.iter().all(|c| report.best.total_j <= c.total_j + 1e-9));
//! ```
//!
//! ## Tool-orientation smoothing (multi-axis)
//!
//! [`orient::smooth`] smooths the tool vectors of multi-axis G-code within a tolerance cone
//! (after the CIRP 2022 paper); [`orient::smooth_points`] does the same on point-vector data.
//!
//! ```
//! use quietpath::orient::{smooth_points, PointVector, SmoothOptions};
//!
//! // A straight path whose tool vector wobbles by ±5°.
//! let points: Vec<PointVector> = (0..60)
//!     .map(|n| {
//!         let tilt = if n % 2 == 0 { 0.087 } else { -0.087 };
//!         PointVector { x: n as f64, y: 0.0, z: 0.0, i: tilt, j: 0.0, k: 1.0, path: 0 }
//!     })
//!     .collect();
//! let (report, smoothed) = smooth_points(&points, &SmoothOptions::default()).unwrap();
//! assert_eq!(smoothed.len(), points.len());
//! assert!(report.after.roughness < report.before.roughness);
//! assert!(report.max_angle_to_original_deg <= 30.0); // half the default 60° cone
//! ```
//!
//! ## Modules
//!
//! - [`gcode`]: zero-copy lines and words, slicer dialects, lossless writing.
//! - [`machine`]: modal printer state, arcs, extrusion modes; turns lines into motion events.
//! - [`analyze`](mod@analyze): one streaming pass giving the report.
//! - [`plan`]: firmware-style motion planning (trapezoids, junctions, look-ahead).
//! - [`energy`]: energy (thesis stepper model, VTG servo/fuse/aux model) and CO₂.
//! - [`path`]: every move of a file with its layer, feature and planned timing.
//! - [`dynamics`]: lumped-mass axis model, trajectory deviation, vibration spectra.
//! - [`vtg`]: vibration-suppressed toolpath generation.
//! - [`infill`]: infill regeneration and the energy-driven search.
//! - [`orient`]: tool-orientation smoothing for multi-axis toolpaths.
//! - [`math`]: portable transcendental functions (identical results native and wasm).
//! - [`vec3`]: 3-vector helpers shared by [`vtg`] and [`orient`].
//! - [`progress`]: the progress callback every long job takes.

// No unsafe code in the library, whatever the workspace allows its binary.
#![forbid(unsafe_code)]

pub mod analyze;
pub mod dynamics;
pub mod energy;
pub mod error;
pub mod estimate;
pub mod gcode;
pub mod infill;
pub mod machine;
pub mod math;
pub mod optimize;
pub mod orient;
pub mod parallel;
pub mod path;
pub mod plan;
pub mod progress;
pub mod read;
pub mod vec3;
pub mod vtg;

// The TypeScript declarations of the JS boundary's serde types, rendered and checked in a test.
#[cfg(all(test, not(target_arch = "wasm32")))]
mod ts_types;

#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use analyze::{analyze, AnalyzeOptions, Report};
pub use error::{Error, ErrorKind, Warning};

/// The crate version, reported in every report.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
