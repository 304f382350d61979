//! Wavefront OBJ writer: `v x y z`, `vn nx ny nz` and `f a//a b//b c//c` (1-based, the normal
//! index equals the position index).

use super::TriMesh;
use std::io::Write;

/// Writes `mesh` as OBJ text (shortest round-trip decimal form).
///
/// # Errors
/// Any I/O error of `out`.
pub fn write(mesh: &TriMesh, out: &mut dyn Write) -> std::io::Result<()> {
    writeln!(out, "# apatch tessellation")?;
    for p in &mesh.positions {
        writeln!(out, "v {:e} {:e} {:e}", p[0], p[1], p[2])?;
    }
    for n in &mesh.normals {
        writeln!(out, "vn {:e} {:e} {:e}", n[0], n[1], n[2])?;
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
    }
    Ok(())
}
