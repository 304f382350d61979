//! PLY writer: binary little-endian, `float x y z nx ny nz` vertices (f32) and
//! `list uchar int vertex_indices` faces.

use super::TriMesh;
use std::io::Write;

/// Writes `mesh` as binary little-endian PLY.
///
/// # Errors
/// Any I/O error of `out`.
pub fn write(mesh: &TriMesh, out: &mut dyn Write) -> std::io::Result<()> {
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment apatch tessellation\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        for v in p.iter().chain(n) {
            out.write_all(&(*v as f32).to_le_bytes())?;
        }
    }
    for t in &mesh.triangles {
        out.write_all(&[3u8])?;
        for &i in t {
            // Indices fit: the tessellator refuses meshes with more than i32::MAX vertices.
            out.write_all(&(i as i32).to_le_bytes())?;
        }
    }
    Ok(())
}
