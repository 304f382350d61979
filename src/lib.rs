//! # apatch
//!
//! Turns a polyhedron (triangle or polygon mesh) into a smooth implicit surface made of
//! A-patches — zero sets of trivariate Bernstein–Bézier (BB) polynomials, one per tetrahedron of
//! a simplicial hull built around or inside the mesh — and ray traces that surface directly.
//!
//! Data flow (see `ARCHITECTURE.md`):
//! `mesh` → vertex normals → `hull` → `scheme` → [`complex::PatchComplex`] → `trace` / `check` / `export`.
//!
//! ## Conventions (stated once, used everywhere)
//! - All construction math is `f64` (`glam::DVec3`).
//! - Barycentric coordinates α = (α1, α2, α3, α4) of a tetrahedron [v1 v2 v3 v4] satisfy
//!   p = Σ αi vi, Σ αi = 1.
//! - Multi-indices λ with |λ| = n are ordered decreasing-lexicographically:
//!   (n,0,0,0), (n-1,1,0,0), (n-1,0,1,0), (n-1,0,0,1), (n-2,2,0,0), …, (0,0,0,n).
//!   Weights are stored, exported and read in that order.
//! - F(α) = Σ w_λ · n!/(λ1!λ2!λ3!λ4!) · α^λ (+ rational terms, 2001 scheme). The surface is F = 0;
//!   the side F < 0 is inside the solid, F > 0 outside, for every scheme.
#![warn(missing_docs)]

pub mod bb;
pub mod check;
pub mod compare;
pub mod complex;
pub mod complex_io;
pub mod error;
pub mod export;
pub mod fixtures;
pub mod hull;
pub mod mesh;
pub mod progress;
pub mod scene;
pub mod scheme;
pub mod trace;
