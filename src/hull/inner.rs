//! The inner "corner-cutting" simplicial hull of Bajaj, Chen, Xu (1994), §3–5 and appendices
//! A–C: from a simple polyhedron with vertex normals to a smoothable simplicial hull
//! ([`SimplicialHull`], Definition 3.6).
//!
//! Pipeline ([`build_with_report`]):
//! 0. [`close`] (opt-in, [`InnerOptions::merge_close`]): vertices of one polygon closer than a
//!    share of the bounding-box diagonal become one corner of T (near-duplicate crease rings of
//!    control cages; no vertex moves, the sliver faces between them drop out).
//!    [`planar`]: polygons that are not planar (beyond [`InnerOptions::planar_tolerance`] of
//!    their size: subdivision control cages) are split into triangles, no vertex moved, with
//!    diagonals that fold like their neighbouring edges and do not end at steep corners
//!    (vertex normal almost in the polygon's plane, [`planar::STEEP_CORNER`]); nearly
//!    coplanar triangles meeting at a folded corner are joined back ([`planar::JOIN_ANGLE`]);
//!    with [`InnerOptions::split_search`], where the finished hull fails [`verify`], the splits
//!    at the corners its violations name are chosen by rebuilding and verifying
//!    ([`retriangulate`]). (The mesh must be a closed 2-manifold;
//!    [`closed::require_closed`] says why one is not, for the scenes.)
//! 1. [`coplanar`]: edge-adjacent coplanar faces are merged into one polygon (one face per
//!    plane, as the paper's polyhedra have; Appendix B's coplanarity treated at its source).
//! 2. [`decompose`]: corner guards (§5, Algorithm 2 step (1)). A star-shaped non-convex polygon
//!    keeps one guard, the centroid of its kernel (it sees every corner); other non-convex
//!    polygons are split into convex pieces whose centroids are the guards (Algorithm 2
//!    reduced to Algorithm 1, as §4 allows).
//!    Then [`flatnet`] (Appendix B, Algorithm 3): a merged flat region whose point of T lies
//!    far from one of its corners gets a guard per corner, near it, and its interior becomes a
//!    zero coplanar group of triangles among those guards (fandisk's large flat regions; also
//!    merged strips whose point folds a corner's fan and regions whose diagonals of T pass
//!    beside an edge at a nearly flat corner, [`flatnet::diagonal_misses`]).
//!    Then [`nearguard`]: a star face's corner served from far by its kernel guard, where the
//!    face meets a nearly flat neighbour whose guard changes along that edge, gets a guard of
//!    its own near it (mpi_poly's corner 74).
//! 3. [`above`]: the normal of every non-trihedral vertex is made "above face" (§4 (ii),
//!    Appendix C) by rotating it where needed; corners where no direction is above all faces
//!    are re-meshed first by Appendix C's corner smoothing ([`remesh`], before step 1).
//! 4. [`corner`]: Algorithm 1 steps (3)–(5) vertex by vertex, with Algorithm 2's step (3')
//!    for hallway corners (trihedral, one reflex face angle): T and the face tetrahedra; then
//!    [`corner::spread_hallway_apexes`] moves the hallway corners' outer apexes off the
//!    concave edge so the edge tetrahedra there are not inverted.
//! 5. [`sides`]: every triangle gets a face tetrahedron on each side its edges' convexity asks
//!    for (Definitions 3.1–3.4; the cubic's edge curves put the surface there), and every
//!    step (5) triangle gets its apexes over its base, rising along the mean vertex normal by
//!    the least height that keeps it tangent-containing; where T folds, apex pairs are raised
//!    until their midpoints clear both triangles. (Dense triangle meshes: the paper's T_0/T_1
//!    choice gives one-sided edges, slivers over the chord C_1C_2 and overlaps there.)
//!    Before that, [`unfold`] flips edges of T that fold back between two pseudo-centroids
//!    (short polyhedron edges between non-trihedral vertices), [`umbrella`] turns the
//!    normals of pseudo-centroids whose fan triangles stand almost edge-on to them, and
//!    [`slit`] flips edges of T across a thin slit of the polyhedron to run along its bottom.
//! 6. [`wedge`]: where T folds, apexes of step (5) triangles that lean across the plane
//!    bisecting the fold (into the neighbour's tetrahedra) are moved the least distance back
//!    inside their wedge, keeping tangent containment and the least height (beyond the paper;
//!    the nut's valleys of T). After it, [`clearance`] lifts apexes that lie below a base
//!    vertex's tangent plane (else the surface leaves the hull through the edge tetrahedra's
//!    outer faces; those below by less than the input's non-planarity are nudged over by a
//!    hair), and [`degenerate`] rebuilds over the base any face tetrahedron that
//!    is still degenerate (far apexes from nearly parallel intersections), or names the
//!    element in an error.
//!    Between steps 4 and 5, [`normals`] may turn pseudo-centroid normals towards their large
//!    faces (opt-in `ring_normals`: flat faces stay flat, the bend moves to the edges).
//! 7. Step (6), the edge tetrahedra, is derived by [`SimplicialHull::edge_tets`].
//!
//! In step 4, [`fan`] places the pseudo-centroid C_0 of a separable vertex where its fan
//! C_0C_iC_{i+1} is an umbrella round n_V with convex edges (beyond the paper: on coarse or
//! sharply folded models the paper's C_0 folds a fan triangle back over its neighbours).
//!
//! [`verify`] checks Definition 3.6 and Lemmas 4.1–4.3 on any hull. A hull with flat nets
//! that fails it is rebuilt by [`overlapnet`]: merged regions whose triangles of T overlap get
//! flat nets too, one at a time, each kept only when the rebuilt hull has fewer violations
//! (fandisk's strips along its 90° edges; hulls without flat nets are built once).
//!
//! Shape control (§7.1) splits into a hull part and a weight part. The hull part is α
//! ([`InnerOptions::alpha`]): how deep a non-trihedral corner is cut. For a trihedral corner the
//! hull is fixed (the face tetrahedron [C_1C_2C_3V] has V as its top: "as high as the vertex V"
//! and "the top of the face-tetrahedron" coincide), so its level — where between the bottom
//! triangle (0) and V (1) the patch rises — is a weight choice of the scheme; the hull only
//! carries it ([`InnerOptions::trihedral_level`]).

