#!/usr/bin/env bash
# VTG on four more models no tuning has seen (tests/fixtures/models/unseen/manifold.scad: a block
# with six bores of three sizes, two bored bosses, a 0.9 mm wall 30 mm tall and a separate tube;
# comb.scad: 24 thin teeth on a spine, a star-shaped grip and an oval ring), sliced eight ways
# under settings the other measurements did not use (support, cubic-subdivision, 3-D honeycomb,
# Archimedean-chords, adaptive-cubic and zigzag infill, a 0.6 mm nozzle with 2.85 mm filament,
# Repetier and RepRap flavours, a Klipper printer, random seams), and two added on 2026-12-06
# (knob.scad: a 36-point knurled ring, a D-shaft bore and a pointer rib; hook.scad: a plate with
# two countersunk holes, a quarter-torus arm and a gusset) sliced six ways (lines, octet, stars,
# concentric and rectilinear infill; Griffin, RepRapFirmware with relative E, Teacup and
# Smoothieware flavours; 0.1 mm layers), then each output checked by
# runs of its own (scripts/vtg-check-independently.py: the input and the output analysed and
# simulated apart from the rewrite). Extra arguments are passed on to `quietpath vtg`.
# Results: docs/measurements/vtg.md ("Parts it was not tuned on").
#
# Needs Debian's `openscad`, `prusa-slicer`, `slic3r` and `cura-engine`, python3 and `make cli`
# (Cura's printer definitions as in scripts/vtg-unseen-parts.sh).
#
#   bash scripts/vtg-fresh-parts.sh [vtg options...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
for tool in openscad prusa-slicer slic3r CuraEngine python3; do
  command -v "$tool" >/dev/null || { echo "missing: $tool (see the comment at the top)" >&2; exit 1; }
done
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
resources="$("$root/scripts/cura-resources.sh" "$work")"
export CURA_ENGINE_SEARCH_PATH="$resources/definitions:$resources/extruders"
for model in manifold comb knob hook; do
  "$root/scripts/openscad-stl.sh" "$work/$model.stl" "$root/tests/fixtures/models/unseen/$model.scad"
done

cura() { # model, output name, settings...
  local model="$1" name="$2"
  shift 2
  CuraEngine slice -j "$resources/definitions/fdmprinter.def.json" \
    -s machine_width=220 -s machine_depth=220 -s machine_height=250 -s center_object=true \
    "$@" -e0 -s machine_nozzle_size="${nozzle:-0.4}" -s material_diameter="${filament:-1.75}" \
    -l "$work/$model.stl" -o "$work/$name.gcode" >/dev/null 2>&1
}
marlin=(-s machine_gcode_flavor="RepRap (Marlin/Sprinkler)")
cura manifold curaengine_manifold_cubicsubdiv_support "${marlin[@]}" -s layer_height=0.16 \
  -s wall_line_count=2 -s infill_sparse_density=20 -s infill_pattern=cubicsubdiv \
  -s support_enable=true -s speed_print=90 -s acceleration_enabled=true \
  -s acceleration_print=1500 -s jerk_enabled=true -s jerk_print=12
cura comb curaengine_comb_zigzag_random_seam "${marlin[@]}" -s layer_height=0.24 \
  -s infill_pattern=zigzag -s infill_sparse_density=40 -s top_bottom_pattern=concentric \
  -s z_seam_type=random -s speed_print=50
nozzle=0.6 filament=2.85 cura manifold curaengine_manifold_reprap_0.6mm \
  -s machine_gcode_flavor="RepRap (RepRap)" -s layer_height=0.28 -s wall_line_count=4 \
  -s line_width=0.6 -s infill_sparse_density=10 -s infill_pattern=grid -s speed_print=100
