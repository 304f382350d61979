//! Mesh input, validation, topology and vertex normals.
//!
//! [`load`] reads OBJ or OFF (polygon faces kept), welds exactly coincident vertices, removes
//! degenerate faces, makes the orientation consistent and outward, and validates. [`triangulate`]
//! ear-clips polygons for the 2001 scheme; [`vertex_normals`] estimates the normals the schemes
//! interpolate; [`convexity`] classifies edges and faces. Opt-in repairs for coarse, folded
//! meshes under the 2001 scheme: [`subdivide()`] (Loop's approximating subdivision) and
//! [`weld()`] (vertices closer than a tolerance merged).
//!
//! ```
//! use apatch::mesh::{self, NormalMethod};
//! let (polygons, report) = mesh::load("scenes/models/l_prism.obj".as_ref())?;
//! assert!(report.findings.is_empty());
//! report.require(true)?; // closed, manifold, orientable: fine for every scheme
//! let triangles = mesh::triangulate(&polygons); // for the 2001 scheme
//! assert_eq!(triangles.faces.len(), 6 * 2 + 2 * 4);
//! let normals = mesh::vertex_normals(&triangles, NormalMethod::Loop)?;
//! assert!(mesh::above_face_failures(&triangles, &normals).is_empty());
//! # Ok::<(), apatch::error::Error>(())
//! ```
//!
//! # Errors and warnings
//! Hard errors (`load` returns `Err` naming file and line): unreadable file, unknown format,
//! syntax errors, non-UTF-8 data lines, NaN/inf coordinates or coordinates beyond
//! [`raw::MAX_COORDINATE`], face indices that are 0, out of range or before the first vertex,
//! faces with fewer than 3 vertices or more than [`raw::MAX_FACE_VERTICES`], no faces, only
//! degenerate faces.
//!
//! Findings in the [`Report`] (the mesh is still returned):
//! - notes: welded duplicates, boundary edges, averaged file normals, ignored statements;
//! - warnings, repaired: repeated vertices in a face (removed), faces with < 3 distinct
//!   vertices (dropped), duplicate faces (dropped), unreferenced vertices (dropped),
//!   vertices whose faces form several edge-connected fans (split into one vertex per fan, see
//!   `split`), inconsistent orientation (flipped), inward closed surface (flipped);
//! - warnings, kept: zero-area faces, non-planar polygons, non-manifold edges and vertices,
//!   non-orientable components, incomplete file normals.
//!
//! `apatch info` exits 0 with notes only, 1 with warnings (or normals that cannot be computed),
//! 2 on hard errors. Element indices in findings are the loaded mesh's (after welding and
//! dropping), except for dropped faces and vertices, which carry the file's 0-based number;
//! every element carries its 1-based file line.
//!
//! Which schemes accept what ([`Report::require`]): every scheme needs a manifold, orientable
//! mesh. The 2001 rational scheme accepts boundary edges; the 1994 inner-hull schemes need a
//! closed mesh.

pub mod clean;
pub mod convexity;
pub mod flatten;
pub mod geometry;
mod load;
mod normals;
mod obj;
mod off;
mod orient;
pub mod raw;
mod report;
mod split;
pub mod subdivide;
mod summary;
pub mod topology;
mod triangulate;
mod validate;
pub mod weld;

pub use clean::{clean, clean_with, CleanOptions, CleanReport};
pub use load::{from_polygons, load, load_bytes, Format};
pub use normals::{above_face_failures, loop_limit_normal, vertex_normals, NormalMethod};
pub use orient::signed_volume;
pub use report::{Element, Finding, FindingKind, Report, Severity, LISTED_ELEMENTS};
pub use subdivide::{subdivide, Subdivision, SubdivisionRule};
pub use summary::{summary, ClassCounts, Summary};
pub use topology::{Fan, Topology};
pub use triangulate::{ear_clip, triangulate};
pub use validate::{PLANARITY_TOL, ZERO_AREA_TOL};
pub use weld::weld;

use glam::DVec3;

/// A polygon mesh: plain data. Indices are 0-based; faces are counter-clockwise seen from
/// outside after `load`'s orientation fixes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// #V vertex positions, in the file's units.
    pub positions: Vec<DVec3>,
    /// #F polygons (≥ 3 distinct vertex indices each).
    pub faces: Vec<Vec<u32>>,
    /// #V unit normals from the file (OBJ `vn`, NOFF), if every vertex has one.
    pub file_normals: Option<Vec<DVec3>>,
    /// #V 1-based line of the file defining each vertex (0 when not from a file).
    pub vertex_lines: Vec<u32>,
    /// #F 1-based line of the file defining each face (0 when not from a file).
    pub face_lines: Vec<u32>,
    /// #F the face of the loaded mesh each face comes from: identity after `load`, the
    /// original polygon after [`triangulate`].
    pub face_parent: Vec<u32>,
}

impl Mesh {
    /// A mesh from positions and faces (no file lines; identity `face_parent`). Does not validate.
    #[must_use]
    pub fn new(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Mesh {
        Mesh {
            vertex_lines: vec![0; positions.len()],
            face_lines: vec![0; faces.len()],
            face_parent: (0..faces.len() as u32).collect(),
            positions,
            faces,
            file_normals: None,
        }
    }

    /// True when every face is a triangle.
    #[must_use]
    pub fn is_triangle_mesh(&self) -> bool {
        self.faces.iter().all(|f| f.len() == 3)
    }
}
