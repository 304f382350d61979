//! Measuring a patch complex against its scheme's promise: continuity across every shared
//! tetrahedron face, interpolation of the vertices and normals, conformity (faces shared by more
//! than two patches, T-junctions), sheet uniqueness and holes (the surface of single-sheeted
//! patches crossing a face of one patch only, where nothing continues it: [`holes`]).
//!
//! [`check`] never fails: it returns a [`CheckReport`] whose [`CheckReport::passed`] compares every
//! measure with the tolerances of [`CheckOptions`].
//!
//! ```
//! use apatch::check::{check, CheckOptions};
//! use apatch::fixtures::{quadric_complex, Quadric};
//! use glam::DVec3;
//!
//! let sphere = Quadric::sphere(DVec3::ZERO, 0.8);
//! let mut complex = quadric_complex(&sphere, DVec3::splat(-1.0), DVec3::splat(1.0), 2, 3);
//! assert!(check(&complex, &CheckOptions::default()).passed());
//!
//! complex.patches[0].weights[0] += 1e-3; // break continuity at a shared corner weight
//! let report = check(&complex, &CheckOptions::default());
//! assert!(!report.passed());
//! println!("{report}"); // one line per measure, worst patches named
//! ```
//!
//! ## Relative measures
//! Jumps and errors are scaled so they do not depend on the size of the model or of F:
//! for a shared face with longest edge L and gradient scale G (the largest |∇F| of either patch
//! over the face's samples; the patches' largest weight / L if that is 0),
//! - value jump |F⁺ − F⁻| / (G·L),
//! - gradient jump |∇F⁺ − ∇F⁻| / G,
//! - Hessian jump ‖H⁺ − H⁻‖_F · L / G;
//!
//! at a vertex (a corner of tetrahedra with longest edge L), |F| / (|∇F|·L) and the angle between
//! ∇F and the vertex normal (radians; ∇F points to F > 0, the outside). Sheet measures use the
//! patch's largest weight S: a root of the shooting polynomial φ(t) is simple when
//! |φ′(t)| > tolerance · S.

pub mod anatomy;
pub mod distance;
pub mod eval;
mod faces;
pub use faces::pair_jumps;
pub mod holes;
mod interp;
mod report;
pub(crate) mod sheets;
pub mod tjunction;

use crate::complex::PatchComplex;
use serde::Serialize;

/// Default tolerance for the relative value and gradient jumps of a C1 (or C2) promise.
pub const DEFAULT_JUMP_TOLERANCE: f64 = 1e-9;
/// Default tolerance for the relative Hessian jump of a C2 promise.
pub const DEFAULT_HESSIAN_TOLERANCE: f64 = 1e-7;
/// Default tolerance for the relative |F| at an interpolated vertex.
pub const DEFAULT_VALUE_TOLERANCE: f64 = 1e-9;
/// Default tolerance for the angle (radians) between ∇F and a vertex normal.
pub const DEFAULT_ANGLE_TOLERANCE: f64 = 1e-7;
/// Default relative derivative below which a shooting root counts as not simple.
pub const DEFAULT_SIMPLE_ROOT_TOLERANCE: f64 = 1e-8;

/// What to measure and how strictly.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckOptions {
    /// Continuity to hold the complex to; `None` = the complex's own promise
    /// ([`PatchComplex::promised_continuity`]).
    pub continuity: Option<u8>,
    /// Largest allowed relative value and gradient jump.
    pub jump_tolerance: f64,
    /// Largest allowed relative Hessian jump (checked when the promise is C2).
    pub hessian_tolerance: f64,
    /// Largest allowed relative |F| at a vertex.
    pub value_tolerance: f64,
    /// Largest allowed angle (radians) between ∇F and a vertex normal.
    pub angle_tolerance: f64,
    /// Relative |φ′| at or below which a shooting root is not simple.
    pub simple_root_tolerance: f64,
    /// Face samples: the interior points of the triangle lattice with this many steps per edge
    /// (at least degree + 2 is used).
    pub face_resolution: usize,
    /// Sheet lines: lattice steps on the base/top simplices (shooting) or opposite faces
    /// (vertex lines).
    pub sheet_resolution: usize,
    /// Samples along each sheet line.
    pub line_samples: usize,
    /// The scheme promises single-sheeted patches for [`crate::complex::SheetRule::Any`]:
    /// patches crossed twice by lines from each of their vertices
    /// ([`SheetStats::multi_sheet_patches`]) fail the check instead of only being reported.
    pub single_sheet: bool,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            continuity: None,
            jump_tolerance: DEFAULT_JUMP_TOLERANCE,
            hessian_tolerance: DEFAULT_HESSIAN_TOLERANCE,
            value_tolerance: DEFAULT_VALUE_TOLERANCE,
            angle_tolerance: DEFAULT_ANGLE_TOLERANCE,
            simple_root_tolerance: DEFAULT_SIMPLE_ROOT_TOLERANCE,
            face_resolution: 6,
            sheet_resolution: 5,
            line_samples: 48,
            single_sheet: false,
        }
    }
}

