// GENERATED from the Rust types by crate/src/ts_types.rs (ts-rs): do not edit. Regenerate:
//   UPDATE_TYPES=1 cargo test -p quietpath --lib ts_types
// The serde form of the reports, options and profiles: the same JSON as the CLI's --json.
// Hand-written declarations (typed-array results, callbacks, errors) are in types.d.ts.

/**
 * Options of `analyze`, and of how every other job reads its input. Every field is optional
 * in JSON.
 */
export type AnalyzeOptions = Partial<{
  /**
   * Stop at the first malformed line instead of warning.
   */
  strict: boolean,
  /**
   * Filament diameter, mm (default: from the file, else 1.75).
   */
  filament_diameter_mm: number | null,
  /**
   * Filament density, g/cm³ (default: from the file, else 1.24, PLA).
   */
  density_g_cm3: number | null,
  /**
   * Force the starting extrusion mode instead of inferring it.
   */
  extrusion_mode: ExtrusionModeOption | null,
  /**
   * Built-in machine preset (see `plan::profiles::PRESETS`); default: chosen from the file's
   * flavour.
   */
  machine: string | null,
  /**
   * A whole machine profile (wins over `machine`).
   */
  machine_profile: MachineProfile | null,
  /**
   * Junction model; default: the profile's, or Klipper's for files that drive Klipper.
   */
  junction_model: JunctionModel | null,
  /**
   * Length of the segments arcs are split into, mm (default: the profile's, 1 mm).
   */
  arc_segment_mm: number | null,
  /**
   * Energy model settings (coefficients, material, powers, emission factors); default:
   * [`EnergyOptions::default`].
   */
  energy: EnergyOptions | null,
  /**
   * The printer's Klipper config (`printer.cfg`): the file runs on Klipper with these
   * limits, over the profile's. In JSON, the config's text or its parsed form.
   */
  klipper_config: string | KlipperConfig | null,
  /**
   * How that Klipper reads `max_accel_to_decel` (default: current Klipper).
   */
  klipper_version: KlipperVersion | null,
  /**
   * A Marlin printer's own settings as its `M503` prints them (`M201`, `M203`, `M204`,
   * `M205`…), applied before the file, over the profile's limits and the slicer's settings
   * block. Not with `klipper_config` (a Klipper printer's settings are its config).
   */
  machine_gcode: string | null,
}>;

/**
 * How a Marlin-family firmware cuts `G2`/`G3` into straight segments (Klipper's
 * `[gcode_arcs]` cuts by its own rule, [`super::ArcCutting`]).
 */
export type ArcRule = "chord_deviation" | "circle_segments";

/**
 * Arcs in the output.
 */
export type ArcsMode = "auto" | "on" | "off";

/**
 * Powers and heat capacities of the auxiliary systems.
 */
export type AuxPowers = Partial<{
  /**
   * Bed heat loss per kelvin above ambient, W/K (0.9: about 32 W holding 60 °C).
   */
  bed_w_per_k: number,
  /**
   * Bed heat capacity (aluminium plate and steel sheet, about 0.4 + 0.3 kg), J/K.
   */
  bed_heat_capacity_j_per_k: number,
  /**
   * Hotend heat loss per kelvin above ambient, W/K (0.065: about 12 W holding 215 °C).
   */
  hotend_w_per_k: number,
  /**
   * Hotend heat capacity (heater block, nozzle, cartridge), J/K.
   */
  hotend_heat_capacity_j_per_k: number,
  /**
   * Heated-chamber loss per kelvin above ambient, W/K.
   */
  chamber_w_per_k: number,
  /**
   * Heated-chamber heat capacity (air, walls), J/K.
   */
  chamber_heat_capacity_j_per_k: number,
  /**
   * Power of each part-cooling fan at full speed, W (a 24 V, 0.1 A blower).
   */
  fan_w: number,
  /**
   * Constant draw of the electronics while printing, W.
   */
  electronics_w: number,
}>;

/**
 * `E_aux` by system, J.
 */
export type AuxReport = {
  /**
   * Bed holding its targets, J.
   */
  bed_j: number,
  /**
   * Hotends holding their targets, J.
   */
  hotend_j: number,
  /**
   * Chamber holding its target, J.
   */
  chamber_j: number,
  /**
   * Warming heaters up to raised targets, J.
   */
  heat_up_j: number,
  /**
   * Part-cooling fans, J.
   */
  fan_j: number,
  /**
   * Electronics, J.
   */
  electronics_j: number,
};

/**
 * Modes of one axis.
 */
export type AxisModes = {
  /**
   * `x` or `y`.
   */
  axis: string,
  /**
   * Axis position the modes are taken at (the middle of the printed area), mm.
   */
  position_mm: number,
  /**
   * Modes by increasing frequency.
   */
  modes: Array<Mode>,
};

/**
 * A ball-screw drive (VTG eq. 1–9).
 */
export type BallScrew = {
  /**
   * Screw radius `r_s`, m.
   */
  screw_radius_m: number,
  /**
   * Screw length `l_s`, m.
   */
  screw_length_m: number,
  /**
   * Lead (table travel per screw turn), m; the transmission ratio is `i_s = lead / 2π`.
   */
  lead_m: number,
  /**
   * Screw material density `ρ`, kg/m³.
   */
  density_kg_m3: number,
  /**
   * Young's modulus `E`, Pa.
   */
  youngs_modulus_pa: number,
  /**
   * Shear modulus `G`, Pa.
   */
  shear_modulus_pa: number,
  /**
   * Motor rotor mass `m_r` (VTG eq. 1), kg.
   */
  rotor_mass_kg: number,
  /**
   * Coupling mass `m_c` (VTG eq. 1), kg.
   */
  coupling_mass_kg: number,
  /**
   * Coupling inertia `J_c` (VTG eq. 3), kg·m².
   */
  coupling_inertia_kg_m2: number,
  /**
   * Motor rotor inertia `J_M`, kg·m².
   */
  motor_inertia_kg_m2: number,
  /**
   * Slave pedestal (nut block, slider) mass `m_3`, kg.
   */
  pedestal_mass_kg: number,
  /**
   * Working table (what the axis carries) mass `m_4`, kg.
   */
  table_mass_kg: number,
  /**
   * Axial stiffness of the fixed bearing `k_zn` (VTG eq. 8), N/m.
   */
  bearing_stiffness_n_m: number,
  /**
   * Torsional stiffness of the coupling `k_zt` (VTG eq. 9), N·m/rad.
   */
  coupling_stiffness_nm_rad: number,
  /**
   * Nut reference stiffness without preload `k_c` (VTG eq. 7), N/m.
   */
  nut_reference_stiffness_n_m: number,
  /**
   * Nut preload `F_z` (VTG eq. 7), N.
   */
  preload_n: number,
  /**
   * Dynamic load rating `C_a` (VTG eq. 7), N.
   */
  dynamic_load_rating_n: number,
  /**
   * Axial stiffness of one flexure hinge between pedestal and table `k_mw`, N/m.
   */
  hinge_stiffness_n_m: number,
  /**
   * Damping coefficient of the nut `C_mn` (VTG eq. 13), N·s/m.
   */
  nut_damping_ns_m: number,
  /**
   * Damping coefficient of one flexure hinge `C_mw` (VTG eq. 13), N·s/m.
   */
  hinge_damping_ns_m: number,
  /**
   * Distance from coupling to nut at axis position 0, m (`l_n = offset + position`).
   */
  nut_offset_m: number,
  /**
   * Position loop.
   */
  servo: ServoLoop,
};

/**
 * A belt drive of a desktop printer, mapped onto the same coordinates.
 */
export type Belt = {
  /**
   * Pulley pitch radius (the transmission ratio `i_s`), m.
   */
  pulley_radius_m: number,
  /**
   * Belt specific stiffness `EA`, N (force per unit strain).
   */
  belt_ea_n: number,
  /**
   * Length of the belt loop's two straight spans together, m.
   */
  span_length_m: number,
  /**
   * Span between pulley and carriage at axis position 0, m (`l₁ = offset + position`).
   */
  span_offset_m: number,
  /**
   * Motor rotor inertia `J_M`, kg·m².
   */
  motor_inertia_kg_m2: number,
  /**
   * Pulley inertia `J_S`, kg·m².
   */
  pulley_inertia_kg_m2: number,
  /**
   * Torsional stiffness of the motor shaft between rotor and pulley, N·m/rad.
   */
  shaft_stiffness_nm_rad: number,
  /**
   * Motor and mount mass moving with the frame along the belt (x1), kg.
   */
  motor_mount_mass_kg: number,
  /**
   * Idler mass (x2), kg.
   */
  idler_mass_kg: number,
  /**
   * Stiffness of the motor mount and of the idler mount along the belt, N/m.
   */
  mount_stiffness_n_m: number,
  /**
   * Carriage (belt clamp, wheels or bearing blocks) mass `m_3`, kg.
   */
  carriage_mass_kg: number,
  /**
   * Toolhead (X) or bed (Y) mass on the carriage `m_4`, kg.
   */
  payload_mass_kg: number,
  /**
   * Stiffness of one of the two payload mounts `k_mw`, N/m.
   */
  mount_hinge_stiffness_n_m: number,
  /**
   * Guide damping on the carriage `C_mn`, N·s/m.
   */
  carriage_damping_ns_m: number,
  /**
   * Damping of one payload mount `C_mw`, N·s/m.
   */
  payload_damping_ns_m: number,
  /**
   * Stepper (or servo) loop.
   */
  servo: ServoLoop,
};

/**
 * Axis-aligned bounding box.
 */
export type Bounds = {
  /**
   * Minimum X, Y, Z, mm.
   */
  min: [number, number, number],
  /**
   * Maximum X, Y, Z, mm.
   */
  max: [number, number, number],
};

/**
 * Why a calibration failed. Rows are 1-based lines of the CSV (or positions in a list).
 */