pub mod above;
pub mod clearance;
pub mod close;
pub mod closed;
pub mod coplanar;
pub mod corner;
pub mod decompose;
pub mod degenerate;
pub mod fan;
pub mod flatnet;
pub mod guardnet;
pub mod nearguard;
pub mod netmesh;
pub mod normals;
pub mod overlapnet;
pub mod planar;
pub mod reapex;
pub mod recut;
pub mod remesh;
pub mod retriangulate;
pub mod sides;
pub mod slit;
pub mod umbrella;
pub mod unfold;
pub mod unused;
pub mod verify;
pub mod wedge;

pub use verify::{verify, HullViolation, ViolationKind};

use crate::error::{Error, Result};
use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use crate::mesh::Mesh;
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// Shape-control parameters of the hull (§7.1).
#[derive(Clone, Debug, PartialEq)]
pub struct InnerOptions {
    /// α of the pseudo-centroid C_0 = αV + (1-α)V̄ of a non-trihedral vertex (Algorithm 1 (4)),
    /// in (0, 1): close to 1 cuts little off the corner, close to 0 almost all of it.
    pub alpha: f64,
    /// For trihedral corners (step (3)): how high the surface rises in the face tetrahedron
    /// [C_1C_2C_3V], from 0 (its bottom triangle) to 1 (the vertex V, its top). A weight
    /// parameter for the schemes; the hull does not depend on it.
    pub trihedral_level: f64,
    /// Rotate vertex normals that are not "above face" (Appendix C); when false such normals
    /// are errors.
    pub fix_normals: bool,
    /// Polygons deviating from their plane by more than this share of their size are split
    /// into triangles before the hull ([`planar`]; default [`planar::DEFAULT_TOLERANCE`]).
    /// `f64::INFINITY` turns the split off.
    pub planar_tolerance: f64,
    /// How far pseudo-centroid normals turn towards their large faces' normals, in [0, 1]
    /// ([`normals::flatten_ring_normals`]; default 0, the paper's n_V). Flattens large planar
    /// faces (the nut's sides); on curved models it can make the surface less fair.
    pub ring_normals: f64,
    /// Vertices of one polygon closer than this share of the bounding-box diagonal are merged
    /// into one corner of T before everything else ([`close`]; default 0: off). For cages with
    /// near-duplicate crease rings (spot_control_cage).
    pub merge_close: f64,
    /// Smallest relative volume 6V / L³ of a face tetrahedron: flatter ones are rebuilt over
    /// their base by [`degenerate::repair_below`], the hull's last step. Default
    /// [`verify::DEGENERATE_VOLUME`] (what `verify` calls degenerate, enough for the cubic);
    /// [`InnerOptions::from_toml`] raises it to [`verify::C2_MIN_VOLUME`] for `type =
    /// "quintic-c2"`, whose C2 rows carry squared barycentrics.
    pub min_volume: f64,
    /// Where the hull of the ranked splits of bent polygons fails `verify`, change those splits
    /// by verification ([`retriangulate`]; default false: opt-in, it rebuilds the hull up to
    /// [`retriangulate::MAX_TRIALS`] times). For strongly bent control cages
    /// (spot_control_cage).
    pub split_search: bool,
    /// Where the hull (after the split search, if on) still fails `verify`, re-cut the
    /// corners its violations name: n_V turned further above face and α per corner, chosen by
    /// rebuilding and verifying ([`recut`]; default false: opt-in, up to
    /// [`recut::MAX_TRIALS`] rebuilds). For strongly folded control cages (spot_control_cage).
    pub corner_search: bool,
    /// Where the hull (after the searches above, if on) still has overlapping tetrahedra,
    /// unsigned edge tetrahedra or tangent planes that miss their face tetrahedra, move the
    /// apexes they depend on: lower, towards the centroid or sideways, or to the deepest point
    /// of the region they may take, chosen by the overlap test itself ([`reapex`]; default
    /// false: opt-in). For strongly folded control cages (spot_control_cage) and models with
    /// sharp ridges of T (fandisk, mpi_poly).
    pub apex_search: bool,
    /// Give every polygon with at least [`flatnet::MIN_CORNERS`] corners a zero coplanar
    /// corner guard net (Appendix B), not only the large merged flat regions whose points of T
    /// lie far from a corner ([`flatnet`]; default false: opt-in). For models whose non-convex
    /// faces are split into convex pieces with guards far from the corners they serve
    /// (mpi_poly cleaned by `model.clean`: its U-shaped faces).
    pub all_flat_nets: bool,
    /// Smallest angle (degrees) the triangles of every flat net should reach: points of T are
    /// added inside the nets' guard polygons until they do where they can ([`netmesh`]; 0 =
    /// off, the default: the nets triangulate their guards only). A guard polygon with long
    /// sides sampled finely along one of them (flattened fandisk) is otherwise a fan of
    /// needles, which the quintic's C2 conditions extrapolate by hundreds of their sizes.
    pub flat_net_angle: f64,
    /// Keep the vertices on a straight edge between two flat nets as corners of both polygons
    /// (default false: [`coplanar`] drops every vertex between only two polygons): they get a
    /// guard in each net and step (5') cells on their edges, no corner triangles. Otherwise the
    /// edge is as long as the whole crease (flattened fandisk: 0.81 and 0.52, their neighbours
    /// 0.019), and the nets' triangles and cells on it are needles.
    pub straight_corners: bool,
}

