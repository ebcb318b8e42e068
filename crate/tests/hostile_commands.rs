#![cfg(not(target_arch = "wasm32"))]
//! Hostile inputs through every command, not just the parser: each job (`analyze`, `vtg`,
//! `infill`, `smooth`, `vibration`) gives a typed error or a sane result (the fuzz targets'
//! checks, `crate/fuzz/checks.rs`), within a bounded time per megabyte. Inputs are generated
//! here: 200 000 layers, 2 000 layers of sharp corners, a 20 MB comment line, a megabyte of
//! random bytes, a file cut mid-line, CRLF, an empty file, zero, vanishing and absurd feed
//! rates, 1e15 mm moves and degenerate arcs. (NaN/1e999 words, UTF-16 and the parser's own
//! limits are in `hostile.rs`; fuzzing covers the rest of the space.)

#![allow(clippy::unwrap_used)]

use std::time::Instant;

#[path = "../fuzz/checks.rs"]
mod checks;

/// Seconds a job may take per megabyte of input (at least one megabyte's worth), in this
/// test profile (opt-level 1), with room for a loaded CI machine.
const SECONDS_PER_MB: f64 = 20.0;

type Check = fn(&[u8]);

const EVERY_JOB: [(&str, Check); 5] = [
    ("analyze", checks::analyze),
    ("vtg", checks::vtg),
    ("infill", checks::infill),
    ("smooth", checks::smooth),
    ("vibration", checks::vibration),
];

fn run_all(name: &str, data: &[u8], jobs: &[(&str, Check)]) {
    for (job, check) in jobs {
        let t = Instant::now();
        check(data);
        let secs = t.elapsed().as_secs_f64();
        eprintln!("{job} on {name}: {secs:.2} s");
        let limit = SECONDS_PER_MB * (data.len() as f64 / 1e6).max(1.0);
        assert!(
            secs <= limit,
            "{job} on {name}: {secs:.1} s (limit {limit:.0} s)"
        );
    }
}

/// `layers` layers of one extrusion line each (back and forth), with PrusaSlicer's markers: the
/// count of layers is what is hostile here, not the work per layer.
fn many_layers(layers: usize) -> Vec<u8> {
    let mut s = String::from("G21\nG90\nM83\n");
    for i in 0..layers {
        let z = 0.2 + i as f64 * 0.01;
        let x = if i % 2 == 0 { 10 } else { 0 };
        s.push_str(&format!(
            ";LAYER_CHANGE\n;Z:{z:.2}\nG1 Z{z:.2} F600\n;TYPE:Perimeter\nG1 X{x} E0.3 F1800\n"
        ));
    }
    s.into_bytes()
}

/// `layers` square perimeters, one per layer: four sharp corners a layer for VTG to round.
fn square_layers(layers: usize) -> Vec<u8> {
    let mut s = String::from("G21\nG90\nM83\n");
    for i in 0..layers {
        let z = 0.2 + i as f64 * 0.01;
        s.push_str(&format!(
            ";LAYER_CHANGE\n;Z:{z:.2}\nG1 Z{z:.2} F600\n;TYPE:External perimeter\n\
             G1 X10 Y0 E0.3 F1800\nG1 X10 Y10 E0.3\nG1 X0 Y10 E0.3\nG1 X0 Y0 E0.3\n"
        ));
    }
    s.into_bytes()
}

