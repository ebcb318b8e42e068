use super::*;
use crate::analyze::{analyze, AnalyzeOptions};

fn folded(g: &str) -> (String, u64) {
    match fold(g.as_bytes()) {
        Some(f) => (String::from_utf8(f.bytes.clone()).unwrap(), f.lines()),
        None => (g.to_string(), 0),
    }
}

#[test]
fn a_feed_line_is_folded_into_the_move_that_reads_it() {
    let g = "G90\nM83\nG1 F6000\nG1 X1 Y2 E.1\nG1 X3 Y2 E.1\n";
    assert_eq!(
        folded(g),
        ("G90\nM83\nG1 X1 Y2 E.1 F6000\nG1 X3 Y2 E.1\n".into(), 1)
    );
}

/// Comments, progress, fans, accelerations and E resets leave the feed unread; the line
/// endings of a CRLF file stay CRLF.
#[test]
fn lines_that_do_not_read_the_feed_are_crossed() {
    let g = "G1 F1800\r\n;TYPE:Perimeter\r\n\r\nM73 P1 R2\r\nM204 S800\r\nM106 S255\r\nG92 E0\r\n\
SET_VELOCITY_LIMIT ACCEL=500\r\nG1 X1 Y2 E.1 \r\nG1 X2 E.1\r\n";
    let (out, lines) = folded(g);
    assert_eq!(lines, 1);
    assert!(out.starts_with(";TYPE:Perimeter\r\n\r\nM73"), "{out}");
    assert!(
        out.ends_with("ACCEL=500\r\nG1 X1 Y2 E.1 F1800 \r\nG1 X2 E.1\r\n"),
        "{out}"
    );
}

/// A feed the next move overrides, or the next feed line of the same command, is never read:
/// dropped.
#[test]
fn a_feed_never_read_is_dropped() {
    let g = "G1 F6000\nG1 X1 Y2 F30000\nG1 F1200\nG1 F1500\nG2 X2 Y3 I1 J0 E.2\n";
    assert_eq!(
        folded(g),
        ("G1 X1 Y2 F30000\nG2 X2 Y3 I1 J0 E.2 F1500\n".into(), 3)
    );
}

/// What might read the feed, or read another one, ends the search: a macro, a tool change, a
/// `G0` after a `G1` feed (Marlin's `VARIABLE_G0_FEEDRATE`), a move with a comment or a line
/// number; the feed lines with comments stay too.
#[test]
fn a_feed_is_left_where_something_else_may_read_it() {
    for g in [
        "G1 F6000\nM600\nG1 X1 E1\n",
        "G1 F6000\nT1\nG1 X1 E1\n",
        "G1 F6000\nPAUSE\nG1 X1 E1\n",
        "G1 F6000\nG28 X\nG1 X1 E1\n",
        "G1 F6000\nG0 X5 Y5\nG1 X1 E1\n",
        "G0 F9000\nG1 X5 Y5\n",
        "G1 F6000\nG1 X1 E1 ; wall\n",
        "G1 F6000\nN10 G1 X1 E1*12\n",
        "G1 F6000 ; speed\nG1 X1 E1\n",
        "G1 F6000 X2\nG1 X1 E1\n",
    ] {
        assert_eq!(folded(g), (g.to_string(), 0), "{g}");
    }
    assert_eq!(
        folded("G0 F9000\nG0 X5 Y5\n"),
        ("G0 X5 Y5 F9000\n".into(), 1)
    );
}

/// The demo (PrusaSlicer 2.5) folded plans the same to the bit, with as many moves, the same
/// filament and energy, in 226 fewer lines; folding it again finds nothing.
#[test]
fn a_folded_file_plans_as_the_original_does() {
    let demo = include_bytes!("../../../../www/demo/demo.gcode");
    let f = fold(demo).expect("feed lines");
    let options = AnalyzeOptions::default();
    let (a, b) = (
        analyze(demo, &options).unwrap(),
        analyze(&f.bytes, &options).unwrap(),
    );
    assert_eq!(f.lines(), 226);
    assert_eq!(b.file.lines + f.lines(), a.file.lines);
    assert_eq!(a.time_s, b.time_s);
    assert_eq!(a.moves, b.moves);
    assert_eq!(a.filament_mm, b.filament_mm);
    assert_eq!(a.energy, b.energy);
    let unnumbered = |r: &crate::analyze::Report| {
        let mut layers = r.layer_list.clone();
        layers.iter_mut().for_each(|l| l.line = 0);
        layers
    };
    assert_eq!(unnumbered(&a), unnumbered(&b));
    assert_eq!(fold(&f.bytes), None);
}

/// The lines removed are numbered as in the original; the kept lines after them move up by as
/// many (what the rewrite's timing, read from the original's analysis, is matched by).
#[test]
fn the_original_s_lines_are_found_in_the_folded_file() {
    let g = b"M83\nG1 F600\nG1 X1 E1\nG1 F900\nG1 F1200\nG1 X2 E1\nM400\n";
    let f = fold(g).expect("folded");
    assert_eq!(f.removed, vec![2, 4, 5]);
    assert_eq!([1, 3, 6, 7].map(|l| f.line_in_folded(l)), [1, 2, 3, 4]);
    let lines: Vec<&[u8]> = f.bytes.split(|&b| b == b'\n').collect();
    assert_eq!(lines[2], b"G1 X2 E1 F1200");
}