export type CalibrationError = {
  "kind": "empty"
} | {
  "kind": "columns",
  /**
   * Row.
   */
  row: number,
  /**
   * What was expected.
   */
  expected: string,
  /**
   * Fields found.
   */
  found: number,
} | {
  "kind": "invalid_number",
  /**
   * Row.
   */
  row: number,
  /**
   * 1-based column.
   */
  column: number,
  /**
   * The field.
   */
  text: string,
} | {
  "kind": "out_of_range",
  /**
   * Row.
   */
  row: number,
  /**
   * 1-based column.
   */
  column: number,
  /**
   * The value.
   */
  value: number,
} | {
  "kind": "empty_path",
  /**
   * Row.
   */
  row: number,
} | {
  "kind": "gcode",
  /**
   * Row.
   */
  row: number,
  /**
   * Path as resolved.
   */
  path: string,
  /**
   * What went wrong.
   */
  message: string,
} | {
  "kind": "too_few_rows",
  /**
   * Rows needed.
   */
  needed: number,
  /**
   * Rows found.
   */
  found: number,
} | {
  "kind": "rank_deficient",
  /**
   * Numerical rank.
   */
  rank: number,
};

/**
 * The fitted coefficients and the quality of the fit.
 */
export type CalibrationFit = {
  /**
   * `k_a·m_x`, W·ms per (mm/s)².
   */
  k_a_mx: number,
  /**
   * `k_a·m_y`, W·ms per (mm/s)².
   */
  k_a_my: number,
  /**
   * `k_c`, W·ms per mm.
   */
  k_c: number,
  /**
   * `k_h`, W·ms per s.
   */
  k_h: number,
  /**
   * Standard errors of the four coefficients, same units.
   */
  standard_errors: ThesisCoefficients,
  /**
   * Uncentred coefficient of determination (regression through the origin).
   */
  r2: number,
  /**
   * `r2` adjusted for the degrees of freedom, `1 − (1 − r2)·n/(n − 4)`.
   */
  adjusted_r2: number,
  /**
   * Root-mean-square residual, W·ms.
   */
  rmse: number,
  /**
   * Standard error of the regression, `√(SS_res/(n − 4))`, W·ms.
   */
  standard_error: number,
  /**
   * F statistic of the regression (4 and n − 4 degrees of freedom).
   */
  f_statistic: number,
  /**
   * Probability of an F at least this large if all coefficients were zero (4 and n − 4
   * degrees of freedom). Excel's regression tool, with a zero constant, takes n − 5 for the
   * second: the thesis's 8.48532·10⁻⁸ is `f_upper_tail(1388.57, 4, 5)`.
   */
  p_value: number,
  /**
   * Observations.
   */
  n: number,
  /**
   * Unit of the energies and residuals.
   */
  energy_unit: string,
  /**
   * Per-row fit.
   */
  residuals: Array<Residual>,
};

/**
 * Emission figures (VTG eq. 17).
 */
export type Co2Report = {
  /**
   * Grid factor used, kg CO₂ per kWh.
   */
  grid_kg_per_kwh: number,
  /**
   * Material factor used, kg CO₂ per kg.
   */
  material_kg_per_kg: number,
  /**
   * From electricity, g.
   */
  energy_g: number,
  /**
   * From material, g.
   */
  material_g: number,
};

/**
 * A figure before and after, and the relative change.
 */
export type Comparison = {
  /**
   * Before VTG.
   */
  before: number,
  /**
   * After VTG.
   */
  after: number,
  /**
   * `(after − before) / before`, percent (0 when `before` is 0).
   */
  change_pct: number,
};

/**
 * What the X, Y, Z words of multi-axis G-code are.
 */
export type Coordinates = "machine" | "workpiece";

/**
 * Trajectory deviation statistics (VTG eq. 15), mm.
 */
export type Deviation = {
  /**
   * Largest deviation.
   */
  max: number,
  /**
   * Smallest deviation.
   */
  min: number,
  /**
   * Mean deviation.
   */
  mean: number,
  /**
   * Commanded X, Y (mm) and time (s) of the largest deviation.
   */
  max_at: [number, number, number],
  /**
   * Samples (one per `T_s` while the machine runs a move).
   */
  samples: number,
};

/**
 * Deviation of the simulated tool from the programmed path (the paper's Table 2 kinematic
 * rows), from the dynamics model; filled in when that model is run on both files.
 */
export type DeviationComparison = {
  /**
   * Largest deviation, mm.
   */
  max_mm: Comparison,
  /**
   * Smallest deviation, mm.
   */
  min_mm: Comparison,
  /**
   * Mean deviation, mm.
   */
  mean_mm: Comparison,
};

/**
 * One axis drive.
 */
export type Drive = {
  "type": "ball_screw"
} & BallScrew | {
  "type": "belt"
} & Belt;

/**
 * Energy and carbon figures (see [`crate::energy`] for the models, their units and sources).
 *
 * `total_j = servo_j + fuse_j + aux_j` (VTG eq. 16); `co2_g` is VTG eq. 17.
 */
export type Energy = {
  /**
   * X/Y stepper energy by the thesis model (thesis eq. 28), J. Always computed.
   */
  thesis_j: number,
  /**
   * Energy of the X/Y drives, `E_servo`, J (equal to `thesis_j` with the thesis model).
   */
  servo_j: number,
  /**
   * Model that gave `servo_j`: `thesis` or `physical`.
   */
  servo_model: ServoModel,
  /**
   * Heat to melt the filament, `E_fuse`, J.
   */
  fuse_j: number,
  /**
   * Heaters, fans and electronics over the print, `E_aux`, J.
   */
  aux_j: number,
  /**
   * `E = E_servo + E_fuse + E_aux`, J.
   */
  total_j: number,
  /**
   * The same in kWh.
   */
  total_kwh: number,
  /**
   * Material mass the fuse and carbon figures use, g.
   */
  material_g: number,
  /**
   * Carbon emission `f_e·E + f_m·m`, g CO₂.
   */
  co2_g: number,
  /**
   * The thesis terms `A`, `B`, `C`, `H` and the coefficients used.
   */
  thesis: ThesisReport,
  /**
   * The physical servo model's parts, when it gave `servo_j`.
   */
  physical_servo: ServoReport | null,
  /**
   * How `fuse_j` was computed.
   */
  fuse: FuseReport,
  /**
   * `aux_j` by system.
   */
  aux: AuxReport,
  /**
   * `co2_g` by source and the factors used.
   */
  co2: Co2Report,
};

/**
 * Settings of the energy models; every field is optional in JSON.
 */
export type EnergyOptions = Partial<{
  /**
   * Coefficients of the thesis model (default: the published ones).
   */
  thesis: Partial<ThesisCoefficients>,
  /**
   * Model of the X/Y drives.
   */
  servo_model: ServoModel,
  /**
   * Parameters of the physical servo model.
   */
  servo: ServoProfile,
  /**
   * Material (default: the file's `filament_type`, else PLA).
   */
  material: Material | null,
  /**
   * Properties replacing the material's built-in ones.
   */
  material_properties: Partial<MaterialProperties> | null,
  /**
   * Ambient temperature, °C.
   */
  ambient_c: number,
  /**
   * Share of the heater's extra energy that reaches the filament, 0..=1.
   */
  heater_efficiency: number,
  /**
   * Auxiliary powers.
   */
  aux: AuxPowers,
  /**
   * Grid emission factor, kg CO₂ per kWh.
   */
  grid_kg_co2_per_kwh: number,
  /**
   * Material emission factor, kg CO₂ per kg (default: the material's).
   */
  material_kg_co2_per_kg: number | null,
}>;

/**
 * What went wrong, independent of where.
 */
export type ErrorKind = {
  "kind": "invalid_number",
  /**
   * The word letter, upper case.
   */
  letter: string,
} | {
  "kind": "non_finite_number",
  /**
   * The word letter, upper case.
   */
  letter: string,
} | {
  "kind": "unexpected_character",
  /**
   * The offending character (bytes above 0x7f are shown as U+FFFD).
   */
  found: string,
} | {
  "kind": "unclosed_comment"
} | {
  "kind": "checksum_mismatch",
  /**
   * The checksum written in the line.
   */
  found: number,
  /**
   * The checksum computed from the line.
   */
  computed: number,
} | {
  "kind": "too_many_words",
  /**
   * The limit.
   */
  max: number,
} | {
  "kind": "duplicate_word",
  /**
   * The repeated letter.
   */
  letter: string,
} | {
  "kind": "invalid_arc",
  /**
   * Why.
   */
  reason: string,
} | {
  "kind": "utf16"
} | {
  "kind": "binary"
} | {
  "kind": "line_too_long",
  /**
   * The limit.
   */
  max: number,
} | {
  "kind": "invalid_option",
  /**
   * Why.
   */
  reason: string,
} | {
  "kind": "machine_settings",
  /**
   * 1-based line of the settings text.
   */
  line: number,
  /**
   * Why, with the line.
   */
  reason: string,
} | {
  "kind": "no_rotary_motion",
  /**
   * The first rotary axis letter of the kinematic model.
   */
  first: string,
  /**
   * The second rotary axis letter.
   */
  second: string,
} | {
  "kind": "transfer",
  /**
   * Why.
   */
  reason: string,
} | {
  "kind": "nothing_to_regenerate",
  /**
   * What the file lacks.
   */
  reason: string,
} | {
  "kind": "cancelled"
};

/**
 * What [`rewrite_estimates`] changed.
 */
export type EstimateReport = {
  /**
   * Print time by our planner, s (`analyze`'s `time_s` of the file).
   */
  time_s: number,
  /**
   * `M73` progress lines rewritten.
   */
  progress_lines: number,
  /**
   * Time comments rewritten.
   */
  time_comments: number,
  /**
   * Header comment lines written (earlier quietpath headers are replaced).
   */
  header_lines: number,
};

/**
 * Extrusion settings used for filament and mass.
 */
export type ExtrusionInfo = {
  /**
   * Mode the file starts in.
   */
  mode: ExtrusionMode,
  /**
   * Where that mode came from.
   */
  source: ModeSource,
  /**
   * Filament diameter, mm.
   */
  filament_diameter_mm: number,
  /**
   * Filament density, g/cm³.
   */
  density_g_cm3: number,
};

