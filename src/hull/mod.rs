//! Simplicial hulls: the outer face/edge hull (2001) and the inner corner-cutting hull (1994).

pub mod inner;
pub mod outer;
pub mod simplicial;
