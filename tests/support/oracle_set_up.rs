//! Included by both Klipper oracle test files (`crate/tests/klipper_oracle.rs` and
//! `tests/conformance/klipper.rs`, two crates): the oracle's first run of each version alone.

/// `run` the oracle for `version`; its first run of each version alone. On first use the
/// oracle sets itself up (a venv, then a build per Klipper version), and two set-ups at once
/// fail on a fresh machine (`File exists`); each test file runs two versions in parallel.
pub fn first_alone<T>(version: &str, run: impl FnOnce() -> T) -> T {
    static SET_UP: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    let mut set_up = SET_UP.lock().unwrap_or_else(|e| e.into_inner());
    if set_up.iter().any(|v| v == version) {
        drop(set_up);
        return run();
    }
    let out = run();
    set_up.push(version.to_owned());
    out
}
