# quietpath: the two commands that matter are `make serve` and `make test`.
# Both install what they need first (scripts/setup.sh).

PORT ?= 8080
SHELL := /bin/bash
# npm's binaryen wasm-opt first: Debian's wasm-opt 108 produces broken modules with current wasm-bindgen.
export PATH := $(CURDIR)/node_modules/.bin:$(HOME)/.cargo/bin:$(PATH)
CORPUS ?= $(CURDIR)/../shared/corpus
LARGE := $(CORPUS)/curaengine-4.13.0_extruder-idler-x2.5_large.gcode

.PHONY: all setup setup-test pkg wasm-plain wasm-web wasm-web-threads wasm-node wasm-bundler serve test typecheck test-rust test-js fuzz-smoke lint cli bench measurements measure-vtg-w16 measure-vtg-unseen measure-vtg-fresh fuzz clean

all: pkg cli

setup:
	@scripts/setup.sh wasm

setup-test:
	@scripts/setup.sh test

## Build the npm package (pkg/: web, node and bundler builds under one package.json), link the
## web build and the threaded one into the playground and copy uPlot and three.js (the 3-D view)
## beside them, each with its TypeScript declarations for `make typecheck` (a .d.ts beside the
## .js is what tsc reads).
pkg: setup
	$(MAKE) --no-print-directory --output-sync=target -j2 wasm-plain wasm-web-threads
	node scripts/package.mjs
	ln -sfn ../pkg/web www/pkg
	ln -sfn ../pkg/web-threads www/pkg-threads
	mkdir -p www/vendor
	cp node_modules/uplot/dist/uPlot.esm.js node_modules/uplot/dist/uPlot.min.css www/vendor/
	cp node_modules/three/build/three.module.js node_modules/three/build/three.core.js www/vendor/
	cp node_modules/uplot/dist/uPlot.d.ts www/vendor/uPlot.esm.d.ts
	cp www/types/three.module.d.ts www/vendor/

# The three plain wasm-pack builds of `pkg`, run side by side: they share one compile (cargo's
# lock holds the later two until it is done), then each runs wasm-bindgen. Their modules are the
# same, so wasm-opt (npm binaryen's -O3, one thread, about 45 s) runs once for the three
# (scripts/wasm-opt-once.sh), beside the threaded build.
wasm-plain:
	$(MAKE) --no-print-directory --output-sync=target -j3 wasm-web wasm-node wasm-bundler
	scripts/wasm-opt-once.sh
wasm-web:
	wasm-pack build crate --release --target web --no-opt --out-dir ../pkg/web --out-name quietpath
# The playground's threaded build (pkg/web-threads, not part of the npm package): the parallel
# maps on a pool of Web Workers sharing the module's memory (the `threads` feature, rayon through
# wasm-bindgen-rayon). Shared memory needs the atomics target feature in std as well, so std is
# rebuilt with nightly's build-std; the linker arguments are wasm-bindgen's for threads, the
# memory's maximum raised to 4 GB (the 34 MB file's VTG needs more than the 1 GB default). Its own
# target directory: a different toolchain and flags, built beside the other three. The pool's
# workers then start from their script's URL, not a blob (scripts/pool-helper.mjs: the CSP).
THREADS_RUSTFLAGS := -C target-feature=+atomics,+bulk-memory,+mutable-globals,+simd128 \
	-C link-arg=--shared-memory -C link-arg=--import-memory -C link-arg=--max-memory=4294967296 \
	-C link-arg=--export=__wasm_init_tls -C link-arg=--export=__tls_size \
	-C link-arg=--export=__tls_align -C link-arg=--export=__tls_base
wasm-web-threads:
	RUSTUP_TOOLCHAIN=nightly CARGO_UNSTABLE_BUILD_STD=panic_abort,std CARGO_TARGET_DIR=$(CURDIR)/target/wasm-threads \
	RUSTFLAGS="$(THREADS_RUSTFLAGS)" \
	wasm-pack build crate --release --target web --out-dir ../pkg/web-threads --out-name quietpath --features threads
	node scripts/pool-helper.mjs pkg/web-threads
wasm-node:
	wasm-pack build crate --release --target nodejs --no-opt --out-dir ../pkg/node --out-name quietpath
wasm-bundler:
	wasm-pack build crate --release --target bundler --no-opt --out-dir ../pkg/bundler --out-name quietpath

## Build the wasm and serve the playground on http://127.0.0.1:$(PORT)
serve: pkg
	PORT=$(PORT) node scripts/serve.mjs www

## The native command-line tool: target/release/quietpath
cli:
	cargo build --release

