#![cfg(not(target_arch = "wasm32"))]
//! A seeded mutation run of the fuzz targets' checks, part of `make test` on stable Rust.
//!
//! Each target's committed seeds (`crate/fuzz/seeds/<target>/`) are mutated the way libFuzzer's
//! default mutators do (flipped bits, changed, inserted, erased and copied ranges, tokens of
//! `crate/fuzz/gcode.dict`, splices of two seeds) and run through the same checks as `cargo fuzz`
//! (`crate/fuzz/checks.rs`): no panic, typed errors, sane outputs, bounded time. The generator is
//! seeded, so every machine tries the same inputs. There is no coverage guidance here: that
//! exploring run is `make fuzz` (nightly, cargo-fuzz), and `make fuzz-smoke` its seeded short
//! run; both need a toolchain build of several minutes that `make test` does without.

#![allow(clippy::unwrap_used)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The fuzz targets' own checks (one copy, shared with `crate/fuzz/fuzz_targets/`).
#[path = "../fuzz/checks.rs"]
mod checks;

/// The generator's seed: `FUZZ_SEED` (as for `make fuzz-smoke`), else a fixed number.
fn seed() -> u64 {
    std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_261_122)
}

/// SplitMix64: small, fast and good enough to pick mutations; reproducible from its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (0 when `n` is 0).
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

/// The committed seeds of one target, sorted by name.
fn seeds(target: &str) -> Vec<Vec<u8>> {
    let dir = fuzz_dir().join("seeds").join(target);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no seeds in {}", dir.display());
    paths.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// The tokens of `gcode.dict` (libFuzzer's format: one quoted string a line, `\xNN` escapes).
fn dictionary() -> Vec<Vec<u8>> {
    let path = fuzz_dir().join("gcode.dict");
    let text = std::fs::read_to_string(&path).unwrap();
    let tokens: Vec<Vec<u8>> = text
        .lines()
        .filter_map(|l| l.trim().strip_prefix('"')?.strip_suffix('"'))
        .map(unescape)
        .collect();
    assert!(
        tokens.len() > 20,
        "{}: {} tokens",
        path.display(),
        tokens.len()
    );
    tokens
}

fn unescape(token: &str) -> Vec<u8> {
    let bytes = token.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes
            .get(i + 2..i + 4)
            .and_then(|h| u8::from_str_radix(std::str::from_utf8(h).ok()?, 16).ok());
        match (bytes[i], bytes.get(i + 1), hex) {
            (b'\\', Some(b'x'), Some(byte)) => {
                out.push(byte);
                i += 4;
            }
            (b'\\', Some(&c), _) => {
                out.push(c);
                i += 2;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    out
}

/// Bytes a G-code parser treats specially, for the byte-setting mutation.
const INTERESTING: &[u8] = b"\n\r \t;()*%-+.e0123456789GMTXYZEFIJRSPNgmxyz\x00\xff";

/// One of libFuzzer's mutations, picked by `rng`, applied to `data` in place.
fn mutate(data: &mut Vec<u8>, rng: &mut Rng, dict: &[Vec<u8>], other: &[u8]) {
    let len = data.len();
    let at = rng.below(len + 1);
    let span = 1 + rng.below(64.min(len.max(1)));
    let end = (at + span).min(len);
    match rng.below(7) {
        0 if len > 0 => data[at.min(len - 1)] ^= 1 << rng.below(8),
        1 if len > 0 => data[at.min(len - 1)] = INTERESTING[rng.below(INTERESTING.len())],
        2 => {
            let token = &dict[rng.below(dict.len())];
            data.splice(at..at, token.iter().copied());
        }
        3 => {
            data.drain(at..end);
        }
        4 => {
            let copy = data[at..end].to_vec();
            let to = rng.below(data.len() + 1);
            data.splice(to..to, copy);
        }
        5 => {
            let from = rng.below(other.len() + 1);
            data.truncate(at);
            data.extend_from_slice(&other[from..]);
        }
        _ => data.truncate(at),
    }
}

/// A seed picked by `rng` with one to five mutations.
fn mutated(seeds: &[Vec<u8>], dict: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let mut input = seeds[rng.below(seeds.len())].clone();
    for _ in 0..1 + rng.below(5) {
        let other = &seeds[rng.below(seeds.len())];
        mutate(&mut input, rng, dict, other);
    }
    input
}

/// Runs `runs` mutated inputs through `check`; panics listing every input that panicked or
/// took more than 10 s (cargo fuzz's `-timeout=10`), each saved to the temporary directory.
fn smoke(target: &str, check: fn(&[u8]), runs: usize) {
    let seeds = seeds(target);
    let dict = dictionary();
    let mut rng = Rng(seed()
        ^ target
            .bytes()
            .fold(0u64, |h, b| h.wrapping_mul(31) ^ u64::from(b)));
    let mut failures = Vec::new();
    for run in 0..runs {
        let input = mutated(&seeds, &dict, &mut rng);
        let started = Instant::now();
        let panicked = catch_unwind(AssertUnwindSafe(|| check(&input))).is_err();
        let secs = started.elapsed().as_secs_f64();
        if panicked || secs > 10.0 {
            let path = std::env::temp_dir().join(format!("quietpath-fuzz-{target}-{run}.gcode"));
            std::fs::write(&path, &input).unwrap();
            let why = if panicked {
                "panicked".to_string()
            } else {
                format!("took {secs:.1} s")
            };
            failures.push(format!("input {run} {why}: {}", path.display()));
        }
    }
    assert!(
        failures.is_empty(),
        "{target}: {} of {runs} inputs failed (copy them into crate/fuzz/regressions/):\n  {}",
        failures.len(),
        failures.join("\n  ")
    );
}

#[test]
fn mutated_seeds_parse_line() {
    smoke("parse_line", checks::parse_line, 100_000);
}

#[test]
fn mutated_seeds_analyze() {
    smoke("analyze", checks::analyze, 10_000);
}

#[test]
fn mutated_seeds_rewrite() {
    smoke("rewrite", checks::rewrite, 200_000);
}

#[test]
fn mutated_seeds_planner() {
    smoke("planner", checks::planner, 200_000);
}

#[test]
fn mutated_seeds_vtg() {
    smoke("vtg", checks::vtg, 400);
}

#[test]
fn mutated_seeds_infill() {
    smoke("infill", checks::infill, 20_000);
}

#[test]
fn mutated_seeds_smooth() {
    smoke("smooth", checks::smooth, 4_000);
}

#[test]
fn mutated_seeds_vibration() {
    smoke("vibration", checks::vibration, 100);
}

#[test]
fn the_dictionary_unescapes_hex_bytes() {
    assert_eq!(unescape(r"\x0d\x0a"), b"\r\n");
    assert_eq!(unescape(r#"a\"b"#), b"a\"b");
    assert_eq!(unescape(r"\xzz"), b"xzz");
}

#[test]
fn most_mutated_inputs_differ_from_every_seed() {
    let (seeds, dict) = (seeds("analyze"), dictionary());
    let mut rng = Rng(seed());
    let new = (0..200)
        .filter(|_| !seeds.contains(&mutated(&seeds, &dict, &mut rng)))
        .count();
    assert!(new >= 180, "only {new} of 200 mutated inputs are new");
}