/**
 * Extrusion mode for E words.
 */
export type ExtrusionMode = "absolute" | "relative";

/**
 * Starting extrusion mode, as an option.
 */
export type ExtrusionModeOption = "absolute" | "relative";

/**
 * A fan speed set at some point of the print.
 */
export type FanEvent = {
  /**
   * 1-based line.
   */
  line: number,
  /**
   * Print time at that line, s.
   */
  time_s: number,
  /**
   * Fan index.
   */
  index: number,
  /**
   * Speed, 0..=1.
   */
  speed: number,
};

/**
 * The canonical kind of a printed feature, mapped from every slicer's own names.
 */
export type FeatureKind = "outer_wall" | "inner_wall" | "sparse_infill" | "solid_infill" | "bridge" | "gap_fill" | "support" | "adhesion" | "other";

/**
 * Totals for one printed feature (as named by the slicer), or for travel.
 */
export type FeatureSummary = {
  /**
   * Name as the slicer wrote it (`travel` for non-printing moves, `unmarked` when the file
   * names no features).
   */
  name: string,
  /**
   * Canonical kind (`null` for travel).
   */
  kind: FeatureKind | null,
  /**
   * Moves.
   */
  moves: number,
  /**
   * Path length, mm.
   */
  distance_mm: number,
  /**
   * Net filament, mm.
   */
  filament_mm: number,
  /**
   * Time, s (same model as `time_s`).
   */
  time_s: number,
  /**
   * Energy of its moves, J: their `E_servo` plus the share of `E_aux` of their time (see
   * [`crate::energy`]).
   */
  energy_j: number,
};

/**
 * Facts about the input file.
 */
export type FileInfo = {
  /**
   * Size, bytes.
   */
  bytes: number,
  /**
   * Number of lines.
   */
  lines: number,
  /**
   * Slicer that wrote it, from its header.
   */
  slicer: string | null,
  /**
   * Firmware flavour declared in the file.
   */
  flavor: string | null,
  /**
   * The slicer's own print-time estimate written in the file, s.
   */
  slicer_time_s: number | null,
};

/**
 * Which filter smooths the orientation.
 */
export type FilterKind = "zero-phase-moving-average" | "zero-phase-median" | "moving-average" | "median";

/**
 * How one file measures against the budget.
 */
export type FirmwareFigures = {
  /**
   * Lines of the file.
   */
  lines: number,
  /**
   * Bytes of the file.
   */
  bytes: number,
  /**
   * Moves that print (`G1` with extrusion, `G2`/`G3`).
   */
  printing_segments: number,
  /**
   * Printing segments shorter than 0.1 mm.
   */
  segments_under_0_1mm: number,
  /**
   * Printing segments whose planned time is under the minimum segment time.
   */
  segments_under_min_time: number,
  /**
   * Most moves the planner runs in any 1 s of planned time.
   */
  peak_segments_per_s: number,
  /**
   * Segments per second the firmware reads at this file's mean bytes per move line.
   */
  budget_segments_per_s: number,
};

/**
 * Both files against the machine's budget, for the report.
 */
export type FirmwareReport = {
  /**
   * The budget they are measured against.
   */
  budget: SegmentBudget,
  /**
   * The original.
   */
  before: FirmwareFigures,
  /**
   * The rewrite.
   */
  after: FirmwareFigures,
  /**
   * Set when the rewrite's peak segment rate exceeds the budget where the original's did
   * not, or exceeds it by more.
   */
  warning: string | null,
};

/**
 * How `E_fuse` was computed.
 */
export type FuseReport = {
  /**
   * Material.
   */
  material: Material,
  /**
   * Where the material came from.
   */
  material_source: MaterialSource,
  /**
   * Properties used.
   */
  properties: MaterialProperties,
  /**
   * Printing temperature used (the highest hotend target in the file, else the
   * material's), °C.
   */
  print_temp_c: number,
  /**
   * Ambient temperature, °C.
   */
  ambient_c: number,
  /**
   * Share of the heater's extra energy that reaches the filament.
   */
  heater_efficiency: number,
};

/**
 * Which heater a temperature command addresses.
 */
export type Heater = {
  "hotend": number
} | "bed" | "chamber";

/**
 * The chosen result.
 */
export type InfillBest = {
  /**
   * Pattern (the most used one for a per-layer result), or `original` when the input is
   * kept.
   */
  pattern: InfillChoice,
  /**
   * Infill angle, degrees.
   */
  angle_deg: number,
  /**
   * Part rotation, degrees.
   */
  rotation_deg: number,
  /**
   * Thesis stepper energy, J.
   */
  thesis_j: number,
  /**
   * Total energy, J.
   */
  total_j: number,
  /**
   * Print time, s.
   */
  time_s: number,
  /**
   * Toolpath length, mm.
   */
  length_mm: number,
  /**
   * `before.total_j − total_j`, J.
   */
  saving_j: number,
  /**
   * Saving in percent of `before.total_j`.
   */
  saving_pct: number,
  /**
   * Per-layer choices when `per_layer` was asked and beat the single best.
   */
  layers: Array<InfillLayerChoice> | null,
  /**
   * Why the original was kept, or that a worse candidate was forced; `None` when the
   * written candidate beats the original.
   */
  message: string | null,
};

/**
 * One candidate: the whole file with this pattern, angle and rotation.
 */
export type InfillCandidate = {
  /**
   * Pattern.
   */
  pattern: InfillPattern,
  /**
   * Whether the costs are an estimate from a sample of layers (a candidate ruled out as
   * clearly worse than the best; never chosen) rather than the whole file's.
   */
  estimated: boolean,
  /**
   * Infill angle, degrees (machine frame).
   */
  angle_deg: number,
  /**
   * Part rotation about Z, degrees.
   */
  rotation_deg: number,
  /**
   * Thesis stepper energy of the whole file (thesis eq. 28), J.
   */
  thesis_j: number,
  /**
   * Total energy of the whole file, J.
   */
  total_j: number,
  /**
   * Print time, s.
   */
  time_s: number,
  /**
   * Toolpath length (printing and travel), mm.
   */
  length_mm: number,
  /**
   * Filament, mm.
   */
  filament_mm: number,
  /**
   * Length of the new infill strokes, mm (`L_infill`, VTG eq. 25; VTG Fig. 4).
   */
  infill_length_mm: number,
  /**
   * Turning points of the new infill (turns above 30°, VTG eq. 26's δθ; Fig. 5).
   */
  infill_turning_points: number,
  /**
   * Mean turning angle of the new infill, degrees (VTG eq. 26; Fig. 5).
   */
  infill_mean_turn_deg: number,
};

/**
 * What was written: a regenerated pattern, or the original file kept as it was.
 */
export type InfillChoice = "original" | InfillPattern;

/**
 * A layer's choice in a per-layer (hybrid) result.
 */
export type InfillLayerChoice = {
  /**
   * Layer index.
   */
  layer: number,
  /**
   * Pattern, or `original` for a layer that keeps the file's own infill (no candidate beat
   * it on that layer).
   */
  pattern: InfillChoice,
  /**
   * Infill angle, degrees.
   */
  angle_deg: number,
};

/**
 * What the method measured from the file.
 */
export type InfillMeasured = {
  /**
   * Rectilinear-equivalent line spacing, mm.
   */
  spacing_mm: number,
  /**
   * Distance from the innermost wall's centre line to the infill line ends, mm.
   */
  clearance_mm: number,
  /**
   * Filament per mm of infill line.
   */
  e_per_mm: number,
  /**
   * Layers whose sparse infill is regenerated.
   */
  layers_regenerated: number,
  /**
   * Sparse-infill blocks replaced.
   */
  blocks: number,
  /**
   * Infill print feed, mm/s.
   */
  print_feed_mm_s: number,
  /**
   * Travel feed, mm/s.
   */
  travel_feed_mm_s: number,
  /**
   * Retraction length, mm (0: none).
   */
  retract_mm: number,
};

/**
 * Options of [`infill`]. Every field is optional in JSON.
 */
export type InfillOptions = Partial<{
  /**
   * How the file is read and costed (machine, junction model, energy).
   */
  analyze: AnalyzeOptions,
  /**
   * Infill angles to try, degrees in the machine frame (default 0, 15, …, 165).
   */
  angles_deg: Array<number>,
  /**
   * Part rotations about Z to try, degrees (default 0 only: the part stays where it is).
   */
  rotations_deg: Array<number>,
  /**
   * Patterns to try (default: the thesis's five, Table 4).
   */
  patterns: Array<InfillPattern>,
  /**
   * What to minimise.
   */
  objective: Objective,
  /**
   * Weights of [`Objective::Weighted`].
   */
  weights: Weights,
  /**
   * After the search, pick pattern and angle layer by layer (the thesis's hybrid), keeping
   * the best rotation.
   */
  per_layer: boolean,
  /**
   * Rectilinear-equivalent line spacing, mm (default: measured from the file).
   */
  spacing_mm: number | null,
  /**
   * Write the best candidate even when it does not beat the original on the objective
   * (default false: the original is kept and the report says so).
   */
  force_candidate: boolean,
  /**
   * Rewrite the file's time comments and `M73` lines from the planner when a candidate is
   * written (default true; see [`crate::estimate`]).
   */
  estimates: boolean,
  /**
   * Cost every candidate on the whole file (default false: a candidate whose estimate from
   * a sample of layers is clearly worse than the best so far is listed with that estimate,
   * `estimated: true`, and not costed whole; the DOE table sets it).
   */
  exhaustive: boolean,
}>;

/**
 * An infill pattern.
 */
export type InfillPattern = "rectilinear" | "grid" | "triangles" | "tri_hexagon" | "concentric" | "hilbert" | "archimedean_chords" | "octagram_spiral" | "cross_line";

/**
 * Result of [`infill`].
 */
