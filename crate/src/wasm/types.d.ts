// ── quietpath result and option types (the serde form of the Rust types; the same JSON as the
// CLI's --json). Checked against real CLI output by tests/js/types.test.mjs. ──

/** Where a machine limit came from, in order of precedence. */
export type LimitSource = "command" | "slicer_settings" | "printer_config" | "machine_settings" | "profile" | "option";
export interface Limit { value: number; source: LimitSource }
export type JunctionModel = "classic_jerk" | "junction_deviation" | "klipper";
/** Machine limits; arrays are per axis X, Y, Z, E. */
export interface Limits {
  max_feedrate: Limit[];
  max_acceleration: Limit[];
  acceleration: Limit;
  retract_acceleration: Limit;
  travel_acceleration: Limit;
  max_jerk: Limit[];
  junction_deviation: Limit;
  square_corner_velocity: Limit;
  minimum_cruise_ratio: Limit;
  /** Older Klipper's max_accel_to_decel, mm/s²; 0 when minimum_cruise_ratio applies. */
  accel_to_decel: Limit;
  min_feedrate: Limit;
  min_travel_feedrate: Limit;
  arc_segment_mm: Limit;
  /** Klipper's [extruder] instantaneous_corner_velocity, mm/s; absent: Klipper's 1 mm/s. */
  instantaneous_corner_velocity?: Limit;
}
export interface MachineProfile {
  name: string;
  description?: string;
  junction: JunctionModel;
  limits: Limits;
  [key: string]: unknown;
}
export type Material = "pla" | "petg" | "abs";
export interface MaterialProperties {
  specific_heat_j_gk: number;
  heat_of_fusion_j_g: number;
  crystallinity: number;
  print_temp_c: number;
  co2_kg_per_kg: number;
}
export interface ThesisCoefficients { k_a_mx: number; k_a_my: number; k_c: number; k_h: number }
/** Energy settings; every field optional (defaults are documented in the README). */
export interface EnergyOptions {
  thesis?: Partial<ThesisCoefficients>;
  servo_model?: "auto" | "thesis" | "physical";
  servo?: Record<string, unknown>;
  material?: Material | null;
  material_properties?: Partial<MaterialProperties> | null;
  ambient_c?: number;
  heater_efficiency?: number;
  aux?: Record<string, number>;
  grid_kg_co2_per_kwh?: number;
  material_kg_co2_per_kg?: number | null;
}
/** Options of analyze (and of every job that plans a file). */
export interface AnalyzeOptions {
  strict?: boolean;
  filament_diameter_mm?: number | null;
  density_g_cm3?: number | null;
  extrusion_mode?: "absolute" | "relative" | null;
  machine?: string | null;
  machine_profile?: MachineProfile | null;
  junction_model?: JunctionModel | null;
  arc_segment_mm?: number | null;
  energy?: EnergyOptions | null;
  /** The printer's Klipper config: the text of its printer.cfg (includes pasted in place). */
  klipper_config?: string | null;
  /** How that Klipper reads max_accel_to_decel (default "current"). */
  klipper_version?: "legacy" | "current" | null;
  /** A Marlin printer's own settings as its M503 prints them (M201, M203, M204, M205…), applied before the file; not with klipper_config. */
  machine_gcode?: string | null;
}
export interface Warning { line: number; message: string }
export type FeatureKind =
  | "outer_wall" | "inner_wall" | "sparse_infill" | "solid_infill" | "bridge"
  | "gap_fill" | "support" | "adhesion" | "other";