impl Default for InnerOptions {
    fn default() -> Self {
        InnerOptions {
            alpha: 0.5,
            trihedral_level: 0.5,
            fix_normals: true,
            planar_tolerance: planar::DEFAULT_TOLERANCE,
            ring_normals: 0.0,
            merge_close: 0.0,
            min_volume: verify::DEGENERATE_VOLUME,
            split_search: false,
            corner_search: false,
            apex_search: false,
            all_flat_nets: false,
            flat_net_angle: 0.0,
            straight_corners: false,
        }
    }
}

impl InnerOptions {
    /// The `[scheme]` keys [`InnerOptions::from_toml`] reads.
    pub const KEYS: [&'static str; 12] = [
        "alpha",
        "trihedral_level",
        "fix_normals",
        "planar_tolerance",
        "ring_normals",
        "merge_close",
        "split_search",
        "corner_search",
        "apex_search",
        "all_flat_nets",
        "flat_net_angle",
        "straight_corners",
    ];

    /// Reads `alpha` (number in (0, 1)), `trihedral_level` (number in [0, 1]), `fix_normals`
    /// (boolean), `planar_tolerance` (number ≥ 0, or `false` for no split) and `ring_normals`
    /// (number in [0, 1]), `merge_close` (number in [0, 0.05]), `split_search`, `corner_search`,
    /// `apex_search`, `all_flat_nets` and `straight_corners` (booleans), `flat_net_angle`
    /// (degrees in [0, 30])
    /// from a scene's `[scheme]` table (and sets [`InnerOptions::min_volume`] from its `type`); absent keys keep their defaults, other keys
    /// are ignored (the scheme checks for unknown keys, see [`InnerOptions::KEYS`]).
    ///
    /// # Errors
    /// A key of the wrong type or out of range, naming the scene file and the key.
    pub fn from_toml(table: &toml::Table, scene: &Path) -> Result<InnerOptions> {
        let bad = |message: String| Error::Input {
            path: scene.to_path_buf(),
            message,
        };
        let number = |key: &str| -> Result<Option<f64>> {
            match table.get(key) {
                None => Ok(None),
                Some(toml::Value::Float(x)) => Ok(Some(*x)),
                Some(toml::Value::Integer(i)) => Ok(Some(*i as f64)),
                Some(v) => Err(bad(format!(
                    "`scheme.{key}`: expected a number, found {}",
                    v.type_str()
                ))),
            }
        };
        let mut o = InnerOptions::default();
        // The quintic's C2 rows need face tetrahedra that stand off their base (a degree-aware
        // bound; the cubic keeps verify's).
        if table.get("type").and_then(toml::Value::as_str) == Some("quintic-c2") {
            o.min_volume = verify::C2_MIN_VOLUME;
        }
        if let Some(a) = number("alpha")? {
            if !(a > 0.0 && a < 1.0) {
                return Err(bad(format!(
                    "`scheme.alpha` = {a}: must lie strictly between 0 and 1"
                )));
            }
            o.alpha = a;
        }
        if let Some(l) = number("trihedral_level")? {
            if !(0.0..=1.0).contains(&l) {
                return Err(bad(format!(
                    "`scheme.trihedral_level` = {l}: must lie in [0, 1]"
                )));
            }
            o.trihedral_level = l;
        }
        if let Some(b) = number("ring_normals")? {
            if !(0.0..=1.0).contains(&b) {
                return Err(bad(format!(
                    "`scheme.ring_normals` = {b}: must lie in [0, 1]"
                )));
            }
            o.ring_normals = b;
        }
        if let Some(t) = number("merge_close")? {
            // Beyond 5 % of the diagonal whole features would merge: surely a typo.
            if !(0.0..=0.05).contains(&t) {
                return Err(bad(format!(
                    "`scheme.merge_close` = {t}: must lie in [0, 0.05] (a share of the bounding-box diagonal)"
                )));
            }
            o.merge_close = t;
        }
        if let Some(a) = number("flat_net_angle")? {
            // Ruppert's refinement is proven to end below about 20.7°; the nets' kept edges
            // stop it earlier anyway, and beyond 30° it would only spend points.
            if !(0.0..=30.0).contains(&a) {
                return Err(bad(format!(
                    "`scheme.flat_net_angle` = {a}: must lie in [0, 30] (degrees; 0 = off)"
                )));
            }
            o.flat_net_angle = a;
        }
        match table.get("planar_tolerance") {
            None => {}
            Some(toml::Value::Boolean(false)) => o.planar_tolerance = f64::INFINITY,
            Some(v) => {
                let t = v
                    .as_float()
                    .or_else(|| v.as_integer().map(|i| i as f64))
                    .ok_or_else(|| {
                        bad(format!(
                            "`scheme.planar_tolerance`: expected a number or false, found {}",
                            v.type_str()
                        ))
                    })?;
                if t.is_nan() || t < 0.0 {
                    return Err(bad(format!(
                        "`scheme.planar_tolerance` = {t}: must be a number ≥ 0 (or false)"
                    )));
                }
                o.planar_tolerance = t;
            }
        }
        match table.get("fix_normals") {
            None => {}
            Some(toml::Value::Boolean(b)) => o.fix_normals = *b,
            Some(v) => {
                return Err(bad(format!(
                    "`scheme.fix_normals`: expected a boolean, found {}",
                    v.type_str()
                )))
            }
        }
        for (key, slot) in [
            ("split_search", &mut o.split_search),
            ("corner_search", &mut o.corner_search),
            ("apex_search", &mut o.apex_search),
            ("all_flat_nets", &mut o.all_flat_nets),
            ("straight_corners", &mut o.straight_corners),
        ] {
            match table.get(key) {
                None => {}
                Some(toml::Value::Boolean(b)) => *slot = *b,
                Some(v) => {
                    return Err(bad(format!(
                        "`scheme.{key}`: expected a boolean, found {}",
                        v.type_str()
                    )))
                }
            }
        }
        Ok(o)
    }
}

