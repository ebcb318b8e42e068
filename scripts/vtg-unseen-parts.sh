#!/usr/bin/env bash
# VTG on parts and slicers it was never tuned on: the three models of
# tests/fixtures/models/unseen/ (a spur gear with a bore and lightening holes, a plate pierced
# by hexagonal holes, 25 mm fins) sliced with Debian's CuraEngine 4.13 (Marlin flavour, 1.75 mm,
# triangles infill, 2000 mm/s² and 10 mm/s jerk), Slic3r 1.3 (RepRap flavour, 0.25 mm layers,
# honeycomb) and PrusaSlicer 2.5 for a Klipper printer (SET_VELOCITY_LIMIT ACCEL=5000
# SQUARE_CORNER_VELOCITY=5 in its start G-code, 0.15 mm, gyroid, perimeters 120 mm/s, infill
# 200 mm/s), then `quietpath vtg --json` with the defaults and with `--allow-more-lines 1000`
# (extra vtg options are passed on to both). A fourth model, an L-bracket
# (tests/fixtures/models/unseen/bracket.scad), is sliced under each slicer's less common settings:
# CuraEngine with volumetric E and Z hops, concentric infill with ironing, lightning infill
# with coasting; PrusaSlicer with firmware retraction, fuzzy skin and two copies printed one
# after the other, and for RepRapFirmware with ironing at 0.1 mm; Slic3r for Smoothieware with
# concentric infill at 0.3 mm, and with firmware retraction and a Hilbert-curve top.
# Prints a markdown table per run: lines, sharp corners, energy, time, the dynamics model's
# mean and peak deviation, the measured deviation, layers kept, the peak segment rate against
# the machine's budget, and the message.
# Results: docs/measurements/vtg.md ("Parts it was not tuned on").
#
# Needs Debian's `openscad`, `prusa-slicer`, `slic3r` and `cura-engine`, python3 and `make cli`.
# CuraEngine needs Cura's printer definitions, which Debian ships in the `cura` package: they
# are taken from /usr/share/cura/resources, else from `apt-get download cura` unpacked in a
# temporary directory (without installing Cura and its Qt).
#
#   bash scripts/vtg-unseen-parts.sh [extra quietpath vtg options...]
#   UNSEEN_KEEP=/tmp/unseen bash scripts/vtg-unseen-parts.sh   # keep the sliced files there
#   UNSEEN_SLICES=/tmp/unseen bash scripts/vtg-unseen-parts.sh # measure kept slices again
#
# The models are rendered with scripts/openscad-stl.sh (facets in a fixed order), and Slic3r
# slices the same STL to the same bytes every time; PrusaSlicer 2.5 does not (where a hole's
# loop starts moves from run to run, even on one thread with the seam at the rear), so two
# builds are compared on one set of slices: keep them once with UNSEEN_KEEP and measure each
# build on them with UNSEEN_SLICES.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
quietpath="$root/target/release/quietpath"
[ -x "$quietpath" ] || { echo "build the CLI first: make cli" >&2; exit 1; }
for tool in openscad prusa-slicer slic3r CuraEngine python3; do
  command -v "$tool" >/dev/null || { echo "missing: $tool (see the comment at the top)" >&2; exit 1; }
done
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
work="${UNSEEN_SLICES:-${UNSEEN_KEEP:-$scratch}}"
mkdir -p "$work"

