//! Measuring a patch complex: continuity across shared faces, interpolation, sheets.

pub mod eval;
