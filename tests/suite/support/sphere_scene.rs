//! The unit-sphere scene of the render tests (`trace_cli`, `trace_render`, `compare_mitsuba`):
//! the exact unit sphere as quadratic A-patches, written as patch JSON, seen by a camera on the
//! +z axis. Included with `#[path]`; has no tests of its own.
#![allow(dead_code)]

use apatch::complex::PatchComplex;
use apatch::fixtures::{quadric_complex, Quadric};
use glam::DVec3;
use std::path::Path;

/// The unit sphere as degree-2 A-patches on 2³ Kuhn cubes of [-1.2, 1.2]³ (exact: one global
/// quadric).
pub fn unit_sphere() -> PatchComplex {
    let q = Quadric::sphere(DVec3::ZERO, 1.0);
    quadric_complex(&q, DVec3::splat(-1.2), DVec3::splat(1.2), 2, 2)
}

/// Writes [`unit_sphere`] as patch JSON to `dir/name` and returns it.
pub fn write_unit_sphere(dir: &Path, name: &str) -> PatchComplex {
    let c = unit_sphere();
    std::fs::write(dir.join(name), serde_json::to_string(&c).unwrap()).unwrap();
    c
}

/// A scene file's `[model]` (the patch JSON `patches`) and `[camera]` (at (0, 0, 4), looking
/// at the origin with +y up, vertical fov 40°, `width` × `height` pixels), followed by `rest`
/// (film, lights, render sections).
pub fn sphere_scene(patches: &str, width: u32, height: u32, rest: &str) -> String {
    format!(
        r#"
[model]
patches = "{patches}"
[camera]
origin = [0, 0, 4]
target = [0, 0, 0]
up = [0, 1, 0]
fov = 40
width = {width}
height = {height}
{}"#,
        rest.trim_start_matches('\n')
    )
}
