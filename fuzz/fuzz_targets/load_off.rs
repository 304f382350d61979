//! Any bytes: the Off reader returns a mesh or an error, never panics; loaded meshes
//! triangulate and summarise without panicking.
#![no_main]

use apatch::mesh::{self, Format, NormalMethod};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok((m, r)) = mesh::load_bytes(data, Format::Off, Path::new("fuzz")) {
        let t = mesh::triangulate(&m);
        let _ = mesh::vertex_normals(&t, NormalMethod::Loop);
        let _ = mesh::summary(&m, &r, NormalMethod::default_for(&m));
    }
});
