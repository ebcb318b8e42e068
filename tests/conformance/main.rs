//! The conformance suite: quietpath against the real corpus (`../shared/corpus`), Klipper's
//! own planner and the slicers' estimates, one module per concern.
//!
//! One test binary, not one per module: each is linked with thin LTO in release (`make test`
//! runs the suite there), about 13 s a link on the 2-core reference machine, and one pool of
//! test threads then runs the Klipper oracle's runs beside the VTG ones instead of after them.
//! `cargo test --release -p quietpath-conformance vtg:: -- --nocapture` runs one module.

mod corpus;
mod dynamics;
mod feeds;
mod infill;
mod klipper;
mod orient;
mod slicer_times;
mod vtg;
