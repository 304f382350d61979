//! Schemes: the weights of every patch, producing a `PatchComplex`.

pub mod rational_c1;