/// Where a worst value was found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Location {
    /// The patch indices involved (one, or two for a shared face).
    pub patches: Vec<usize>,
    /// The point (world coordinates).
    pub point: [f64; 3],
    /// The mesh vertex index, for vertex measures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertex: Option<usize>,
    /// Each patch's hull role and mesh element, e.g. "face 12".
    pub elements: Vec<String>,
}

impl Location {
    /// The location of `point` in `patches` (and at mesh vertex `vertex`).
    #[must_use]
    pub fn new(patches: &[&eval::PatchEval<'_>], point: [f64; 3], vertex: Option<usize>) -> Self {
        Location {
            patches: patches.iter().map(|e| e.id).collect(),
            point,
            vertex,
            elements: patches.iter().map(|e| e.element()).collect(),
        }
    }
}

/// One measure: its worst value over all samples and where it occurred.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Measure {
    /// The largest value (0 when nothing was sampled).
    pub worst: f64,
    /// Number of samples.
    pub samples: usize,
    /// Where `worst` occurred.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<Location>,
}

impl Measure {
    /// Keeps the larger of two measures (NaN counts as largest; ties keep `self`), adding counts.
    #[must_use]
    pub fn max(self, other: Measure) -> Measure {
        let samples = self.samples + other.samples;
        let take_other = other.worst > self.worst
            || (other.worst.is_nan() && !self.worst.is_nan())
            || (self.at.is_none() && other.at.is_some() && self.worst <= other.worst);
        let mut m = if take_other { other } else { self };
        m.samples = samples;
        m
    }

    /// A single sample.
    #[must_use]
    pub fn one(worst: f64, at: Location) -> Measure {
        Measure {
            worst,
            samples: 1,
            at: Some(at),
        }
    }

    /// True when `worst ≤ tolerance` (NaN fails).
    #[must_use]
    pub fn within(&self, tolerance: f64) -> bool {
        self.worst <= tolerance
    }
}

/// Conformity of the tetrahedra: how faces are shared.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FaceStats {
    /// Faces shared by exactly two patches (the ones whose jumps are measured).
    pub shared: usize,
    /// Faces of one patch only (the hull's boundary).
    pub boundary: usize,
    /// Faces shared by more than two patches (a failure).
    pub overshared: usize,
    /// An example of an overshared face.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overshared_at: Option<Location>,
    /// Pairs of boundary faces in one plane, facing each other and overlapping: T-junctions
    /// (a face shared geometrically but with different vertices; a failure). See
    /// [`tjunction`] for what this cheap test misses.
    pub t_junctions: usize,
    /// An example T-junction (the centroid of one face; the two patches).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub t_junction_at: Option<Location>,
}

/// Interpolation of the complex's vertices and normals.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct InterpolationStats {
    /// |F| / (|∇F|·L) over every (vertex, incident patch).
    pub value: Measure,
    /// Angle between ∇F and the vertex normal (radians), when normals are given.
    pub normal_angle: Measure,
    /// Vertices that are no tetrahedron's corner but lie inside some tetrahedron (measured
    /// there).
    pub off_corner: usize,
    /// Vertices outside every tetrahedron (a failure).
    pub outside: usize,
}

