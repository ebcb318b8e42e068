#![cfg(not(target_arch = "wasm32"))]
//! Property tests of what users rely on from every optimiser, on random but plausible prints:
//! layers of star-shaped walls (4 to 11 corners, sharp and shallow turns, uneven edges) or of
//! square walls filled with a zigzag of infill at a random spacing, as a slicer fills them, in
//! absolute or relative extrusion.
//!
//! Each file goes through the fuzz targets' checks (`crate/fuzz/checks.rs`: typed errors or a
//! re-parsing output that keeps every non-motion line in order and writes only finite, sane
//! numbers; VTG within its measured tolerance; smoothing inside its cone; finite dynamics), and
//! filament is conserved as each optimiser states: VTG to the rounding of the E words it writes,
//! infill regeneration within 10 %.

use proptest::prelude::*;

#[path = "../fuzz/checks.rs"]
mod checks;

#[derive(Debug, Clone)]
struct Layer {
    /// Corners: (angle jitter in slot fractions, radius fraction).
    corners: Vec<(f64, f64)>,
    radius: f64,
    feed_mm_s: f64,
    /// A square wall filled with infill rows this far apart (mm) instead of the star.
    infill: Option<f64>,
}

fn layer() -> impl Strategy<Value = Layer> {
    (
        proptest::collection::vec((-0.3f64..0.3, 0.5f64..1.0), 4..12),
        3.0f64..25.0,
        10.0f64..150.0,
        proptest::option::of(0.8f64..2.5),
    )
        .prop_map(|(corners, radius, feed_mm_s, infill)| Layer {
            corners,
            radius,
            feed_mm_s,
            infill,
        })
}

/// The G-code of `layers` around (100, 100); `relative`: M83.
fn gcode(layers: &[Layer], relative: bool) -> String {
    const E_PER_MM: f64 = 0.0333;
    let mut s = format!(
        "G21\nG90\n{}\nG92 E0\n",
        if relative { "M83" } else { "M82" }
    );
    let mut e = 0.0f64;
    let mut at: (f64, f64);
    let mut extrude = |s: &mut String, at: &mut (f64, f64), to: (f64, f64), feed: Option<f64>| {
        let d = ((to.0 - at.0).powi(2) + (to.1 - at.1).powi(2)).sqrt() * E_PER_MM;
        e += d;
        let word = if relative { d } else { e };
        s.push_str(&format!("G1 X{:.3} Y{:.3} E{word:.5}", to.0, to.1));
        if let Some(f) = feed {
            s.push_str(&format!(" F{:.0}", f * 60.0));
        }
        s.push('\n');
        *at = to;
    };
    for (i, l) in layers.iter().enumerate() {
        let z = 0.2 * (i + 1) as f64;
        s.push_str(&format!(";LAYER_CHANGE\n;Z:{z:.1}\nG1 Z{z:.1} F600\n"));
        if let Some(spacing) = l.infill {
            // A square wall of half-side R and its inside filled edge to edge (less a line
            // width), row by row.
            let r = 8.0 + l.radius;
            let corners = [(r, -r), (r, r), (-r, r), (-r, -r)].map(|(x, y)| (100.0 + x, 100.0 + y));
            s.push_str(&format!("G0 X{:.3} Y{:.3} F9000\n", 100.0 - r, 100.0 - r));
            at = (100.0 - r, 100.0 - r);
            s.push_str(";TYPE:External perimeter\n");
            for (k, &p) in corners.iter().enumerate() {
                extrude(&mut s, &mut at, p, (k == 0).then_some(l.feed_mm_s));
            }
            let h = r - 0.45;
            s.push_str(&format!("G0 X{:.3} Y{:.3} F9000\n", 100.0 - h, 100.0 - h));
            at = (100.0 - h, 100.0 - h);
            s.push_str(";TYPE:Internal infill\n");
            let rows = (2.0 * h / spacing).floor() as usize;
            for row in 0..=rows {
                let y = 100.0 - h + spacing * row as f64;
                let (x0, x1) = if row % 2 == 0 {
                    (100.0 - h, 100.0 + h)
                } else {
                    (100.0 + h, 100.0 - h)
                };
                if row > 0 {
                    extrude(&mut s, &mut at, (x0, y), None);
                }
                extrude(&mut s, &mut at, (x1, y), Some(l.feed_mm_s));
            }
            continue;
        }
        let n = l.corners.len();
        let pts: Vec<(f64, f64)> = l
            .corners
            .iter()
            .enumerate()
            .map(|(k, &(jitter, r))| {
                let a = std::f64::consts::TAU * (k as f64 + jitter) / n as f64;
                (
                    100.0 + l.radius * r * a.cos(),
                    100.0 + l.radius * r * a.sin(),
                )
            })
            .collect();
        s.push_str(&format!("G0 X{:.3} Y{:.3} F9000\n", pts[0].0, pts[0].1));
        at = pts[0];
        s.push_str(";TYPE:External perimeter\n");
        for (k, &p) in pts.iter().skip(1).chain([&pts[0]]).enumerate() {
            extrude(&mut s, &mut at, p, (k == 0).then_some(l.feed_mm_s));
        }
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn every_optimiser_keeps_its_promises(
        layers in proptest::collection::vec(layer(), 1..5),
        relative in any::<bool>(),
    ) {
        let text = gcode(&layers, relative);
        let data = text.as_bytes();
        checks::analyze(data);
        checks::vtg(data);
        checks::infill(data);
        checks::smooth(data);
        checks::vibration(data);

        let vtg = quietpath::vtg::vtg(
            data,
            &quietpath::vtg::VtgOptions {
                dynamics: false,
                allow_more_lines_pct: 1000.0,
                ..Default::default()
            },
        );
        let vtg = vtg.map_err(|e| TestCaseError::fail(format!("vtg: {e}\n{text}")))?;
        // Each rewritten path writes its E words to 5 decimals from a running total (relative)
        // or as absolute positions ending on the original's last word: the file's filament
        // moves by at most half a unit of the last place per path.
        let (b, a) = (vtg.before.filament_mm, vtg.after.filament_mm);
        let bound = 1e-5 * (1 + vtg.paths.rewritten) as f64 + 1e-9;
        prop_assert!((a - b).abs() <= bound, "VTG filament {b} -> {a}\n{text}");
        prop_assert!(vtg.max_deviation_mm <= vtg.tolerance_mm * 1.01);

        if let Ok(r) = quietpath::infill::infill(data, &Default::default()) {
            let (b, a) = (r.before.filament_mm, r.after.filament_mm);
            prop_assert!((a - b).abs() <= 0.1 * b, "infill filament {b} -> {a}\n{text}");
        }
    }
}