/// What [`build_with_report`] changed or decided, for users and tests.
#[derive(Clone, Debug, Default)]
pub struct InnerReport {
    /// Vertices whose normal was rotated to be "above face" (Appendix C), with the new normal.
    pub adjusted_normals: Vec<(u32, DVec3)>,
    /// Non-convex input polygons split into convex pieces (corner guards), with the piece count.
    pub split_faces: Vec<(u32, usize)>,
    /// Non-convex but star-shaped input polygons kept whole, with their single corner guard.
    pub star_faces: Vec<(u32, DVec3)>,
    /// Non-trihedral vertices that are unseparable from their face centroids (C_0 = V).
    pub unseparable: Vec<u32>,
    /// How the face tetrahedra were chosen.
    pub cases: corner::CaseCounts,
    /// Triangles whose sides were settled from the convexity of their edges ([`sides`]).
    pub sides: sides::SideCounts,
    /// Non-planar polygons split into triangles before the hull ([`planar`]); face indices
    /// are the input mesh's.
    pub planar_split: Vec<planar::SplitFace>,
    /// Corners re-meshed before the hull because no direction was above all their faces
    /// (Appendix C, [`remesh`]); vertex indices of the re-meshed mesh follow the input's.
    pub remeshed: Vec<remesh::RemeshedCorner>,
    /// Triangles whose degenerate face tetrahedra were rebuilt over their base ([`degenerate`]).
    pub degenerate_repaired: usize,
    /// Pseudo-centroid normals turned towards their large faces ([`normals`], `ring_normals`).
    pub ring_normals: usize,
    /// Apexes moved back inside the wedge of a fold of T ([`wedge`]).
    pub wedged: usize,
    /// Folded-back edges of T between pseudo-centroid pairs replaced by the other diagonal
    /// ([`unfold`]).
    pub flipped_folds: usize,
    /// Edges of T across a slit of the polyhedron flipped to run along its bottom
    /// ([`slit::flip_slits`]).
    pub flipped_slits: usize,
    /// Apexes lifted over their base vertices' tangent planes ([`clearance`]).
    pub lifted_apexes: usize,
    /// Clusters of near-duplicate vertices merged into one corner of T ([`close`],
    /// `merge_close`), representative first.
    pub merged_clusters: Vec<Vec<u32>>,
    /// Points of T (pseudo-centroids) whose normals were turned to face their fan triangles
    /// ([`umbrella`]).
    pub umbrella_normals: Vec<u32>,
    /// Bent polygons whose split the verification search changed ([`retriangulate`]; faces of
    /// the mesh after the close-vertex merge), with the violations before and after.
    pub retriangulated: retriangulate::Search,
    /// Corners whose normal or α the verification search changed ([`recut`],
    /// `corner_search`), with the violations before and after.
    pub recut: recut::Search,
    /// The apex search's log ([`reapex`]; empty unless `apex_search`).
    pub reapex: reapex::Search,
    /// Flat polygons given a guard per corner and a zero coplanar group ([`flatnet`]).
    pub flat_nets: usize,
    /// Corners kept on straight edges between two flat nets (`straight_corners`).
    pub straight_corners: usize,
    /// Input faces of the merged polygons that could take a flat net but have none
    /// ([`flatnet::FlatNets::eligible`]).
    pub flat_net_candidates: Vec<u32>,
    /// Input faces whose merged polygons were given flat nets because their triangles of T
    /// overlapped in an earlier build ([`overlapnet`]).
    pub overlap_nets: Vec<u32>,
    /// Corners of star faces given a guard of their own ([`nearguard`]): (input face, vertex).
    pub near_guards: Vec<(u32, u32)>,
    /// Points of T no triangle used (guards the guard net gave no corner), dropped
    /// ([`unused`]); indices before the drop.
    pub unused_points: Vec<u32>,
}