/// Sheet measures.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SheetStats {
    /// Patches with a shooting sheet rule that can vanish (the others have no surface).
    pub shooting_patches: usize,
    /// Shooting lines sampled.
    pub shooting_lines: usize,
    /// Shooting lines whose minimal root in [0, 1) is not simple (a failure).
    pub non_simple: usize,
    /// The smallest relative |φ′| at a minimal root (`None` when no root was found).
    pub min_root_slope: Option<f64>,
    /// Where `min_root_slope` occurred.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_root_slope_at: Option<Location>,
    /// Lines from tetrahedron vertices sampled in single-sheet ("any") patches of degree ≥ 2
    /// that can vanish.
    pub vertex_lines: usize,
    /// Of those, lines crossing F = 0 more than once (information: an A-patch is single
    /// sheeted with respect to one vertex; lines from the others may cross twice).
    pub multi_root_lines: usize,
    /// An example of a multi-root line (its first root).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multi_root_at: Option<Location>,
    /// Patches with a multi-root line from every one of their four vertices: single-sheeted
    /// with respect to none (a failure only if single sheets are promised).
    pub multi_sheet_patches: usize,
    /// An example of such a patch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multi_sheet_at: Option<Location>,
    /// Patches with a promised j-vertex or j-edge ([`crate::complex::Patch::jvertex`],
    /// [`crate::complex::Patch::jedge`]) that can vanish.
    pub j_patches: usize,
    /// Lines sampled through them: from the j-vertex to lattice points of the opposite face,
    /// or between lattice points of the j-edge and of the opposite edge.
    pub j_lines: usize,
    /// Of those, lines meeting F = 0 more than once away from their ends (a failure).
    pub j_multi_lines: usize,
    /// Patches with such a line.
    pub j_multi_patches: usize,
    /// An example (the line's first sample past its first root).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub j_multi_at: Option<Location>,
    /// Every patch with such a line, in patch order (`apatch check --holes FILE` writes them
    /// beside the holes). Not in the report's JSON, as [`HoleStats::faces`].
    #[serde(skip)]
    pub j_sheets: Vec<JSheet>,
}

/// One patch whose surface a j-line meets more than once (a j-sheet), for locating them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JSheet {
    /// The patch.
    pub patch: usize,
    /// The patch's hull role and mesh element, e.g. "face 12".
    pub element: String,
    /// Its j-lines that meet F = 0 more than once (a zero face that turns counts as one).
    pub lines: usize,
    /// Where: on the first such line, its first sample past the first root (within
    /// 1/[`CheckOptions::line_samples`] of the line's length), or the zero face's centroid.
    pub point: [f64; 3],
}

/// Holes: boundary faces of the hull (faces of one patch only) that the surface crosses
/// ([`holes`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct HoleStats {
    /// Boundary faces of single-sheeted ([`crate::complex::SheetRule::Any`]) patches examined.
    pub boundary_faces: usize,
    /// Of those, faces where F is certified not to change sign (one-signed BB coefficients,
    /// of the face or of all its sub-triangles, or a patch whose weights share one strict sign).
    pub certified: usize,
    /// Faces where F takes both strict signs: the surface reaches the boundary of the hull and
    /// ends there, a hole (a failure).
    pub crossing: usize,
    /// Crossed faces counted by the hull role of their patch ("face", "edge", …).
    pub crossing_by_role: std::collections::BTreeMap<String, usize>,
    /// Crossed faces counted by what holds their coefficient most against the face's sign
    /// ([`anatomy::HeldBy`]: "normal", "hessian", "weights", "unsigned").
    pub crossing_by_cause: std::collections::BTreeMap<String, usize>,
    /// Faces neither certified nor found crossing (information).
    pub uncertified: usize,
    /// Boundary faces of shooting patches, not examined (their surface is the first root only).
    pub skipped: usize,
    /// The largest depth of a crossing: the smaller of max F and −min F on the face over the
    /// patch's largest weight.
    pub worst: f64,
    /// The worst crossing face's patch and a point of F's minority sign on it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crossing_at: Option<Location>,
    /// Every crossed face, in the order the boundary faces are examined (`apatch check --holes
    /// FILE` writes them). Not in the
    /// report's JSON: a model with thousands of holes would drown the measures.
    #[serde(skip)]
    pub faces: Vec<CrossedFace>,
}

