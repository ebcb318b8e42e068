#!/usr/bin/env bash
# Optimises the plain wasm builds (pkg/web, pkg/node, pkg/bundler, made with `wasm-pack --no-opt`)
# with one wasm-opt run instead of three. wasm-bindgen's module is the same for the three targets
# (only the JS glue differs), and wasm-opt is deterministic, so the result is byte for byte what
# wasm-pack's own wasm-opt step gives each (checked: the same SHA-256). Where the modules differ
# (another wasm-bindgen may one day), each is optimised on its own.
# The flags are crate/Cargo.toml's [package.metadata.wasm-pack.profile.release] wasm-opt.
set -euo pipefail
cd "$(dirname "$0")/.."
flags=(-O3)
web=pkg/web/quietpath_bg.wasm
others=(pkg/node/quietpath_bg.wasm pkg/bundler/quietpath_bg.wasm)
same=1
for f in "${others[@]}"; do cmp -s "$web" "$f" || same=0; done
if [ "$same" = 1 ]; then
  wasm-opt "$web" -o "$web.opt" "${flags[@]}"
  mv "$web.opt" "$web"
  for f in "${others[@]}"; do cp "$web" "$f"; done
else
  for f in "$web" "${others[@]}"; do
    wasm-opt "$f" -o "$f.opt" "${flags[@]}"
    mv "$f.opt" "$f"
  done
fi