prusa-slicer --export-gcode --gcode-flavor marlin2 --layer-height 0.12 --perimeters 2 \
  --fill-density 35% --fill-pattern honeycomb --perimeter-generator classic \
  --perimeter-speed 60 --external-perimeter-speed 40 --infill-speed 120 \
  --default-acceleration 1500 --perimeter-acceleration 800 --infill-acceleration 2500 \
  --output "$work/prusaslicer_manifold_honeycomb_accelerations.gcode" "$work/manifold.stl" >/dev/null 2>&1
prusa-slicer --export-gcode --gcode-flavor marlin --layer-height 0.2 --fill-density 100% \
  --fill-pattern rectilinear --top-fill-pattern monotonic --seam-position random \
  --output "$work/prusaslicer_comb_solid_random_seam.gcode" "$work/comb.stl" >/dev/null 2>&1
prusa-slicer --export-gcode --gcode-flavor marlin2 \
  --start-gcode "SET_VELOCITY_LIMIT ACCEL=3000 SQUARE_CORNER_VELOCITY=8
G28
G1 Z5 F3000" \
  --layer-height 0.16 --perimeters 2 --fill-density 25% --fill-pattern adaptivecubic \
  --perimeter-speed 90 --infill-speed 150 \
  --output "$work/prusaslicer-klipper_comb_adaptivecubic.gcode" "$work/comb.stl" >/dev/null 2>&1
slic3r() { # model, output name, options...
  local model="$1" name="$2"
  shift 2
  command slic3r --no-gui --print-center 100,100 --filament-diameter 1.75 --nozzle-diameter 0.4 \
    "$@" --output "$work/$name.gcode" "$work/$model.stl" >/dev/null 2>&1
}
slic3r manifold slic3r_manifold_repetier_3dhoneycomb_support --gcode-flavor repetier \
  --layer-height 0.3 --perimeters 2 --fill-density 20% --fill-pattern 3dhoneycomb --support-material
slic3r comb slic3r_comb_archimedeanchords --gcode-flavor marlin --layer-height 0.2 \
  --perimeters 3 --fill-density 25% --fill-pattern archimedeanchords

cura knob curaengine_knob_lines_accel3000 "${marlin[@]}" -s layer_height=0.2 \
  -s wall_line_count=3 -s infill_pattern=lines -s infill_sparse_density=15 -s speed_print=70 \
  -s acceleration_enabled=true -s acceleration_print=3000 -s jerk_enabled=true -s jerk_print=8
cura hook curaengine_hook_octet_griffin -s machine_gcode_flavor="Griffin" -s layer_height=0.15 \
  -s infill_pattern=octet -s infill_sparse_density=30 -s speed_print=45 -s retraction_combing=off
prusa-slicer --export-gcode --gcode-flavor reprapfirmware --use-relative-e-distances \
  --layer-height 0.2 --fill-density 20% --fill-pattern stars --perimeters 3 \
  --output "$work/prusaslicer_knob_stars_rrf_relE.gcode" "$work/knob.stl" >/dev/null 2>&1
prusa-slicer --export-gcode --gcode-flavor marlin2 --layer-height 0.1 --fill-density 40% \
  --fill-pattern concentric --perimeters 2 --external-perimeters-first --infill-speed 90 \
  --max-print-speed 150 \
  --output "$work/prusaslicer_hook_concentric_0.1.gcode" "$work/hook.stl" >/dev/null 2>&1
slic3r knob slic3r_knob_teacup_line --gcode-flavor teacup --layer-height 0.25 --perimeters 2 \
  --fill-density 30% --fill-pattern line
slic3r hook slic3r_hook_smoothie_rect --gcode-flavor smoothie --layer-height 0.2 \
  --perimeters 3 --fill-density 15% --fill-pattern rectilinear

files=("$work"/*.gcode)
[ "${#files[@]}" -eq 14 ] || { echo "expected 14 slices, got ${#files[@]}" >&2; exit 1; }
python3 "$root/scripts/vtg-check-independently.py" "${files[@]}" ${1:+-- "$@"}
