//! The direct ray tracer: a Mitsuba-compatible camera, a BVH over the patches' tetrahedra,
//! ray × patch intersection with sheet selection, shading modes, a box-filtered film, and
//! EXR/PNG output.
//!
//! Pipeline: [`Geometry::new`] compiles a [`PatchComplex`](crate::complex::PatchComplex) once
//! (barycentric maps, weights, BVH); [`render`] runs every pixel's samples in parallel rows and a
//! deterministic finishing pass; [`write_exr`] / [`write_png`] write the [`Frame`].
//!
//! Modules: `camera` (sensor), `bvh` (the only obvhs user), `patch` (compiled patches, segment
//! restriction, derivatives; the univariate Bernstein work and root finder are [`crate::bb`]'s),
//! `intersect` (closest hit and occlusion), `shade` (lights, modes), `film` (sampling, parallel rows, finishing),
//! `output` (files; the EXR channel list is documented there).

pub mod bvh;
pub mod camera;
pub mod film;
pub mod intersect;
pub mod output;
pub mod patch;
pub mod shade;

pub use camera::{Camera, FovAxis};
pub use film::{render, render_pixel, Frame, Interrupted, Pixel, RenderSettings};
pub use intersect::{Geometry, Hit};
pub use output::{write_exr, write_png};
pub use shade::{Light, Lighting, Mode, ModeOptions};
