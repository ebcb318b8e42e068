#!/usr/bin/env bash
# Rebuilds the fuzz seed corpus in fuzz/seeds/<target>/ from the real slicer files in the shared
# corpus. Deterministic: the same corpus gives the same seeds, byte for byte.
#
#   crate/fuzz/make_seeds.sh [CORPUS_DIR]     (default: ../../../shared/corpus from this script)
#
# For every slicer file except the 34 MB one (whose excerpts would repeat CuraEngine's), it takes
# one excerpt per target, cut at line boundaries so terminators (LF, CRLF) stay as written:
#   parse_line  3 KB starting at 5% of the file      (header comments, settings, thumbnails)
#   analyze     4 KB from the first G/M/T command    (start G-code: units, modes, temperatures)
#   rewrite     the last 3 KB of the file            (end G-code, settings, final terminator)
# Excerpts are 2-8 KB each and the whole corpus stays under 300 KB.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
corpus=${1:-$here/../../../shared/corpus}
out=$here/seeds
[ -d "$corpus" ] || { echo "make_seeds.sh: no corpus at $corpus" >&2; exit 1; }

export LC_ALL=C

# Bytes [offset, offset+count) of a file (no pipes into head: SIGPIPE would trip pipefail).
bytes_at() { dd if="$1" iflag=skip_bytes,count_bytes skip="$2" count="$3" status=none; }

# Drops the (partial) first line of stdin.
drop_first_line() { sed '1d'; }

# Drops a partial last line: keeps everything up to and including the last '\n'. Input without any
# newline is kept whole.
drop_partial_last_line() {
    local tmp
    tmp=$(mktemp)
    cat > "$tmp"
    local len keep
    len=$(wc -c < "$tmp")
    # Offset of the last newline: bytes after it form the partial line.
    keep=$(od -An -v -tu1 -w1 "$tmp" | awk -v len="$len" '$1 == 10 { last = NR } END { print (last ? last : len) }')
    head -c "$keep" "$tmp"
    rm -f "$tmp"
}

rm -rf "$out"
mkdir -p "$out/parse_line" "$out/analyze" "$out/rewrite"

for f in "$corpus"/*.gcode; do
    name=$(basename "$f" .gcode)
    case $name in *_large) continue ;; esac
    size=$(wc -c < "$f")

    # parse_line: 3 KB at 5% of the file.
    off=$((size / 20))
    bytes_at "$f" "$off" 3200 | drop_first_line | drop_partial_last_line > "$out/parse_line/$name.gcode"

    # analyze: 4 KB from the first line that is a command (skips thumbnail blocks).
    first=$(grep -b -m1 -a '^[GMT][0-9]' "$f" | cut -d: -f1 || true)
    bytes_at "$f" "${first:-0}" 4096 | drop_partial_last_line > "$out/analyze/$name.gcode"

    # rewrite: the last 3 KB, starting at a line boundary; the file's own ending is kept.
    bytes_at "$f" "$((size > 3200 ? size - 3200 : 0))" 3200 | drop_first_line > "$out/rewrite/$name.gcode"
done

# Drop excerpts that came out too small to be useful (a file shorter than its excerpt).
find "$out" -type f -size -2k -delete

echo "seeds: $(find "$out" -type f | wc -l) files, $(du -sb "$out" | cut -f1) bytes in $out"
