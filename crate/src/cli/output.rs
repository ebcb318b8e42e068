//! Output helpers: JSON, atomic file writes, the progress bar.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Writes `value` as pretty JSON and a newline.
///
/// Buffered: stdout is line-buffered, and a report of 200 000 layers is millions of short
/// lines (one `write` call each would take longer than the job).
pub fn write_json<T: serde::Serialize>(out: &mut impl Write, value: &T) -> Result<(), String> {
    let mut buffered = io::BufWriter::with_capacity(1 << 16, out);
    serde_json::to_writer_pretty(&mut buffered, value).map_err(|e| e.to_string())?;
    writeln!(buffered).map_err(|e| e.to_string())?;
    buffered.flush().map_err(|e| e.to_string())
}

/// The end of a rewriting command: the new file written atomically, then the report on
/// stdout as JSON or as the command's table (`table`).
pub fn finish_rewrite<T: serde::Serialize>(
    input: &Path,
    output: &Path,
    force: bool,
    bytes: &[u8],
    report: &T,
    json: bool,
    table: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), String> {
    write_atomically(input, output, force, |out| out.write_all(bytes))?;
    let mut stdout = io::stdout().lock();
    if json {
        write_json(&mut stdout, report)?;
    } else {
        table(&mut stdout).map_err(|e| e.to_string())?;
    }
    stdout.flush().map_err(|e| e.to_string())
}

/// Writes `output` through a temporary file in the same directory and a rename, so an
/// interrupted run never leaves a half-written file where a complete one is expected. Refuses to
/// replace `input` unless `force`. A symbolic link is followed (the file it names is
/// replaced, the link stays), and an output that exists and is not a regular file (`/dev/null`,
/// a named pipe, a terminal) is written in place: a rename would put a plain file where the
/// device was, and `-o /dev/null` run as root would break every later program that reads it.
pub fn write_atomically(
    input: &Path,
    output: &Path,
    force: bool,
    body: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), String> {
    if !force && same_file(input, output) {
        return Err(format!(
            "{} is the input file; pass --force to overwrite it",
            output.display()
        ));
    }
    let fail = |e: io::Error| format!("{}: {e}", output.display());
    match fs::metadata(output) {
        Ok(meta) if !meta.is_file() && !meta.is_dir() => {
            let mut w = BufWriter::with_capacity(1 << 20, fs::File::create(output).map_err(fail)?);
            return body(&mut w).and_then(|()| w.flush()).map_err(fail);
        }
        _ => {}
    }
    let target = match fs::symlink_metadata(output) {
        Ok(meta) if meta.file_type().is_symlink() => link_target(output).map_err(fail)?,
        _ => output.to_path_buf(),
    };
    replace_through_temporary(&target, body).map_err(fail)
}

/// The file a symbolic link names, whether or not it exists yet (a relative target is taken
/// from the link's own directory).
fn link_target(link: &Path) -> io::Result<std::path::PathBuf> {
    if let Ok(path) = fs::canonicalize(link) {
        return Ok(path);
    }
    let to = fs::read_link(link)?;
    Ok(match link.parent() {
        Some(dir) if to.is_relative() => dir.join(to),
        _ => to,
    })
}

/// Writes `body` to a temporary file beside `target`, then renames it onto `target`.
fn replace_through_temporary(
    target: &Path,
    body: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let dir = target
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = target
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "not a file name"))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> io::Result<()> {
        let file = fs::File::create(&tmp)?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        body(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        fs::rename(&tmp, target)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (fs::canonicalize(a), fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// A one-line progress bar on stderr (drawn only when enabled).
#[derive(Debug)]
pub struct ProgressBar {
    enabled: bool,
    last: i32,
}

impl ProgressBar {
    /// A bar that draws only if `enabled`.
    pub fn new(enabled: bool) -> Self {
        Self { enabled, last: -1 }
    }

    /// The bar of a job over an input of `len` bytes: drawn when the input is large enough for
    /// the job to take a while and stderr is a terminal.
    pub fn for_input(len: usize) -> Self {
        Self::new(len >= super::PROGRESS_MIN_BYTES && io::IsTerminal::is_terminal(&io::stderr()))
    }

    /// Shows `fraction` done; always asks the job to go on.
    pub fn update(&mut self, fraction: f64) -> bool {
        let pct = (fraction.clamp(0.0, 1.0) * 100.0) as i32;
        if self.enabled && pct != self.last {
            self.last = pct;
            let filled = (pct / 4) as usize;
            eprint!(
                "\r[{}{}] {pct:3}%",
                "#".repeat(filled),
                " ".repeat(25 - filled)
            );
        }
        true
    }

    /// Clears the bar.
    pub fn finish(&mut self) {
        if self.enabled {
            eprint!("\r{}\r", " ".repeat(40));
        }
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::os::unix::fs::FileTypeExt;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("quietpath-output-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("scratch dir");
        dir
    }

    /// Writes `new` through `link` and checks the link is still a link.
    fn write_through(dir: &std::path::Path, link: &std::path::Path) {
        write_atomically(&dir.join("in.gcode"), link, false, |w| w.write_all(b"new"))
            .expect("written");
        assert!(fs::symlink_metadata(link)
            .expect("link")
            .file_type()
            .is_symlink());
    }

    #[test]
    fn a_link_is_followed_and_kept() {
        let dir = scratch("link");
        let (real, link) = (dir.join("real.gcode"), dir.join("link.gcode"));
        fs::write(&real, "old").expect("write");
        std::os::unix::fs::symlink(&real, &link).expect("symlink");
        write_through(&dir, &link);
        assert_eq!(fs::read(&real).expect("read"), b"new");
        assert_eq!(
            fs::read_dir(&dir).expect("dir").count(),
            2,
            "no temporary left"
        );
        fs::remove_dir_all(&dir).expect("clean");
    }

    #[test]
    fn a_dangling_link_gets_its_file() {
        let dir = scratch("dangling");
        let link = dir.join("link.gcode");
        std::os::unix::fs::symlink("new.gcode", &link).expect("symlink");
        write_through(&dir, &link);
        assert_eq!(fs::read(dir.join("new.gcode")).expect("read"), b"new");
        fs::remove_dir_all(&dir).expect("clean");
    }

    #[test]
    fn a_named_pipe_is_written_not_replaced() {
        let dir = scratch("fifo");
        let fifo = dir.join("out.gcode");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.expect("mkfifo runs").success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || fs::read(fifo).expect("read the pipe"))
        };
        write_atomically(&dir.join("in.gcode"), &fifo, false, |w| {
            w.write_all(b"G1 X1\n")
        })
        .expect("written");
        // The type first: had the pipe been renamed over, the reader would wait for ever.
        assert!(fs::metadata(&fifo).expect("fifo").file_type().is_fifo());
        assert_eq!(reader.join().expect("reader"), b"G1 X1\n");
        assert_eq!(
            fs::read_dir(&dir).expect("dir").count(),
            1,
            "no temporary left"
        );
        fs::remove_dir_all(&dir).expect("clean");
    }

    #[test]
    fn a_regular_file_is_replaced_whole() {
        let dir = scratch("file");
        let out = dir.join("out.gcode");
        fs::write(&out, "a much longer old content").expect("write");
        write_atomically(&dir.join("in.gcode"), &out, false, |w| w.write_all(b"new"))
            .expect("written");
        assert_eq!(fs::read(&out).expect("read"), b"new");
        let refused = write_atomically(&out, &out, false, |w| w.write_all(b"x"));
        assert!(refused.is_err_and(|e| e.contains("--force")));
        fs::remove_dir_all(&dir).expect("clean");
    }
}