/// Builds the inner simplicial hull of `mesh` (polygons, counter-clockwise from outside) with
/// unit vertex normals `normals`.
///
/// # Errors
/// See [`build_with_report`].
pub fn build(mesh: &Mesh, normals: &[DVec3], options: &InnerOptions) -> Result<SimplicialHull> {
    build_with_report(mesh, normals, options).map(|(h, _)| h)
}

/// [`build`], also returning what was changed on the way.
///
/// T's points are, in order: one per convex piece of every polygon (its centroid; normal = the
/// polygon's normal), then one pseudo-centroid per non-trihedral vertex; points no triangle
/// uses (a guard net's unassigned guards) are dropped at the end ([`unused`]). Triangles are emitted
/// vertex by vertex; `element` is the input vertex.
///
/// # Errors
/// Bad options, a normal count that is not #V, non-finite normals, a mesh that is not a closed
/// 2-manifold (naming the vertex and its line), zero-area faces, and corners where no normal is
/// above all faces (or where one is not and `fix_normals` is off).
pub fn build_with_report(
    mesh: &Mesh,
    normals: &[DVec3],
    options: &InnerOptions,
) -> Result<(SimplicialHull, InnerReport)> {
    let (hull, report) = build_searched(mesh, normals, options)?;
    if !options.apex_search {
        return Ok((hull, report));
    }
    Ok(apex_search(hull, report))
}

/// [`search_apexes`] on the built hull, its log in the report.
fn apex_search(hull: SimplicialHull, mut report: InnerReport) -> (SimplicialHull, InnerReport) {
    let (hull, log) = search_apexes(hull, false);
    report.reapex = log;
    (hull, report)
}

/// [`reapex::improve`] on `hull`, kept when `verify` agrees that it helped: fewer violations
/// and no more of other kinds than overlaps (the search counts overlaps only). Returns the
/// hull (moved or as it was) and the search's log (empty when the moves were not kept). For
/// hulls that a scheme changes after the build (the cubic's `prepare_hull`: `keep_slopes`,
/// see [`reapex::improve`]) as well as for [`build_with_report`]'s.
#[must_use]
pub fn search_apexes(hull: SimplicialHull, keep_slopes: bool) -> (SimplicialHull, reapex::Search) {
    let before = verify(&hull);
    let unsigned_before = reapex::unsigned_count(&hull);
    if before.is_empty() && unsigned_before == 0 {
        return (hull, reapex::Search::default());
    }
    let mut moved = hull.clone();
    let log = reapex::improve(&mut moved, keep_slopes);
    if log.moved.is_empty() {
        return (hull, reapex::Search::default());
    }
    let after = verify(&moved);
    let unsigned_after = reapex::unsigned_count(&moved);
    if std::env::var("APATCH_REAPEX_TRACE").is_ok() {
        eprintln!(
            "reapex: violations {} -> {}; overlaps {} -> {}; unsigned {} -> {}; {} moved, {} trials",
            before.len(),
            after.len(),
            log.before,
            log.after,
            unsigned_before,
            unsigned_after,
            log.moved.len(),
            log.trials
        );
    }
    let others = |v: &[HullViolation]| {
        v.iter()
            .filter(|x| x.kind != ViolationKind::Intersecting)
            .count()
    };
    if (after.len(), unsigned_after) < (before.len(), unsigned_before)
        && others(&after) <= others(&before)
    {
        (moved, log)
    } else {
        (hull, reapex::Search::default())
    }
}

