#!/usr/bin/env bash
# Klipper's own planner (../shared/klipper, the oracle) against `quietpath analyze
# --klipper-config` with the oracle's printer.cfg, on the given files (default: the corpus files
# that drive Klipper and the PrusaSlicer fixtures). Prints a markdown table.
#   scripts/klipper-compare.sh [FILE…]     KLIPPER_VERSION=v0.12.0 for the older Klipper
set -euo pipefail
cd "$(dirname "$0")/.."
shared=${SHARED:-../shared}
version=${KLIPPER_VERSION:-head}
bin=${QUIETPATH:-target/release/quietpath}
qv=current; [ "$version" = head ] || qv=legacy
if [ $# -eq 0 ]; then
  set -- $(grep -l -i -E 'klipper|SET_VELOCITY_LIMIT|EXCLUDE_OBJECT' "$shared"/corpus/*.gcode | grep -v large) \
    tests/fixtures/gcode/prusaslicer-*.gcode
fi
echo "| file | Klipper $version, s | quietpath, s | difference |"
echo "|---|---:|---:|---:|"
for f in "$@"; do
  # klippy may crash on its way out after printing its report (seen: exit 139 on the plate
  # fixture): the report is what counts, so its exit status is not.
  k=$({ KLIPPER_VERSION=$version KLIPPER_JSON=1 "$shared/klipper/klipper-time" "$f" 2>/dev/null || true; } \
      | python3 -c '
import json, sys
try:
    r = json.load(sys.stdin)
    print(r["time_s"] if r["errors"] == 0 and r["lines_read"] == r["lines_file"] else "error")
except ValueError:
    print("error")')
  q=$("$bin" analyze --json --klipper-config "$shared/klipper/$version/printer.cfg" --klipper-version $qv "$f" \
      | python3 -c 'import json,sys; print(json.load(sys.stdin)["time_s"])')
  d=$(python3 -c "k='$k'; print('n/a' if k=='error' else '%+.3f %%' % (100*($q-float(k))/float(k)))")
  printf '| %s | %s | %.2f | %s |\n' "$(basename "$f")" "$([ "$k" = error ] && echo error || printf %.2f "$k")" "$q" "$d"
done
