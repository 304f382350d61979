//! Welding vertices that are closer than a tolerance (opt-in repair, scene key
//! `model.weld`).
//!
//! [`super::load`] welds only exactly coincident vertices. Some models carry modelling slop
//! instead: mpi_poly.obj has strips of faces 0.002–0.02 wide and 4 long (ratios up to 1:2000)
//! where two vertices were meant to be one. Such a strip is a knife edge for the 2001 scheme
//! (adjacent faces fold by up to 180°) and survives any number of subdivision levels at its
//! own scale. Welding the vertices removes the strip: every cluster of vertices joined by
//! distances below the tolerance (transitively) moves to the position of its first vertex
//! (the smallest index, so the file's coordinates are kept), and the mesh then goes through
//! [`super::from_polygons`], which merges the coincident vertices, drops the faces that
//! collapsed and validates the result.

use super::topology::UnionFind;
use super::{from_polygons, Mesh, Report};
use crate::error::{Error, Result};
use glam::DVec3;
use std::collections::HashMap;

/// The largest accepted relative tolerance (a hundredth of the model's size).
pub const MAX_WELD_TOLERANCE: f64 = 0.01;

/// Welds the vertices of `mesh` closer than `relative` × the bounding-box diagonal (see the
/// module docs). Returns the welded mesh (file lines are lost: 0), its validation report and
/// how many vertices were moved onto another.
///
/// # Errors
/// A tolerance that is not in [0, [`MAX_WELD_TOLERANCE`]], or a welded mesh that
/// [`from_polygons`] rejects (no face left).
pub fn weld(mesh: &Mesh, relative: f64) -> Result<(Mesh, Report, usize)> {
    if !(0.0..=MAX_WELD_TOLERANCE).contains(&relative) {
        return Err(Error::Invalid(format!(
            "weld tolerance {relative} is not in [0, {MAX_WELD_TOLERANCE}] (relative to the \
             bounding-box diagonal)"
        )));
    }
    let p = &mesh.positions;
    let (lo, hi) = p.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(lo, hi), q| (lo.min(*q), hi.max(*q)),
    );
    let tol = relative * (hi - lo).length();
    let mut uf = UnionFind::new(p.len());
    let mut moved = 0;
    if tol > 0.0 {
        // Uniform grid of cell size tol: close pairs lie in the same or adjacent cells.
        let cell = |q: DVec3| ((q - lo) / tol).floor().as_i64vec3().to_array();
        let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, q) in p.iter().enumerate() {
            grid.entry(cell(*q)).or_default().push(i as u32);
        }
        for (i, q) in p.iter().enumerate() {
            let c = cell(*q);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                            continue;
                        };
                        for &j in list {
                            if (j as usize) < i && p[j as usize].distance(*q) < tol {
                                uf.union(i as u32, j);
                            }
                        }
                    }
                }
            }
        }
    }
    // Every vertex takes the position of the smallest index in its cluster.
    let mut first: Vec<u32> = vec![u32::MAX; p.len()];
    for i in 0..p.len() as u32 {
        let r = uf.find(i) as usize;
        first[r] = first[r].min(i);
    }
    let positions: Vec<DVec3> = (0..p.len() as u32)
        .map(|i| {
            let f = first[uf.find(i) as usize];
            if f != i {
                moved += 1;
            }
            p[f as usize]
        })
        .collect();
    let (welded, report) = from_polygons(positions, mesh.faces.clone())?;
    Ok((welded, report, moved))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube of quads whose top face is split into a thin strip: vertices 8 and 9 lie
    /// 1e-3 from 4 and 5 (a sliver face 4-5-9-8 between the top face and the side).
    fn cube_with_strip() -> Mesh {
        let mut positions: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        positions.push(DVec3::new(0.0, 0.0, 1.0 - 1e-3)); // near 4
        positions.push(DVec3::new(1.0, 0.0, 1.0 - 1e-3)); // near 5
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![8, 9, 5, 4], // the sliver (1e-3 wide)
            vec![4, 5, 7, 6],
            vec![0, 1, 9, 8],
            vec![2, 6, 7, 3],
            vec![0, 8, 4, 6, 2],
            vec![1, 3, 7, 5, 9],
        ];
        Mesh::new(positions, faces)
    }

    #[test]
    fn strip_collapses_and_the_cube_is_closed() {
        let m = cube_with_strip();
        // 1e-3 apart in a cube of diagonal √3: relative 1e-3 welds them (1e-3 < 1.7e-3).
        let (w, report, moved) = weld(&m, 1e-3).unwrap();
        assert_eq!(moved, 2);
        assert_eq!(w.positions.len(), 8);
        assert_eq!(w.faces.len(), 6, "the sliver is dropped: {:?}", w.faces);
        report.require(true).unwrap();
        // The kept positions are the file's (the first of each cluster), exactly.
        for q in &w.positions {
            assert!(q.to_array().iter().all(|c| *c == 0.0 || *c == 1.0), "{q}");
        }
        // Tolerance 0 changes nothing.
        let (w0, _, moved0) = weld(&m, 0.0).unwrap();
        assert_eq!((moved0, w0.positions.len(), w0.faces.len()), (0, 10, 7));
    }

    #[test]
    fn bad_tolerances_are_errors() {
        let m = cube_with_strip();
        for t in [-1e-3, 0.5, f64::NAN] {
            let e = weld(&m, t).unwrap_err().to_string();
            assert!(e.contains("weld tolerance"), "{e}");
        }
    }
}