/// [`build_with_report`] up to the apex search: the build with the flat nets the overlaps
/// force, then the split and corner searches.
fn build_searched(
    mesh: &Mesh,
    normals: &[DVec3],
    options: &InnerOptions,
) -> Result<(SimplicialHull, InnerReport)> {
    let none = std::collections::BTreeSet::new();
    let (hull, report, bent) = build_with(mesh, normals, options, &none, &[], &[])?;
    // Merged regions whose triangles of T overlap get flat nets too ([`overlapnet`]).
    let (hull, report) = if report.flat_nets == 0 && !options.all_flat_nets {
        (hull, report)
    } else {
        overlapnet::force_nets(hull, report, |forced| {
            build_forced(mesh, normals, options, forced)
        })
    };
    if !options.split_search && !options.corner_search {
        return Ok((hull, report));
    }
    let violations = verify(&hull);
    if violations.is_empty() {
        return Ok((hull, report));
    }
    let nets: std::collections::BTreeSet<u32> = report.overlap_nets.iter().copied().collect();
    // Bent polygons' splits (`split_search`) and corners' cuts (`corner_search`) chosen by
    // verification where the ranked ones fail, in turns while either still improves.
    let (mut forced, mut cuts) = (Vec::new(), Vec::new());
    let mut current = violations;
    let (mut split_log, mut cut_log) = (retriangulate::Search::default(), recut::Search::default());
    let mut changed = false;
    // The split search alone is one pass (it converged within its rounds).
    let passes = if options.corner_search {
        SEARCH_PASSES
    } else {
        1
    };
    for pass in 0..passes {
        let mut improved = false;
        if options.split_search && !bent.is_empty() && !current.is_empty() {
            let s = retriangulate::improve_from(&bent, &forced, &current, |f| {
                build_with(mesh, normals, options, &nets, f, &cuts)
                    .ok()
                    .map(|(h, _, _)| verify(&h))
            });
            if s.after < s.before {
                forced.clone_from(&s.forced);
                current = build_with(mesh, normals, options, &nets, &forced, &cuts)
                    .map(|(h, _, _)| verify(&h))?;
                improved = true;
            }
            split_log = merge_log(split_log, s, pass);
        }
        if options.corner_search && !current.is_empty() {
            let s = recut::improve_from(&cuts, &recut::CUTS, &current, |c| {
                build_with(mesh, normals, options, &nets, &forced, c)
                    .ok()
                    .map(|(h, _, _)| verify(&h))
            });
            if s.after < s.before {
                cuts.clone_from(&s.cuts);
                current = build_with(mesh, normals, options, &nets, &forced, &cuts)
                    .map(|(h, _, _)| verify(&h))?;
                improved = true;
            }
            cut_log = merge_log(cut_log, s, pass);
        }
        changed |= improved;
        if !improved {
            break;
        }
    }
    if !changed {
        return Ok((hull, report));
    }
    let (hull, mut report, _) = build_with(mesh, normals, options, &nets, &forced, &cuts)?;
    report.retriangulated = split_log;
    report.recut = cut_log;
    Ok((hull, report))
}

/// Turns of the split search and the corner search ([`build_with_report`]).
pub const SEARCH_PASSES: usize = 3;

/// A search log over passes: the first pass's `before`, the last's choices and `after`, the
/// trials summed.
fn merge_log<S: SearchLog>(old: S, new: S, pass: usize) -> S {
    if pass == 0 {
        return new;
    }
    S::join(old, new)
}

/// What [`merge_log`] needs of a search's record.
trait SearchLog {
    /// `old`'s start, `new`'s choices and end, trials of both.
    fn join(old: Self, new: Self) -> Self;
}

impl SearchLog for retriangulate::Search {
    fn join(old: Self, new: Self) -> Self {
        retriangulate::Search {
            before: old.before,
            trials: old.trials + new.trials,
            ..new
        }
    }
}

impl SearchLog for recut::Search {
    fn join(old: Self, new: Self) -> Self {
        recut::Search {
            before: old.before,
            trials: old.trials + new.trials,
            ..new
        }
    }
}

/// [`build_with_report`] without its rebuilds, with the merged regions of the input faces
/// `forced` given flat nets ([`flatnet::spread_guards_forced`]).
///
/// # Errors
/// See [`build_with_report`].
pub fn build_forced(
    mesh: &Mesh,
    normals: &[DVec3],
    options: &InnerOptions,
    forced: &std::collections::BTreeSet<u32>,
) -> Result<(SimplicialHull, InnerReport)> {
    build_with(mesh, normals, options, forced, &[], &[]).map(|(h, r, _)| (h, r))
}

