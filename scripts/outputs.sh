#!/usr/bin/env bash
# Writes every command's output (JSON reports and rewritten G-code) for every corpus file and
# fixture into DIR, so two builds can be compared byte for byte:
#   scripts/outputs.sh BIN DIR            e.g. scripts/outputs.sh target/release/quietpath /tmp/after
#   diff -r /tmp/before /tmp/after        (the refactor check of docs/development.md)
# JSON reports carry the crate version only; no timestamps or paths, so equal builds give equal bytes.
set -uo pipefail
bin=$(realpath "$1"); out=$2
cd "$(dirname "$0")/.."
corpus=${CORPUS:-../shared/corpus}
mkdir -p "$out"
files=("$corpus"/*.gcode tests/fixtures/gcode/*.gcode)
run() { # name, command...
  local name=$1; shift
  "$@" > "$out/$name.out" 2> "$out/$name.err"; echo "exit $?" >> "$out/$name.out"
}
for f in "${files[@]}"; do
  b=$(basename "$f" .gcode)
  run "$b.analyze" "$bin" analyze --json "$f"
  case "$b" in
    multiaxis*)
      run "$b.smooth" "$bin" smooth "$f" -o "$out/$b.smooth.gcode" --kinematics table-bc --json --force ;;
    *)
      run "$b.vtg" "$bin" vtg "$f" -o "$out/$b.vtg.gcode" --no-dynamics --json --force
      run "$b.infill" "$bin" infill "$f" -o "$out/$b.infill.gcode" --angles 0,90 --patterns rectilinear,concentric --json --force ;;
  esac
done
# The slower jobs on a few files: dynamics, vibration, the full infill search and VTG with arcs.
for b in prusaslicer-2.5.0_thesis_square prusaslicer-2.5.0_star_fast_jerk15 crealityprint-5_k1c_benchy_klipper_exclude-object; do
  f=$(ls "$corpus/$b.gcode" tests/fixtures/gcode/$b.gcode 2>/dev/null | head -1)
  run "$b.vibration" "$bin" vibration --json "$f"
  run "$b.vtg-dyn" "$bin" vtg "$f" -o "$out/$b.vtg-dyn.gcode" --arcs --json --force
  run "$b.infill-full" "$bin" infill "$f" -o "$out/$b.infill-full.gcode" --json --force
done
echo "outputs in $out: $(ls "$out" | wc -l) files"