export interface FeatureSummary {
  name: string;
  kind: FeatureKind | null;
  moves: number;
  distance_mm: number;
  filament_mm: number;
  time_s: number;
  energy_j: number;
}
export interface LayerSummary {
  index: number;
  z: number | null;
  line: number;
  moves: number;
  extrude_distance_mm: number;
  travel_distance_mm: number;
  filament_mm: number;
  time_s: number;
  energy_j: number;
}
export type Heater = { hotend: number } | "bed" | "chamber";
export interface TemperatureEvent { line: number; time_s: number; heater: Heater; target_c: number; wait: boolean }
export interface FanEvent { line: number; time_s: number; index: number; speed: number }
export interface ThesisReport {
  a: number; b: number; c: number; h: number;
  coefficients: ThesisCoefficients;
  e_wms: number;
  accel_decel_s: number;
  coast_s: number;
}
export interface ServoReport { kinetic_j: number; friction_j: number; copper_j: number; standby_j: number; [key: string]: number }
export interface Energy {
  thesis_j: number;
  servo_j: number;
  servo_model: "auto" | "thesis" | "physical";
  fuse_j: number;
  aux_j: number;
  total_j: number;
  total_kwh: number;
  material_g: number;
  co2_g: number;
  thesis: ThesisReport;
  physical_servo: ServoReport | null;
  fuse: {
    material: Material;
    material_source: "option" | "file" | "default";
    properties: MaterialProperties;
    print_temp_c: number;
    ambient_c: number;
    heater_efficiency: number;
  };
  aux: { bed_j: number; hotend_j: number; chamber_j: number; heat_up_j: number; fan_j: number; electronics_j: number };
  co2: { grid_kg_per_kwh: number; material_kg_per_kg: number; energy_g: number; material_g: number };
}
/** Trajectory metrics of the VTG paper (eq. 24–26, 28, 31). */
export interface ToolpathMetrics {
  l_total_mm: number;
  l_infill_mm: number;
  n_total: number;
  n_infill: number;
  /** Turns above the critical angle. */
  n_turning: number;
  /** Vertices between two printing segments. */
  n_corners: number;
  mean_turn_deg: number;
  mean_chord_error_mm: number;
  critical_angle_deg: number;
}
/** The analysis report (`quietpath analyze --json`). */
export interface Report {
  version: string;
  file: { bytes: number; lines: number; slicer: string | null; flavor: string | null; slicer_time_s: number | null };
  time_s: number;
  /** Time in dwells (G4), s, included in time_s. */
  dwell_s: number;
  /** Homings (G28) on Klipper, left out of time_s and of moves (no file tells how long they
   * take); absent when none, and on Marlin-style files (G28 timed as a move there). */
  homing_count?: number;
  time_model: string;
  machine: { profile: string; junction_model: JunctionModel; reason: string; limits: Limits };
  moves: number;
  extruding_moves: number;
  layers: number;
  layer_source:
    | { method: "markers"; marker: "layer_change" | "cura_layer" | "simplify3d" | "kis_slicer" | "kiri_moto" }
    | { method: "z_changes" };
  distance_mm: number;
  extrude_distance_mm: number;
  travel_distance_mm: number;
  filament_mm: number;
  filament_volume_mm3: number;
  material_g: number;
  retractions: number;
  extrusion: {
    mode: "absolute" | "relative";
    source: "explicit" | "inferred" | "default";
    filament_diameter_mm: number;
    density_g_cm3: number;
  };
  bounds: { min: number[]; max: number[] } | null;
  features: FeatureSummary[];
  layer_list: LayerSummary[];
  temperatures: TemperatureEvent[];
  fans: FanEvent[];
  energy: Energy;
  toolpath: ToolpathMetrics;
  warnings: Warning[];
  warnings_dropped: number;
}
/** Drawing data of one layer (Session.layer). Segment i is xy[4i..4i+4] = x0, y0, x1, y1. */
export interface LayerGeometry {
  z: number | null;
  xy: Float32Array;
  /** 0 travel, 1 outer wall, 2 inner wall, 3 sparse infill, 4 solid infill, 5 bridge,
   *  6 gap fill, 7 support, 8 adhesion, 9 other. */
  kind: Uint8Array;
  speed: Float32Array;
  curvature: Float32Array;
  /** A multi-axis file's segments in 3-D, six numbers each (x0, y0, z0, x1, y1, z1, mm),
   *  parallel to `xy`: the tool tip in the workpiece frame (where the material goes on the part),
   *  while `xy` holds the machine axes. Empty for a three-axis file. */
  xyz: Float32Array;
  /** Tool vectors of a multi-axis file (rotary words), six numbers each: tool tip x, y, z (mm)
   *  and unit tool vector i, j, k (tip towards the nozzle), both in the workpiece frame, one per
   *  extruding move. Empty for a three-axis file. */
  tool: Float32Array;
}
/** One calibration row: thesis terms A, B, C, H and the measured energy E (W·ms). */
export type CalibrationRow = [number, number, number, number, number] | { a: number; b: number; c: number; h: number; e: number };
export interface CalibrationFit {
  k_a_mx: number;
  k_a_my: number;
  k_c: number;
  k_h: number;
  [key: string]: unknown;
}
/** An error thrown by the API: a JS Error with the position of the problem. */
export interface QuietpathError extends Error {
  line?: number;
  column?: number;
  kind?: { kind: string; [key: string]: unknown };
}
/** Progress callback: fraction done in [0, 1]; return false to cancel (the job throws a
 *  `cancelled` error). */
