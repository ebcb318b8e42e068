#!/usr/bin/env bash
# Installs what building and testing quietpath needs, and nothing that is already there.
#   scripts/setup.sh wasm     Rust wasm32 target, wasm-pack, wasm-bindgen-cli (matching Cargo.lock), npm devDependencies
#   scripts/setup.sh test     the above, plus Debian's chromium for the browser tests
# Known traps (see docs/development.md): Debian's binaryen/wasm-opt 108 silently breaks current wasm-bindgen output,
# so the npm `binaryen` package's wasm-opt is put first on PATH by the Makefile; browser downloads by test
# tools fail here, so tests drive Debian's /usr/bin/chromium through playwright-core.
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-wasm}"
export PATH="$HOME/.cargo/bin:$PATH"

say() { printf '\033[1msetup:\033[0m %s\n' "$*" >&2; }

if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  say "adding the wasm32-unknown-unknown target"
  rustup target add wasm32-unknown-unknown
fi

# The playground's threaded build rebuilds std with shared memory: nightly's build-std, from rust-src.
if ! rustup component list --toolchain nightly --installed 2>/dev/null | grep -qx rust-src; then
  say "adding nightly Rust with rust-src (the playground's threaded build)"
  rustup toolchain install nightly --profile minimal --component rust-src
fi

WASM_PACK_VERSION=0.15.1
if ! wasm-pack --version 2>/dev/null | grep -q "$WASM_PACK_VERSION"; then
  say "installing wasm-pack $WASM_PACK_VERSION (a few minutes, once)"
  cargo install --locked wasm-pack --version "$WASM_PACK_VERSION"
fi

# wasm-bindgen-cli must match the wasm-bindgen crate in Cargo.lock exactly.
BINDGEN_VERSION=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [ -z "$BINDGEN_VERSION" ]; then
  say "cannot read the wasm-bindgen version from Cargo.lock"; exit 1
fi
if ! wasm-bindgen --version 2>/dev/null | grep -q " $BINDGEN_VERSION\$"; then
  say "installing wasm-bindgen-cli $BINDGEN_VERSION (a few minutes, once)"
  # Not --locked: its lockfile pins a webpki-roots release the registry no longer serves.
  cargo install wasm-bindgen-cli --version "$BINDGEN_VERSION"
fi

if [ ! -x node_modules/.bin/wasm-opt ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  say "installing npm devDependencies"
  npm ci --no-audit --no-fund
fi

if [ "$what" = test ] && [ ! -x /usr/bin/chromium ]; then
  say "installing Debian's chromium for the browser tests"
  if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium
fi