/// One build without rebuilds: the merged regions of the input faces `nets` given flat nets
/// ([`flatnet::spread_guards_forced`]) and the splits of some bent polygons forced
/// ([`planar::split_nonplanar_forced`]; faces of the mesh after the close-vertex merge); also
/// returns the split polygons the split search may change. Corners listed in `cuts` take their
/// normal turn and α from it ([`recut`]).
fn build_with(
    mesh: &Mesh,
    normals: &[DVec3],
    options: &InnerOptions,
    nets: &std::collections::BTreeSet<u32>,
    splits: &[(u32, planar::Forced)],
    cuts: &[(u32, recut::Cut)],
) -> Result<(SimplicialHull, InnerReport, Vec<retriangulate::Bent>)> {
    if !(options.alpha > 0.0 && options.alpha < 1.0) {
        return Err(Error::Invalid(format!(
            "inner hull: alpha = {} must lie strictly between 0 and 1",
            options.alpha
        )));
    }
    let nv = mesh.positions.len();
    if normals.len() != nv {
        return Err(Error::Invalid(format!(
            "inner hull: {} normals for {nv} vertices",
            normals.len()
        )));
    }
    let mut report = InnerReport::default();
    // Near-duplicate corners (opt-in): one corner of T per cluster.
    let close = close::merge_close_vertices(mesh, normals, options.merge_close)?;
    let (mesh, normals) = match &close {
        Some(c) => {
            report.merged_clusters.clone_from(&c.clusters);
            (&c.mesh, &c.normals[..])
        }
        None => (mesh, normals),
    };
    // Polygons that are not planar are split into triangles (no vertex moves).
    let split =
        planar::split_nonplanar_forced(mesh, options.planar_tolerance, Some(normals), splits);
    let bent: Vec<retriangulate::Bent> = split.as_ref().map_or(Vec::new(), |s| {
        s.faces
            .iter()
            .enumerate()
            .map(|(i, sf)| retriangulate::Bent {
                face: sf.face,
                corners: mesh.faces[sf.face as usize].clone(),
                candidates: s.candidates[i],
                ranked: planar::Forced {
                    triangulation: s.chosen[i],
                    join: s.join[i],
                },
                joinable: s.joinable[i].clone(),
            })
            .collect()
    });
    let mesh = match &split {
        Some(s) => {
            report.planar_split.clone_from(&s.faces);
            // Faces named as the input's (the close-vertex merge may have dropped some).
            if close.is_some() {
                for sf in &mut report.planar_split {
                    sf.face = mesh.face_parent[sf.face as usize];
                }
            }
            &s.mesh
        }
        None => mesh,
    };
    // Appendix C: corners round which no direction is above every face are re-meshed first.
    let remeshed = if options.fix_normals {
        remesh::remesh_corners(mesh, normals)?
    } else {
        None
    };
    let (mesh, normals) = match &remeshed {
        Some(r) => {
            report.remeshed.clone_from(&r.corners);
            (&r.mesh, &r.normals[..])
        }
        None => (mesh, normals),
    };
    let nv = mesh.positions.len();
    let line = |v: usize| mesh.vertex_lines.get(v).copied().unwrap_or(0);
    let (mut merged, mut merged_counts) = coplanar::merge_coplanar_counted(mesh);
    let mut forced = nets.clone();
    let mut straight = std::collections::BTreeSet::new();
    if options.straight_corners {
        // The polygons that get flat nets with the straight vertices dropped keep those
        // between two of them, and get their nets again.
        let mut probe = guardnet::GuardNet::build(&merged, decompose::convex_pieces(&merged)?);
        let netted: std::collections::BTreeSet<u32> = flatnet::spread_guards_forced(
            &mut probe,
            &merged,
            &merged_counts,
            Some(normals),
            nets,
            options.all_flat_nets,
            0.0,
        )
        .groups
        .iter()
        .map(|g| merged.face_parent[g.face as usize])
        .collect();
        let (kept, counts) = coplanar::merge_coplanar_keeping(mesh, |a, b| {
            netted.contains(&a) && netted.contains(&b)
        });
        let mut polygons: HashMap<u32, usize> = HashMap::new();
        for face in &kept.faces {
            for &v in face {
                *polygons.entry(v).or_default() += 1;
            }
        }
        straight = polygons
            .into_iter()
            .filter(|&(_, n)| n == 2)
            .map(|(v, _)| v)
            .collect();
        report.straight_corners = straight.len();
        (merged, merged_counts) = (kept, counts);
        forced.extend(netted);
    }
    let mesh = &merged;
    // Algorithm 2 step (1): regions with several pieces get a corner guard net.
    let mut net = guardnet::GuardNet::build(mesh, decompose::convex_pieces(mesh)?);
    net.straight = straight;
    // Appendix B: large flat polygons get a guard per corner and a zero coplanar group.
    let flat = flatnet::spread_guards_forced(
        &mut net,
        mesh,
        &merged_counts,
        Some(normals),
        &forced,
        options.all_flat_nets,
        options.flat_net_angle,
    );
    report.flat_nets = flat.groups.len();
    // A straight corner needs both its polygons' nets (their guards and cells stand in for its
    // corner triangles).
    if !net.straight.is_empty() {
        let netted: std::collections::BTreeSet<u32> = flat.groups.iter().map(|g| g.face).collect();
        for &v in &net.straight {
            if let Some(f) = (0..mesh.faces.len() as u32)
                .find(|&f| mesh.faces[f as usize].contains(&v) && !netted.contains(&f))
            {
                return Err(Error::Invalid(format!(
                    "vertex {v} (line {}): kept as a straight corner (`straight_corners`) but its face {} got no flat net",
                    line(v as usize),
                    mesh.face_parent[f as usize]
                )));
            }
        }
    }
    report.flat_net_candidates.clone_from(&flat.eligible);
    report.overlap_nets = nets.iter().copied().collect();
    // Star faces' corners served from far where the face folds nearly flat into a neighbour.
    report.near_guards = nearguard::add_near_guards(&mut net, mesh)
        .into_iter()
        .map(|(f, v, _)| (mesh.face_parent[f as usize], v))
        .collect();
    let pieces = &net.pieces;
    let input_face = |f: u32| mesh.face_parent[f as usize];
    report.split_faces = pieces
        .split
        .iter()
        .map(|&(f, n)| (input_face(f), n))
        .collect();
    report.star_faces = pieces
        .star
        .iter()
        .map(|&(f, g)| (input_face(f), g))
        .collect();
    let topo = &net.topo;

    let mut hull = SimplicialHull::default();
    for (f, _) in pieces.faces.iter().enumerate() {
        let c = pieces.center[f];
        hull.points.push(c);
        hull.normals.push(pieces.normal[f]);
        let face = mesh.face_parent[pieces.parent[f] as usize];
        hull.origins.push(if pieces.guard[f] {
            PointOrigin::CornerGuard { face }
        } else {
            PointOrigin::Centroid { face }
        });
    }
    let mut ring = Vec::new();
    let mut hallway = Vec::new();
    #[allow(clippy::needless_range_loop)] // v indexes positions, normals, lines and topology
    for v in 0..nv {
        if topo.vertex_corners(v as u32).is_empty() || net.inside(v as u32) {
            continue; // unreferenced, or inside one region: no corner of the polyhedron
        }
        if net.straight.contains(&(v as u32)) {
            continue; // a straight corner between two flat nets: their cells meet there
        }
        let fan = match net.fan(v as u32) {
            Some(f) if f.closed => f,
            Some(_) => {
                return Err(Error::Invalid(format!(
                "vertex {v} (line {}) is on a boundary: the inner hull needs a closed polyhedron",
                line(v)
            )))
            }
            None => {
                return Err(Error::Invalid(format!(
                "vertex {v} (line {}) is non-manifold: the inner hull needs a closed 2-manifold",
                line(v)
            )))
            }
        };
        let mut n = normals[v];
        if fan.faces.len() != 3 {
            n = n.try_normalize().ok_or_else(|| {
                Error::Invalid(format!(
                    "vertex {v} (line {}): normal {n} is zero or not finite",
                    line(v)
                ))
            })?;
            let face_normals: Vec<DVec3> = fan
                .faces
                .iter()
                .map(|&f| pieces.normal[f as usize])
                .collect();
            if above::clearance(n, &face_normals) < above::ABOVE_MARGIN {
                let fixed = if options.fix_normals {
                    above::make_above(n, &face_normals)
                } else {
                    None
                };
                let Some(fixed) = fixed else {
                    return Err(Error::Invalid(format!(
                        "vertex {v} (line {}): {} (Appendix C)",
                        line(v),
                        if options.fix_normals {
                            "no normal direction is above all its faces; the corner would need re-meshing"
                        } else {
                            "the normal is not above all its faces and fix_normals is off"
                        }
                    )));
                };
                n = fixed;
                report.adjusted_normals.push((v as u32, n));
            }
        }
        let cut = cuts.iter().find(|(w, _)| *w == v as u32).map(|(_, c)| *c);
        let recut_options;
        let corner_options = match cut {
            Some(cut) if fan.faces.len() != 3 => {
                if cut.turn > 0.0 {
                    let face_normals: Vec<DVec3> = fan
                        .faces
                        .iter()
                        .map(|&f| pieces.normal[f as usize])
                        .collect();
                    let best = above::most_above(&face_normals);
                    // Both ends are above face, so is their blend (a convex cone); kept only
                    // if rounding agrees.
                    if let Some(t) = (n + cut.turn * (best - n)).try_normalize() {
                        if above::clearance(t, &face_normals) >= above::ABOVE_MARGIN {
                            n = t;
                        }
                    }
                }
                recut_options = InnerOptions {
                    alpha: cut.alpha.unwrap_or(options.alpha),
                    ..options.clone()
                };
                &recut_options
            }
            _ => options,
        };
        ring.clear();
        ring.extend(fan.ring.iter().map(|&w| mesh.positions[w as usize]));
        let reflex = (0..fan.faces.len()).find(|&i| {
            let a = ring[i] - mesh.positions[v];
            let b = ring[(i + 1) % ring.len()] - mesh.positions[v];
            // Reflex when the turn at V is clockwise in the face's plane, beyond rounding of
            // the edge vectors (1e-12 relative).
            a.cross(b).dot(pieces.normal[fan.faces[i] as usize]) < -1e-12 * a.length() * b.length()
        });
        let c = corner::Corner {
            vertex: v as u32,
            v: mesh.positions[v],
            n,
            ring: &ring,
            faces: &fan.faces,
            reflex,
        };
        if !corner::build_corner(
            &mut hull,
            &c,
            corner_options,
            &mut report.cases,
            &mut hallway,
        ) {
            report.unseparable.push(v as u32);
        }
    }
    corner::spread_hallway_apexes(&mut hull, &hallway);
    net.add_edge_cells(&mut hull, &mesh.positions);
    flat.add_triangles(&mut hull);
    report.ring_normals = normals::flatten_ring_normals(&mut hull, options.ring_normals);
    report.flipped_folds = unfold::flip_folds(&mut hull, &mesh.positions);
    report.umbrella_normals = umbrella::face_fans(&mut hull);
    report.flipped_slits = slit::flip_slits(&mut hull, &mesh.positions);
    report.sides = sides::settle(&mut hull, options.apex_search);
    report.wedged = wedge::keep_in_wedges(&mut hull);
    report.lifted_apexes = clearance::lift_apexes(&mut hull);
    report.degenerate_repaired =
        degenerate::repair_below(&mut hull, &mesh.vertex_lines, options.min_volume)?;
    let (unused_points, renumber) = unused::drop_unused_points(&mut hull);
    if !unused_points.is_empty() {
        for i in &mut report.umbrella_normals {
            *i = renumber[*i as usize].expect("an umbrella point has fan triangles");
        }
    }
    report.unused_points = unused_points;
    Ok((hull, report, bent))
}
