#!/usr/bin/env bash
# Regenerates rect_infill_{0,45,90}.gcode: a 60 × 30 × 5 mm box (OpenSCAD cube) sliced by
# PrusaSlicer for a Marlin 2 machine with rectilinear 20 % infill at 0°, 45° and 90° and no
# solid top or bottom layers, so the files differ only in the infill direction. Used by
# crate/tests/energy.rs to check the thesis's finding that 45° infill costs the most stepper
# energy. Needs `prusa-slicer` and `openscad` (Debian: apt-get install -y prusa-slicer openscad).
# Committed files: PrusaSlicer 2.5.0 (Debian), OpenSCAD 2021.01.
set -euo pipefail
cd "$(dirname "$0")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo 'cube([60, 30, 5]);' > "$tmp/box.scad"
openscad -o "$tmp/box.stl" "$tmp/box.scad"
for angle in 0 45 90; do
  prusa-slicer --export-gcode \
    --gcode-flavor marlin2 --machine-limits-usage emit_to_gcode \
    --fill-pattern rectilinear --fill-density 20% --fill-angle "$angle" \
    --top-solid-layers 0 --bottom-solid-layers 0 \
    --layer-height 0.2 --first-layer-height 0.2 --perimeters 2 --skirts 0 \
    --center 100,100 \
    --output "rect_infill_$angle.gcode" "$tmp/box.stl"
done
