"""Checks `quietpath vtg` outputs by runs of their own: each file given is rewritten with the
defaults (and any options after `--`), then the input and the output are analysed
(`quietpath analyze`) and simulated (`quietpath vibration`) apart from the rewrite, and the
no-dearer rule is checked on those figures: lines, planned time (at most +1 %), total energy,
the dynamics model's peak and mean printing deviation, the measured deviation against the
tolerance and the peak segment rate against the machine's budget. One line per file, then
"N passed, N failed"; exits non-zero where any failed.

    python3 scripts/vtg-check-independently.py FILE.gcode... [-- VTG OPTIONS...]
"""
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
QUIETPATH = os.path.join(ROOT, "target", "release", "quietpath")


def report(*args):
    run = subprocess.run([QUIETPATH, *args, "--json"], capture_output=True, text=True)
    if run.returncode:
        raise RuntimeError(run.stderr.strip()[:300])
    return json.loads(run.stdout)


def lines(path):
    with open(path, "rb") as f:
        return sum(1 for _ in f)


def failures(rep, before, after):
    """What the output (`after`) is worse on than the input (`before`)."""
    (a0, v0, n0), (a1, v1, n1) = before, after
    found = []
    if n1 > n0:
        found.append(f"lines {n0} -> {n1}")
    if a1["time_s"] > a0["time_s"] * 1.01:
        found.append(f"time {a0['time_s']:.1f} -> {a1['time_s']:.1f} s")
    e0, e1 = a0["energy"]["total_j"], a1["energy"]["total_j"]
    if e1 > e0:
        found.append(f"energy {e0:.1f} -> {e1:.1f} J")
    for key in ("max", "mean"):
        if v1[key] > v0[key]:
            found.append(f"{key} deviation {v0[key]:.7f} -> {v1[key]:.7f} mm")
    if rep["max_deviation_mm"] > rep["tolerance_mm"]:
        found.append(f"measured deviation {rep['max_deviation_mm']:.4f} mm")
    fw = rep["firmware"]["after"]
    if fw["peak_segments_per_s"] > fw["budget_segments_per_s"]:
        found.append("peak segment rate over the budget")
    return found


def check(path, options, scratch):
    out = os.path.join(scratch, "out.gcode")
    start = time.time()
    rep = report("vtg", *options, "-o", out, "--force", path)
    took = time.time() - start
    sides = []
    for f in (path, out):
        vibration = report("vibration", f)["printing_deviation_mm"]
        sides.append((report("analyze", f), vibration, lines(f)))
    found = failures(rep, *sides)
    (a0, v0, n0), (a1, v1, n1) = sides
    change = lambda x, y: f"{(y / x - 1) * 100:+.2f} %" if x else "—"
    corners = rep["table1"]["n_turning"]["change_pct"]
    print(
        f"{os.path.basename(path)}: {took:.1f} s, lines {change(n0, n1)}, sharp corners "
        f"{'—' if corners is None else f'{corners:+.0f} %'}, time "
        f"{change(a0['time_s'], a1['time_s'])}, energy "
        f"{change(a0['energy']['total_j'], a1['energy']['total_j'])}, mean deviation "
        f"{change(v0['mean'], v1['mean'])}, peak {change(v0['max'], v1['max'])}, layers kept "
        f"{len(rep['peak_layers_kept'])}: {'FAILED ' + '; '.join(found) if found else 'ok'}"
        f"{' (' + rep['message'] + ')' if rep.get('message') else ''}",
        flush=True,
    )
    return not found


def main(argv):
    if not os.access(QUIETPATH, os.X_OK):
        sys.exit("build the CLI first: make cli")
    files, options = (argv[: argv.index("--")], argv[argv.index("--") + 1 :]) if "--" in argv else (argv, [])
    if not files:
        sys.exit(__doc__)
    with tempfile.TemporaryDirectory() as scratch:
        passed = sum(check(f, options, scratch) for f in files)
    print(f"{passed} passed, {len(files) - passed} failed")
    sys.exit(0 if passed == len(files) else 1)


if __name__ == "__main__":
    main(sys.argv[1:])
