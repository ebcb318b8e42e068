//! The values that tune the rewrite, in one place: each trades one good against another, and
//! [`TUNING`] holds the ones every output is made with. The measurements behind them are in
//! `docs/method/vtg-tuning-notes.md`. What stays a `const` beside its code is either a
//! definition (the paper's critical angle, a cubic B-spline, what counts as a hairpin or a
//! straight vertex) or the resolution of a search (centres, bisections, samples), which buys
//! accuracy with run time only.

/// The tuning of the rewrite; [`Tuning::default`] gives [`TUNING`], today's values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tuning {
    // The tolerance shared between the stages (VTG eq. 21–28).
    /// Share of the tolerance the corner blends may use. More makes wider fillets, which the
    /// machine runs faster (`√(a r)`); less leaves room to the fit and the walk, so fewer paths
    /// are tried again with smaller blends. With the next two it adds up to more than the whole
    /// tolerance on purpose: the three seldom peak at one point, and the measured check
    /// catches the paths where they do.
    pub(crate) blend_share: f64,
    /// Share of the tolerance the fit's residuals may use: more fits with fewer knots, less
    /// keeps more for the blends (the blended data are smooth, so a small share does).
    pub(crate) fit_share: f64,
    /// Share of the tolerance the walk's chords may sag: more allows longer steps on gentle
    /// curves. In a fillet the turn per step binds first (a step turning by φ on radius `r` sags
    /// `r (1 − cos(φ/2))`, 0.03 r at 27°), so little is needed.
    pub(crate) chord_share: f64,
    /// Tries of a path whose measured deviation exceeds the tolerance, each with smaller
    /// blends: more rounds more paths, at the cost of run time.
    pub(crate) attempts: usize,
    /// Blend size of a retry relative to the try before: nearer 1 gives up less corner speed
    /// per retry but needs more of them.
    pub(crate) retry_scale: f64,
    /// Share of a leg the blends at its two ends may use together: more gives wider blends,
    /// less keeps a straight stretch where the fit sees one blend end and the next begin.
    pub(crate) leg_share: f64,
    /// Longest gap between the fit's data points on straight runs, mm: shorter holds straights
    /// straighter, at more knots to fit.
    pub(crate) straight_spacing_mm: f64,
    // Algorithm 1 and the firmware's segments.
    /// Largest turn of one interpolation step, as a share of the critical angle: nearer 1
    /// gives fewer, longer steps, each closer to counting as a sharp turn itself.
    pub(crate) step_turn_share: f64,
    /// Largest counter-turn where a keyhole leaves or rejoins the path, as a share of the
    /// critical angle: more admits more loops, each with a sharper kink (below the walk's share:
    /// the leg itself may bend a little there).
    pub(crate) kink_share: f64,
    /// Shortest interpolation step on firmware that plans every segment (Klipper), mm: shorter
    /// follows tight curves more closely, but the written coordinates' rounding (0.001 mm) then
    /// turns each segment's direction more.
    pub(crate) klipper_min_step_mm: f64,
    /// Shortest interpolation step on Marlin and Prusa firmware, mm: they fold a block of fewer
    /// than 6 steps (or of at most 5 segments) into the next, anything under 0.05–0.075 mm at
    /// 80–100 steps/mm, which would turn twice as much as written.
    pub(crate) marlin_min_step_mm: f64,
    // Corners the fillet cannot round well.
    /// Shares of the tolerance tried as the racing line's offset, largest first: a wider offset
    /// gives a wider circle, and needs more room on the legs.
    pub(crate) racing_offset_shares: [f64; 3],
    /// Peak curvature of a ramp out to the racing line, as a share of the fillet's: lower makes
    /// gentler, longer ramps that need more room (low, since the machine is still fast there).
    pub(crate) ramp_curvature_share: f64,
    /// Longest connector between the two corners of a hairpin, mm: longer turns more corner
    /// pairs into one arc, each straying further from the connector.
    pub(crate) hairpin_max_connector_mm: f64,
    /// Turn of one side of the polygon that stands for a hairpin's arc or a keyhole's circle:
    /// smaller follows the circle more closely in more lines (15°: its sagitta is 0.009 r, and
    /// the blends at its corners round it back towards the circle).
    pub(crate) polygon_turn_rad: f64,
    /// Share of the tolerance a Klipper polygon corner is sized for: the rest absorbs the
    /// rounding of written coordinates and the sampling of the check.
    pub(crate) corner_tolerance_share: f64,
    /// Share of the tolerance within which a run of new points must lie on a circle to be
    /// written as an arc: more writes more arcs, each further from the points it replaces.
    pub(crate) arc_share: f64,
    /// Smallest arc radius written, mm: smaller writes more arcs, but the centre (4 decimals)
    /// and end (3) as written then miss the circle by more than firmware accepts.
    pub(crate) arc_min_radius_mm: f64,
    /// Largest arc radius written, mm: flatter runs are straight enough as lines.
    pub(crate) arc_max_radius_mm: f64,
    /// Largest spread of the feed rates one arc joins (it takes the lowest): more writes longer
    /// arcs, slowing their faster parts.
    pub(crate) arc_feed_spread: f64,
    /// Share of the tolerance a path without sharp corners may stray from its own points when
    /// its runs on a circle are written as arcs to save lines (`search::compact`): more
    /// finds more arcs in coarsely sliced curves. At the default 0.1 mm tolerance, 0.25 is
    /// ArcWelder's default resolution of 0.05 mm (± 0.025 mm).
    pub(crate) compact_share: f64,
    // Fit and feed (VTG eq. 29).
    /// Data points per knot span in the first fit: fewer spans fit faster, more need fewer
    /// refinement rounds.
    pub(crate) points_per_span: f64,
    /// Weight of the penalty on the curve's second derivative: it only makes the normal
    /// equations definite where a span holds no data; larger would bend the fit from the data.
    pub(crate) fit_penalty: f64,
    /// Refinement rounds of the fit (each inserts a knot in every span that misses the
    /// tolerance): more fits more paths, at more run time.
    pub(crate) fit_rounds: usize,
    /// Share of the jerk limit a rising feed may step by from one piece to the next on
    /// classic-jerk firmware: the rest is left for the change of direction at the junction.
    pub(crate) ramp_jerk_share: f64,
    /// Shortest ramp piece, mm: shorter ramps more smoothly, in more lines.
    pub(crate) min_ramp_piece_mm: f64,
    // The search.
    /// Scales of the VTG eq. 29 speeds tried in turn until a rewrite costs no time (`None`: no
    /// caps): each step trades a little vibration suppression for speed.
    pub(crate) cap_scales: [Option<f64>; 8],
    /// The dearer variants offered for a path when time may be spent, as the slowest a rounded
    /// corner may be run against the sharp one: more rungs let the budget buy a path's cheap
    /// corners without its dear ones, at more run time.
    pub(crate) dearer_speed_shares: [f64; 2],
    /// Share of what the free rewrites saved (time and motor energy, each) that the dearer
    /// ones may spend: the file still prints faster and on less energy by the rest.
    pub(crate) spend_share: f64,
    /// Weight of a joule against a second when time is allowed, as a share of the time the
    /// print takes to spend one: more buys the corners that save energy first, fewer corners
    /// in all. Only the order of the purchases depends on it.
    pub(crate) energy_weight: f64,
    /// Choices made against the whole file's measured time before giving up the allowance:
    /// more keeps more of it, at one analysis of the file each.
    pub(crate) time_rounds: usize,
    /// Each round cuts the allowance by this many times the excess measured: more meets the
    /// allowance in fewer rounds, spending less of it.
    pub(crate) time_margin: f64,
    /// Scales of the VTG eq. 29 speeds a whole file is rewritten with, in turn, where the dynamics
    /// model finds it ringing more than the original (then the same without keyhole loops):
    /// more scales find a quieter rewrite more often, at one rewrite each.
    pub(crate) quieter_scales: [f64; 3],
}