export type InfillReport = {
  /**
   * `analyze` of the input.
   */
  before: Report,
  /**
   * `analyze` of the output.
   */
  after: Report,
  /**
   * The chosen candidate.
   */
  best: InfillBest,
  /**
   * Every candidate costed, in search order.
   */
  candidates: Array<InfillCandidate>,
  /**
   * Candidates not costed because their geometry is the same as an earlier one's (a
   * concentric pattern at another angle, a rotation that gives the same strokes).
   */
  candidates_skipped: number,
  /**
   * Candidates ruled out on a sample of layers (listed with `estimated: true`).
   */
  candidates_estimated: number,
  /**
   * What was measured from the file.
   */
  measured: InfillMeasured,
  /**
   * Rotations skipped (the part would not fit on the bed), degrees.
   */
  rotations_skipped: Array<number>,
};

/**
 * Input format of [`smooth`].
 */
export type InputFormat = "auto" | "gcode" | "csv" | "json";

/**
 * How junction speeds between consecutive moves are limited.
 */
export type JunctionModel = "classic_jerk" | "junction_deviation" | "klipper";

/**
 * The limits VTG eq. 30 is built from.
 */
export type KinematicLimits = {
  /**
   * Highest feed rate `v_max`, mm/s.
   */
  v_max_mm_s: number,
  /**
   * Interpolation period `T_s`, s.
   */
  interpolation_period_s: number,
  /**
   * Chord tolerance `δ`, mm.
   */
  chord_tolerance_mm: number,
  /**
   * Normal acceleration limit `A_n`, mm/s².
   */
  normal_accel_mm_s2: number,
  /**
   * Normal jerk limit `J_n`, mm/s³.
   */
  normal_jerk_mm_s3: number,
  /**
   * Nozzle radius `R_n`, mm.
   */
  nozzle_radius_mm: number,
};

/**
 * Which machine layout the rotary axes have.
 */
export type KinematicModel = "table-bc" | "head-ab";

/**
 * A kinematic model with its geometry.
 */
export type Kinematics = Partial<{
  /**
   * Machine layout (default `table-bc`).
   */
  model: KinematicModel,
  /**
   * `table-bc`: a point on the B axis (direction +Y), machine coordinates, mm.
   */
  b_axis_point_mm: [number, number, number],
  /**
   * `table-bc`: a point on the C axis (direction +Z) when B = 0, machine coordinates, mm.
   */
  c_axis_point_mm: [number, number, number],
  /**
   * `head-ab`: distance from the nozzle tip up to the pivot point the controller programs, mm.
   */
  pivot_length_mm: number,
}>;

/**
 * The motion settings of a Klipper config. `None`: not in the file (Klipper's default then
 * applies, or the profile's where Klipper has none).
 */
export type KlipperConfig = Partial<{
  /**
   * `[printer] kinematics`.
   */
  kinematics: string | null,
  /**
   * `[printer] max_velocity`, mm/s.
   */
  max_velocity: number | null,
  /**
   * `[printer] max_accel`, mm/s².
   */
  max_accel: number | null,
  /**
   * `[printer] minimum_cruise_ratio`.
   */
  minimum_cruise_ratio: number | null,
  /**
   * `[printer] max_accel_to_decel`, mm/s² (older Klipper).
   */
  max_accel_to_decel: number | null,
  /**
   * `[printer] square_corner_velocity`, mm/s.
   */
  square_corner_velocity: number | null,
  /**
   * `[printer] max_z_velocity`, mm/s.
   */
  max_z_velocity: number | null,
  /**
   * `[printer] max_z_accel`, mm/s².
   */
  max_z_accel: number | null,
  /**
   * `[extruder] max_extrude_only_velocity`, mm/s.
   */
  max_extrude_only_velocity: number | null,
  /**
   * `[extruder] max_extrude_only_accel`, mm/s².
   */
  max_extrude_only_accel: number | null,
  /**
   * `[extruder] instantaneous_corner_velocity`, mm/s.
   */
  instantaneous_corner_velocity: number | null,
  /**
   * `[extruder] nozzle_diameter`, mm.
   */
  nozzle_diameter: number | null,
  /**
   * `[extruder] filament_diameter`, mm.
   */
  filament_diameter: number | null,
  /**
   * `[gcode_arcs] resolution`, mm (the section present without it: Klipper's 1 mm).
   */
  arc_resolution: number | null,
  /**
   * `[firmware_retraction] retract_length`, mm.
   */
  retract_length: number | null,
  /**
   * `[firmware_retraction] retract_speed`, mm/s.
   */
  retract_speed: number | null,
  /**
   * `[firmware_retraction] unretract_extra_length`, mm.
   */
  unretract_extra_length: number | null,
  /**
   * `[firmware_retraction] unretract_speed`, mm/s.
   */
  unretract_speed: number | null,
}>;

/**
 * What Klipper's version does with `max_accel_to_decel`: older Klipper (v0.12, and the
 * firmware of Creality's K1 family) takes it as an absolute rate; current Klipper (since
 * 2025-08) ignores it and smooths with `minimum_cruise_ratio` only.
 */
export type KlipperVersion = "legacy" | "current";

/**
 * The family of layer-change marker a file uses. A file is counted by the first family seen,
 * so a file that writes both `;LAYER_CHANGE` and `;LAYER:n` is not counted twice.
 */
export type LayerMarkerKind = "layer_change" | "cura_layer" | "simplify3d" | "kis_slicer" | "kiri_moto";

/**
 * Per-layer toolpath metrics before and after.
 */
export type LayerMetrics = {
  /**
   * Layer index.
   */
  index: number,
  /**
   * Before.
   */
  before: ToolpathMetrics,
  /**
   * After.
   */
  after: ToolpathMetrics,
};

/**
 * How the layer count was obtained.
 */
export type LayerSource = {
  "method": "markers",
  "marker": LayerMarkerKind
} | {
  "method": "z_changes"
};

/**
 * Totals for one layer.
 */
export type LayerSummary = {
  /**
   * 0-based layer index.
   */
  index: number,
  /**
   * Z of the layer, mm (the marker's, else the first extrusion's).
   */
  z: number | null,
  /**
   * 1-based line where the layer starts.
   */
  line: number,
  /**
   * Moves in the layer.
   */
  moves: number,
  /**
   * Path length while extruding, mm.
   */
  extrude_distance_mm: number,
  /**
   * Path length of travel, mm.
   */
  travel_distance_mm: number,
  /**
   * Net filament, mm.
   */
  filament_mm: number,
  /**
   * Time, s.
   */
  time_s: number,
  /**
   * Energy, J: `E_servo` of its moves and dwells plus the share of `E_aux` of its time.
   */
  energy_j: number,
};

/**
 * Vibration of one layer (the paper's Fig. 9c).
 */
export type LayerVibration = {
  /**
   * 0-based layer index.
   */
  layer: number,
  /**
   * Layer height, mm.
   */
  z: number | null,
  /**
   * Vibration amplitude: the largest trajectory deviation in the layer, mm.
   */
  amplitude: number,
  /**
   * The largest deviation while extruding in the layer, mm (0 where it prints nothing): the
   * layer's share of the printing peak, which VTG's no-dearer rule holds.
   */
  printing_amplitude: number,
  /**
   * Mean deviation while extruding in the layer, mm (0 where it prints nothing).
   */
  printing_mean: number,
  /**
   * Samples taken while extruding in the layer (one per `T_s`): the weight of its
   * `printing_mean` in the file's.
   */
  printing_samples: number,
  /**
   * Mean deviation in the layer, mm.
   */
  mean: number,
  /**
   * RMS of the table's acceleration in the layer, m/s².
   */
  acceleration_rms: number,
};

/**
 * One limit value with its origin.
 */
export type Limit = {
  /**
   * The value (mm/s, mm/s², mm or a ratio).
   */
  value: number,
  /**
   * Where it came from.
   */
  source: LimitSource,
};

/**
 * Where a limit's current value came from.
 */
export type LimitSource = "profile" | "slicer_settings" | "printer_config" | "machine_settings" | "command" | "option";

/**
 * The motion limits in force. Axis arrays are X, Y, Z, E.
 */
export type Limits = {
  /**
   * Maximum feed rate per axis, mm/s (`M203`).
   */
  max_feedrate: [Limit, Limit, Limit, Limit],
  /**
   * Maximum acceleration per axis, mm/s² (`M201`).
   */
  max_acceleration: [Limit, Limit, Limit, Limit],
  /**
   * Acceleration for printing moves, mm/s² (`M204 P`, or `S`).
   */
  acceleration: Limit,
  /**
   * Acceleration for E-only moves, mm/s² (`M204 R`).
   */
  retract_acceleration: Limit,
  /**
   * Acceleration for travel moves, mm/s² (`M204 T`, or `S`).
   */
  travel_acceleration: Limit,
  /**
   * Classic jerk per axis, mm/s (`M205 X Y Z E`, RepRapFirmware `M566` in mm/min).
   */
  max_jerk: [Limit, Limit, Limit, Limit],
  /**
   * Junction deviation, mm (`M205 J`).
   */
  junction_deviation: Limit,
  /**
   * Klipper square-corner velocity, mm/s.
   */
  square_corner_velocity: Limit,
  /**
   * Klipper `minimum_cruise_ratio`: a chain of moves is smoothed as if it sped up and
   * braked at accel (1 − ratio). Used when `accel_to_decel` is 0.
   */
  minimum_cruise_ratio: Limit,
  /**
   * Older Klipper's `max_accel_to_decel`, mm/s², the smoothed rate itself (at most the
   * acceleration in force); 0 when the cruise ratio applies instead. Creality's Klipper
   * (K1 series) and the slicers written for it set it apart from the acceleration, before
   * it (`SET_VELOCITY_LIMIT ACCEL_TO_DECEL=18000` then `M204 S20000`): as a ratio of the
   * acceleration then in force it would mean something else.
   */
  accel_to_decel: Limit,
  /**
   * Minimum feed rate of printing moves, mm/s (`M205 S`).
   */
  min_feedrate: Limit,
  /**
   * Minimum feed rate of travel moves, mm/s (`M205 T`).
   */
  min_travel_feedrate: Limit,
  /**
   * Length of the straight segments arcs are split into, mm.
   */
  arc_segment_mm: Limit,
  /**
   * How a Marlin-family firmware cuts arcs into segments of at most `arc_segment_mm`.
   */
  arc_rule?: ArcRule,
  /**
   * Klipper's `[extruder] instantaneous_corner_velocity`, mm/s: the largest step in filament
   * speed a junction may ask of the extruder. Unset: Klipper's default,
   * [`KLIPPER_INSTANT_CORNER_V`](super::junction::KLIPPER_INSTANT_CORNER_V) (and not in the
   * report, which is unchanged for every file that sets no Klipper config).
   */
  instantaneous_corner_velocity?: Limit | null,
};

