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
/// replace `input` unless `force`.
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
    let dir = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = output
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", output.display()))?;
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
        fs::rename(&tmp, output)
    })();
    result.map_err(|e| {
        let _ = fs::remove_file(&tmp);
        format!("{}: {e}", output.display())
    })
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
