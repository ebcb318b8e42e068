//! Reading a Klipper `printer.cfg` from disk, `[include …]` globs followed as Klipper does:
//! relative to the including file, matches in sorted order, a glob with no match allowed, a
//! plain name that does not exist an error.

use std::path::{Path, PathBuf};

use quietpath::plan::KlipperConfig;

/// Reads the config at `path` with its includes.
pub fn read_config(path: &Path) -> Result<KlipperConfig, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let name = path.display().to_string();
    KlipperConfig::parse(&name, &text, &mut |pattern, from| {
        let dir = Path::new(from).parent().unwrap_or(Path::new("."));
        include(dir, pattern)
    })
    .map_err(|e| e.to_string())
}

/// The files an `[include pattern]` names, relative to `dir`, as (name, text).
fn include(dir: &Path, pattern: &str) -> Result<Vec<(String, String)>, String> {
    let full = dir.join(pattern);
    let files: Vec<PathBuf> = if pattern.contains(['*', '?', '[']) {
        let parent = full.parent().unwrap_or(dir);
        let glob = full.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let entries =
            std::fs::read_dir(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        let mut found: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .map(|entry| entry.path())
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| matches(glob.as_bytes(), n.as_bytes()))
            })
            .collect();
        found.sort();
        found
    } else if full.is_file() {
        vec![full]
    } else {
        return Err(format!("include file {} does not exist", full.display()));
    };
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            Ok((p.display().to_string(), text))
        })
        .collect()
}

/// Whether `name` matches the shell pattern `glob` (`*`, `?`, `[abc]`, `[a-z]`).
fn matches(glob: &[u8], name: &[u8]) -> bool {
    match glob.split_first() {
        None => name.is_empty(),
        Some((b'*', rest)) => (0..=name.len()).any(|i| matches(rest, &name[i..])),
        Some((b'?', rest)) => !name.is_empty() && matches(rest, &name[1..]),
        Some((b'[', rest)) => {
            let Some(close) = rest.iter().position(|&c| c == b']') else {
                return name.first() == Some(&b'[') && matches(rest, &name[1..]);
            };
            let (set, after) = (&rest[..close], &rest[close + 1..]);
            name.split_first()
                .is_some_and(|(&c, tail)| in_set(set, c) && matches(after, tail))
        }
        Some((&c, rest)) => name.first() == Some(&c) && matches(rest, &name[1..]),
    }
}

fn in_set(set: &[u8], c: u8) -> bool {
    let (negate, set) = match set.split_first() {
        Some((b'!', rest)) => (true, rest),
        _ => (false, set),
    };
    let mut i = 0;
    let mut found = false;
    while i < set.len() {
        if i + 2 < set.len() && set[i + 1] == b'-' {
            found |= (set[i]..=set[i + 2]).contains(&c);
            i += 3;
        } else {
            found |= set[i] == c;
            i += 1;
        }
    }
    found != negate
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_patterns() {
        assert!(matches(b"*.cfg", b"macros.cfg"));
        assert!(!matches(b"*.cfg", b"macros.cfg.bak"));
        assert!(matches(b"m?cros.cfg", b"macros.cfg"));
        assert!(matches(b"[a-c]*.cfg", b"b.cfg"));
        assert!(!matches(b"[!a-c]*.cfg", b"b.cfg"));
    }

    #[test]
    fn includes_are_read_from_disk_relative_to_the_including_file() {
        let dir = std::env::temp_dir().join(format!("qp-klipper-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("conf.d")).unwrap();
        std::fs::write(
            dir.join("printer.cfg"),
            "[printer]\nmax_accel: 1\n[include conf.d/*.cfg]\n",
        )
        .unwrap();
        std::fs::write(dir.join("conf.d/b.cfg"), "[printer]\nmax_accel: 3\n").unwrap();
        std::fs::write(
            dir.join("conf.d/a.cfg"),
            "[printer]\nmax_accel: 2\nmax_velocity: 9\n[include ../missing.cfg]\n",
        )
        .unwrap();
        let e = read_config(&dir.join("printer.cfg")).unwrap_err();
        assert!(e.contains("a.cfg:4") && e.contains("does not exist"), "{e}");
        std::fs::write(
            dir.join("missing.cfg"),
            "[extruder]\nmax_extrude_only_velocity: 50\n",
        )
        .unwrap();
        let c = read_config(&dir.join("printer.cfg")).unwrap();
        // Sorted: a.cfg then b.cfg, so b's acceleration wins.
        assert_eq!((c.max_accel, c.max_velocity), (Some(3.0), Some(9.0)));
        assert_eq!(c.max_extrude_only_velocity, Some(50.0));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
