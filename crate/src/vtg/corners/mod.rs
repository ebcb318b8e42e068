//! Replacements for sharp corners. Each kind proposes the points that stand for the stretch
//! around one or two corners, and says what it costs; `search::smooth` chooses among them.
//!
//! | kind | proposes | its cost, as the search weighs it |
//! |---|---|---|
//! | `blend` | a fillet tangent to the legs, or the racing line out and back (`Blend`, per vertex) | its peak curvature: the machine runs it at `√(a/κ)`, against the original's speed at the corner (`smooth::pays`) |
//! | `hairpin` | one arc for two corners across a short leg (`Hairpin`, 2 corners) | its radius, likewise |
//! | `keyhole` | a loop round a corner too tight to fillet (`Hairpin`, 1 corner) | the loop's radius, likewise, and its deviation both ways |
//! | `klipper` | a polygon placed for Klipper's look-ahead (`Corner`, its `pin` a `Hairpin`) | the slowest planned speed through it against the sharp corner's |
//! | `arcs` | runs of new points on a circle as `G2`/`G3` (not a corner: any rewritten path) | its planned time and energy against the lines' (`rewrite::with_arcs`) |
//!
//! Every replacement but the fillet is a `Hairpin`: points between where it leaves the path
//! and where it rejoins it, spliced in by `hairpin::substitute` before the fit.

pub(crate) mod arcs;
pub(crate) mod blend;
pub(crate) mod hairpin;
pub(crate) mod keyhole;
pub(crate) mod klipper;