/// The tuning every rewrite is made with.
pub(crate) const TUNING: Tuning = Tuning {
    blend_share: 0.9,
    fit_share: 0.1,
    chord_share: 0.09,
    attempts: 4,
    retry_scale: 0.7,
    leg_share: 0.9,
    straight_spacing_mm: 3.0,
    step_turn_share: 0.9,
    kink_share: 0.8,
    klipper_min_step_mm: 0.03,
    marlin_min_step_mm: 0.06,
    racing_offset_shares: [1.0, 0.5, 0.25],
    ramp_curvature_share: 0.15,
    hairpin_max_connector_mm: 2.0,
    polygon_turn_rad: 15.0 * std::f64::consts::PI / 180.0,
    corner_tolerance_share: 0.97,
    arc_share: 0.05,
    arc_min_radius_mm: 0.2,
    arc_max_radius_mm: 500.0,
    arc_feed_spread: 1.05,
    compact_share: 0.25,
    points_per_span: 2.5,
    fit_penalty: 1e-3,
    fit_rounds: 6,
    ramp_jerk_share: 0.7,
    min_ramp_piece_mm: 0.02,
    cap_scales: [
        Some(1.0),
        Some(1.2),
        Some(1.44),
        Some(1.73),
        Some(2.07),
        Some(2.5),
        Some(3.0),
        None,
    ],
    dearer_speed_shares: [0.8, 0.0],
    spend_share: 0.5,
    energy_weight: 0.5,
    time_rounds: 4,
    time_margin: 1.2,
    quieter_scales: [1.0, 1.5, 2.0],
};

impl Default for Tuning {
    fn default() -> Self {
        TUNING
    }
}
