//! No function in the library is longer than a reader can hold: 80 lines from its `fn` to its
//! closing brace, test modules included. The one exception is the parser's hand tokenizer
//! (`gcode::line::parse_line_into`), a single state machine over the bytes of a line that reads
//! worse cut into pieces.

use std::path::{Path, PathBuf};

const MAX_LINES: usize = 80;
const EXCEPTIONS: &[(&str, &str)] = &[("gcode/line.rs", "parse_line_into")];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("read src") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `(name, first line, lines)` of every function in `text`, found by indentation: a line whose
/// code starts with `fn` or a qualified `fn` opens one, and the first later line at the same
/// indentation that starts with `}` closes it (rustfmt's layout).
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let code = line.trim_start();
        let indent = line.len() - code.len();
        let after_qualifiers = code
            .trim_start_matches("pub(crate) ")
            .trim_start_matches("pub(super) ")
            .trim_start_matches("pub ")
            .trim_start_matches("const ")
            .trim_start_matches("unsafe ")
            .trim_start_matches("async ");
        let Some(rest) = after_qualifiers.strip_prefix("fn ") else {
            continue;
        };
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let end = lines[i..].iter().position(|l| {
            let t = l.trim_start();
            l.len() - t.len() == indent && t.starts_with('}')
        });
        // A declaration without a body (`fn f();` in a trait) has no closing brace of its own.
        if lines[i..]
            .iter()
            .take_while(|l| !l.contains('{'))
            .any(|l| l.trim_end().ends_with(';'))
        {
            continue;
        }
        if let Some(end) = end {
            out.push((name, i + 1, end + 1));
        }
    }
    out
}

#[test]
fn no_function_is_longer_than_eighty_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    files.sort();
    let mut long = Vec::new();
    for file in &files {
        let rel = file
            .strip_prefix(&root)
            .expect("under src")
            .to_string_lossy()
            .replace('\\', "/");
        let text = std::fs::read_to_string(file).expect("read");
        for (name, line, len) in functions(&text) {
            let excepted = EXCEPTIONS.iter().any(|(f, n)| rel == *f && name == *n);
            if len > MAX_LINES && !excepted {
                long.push(format!("{rel}:{line} {name}: {len} lines"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn the_measure_counts_from_fn_to_its_closing_brace() {
    let text = "fn a() {\n    x();\n}\n\nimpl T {\n    pub fn b(\n        y: u8,\n    ) {\n        if y {\n        }\n    }\n    fn c();\n}\n";
    let f = functions(text);
    assert_eq!(f, vec![("a".into(), 1, 3), ("b".into(), 6, 6)]);
}
