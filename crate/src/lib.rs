//! # quietpath
//!
//! Quieter, cheaper 3D-printer toolpaths. quietpath reads real G-code from every common slicer,
//! models how the machine moves and how much energy it spends, and rewrites the toolpath to
//! suppress vibration and save energy.
//!
//! The crate is one core with thin front ends: the `quietpath` command-line tool (native) and a
//! WebAssembly binding (`wasm` module, compiled only for `wasm32`). Both return the same
//! serde types, so a report is the same JSON wherever it comes from.
//!
//! ```
//! let gcode = b"G21\nG90\nM83\nG1 X10 Y0 E0.5 F1200\nG1 X10 Y10 E0.5\n";
//! let report = quietpath::analyze::analyze(gcode, &Default::default()).unwrap();
//! assert_eq!(report.moves, 2);
//! assert!((report.filament_mm - 1.0).abs() < 1e-12);
//! assert!((report.distance_mm - 20.0).abs() < 1e-12);
//! ```
//!
//! Modules:
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

pub mod analyze;
pub mod dynamics;
pub mod energy;
pub mod error;
pub mod gcode;
pub mod infill;
pub mod machine;
pub mod math;
pub mod orient;
pub mod parallel;
pub mod path;
pub mod plan;
pub mod progress;
pub mod vec3;
// The rewriter keeps its points in slices and hands them to `vec3` by reference, which the
// helpers take as well as values (`impl Borrow<V3>`).
#[allow(clippy::needless_borrows_for_generic_args)]
pub mod vtg;

#[cfg(target_arch = "wasm32")]
pub mod wasm;

pub use analyze::{analyze, AnalyzeOptions, Report};
pub use error::{Error, ErrorKind, Warning};

/// The crate version, reported in every report.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