export type ProgressCallback = (fraction: number) => boolean | void;

// ── vibration (`quietpath vibration --json`) ──
export interface VibrationOptions {
  analyze?: AnalyzeOptions;
  /** Interpolation period T_s, ms (default 1). */
  ts_ms?: number;
  /** Accelerometer sampling rate for the spectrum, Hz (default 200). */
  fs_hz?: number;
  /** Welch segment length, samples (default 512). */
  window?: number;
  window_kind?: "hamming" | "hann" | "rectangular";
  /** Built-in dynamics parameter set: "ldam-ball-screw" | "desktop-belt" (default: from the machine). */
  dynamics?: string | null;
  dynamics_parameters?: Record<string, unknown> | null;
  bucket_mm?: number;
  peaks?: number;
}
/** Trajectory deviation (eq. 15 of the VTG paper), mm. */
export interface Deviation { max: number; min: number; mean: number; max_at: number[]; samples: number }
export interface Mode { frequency_hz: number; damping_ratio: number }
export interface VibrationReport {
  machine: string;
  dynamics: string;
  ts_ms: number;
  natural_frequencies_hz: number[];
  damping_ratios: number[];
  axes: { axis: string; position_mm: number; modes: Mode[] }[];
  deviation_mm: Deviation;
  /** The same over extruding moves only. */
  printing_deviation_mm: Deviation;
  layers: { layer: number; z: number | null; amplitude: number; mean: number; acceleration_rms: number }[];
  psd: {
    fs_hz: number;
    window: number;
    window_kind: "hamming" | "hann" | "rectangular";
    overlap: number;
    segments: number;
    freqs: number[];
    power: number[];
    peaks: { hz: number; power: number }[];
  };
  simulated_s: number;
  steps: number;
}
/** vibration() result: the report with the spectrum as typed arrays. */
export interface VibrationResult extends Omit<VibrationReport, "psd"> {
  psd: Omit<VibrationReport["psd"], "freqs" | "power"> & { freqs: Float64Array; power: Float64Array };
}

