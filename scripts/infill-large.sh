#!/usr/bin/env bash
# Times the default infill search (the thesis's five patterns x 12 angles) on a large part
# sliced here: the W16-style block (tests/fixtures/models/w16_block.scad, 230 x 195 x 20 mm,
# sixteen bores, 100 layers), PrusaSlicer with 5 perimeters and 70 % rectilinear infill at 45°,
# about 23.5 MB. The G-code is too large to commit, so it is made in a temporary folder.
# Needs Debian's `openscad` and `prusa-slicer`, and `make cli`.
#
#   bash scripts/infill-large.sh [extra quietpath infill options...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
openscad -o "$work/w16.stl" "$root/tests/fixtures/models/w16_block.scad" >/dev/null 2>&1
prusa-slicer --export-gcode --machine-limits-usage emit_to_gcode --remaining-times \
  --nozzle-diameter 0.4 --filament-diameter 1.75 --temperature 215 --bed-temperature 60 \
  --bed-shape 0x0,250x0,250x210,0x210 --center 125,105 --skirts 0 --first-layer-height 0.2 \
  --gcode-flavor marlin2 --use-relative-e-distances --layer-gcode "G92 E0" \
  --layer-height 0.2 --perimeters 5 --fill-pattern rectilinear --fill-density 70% \
  --fill-angle 45 --top-solid-layers 3 --bottom-solid-layers 3 \
  --output "$work/w16.gcode" "$work/w16.stl" >"$work/log" 2>&1 || { cat "$work/log" >&2; exit 1; }
echo "w16 block: $(wc -c <"$work/w16.gcode") bytes, $(grep -c ';LAYER_CHANGE' "$work/w16.gcode") layers"
/usr/bin/time -f "search: %e s wall, %U s user, %M KB peak" \
  "$root/target/release/quietpath" infill "$work/w16.gcode" -o "$work/out.gcode" "$@" >/dev/null
