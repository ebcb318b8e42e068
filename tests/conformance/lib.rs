//! Fixtures for the conformance suite: where the shared corpus lives and what its provenance
//! file (`SOURCES.md`) says about each file. The expectations come from the slicers' own
//! markers and summaries, not from quietpath.

use std::path::PathBuf;

/// The corpus directory: `$QUIETPATH_CORPUS`, else `../shared/corpus` beside the repository.
pub fn corpus_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("QUIETPATH_CORPUS") {
        return PathBuf::from(dir);
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus")
}

/// The repository's own test inputs: `tests/fixtures` (G-code sliced here from the OpenSCAD
/// models beside it; `tests/fixtures/README.md` says how).
pub fn fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures")
}

/// The G-code fixtures (`tests/fixtures/gcode/*.gcode`), sorted.
pub fn fixture_gcode() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(fixtures_dir().join("gcode"))
        .expect("fixtures")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "gcode"))
        .collect();
    files.sort();
    files
}

/// One row of the table in `SOURCES.md`.
#[derive(Debug, Clone)]
pub struct CorpusFile {
    /// File name.
    pub name: String,
    /// Size in bytes as listed.
    pub bytes: u64,
    /// Number of lines as listed.
    pub lines: u64,
    /// Count of the slicer's own layer markers, if it writes any.
    pub marker_layers: Option<u64>,
    /// Distinct Z heights at which extrusion happens.
    pub z_extruding: u64,
}

impl CorpusFile {
    /// Full path of the file.
    pub fn path(&self) -> PathBuf {
        corpus_dir().join(&self.name)
    }

    /// The file's bytes.
    pub fn read(&self) -> Vec<u8> {
        std::fs::read(self.path()).unwrap_or_else(|e| panic!("{}: {e}", self.path().display()))
    }
}

/// Every corpus file listed in `SOURCES.md`, in table order.
pub fn corpus() -> Vec<CorpusFile> {
    let sources = corpus_dir().join("SOURCES.md");
    let text = std::fs::read_to_string(&sources).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (the corpus must be at ../shared/corpus)",
            sources.display()
        )
    });
    let mut files = Vec::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | file | size | lines | slicer | flavour | M82 | M83 | G2 | G3 | TYPE | layers | Zext | axes |
        if cells.len() < 14 || !cells[1].ends_with(".gcode") {
            continue;
        }
        let num = |s: &str| s.parse::<u64>().ok();
        let marker_layers = cells[11].split_whitespace().next().and_then(num);
        files.push(CorpusFile {
            name: cells[1].to_string(),
            bytes: num(cells[2]).unwrap_or(0),
            lines: num(cells[3]).unwrap_or(0),
            marker_layers,
            z_extruding: num(cells[12]).unwrap_or(0),
        });
    }
    files
}