// ── smooth (`quietpath smooth --json`) ──
export type FilterKind = "zero-phase-moving-average" | "zero-phase-median" | "moving-average" | "median";
export interface SmoothOptions {
  kinematics?: { model?: "table-bc" | "head-ab"; b_axis_point_mm?: number[]; c_axis_point_mm?: number[]; pivot_length_mm?: number };
  /** G-code: X/Y/Z are machine axes (default) or the tool tip in the workpiece frame (RTCP/TCPM; only rotary words are rewritten). */
  coordinates?: "machine" | "workpiece";
  filter?: FilterKind;
  /** Window by point count or by path length. */
  window?: { points: number } | { millimetres: number };
  /** Tolerance cone opening γ, degrees (default 60): every vector stays within γ/2. */
  cone_deg?: number;
  singular_deg?: number;
  max_gap_mm?: number;
  decimals?: number;
  format?: "auto" | "gcode" | "csv" | "json";
  feed_mm_s?: number;
  analyze?: AnalyzeOptions;
  /** Rewrite a G-code file's time comments and M73 lines from the planner when it changed (default true). */
  estimates?: boolean;
}
export interface RotaryMetrics {
  axis: string;
  travel_deg: number;
  max_velocity_deg_s: number;
  rms_velocity_deg_s: number;
  max_acceleration_deg_s2: number;
  rms_acceleration_deg_s2: number;
  max_jerk_deg_s3: number;
  rms_jerk_deg_s3: number;
}
export interface OrientationMetrics {
  /** RMS of ‖T(m+1) − 2T(m) + T(m−1)‖ over consecutive points of each run. */
  roughness: number;
  mean_second_difference: number;
  max_second_difference: number;
  mean_angle_change_deg: number;
  max_angle_change_deg: number;
  mean_angle_change_per_mm_deg: number;
  max_angle_change_per_mm_deg: number;
  rotary: RotaryMetrics[];
}
export interface SmoothReport {
  format: string;
  kinematics: string;
  coordinates: "machine" | "workpiece";
  filter: FilterKind;
  window: { points: number } | { millimetres: number };
  cone_deg: number;
  motion_lines: number;
  points: number;
  runs: number;
  corrected: number;
  changed: number;
  max_angle_to_original_deg: number;
  mean_angle_to_original_deg: number;
  before: OrientationMetrics;
  after: OrientationMetrics;
  roughness_reduction: number;
  max_tip_deviation_mm: number;
  planned_time_before_s: number;
  planned_time_after_s: number;
  series: {
    axes: string[];
    point: number[];
    first_before: number[];
    first_after: number[];
    second_before: number[];
    second_after: number[];
    angle_to_original_deg: number[];
  };
  warnings: Warning[];
}
/** smooth() result: the report plus the smoothed file. A file whose rotary axes never move
 *  (3-axis) throws a QuietpathError of kind `no_rotary_motion` ({ first, second } axis letters). */
export interface SmoothResult extends SmoothReport { output: Uint8Array }

// ── infill (`quietpath infill --json`) ──
export type InfillPattern =
  | "rectilinear" | "grid" | "triangles" | "tri_hexagon" | "cross_line" | "concentric"
  | "hilbert" | "archimedean_chords" | "octagram_spiral";
export interface InfillOptions {
  analyze?: AnalyzeOptions;
  /** Infill angles to try, degrees (default 0 to 165 in steps of 15). */
  angles_deg?: number[];
  /** Part rotations about Z to try, degrees (default 0). */
  rotations_deg?: number[];
  patterns?: InfillPattern[];
  objective?: "energy" | "time" | "length" | "weighted";
  weights?: { energy?: number; time?: number; length?: number };
  /** Choose pattern and angle per layer (the thesis's hybrid). */
  per_layer?: boolean;
  spacing_mm?: number | null;
  /** Write the best candidate even when it does not beat the original (default false: the original is kept). */
  force_candidate?: boolean;
  /** Rewrite the file's time comments and M73 lines from the planner when a candidate is written (default true). */
  estimates?: boolean;
}
export interface InfillCandidate {
  pattern: InfillPattern;
  angle_deg: number;
  rotation_deg: number;
  thesis_j: number;
  total_j: number;
  time_s: number;
  length_mm: number;
  filament_mm: number;
  /** Length of the new infill strokes, mm (VTG eq. 25; Fig. 4). */
  infill_length_mm: number;
  /** Turning points of the new infill (turns above 30°; Fig. 5). */
  infill_turning_points: number;
  /** Mean turning angle of the new infill, degrees (eq. 26; Fig. 5). */
  infill_mean_turn_deg: number;
}
export interface InfillReport {
  before: Report;
  after: Report;
  best: {
    /** The regenerated pattern, or `original` when no candidate beat the input (the output is then the input). */
    pattern: InfillPattern | 'original';
    angle_deg: number;
    rotation_deg: number;
    thesis_j: number;
    total_j: number;
    time_s: number;
    length_mm: number;
    saving_j: number;
    saving_pct: number;
    layers: { layer: number; pattern: InfillPattern | 'original'; angle_deg: number; [key: string]: unknown }[] | null;
    /** Why the original was kept (or that a dearer candidate was forced); null when the output beats the input. */
    message: string | null;
  };
  candidates: InfillCandidate[];
  /** Candidates with the geometry of an earlier one (concentric at another angle): listed with its costs, not costed again. */
  candidates_skipped: number;
  measured: {
    spacing_mm: number;
    clearance_mm: number;
    e_per_mm: number;
    layers_regenerated: number;
    blocks: number;
    print_feed_mm_s: number;
    travel_feed_mm_s: number;
    retract_mm: number;
    [key: string]: number;
  };
  rotations_skipped: number[];
}
/** infill() result: the report plus the rewritten file. */
export interface InfillResult extends InfillReport { output: Uint8Array }

