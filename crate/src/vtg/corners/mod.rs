//! Replacements for sharp corners, behind one interface: each kind ([`CornerKind`]) is asked
//! about a corner of a path, proposes what stands for it and says what that costs
//! ([`Proposal`]); `search::smooth` asks the kinds in its order and takes what it accepts.
//!
//! | kind | asked about | proposes ([`Replacement`]) | its cost ([`Cost`]), as the search weighs it |
//! |---|---|---|---|
//! | `blend::Fillets` | every sharp corner, first | a fillet tangent to the legs, or the racing line out and back (`Fillet`: the `Blend` that `blend::plan` lays out at the vertex); none where it cannot be walked in steps under the critical angle (the corner is then *tight*) | its peak curvature: the machine runs it at `√(a/κ)`, against the original's speed at the corner; a corner whose fillet is accepted is rounded alone |
//! | `klipper::Polygons` | on a Klipper path with planned speeds, first of all: each sharp corner whose fillet is not accepted at no loss of speed | a polygon placed for Klipper's look-ahead, written as it is (`Written`) | the slowest planned speed through it against the sharp corner's, at least `Settings::min_speed_share` of it |
//! | `arc_hairpin::ArcHairpins` | where arcs are written and the firmware cuts a hairpin's arc into chords under the walk's turn: two sharp corners across a short connector | one arc for the two (`Written`, 2 corners), written as one `G2`/`G3` in place of the connector | not weighed: the rewrite's planned time and energy decide |
//! | `hairpin::Hairpins` | two sharp corners across a short leg that are not both rounded alone | one arc for the two (`Fitted`, 2 corners), sought again within the smaller blend share of a retry | not weighed: taken wherever it fits |
//! | `keyhole::Keyholes` | a tight corner not already replaced, where keyholes are on | a loop round it (`Fitted`, 1 corner) | the loop's curvature (its radius is always the smallest the walk follows, so the cost is known before the loop is sought), likewise |
//!
//! `arcs` is not a corner kind: it writes runs of new points on a circle as `G2`/`G3` on any
//! rewritten path, weighed by its planned time and energy against the lines'
//! (`rewrite::with_arcs`).
//!
//! Every replacement but the fillet is a `Hairpin`: points between where it leaves the path
//! and where it rejoins it, spliced in by `hairpin::substitute` before the fit.

pub(crate) mod arc_hairpin;
pub(crate) mod arcs;
pub(crate) mod blend;
pub(crate) mod hairpin;
pub(crate) mod keyhole;
pub(crate) mod klipper;

use crate::vtg::smooth::{Settings, SmoothPath};
use hairpin::Hairpin;

/// One way of replacing sharp corners. The search asks it about the corners of a path in
/// turn; it proposes a replacement and says what it costs, and the search decides.
pub(crate) trait CornerKind {
    /// Whether the kind has anything to propose on `path` at all (by default it has): the
    /// search asks a kind about no corner of a path it does not apply to.
    fn applies(&self, _path: &SmoothPath<'_>, _s: &Settings) -> bool {
        true
    }

    /// Whether its replacements stand for what they replace without a line more (by default
    /// they add lines): asked in a path's lean rewrite ([`crate::vtg::smooth::Settings::lean`]).
    fn adds_no_lines(&self) -> bool {
        false
    }

    /// Whether the search asks about corner `i` of `site` at all, given what it has decided of
    /// the path's corners so far.
    fn asks_about(&self, site: &Site<'_>, i: usize) -> bool;

    /// What every proposal of this kind costs, where that is known before one is sought (the
    /// search then seeks none it would not take); `None` by default.
    fn known_cost(&self, _s: &Settings) -> Option<Cost> {
        None
    }

    /// The replacement for corner `i` of `site` (the first of the two, for a kind that replaces
    /// two), and what it costs; `None` where none fits.
    fn propose(&self, site: &Site<'_>, i: usize) -> Option<Proposal>;

    /// A replacement this kind proposed, on a retry with the blends within the smaller
    /// `blend_tol_mm`: sought again, or kept as it is (the default); `None`: none fits now.
    fn again(
        &self,
        _pts: &[[f64; 3]],
        pin: &Hairpin,
        _blend_tol_mm: f64,
        _s: &Settings,
    ) -> Option<Hairpin> {
        Some(pin.clone())
    }
}

/// What a kind proposes for a corner: the replacement and what it costs.
#[derive(Debug, Clone)]
pub(crate) struct Proposal {
    pub(crate) replacement: Replacement,
    pub(crate) cost: Cost,
}

/// What stands for a corner in the new path.
#[derive(Debug, Clone)]
pub(crate) enum Replacement {
    /// The fillet or racing line `blend::plan` laid out at the vertex, which the fit follows.
    Fillet,
    /// Points spliced in between where the path leaves and rejoins it
    /// ([`hairpin::substitute`]), then blended and fitted with the rest of the path.
    Fitted(Hairpin),
    /// Points spliced in and written as they are, and their measured largest distance from
    /// the original, both ways, mm.
    Written(Hairpin, f64),
}

/// What a replacement costs, in the terms the search weighs it in (`smooth::accepts`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Cost {
    /// Run round a curve of this peak curvature, 1/mm: a junction-deviation or Klipper planner
    /// holds it to `√(a/κ)`, weighed against the firmware's speed through the sharp corner.
    Curvature(f64),
    /// Planned through by Klipper's look-ahead no faster than `slowest_mm_s`, against
    /// `sharp_mm_s` through the sharp corner (the same model), mm/s.
    Planned { slowest_mm_s: f64, sharp_mm_s: f64 },
    /// Not weighed: taken wherever it fits.
    Unweighed,
}

/// A path as the kinds see it when asked about one of its corners.
#[derive(Clone, Copy)]
pub(crate) struct Site<'a> {
    /// The path.
    pub(crate) path: &'a SmoothPath<'a>,
    /// Arc length at each of its points, mm.
    pub(crate) arc: &'a [f64],
    /// What it is rewritten with.
    pub(crate) settings: &'a Settings,
    /// What the search has decided of each of its corners so far.
    pub(crate) marks: &'a Marks,
    /// The deviation a replacement that is blended and fitted may use, mm (the blend share of
    /// the tolerance).
    pub(crate) blend_tol_mm: f64,
}

/// What each point of a path is as a corner, as the search has decided so far; kept in one
/// place because the kinds and the cuts all read (and the cuts clear) the same flags.
#[derive(Debug, Clone)]
pub(crate) struct Marks {
    /// A turn above the critical angle.
    pub(crate) sharp: Vec<bool>,
    /// Can be rounded on its own, at a cost the search accepts.
    pub(crate) alone: Vec<bool>,
    /// A zero-length leg meets it.
    pub(crate) degenerate: Vec<bool>,
    /// Too tight to round within the tolerance (rather than not worth it).
    pub(crate) tight: Vec<bool>,
    /// Replaced by a kind's proposal.
    pub(crate) pinned: Vec<bool>,
}
