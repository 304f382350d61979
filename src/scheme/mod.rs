//! Schemes: the weights of every patch, producing a `PatchComplex`.

pub mod cubic_c1;
pub mod quintic_c2;
pub mod rational_c1;