// ── vtg (`quietpath vtg --json`) ──
export interface VtgOptions {
  analyze?: AnalyzeOptions;
  /** Largest distance the new path may stray from the original, mm (default 0.1). */
  tolerance_mm?: number;
  /** Critical angle δθ, degrees (default 30). */
  critical_angle_deg?: number;
  interpolation_period_s?: number;
  /** Normal jerk limit J_n, mm/s³ (default: A_n × the machine's first natural frequency). */
  normal_jerk_mm_s3?: number | null;
  nozzle_diameter_mm?: number;
  /** Lower the feed where the curvature exceeds K_cr (eq. 29–30; default true). */
  limit_feed?: boolean;
  /** Simulate both files for Table 2's deviation rows (default true). */
  dynamics?: boolean;
  /** Write runs of new points on a circle as G2/G3 arcs (default false: the firmware must have arcs enabled). */
  arcs?: boolean;
  /** Print time the rewrite may add to round corners that cost time, % of the original's (default 1, the bar; only machines that take sharp corners faster than round ones, such as Klipper at a high square-corner velocity, spend it; 0: no slower, no dearer; 100 rounds every corner the tolerance allows). */
  allow_slower_pct?: number;
  /** Round corners only on the inside, with fillets tangent to the legs (default false: the racing line, easing out by up to the tolerance before a corner for a circle 2.4× wider at 90°). */
  inside_corners?: boolean;
  /** Rewrite the file's time comments and M73 lines from the planner when the toolpath changed (default true). */
  estimates?: boolean;
  /** The firmware's minimum segment time, ms (default: the file's M205 B, else Marlin's 20 ms): new segments are joined up to this long at their feed where the tolerance allows. */
  min_segment_time_ms?: number | null;
}
/** before, after and the relative change in percent. */
export interface Comparison { before: number; after: number; change_pct: number }
export interface VtgReport {
  tolerance_mm: number;
  max_deviation_mm: number;
  critical_angle_deg: number;
  k_cr_per_mm: number;
  limits: {
    v_max_mm_s: number;
    interpolation_period_s: number;
    chord_tolerance_mm: number;
    normal_accel_mm_s2: number;
    normal_jerk_mm_s3: number;
    nozzle_radius_mm: number;
  };
  paths: {
    candidates: number;
    rewritten: number;
    replaced_moves: number;
    written_moves: number;
    above_k_cr_segments: number;
    lowered_feed_segments: number;
    /** Paths whose eq. 29 speeds were raised (up to 3×) so they cost no time. */
    raised_caps: number;
    /** Paths written without eq. 29 feed caps (even raised, they would have made them slower). */
    uncapped: number;
    /** Paths slower or dearer when rounded, even without caps, paid for out of half of what the other rewrites saved, or with the time `allow_slower_pct` allows. */
    paid_from_savings: number;
    /** Paths kept as they were: slower or dearer when rounded, and not paid for. */
    kept_for_time: number;
    mean_speed_fluctuation_pct: number;
    /** Scale the eq. 29 speeds started from: 1, or 1.5 / 2 where the dynamics model found the rewrite at 1 rang more than the original. */
    feed_cap_scale: number;
    /** Whether the walked steps were joined up to the firmware's segment budget (false where the dynamics model found the steps as walked quieter). */
    steps_joined: boolean;
    /** Arcs (G2/G3) written in place of runs of steps on a circle (option `arcs`). */
    arcs_written: number;
    /** Single corners too tight to fillet (wedge tips) turned round a small keyhole loop instead; 0 where the dynamics model found the loops ringing more than the original. */
    keyholes: number;
  };
  /** The VTG paper's Table 1. */
  table1: {
    l_total_mm: Comparison;
    n_total: Comparison;
    l_infill_mm: Comparison;
    n_infill: Comparison;
    n_turning: Comparison;
    mean_turn_deg: Comparison;
    mean_chord_error_mm: Comparison;
  };
  /** The VTG paper's Table 2 (deviation from the dynamics model; null when not simulated). */
  table2: {
    deviation: { max_mm: Comparison; min_mm: Comparison; mean_mm: Comparison } | null;
    energy_j: Comparison;
    servo_energy_j: Comparison;
    material_g: Comparison;
    co2_g: Comparison;
    time_s: Comparison;
  };
  layers: { index: number; before: ToolpathMetrics; after: ToolpathMetrics }[];
  before: Report;
  after: Report;
  /** Both files against the machine's segment budget (Marlin's min_segment_time and block buffer, a serial stream's line rate). */
  firmware: {
    budget: {
      min_segment_time_s: number;
      /** "file" (M205 B), "option" or "default". */
      min_segment_time_source: string;
      block_buffer: number;
      stream_bytes_per_s: number;
    };
    before: FirmwareFigures;
    after: FirmwareFigures;
    /** Set when the rewrite's peak segment rate exceeds the budget (and the original's). */
    warning: string | null;
  } | null;
}
/** How one file measures against the segment budget. */
export interface FirmwareFigures {
  lines: number;
  bytes: number;
  printing_segments: number;
  segments_under_0_1mm: number;
  segments_under_min_time: number;
  /** Most planned moves that start within any 1 s of planned time. */
  peak_segments_per_s: number;
  /** Segments per second the firmware reads at this file's mean bytes per line. */
  budget_segments_per_s: number;
}
/** vtg() result: the report plus the rewritten file. */
export interface VtgResult extends VtgReport { output: Uint8Array }

