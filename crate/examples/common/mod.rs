//! What the timing examples share: their command line, `FILE [RUNS]`.

/// The file named first on the command line, its bytes, and the runs named after it
/// (`default_runs` without); `None`, said on stderr, without a file or where it cannot be read.
pub fn file_and_runs(example: &str, default_runs: usize) -> Option<(String, Vec<u8>, usize)> {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: {example} FILE [RUNS]");
        return None;
    };
    let runs = std::env::args()
        .nth(2)
        .and_then(|r| r.parse().ok())
        .unwrap_or(default_runs);
    match std::fs::read(&path) {
        Ok(input) => Some((path, input, runs)),
        Err(e) => {
            eprintln!("{path}: {e}");
            None
        }
    }
}
