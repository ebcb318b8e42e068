//! Conformance of `vtg` on the real corpus (filled in with the capability).