/**
 * The drives of the X and Y axes (Z moves only between layers and is taken as rigid).
 */
export type MachineDynamics = {
  /**
   * Short name.
   */
  name: string,
  /**
   * X drive.
   */
  x: Drive,
  /**
   * Y drive.
   */
  y: Drive,
};

/**
 * The machine a file was planned for.
 */
export type MachineInfo = {
  /**
   * Profile name.
   */
  profile: string,
  /**
   * Junction model used.
   */
  junction_model: JunctionModel,
  /**
   * Why this profile and model.
   */
  reason: string,
  /**
   * Limits in force at the first printing move, each with where it came from.
   */
  limits: Limits,
};

/**
 * A machine profile.
 */
export type MachineProfile = {
  /**
   * Short name (`prusa-mk3s`).
   */
  name: string,
  /**
   * What the machine is.
   */
  description: string,
  /**
   * Junction model its firmware uses.
   */
  junction: JunctionModel,
  /**
   * Motion limits.
   */
  limits: Limits,
};

/**
 * A filament material with built-in properties.
 */
export type Material = "pla" | "petg" | "abs";

/**
 * What `E_fuse` and the material part of VTG eq. 17 need to know about a material.
 */
export type MaterialProperties = {
  /**
   * Mean specific heat from room to printing temperature, J/(g·K).
   */
  specific_heat_j_gk: number,
  /**
   * Heat of fusion of the fully crystalline polymer, J/g (0 for amorphous polymers).
   */
  heat_of_fusion_j_g: number,
  /**
   * Crystalline fraction of the filament, 0..=1.
   */
  crystallinity: number,
  /**
   * Printing temperature used when the file sets no hotend temperature, °C.
   */
  print_temp_c: number,
  /**
   * Cradle-to-gate emission factor of the material, kg CO₂e per kg.
   */
  co2_kg_per_kg: number,
};

/**
 * Where the material came from.
 */
export type MaterialSource = "option" | "file" | "default";

/**
 * One vibration mode.
 */
export type Mode = {
  /**
   * Undamped natural frequency `ωₙ / 2π`, Hz.
   */
  frequency_hz: number,
  /**
   * Damping ratio `ζ`.
   */
  damping_ratio: number,
};

/**
 * Where the initial extrusion mode came from.
 */
export type ModeSource = "explicit" | "inferred" | "default";

/**
 * What the search minimises.
 */
export type Objective = "energy" | "time" | "length" | "weighted";

/**
 * One observation: the terms of a print and its measured energy.
 */
export type Observation = {
  /**
   * Where it came from (1-based line of the CSV, or position in a list), for errors and
   * residuals.
   */
  row?: number,
  /**
   * `A`, (mm/s)².
   */
  a: number,
  /**
   * `B`, (mm/s)².
   */
  b: number,
  /**
   * `C`, mm.
   */
  c: number,
  /**
   * `H`, s.
   */
  h: number,
  /**
   * Measured energy, W·ms.
   */
  e: number,
};

/**
 * Options of [`optimize`]. Every field is optional in JSON.
 */
export type OptimizeOptions = Partial<{
  /**
   * How the file is read and the machine it runs on; every stage uses these.
   */
  analyze: AnalyzeOptions,
  /**
   * Run the infill search first with these options (default: off). Its `analyze` is
   * replaced by the one above.
   */
  infill: InfillOptions | null,
  /**
   * Run VTG (default true).
   */
  vtg: boolean,
  /**
   * VTG's options (default: VTG's). Its `analyze`, `arcs` and `allow_slower_pct` are
   * replaced by this pipeline's.
   */
  vtg_options: VtgOptions,
  /**
   * Print time VTG may add to round corners, percent (default 0: the pipeline never
   * trades time for corners; every stage must also leave the file no slower).
   */
  allow_slower_pct: number,
  /**
   * Arcs in VTG's output: `auto` (default) writes them where the firmware runs them.
   */
  arcs: ArcsMode,
  /**
   * Rewrite the time comments and `M73` lines (default true).
   */
  estimates: boolean,
}>;

/**
 * Result of [`optimize`].
 */
export type OptimizeReport = {
  /**
   * `analyze` of the input.
   */
  before: Report,
  /**
   * `analyze` of the output.
   */
  after: Report,
  /**
   * Each stage in order.
   */
  stages: Array<OptimizeStage>,
  /**
   * The estimates written, when asked.
   */
  estimates: EstimateReport | null,
};

/**
 * One stage's outcome.
 */
export type OptimizeStage = {
  /**
   * `infill`, `vtg` or `estimates`.
   */
  stage: string,
  /**
   * Whether the stage's file was kept.
   */
  applied: boolean,
  /**
   * What it did, or why its file was not kept.
   */
  message: string,
  /**
   * Print time before and after the stage, s.
   */
  time_s: [number, number],
  /**
   * Total energy before and after the stage, J.
   */
  energy_j: [number, number],
  /**
   * Lines before and after the stage.
   */
  lines: [number, number],
};

/**
 * Orientation metrics of a set of runs.
 */
export type OrientationMetrics = {
  /**
   * Orientation roughness: root mean square of the second difference of the unit tool
   * vector, `‖T_{m+1} − 2 T_m + T_{m−1}‖`, over the interior points of every run (consecutive
   * points of one continuous path; the discrete curvature the CIRP paper's filters act on).
   */
  roughness: number,
  /**
   * Mean of the same norm.
   */
  mean_second_difference: number,
  /**
   * Largest second-difference norm.
   */
  max_second_difference: number,
  /**
   * Mean angle between consecutive tool vectors, degrees.
   */
  mean_angle_change_deg: number,
  /**
   * Largest angle between consecutive tool vectors, degrees.
   */
  max_angle_change_deg: number,
  /**
   * Mean angle change per millimetre of tool-tip path, °/mm (segments longer than 1 µm).
   */
  mean_angle_change_per_mm_deg: number,
  /**
   * Largest angle change per millimetre, °/mm.
   */
  max_angle_change_per_mm_deg: number,
  /**
   * The two rotary axes.
   */
  rotary: Array<RotaryMetrics>,
};

/**
 * What the rewrite did to the paths.
 */
export type PathCounts = {
  /**
   * Extrusion paths with a turn above the critical angle.
   */
  candidates: number,
  /**
   * Of those, paths rewritten (the rest could not be rounded within the tolerance, or their
   * lines could not be replaced safely, and were kept).
   */
  rewritten: number,
  /**
   * Moves replaced.
   */
  replaced_moves: number,
  /**
   * Moves written in their place.
   */
  written_moves: number,
  /**
   * Written segments whose curvature is above `K_cr`.
   */
  above_k_cr_segments: number,
  /**
   * Of those, segments written with a lower feed rate (VTG eq. 29).
   */
  lowered_feed_segments: number,
  /**
   * Rewritten paths whose VTG eq. 29 speeds were raised (up to 3×) so they cost no time.
   */
  raised_caps: number,
  /**
   * Rewritten paths written without the VTG eq. 29 feed caps because even raised they would
   * have made them slower than the original (the firmware's own cornering sets their
   * speed).
   */
  uncapped: number,
  /**
   * Rewritten paths that plan slower, or cost more motor energy, than the original even
   * without caps, paid for out of half of what the other rewrites saved (a firmware that
   * takes sharp corners faster than any fillet within the tolerance allows). With
   * `allow_slower_pct`, also those bought with the time it allows.
   */
  paid_from_savings: number,
  /**
   * Paths like those that the savings could not pay for, kept as they were.
   */
  kept_for_time: number,
  /**
   * Paths kept as they were because rounding them would add more lines than the file's
   * line budget had left (`allow_more_lines_pct`).
   */
  kept_for_lines: number,
  /**
   * Paths without sharp corners written with arcs, as their own points lie, for the lines
   * they save (only as many as the corners rounded elsewhere need).
   */
  compacted: number,
  /**
   * Mean speed fluctuation of the interpolation steps, percent (VTG eq. 28).
   */
  mean_speed_fluctuation_pct: number,
  /**
   * The scale the VTG eq. 29 speeds of every rewrite started from: 1, or higher where the
   * dynamics model found that the rewrite at 1 left the machine ringing more than the
   * original (see [`crate::vtg::VtgOptions::dynamics`]).
   */
  feed_cap_scale: number,
  /**
   * Whether the walked steps were joined up to the firmware's segment budget
   * ([`crate::vtg::VtgOptions::min_segment_time_ms`]); `false` where the dynamics model
   * found the joined rewrite ringing more than the original and the steps as walked
   * quieter (see [`crate::vtg::VtgOptions::dynamics`]).
   */
  steps_joined: boolean,
  /**
   * Whether a segment that joins walked steps was also offered the VTG eq. 29 speed of the
   * stretch it stands for (its mean curvature), not only that of the tightest of its steps:
   * `true` where, with the dynamics model, that rewrite kept the no-dearer rule and left
   * fewer sharp corners (see [`crate::vtg::VtgOptions::dynamics`]).
   */
  stretch_caps: boolean,
  /**
   * Arcs (`G2`/`G3`) written (with the `arcs` option), each in place of several steps.
   */
  arcs_written: number,
  /**
   * Single corners too tight to fillet that were turned round a keyhole loop instead
   * (`keyhole`); 0 where the dynamics model found the loops left the machine
   * ringing more than the original (see [`crate::vtg::VtgOptions::dynamics`]).
   */
  keyholes: number,
};

/**
 * A spectral peak.
 */
