//! Conformance of `orient` on the real corpus (filled in with the capability).
