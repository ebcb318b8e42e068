//! Conformance of `infill` on the real corpus (filled in with the capability).