export type Peak = {
  /**
   * Frequency, Hz.
   */
  hz: number,
  /**
   * Power spectral density at the peak.
   */
  power: number,
};

/**
 * Welch PSD of the table's acceleration (X and Y spectra summed), (m/s²)²/Hz.
 */
export type Psd = {
  /**
   * Sampling rate, Hz.
   */
  fs_hz: number,
  /**
   * Segment length, samples (the option, or the whole signal when it is shorter).
   */
  window: number,
  /**
   * Window function.
   */
  window_kind: SpectrumWindow,
  /**
   * Overlap between segments, samples.
   */
  overlap: number,
  /**
   * Segments averaged.
   */
  segments: number,
  /**
   * Bin frequencies, Hz.
   */
  freqs: Array<number>,
  /**
   * Power spectral density per bin.
   */
  power: Array<number>,
  /**
   * Highest local maxima, highest first.
   */
  peaks: Array<Peak>,
};

/**
 * Everything `analyze` says about a file.
 */
export type Report = {
  /**
   * quietpath version that made the report.
   */
  version: string,
  /**
   * Facts about the file itself.
   */
  file: FileInfo,
  /**
   * Estimated print time, s (the planned moves, plus dwells).
   */
  time_s: number,
  /**
   * Time spent in dwells (`G4`), s: included in `time_s`. (PrusaSlicer's estimate leaves
   * dwells out, so comparisons with it subtract this.)
   */
  dwell_s: number,
  /**
   * Homings (`G28`) on Klipper, left out of `time_s` and of the moves: how long homing
   * takes depends on the printer, and no file tells. Each stops the toolhead. Absent when
   * there are none (and on Marlin-style files, where `G28` is timed as a move to 0).
   */
  homing_count?: number,
  /**
   * How `time_s` was computed (`planner`: firmware look-ahead with the junction model below).
   */
  time_model: string,
  /**
   * The machine the file was planned for.
   */
  machine: MachineInfo,
  /**
   * Motion commands that moved something (XYZ, rotary axes or the extruder).
   */
  moves: number,
  /**
   * Of those, moves that laid down material.
   */
  extruding_moves: number,
  /**
   * Layers printed.
   */
  layers: number,
  /**
   * How layers were counted.
   */
  layer_source: LayerSource,
  /**
   * Tool-tip path length, mm (printing and travel).
   */
  distance_mm: number,
  /**
   * Path length while extruding, mm.
   */
  extrude_distance_mm: number,
  /**
   * Path length without extruding, mm.
   */
  travel_distance_mm: number,
  /**
   * Net filament pushed into the nozzle, mm (retractions cancel their recoveries).
   */
  filament_mm: number,
  /**
   * Filament volume, mm³.
   */
  filament_volume_mm3: number,
  /**
   * Filament mass, g.
   */
  material_g: number,
  /**
   * Retraction moves (E going back), including firmware retraction.
   */
  retractions: number,
  /**
   * Extrusion settings used.
   */
  extrusion: ExtrusionInfo,
  /**
   * Bounding box of the printed (extruded) path, or `null` if nothing was extruded.
   */
  bounds: Bounds | null,
  /**
   * Per-feature totals, in order of first appearance; travel last.
   */
  features: Array<FeatureSummary>,
  /**
   * Per-layer totals.
   */
  layer_list: Array<LayerSummary>,
  /**
   * Heater targets over time.
   */
  temperatures: Array<TemperatureEvent>,
  /**
   * Part-cooling fan speeds over time.
   */
  fans: Array<FanEvent>,
  /**
   * Energy models (filled by the energy module).
   */
  energy: Energy,
  /**
   * Toolpath metrics (filled by the VTG module).
   */
  toolpath: ToolpathMetrics,
  /**
   * Problems found, with their line numbers (at most 1000; see `warnings_dropped`).
   */
  warnings: Array<Warning>,
  /**
   * Warnings counted beyond the ones listed.
   */
  warnings_dropped: number,
};

/**
 * One row's fit.
 */
export type Residual = {
  /**
   * Row (as in the input).
   */
  row: number,
  /**
   * Measured energy, W·ms.
   */
  observed: number,
  /**
   * Energy the fit predicts, W·ms.
   */
  predicted: number,
  /**
   * `observed − predicted`, W·ms.
   */
  residual: number,
};

/**
 * Motion of one rotary axis.
 */
export type RotaryMetrics = {
  /**
   * Axis letter.
   */
  axis: string,
  /**
   * Total angle travelled, degrees.
   */
  travel_deg: number,
  /**
   * Largest angular velocity, °/s.
   */
  max_velocity_deg_s: number,
  /**
   * Root-mean-square angular velocity, °/s.
   */
  rms_velocity_deg_s: number,
  /**
   * Largest angular acceleration between consecutive moves, °/s².
   */
  max_acceleration_deg_s2: number,
  /**
   * Root-mean-square angular acceleration, °/s².
   */
  rms_acceleration_deg_s2: number,
  /**
   * Largest angular jerk, °/s³.
   */
  max_jerk_deg_s3: number,
  /**
   * Root-mean-square angular jerk, °/s³.
   */
  rms_jerk_deg_s3: number,
};

/**
 * The segment budget of the machine a file runs on.
 */
export type SegmentBudget = {
  /**
   * Shortest time a segment may last before the firmware slows it when its buffer runs
   * low, s (Marlin's `M205 B`; [`MARLIN_MIN_SEGMENT_TIME_S`] by default). On Klipper,
   * which has none, the same value is the rewrite's target.
   */
  min_segment_time_s: number,
  /**
   * Where `min_segment_time_s` came from: `"file"` (`M205 B`), `"option"` or `"default"`.
   */
  min_segment_time_source: string,
  /**
   * Planner blocks the firmware buffers (Marlin's `BLOCK_BUFFER_SIZE`; 0 on Klipper, which
   * plans on the host).
   */
  block_buffer: number,
  /**
   * Bytes per second the firmware reads (a 115200-baud serial stream by default).
   */
  stream_bytes_per_s: number,
};

/**
 * The position loop that drives the motor: torque
 * `τ = K_p (θ_c − θ_M) + K_d (θ̇_c − θ̇_M) + feed-forward`, where `θ_c` is the commanded position
 * over the transmission ratio. The feed-forward supplies `k_v` of the torque that moves the rigid
 * axis against its viscous damping at the commanded speed and `k_a` of the torque that
 * accelerates its inertia.
 */
export type ServoLoop = {
  /**
   * Position gain `K_p`, N·m/rad (for a stepper: holding torque × rotor teeth).
   */
  stiffness_nm_per_rad: number,
  /**
   * Velocity gain `K_d`, N·m·s/rad.
   */
  damping_nms_per_rad: number,
  /**
   * Velocity feed-forward `k_v`, 0..=1.
   */
  velocity_feedforward: number,
  /**
   * Acceleration (torque) feed-forward `k_a`, 0..=1.
   */
  acceleration_feedforward: number,
};

/**
 * Which model gives `E_servo`.
 */
export type ServoModel = "auto" | "thesis" | "physical";

/**
 * Parameters of the physical servo model. Defaults describe a large-format ball-screw gantry
 * like the VTG paper's printer (1000 × 800 × 350 mm); they are engineering estimates, not
 * measurements, and should be replaced with the machine's own values.
 */
export type ServoProfile = Partial<{
  /**
   * Moving mass per axis X, Y, kg (print head carriage on X; the gantry, which carries X,
   * on Y; ball-screw rotors add their reflected inertia).
   */
  moving_mass_kg: [number, number],
  /**
   * Friction force per axis (linear guides, ball-screw preload, seals), N.
   */
  friction_n: [number, number],
  /**
   * Electrical-to-mechanical efficiency of drive, motor and screw, 0..=1 (ball screws ~0.9,
   * servo motor and amplifier ~0.85–0.9).
   */
  efficiency: number,
  /**
   * Copper-loss coefficient per axis, W per N² of axial force (winding resistance over the
   * square of the force constant through the screw).
   */
  copper_w_per_n2: [number, number],
  /**
   * Power each enabled drive draws at standstill (amplifier logic, holding loop), W.
   */
  standby_w: [number, number],
  /**
   * Fraction of braking energy the drives return, 0..=1.
   */
  regeneration: number,
}>;

/**
 * The physical model's energy, by kind, J.
 */
export type ServoReport = {
  /**
   * Kinetic energy drawn while accelerating (net of regeneration), J.
   */
  kinetic_j: number,
  /**
   * Friction work, J.
   */
  friction_j: number,
  /**
   * Copper losses, J.
   */
  copper_j: number,
  /**
   * Standby draw of the enabled drives, J.
   */
  standby_j: number,
};

/**
 * Options of [`smooth`]. Every field is optional in JSON.
 */
export type SmoothOptions = Partial<{
  /**
   * Kinematic model (default: table-tilting B then rotary C, axes through the origin, as in
   * the corpus 5-axis file).
   */
  kinematics: Kinematics,
  /**
   * G-code: what X, Y, Z are (default machine axes).
   */
  coordinates: Coordinates,
  /**
   * Filter (default: zero-phase moving average, the paper's choice).
   */
  filter: FilterKind,
  /**
   * Window (default: 15 points).
   */
  window: SmoothWindow,
  /**
   * Opening `γ` of the tolerance cone, degrees (default 60, the paper's FFF value); every
   * output vector stays within `γ/2` of its original.
   */
  cone_deg: number,
  /**
   * Keep-out angle around the kinematic singularity (the table's C axis, the head's B = ±90°),
   * degrees; 0 disables. Points whose original vector is inside it are kept as written, and a
   * smoothed vector is kept at least `min(singular_deg, tilt of its original)` away from it.
   * Default (`None`): 6° for G-code (the λ of the corpus file's generator), 0 for point-vector
   * data (a robot cell has no turntable singularity; the kinematics only serve the metrics).
   */
  singular_deg: number | null,
  /**
   * Longest tool-tip step between two points of one continuous path, mm, measured in the
   * workpiece frame (default 5, the jump length of the corpus file's generator). A longer
   * step is a jump to another section: the filter does not average across it (in G-code the
   * jumping move stays as written). Machine-axis travel is no criterion: the table swinging
   * round a corner of the path moves the axes far for a short tip step (CIRP section 2.2).
   */
  max_gap_mm: number,
  /**
   * Decimals written for the rewritten axis words (default 3).
   */
  decimals: number,
  /**
   * Input format (default: detected).
   */
  format: InputFormat,
  /**
   * Point-vector data: feed used for the rotary-axis timing, mm/s (default 6, the paper's
   * 36 cm/min travel speed).
   */
  feed_mm_s: number,
  /**
   * How G-code is read and planned (machine preset, limits).
   */
  analyze: AnalyzeOptions,
  /**
   * Rewrite a G-code file's time comments and `M73` lines from the planner when the file
   * changed (default true; see [`crate::estimate`]).
   */
  estimates: boolean,
}>;

