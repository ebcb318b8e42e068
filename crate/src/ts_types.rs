//! The TypeScript declarations of every serde type that crosses the JS boundary, rendered from
//! the Rust types by `ts-rs` (`#[cfg_attr(test, derive(ts_rs::TS))]` on each), so that the
//! declarations cannot drift from the JSON the CLI and the wasm package emit.
//!
//! The test below renders them into `src/wasm/types.generated.d.ts` (which the wasm package
//! includes as its `typescript_custom_section`) and fails when the committed file differs;
//! `UPDATE_TYPES=1 cargo test -p quietpath --lib ts_types` rewrites it.

use std::any::TypeId;
use std::collections::{BTreeMap, HashSet};
use std::fmt::Write as _;

use serde::de::DeserializeOwned;
use ts_rs::{Config, TypeVisitor, TS};

use crate::analyze::{AnalyzeOptions, Report};
use crate::dynamics::{VibrationOptions, VibrationReport};
use crate::energy::calibrate::{Calibration, CalibrationError, Observation};
use crate::error::ErrorKind;
use crate::estimate::EstimateReport;
use crate::infill::{InfillOptions, InfillReport};
use crate::optimize::{OptimizeOptions, OptimizeReport};
use crate::orient::{SmoothOptions, SmoothReport};
use crate::plan::MachineProfile;
use crate::vtg::{VtgOptions, VtgReport};

/// The generated file, relative to the crate.
const FILE: &str = "src/wasm/types.generated.d.ts";

/// The command that rewrites [`FILE`].
const COMMAND: &str = "UPDATE_TYPES=1 cargo test -p quietpath --lib ts_types";

/// Declarations gathered from the root types and everything they reference, by TS name (sorted,
/// so the file does not change with the order types are reached in).
struct Collector {
    cfg: Config,
    seen: HashSet<TypeId>,
    decls: BTreeMap<String, String>,
    /// Names of the options structs whose every field has a serde default: declared as
    /// `Partial<…>`, since JS may leave any field out.
    partial: HashSet<String>,
    /// Two Rust types with the same TS name (the second would silently replace the first).
    clashes: Vec<String>,
}

impl TypeVisitor for Collector {
    fn visit<T: TS + 'static + ?Sized>(&mut self) {
        // Primitives, `Vec`, `Option`… have no file of their own and no declaration.
        if T::output_path().is_none() || !self.seen.insert(TypeId::of::<T>()) {
            return;
        }
        let name = T::ident(&self.cfg);
        let mut text = String::new();
        if let Some(docs) = T::docs() {
            text.push_str(&docs);
        }
        if self.partial.contains(&name) {
            let _ = write!(
                text,
                "export {}",
                layout(&format!("type {name} = Partial<{}>;", T::inline(&self.cfg)))
            );
        } else {
            let _ = write!(text, "export {}", layout(&T::decl(&self.cfg)));
        }
        if self.decls.insert(name.clone(), text).is_some() {
            self.clashes.push(name);
        }
        T::visit_dependencies(self);
    }
}

impl Collector {
    /// An options struct: every field may be left out in JS. Checked: `{}` must deserialize.
    fn input<T: TS + DeserializeOwned + 'static>(&mut self) -> Result<(), String> {
        let name = T::ident(&self.cfg);
        serde_json::from_str::<T>("{}")
            .map_err(|e| format!("{name} is declared Partial but `{{}}` does not parse: {e}"))?;
        self.partial.insert(name);
        Ok(())
    }
}

/// Lays out one ts-rs declaration (one line but for its doc comments) as one member per line,
/// each object's `{` ending a line and its `}` starting one. wasm-bindgen re-indents the custom
/// section by exactly that rule (a line ending in `{` opens a level, one starting with `}`
/// closes it), so ts-rs's `…, last: T, };` would leave every later line one level deeper.
fn layout(decl: &str) -> String {
    let mut out = String::with_capacity(decl.len() * 5 / 4);
    // Open brackets: `{` breaks lines at its commas, `[` and `<` do not.
    let mut open: Vec<char> = Vec::new();
    let depth = |open: &[char]| open.iter().filter(|&&c| c == '{').count();
    let mut chars = decl.chars().peekable();
    let skip_spaces = |chars: &mut std::iter::Peekable<std::str::Chars<'_>>| {
        while chars.next_if_eq(&' ').is_some() {}
    };
    while let Some(c) = chars.next() {
        match c {
            '/' if chars.peek() == Some(&'*') => copy_comment(&mut chars, &mut out, depth(&open)),
            '"' => copy_string(&mut chars, &mut out),
            '{' => {
                open.push('{');
                out.push('{');
                newline(&mut out, depth(&open));
                skip_spaces(&mut chars);
            }
            '}' => {
                open.pop();
                newline(&mut out, depth(&open));
                out.push('}');
            }
            '[' | '<' => {
                open.push(c);
                out.push(c);
            }
            ']' | '>' => {
                if open.last() == Some(&if c == ']' { '[' } else { '<' }) {
                    open.pop();
                }
                out.push(c);
            }
            ',' if open.last() == Some(&'{') => {
                out.push(',');
                skip_spaces(&mut chars);
                if chars.peek() != Some(&'}') {
                    newline(&mut out, depth(&open));
                }
            }
            '\n' => {
                newline(&mut out, depth(&open));
                skip_spaces(&mut chars);
            }
            // No space after the indentation of a new line.
            ' ' if out.rsplit('\n').next().is_some_and(|l| l.trim().is_empty()) => {}
            _ => out.push(c),
        }
    }
    out.truncate(out.trim_end().len());
    out.push('\n');
    out
}

