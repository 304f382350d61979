//! Schemes: the weights of every patch, producing a `PatchComplex`.