/// One boundary face the surface crosses (a hole), for locating the holes of a model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CrossedFace {
    /// The patch whose face it is.
    pub patch: usize,
    /// The patch's hull role and mesh element, e.g. "face 12".
    pub element: String,
    /// The face's corners (world coordinates), in the patch's vertex order.
    pub corners: [[f64; 3]; 3],
    /// min(max F, −min F) on the face over the patch's largest weight: how deep the surface
    /// reaches past the face.
    pub depth: f64,
    /// A point of the face where F has the minority sign.
    pub point: [f64; 3],
    /// The sign the face's number 1 weights give it (+1, −1; 0 when none: no corner on the
    /// surface, or only zero number 1 weights) ([`anatomy`]).
    pub sign: i8,
    /// The patch-local multi-index of the face's coefficient most against that sign (absent
    /// when unsigned).
    pub against: Option<[u8; 4]>,
    /// That coefficient times the sign over the face's largest |coefficient| (negative).
    pub against_share: f64,
    /// Its distance from the nearest corner on the surface (n − its largest multiplicity
    /// there): 1 the normal's, 2 the Hessian's (C2), more the solved weights'.
    pub against_order: Option<u8>,
    /// What fixes that coefficient: "normal" (the normals and the hull's geometry),
    /// "hessian" (a jet's Hessian, C2), "weights" (the weights the scheme solves for), or
    /// "unsigned".
    pub held_by: String,
}

/// Everything [`check`] measured, with the options used.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckReport {
    /// The complex's scheme name.
    pub scheme: String,
    /// The continuity held to (1 or 2).
    pub continuity: u8,
    /// Number of patches.
    pub patches: usize,
    /// Number of vertices.
    pub vertices: usize,
    /// Patches that fail [`crate::complex_io::validate_patch`] (not measured; a failure).
    pub invalid_patches: usize,
    /// The first invalid patch's problem.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_invalid: Option<String>,
    /// Face sharing.
    pub faces: FaceStats,
    /// Relative value jump across shared faces.
    pub value_jump: Measure,
    /// Relative gradient jump across shared faces.
    pub gradient_jump: Measure,
    /// Relative Hessian jump across shared faces (always measured; judged for C2 only).
    pub hessian_jump: Measure,
    /// Vertex interpolation.
    pub interpolation: InterpolationStats,
    /// Sheet uniqueness.
    pub sheets: SheetStats,
    /// The surface against the hull's boundary (holes).
    pub holes: HoleStats,
    /// The options used.
    pub options: CheckOptions,
}

impl CheckReport {
    /// True when every measure is within its tolerance.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.failures().is_empty()
    }

    /// The names of the measures that fail (empty when [`CheckReport::passed`]).
    #[must_use]
    pub fn failures(&self) -> Vec<&'static str> {
        let o = &self.options;
        let mut f = Vec::new();
        if self.invalid_patches > 0 {
            f.push("invalid patches");
        }
        if !self.value_jump.within(o.jump_tolerance) {
            f.push("value jump");
        }
        if !self.gradient_jump.within(o.jump_tolerance) {
            f.push("gradient jump");
        }
        if self.continuity >= 2 && !self.hessian_jump.within(o.hessian_tolerance) {
            f.push("hessian jump");
        }
        if self.faces.overshared > 0 {
            f.push("overshared faces");
        }
        if self.faces.t_junctions > 0 {
            f.push("t-junctions");
        }
        if !self.interpolation.value.within(o.value_tolerance) {
            f.push("vertex value");
        }
        if !self.interpolation.normal_angle.within(o.angle_tolerance) {
            f.push("vertex normal");
        }
        if self.interpolation.outside > 0 {
            f.push("vertices outside");
        }
        if self.sheets.non_simple > 0 {
            f.push("non-simple shooting roots");
        }
        if o.single_sheet && self.sheets.multi_sheet_patches > 0 {
            f.push("multiple sheets");
        }
        if self.sheets.j_multi_lines > 0 {
            f.push("multiple sheets along j-lines");
        }
        if self.holes.crossing > 0 {
            f.push("holes");
        }
        f
    }
}