# Renders and slices every part into $work, adding the slices to `files` (the body is not
# indented: the PrusaSlicer start G-code below is a string across lines).
slice_all() {
resources="$("$root/scripts/cura-resources.sh" "$scratch")"
export CURA_ENGINE_SEARCH_PATH="$resources/definitions:$resources/extruders"

for model in gear hexgrid tall_fins; do
  "$root/scripts/openscad-stl.sh" "$work/$model.stl" "$root/tests/fixtures/models/unseen/$model.scad"
  CuraEngine slice -j "$resources/definitions/fdmprinter.def.json" \
    -s machine_width=220 -s machine_depth=220 -s machine_height=250 -s center_object=true \
    -s machine_gcode_flavor="RepRap (Marlin/Sprinkler)" -s layer_height=0.2 \
    -s wall_line_count=3 -s infill_sparse_density=25 -s infill_pattern=triangles \
    -s speed_print=70 -s speed_wall_0=35 -s acceleration_enabled=true -s acceleration_print=2000 \
    -s jerk_enabled=true -s jerk_print=10 \
    -e0 -s machine_nozzle_size=0.4 -s material_diameter=1.75 \
    -l "$work/$model.stl" -o "$work/curaengine_$model.gcode" >/dev/null 2>&1
  slic3r --no-gui --gcode-flavor reprap --print-center 100,100 --filament-diameter 1.75 \
    --nozzle-diameter 0.4 --layer-height 0.25 --perimeters 2 --fill-density 30% \
    --fill-pattern honeycomb --output "$work/slic3r_$model.gcode" "$work/$model.stl" >/dev/null 2>&1
  prusa-slicer --export-gcode --gcode-flavor marlin2 --machine-limits-usage emit_to_gcode \
    --start-gcode "SET_VELOCITY_LIMIT ACCEL=5000 SQUARE_CORNER_VELOCITY=5
G28
G1 Z5 F3000" \
    --center 125,105 --use-relative-e-distances --layer-gcode "G92 E0" --layer-height 0.15 \
    --perimeters 3 --fill-density 15% --fill-pattern gyroid --perimeter-speed 120 \
    --external-perimeter-speed 80 --infill-speed 200 \
    --output "$work/prusaslicer-klipper_$model.gcode" "$work/$model.stl" >/dev/null 2>&1
  files+=("$work/curaengine_$model.gcode" "$work/slic3r_$model.gcode" "$work/prusaslicer-klipper_$model.gcode")
done

# One more part, an L-bracket with ribs, a bored boss, a slot, a cross hole and a separate
# tube, under settings the tuning never met: each slicer's less common options.
"$root/scripts/openscad-stl.sh" "$work/bracket.stl" "$root/tests/fixtures/models/unseen/bracket.scad"
cura() { # output name, settings...
  local name="$1"
  shift
  CuraEngine slice -j "$resources/definitions/fdmprinter.def.json" \
    -s machine_width=220 -s machine_depth=220 -s machine_height=250 -s center_object=true \
    -s layer_height=0.2 "$@" -l "$work/bracket.stl" -o "$work/$name.gcode" >/dev/null 2>&1
  files+=("$work/$name.gcode")
}
extruder=(-e0 -s machine_nozzle_size=0.4 -s material_diameter=1.75)
cura curaengine_bracket_volumetric_gyroid_zhop -s machine_gcode_flavor="RepRap (Volumetric)" \
  -s relative_extrusion=true "${extruder[@]}" -s infill_pattern=gyroid \
  -s infill_sparse_density=20 -s retraction_hop_enabled=true
cura curaengine_bracket_concentric_ironing "${extruder[@]}" -s infill_pattern=concentric \
  -s infill_sparse_density=30 -s ironing_enabled=true
cura curaengine_bracket_lightning_coasting "${extruder[@]}" -s infill_pattern=lightning \
  -s infill_sparse_density=15 -s coasting_enable=true -s acceleration_enabled=true \
  -s acceleration_print=3000 -s jerk_enabled=true -s jerk_print=8
prusa-slicer --export-gcode --gcode-flavor marlin2 --use-firmware-retraction \
  --fuzzy-skin external --duplicate 2 --complete-objects --extruder-clearance-radius 20 \
  --layer-height 0.2 --fill-density 20% --fill-pattern cubic \
  --output "$work/prusaslicer_bracket_fwretract_fuzzy_sequential.gcode" "$work/bracket.stl" >/dev/null 2>&1
prusa-slicer --export-gcode --gcode-flavor reprapfirmware --ironing --ironing-type top \
  --layer-height 0.1 --fill-density 40% --fill-pattern rectilinear --seam-position rear \
  --use-relative-e-distances \
  --output "$work/prusaslicer_bracket_rrf_ironing_0.1mm.gcode" "$work/bracket.stl" >/dev/null 2>&1
slic3r --no-gui --gcode-flavor smoothie --print-center 100,100 --filament-diameter 1.75 \
  --nozzle-diameter 0.4 --layer-height 0.3 --perimeters 3 --fill-density 25% \
  --fill-pattern concentric \
  --output "$work/slic3r_bracket_smoothie_concentric.gcode" "$work/bracket.stl" >/dev/null 2>&1
slic3r --no-gui --gcode-flavor reprap --use-firmware-retraction --use-relative-e-distances \
  --print-center 100,100 --filament-diameter 1.75 --nozzle-diameter 0.4 --layer-height 0.2 \
  --fill-density 60% --fill-pattern rectilinear --top-infill-pattern hilbertcurve \
  --output "$work/slic3r_bracket_fwretract_hilbert.gcode" "$work/bracket.stl" >/dev/null 2>&1
files+=("$work/prusaslicer_bracket_fwretract_fuzzy_sequential.gcode"
  "$work/prusaslicer_bracket_rrf_ironing_0.1mm.gcode"
  "$work/slic3r_bracket_smoothie_concentric.gcode" "$work/slic3r_bracket_fwretract_hilbert.gcode")
}

