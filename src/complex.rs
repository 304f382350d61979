//! The patch complex: the contract between surface construction and every consumer
//! (tracer, checker, exporters, library users).
//!
//! A [`PatchComplex`] is plain data: the vertices and normals the surface interpolates (or
//! approximates) and one [`Patch`] per tetrahedron of the hull. Its JSON form (`apatch export
//! patches`) is:
//!
//! ```text
//! {"format":"apatch-patches","version":1,"scheme":"…","vertices":[[x,y,z],…],"normals":[[x,y,z],…],
//!  "patches":[{"tet":[[x,y,z]×4],"degree":n,"weights":[… C(n+3,3) numbers …],
//!              "rational":[{"index":[k1,k2,k3,k4],"terms":[[w,[m1,m2,m3,m4]],…]}],   (omitted when none)
//!              "sheet":{"rule":"shooting","base":[…],"top":[…]},                      (omitted when "any")
//!              "role":"face|edge|…","element":id}]}
//! ```
//!
//! meaning F(α) = Σ w_λ·n!/(λ1!λ2!λ3!λ4!)·α^λ + Σ_r (Σ_m w_m α^μm)/(Σ_m α^μm)·B^n_κr(α),
//! weights in the crate's multi-index order (decreasing lexicographic).

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Identifies the file format in JSON.
pub const FORMAT: &str = "apatch-patches";
/// Current JSON format version.
pub const VERSION: u32 = 1;

/// A whole piecewise-polynomial implicit surface: one patch per hull tetrahedron.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PatchComplex {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] for files this crate writes.
    pub version: u32,
    /// The scheme that built it: `rational-c1`, `cubic-c1`, `quintic-c2`, or a test name.
    pub scheme: String,
    /// Continuity the scheme promises (1 or 2); when absent it follows from `scheme`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub continuity: Option<u8>,
    /// Points the surface passes through (mesh vertices for interpolating schemes).
    pub vertices: Vec<[f64; 3]>,
    /// Unit normals the surface has at `vertices` (same length, or empty).
    pub normals: Vec<[f64; 3]>,
    /// One entry per tetrahedron.
    pub patches: Vec<Patch>,
}

/// One A-patch: a BB polynomial (plus optional rational terms) on one tetrahedron.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Patch {
    /// The tetrahedron [v1 v2 v3 v4]; barycentric αi belongs to `tet[i]`.
    pub tet: [[f64; 3]; 4],
    /// Polynomial degree n (1..=7).
    pub degree: u8,
    /// C(n+3,3) BB weights in the crate's multi-index order.
    pub weights: Vec<f64>,
    /// Rational corrections (2001 scheme); empty for polynomial patches.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rational: Vec<RationalTerm>,
    /// Which roots inside the tetrahedron belong to the surface.
    #[serde(default, skip_serializing_if = "SheetRule::is_any")]
    pub sheet: SheetRule,
    /// The hull role of the tetrahedron (face, edge, vertex, planar, …).
    pub role: Role,
    /// Index of the mesh element (face, edge or vertex) the tetrahedron belongs to.
    pub element: u32,
}

/// The rational term (Σ_m w_m α^μm)/(Σ_m α^μm) · B^n_κ(α) added to a patch.
///
/// `index` is κ (|κ| = n); each term is (w_m, μ_m). The denominator Σ α^μm is positive inside
/// the tetrahedron except where it vanishes on an edge, where the term is defined by continuity
/// (B^n_κ vanishes faster there).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RationalTerm {
    /// κ, the multi-index of the Bernstein polynomial the blended weight multiplies.
    pub index: [u8; 4],
    /// (w_m, μ_m) pairs: the weights blended by the monomials α^μm.
    pub terms: Vec<(f64, [u8; 4])>,
}

/// How to pick the surface among the zeros of F inside a tetrahedron.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "lowercase")]
pub enum SheetRule {
    /// Single-sheeted A-patch: every zero inside the tetrahedron is on the surface.
    #[default]
    Any,
    /// 2001 scheme, (4.5)–(4.7): a point p is on the surface only if, on the shooting line
    /// through p from the base simplex (tetrahedron vertices `base`) to the top simplex
    /// (vertices `top`), p is the zero with the smallest parameter t ∈ [0, 1)
    /// (t = Σ_{i∈top} αi at p; q and u are the normalised base and top parts of α).
    Shooting {
        /// Tetrahedron-local vertex indices spanning the base (a face: 3, an edge: 2).
        base: Vec<u8>,
        /// Tetrahedron-local vertex indices spanning the top (a vertex: 1, an edge: 2).
        top: Vec<u8>,
    },
}

impl SheetRule {
    /// True for [`SheetRule::Any`] (used to omit it from JSON).
    #[must_use]
    pub fn is_any(&self) -> bool {
        matches!(self, SheetRule::Any)
    }
}

/// The hull role of a tetrahedron, for shading by patch type and for error messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Face tetrahedron (2001: [p_i p_j p_k u_ijk] or with v_ijk; 1994: face tetrahedron).
    Face,
    /// Edge tetrahedron between two face tetrahedra across a mesh edge.
    Edge,
    /// Vertex tetrahedron (1994 inner hull, around a mesh vertex).
    Vertex,
    /// A zero-convex face reproduced as its own plane.
    Planar,
    /// Anything else (test complexes).
    Other,
}

impl Role {
    /// The lowercase name used in JSON and reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Role::Face => "face",
            Role::Edge => "edge",
            Role::Vertex => "vertex",
            Role::Planar => "planar",
            Role::Other => "other",
        }
    }
}

impl PatchComplex {
    /// An empty complex for `scheme`.
    #[must_use]
    pub fn new(scheme: &str) -> Self {
        PatchComplex {
            format: FORMAT.to_string(),
            version: VERSION,
            scheme: scheme.to_string(),
            continuity: None,
            vertices: Vec::new(),
            normals: Vec::new(),
            patches: Vec::new(),
        }
    }

    /// The continuity the complex promises: the explicit field, else from the scheme's name
    /// (`quintic-c2` → 2, anything else → 1).
    #[must_use]
    pub fn promised_continuity(&self) -> u8 {
        self.continuity
            .unwrap_or(if self.scheme.contains("c2") { 2 } else { 1 })
    }
}

impl Patch {
    /// The tetrahedron's vertices as vectors.
    #[must_use]
    pub fn tet_points(&self) -> [DVec3; 4] {
        self.tet.map(DVec3::from_array)
    }
}
