#!/usr/bin/env bash
# An OpenSCAD model rendered to an ASCII STL whose facets are in a fixed order:
#
#   scripts/openscad-stl.sh OUT.stl MODEL.scad [openscad options...]
#
# OpenSCAD 2021.01 (Debian 12) writes the same facets in a different order from run to run
# (CGAL's polyhedron is built from hash maps), and the slicers' output follows the facet order
# in its last digits: two slices of one model differed byte for byte, and with them what a
# measurement of the slices reported. Sorted, the facets are the same bytes every run, so a
# script's slices, and the tables made from them, compare builds rather than renders.
set -euo pipefail
out="$1"
model="$2"
shift 2
raw="$(mktemp --suffix=.stl)"
log="$(mktemp)"
trap 'rm -f "$raw" "$log"' EXIT
openscad "$@" -o "$raw" "$model" >"$log" 2>&1 || { cat "$log" >&2; exit 1; }
python3 - "$raw" "$out" <<'PY'
import sys
src, dst = sys.argv[1], sys.argv[2]
lines = open(src).read().splitlines()
if not lines or not lines[0].startswith("solid"):
    sys.exit(f"{src}: not an ASCII STL")
facets, current = [], []
for line in lines[1:]:
    if line.strip().startswith("endsolid"):
        break
    current.append(line)
    if line.strip() == "endfacet":
        facets.append("\n".join(current))
        current = []
if current:
    sys.exit(f"{src}: a facet without its end")
with open(dst, "w") as f:
    f.write(lines[0] + "\n")
    for facet in sorted(facets):
        f.write(facet + "\n")
    f.write("endsolid " + lines[0][len("solid"):].strip() + "\n")
PY