/// Folded in place, a file comes out as [`fold`] writes it, with as many lines removed.
#[test]
fn folding_in_place_writes_what_folding_a_copy_does() {
    let demo = include_bytes!("../../../../www/demo/demo.gcode");
    let cases: [&[u8]; 4] = [
        demo,
        b"G1 F6000\nG1 X1 Y2 F30000\nG1 F1200\nG1 F1500\nG2 X2 Y3 I1 J0 E.2\n",
        b"G1 F1800\r\n;TYPE:Perimeter\r\nM204 S800\r\nG1 X1 Y2 E.1\r\nG1 X2 E.1",
        b"G90\nG1 X5 Y5\n",
    ];
    for g in cases {
        let mut bytes = g.to_vec();
        let removed = fold_in_place(&mut bytes);
        match fold(g) {
            Some(f) => assert_eq!((&bytes, removed), (&f.bytes, f.lines())),
            None => assert_eq!((&bytes[..], removed), (g, 0)),
        }
    }
}

/// A line of a random program: moves of every kind with and without feeds, feed-only lines,
/// lines a fold crosses and lines that stop it, mode changes and comments.
fn program_line() -> impl proptest::strategy::Strategy<Value = String> {
    use proptest::prelude::*;
    let coord = || (0u32..2000).prop_map(|v| f64::from(v) / 10.0);
    let feed = || (1u32..400).prop_map(|v| v * 60);
    prop_oneof![
        feed().prop_map(|f| format!("G1 F{f}")),
        feed().prop_map(|f| format!("G0 F{f}")),
        (coord(), coord()).prop_map(|(x, y)| format!("G1 X{x} Y{y} E0.05")),
        (coord(), coord(), feed()).prop_map(|(x, y, f)| format!("G1 X{x} Y{y} E0.05 F{f}")),
        (coord(), coord()).prop_map(|(x, y)| format!("G0 X{x} Y{y}")),
        (coord(), feed()).prop_map(|(x, f)| format!("G0 X{x} F{f}")),
        (coord(), coord()).prop_map(|(x, y)| format!("G2 X{x} Y{y} I1 J1 E0.1")),
        (1u32..30).prop_map(|z| format!("G1 Z{}", f64::from(z) / 10.0)),
        Just("G1 E-0.8".to_string()),
        Just("G1 E0.8 F2100".to_string()),
        (200u32..5000).prop_map(|a| format!("M204 S{a}")),
        Just("M106 S255".to_string()),
        Just("M107".to_string()),
        Just("G92 E0".to_string()),
        Just("M73 P10 R5".to_string()),
        Just(";TYPE:Perimeter".to_string()),
        Just(String::new()),
        Just("M400".to_string()),
        Just("M83".to_string()),
        Just("M82".to_string()),
        Just("G91".to_string()),
        Just("G90".to_string()),
        Just("G1 X1 E0.05 ; wall".to_string()),
    ]
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]
    /// Any program folded plans as it did, to the bit (under the classic-jerk and Klipper
    /// planners), with the same moves, filament and
    /// energy, in as many fewer lines as were folded; folding in place writes the same bytes,
    /// folding again finds nothing, and each kept line is found where `line_in_folded` says.
    #[test]
    fn any_program_folded_plans_as_it_did(
        lines in proptest::collection::vec(program_line(), 1..80),
        crlf in proptest::bool::ANY,
        klipper in proptest::bool::ANY,
    ) {
        let end = if crlf { "\r\n" } else { "\n" };
        let g = format!("G90\nM83\nG28\n{}{end}", lines.join(end));
        let Some(f) = fold(g.as_bytes()) else {
            return Ok(());
        };
        let options = AnalyzeOptions {
            junction_model: klipper.then_some(crate::plan::JunctionModel::Klipper),
            ..AnalyzeOptions::default()
        };
        let (a, b) = (
            analyze(g.as_bytes(), &options).unwrap(),
            analyze(&f.bytes, &options).unwrap(),
        );
        proptest::prop_assert_eq!(b.file.lines + f.lines(), a.file.lines);
        proptest::prop_assert_eq!(a.time_s.to_bits(), b.time_s.to_bits(), "{}", g);
        proptest::prop_assert_eq!(a.moves, b.moves);
        proptest::prop_assert_eq!(a.filament_mm.to_bits(), b.filament_mm.to_bits());
        proptest::prop_assert_eq!(&a.energy, &b.energy);
        proptest::prop_assert_eq!(fold(&f.bytes), None);
        let mut bytes = g.as_bytes().to_vec();
        proptest::prop_assert_eq!(fold_in_place(&mut bytes), f.lines());
        proptest::prop_assert_eq!(&bytes, &f.bytes);
        let kept: Vec<&str> = g.split('\n').collect();
        let out: Vec<&[u8]> = f.bytes.split(|&c| c == b'\n').collect();
        for (i, line) in kept.iter().enumerate() {
            let n = i as u32 + 1;
            if f.removed.contains(&n) || line.starts_with("G") {
                continue;
            }
            let at = f.line_in_folded(n) as usize - 1;
            proptest::prop_assert_eq!(out[at], line.as_bytes());
        }
    }
}
