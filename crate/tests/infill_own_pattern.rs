//! The own-pattern bar (issue 30): on parts PrusaSlicer sliced with its connected rectilinear
//! infill at 45°, regenerating that same pattern at that same angle must give a file within
//! +2 % of the slicer's time and +10 % of its travel, with every new infill move inside the
//! part. Time and travel are `analyze` of the written file; "inside" is measured here from the
//! written G-code alone (the layer's external-perimeter loops, even-odd), not from the
//! generator's regions.
#![cfg(not(target_arch = "wasm32"))]
#![allow(clippy::unwrap_used)]

use std::path::Path;

use quietpath::infill::{infill, Choice, InfillOptions, Pattern};

/// PrusaSlicer 2.5.0 files with rectilinear 20 %/15 % infill at 45° (tests/fixtures/README.md).
const PARTS: [&str; 11] = [
    "bored_block_rect45",
    "bosses_rect45",
    "ribbed_box_rect45",
    "islands_rect45",
    "cube_marlin2_defaults",
    "thesis_l_bracket",
    "thesis_square",
    "thesis_rectangle",
    "thesis_triangle",
    "thesis_teardrop",
    "thesis_oval",
];

type P2 = [f64; 2];

/// One layer of a file as the test reads it: external-perimeter polylines and the sparse
/// infill's extruding moves.
#[derive(Default)]
struct Layer {
    outline: Vec<Vec<P2>>,
    infill: Vec<[P2; 2]>,
}

/// Reads PrusaSlicer-style G-code (absolute XY, `;TYPE:` and `;LAYER_CHANGE` comments,
/// relative or absolute E): per layer the external perimeters and the sparse-infill moves.
fn layers(text: &str) -> Vec<Layer> {
    let mut out: Vec<Layer> = vec![Layer::default()];
    let (mut pos, mut e, mut rel_e) = ([0.0f64; 2], 0.0f64, false);
    let mut kind = String::new();
    let mut last_outline_end: Option<P2> = None;
    for line in text.lines() {
        if line.starts_with(";LAYER_CHANGE") {
            out.push(Layer::default());
            last_outline_end = None;
            continue;
        }
        if let Some(t) = line.strip_prefix(";TYPE:") {
            kind = t.trim().to_string();
            continue;
        }
        let code = line.split(';').next().unwrap_or("").trim();
        match code {
            "M83" => rel_e = true,
            "M82" => rel_e = false,
            _ => {}
        }
        let mut words = code.split_whitespace();
        let Some(cmd) = words.next() else { continue };
        let (mut to, mut de) = (pos, 0.0);
        let mut ne = None;
        for w in words {
            let v: f64 = w[1..].parse().unwrap_or(f64::NAN);
            match &w[..1] {
                "X" => to[0] = v,
                "Y" => to[1] = v,
                "E" => ne = Some(v),
                _ => {}
            }
        }
        if cmd == "G92" {
            e = ne.unwrap_or(e);
            continue;
        }
        if cmd != "G1" && cmd != "G0" {
            continue;
        }
        if let Some(v) = ne {
            de = if rel_e { v } else { v - e };
            e = if rel_e { e + v } else { v };
        }
        let layer = out.last_mut().unwrap();
        let moved = to != pos;
        if moved && de > 0.0 {
            if kind == "External perimeter" {
                if last_outline_end != Some(pos) {
                    layer.outline.push(vec![pos]);
                }
                layer.outline.last_mut().unwrap().push(to);
                last_outline_end = Some(to);
            } else if kind == "Internal infill" {
                layer.infill.push([pos, to]);
            }
        }
        pos = to;
    }
    out
}

fn inside(loops: &[Vec<P2>], p: P2) -> bool {
    let mut odd = false;
    for c in loops {
        for w in c.windows(2) {
            let (a, b) = (w[0], w[1]);
            if (a[1] > p[1]) != (b[1] > p[1])
                && a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) > p[0]
            {
                odd = !odd;
            }
        }
    }
    odd
}

fn seg_dist(p: P2, a: P2, b: P2) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

/// Length of sparse infill, and of the part of it that lies inside the layer's outline and at
/// least `clear` mm from the external perimeter's centre line (sampled every 0.25 mm).
fn infill_inside(text: &str, clear: f64) -> (f64, f64) {
    let (mut all, mut ok) = (0.0, 0.0);
    for layer in layers(text) {
        // Closed loops only (PrusaSlicer ends a loop a little short of its start: close it).
        let loops: Vec<Vec<P2>> = layer
            .outline
            .into_iter()
            .filter(|c| c.len() >= 3)
            .map(|mut c| {
                c.push(c[0]);
                c
            })
            .collect();
        for [a, b] in layer.infill {
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let n = (len / 0.25).ceil().max(1.0) as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                let w = len / (n + 1) as f64;
                all += w;
                let far = loops
                    .iter()
                    .flat_map(|c| c.windows(2))
                    .all(|s| seg_dist(p, s[0], s[1]) >= clear);
                if inside(&loops, p) && far {
                    ok += w;
                }
            }
        }
    }
    (all, ok)
}

#[test]
fn regenerating_the_slicers_own_pattern_matches_its_time_and_travel() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/gcode");
    let o = InfillOptions {
        patterns: vec![Pattern::Rectilinear],
        angles_deg: vec![45.0],
        force_candidate: true,
        estimates: false,
        ..Default::default()
    };
    let mut failures = Vec::new();
    for part in PARTS {
        let input = std::fs::read(dir.join(format!("prusaslicer-2.5.0_{part}.gcode"))).unwrap();
        let r = infill(&input, &o).unwrap();
        assert_ne!(r.best.pattern, Choice::Original, "{part}: not regenerated");
        let before = quietpath::analyze(&input, &o.analyze).unwrap();
        let after = quietpath::analyze(&r.output, &o.analyze).unwrap();
        let dt = after.time_s / before.time_s - 1.0;
        let dtravel = after.travel_distance_mm / before.travel_distance_mm - 1.0;
        let (all, ok) = infill_inside(std::str::from_utf8(&r.output).unwrap(), 0.5);
        let (all0, ok0) = infill_inside(std::str::from_utf8(&input).unwrap(), 0.5);
        eprintln!(
            "{part}: time {:+.2} %, travel {:+.1} %, infill inside {:.3} % (slicer's {:.3} %)",
            100.0 * dt,
            100.0 * dtravel,
            100.0 * ok / all,
            100.0 * ok0 / all0
        );
        if dt > 0.02 || dtravel > 0.10 || ok < 0.999 * all {
            failures.push(part);
        }
    }
    assert!(failures.is_empty(), "over the bar: {failures:?}");
}