fn demo() -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../www/demo/demo.gcode");
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn two_hundred_thousand_layers() {
    let data = many_layers(200_000);
    let r = quietpath::analyze(&data, &Default::default()).unwrap();
    assert_eq!(r.layers, 200_000);
    run_all("200 000 layers", &data, &EVERY_JOB);
    // Work in every layer: VTG rounds 8 000 corners (with the lines they take allowed).
    let squares = square_layers(2_000);
    let v = quietpath::vtg::vtg(
        &squares,
        &quietpath::vtg::VtgOptions {
            dynamics: false,
            allow_more_lines_pct: 1000.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(v.paths.rewritten, 2_000);
    assert_eq!(v.layers.len(), 2_000);
    run_all("2 000 square layers", &squares, &EVERY_JOB);
}

#[test]
fn a_twenty_megabyte_comment_line() {
    let mut data = demo();
    data.extend_from_slice(b"; ");
    data.extend(std::iter::repeat_n(b'x', 20 << 20));
    data.extend_from_slice(b"\nG1 X1 Y1 E0.1\n");
    run_all("20 MB comment", &data, &EVERY_JOB);
}

#[test]
fn random_bytes_and_a_truncated_file() {
    // xorshift: deterministic noise, some of it line breaks and G-code letters.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let noise: Vec<u8> = (0..1 << 20)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            match x % 16 {
                0 => b'\n',
                1 => b'G',
                2 => b' ',
                _ => (x >> 8) as u8,
            }
        })
        .collect();
    run_all("random bytes", &noise, &EVERY_JOB);
    let full = demo();
    let cut = &full[..full.len() / 2 + 7]; // mid-line
    run_all("truncated demo", cut, &EVERY_JOB);
    let crlf: Vec<u8> = full
        .iter()
        .flat_map(|&b| {
            if b == b'\n' {
                vec![b'\r', b'\n']
            } else {
                vec![b]
            }
        })
        .collect();
    run_all("CRLF demo", &crlf, &EVERY_JOB);
    run_all("empty", b"", &EVERY_JOB);
}

#[test]
fn zero_vanishing_and_absurd_feeds_and_huge_moves() {
    let data = b"G21\nG90\nM83\n;LAYER_CHANGE\n;TYPE:External perimeter\nG1 X10 Y0 E1 F0\n\
G1 X10 Y10 E1 F1e-300\nG1 X0 Y10 E1 F1e300\nG1 X0 Y0 E1 Fnan\nG1 X1e15 Y0 E1\n\
G1 X0 Y1e15 E1\nG2 X0 Y0 I1e12 J0 E1\nG3 X5 Y5 R0 E1\nG1 X20 Y20 E1e300\nG1 X0 Y0 E-1e300\n";
    run_all("absurd feeds and moves", data, &EVERY_JOB);
}

/// 20 000 arcs with centre offsets up to 1e9 mm and end points up to 1e6 mm (1.4 MB): what
/// no printer runs must cost no more than a line (it cost 29 s to analyze and 118 s to rewrite
/// when every arc was cut into the most segments an arc gets).
fn absurd_arcs() -> Vec<u8> {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut out = String::from("G21\nG90\nM83\nG1 X0 Y0 F3000\n");
    for k in 0..20_000 {
        let (x, y, i, j) = (next() * 1e6, next() * 1e6, next() * 1e9, next() * 1e9);
        let g = 2 + k % 2;
        out += &format!("G{g} X{x:.3} Y{y:.3} I{i:.3} J{j:.3} E0.1 F1200\n");
    }
    out.into_bytes()
}

#[test]
fn arcs_larger_than_any_printer_cost_what_a_line_costs() {
    let data = absurd_arcs();
    let report = quietpath::analyze(&data, &Default::default()).unwrap();
    let first = report.warnings.first().unwrap();
    assert_eq!(first.line, 5, "the first absurd arc is named");
    assert!(
        first.message.contains("larger than any printer"),
        "{}",
        first.message
    );
    // The bound, 2 s per megabyte, here in the test profile.
    let jobs: [(&str, Check); 2] = [("analyze", checks::analyze), ("vtg", checks::vtg)];
    for (job, check) in jobs {
        let t = Instant::now();
        check(&data);
        let secs = t.elapsed().as_secs_f64();
        let limit = 2.0 * data.len() as f64 / 1e6;
        assert!(secs <= limit, "{job}: {secs:.2} s (limit {limit:.1} s)");
    }
    run_all("absurd arcs", &data, &EVERY_JOB);
}