// ── optimize (`quietpath optimize --json`) ──
export interface OptimizeOptions {
  analyze?: AnalyzeOptions;
  /** Run the infill search first with these options (default: off); its `analyze` is replaced by this one's. */
  infill?: InfillOptions | null;
  /** Run VTG (default true). */
  vtg?: boolean;
  /** VTG's options (default: VTG's); `analyze`, `arcs` and `allow_slower_pct` are replaced by the pipeline's. */
  vtg_options?: VtgOptions;
  /** Print time VTG may add to round corners, percent (default 0: never slower). */
  allow_slower_pct?: number;
  /** Arcs in the output: where the firmware runs them (default), always, never. */
  arcs?: 'auto' | 'on' | 'off';
  /** Rewrite the time comments and M73 lines (default true). */
  estimates?: boolean;
}
/** One stage of the pipeline. */
export interface OptimizeStage {
  stage: 'infill' | 'vtg' | 'estimates';
  /** Whether its file was kept (no dearer in time and energy). */
  applied: boolean;
  /** What it did, or why its file was not kept. */
  message: string;
  /** Before and after the stage. */
  time_s: [number, number];
  energy_j: [number, number];
  lines: [number, number];
}
/** What the estimates stage wrote (`quietpath estimate --json`). */
export interface EstimateReport {
  time_s: number;
  progress_lines: number;
  time_comments: number;
  header_lines: number;
}
export interface OptimizeReport {
  before: Report;
  after: Report;
  stages: OptimizeStage[];
  estimates: EstimateReport | null;
}
/** optimize() result: the report plus the optimised file. */
export interface OptimizeResult extends OptimizeReport { output: Uint8Array }