# The slices, in the order they were sliced in: listed in slices.txt beside them, so that
# UNSEEN_SLICES measures the same files in the same order.
files=()
if [ -n "${UNSEEN_SLICES:-}" ]; then
  [ -f "$work/slices.txt" ] || { echo "no slices.txt in $work (slice with UNSEEN_KEEP)" >&2; exit 1; }
  while read -r name; do
    [ -f "$work/$name" ] || { echo "missing kept slice: $work/$name" >&2; exit 1; }
    files+=("$work/$name")
  done <"$work/slices.txt"
else
  slice_all
  printf '%s\n' "${files[@]##*/}" >"$work/slices.txt"
fi

run() { # title, extra options...
  local title="$1"
  shift
  echo
  echo "**$title**"
  echo
  python3 - "$quietpath" "$scratch" "$@" "${files[@]}" <<'PY'
import json, subprocess, sys, time
quietpath, work, rest = sys.argv[1], sys.argv[2], sys.argv[3:]
options = [a for a in rest if not a.endswith(".gcode")]
files = [a for a in rest if a.endswith(".gcode")]
print("| file | s | lines | sharp corners | energy | time | mean dev. | peak dev. | measured mm | layers kept | segments/s (budget) | message |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
pct = lambda x: "—" if x is None else f"{x:+.1f} %"
for f in files:
    t = time.time()
    out = subprocess.run([quietpath, "vtg", *options, "--json", "-o", f"{work}/out.gcode", f],
                         capture_output=True, text=True)
    s = time.time() - t
    name = f.split("/")[-1]
    if out.returncode:
        print(f"| {name} | failed: {out.stderr.strip()[:200]} |")
        continue
    r = json.loads(out.stdout)
    fw, t2, dev = r["firmware"], r["table2"], r["table2"]["deviation"]
    lines = (fw["after"]["lines"] / fw["before"]["lines"] - 1) * 100
    mean = dev and dev["mean_mm"]["change_pct"]
    peak = dev and dev["max_mm"]["change_pct"]
    msg = (r["message"] or "").replace("|", "/")
    print(f"| {name} | {s:.1f} | {lines:+.1f} % | {pct(r['table1']['n_turning']['change_pct'])} "
          f"| {pct(t2['energy_j']['change_pct'])} | {pct(t2['time_s']['change_pct'])} | {pct(mean)} "
          f"| {pct(peak)} | {r['max_deviation_mm']:.3f} | {len(r['peak_layers_kept'])} "
          f"| {fw['after']['peak_segments_per_s']:.0f} ({fw['after']['budget_segments_per_s']:.0f}) | {msg} |")
PY
}
run "Defaults" "$@"
run "With --allow-more-lines 1000" --allow-more-lines 1000 "$@"
