//! The crate's modules stay in their layers: no module names a module above it.
//!
//! Every `crate::…` path in the code of `crate/src/**/*.rs` (comments and doc comments are
//! skipped, so a doc link may point anywhere) is attributed to the top-level module of the file
//! it is in and checked against [`ALLOWED`]. Grouped imports (`use crate::{a::X, b::Y}`) count
//! each of their top-level names. `super::` paths are not followed: they stay inside the module
//! of the file (the one exception, `super::` in a top-level file, names the crate root, which
//! defines nothing but modules and re-exports).
#![cfg(not(target_arch = "wasm32"))]

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Helpers at the crate root that every module may use, and that use only each other.
const ROOT_HELPERS: &[&str] = &["error", "math", "parallel", "progress", "vec3"];

/// Lowest layer first: each module and the modules (besides [`ROOT_HELPERS`]) it may use.
///
/// gcode → machine → plan → energy → read → analyze → path → estimate → dynamics / vtg / infill /
/// orient → optimize → cli / wasm. `read` sits above `energy` because its options carry the energy settings every
/// job passes on. `vtg` may use `dynamics` (its deviation rows); the four top library modules
/// use nothing else of each other.
const ALLOWED: &[(&str, &[&str])] = &[
    ("gcode", &[]),
    ("machine", &["gcode"]),
    ("plan", &["gcode", "machine"]),
    ("energy", &["gcode", "machine", "plan"]),
    ("read", &["gcode", "machine", "plan", "energy"]),
    ("analyze", &["gcode", "machine", "plan", "read", "energy"]),
    (
        "path",
        &["gcode", "machine", "plan", "read", "energy", "analyze"],
    ),
    (
        "estimate",
        &[
            "gcode", "machine", "plan", "read", "energy", "analyze", "path",
        ],
    ),
    (
        "dynamics",
        &[
            "gcode", "machine", "plan", "read", "energy", "analyze", "path",
        ],
    ),
    (
        "vtg",
        &[
            "gcode", "machine", "plan", "read", "energy", "analyze", "path", "dynamics", "estimate",
        ],
    ),
    (
        "infill",
        &[
            "gcode", "machine", "plan", "read", "energy", "analyze", "path", "estimate",
        ],
    ),
    (
        "orient",
        &[
            "gcode", "machine", "plan", "read", "energy", "analyze", "path", "estimate",
        ],
    ),
    (
        "optimize",
        &[
            "gcode", "machine", "plan", "read", "energy", "analyze", "path", "estimate",
            "dynamics", "vtg", "infill",
        ],
    ),
];

/// Front ends: they may use everything. `ts_types` (test-only) renders the JS boundary's
/// TypeScript declarations, so it names the report and option types of every layer, as `wasm`.
const FRONT_ENDS: &[&str] = &["cli", "wasm", "ts_types"];