/// Measures `complex`. Patches failing [`crate::complex_io::validate_patch`] are counted in
/// [`CheckReport::invalid_patches`] (a failure) and left out of every measure; non-finite
/// results elsewhere (overflow) also fail.
#[must_use]
pub fn check(complex: &PatchComplex, opts: &CheckOptions) -> CheckReport {
    let continuity = opts
        .continuity
        .unwrap_or_else(|| complex.promised_continuity());
    // Invalid patches are reported, not evaluated.
    let mut invalid_patches = 0;
    let mut first_invalid = None;
    let mut evals = Vec::with_capacity(complex.patches.len());
    for (i, p) in complex.patches.iter().enumerate() {
        match crate::complex_io::validate_patch(p) {
            Ok(()) => evals.push(eval::PatchEval::new(p, i)),
            Err(m) => {
                invalid_patches += 1;
                first_invalid.get_or_insert_with(|| format!("patch {i}: {m}"));
            }
        }
    }
    let faces = faces::measure(&evals, opts);
    let interpolation = interp::measure(complex, &evals);
    let sheets = sheets::measure(&evals, opts);
    let surface: std::collections::HashSet<faces::PointKey> = complex
        .vertices
        .iter()
        .map(|&v| faces::point_key(v))
        .collect();
    let holes = holes::measure(&evals, &faces.boundary, &surface, continuity);
    CheckReport {
        scheme: complex.scheme.clone(),
        continuity,
        patches: complex.patches.len(),
        vertices: complex.vertices.len(),
        invalid_patches,
        first_invalid,
        faces: faces.stats,
        value_jump: faces.value,
        gradient_jump: faces.gradient,
        hessian_jump: faces.hessian,
        interpolation,
        sheets,
        holes,
        options: opts.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::complex::{Patch, Role, SheetRule};
    use crate::fixtures::{plain_patch, quadric_complex, Quadric, UNIT_TET};
    use glam::DVec3;

    fn sphere_complex(degree: usize) -> PatchComplex {
        let q = Quadric::sphere(DVec3::new(0.1, -0.05, 0.02), 0.8);
        quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 3, degree)
    }

    #[test]
    fn global_quadric_is_continuous() {
        for degree in [2, 3, 5] {
            let c = sphere_complex(degree);
            let opts = CheckOptions {
                continuity: Some(2),
                ..CheckOptions::default()
            };
            let r = check(&c, &opts);
            // 27 cubes × 6 tets; interior faces: 6 per cube inside + 3 axes × 2 × 3 × 9 between.
            assert_eq!(r.faces.shared, 27 * 6 + 3 * 2 * 2 * 9, "{r}");
            assert_eq!(r.faces.boundary, 6 * 2 * 9, "{r}");
            assert_eq!(r.faces.overshared, 0);
            assert_eq!(r.faces.t_junctions, 0);
            // One global polynomial: only rounding separates the two sides.
            assert!(r.value_jump.worst < 1e-13, "{r}");
            assert!(r.gradient_jump.worst < 1e-12, "{r}");
            assert!(r.hessian_jump.worst < 1e-10, "{r}");
            assert!(r.passed(), "{r}");
        }
    }

    #[test]
    fn fixture_grid_is_conforming_for_inexact_steps() {
        // Step 2/7 is inexact: neighbouring cubes must still share corners bit for bit, so every
        // interior face is matched and no T-junction is seen.
        let q = Quadric::sphere(DVec3::ZERO, 0.9);
        let cells = 7;
        let c = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), cells, 2);
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.faces.boundary, 6 * 2 * cells * cells, "{r}");
        assert_eq!(r.faces.t_junctions, 0, "{r}");
        assert!(r.passed(), "{r}");
    }

    #[test]
    fn perturbed_weight_is_reported() {
        let mut c = sphere_complex(3);
        // Weight (2,1,0,0) lies on the faces opposite vertices 3 and 4 of patch 40.
        let k = crate::bb::index_of([2, 1, 0, 0]);
        c.patches[40].weights[k] += 1e-6;
        let r = check(&c, &CheckOptions::default());
        assert!(!r.passed());
        assert!(r.value_jump.worst > 1e-8, "{r}");
        assert!(
            r.value_jump.at.as_ref().unwrap().patches.contains(&40),
            "{r}"
        );
        assert!(r.failures().contains(&"value jump"));
    }

    #[test]
    fn gradient_only_break_is_reported() {
        let mut c = sphere_complex(3);
        // Weight (1,1,1,0) is on face 4 (opposite vertex 4) only; (1,1,0,1)… pick an index with
        // exactly one zero component: it moves values on one face and gradients on others.
        let k = crate::bb::index_of([1, 1, 1, 0]);
        c.patches[100].weights[k] -= 1e-5;
        let r = check(&c, &CheckOptions::default());
        assert!(r.gradient_jump.worst > 1e-7, "{r}");
        assert!(!r.passed());
    }

    #[test]
    fn hessian_break_judged_only_for_c2() {
        // Add c·max(0, x − ⅓)², which is C1 but not C2 across the grid plane x = ⅓: patches on
        // its right get the quadric c(x − ⅓)² added to their weights.
        let mut c = sphere_complex(4);
        // The grid plane exactly as the fixture computes it (lo + step·2).
        let x0 = -1.0 + 2.0 / 3.0 * 2.0;
        let bump = Quadric {
            a: glam::DMat3::from_diagonal(DVec3::new(0.01, 0.0, 0.0)),
            b: DVec3::new(-0.02 * x0, 0.0, 0.0),
            c: 0.01 * x0 * x0,
        };
        for p in &mut c.patches {
            let tet = p.tet_points();
            if tet.iter().all(|v| v.x >= x0) {
                let extra = crate::fixtures::quadric_weights(&bump, &tet, 4);
                for (w, e) in p.weights.iter_mut().zip(extra) {
                    *w += e;
                }
            }
        }
        let r1 = check(&c, &CheckOptions::default());
        // Rounding only for F and ∇F; the Hessian jumps by 0.02 in xx (relative ~1e-2).
        assert!(r1.value_jump.worst < 1e-13, "{r1}");
        assert!(r1.gradient_jump.worst < 1e-12, "{r1}");
        assert!(r1.hessian_jump.worst > 1e-3, "{r1}");
        assert!(r1.passed(), "C1 promise ignores the Hessian: {r1}");
        let opts = CheckOptions {
            continuity: Some(2),
            ..CheckOptions::default()
        };
        let r2 = check(&c, &opts);
        assert_eq!(r2.failures(), vec!["hessian jump"], "{r2}");
    }

    #[test]
    fn invalid_patches_are_reported_not_evaluated() {
        let mut c = sphere_complex(2);
        c.patches[3].weights.truncate(4);
        c.patches[4].degree = 9;
        c.patches[5].weights = vec![1.0; 220];
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.invalid_patches, 3, "{r}");
        assert!(
            r.first_invalid
                .as_deref()
                .unwrap()
                .starts_with("patch 3: 4 weights"),
            "{r}"
        );
        // The unmeasured patches leave open faces on their neighbours, where the sphere crosses
        // them: holes, reported after the cause.
        assert_eq!(r.failures(), vec!["invalid patches", "holes"], "{r}");
        // An empty complex measures nothing and passes.
        assert!(check(&PatchComplex::new("empty"), &CheckOptions::default()).passed());
    }

    /// A closed sphere passes the hole test; the same complex with one patch removed has a
    /// hole where the sphere meets the faces that patch shared, and fails with that location.
    #[test]
    fn missing_patch_is_a_hole() {
        let c = sphere_complex(3);
        let r = check(&c, &CheckOptions::default());
        assert!(r.holes.boundary_faces > 0 && r.holes.crossing == 0, "{r}");
        assert!(r.passed(), "{r}");
        // The patch whose tetrahedron the sphere passes through, nearest the point (0.8, 0, 0).
        let k = c
            .patches
            .iter()
            .position(|p| {
                let t = p.tet().unwrap();
                let a = t.bary(DVec3::new(0.8, 0.01, 0.02));
                a.iter().all(|&x| x > 0.0)
            })
            .unwrap();
        let mut holed = c.clone();
        holed.patches.remove(k);
        let r = check(&holed, &CheckOptions::default());
        assert!(r.holes.crossing > 0, "{r}");
        assert!(r.failures().contains(&"holes"), "{r}");
        let at = r.holes.crossing_at.as_ref().unwrap();
        // The crossing point is on the removed tetrahedron's boundary, near the sphere.
        let x = DVec3::from_array(at.point);
        assert!((x.length() - 0.8).abs() < 0.5, "{r}");
        let t = c.patches[k].tet().unwrap();
        // 1e-9: barycentrics of a point computed from the same tetrahedron's corners.
        assert!(t.bary(x).iter().all(|&a| a > -1e-9), "{r}");
    }

    #[test]
    fn duplicate_patch_is_overshared() {
        let mut c = sphere_complex(2);
        // Patch 80 is in the centre cube: all four faces are already shared.
        let p = c.patches[80].clone();
        c.patches.push(p);
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.faces.overshared, 4, "{r}");
        assert!(!r.passed());
    }

    #[test]
    fn t_junction_is_reported() {
        // A unit cube of 6 tetrahedra next to a unit cube split into 2×2×2 cells: their faces
        // on the plane x = 1 overlap without sharing vertices.
        let q = Quadric::sphere(DVec3::ZERO, 0.5);
        let mut c = quadric_complex(&q, DVec3::ZERO, DVec3::ONE, 1, 2);
        let right = quadric_complex(
            &q,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 1.0),
            2,
            2,
        );
        c.patches.extend(right.patches);
        let r = check(&c, &CheckOptions::default());
        assert!(r.faces.t_junctions > 0, "{r}");
        assert!(!r.passed());
    }

    fn unit_tet_patch(degree: u8, weights: Vec<f64>, sheet: SheetRule) -> Patch {
        Patch {
            sheet,
            role: Role::Face,
            ..plain_patch(UNIT_TET, degree.into(), weights)
        }
    }

    /// Quadratic BB weights of αᵀMα (M symmetric): w_{ei+ej} = M_ij.
    fn quadratic_weights(m: [[f64; 4]; 4]) -> Vec<f64> {
        crate::bb::multi_indices(2)
            .iter()
            .map(|l| {
                let idx: Vec<usize> = (0..4)
                    .flat_map(|i| std::iter::repeat_n(i, l[i] as usize))
                    .collect();
                m[idx[0]][idx[1]]
            })
            .collect()
    }

    fn shooting() -> SheetRule {
        SheetRule::Shooting {
            base: [0, 1, 2].into(),
            top: [3].into(),
        }
    }

    #[test]
    fn simple_shooting_root_passes() {
        // F = α4 − ½: a plane, root t = ½ on every shooting line, φ′ = 1.
        let mut c = PatchComplex::new("test");
        c.patches
            .push(unit_tet_patch(1, vec![-0.5, -0.5, -0.5, 0.5], shooting()));
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.sheets.shooting_patches, 1);
        assert_eq!(r.sheets.non_simple, 0, "{r}");
        // φ′ = 1 and S = ½: relative slope 2, up to bisection rounding.
        let slope = r.sheets.min_root_slope.unwrap();
        assert!((slope - 2.0).abs() < 1e-12, "{r}");
    }

    #[test]
    fn double_shooting_root_fails() {
        // F = ¼(α4 − α1 − α2 − α3)² = (t − ½)² on every shooting line: a double root at ½.
        let mut m = [[0.0; 4]; 4];
        let s = [-1.0, -1.0, -1.0, 1.0];
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] = 0.25 * s[i] * s[j];
            }
        }
        let mut c = PatchComplex::new("test");
        c.patches
            .push(unit_tet_patch(2, quadratic_weights(m), shooting()));
        let r = check(&c, &CheckOptions::default());
        assert!(r.sheets.shooting_lines > 0);
        assert_eq!(r.sheets.non_simple, r.sheets.shooting_lines, "{r}");
        let at = r.sheets.min_root_slope_at.as_ref().unwrap();
        // The double root is at t = ½, i.e. z = ½ (the top vertex is (0,0,1)).
        assert!((at.point[2] - 0.5).abs() < 1e-6, "{r}");
        assert!(!r.passed());
    }

    #[test]
    fn two_sheets_are_a_warning_unless_promised() {
        // F = (α4 − α1 − α2 − α3)² − 0.01: roots at α4 = 0.45 and 0.55 on lines towards v4.
        let mut m = [[0.0; 4]; 4];
        let s = [-1.0, -1.0, -1.0, 1.0];
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] = s[i] * s[j] - 0.01;
            }
        }
        let mut c = PatchComplex::new("test");
        c.patches
            .push(unit_tet_patch(2, quadratic_weights(m), SheetRule::Any));
        let r = check(&c, &CheckOptions::default());
        assert!(r.sheets.multi_root_lines > 0, "{r}");
        assert_eq!(r.sheets.multi_sheet_patches, 1, "{r}");
        // A lone tetrahedron: both sheets run into its open faces (holes), but the sheets alone
        // are only a warning.
        assert_eq!(r.failures(), vec!["holes"], "{r}");
        let strict = CheckOptions {
            single_sheet: true,
            ..CheckOptions::default()
        };
        assert!(check(&c, &strict).failures().contains(&"multiple sheets"));
    }

    #[test]
    fn j_sheets_are_listed_with_their_first_root() {
        // Quadratic weights 1 at the apex (vertex 3) and on the base, −2 between: along every
        // j-line from the apex, φ(t) = (1−t)² − 4t(1−t) + t² = 1 − 6t + 6t², with two roots in
        // (0, 1), the first at t* = (3 − √3)/6.
        let twice: Vec<f64> = crate::bb::multi_indices(2)
            .iter()
            .map(|l| if l[3] == 1 { -2.0 } else { 1.0 })
            .collect();
        // F = λ₃ − ½ (weights: apex 1, base −½, between ¼): one root on every j-line.
        let once: Vec<f64> = crate::bb::multi_indices(2)
            .iter()
            .map(|l| f64::from(l[3]) / 2.0 - 0.5)
            .collect();
        let apex_patch = |w: Vec<f64>, shift: f64| {
            let p = unit_tet_patch(2, w, SheetRule::Any);
            Patch {
                jvertex: Some(3),
                element: 7,
                tet: p.tet.map(|v| v.map(|x| x + shift)),
                ..p
            }
        };
        let mut c = PatchComplex::new("test");
        c.patches.push(apex_patch(once, 0.0));
        c.patches.push(apex_patch(twice, 5.0));
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.sheets.j_multi_patches, 1, "{r}");
        assert_eq!(r.sheets.j_sheets.len(), 1, "{r}");
        let s = &r.sheets.j_sheets[0];
        assert_eq!((s.patch, s.element.as_str()), (1, "face 7"));
        // Every line of the second patch crosses twice: half of all lines sampled.
        assert_eq!(2 * s.lines, r.sheets.j_lines, "{r}");
        assert_eq!(s.lines, r.sheets.j_multi_lines, "{r}");
        // The point is the line's first sample past its first root: t in [t*, t* + 1/n) for
        // the checker's n samples per line, so λ₃ = z − 5 (the patch moved by 5 along every
        // axis) = 1 − t lies in (1 − t* − 1/n, 1 − t*].
        let n = CheckOptions::default().line_samples as f64;
        let t = 1.0 - (s.point[2] - 5.0);
        let t_star = (3.0 - 3f64.sqrt()) / 6.0;
        assert!(t >= t_star && t < t_star + 1.0 / n, "{s:?}");
        assert!(r.failures().contains(&"multiple sheets along j-lines"));
    }

    #[test]
    fn vertex_interpolation() {
        // Unit sphere on an integer grid: (±1,0,0), … are grid corners on the surface.
        let q = Quadric::sphere(DVec3::ZERO, 1.0);
        let mut c = quadric_complex(&q, DVec3::splat(-2.0), DVec3::splat(2.0), 4, 2);
        for v in [DVec3::X, DVec3::Y, DVec3::NEG_Z] {
            c.vertices.push(v.to_array());
            c.normals.push(v.to_array());
        }
        let r = check(&c, &CheckOptions::default());
        assert!(r.interpolation.value.samples > 0);
        assert_eq!(r.interpolation.off_corner, 0);
        // Exact data: rounding only.
        assert!(r.interpolation.value.worst < 1e-15, "{r}");
        assert!(r.interpolation.normal_angle.worst < 1e-15, "{r}");
        assert!(r.passed(), "{r}");

        // A vertex off the surface and a tilted normal are reported.
        c.vertices.push([1.0, 1.0, 0.0]);
        c.normals.push([0.0, 0.0, 1.0]);
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.interpolation.off_corner, 0, "grid point is a corner");
        assert_eq!(r.interpolation.value.at.as_ref().unwrap().vertex, Some(3));
        assert!(r.interpolation.value.worst > 0.1, "{r}");
        assert!(r.interpolation.normal_angle.worst > 0.5, "{r}");
        assert!(!r.passed());

        // A vertex inside a tetrahedron (not a corner) is found and measured; one outside fails.
        c.vertices.truncate(3);
        c.normals.truncate(3);
        c.vertices.push([0.6, 0.8, 0.0]);
        c.normals.push([0.6, 0.8, 0.0]);
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.interpolation.off_corner, 1);
        assert_eq!(r.interpolation.outside, 0);
        // Barycentric map rounding only.
        assert!(r.interpolation.value.worst < 1e-14, "{r}");
        c.vertices.push([3.0, 0.0, 0.0]);
        c.normals.push([1.0, 0.0, 0.0]);
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.interpolation.outside, 1);
        assert!(!r.passed());
    }
}
