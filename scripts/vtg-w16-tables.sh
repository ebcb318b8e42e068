#!/usr/bin/env bash
# The VTG paper's Table 1 and Table 2 beside ours, on the W16-style block
# (tests/fixtures/models/w16_block.scad: 230 x 195 mm, sixteen Ø20 bores in a 4 x 4 grid) sliced
# here with CONCENTRIC infill, the pattern the paper chose for its tables (VTG section 4).
# PrusaSlicer, marlin2, 0.4 mm nozzle, 0.2 mm layers, 5 perimeters, 70 % concentric infill
# (top and bottom skins concentric too), 3 top and 3 bottom solid layers: the settings of
# scripts/infill-large.sh but the pattern. The block is W16_HEIGHT mm tall (default 4, 20
# layers): the full 20 mm slices to 89 MB in concentric, too slow for the dynamics model
# (the tables compare ratios). Runs `quietpath vtg --json` with the dynamics model on and the
# default options (extra vtg options are passed on) and prints a markdown table: the paper's
# before / after / ratio and ours, every row. Results: docs/measurements/vtg.md.
# Needs Debian's `openscad` and `prusa-slicer`, python3, and `make cli`.
#
#   bash scripts/vtg-w16-tables.sh [extra quietpath vtg options...]
#   W16_HEIGHT=2 W16_KEEP=/tmp/w16 bash scripts/vtg-w16-tables.sh   # 10 layers, keep the files
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
height="${W16_HEIGHT:-4}"
quietpath="$root/target/release/quietpath"
[ -x "$quietpath" ] || { echo "build the CLI first: make cli" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
SECONDS=0
openscad -D "height=$height" -o "$work/w16.stl" "$root/tests/fixtures/models/w16_block.scad" \
  >"$work/log" 2>&1 || { cat "$work/log" >&2; exit 1; }
t_model=$SECONDS
prusa-slicer --export-gcode --machine-limits-usage emit_to_gcode --remaining-times \
  --nozzle-diameter 0.4 --filament-diameter 1.75 --temperature 215 --bed-temperature 60 \
  --bed-shape 0x0,250x0,250x210,0x210 --center 125,105 --skirts 0 --first-layer-height 0.2 \
  --gcode-flavor marlin2 --use-relative-e-distances --layer-gcode "G92 E0" \
  --layer-height 0.2 --perimeters 5 --fill-pattern concentric --fill-density 70% \
  --top-fill-pattern concentric --bottom-fill-pattern concentric \
  --top-solid-layers 3 --bottom-solid-layers 3 \
  --output "$work/w16.gcode" "$work/w16.stl" >"$work/log" 2>&1 || { cat "$work/log" >&2; exit 1; }
t_slice=$((SECONDS - t_model))
echo "W16-style block, ${height} mm tall: $(wc -c <"$work/w16.gcode") bytes," \
  "$(grep -c ';LAYER_CHANGE' "$work/w16.gcode") layers (openscad ${t_model} s, prusa-slicer ${t_slice} s)"
/usr/bin/time -o "$work/time" -f "%e s wall, %U s user, %M KB peak" \
  "$quietpath" vtg "$work/w16.gcode" -o "$work/w16.vtg.gcode" --json "$@" >"$work/vtg.json"
echo "quietpath vtg $*: $(cat "$work/time")"
if [ -n "${W16_KEEP:-}" ]; then
  mkdir -p "$W16_KEEP"
  cp "$work/w16.gcode" "$work/w16.vtg.gcode" "$work/vtg.json" "$W16_KEEP/"
fi
python3 - "$work/vtg.json" <<'PY'
import json, sys

r = json.load(open(sys.argv[1]))
t1, t2 = r["table1"], r["table2"]
dev = t2.get("deviation")

# The paper's values as it prints them (VTG Table 1, Table 2) and its ratio, percent.
PAPER = {
    "l_total": ("17256.96", "14741.66", -14.56),
    "n_total": ("7647", "6909", -9.65),
    "l_infill": ("4094.45", "2829.49", -30.89),
    "n_infill": ("880", "871", -0.99),
    "n_turning": ("360", "211", -41.50),
    "chord": ("0.16", "0.13", -22.04),
    "dev_max": ("0.1676", "0.1353", -19.27),
    "dev_min": ("0.0018", "0.0015", -12.71),
    "dev_mean": ("0.0874", "0.0769", -11.98),
    "energy": ("9.378e+05", "8.248e+05", -12.05),
    "material": ("41.9", "34.0", -18.90),
    "co2": ("196.0", "178.6", -8.87),
}

ROWS = [
    ("1", "L_total (mm)", "l_total", t1["l_total_mm"], "table1.l_total_mm"),
    ("1", "n_total", "n_total", t1["n_total"], "table1.n_total"),
    ("1", "L_infill (mm)", "l_infill", t1["l_infill_mm"], "table1.l_infill_mm"),
    ("1", "n_infill", "n_infill", t1["n_infill"], "table1.n_infill"),
    ("1", "n_turning (> 30°)", "n_turning", t1["n_turning"], "table1.n_turning"),
    ("1", "mean chord error (mm)", "chord", t1["mean_chord_error_mm"],
     "table1.mean_chord_error_mm"),
    ("1", "mean turn (°), not in the paper's table", None, t1["mean_turn_deg"],
     "table1.mean_turn_deg"),
    ("2", "max deviation (mm)", "dev_max", dev and dev["max_mm"], "table2.deviation.max_mm"),
    ("2", "min deviation (mm)", "dev_min", dev and dev["min_mm"], "table2.deviation.min_mm"),
    ("2", "mean deviation (mm)", "dev_mean", dev and dev["mean_mm"], "table2.deviation.mean_mm"),
    ("2", "energy E (J)", "energy", t2["energy_j"], "table2.energy_j"),
    ("2", "servo energy (J), not in the paper's table", None, t2["servo_energy_j"],
     "table2.servo_energy_j"),
    ("2", "material (g)", "material", t2["material_g"], "table2.material_g"),
    ("2", "CO2 (g)", "co2", t2["co2_g"], "table2.co2_g"),
    ("2", "print time (s), not in the paper's table", None, t2["time_s"], "table2.time_s"),
]


def num(x):
    a = abs(x)
    if a >= 100:
        return f"{x:,.0f}".replace(",", " ")
    if a >= 1:
        return f"{x:.2f}"
    if a >= 1e-4 or a == 0:
        return f"{x:.4f}"
    return f"{x:.1e}"


def pct(p):
    return "—" if p is None else f"{p:+.2f} %"


print()
print("| table | row | paper before | paper after | paper ratio (recomputed) "
      "| ours before | ours after | ours ratio | our field |")
print("|---|---|---:|---:|---:|---:|---:|---:|---|")
for table, label, key, ours, field in ROWS:
    if key:
        b, a, stated = PAPER[key]
        recomputed = (float(a) - float(b)) / float(b) * 100
        paper = [b, a, f"{pct(stated)} ({pct(recomputed)})"]
    else:
        paper = ["—", "—", "—"]
    if ours:
        mine = [num(ours["before"]), num(ours["after"]), f"**{pct(ours['change_pct'])}**"]
    else:
        mine = ["—", "—", "— (no dynamics)"]
    print(f"| {table} | {label} | " + " | ".join(paper + mine) + f" | `{field}` |")

p, fw = r["paths"], r["firmware"]
print()
print(f"max deviation from the original {r['max_deviation_mm']:.4f} mm (tolerance "
      f"{r['tolerance_mm']} mm), δθ {r['critical_angle_deg']}°, K_cr {r['k_cr_per_mm']} /mm; "
      f"paths: {p['candidates']} candidates, {p['rewritten']} rewritten, "
      f"{p['keyholes']} keyhole loops, steps joined: {str(p['steps_joined']).lower()}, "
      f"feed-cap scale {p['feed_cap_scale']}")
if fw:
    b, a = fw["before"], fw["after"]
    print(f"firmware: lines {b['lines']} -> {a['lines']}, segments under 0.1 mm "
          f"{b['segments_under_0_1mm']} -> {a['segments_under_0_1mm']}, peak segments/s "
          f"{b['peak_segments_per_s']} -> {a['peak_segments_per_s']} (budget "
          f"{a['budget_segments_per_s']:.0f}/s)"
          + (f"; warning: {fw['warning']}" if fw.get("warning") else ""))
PY
echo "total: ${SECONDS} s"