/// Root helpers may use these (each other, never a layer).
const HELPER_USES: &[(&str, &[&str])] = &[
    ("error", &[]),
    ("math", &[]),
    ("parallel", &[]),
    ("progress", &[]),
    ("vec3", &["math"]),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("read src")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The code of a Rust file with its comments blanked out (string literals kept: a `//` inside
/// one is taken as a comment, which can only hide a path, never invent one).
fn strip_comments(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let mut depth = 0usize;
    while i < b.len() {
        if depth > 0 {
            if b[i..].starts_with(b"*/") {
                depth -= 1;
                i += 2;
            } else if b[i..].starts_with(b"/*") {
                depth += 1;
                i += 2;
            } else {
                if b[i] == b'\n' {
                    out.push('\n');
                }
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            depth = 1;
            i += 2;
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else {
            let ch = text[i..].chars().next().expect("char");
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The top-level names a `crate::` path at the start of `rest` reaches: one for `crate::a::…`,
/// each item's first name for `crate::{a::…, b, …}`.
fn reached(rest: &str) -> Vec<String> {
    let rest = rest.trim_start();
    if let Some(group) = rest.strip_prefix('{') {
        let mut names = Vec::new();
        let mut depth = 0usize;
        let mut start = true;
        for (k, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => start = true,
                c if start && !c.is_whitespace() => {
                    start = false;
                    let name = ident_at(&group[k..]);
                    if !name.is_empty() && name != "self" {
                        names.push(name.to_string());
                    }
                }
                _ => {}
            }
        }
        names
    } else {
        vec![ident_at(rest).to_string()]
    }
}

/// Every (file, top-level module of the file, module named) of the crate's sources.
fn edges() -> Vec<(String, String, String)> {
    let root = src();
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut out = Vec::new();
    for f in files {
        let rel = f.strip_prefix(&root).expect("under src");
        let first = rel.iter().next().expect("component").to_string_lossy();
        let module = first.trim_end_matches(".rs").to_string();
        if module == "lib" || module == "main" {
            continue;
        }
        let code = strip_comments(&std::fs::read_to_string(&f).expect("read"));
        let mut at = 0;
        while let Some(k) = code[at..].find("crate::") {
            let pos = at + k;
            at = pos + "crate::".len();
            let before = code[..pos].chars().next_back();
            if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$') {
                continue;
            }
            for name in reached(&code[at..]) {
                out.push((rel.display().to_string(), module.clone(), name));
            }
        }
    }
    out
}

fn table(module: &str) -> Option<Vec<&'static str>> {
    let listed = |t: &[(&str, &'static [&'static str])]| {
        t.iter()
            .find(|(m, _)| *m == module)
            .map(|(_, uses)| uses.to_vec())
    };
    if let Some(mut uses) = listed(ALLOWED) {
        uses.extend_from_slice(ROOT_HELPERS);
        return Some(uses);
    }
    listed(HELPER_USES)
}

fn known_modules() -> BTreeSet<&'static str> {
    ALLOWED
        .iter()
        .chain(HELPER_USES)
        .map(|(m, _)| *m)
        .chain(FRONT_ENDS.iter().copied())
        .collect()
}

#[test]
fn no_module_uses_a_module_above_it() {
    let known = known_modules();
    let mut bad = Vec::new();
    for (file, module, used) in edges() {
        assert!(
            known.contains(module.as_str()),
            "{file}: module `{module}` is not in the layering table of tests/layering.rs"
        );
        if FRONT_ENDS.contains(&module.as_str()) || used == module {
            continue;
        }
        // Not a module: an item re-exported at the root (`crate::VERSION`, `crate::Error`).
        if !known.contains(used.as_str()) {
            continue;
        }
        let allowed = table(&module).expect("listed");
        if !allowed.contains(&used.as_str()) {
            bad.push(format!("{file}: `{module}` uses `crate::{used}`"));
        }
    }
    bad.sort();
    bad.dedup();
    assert!(
        bad.is_empty(),
        "imports against the layering:\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_table_is_acyclic_and_lists_every_module() {
    // Each module may only use modules listed before it (a lower layer).
    let mut seen: BTreeSet<&str> = BTreeSet::new();
    for (m, uses) in ALLOWED {
        for u in *uses {
            assert!(
                seen.contains(u),
                "`{m}` may use `{u}`, which is not below it"
            );
        }
        seen.insert(m);
    }
    for (m, uses) in HELPER_USES {
        for u in *uses {
            assert!(ROOT_HELPERS.contains(u), "helper `{m}` may use `{u}`");
        }
    }
    let known = known_modules();
    let root = src();
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    for f in files {
        let rel = f.strip_prefix(&root).expect("under src");
        let first = rel.iter().next().expect("component").to_string_lossy();
        let module = first.trim_end_matches(".rs");
        if module != "lib" && module != "main" {
            assert!(
                known.contains(module),
                "module `{module}` is not in the table"
            );
        }
    }
}

#[test]
fn the_scanner_sees_paths_and_groups() {
    let code = strip_comments(
        "use crate::{analyze::{a, b}, plan::X, self};\n// crate::vtg\n/* crate::path */ crate::math::f();",
    );
    let names: Vec<String> = code
        .match_indices("crate::")
        .flat_map(|(k, _)| reached(&code[k + 7..]))
        .collect();
    assert_eq!(names, ["analyze", "plan", "math"]);
}
