//! The integration tests, one module per subject, in one test binary: one link instead of
//! one per file, and the harness runs every test of every subject on all cores at once
//! (as separate binaries they ran one binary after another, a core idle beside each
//! binary's last long test). Run one subject with `cargo test --release --test suite
//! <subject>::`.

mod common;
#[path = "support/sphere_scene.rs"]
mod sphere_scene;

mod bb_props;
mod check_cli;
mod check_fixtures;
mod check_rational;
mod compare_cli;
mod compare_metrics;
mod compare_mitsuba;
mod cubic_c1;
mod cubic_fair;
mod export_mitsuba;
mod inner_above;
mod inner_cage;
mod inner_degenerate;
mod inner_flat_corner;
mod inner_flatnet;
mod inner_guardnet;
mod inner_guards_near;
mod inner_hull;
mod inner_hull_folds;
mod inner_hull_models;
mod inner_hull_realtri;
mod inner_mpi;
mod inner_planar;
mod inner_saddle;
mod json_roundtrip;
mod mesh_corpus;
mod mesh_fuzz;
mod mesh_info;
mod mesh_normals;
mod mesh_tobj;
mod mesh_triangulate;
mod mesh_validate;
mod progress;
mod quintic_c2;
mod quintic_holes;
mod quintic_models;
mod quintic_resume;
mod quintic_solve;
mod rational_meshes;
mod rational_models;
mod rational_normal_fallback;
mod rational_precision;
mod rational_scenes;
mod rational_support;
mod rational_throughput;
mod scenes_all;
mod tessellate_cli;
mod tessellate_closed;
mod trace_cli;
mod trace_cracks;
mod trace_quadric;
mod trace_render;
