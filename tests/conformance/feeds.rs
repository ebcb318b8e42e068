//! Feed-only lines folded into the moves that read them (`quietpath::vtg::feeds`), as `vtg`
//! does before it rewrites a file: on every corpus file and fixture that has them, the folded
//! file plans to the same time to the bit, with the same moves, filament and energy, in as
//! many fewer lines as were folded; folding it again finds nothing. Klipper's own planner on
//! the folded K1C benchy: `klipper.rs`.

use quietpath::vtg::feeds::fold;
use quietpath::{analyze, AnalyzeOptions};
use quietpath_conformance::{corpus, fixture_gcode};

#[test]
fn folded_files_plan_as_the_originals_do() {
    let mut files: Vec<(String, Vec<u8>)> = corpus()
        .into_iter()
        .filter(|c| !c.name.contains("large") && !c.name.contains("multiaxis"))
        .map(|c| (c.name.clone(), c.read()))
        .collect();
    for p in fixture_gcode() {
        let name = p.file_name().unwrap_or_default().to_string_lossy().into();
        files.push((name, std::fs::read(&p).expect("fixture")));
    }
    let options = AnalyzeOptions::default();
    let mut folded_files = 0;
    for (name, bytes) in &files {
        let Some(f) = fold(bytes) else { continue };
        folded_files += 1;
        let (a, b) = (
            analyze(bytes, &options).expect("original"),
            analyze(&f.bytes, &options).expect("folded"),
        );
        assert_eq!(b.file.lines + f.lines(), a.file.lines, "{name}: lines");
        assert!(b.file.bytes < a.file.bytes, "{name}: bytes");
        assert_eq!(a.time_s, b.time_s, "{name}: time");
        assert_eq!(a.moves, b.moves, "{name}: moves");
        assert_eq!(a.filament_mm, b.filament_mm, "{name}: filament");
        assert_eq!(a.energy, b.energy, "{name}: energy");
        assert!(fold(&f.bytes).is_none(), "{name}: folded twice");
    }
    // PrusaSlicer and its descendants write them (the fixtures, five corpus files and more).
    assert!(
        folded_files >= 25,
        "only {folded_files} files with feed lines"
    );
}
