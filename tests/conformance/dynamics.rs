//! Conformance of `dynamics` on the real corpus (filled in with the capability).
