#!/usr/bin/env bash
# Regenerates cura_plate_{linear,volumetric}.gcode: a 20 × 14 × 2 mm plate with a 5 mm hole
# (OpenSCAD) sliced by CuraEngine 4.13 twice with the same settings (1.75 mm filament, grid
# 20 % infill, relative E), once with E in millimetres of filament (Marlin flavour) and once
# as volumes in mm³ (Cura's "Marlin (Volumetric)" flavour). Used by crate/tests/volumetric.rs:
# both must read as the same print. Needs `openscad`, `cura-engine` and Cura's printer
# definitions (Debian's `cura` package; unpacked from `apt-get download cura` when it is not
# installed). Committed files: CuraEngine 4.13.0 (Debian 4.13.0-1+b1), OpenSCAD 2021.01.
set -euo pipefail
cd "$(dirname "$0")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
resources="$(../../../scripts/cura-resources.sh "$tmp")"
export CURA_ENGINE_SEARCH_PATH="$resources/definitions:$resources/extruders"
echo 'difference() { cube([20, 14, 2]); translate([10, 7, -1]) cylinder(r = 2.5, h = 4, $fn = 48); }' > "$tmp/plate.scad"
openscad -o "$tmp/plate.stl" "$tmp/plate.scad" 2>/dev/null
for flavour in linear volumetric; do
  name="RepRap (Marlin/Sprinkler)"
  [ "$flavour" = volumetric ] && name="RepRap (Volumetric)"
  CuraEngine slice -j "$resources/definitions/fdmprinter.def.json" \
    -s machine_width=200 -s machine_depth=200 -s machine_height=200 -s center_object=true \
    -s layer_height=0.2 -s machine_gcode_flavor="$name" -s relative_extrusion=true \
    -e0 -s machine_nozzle_size=0.4 -s material_diameter=1.75 \
    -s infill_pattern=grid -s infill_sparse_density=20 -s top_layers=0 -s bottom_layers=1 \
    -l "$tmp/plate.stl" -o "cura_plate_$flavour.gcode" >/dev/null 2>&1
done