## Everything: formatting, lints, the playground's type check, Rust tests (fuzz checks on mutated seeds among them), JS API and browser tests (the wasm package in Node and Chromium).
test: setup-test lint typecheck test-rust test-js

## `// @ts-check` on the playground's www/*.js: tsc over the page's modules and app.js (DOM) and
## over the two workers (worker.js, sw.js: the webworker library), and over the browser test's
## stand-in package (tests/e2e/mock-package.js) against the generated report types. Needs
## www/pkg and www/vendor.
typecheck: pkg
	tsc -p www/tsconfig.json
	tsc -p www/tsconfig.app.json
	tsc -p www/tsconfig.worker.json
	tsc -p tests/e2e/tsconfig.json

lint:
	cargo fmt --all -- --check
	cargo clippy --workspace --all-targets -- -D warnings
	cargo clippy -p quietpath --lib --target wasm32-unknown-unknown -- -D warnings
	RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet

# Property tests draw a fixed seed here so CI is reproducible; unset PROPTEST_RNG_SEED locally
# (or set another) to explore new cases. The crate's own tests run in the test profile, with
# debug assertions; the corpus conformance suite runs in release, which `cli` builds anyway:
# its VTG and dynamics runs took 554 s in the test profile against 356 s there, and its eight
# test binaries, one linked with thin LTO, 106 s to build (tests/conformance/main.rs). The CLI
# (which `test-js` needs) is built in the same cargo run: the library's one codegen unit keeps
# one core busy, and the binary's and the suite's links then share the two.
test-rust:
	PROPTEST_RNG_SEED=$${PROPTEST_RNG_SEED:-20261122} cargo test --workspace --exclude quietpath-conformance
	cargo build --release -p quietpath -p quietpath-conformance --bin quietpath --test conformance
	PROPTEST_RNG_SEED=$${PROPTEST_RNG_SEED:-20261122} cargo test --release -p quietpath-conformance

test-js: pkg cli
	npm test

## Throughput on the 34 MB corpus file (parse and analyze), plus sha256sum for scale, and the
## infill search's timing test (240 candidates under 10 s).
bench: cli
	@echo "sha256sum:"; time -p sha256sum "$(LARGE)" > /dev/null
	target/release/quietpath bench "$(LARGE)"
	cargo bench -p quietpath --bench parse
	cargo test --release -p quietpath-conformance infill:: -- --ignored --nocapture
	cargo test --release -p quietpath-conformance vtg:: -- --ignored --nocapture

## The generated tables in docs/measurements/generated/ (analyze, vtg, infill, smooth on every
## corpus file and fixture, from the CLI's --json; a few minutes). CORPUS=… for another corpus folder.
measurements:
	cargo build --release
	CORPUS="$(CORPUS)" node scripts/measurements.mjs

## VTG Table 1 and 2 beside the paper's on the W16-style block, sliced with concentric infill
## (scripts/vtg-w16-tables.sh, docs/measurements/vtg.md; about 4-5 min). W16_HEIGHT=… mm (default 4).
measure-vtg-w16: cli
	bash scripts/vtg-w16-tables.sh

## VTG on parts and slicers it was not tuned on: four models of tests/fixtures/models/unseen/
## sliced with CuraEngine, Slic3r and PrusaSlicer (for Klipper, and under less common settings),
## with the defaults and with lines allowed (scripts/vtg-unseen-parts.sh,
## docs/measurements/vtg.md; about 4 min). Needs the slicers. PrusaSlicer's slices differ from
## run to run: UNSEEN_KEEP=DIR keeps them, UNSEEN_SLICES=DIR measures kept ones again.
measure-vtg-unseen: cli
	bash scripts/vtg-unseen-parts.sh

## Four more unseen models sliced fourteen more ways, each vtg output checked by analyze and
## vibration runs of its own, not by vtg's report (scripts/vtg-fresh-parts.sh; about 2 min).
measure-vtg-fresh: cli
	bash scripts/vtg-fresh-parts.sh

## Short, reproducible (seeded, fixed-count) cargo-fuzz run of every target: a nightly build of
## about 3 minutes, so `make test` runs the same checks on mutated seeds on stable instead
## (crate/tests/fuzz_mutations.rs), and CI runs this in its own job.
fuzz-smoke:
	FUZZ_SEED=20261122 crate/fuzz/smoke.sh 10

## Long, unseeded fuzzing run of all eight targets, 10 minutes each, keeping its corpus.
## Installs nightly and cargo-fuzz if missing. FUZZ_SECONDS=… to change.
FUZZ_SECONDS ?= 600
fuzz:
	crate/fuzz/smoke.sh $(FUZZ_SECONDS)

clean:
	cargo clean
	rm -rf pkg www/pkg node_modules