/**
 * What [`smooth`] did.
 */
export type SmoothReport = {
  /**
   * Input format that was read.
   */
  format: InputFormat,
  /**
   * Kinematic model used.
   */
  kinematics: KinematicModel,
  /**
   * What X, Y, Z were read as (G-code).
   */
  coordinates: Coordinates,
  /**
   * Filter used.
   */
  filter: FilterKind,
  /**
   * Window used.
   */
  window: SmoothWindow,
  /**
   * Cone opening `γ`, degrees.
   */
  cone_deg: number,
  /**
   * Motion lines in the input (G-code `G0`/`G1`; point count for point data); the output has
   * the same number.
   */
  motion_lines: number,
  /**
   * Points smoothed (extruding straight moves of G-code).
   */
  points: number,
  /**
   * Continuous runs (paths) they form.
   */
  runs: number,
  /**
   * Points whose smoothed vector left the cone and was put back on its edge (CIRP eq. 7).
   */
  corrected: number,
  /**
   * Lines (points) whose written values changed.
   */
  changed: number,
  /**
   * Largest angle between an output tool vector and its original, degrees (≤ `γ/2`,
   * measured on the written values).
   */
  max_angle_to_original_deg: number,
  /**
   * Mean of the same angle, degrees.
   */
  mean_angle_to_original_deg: number,
  /**
   * Orientation metrics of the input.
   */
  before: OrientationMetrics,
  /**
   * Orientation metrics of the output (G-code: re-read and re-planned).
   */
  after: OrientationMetrics,
  /**
   * `1 − after.roughness / before.roughness` (0 when there is nothing to smooth).
   */
  roughness_reduction: number,
  /**
   * Largest tool-tip displacement in the workpiece frame between input and output, mm (only
   * the rounding of the written words).
   */
  max_tip_deviation_mm: number,
  /**
   * G-code: the input's planned print time, s (quietpath's planner limits X, Y, Z and E).
   */
  planned_time_before_s: number,
  /**
   * G-code: the output's planned print time, s. Without RTCP the feed applies to the machine
   * XYZ motion, and smoother orientation needs less compensating XYZ motion, so the output
   * usually plans faster. The planner knows no rotary-axis limits, so a rewritten move whose
   * XYZ motion shrinks would get an unbounded rotary speed; the rotary rates in
   * [`SmoothReport::before`] and [`SmoothReport::after`] are therefore both measured on the
   * tool tip's planned schedule (the file's X, Y, Z replaced by the tip, as an RTCP
   * controller runs it; the same for both files, whose tips agree within rounding).
   */
  planned_time_after_s: number,
  /**
   * Per-point rotary angles for a chart.
   */
  series: SmoothSeries,
  /**
   * Warnings met while reading.
   */
  warnings: Array<Warning>,
};

/**
 * Rotary angles per point before and after, decimated to at most [`SERIES_MAX`] points (for a
 * chart). `first_*` is the tilt axis (`axes[0]`), `second_*` the other.
 */
export type SmoothSeries = {
  /**
   * Axis letters, e.g. `["B", "C"]`.
   */
  axes: Array<string>,
  /**
   * Index of each kept point among all smoothed points.
   */
  point: Array<number>,
  /**
   * First rotary axis before, degrees.
   */
  first_before: Array<number>,
  /**
   * First rotary axis after, degrees.
   */
  first_after: Array<number>,
  /**
   * Second rotary axis before, degrees.
   */
  second_before: Array<number>,
  /**
   * Second rotary axis after, degrees.
   */
  second_after: Array<number>,
  /**
   * Angle between the tool vector after and before, degrees.
   */
  angle_to_original_deg: Array<number>,
};

/**
 * Filter window.
 */
export type SmoothWindow = {
  "points": number
} | {
  "millimetres": number
};

/**
 * Window function applied to each segment.
 */
export type SpectrumWindow = "hamming" | "hann" | "rectangular";

/**
 * The paper's Table 1: toolpath parameters before and after.
 */
export type Table1 = {
  /**
   * `L_total`, mm.
   */
  l_total_mm: Comparison,
  /**
   * `n_total`.
   */
  n_total: Comparison,
  /**
   * `L_infill`, mm.
   */
  l_infill_mm: Comparison,
  /**
   * `n_infill`.
   */
  n_infill: Comparison,
  /**
   * `n_turning` (turns above the critical angle).
   */
  n_turning: Comparison,
  /**
   * Mean turning angle, degrees.
   */
  mean_turn_deg: Comparison,
  /**
   * `mean(e_c)`, mm.
   */
  mean_chord_error_mm: Comparison,
};

/**
 * The paper's Table 2: kinematic and energy performance before and after.
 */
export type Table2 = {
  /**
   * Simulated toolpath deviation (dynamics model); `null` until that model is run.
   */
  deviation: DeviationComparison | null,
  /**
   * Total energy `E`, J (VTG eq. 16).
   */
  energy_j: Comparison,
  /**
   * Servo (X/Y drive) energy, J.
   */
  servo_energy_j: Comparison,
  /**
   * Material, g.
   */
  material_g: Comparison,
  /**
   * Carbon emission, g CO₂ (VTG eq. 17).
   */
  co2_g: Comparison,
  /**
   * Print time, s.
   */
  time_s: Comparison,
};

/**
 * A heater target set at some point of the print.
 */
export type TemperatureEvent = {
  /**
   * 1-based line.
   */
  line: number,
  /**
   * Print time at that line, s.
   */
  time_s: number,
  /**
   * Which heater.
   */
  heater: Heater,
  /**
   * Target, °C.
   */
  target_c: number,
  /**
   * Whether the printer waits for it.
   */
  wait: boolean,
};

/**
 * The regression coefficients of thesis eq. 28. Units make `E` come out in W·ms:
 * `k_a_mx`, `k_a_my` in W·ms per (mm/s)², `k_c` in W·ms per mm, `k_h` in W·ms per s (so
 * `k_h` = 832.7 is 0.83 W of holding power per axis).
 */
export type ThesisCoefficients = {
  /**
   * `k_a·m_x`: acceleration factor of X.
   */
  k_a_mx: number,
  /**
   * `k_a·m_y`: acceleration factor of Y.
   */
  k_a_my: number,
  /**
   * `k_c`: coasting factor (both axes).
   */
  k_c: number,
  /**
   * `k_h`: holding factor (both axes).
   */
  k_h: number,
};

/**
 * The sums `A`, `B`, `C`, `H` over a file, and the coefficients they are weighed with.
 */
export type ThesisReport = {
  /**
   * `A`: X acceleration/deceleration term (thesis eq. 24), (mm/s)².
   */
  a: number,
  /**
   * `B`: Y acceleration/deceleration term (thesis eq. 25), (mm/s)².
   */
  b: number,
  /**
   * `C`: coasting distance of X and Y (thesis eq. 26), mm.
   */
  c: number,
  /**
   * `H`: holding time of X and Y (thesis eq. 27), s.
   */
  h: number,
  /**
   * Coefficients used (thesis eq. 28).
   */
  coefficients: ThesisCoefficients,
  /**
   * `E` in the thesis's unit, W·ms.
   */
  e_wms: number,
  /**
   * Seconds X and Y spend accelerating or decelerating (both axes counted), for
   * diagnosis: the thesis's finding is that this time drives the energy.
   */
  accel_decel_s: number,
  /**
   * Seconds X and Y spend coasting (both axes counted).
   */
  coast_s: number,
};

/**
 * Toolpath metrics of a file or a layer (VTG eq. 24–26, 31).
 */
export type ToolpathMetrics = {
  /**
   * Printed path length `L_total`, mm (VTG eq. 24).
   */
  l_total_mm: number,
  /**
   * Printed infill length `L_infill`, mm (VTG eq. 25).
   */
  l_infill_mm: number,
  /**
   * Trajectory points `n_total`.
   */
  n_total: number,
  /**
   * Infill trajectory points `n_infill`.
   */
  n_infill: number,
  /**
   * Turning points `n_turning`: interior points turning more than the critical angle.
   */
  n_turning: number,
  /**
   * Interior points (where a turning angle is defined).
   */
  n_corners: number,
  /**
   * Mean turning angle ϑ over interior points, degrees (VTG eq. 26).
   */
  mean_turn_deg: number,
  /**
   * Mean chord error `mean(e_c)` over interior points, mm (VTG eq. 31).
   */
  mean_chord_error_mm: number,
  /**
   * Critical angle δθ used, degrees.
   */
  critical_angle_deg: number,
};

/**
 * Options of [`vibration`]. Every field is optional in JSON.
 */
