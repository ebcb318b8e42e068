#!/usr/bin/env bash
# Runs every cargo-fuzz target for N seconds each (default 20) and exits non-zero if any of them
# finds a crash, a timeout or an out-of-memory input.
#
#   crate/fuzz/smoke.sh [SECONDS] [TARGET...]      (default: all targets)
#
# Needs the nightly toolchain; installs cargo-fuzz if it is missing. New corpus entries go to
# fuzz/corpus/<target>/ (git-ignored); fuzz/seeds/<target>/ is only read. Crashing inputs are
# written to fuzz/artifacts/<target>/ (git-ignored): copy them into fuzz/regressions/ so that
# `cargo test` (tests/fuzz_regressions.rs) replays them for ever.
#
# FUZZ_SEED=N makes the run reproducible (what `make fuzz-smoke` does): libFuzzer's random seed is N,
# each target starts from the committed seeds alone (a fresh corpus directory) and runs a fixed
# number of inputs (about SECONDS' worth on the 2-core reference machine, from the table below),
# so every machine tries the same inputs in the same order and CI cannot turn red on a find
# that depends on how fast, or for how long, the machine fuzzed before. Exploration is the job
# of `make fuzz`, which runs unseeded and keeps its corpus.
set -uo pipefail

secs=${1:-20}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(parse_line analyze rewrite planner vtg infill smooth vibration)

case $secs in ''|*[!0-9]*) echo "smoke.sh: SECONDS must be a whole number, got '$secs'" >&2; exit 2 ;; esac

fuzz_dir=$(cd "$(dirname "$0")" && pwd)
cd "$fuzz_dir/.." || exit 2 # the crate: cargo fuzz looks for ./fuzz

export PATH="$HOME/.cargo/bin:$PATH"
if ! rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    echo "smoke.sh: installing the nightly toolchain (cargo-fuzz needs it)" >&2
    rustup toolchain install nightly --profile minimal || exit 2
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "smoke.sh: installing cargo-fuzz" >&2
    cargo install cargo-fuzz --locked || exit 2
fi

# Inputs per second each target runs on the reference machine (60 % of what it measured), for
# the seeded mode's fixed run counts.
declare -A per_second=(
    [parse_line]=4300 [analyze]=220 [rewrite]=9300 [planner]=8600
    [vtg]=21 [infill]=330 [smooth]=63 [vibration]=3
)

failed=()
for t in "${targets[@]}"; do
    mkdir -p "fuzz/corpus/$t" "fuzz/artifacts/$t"
    corpus="fuzz/corpus/$t"
    mode=(-max_total_time="$secs")
    build=()
    if [ -n "${FUZZ_SEED:-}" ]; then
        corpus=$(mktemp -d)
        runs=$(( ${per_second[$t]:-100} * secs ))
        # The time cap only guards a much slower machine; it then runs a prefix of the same
        # sequence.
        mode=(-seed="$FUZZ_SEED" -runs="$runs" -max_total_time=$(( 4 * secs )))
        # No AddressSanitizer in the seeded smoke run: quietpath forbids unsafe code, so what
        # it looks for (panics, timeouts, runaway memory) needs none, and the inputs run about
        # five times faster (all eight targets: 26 s against 127 s). The exploring run
        # (`make fuzz`) keeps it, for the dependencies' unsafe code.
        build=(--sanitizer none)
        echo "== fuzz $t: $runs inputs, seed $FUZZ_SEED"
    else
        echo "== fuzz $t for ${secs}s"
    fi
    # -timeout: one input taking longer than 10 s is a bug (quadratic paths on hostile input).
    # -rss_limit_mb: the parser streams; 2 GB means a leak or an unbounded structure.
    if ! cargo +nightly fuzz run "${build[@]}" "$t" "$corpus" "fuzz/seeds/$t" -- \
        "${mode[@]}" -timeout=10 -rss_limit_mb=2048 -dict=fuzz/gcode.dict \
        -print_final_stats=1; then
        echo "!! fuzz target $t failed; reproducer in crate/fuzz/artifacts/$t/" >&2
        failed+=("$t")
    fi
    [ -z "${FUZZ_SEED:-}" ] || rm -rf "$corpus"
done

if [ ${#failed[@]} -gt 0 ]; then
    echo "smoke.sh: crashes in: ${failed[*]}" >&2
    exit 1
fi
echo "smoke.sh: no crashes in ${targets[*]} (${secs}s each)"