/// Ends the line (once: never an empty one) and indents the next by `depth` levels.
fn newline(out: &mut String, depth: usize) {
    out.truncate(out.trim_end_matches(' ').len());
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&"  ".repeat(depth));
}

/// Copies a doc comment whose `/` is already read, its lines re-indented to `depth`.
fn copy_comment(
    chars: &mut std::iter::Peekable<std::str::Chars<'_>>,
    out: &mut String,
    depth: usize,
) {
    out.push('/');
    let mut prev = '/';
    for c in chars.by_ref() {
        if c == '\n' {
            newline(out, depth);
        } else {
            out.push(c);
        }
        if prev == '*' && c == '/' {
            break;
        }
        prev = c;
    }
}

/// Copies a string literal (a tag's value) whose `"` is already read, as it is.
fn copy_string(chars: &mut std::iter::Peekable<std::str::Chars<'_>>, out: &mut String) {
    out.push('"');
    let mut escaped = false;
    for c in chars.by_ref() {
        out.push(c);
        if c == '"' && !escaped {
            break;
        }
        escaped = c == '\\' && !escaped;
    }
}

/// Whether wasm-bindgen's re-indentation (see [`layout`]) comes back to the left margin at the
/// end of `text`, never going below it.
fn balanced(text: &str) -> bool {
    let mut level: i64 = 0;
    for line in text.lines().map(str::trim) {
        if line.starts_with('*') {
            continue;
        }
        if line.starts_with('}') {
            level -= 1;
        }
        if level < 0 {
            return false;
        }
        if line.ends_with('{') {
            level += 1;
        }
    }
    level == 0
}

/// Renders the whole file.
fn render() -> Result<String, String> {
    let mut c = Collector {
        // serde_json writes u64 as a plain number; ts-rs's default would be `bigint`.
        cfg: Config::new().with_large_int("number"),
        seen: HashSet::new(),
        decls: BTreeMap::new(),
        partial: HashSet::new(),
        clashes: Vec::new(),
    };
    // The options of every job (all fields optional) and the structs nested in them that
    // are only ever read from JSON.
    c.input::<AnalyzeOptions>()?;
    c.input::<VtgOptions>()?;
    c.input::<InfillOptions>()?;
    c.input::<crate::infill::Weights>()?;
    c.input::<OptimizeOptions>()?;
    c.input::<SmoothOptions>()?;
    c.input::<crate::orient::Kinematics>()?;
    c.input::<VibrationOptions>()?;
    c.input::<crate::energy::EnergyOptions>()?;
    c.input::<crate::energy::AuxPowers>()?;
    c.input::<crate::energy::ServoProfile>()?;
    c.input::<crate::plan::KlipperConfig>()?;
    // The roots: what the wasm functions take and return (and the CLI's --json).
    c.visit::<Report>();
    c.visit::<AnalyzeOptions>();
    c.visit::<MachineProfile>();
    // Behind a `type` override in AnalyzeOptions (it also takes the config's text).
    c.visit::<crate::plan::KlipperConfig>();
    c.visit::<VtgOptions>();
    c.visit::<VtgReport>();
    c.visit::<InfillOptions>();
    c.visit::<InfillReport>();
    c.visit::<OptimizeOptions>();
    c.visit::<OptimizeReport>();
    c.visit::<EstimateReport>();
    c.visit::<SmoothOptions>();
    c.visit::<SmoothReport>();
    c.visit::<VibrationOptions>();
    c.visit::<VibrationReport>();
    c.visit::<Observation>();
    c.visit::<Calibration>();
    c.visit::<CalibrationError>();
    c.visit::<ErrorKind>();
    if !c.clashes.is_empty() {
        return Err(format!(
            "two Rust types share the TS name(s) {:?}: rename one with #[cfg_attr(test, ts(rename = \"…\"))]",
            c.clashes
        ));
    }
    let mut out = format!(
        "// GENERATED from the Rust types by crate/src/ts_types.rs (ts-rs): do not edit. Regenerate:\n\
         //   {COMMAND}\n\
         // The serde form of the reports, options and profiles: the same JSON as the CLI's --json.\n\
         // Hand-written declarations (typed-array results, callbacks, errors) are in types.d.ts.\n"
    );
    for text in c.decls.values() {
        out.push('\n');
        out.push_str(text);
    }
    if !balanced(&out) {
        return Err("the declarations' braces do not balance line by line (see layout())".into());
    }
    Ok(out)
}

#[test]
fn ts_types() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(FILE);
    let generated = match render() {
        Ok(text) => text,
        Err(e) => panic!("{e}"),
    };
    if std::env::var_os("UPDATE_TYPES").is_some() {
        if let Err(e) = std::fs::write(&path, &generated) {
            panic!("cannot write {}: {e}", path.display());
        }
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != generated {
        // The first line that differs, so the failure says what changed.
        let (n, old, new) = committed
            .lines()
            .map(Some)
            .chain(std::iter::repeat(None))
            .zip(generated.lines().map(Some).chain(std::iter::repeat(None)))
            .take(committed.lines().count().max(generated.lines().count()))
            .enumerate()
            .find(|(_, (a, b))| a != b)
            .map_or((0, None, None), |(i, (a, b))| (i + 1, a, b));
        panic!(
            "{FILE} is out of date with the Rust types: run `{COMMAND}` and commit the file\n\
             first difference, line {n}:\n  committed: {}\n  generated: {}",
            old.unwrap_or("(end of file)"),
            new.unwrap_or("(end of file)")
        );
    }
}