export type VibrationOptions = Partial<{
  /**
   * How the file is read and planned (machine preset, junction model...).
   */
  analyze: AnalyzeOptions,
  /**
   * Interpolation period `T_s`, ms (default 1).
   */
  ts_ms: number,
  /**
   * Accelerometer sampling rate `f_s` for the spectrum, Hz (default 200, the VTG paper's);
   * at most `1000 / ts_ms`. The rate used is `1 / (round(1/(f_s T_s)) T_s)`.
   */
  fs_hz: number,
  /**
   * Welch segment length, samples (default 512, the paper's Hamming window size).
   */
  window: number,
  /**
   * Window function (default Hamming, as in the paper).
   */
  window_kind: SpectrumWindow,
  /**
   * Built-in dynamics parameter set (`ldam-ball-screw`, `desktop-belt`); default: the one
   * that goes with the machine preset ([`parameters::preset_for_machine`]).
   */
  dynamics: string | null,
  /**
   * A whole parameter set (wins over `dynamics`).
   */
  dynamics_parameters: MachineDynamics | null,
  /**
   * Travel over which the position-dependent stiffness is held constant, mm (default 5).
   */
  bucket_mm: number,
  /**
   * Spectral peaks reported (default 5).
   */
  peaks: number,
}>;

/**
 * Result of [`vibration`].
 */
export type VibrationReport = {
  /**
   * Machine profile the file was planned with.
   */
  machine: string,
  /**
   * Dynamics parameter set.
   */
  dynamics: string,
  /**
   * Interpolation period, ms.
   */
  ts_ms: number,
  /**
   * Natural frequencies of both axes (mechanism with its position loop), Hz, ascending.
   */
  natural_frequencies_hz: Array<number>,
  /**
   * Damping ratios of the same modes.
   */
  damping_ratios: Array<number>,
  /**
   * Modes per axis.
   */
  axes: Array<AxisModes>,
  /**
   * Trajectory deviation over the print (every sample of every move), mm.
   */
  deviation_mm: Deviation,
  /**
   * Trajectory deviation while extruding only (what the part sees; travel left out), mm.
   */
  printing_deviation_mm: Deviation,
  /**
   * Per-layer vibration.
   */
  layers: Array<LayerVibration>,
  /**
   * Acceleration spectrum.
   */
  psd: Psd,
  /**
   * Motion time simulated, s (rests are skipped once the machine is still).
   */
  simulated_s: number,
  /**
   * Simulation steps.
   */
  steps: number,
};

/**
 * Options of [`vtg`]. Every field is optional in JSON.
 */
export type VtgOptions = Partial<{
  /**
   * How the file is read and the machine it runs on (as `analyze`).
   */
  analyze: AnalyzeOptions,
  /**
   * Largest distance the new path may stray from the original, mm (default 0.1: under a
   * quarter of a 0.45 mm line width, and the paper's own deviations are 0.14 mm; at 0.05 mm
   * a 90° corner cannot be rounded in turns under 30° and is kept).
   */
  tolerance_mm: number,
  /**
   * Critical angle δθ: turns above it are sharp corners, degrees (default 30).
   */
  critical_angle_deg: number,
  /**
   * Interpolation period `T_s` of VTG eq. 30, s (default 0.001: a 1 kHz firmware step planner).
   */
  interpolation_period_s: number,
  /**
   * Normal jerk limit `J_n` of VTG eq. 29–30, mm/s³. By default the machine's own: `A_n · f₁`,
   * with `f₁` the lowest natural frequency of its X and Y drives in the dynamics model
   * ([`crate::dynamics`], the parameter set that goes with the machine preset). An
   * acceleration that builds up over at least one period of the first mode leaves little
   * ringing behind (the reasoning of jerk-limited motion and input shaping); a rounded
   * corner taken faster delivers its whole change of direction within one period, and
   * excites the frame more than the sharp corner it replaced. For a Prusa-class belt
   * printer (`A_n` 1000 mm/s², 43 Hz) that is 43 m/s³; servo CNC controllers are set to
   * 100–1000 m/s³.
   */
  normal_jerk_mm_s3: number | null,
  /**
   * Nozzle diameter (`R_n` is half of it), mm (default 0.4).
   */
  nozzle_diameter_mm: number,
  /**
   * Lower the feed rate where the curvature exceeds `K_cr` (default true).
   */
  limit_feed: boolean,
  /**
   * Run the dynamics model ([`crate::dynamics`]) on both files for the deviation rows of
   * Table 2, and rewrite again with faster VTG eq. 29 speeds if the rewrite rings more than the
   * original (default true; it costs about as much as the rewrite itself, more when it
   * rewrites again). See `closed_loop::with_simulated_deviation`.
   */
  dynamics: boolean,
  /**
   * Write runs of new points that lie on a circle as arcs (`G2`/`G3`) to cut the line
   * count: `auto` (default) where the firmware runs them ([`ArcsMode::Auto`]: a file that
   * already has arcs, Marlin, RepRapFirmware, Smoothieware and Repetier flavours, Klipper
   * only with `[gcode_arcs]` in the printer config given), `on` or `off`.
   */
  arcs: ArcsMode,
  /**
   * Print time the rewrite may add to round corners that cost time, percent of the
   * original's (default [`DEFAULT_ALLOW_SLOWER_PCT`], the bar). On a machine whose
   * firmware takes sharp corners faster than any fillet within the tolerance (Klipper with a
   * square-corner velocity of 50–100 mm/s) rounding costs time, and motor and standby
   * energy with it: this buys the corners that remove the most sharp turns for their time
   * first, energy weighed in, while the file's energy stays within
   * [`VtgOptions::allow_more_energy_pct`]. Where rounding costs nothing
   * (every Marlin file of the corpus) it changes nothing. 0: the print gets no slower and
   * uses no more energy, the corners that would cost being paid only out of what the other
   * rewrites save. 100 rounds every corner the tolerance allows.
   */
  allow_slower_pct: number,
  /**
   * Total energy the rewrite may add, percent of the original's (default 0: the rewritten
   * file uses no more energy than the original). The time [`VtgOptions::allow_slower_pct`]
   * allows is spent only while the whole file's energy, as `analyze` measures it, stays
   * within this; where it would not, the allowance is cut until it does.
   */
  allow_more_energy_pct: number,
  /**
   * Round corners only on the inside, with fillets tangent to the legs (default false: where
   * the path has room, a corner takes the racing line, easing out by up to the tolerance
   * before it and back after it, round a circle 2.4 times wider at 90°; see
   * `blend::racing`). The racing line moves a wall's edge outward by up to the tolerance
   * near a corner, as the inside fillet moves it inward at the corner; this keeps every
   * new point on or inside the corner's legs.
   */
  inside_corners: boolean,
  /**
   * Rewrite the file's time comments and `M73` lines from the planner when the toolpath
   * changed (default true; see [`crate::estimate`]).
   */
  estimates: boolean,
  /**
   * The firmware's minimum segment time, ms (default: the file's last `M205 B`, else
   * Marlin's 20 ms; see [`firmware::SegmentBudget`]). Algorithm 1's steps are joined up to
   * `v · t_min` wherever the tolerance allows, so the firmware's buffer stays full; 0 joins
   * as far as the tolerance and the turn allow.
   */
  min_segment_time_ms: number | null,
  /**
   * Lines the rewritten file may have over the original's, percent (default 0: never more
   * lines). Each rounded corner is walked in several steps where the original had one
   * vertex; a firmware fed over a serial link or from an SD card reads only so many lines a
   * second, and Marlin slows segments when its planner buffer runs low (see [`firmware`]).
   * The rewrites that save lines pay for those that add them, the corners that cost the
   * fewest lines first; the paths that do not fit are kept as they were (`kept_for_lines`).
   */
  allow_more_lines_pct: number,
  /**
   * Where the dynamics model asks for quieter whole-file variants, write and simulate each
   * whole (default false: on a file of 512 kB and 64 layers or more they race on every
   * eighth layer first, and only the one that rings least there is written whole; the
   * verdict is the whole file's either way). Slower on large files; the corpus files give
   * the same output both ways.
   */
  exhaustive: boolean,
}>;

/**
 * Everything `vtg` says about a rewrite.
 */
export type VtgReport = {
  /**
   * Tolerance asked for, mm.
   */
  tolerance_mm: number,
  /**
   * Largest distance of any written point or segment from the original path, mm (measured on
   * the output polylines, sampled every tolerance/10).
   */
  max_deviation_mm: number,
  /**
   * Critical angle δθ, degrees.
   */
  critical_angle_deg: number,
  /**
   * Critical curvature `K_cr` (VTG eq. 30), 1/mm.
   */
  k_cr_per_mm: number,
  /**
   * The limits `K_cr` is built from.
   */
  limits: KinematicLimits,
  /**
   * What was rewritten.
   */
  paths: PathCounts,
  /**
   * Table 1: toolpath parameters.
   */
  table1: Table1,
  /**
   * Table 2: kinematic and energy performance.
   */
  table2: Table2,
  /**
   * Per-layer toolpath metrics.
   */
  layers: Array<LayerMetrics>,
  /**
   * Analysis of the input.
   */
  before: Report,
  /**
   * Analysis of the output.
   */
  after: Report,
  /**
   * Both files against the machine's segment budget: lines, bytes, short segments, the
   * peak segment rate ([`super::firmware`]); `None` only while the report is assembled.
   */
  firmware: FirmwareReport | null,
  /**
   * Why the original was handed back unchanged, or why some layers were kept as they were,
   * when either happened (`None`: the rewrite is the output as it is).
   */
  message: string | null,
  /**
   * Layers (0-based) kept as they were because, rewritten, they rang above the original's
   * peak deviation in the dynamics model (empty: none).
   */
  peak_layers_kept: Array<number>,
  /**
   * Feed-only lines of the original (`G1 F6000` alone) folded into the moves that read
   * them, or dropped where the next move sets its own feed: the same motion in fewer lines,
   * spent on rounded corners (0 where the original is handed back).
   */
  feed_lines_folded: number,
};

/**
 * A non-fatal problem, reported with its line so the user can look at it.
 */
export type Warning = {
  /**
   * 1-based line number (0 for file-level remarks).
   */
  line: number,
  /**
   * Human-readable message.
   */
  message: string,
};

/**
 * Weights of [`Objective::Weighted`] (each of energy, time, length relative to the original).
 */
export type Weights = Partial<{
  /**
   * Weight of `total_j / before`.
   */
  energy: number,
  /**
   * Weight of `time_s / before`.
   */
  time: number,
  /**
   * Weight of `length_mm / before`.
   */
  length: number,
}>;
