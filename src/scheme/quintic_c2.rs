//! C2 quintic A-patches on the inner simplicial hull (Bajaj, Chen, Xu 1994, §6, appendices D–E).
//!
//! One quintic per tetrahedron of a smoothable simplicial hull ([`SimplicialHull`]): every face
//! tetrahedron `[p_i p_j p_k q]` and every edge tetrahedron `[p_i p_j q s]`. The 56 weights of
//! each are fixed in the order of the paper's steps 1–15 (see [`system`] for which condition
//! fixes which weight), the coupled systems around each point of T (appendices D and E) and
//! along each edge of T solved together, each closest to target weights that make the patches
//! single-sheeted (see [`QuinticOptions`]). The result is C2 across every shared face
//! and interpolates T's points with ∇F ∥ their normals.

pub mod beta;
pub mod checkpoint;
pub mod cholesky;
mod dd;
pub mod dense;
pub mod flat;
pub mod holes;
pub mod interior;
pub mod jets;
pub mod localmeet;
pub mod normalpart;
pub mod ordering;
mod pinned;
pub mod project;
pub mod resume;
pub mod signfit;
pub mod signs;
mod signsplit;
pub mod slivers;
pub mod sparse;
pub mod supernodal;
pub mod system;

use crate::complex::{Patch, PatchComplex, SheetRule};
use crate::error::{Error, Result};
use crate::hull::simplicial::{EdgePoint, SimplicialHull};
use crate::mesh::Mesh;
use anyhow::bail;
use glam::DVec3;
use std::path::Path;

/// The free choices of the scheme.
#[derive(Clone, Debug, PartialEq)]
pub struct QuinticOptions {
    /// Scale of the Hessian at the points of T: 1 = the shape operator estimated from the
    /// normals of T's neighbouring points (curvature continuous and close to the normals'),
    /// 0 = zero Hessian (flatter patches).
    pub curvature: f64,
    /// Lift of the free weights toward the vertices off T (apexes, edge midpoints), in units of
    /// their height above T: 0 = the plain blend of the Taylor polynomials.
    pub lift: f64,
    /// Give single-sided triangles of T that are not convex for their side the partner
    /// tetrahedron of an L-U pair before building (Definition 3.6 (4); the cubic scheme's
    /// [`crate::scheme::cubic_c1::sided::complete_lu_pairs`]): their base weights fixed by the
    /// data have the apex's sign ([`signs::base_conflicts`]), so with one side only the
    /// surface would leave the hull through the base (a hole).
    pub complete_lu_pairs: bool,
    /// Solve every point's star together with the number 3/4 weights of its edges and its
    /// Hessian (number 2 weights, closest to the estimate), as the solve does for points not in
    /// general position: the square systems of appendices D and E then have free dimensions
    /// that [`QuinticOptions::signs`] can use. Slower (larger groups).
    pub joint_stars: bool,
    /// Relax the stars whose determined weights (appendices D and E) miss Theorem 2.1's signs:
    /// solve them with their edge middles and Hessian, closest to the targets, and repeat
    /// while the misses fall. Only stars with misses pay for the larger groups.
    pub relax_stars: bool,
    /// Where a star's square system is singular (T not in general position around its point,
    /// e.g. edges through it collinear in pairs), impose the system's consistency conditions
    /// (one linear condition per dependent equation) on the edge middles solved before it,
    /// instead of relaxing the star. Off by default: the conditions couple the edge middles of
    /// all such points into one group.
    pub consistent_stars: bool,
    /// Enforce Theorem 2.1's sign conditions (k = 1, [`signs`]) on the weights the C2
    /// constraints leave free, by pinning the ones whose targets miss their sign (in groups of
    /// up to the in-house factor's 1M unknowns; [`QuinticOptions::sign_targets`] reaches the
    /// larger ones).
    pub signs: bool,
    /// Move each point's estimated Hessian, as little as possible, so that the number 2
    /// weights meet Theorem 2.1's signs ([`signs::fit_hessians`]): the estimate follows the
    /// neighbours' normals and can bend the surface out through a flat base or back before
    /// an apex.
    pub hessian_signs: bool,
    /// Move every apex that lies beyond a tangent plane of its triangle's points to its side of
    /// them before building (the cubic scheme's
    /// [`crate::scheme::cubic_c1::tangent::contain_tangents`]): the number 1 weights toward such
    /// an apex, n_k·(q − p_k)/5, are fixed by the data with the wrong sign, so F starts with
    /// the wrong sign on the boundary faces [p_k q s] of the edge tetrahedra next to p_k (a
    /// hole) whatever the free weights are.
    pub contain_tangents: bool,
    /// As `contain_tangents`, and also move every apex whose slope to a tangent plane of its
    /// triangle's points is below this (0 = off, the default), though on its side, to the
    /// margin [`crate::scheme::cubic_c1::tangent::TANGENT_MARGIN`]
    /// ([`crate::scheme::cubic_c1::tangent::contain_tangents_with`]); the apex search then
    /// clears the overlaps the moves make (as the cubic's `prepare_hull`). Algorithm 1 puts
    /// apexes on the polyhedron's edges, so on flat faces the boundary faces [p q s] of the
    /// edge tetrahedra next to p lie in p's tangent plane and the far star weights decide on
    /// which side F leaves p (mpi_poly, session 32: holes 98 → 49).
    pub tangent_clearance: f64,
    /// Make T's coplanar groups whose points' normals agree with their plane up to input
    /// rounding exact zero coplanar groups (Appendix B (5'')(ii), [`flat`]): points on the
    /// plane with its normal, zero Hessians. Off by default (no shipped scene has one).
    pub zero_groups: bool,
    /// Near-null threshold of the vertex-star systems (0 = off, the default): where a star's
    /// σ/σ_max ≤ this, the matching left singular vector's condition on the weights solved
    /// before the star (edge middles) is imposed, as `consistent_stars` does for exact
    /// dependencies, so the star's weights do not follow their data's noise amplified by 1/σ.
    pub star_tau: f64,
    /// Move the targets of the weights with one of Theorem 2.1's signs into that sign before
    /// each group is solved, by this many times the median |target| of those weights (0 = off,
    /// the default). A group's solution is the point of its equations closest to the targets,
    /// so targets inside the sign box leave fewer weights off their sign at no extra solve:
    /// the one lever on groups too large to pin (fandisk's joint group: holes 9016 → 3533).
    pub sign_targets: f64,
    /// With `signs`: rounds of alternating projections between Theorem 2.1's signs and the
    /// equations in each group too large to pin (beyond the in-house factor, as fandisk's
    /// joint group), all with the group's one factor (0 = off, the default). The signed
    /// weights are clamped into the box of `sign_targets` (or 1) medians of their |target| and
    /// moved back onto the equations, round after round; the round with the fewest weights
    /// off their sign is kept.
    pub joint_sign_rounds: usize,
    /// With `signs`: rounds of the sign program (the fewest weights off Theorem 2.1's signs,
    /// as `sign_program`) in each group too large to pin, split so that a round is one solve
    /// with the group's factor (ADMM, `signsplit`), after its dropped rows are met and moving
    /// orthogonally to what met them (0 = off, the default). The round with the fewest
    /// weights off is kept if, its dropped rows met again, the rows stay met within 10×
    /// the solve's residual.
    pub joint_sign_fit: usize,
    /// With `joint_sign_fit`: what a miss of a weight on a boundary face of the hull costs in
    /// the split sign program, in units of an inner weight's (1, the default: all alike). The
    /// surface leaves the hull where a boundary face's weights miss (a hole), while an inner
    /// weight's miss only loosens Theorem 2.1's certificate; `apatch check --holes` names the
    /// boundary faces' misses (docs/quintic.md, session 55).
    pub joint_sign_boundary: f64,
    /// With `joint_sign_fit`: the miss, relative to the group's scale, to which the meet
    /// after the fit meets the rows its factor dropped (0, the default: the solve's own
    /// tolerance, 1e-13). Those rows lie within ~1e-11 of the kept rows' span, so the meet's
    /// moves are long (1e-2) and take the fit's weights off their signs, while the check's
    /// Hessian jump (bound 1e-7) follows the rows' miss at ~5e4 times it: fandisk, met to
    /// 2e-12 of its scale instead of 1e-13, keeps C2 (gradient 3.0e-10, Hessian 6.8e-8) with
    /// 494 crossed faces and 59 j-sheet patches instead of 623 and 69 (session 63). At most
    /// [`MAX_JOINT_MEET_TOLERANCE`].
    pub joint_meet_tolerance: f64,
    /// With `joint_sign_fit`: the rows the fit leaves missed are met region by region
    /// ([`localmeet`]: the nearest unknowns free, a dense pivoted QR's least move) instead of by the
    /// group's factor, whose meet moves the weights by 1e-2 and takes their signs. On fandisk
    /// the regions' rows have a clean gap between their exact dependencies (σ ~1e-15 of the
    /// largest) and their constraints (σ above ~1e-9), and their moves are 1e-10 … 1e-6
    /// (session 64). Off by default. With it `joint_meet_tolerance` has no effect: the factor's
    /// meet after the fit is not made.
    pub joint_local_meet: bool,
    /// β of the shared faces in the C1/C2 rows ([`beta::FaceBeta`]): `"f64"` (the default,
    /// the f64 barycentric map), `"exact"` (double-double from the stored points) or
    /// `"snapped"` (exact, with the construction's zeros and integers restored: the edge
    /// tetrahedron pairs' rows exactly collinear). On fandisk snapped rows leave the joint
    /// group's sign fit 421 weights off instead of 1020 and the holes 623 instead of 723
    /// (docs/quintic.md, sessions 60–61); the small scenes pass with any of the three.
    pub face_beta: beta::FaceBeta,
    /// The part of each relaxed point's Hessian held at the signed distance's
    /// ([`normalpart::HessianNormal`]): `"free"` (the default: every relaxed Hessian weight
    /// closest to its estimate), `"bend"` (nᵀ∇²F n = 0, a row per point) or `"column"`
    /// (∇²F n = 0, three rows per point). Only points whose Hessian is relaxed (`joint_stars`,
    /// failing stars) are affected: elsewhere the estimate meets the rows.
    pub hessian_normal: normalpart::HessianNormal,
    /// What a relaxed Hessian weight's distance from its estimate costs in a group's least
    /// change, against the other weights' 1 (1, the default: weight by weight alike), in the
    /// group's solve and in its sign pins. In a tetrahedron of height h a change of the
    /// Hessian moves its number 2 weights by only ~h²/20 of it, so at 1 the joint stars bend
    /// the Hessians where that is cheap (the rounded cylinder's level set curves 4× the
    /// cylinder at its points); at 100 the rounded cylinder, both quad tori and the
    /// octahedron keep their estimated Hessians to a few per cent and still pass, but the
    /// curvature moves between the points instead (the cylinder's mean curvature varies 2×
    /// more over its sides; docs/quintic.md, session 68), so no shipped scene sets it.
    pub hessian_cost: f64,
    /// Hold the whole column ∇²F n = 0 (as `hessian_normal = "column"`) at every point of T
    /// flat to this many degrees: the normals of the points of T it shares a tetrahedron with
    /// all within that angle of its own ([`normalpart::flat_points`]); the scene's
    /// `hessian_normal` elsewhere. There F should be the plane's signed distance. Held
    /// everywhere the column leaves fandisk's joint group unmet (session 67); at its points
    /// flat to 0.5° the sign fit and the repair do better than with `"bend"` alone (session
    /// 69). `None` (the default): no point.
    pub hessian_column_flat: Option<f64>,
    /// The joint group's meet before the sign fit (its dropped rows met by moves in the kept
    /// rows' null space) stops after this many rounds in a row that did not lower its
    /// residual, instead of running every round (each ~6 min on fandisk). `None` (the
    /// default): every round. With `hessian_column_flat` fandisk's first two rounds ask a move
    /// of 1.37 and are refused; its scene stops there (session 69).
    pub joint_meet_stall: Option<usize>,
    /// More points of T (indices of the complex's vertices) whose whole column is held, as
    /// for [`Self::hessian_column_flat`]: a point `scripts/normal_curvature.py` ranks first by
    /// its mixed part P H n. Empty by default.
    pub hessian_column_points: Vec<u32>,
    /// The double-double factor's drop threshold (a pivot is a row's squared distance from
    /// the rows before it, relative) for the groups beyond the in-house factor (fandisk's
    /// joint group), instead of [`cholesky::PRECISE_PIVOT`] (1e-15) and, when that factor's
    /// first correction does not help, [`supernodal::PRECISE_RETRY_PIVOT`] (1e-12). A scene
    /// known to need the second (fandisk with snapped β: the first factor's correction takes
    /// the residual 0.74 → 4.7e20) names it and skips the first factor (~12–20 min, 11.6 GB).
    /// Rows dropped are met afterwards ([`cholesky::meet_dropped`]). `None` by default.
    pub precise_pivot: Option<f64>,
    /// After the solve, re-solve the late weights (no point of T at multiplicity ≥ 2, and the
    /// stars one ring in) of the tetrahedra around every boundary face the surface crosses (a
    /// hole) and every patch it crosses twice along a j-line (a j-sheet), with all their
    /// C1/C2 equations and the defect's weights pinned to Theorem 2.1's signs ([`holes`]): C2
    /// is kept exactly and nothing changes away from the defects. Off by default.
    pub repair_holes: bool,
    /// With `repair_holes`: when the repair also frees the Hessians of the jets within reach
    /// ([`holes::Reach::hessians`]), for defects whose weights are all jets and stars, such
    /// as base faces of face tetrahedra. `true` (the default, [`HessianRepair::Last`]): two
    /// last passes for what the others leave (letter_P_poly without `hessian_signs`: 28 → 10
    /// crossed faces; bunny: 6 → 3); `"all"`: every pass; `false`: never.
    pub repair_hessians: HessianRepair,
    /// With `repair_holes`: how many passes with one more ring each follow the first (2 rings)
    /// for the defects left open ([`holes::WIDEN`] = 2 by default, so 2, 3 and 4 rings; at
    /// most [`MAX_REPAIR_WIDEN`]). The defects a pass refuses because their pins could be met
    /// only as weighted targets are held back by weights beyond its reach; a wider pass frees
    /// them (fandisk, docs/quintic.md). A repair taken up from its checkpoint may ask for more.
    pub repair_widen: usize,
    /// With `repair_holes`: a crossed face's sign conditions asked of its polynomial's
    /// coefficients elevated by this many degrees instead of its weights ([`holes`]; 0, the
    /// default, keeps the weights'). Elevated coefficients of one sign are a weaker condition
    /// than the weights' (the face stays uncrossed), which a crease point whose sides ask
    /// opposite curvature signs can still meet: letter_P_poly without `hessian_signs` passes
    /// `check` with 2, not without (docs/quintic.md, session 52–53). At most
    /// [`MAX_REPAIR_ELEVATE`].
    pub repair_elevate: usize,
    /// With `repair_elevate`: the pins a crossed face is tried with, in turn, until one
    /// mends it: `None` the weights' own pins, `Some(m)` the elevated coefficients' with the
    /// margin m (a share of the weights' margin). Default: the weights', then 1, 1e-2, 0 (on
    /// fandisk each margin mends faces the others do not).
    pub repair_margins: Vec<Option<f64>>,
    /// Move apart the apexes of edge tetrahedra that are slivers (relative volume below
    /// [`slivers::EDGE_MIN_VOLUME`]) before building: their world Hessians carry the weights'
    /// rounding times (L / h)², which no solve can remove ([`slivers`]). On by default; hulls
    /// without such slivers are unchanged.
    pub thicken_edges: bool,
    /// Place each edge tetrahedron pair's shared point s on its apexes' line where C1/C2
    /// extrapolate least ([`crate::hull::simplicial::balanced_ratio`]) instead of at the
    /// midpoint: a needle triangle of T, or a small triangle beside a large one, puts the
    /// midpoint 20–200 of its face tetrahedron's sizes away, and the C2 conditions then
    /// multiply the face tetrahedron's weights by that squared. Off by default.
    pub balance_edges: bool,
    /// Rounds of alternating projections between Theorem 2.1's signs and the C1/C2 equations
    /// after the solve ([`project`]; 0 = off, the default): the weights move towards their
    /// signs, C2 is kept, the jets are not moved.
    pub sign_rounds: usize,
    /// Instead of the rounds, move the weights to the fewest (L1-least) misses of Theorem
    /// 2.1's signs that the C1/C2 equations allow, by a linear program ([`signfit`]: HiGHS
    /// with the cargo feature `highs`, else the pure-Rust [`interior`] point method; the
    /// rounds run only if it fails). Off by default.
    pub sign_program: bool,
}

impl Default for QuinticOptions {
    fn default() -> Self {
        QuinticOptions {
            curvature: 1.0,
            lift: LIFT,
            signs: false,
            complete_lu_pairs: true,
            joint_stars: false,
            star_tau: 0.0,
            sign_targets: 0.0,
            joint_sign_rounds: 0,
            joint_sign_fit: 0,
            joint_sign_boundary: 1.0,
            joint_meet_tolerance: 0.0,
            joint_local_meet: false,
            face_beta: beta::FaceBeta::F64,
            hessian_normal: normalpart::HessianNormal::Free,
            hessian_cost: 1.0,
            hessian_column_flat: None,
            joint_meet_stall: None,
            hessian_column_points: Vec::new(),
            precise_pivot: None,
            relax_stars: true,
            consistent_stars: false,
            hessian_signs: false,
            contain_tangents: false,
            tangent_clearance: 0.0,
            zero_groups: false,
            repair_holes: false,
            repair_hessians: HessianRepair::Last,
            repair_widen: holes::WIDEN,
            repair_elevate: 0,
            repair_margins: REPAIR_MARGINS.to_vec(),
            thicken_edges: true,
            balance_edges: false,
            sign_rounds: 0,
            sign_program: false,
        }
    }
}

/// When the hole repair frees the Hessians of the jets within its reach
/// ([`QuinticOptions::repair_hessians`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HessianRepair {
    /// Never: the jets stay as the solve left them.
    Off,
    /// In two last passes, for the defects the passes with the Hessians held leave.
    Last,
    /// In every pass: on fandisk most defects sit at weights the Hessians set, and a pass
    /// with them held refuses those for want of anything to pin (docs/quintic.md).
    All,
}

/// The largest [`QuinticOptions::repair_widen`]: 2 + 8 = 10 rings of points round a defect
/// already reach across most of a model's features, and every ring grows the local group.
pub const MAX_REPAIR_WIDEN: usize = 8;

/// The largest [`QuinticOptions::repair_elevate`]: a face of degree 5 elevated by r has
/// (r + 6)(r + 7)/2 coefficients, each an unknown and a row of the repair's group.
pub const MAX_REPAIR_ELEVATE: usize = 5;

/// Default [`QuinticOptions::repair_margins`]: the weights' pins, then the elevated ones with
/// margins 1, 1e-2 and 0.
pub const REPAIR_MARGINS: [Option<f64>; 4] = [None, Some(1.0), Some(1e-2), Some(0.0)];

/// The largest elevated margin [`QuinticOptions::repair_margins`] takes: 100 times the
/// weights' own margin is already a tenth of the face's largest weight.
pub const MAX_REPAIR_MARGIN: f64 = 100.0;

/// The largest [`QuinticOptions::precise_pivot`]: pivots are squared distances relative to
/// the row, so 1e-6 drops rows up to 1e-3 of their length from the span of the others, which
/// are independent rows for the factor to keep, not rounding for the meet to mend.
pub const MAX_PRECISE_PIVOT: f64 = 1e-6;

/// The largest [`QuinticOptions::hessian_cost`]: costs up to 1e4 were measured (sessions 59,
/// 68); the weighted solve divides the Hessian weights' columns by the cost, and far beyond
/// that they would shrink toward the rows' rounding, changing what the factor drops and not
/// only the norm.
pub const MAX_HESSIAN_COST: f64 = 1e6;

/// The largest [`QuinticOptions::joint_meet_tolerance`]: the check's gradient and Hessian
/// jumps follow the joint group's row misses at ~200 and ~5e4 times them (fandisk), so rows
/// met to 1e-10 of the scale already break C2's bounds (1e-9, 1e-7) by far.
pub const MAX_JOINT_MEET_TOLERANCE: f64 = 1e-10;

/// Default [`QuinticOptions::lift`].
pub const LIFT: f64 = 3.0;

/// The value of `scheme.{key}` as one of `names` (read by `named`), else an error naming
/// `scene`, the key and the names.
fn one_of<T>(
    v: &toml::Value,
    key: &str,
    scene: &Path,
    names: &[&str],
    named: impl Fn(&str) -> Option<T>,
) -> anyhow::Result<T> {
    v.as_str().and_then(named).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: `scheme.{key}` must be one of {}, got {v}",
            scene.display(),
            names
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

impl QuinticOptions {
    /// Reads the `[scheme]` table: `type`, the optional `curvature` (a number ≥ 0) and the inner
    /// hull's keys ([`crate::hull::inner::InnerOptions::KEYS`], read by the hull).
    ///
    /// # Errors
    /// Unknown keys and bad values, naming the key and `scene`.
    pub fn from_toml(table: &toml::Table, scene: &Path) -> anyhow::Result<QuinticOptions> {
        let mut o = QuinticOptions::default();
        for (k, v) in table {
            let flag = || -> anyhow::Result<bool> {
                v.as_bool().ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}: `scheme.{k}` must be true or false, got {v}",
                        scene.display()
                    )
                })
            };
            let count = || -> anyhow::Result<usize> {
                v.as_integer()
                    .and_then(|i| usize::try_from(i).ok())
                    .ok_or_else(|| {
                        anyhow::anyhow!(
                            "{}: `scheme.{k}` must be a whole number ≥ 0, got {v}",
                            scene.display()
                        )
                    })
            };
            // An integer key in [0, max].
            let integer_to = |max: usize| -> anyhow::Result<usize> {
                match v.as_integer() {
                    Some(n) if (0..=max as i64).contains(&n) => Ok(n as usize),
                    _ => Err(anyhow::anyhow!(
                        "{}: `scheme.{k}` must be an integer in [0, {max}], got {v}",
                        scene.display()
                    )),
                }
            };
            // Every numeric key: a float or an integer, finite, in the key's range.
            let number = |in_range: &dyn Fn(f64) -> bool, what: &str| -> anyhow::Result<f64> {
                match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
                    Some(x) if x.is_finite() && in_range(x) => Ok(x),
                    _ => Err(anyhow::anyhow!(
                        "{}: `scheme.{k}` must be {what}, got {v}",
                        scene.display()
                    )),
                }
            };
            match k.as_str() {
                "type" => {}
                k if crate::hull::inner::InnerOptions::KEYS.contains(&k) => {}
                "lift" => o.lift = number(&|x| x >= 0.0, "a number ≥ 0")?,
                "complete_lu_pairs" => o.complete_lu_pairs = flag()?,
                "joint_stars" => o.joint_stars = flag()?,
                "relax_stars" => o.relax_stars = flag()?,
                "consistent_stars" => o.consistent_stars = flag()?,
                "hessian_signs" => o.hessian_signs = flag()?,
                "contain_tangents" => o.contain_tangents = flag()?,
                "repair_holes" => o.repair_holes = flag()?,
                "repair_hessians" => {
                    o.repair_hessians = match (v.as_bool(), v.as_str()) {
                        (Some(true), _) | (_, Some("last")) => HessianRepair::Last,
                        (Some(false), _) => HessianRepair::Off,
                        (_, Some("all")) => HessianRepair::All,
                        _ => bail!(
                            "{}: `scheme.repair_hessians` must be true, false, \"last\" or \"all\", got {v}",
                            scene.display()
                        ),
                    }
                }
                "repair_widen" => o.repair_widen = integer_to(MAX_REPAIR_WIDEN)?,
                "repair_elevate" => o.repair_elevate = integer_to(MAX_REPAIR_ELEVATE)?,
                "repair_margins" => {
                    let bad = || {
                        anyhow::anyhow!(
                            "{}: `scheme.repair_margins` must be a non-empty array of \"weights\" and numbers in [0, {MAX_REPAIR_MARGIN}], got {v}",
                            scene.display()
                        )
                    };
                    let items = v.as_array().filter(|a| !a.is_empty()).ok_or_else(bad)?;
                    o.repair_margins = items
                        .iter()
                        .map(|m| match (m.as_str(), m.as_float().or_else(|| m.as_integer().map(|i| i as f64))) {
                            (Some("weights"), _) => Ok(None),
                            (_, Some(x)) if (0.0..=MAX_REPAIR_MARGIN).contains(&x) => Ok(Some(x)),
                            _ => Err(bad()),
                        })
                        .collect::<anyhow::Result<_>>()?;
                }
                "thicken_edges" => o.thicken_edges = flag()?,
                "balance_edges" => o.balance_edges = flag()?,
                "sign_program" => o.sign_program = flag()?,
                "sign_rounds" => o.sign_rounds = count()?,
                "zero_groups" => o.zero_groups = flag()?,
                "tangent_clearance" => {
                    let margin = crate::scheme::cubic_c1::tangent::TANGENT_MARGIN;
                    o.tangent_clearance = number(
                        &|c| (0.0..=margin).contains(&c),
                        &format!("a number in [0, {margin}] (moved apexes get the slope {margin})"),
                    )?;
                }
                "star_tau" => {
                    o.star_tau = number(&|t| (0.0..1.0).contains(&t), "a number in [0, 1)")?;
                }
                "sign_targets" => {
                    o.sign_targets =
                        number(&|t| (0.0..=100.0).contains(&t), "a number in [0, 100]")?;
                }
                "joint_sign_rounds" => o.joint_sign_rounds = count()?,
                "joint_sign_fit" => o.joint_sign_fit = count()?,
                "joint_meet_stall" => {
                    o.joint_meet_stall = Some(count()?).filter(|&k| k > 0);
                    if o.joint_meet_stall.is_none() {
                        bail!(
                            "{}: `scheme.joint_meet_stall` must be a whole number ≥ 1, got {v}",
                            scene.display()
                        );
                    }
                }
                "joint_sign_boundary" => {
                    o.joint_sign_boundary =
                        number(&|t| (1.0..=1e6).contains(&t), "a number in [1, 1e6]")?;
                }
                "joint_meet_tolerance" => {
                    o.joint_meet_tolerance = number(
                        &|t| (0.0..=MAX_JOINT_MEET_TOLERANCE).contains(&t),
                        &format!("a number in [0, {MAX_JOINT_MEET_TOLERANCE:e}]"),
                    )?;
                }
                "joint_local_meet" => o.joint_local_meet = flag()?,
                "face_beta" => {
                    o.face_beta = one_of(v, k, scene, &beta::FaceBeta::NAMES, beta::FaceBeta::named)?
                }
                "hessian_normal" => {
                    o.hessian_normal = one_of(
                        v,
                        k,
                        scene,
                        &normalpart::HessianNormal::NAMES,
                        normalpart::HessianNormal::named,
                    )?
                }
                "hessian_cost" => {
                    o.hessian_cost = number(
                        &|t| t > 0.0 && t <= MAX_HESSIAN_COST,
                        &format!("a number in (0, {MAX_HESSIAN_COST:e}]"),
                    )?;
                }
                "hessian_column_flat" => {
                    o.hessian_column_flat = Some(number(
                        &|t| t > 0.0 && t <= 90.0,
                        "an angle in degrees in (0, 90]",
                    )?);
                }
                "hessian_column_points" => {
                    let bad = || {
                        anyhow::anyhow!(
                            "{}: `scheme.hessian_column_points` must be an array of indices of points of T (integers ≥ 0), got {v}",
                            scene.display()
                        )
                    };
                    let items = v.as_array().ok_or_else(bad)?;
                    o.hessian_column_points = items
                        .iter()
                        .map(|p| {
                            p.as_integer()
                                .and_then(|i| u32::try_from(i).ok())
                                .ok_or_else(bad)
                        })
                        .collect::<anyhow::Result<_>>()?;
                }
                "precise_pivot" => {
                    o.precise_pivot = Some(number(
                        &|t| t > 0.0 && t <= MAX_PRECISE_PIVOT,
                        &format!("a number in (0, {MAX_PRECISE_PIVOT:e}]"),
                    )?);
                }
                "signs" => o.signs = flag()?,
                "curvature" => o.curvature = number(&|x| x >= 0.0, "a number ≥ 0")?,
                other => bail!(
                    "{}: `scheme.{other}`: unknown key for quintic-c2 (expected `curvature`, `lift`, `signs`, `joint_stars`, `relax_stars`, `consistent_stars`, `hessian_signs`, `complete_lu_pairs`, `contain_tangents`, `tangent_clearance`, `zero_groups`, `star_tau`, `sign_targets`, `joint_sign_rounds`, `joint_sign_fit`, `joint_sign_boundary`, `joint_meet_tolerance`, `joint_meet_stall`, `joint_local_meet`, `face_beta`, `hessian_normal`, `hessian_cost`, `hessian_column_flat`, `hessian_column_points`, `precise_pivot`, `repair_holes`, `repair_hessians`, `repair_widen`, `repair_elevate`, `repair_margins`, `thicken_edges`, `balance_edges`, `sign_rounds`, `sign_program`, {})",
                    scene.display(),
                    crate::hull::inner::InnerOptions::KEYS.map(|k| format!("`{k}`")).join(", ")
                ),
            }
        }
        if table.contains_key("repair_margins") && o.repair_elevate == 0 {
            bail!(
                "{}: `scheme.repair_margins` needs `repair_elevate` ≥ 1 (the margins are the elevated pins')",
                scene.display()
            );
        }
        Ok(o)
    }
}

/// What [`build_with_stats`] measured besides the complex.
pub type BuildStats = system::SolveStats;

/// Builds the C2 quintic complex on `hull`; `complex.continuity = Some(2)`.
///
/// # Errors
/// A hull that is not a manifold, a degenerate tetrahedron, or a coupled system that cannot be
/// met (points not in general position), naming where.
pub fn build(hull: &SimplicialHull, options: &QuinticOptions) -> Result<PatchComplex> {
    build_with_stats(hull, options).map(|(c, _)| c)
}

/// [`build`] that also returns the system's size and final residual.
///
/// # Errors
/// As [`build`].
pub fn build_with_stats(
    hull: &SimplicialHull,
    options: &QuinticOptions,
) -> Result<(PatchComplex, BuildStats)> {
    build_prepared(&prepare_hull(hull, options)?, options)
}

/// The hull the quintic patches fill: the builder's hull after the scheme's own changes, made
/// once (as the cubic's [`crate::scheme::cubic_c1::prepare_hull`]), with what each changed.
#[derive(Clone, Debug)]
pub struct PreparedHull {
    /// The changed hull: its face and edge tetrahedra are the patches'.
    pub hull: SimplicialHull,
    /// Triangles given the partner apex of an L-U pair (`complete_lu_pairs`).
    pub lu_completed: usize,
    /// Sliver edge tetrahedra found, with their volumes before and after (`thicken_edges`).
    pub slivers: Vec<slivers::Sliver>,
    /// Apexes moved to their side of their triangle's tangent planes (`contain_tangents`).
    pub tangent_moved: usize,
    /// Points of T in exact zero coplanar groups (`zero_groups`): on their plane, with its
    /// normal and a zero Hessian.
    pub zero_points: Vec<u32>,
}

/// Makes the scheme's changes to `hull` ([`PreparedHull`]): L-U partners for single-sided
/// triangles that are not convex for their side, sliver edge tetrahedra opened, apexes moved
/// over tangent planes, zero coplanar groups, each as `options` asks.
///
/// # Errors
/// A hull whose arrays are inconsistent or not finite.
pub fn prepare_hull(hull: &SimplicialHull, options: &QuinticOptions) -> Result<PreparedHull> {
    validate(hull)?;
    let (completed, lu_completed) = if options.complete_lu_pairs {
        crate::scheme::cubic_c1::sided::complete_lu_pairs(hull)
    } else {
        (hull.clone(), Vec::new())
    };
    let (completed, slivers) = if options.thicken_edges {
        slivers::thicken(&completed)
    } else {
        (completed, Vec::new())
    };
    let clearance = options.tangent_clearance;
    let (completed, tangent_moved) = if options.contain_tangents || clearance > 0.0 {
        let (h, moved, _stuck) =
            crate::scheme::cubic_c1::tangent::contain_tangents_with(&completed, clearance);
        // Only the clearance's moves are followed by the apex search (spot_control_cage's
        // `contain_tangents` hull stays as it was).
        let h = if clearance > 0.0 {
            crate::hull::inner::search_apexes(h, true).0
        } else {
            h
        };
        (h, moved.len())
    } else {
        (completed, 0)
    };
    let (completed, zero_points) = if options.zero_groups {
        flat::zero_coplanar_groups(&completed)
    } else {
        (completed, Vec::new())
    };
    Ok(PreparedHull {
        hull: completed,
        lu_completed: lu_completed.len(),
        slivers,
        tangent_moved,
        zero_points,
    })
}

/// The patches on a prepared hull ([`prepare_hull`], whose changes are not made again), with
/// what the solve did.
///
/// # Errors
/// As [`build`].
pub fn build_prepared(
    prepared: &PreparedHull,
    options: &QuinticOptions,
) -> Result<(PatchComplex, BuildStats)> {
    let PreparedHull {
        hull,
        lu_completed,
        slivers,
        tangent_moved,
        zero_points,
    } = prepared;
    validate(hull)?;
    let np = hull.points.len() as u32;
    let nt = hull.triangles.len() as u32;
    let mut jets = jets::estimate(hull, options.curvature);
    for &p in zero_points {
        jets[p as usize].h = glam::DMat3::ZERO;
    }
    let rule = if options.balance_edges {
        EdgePoint::Balanced
    } else {
        EdgePoint::Midpoint
    };
    let (tets, _pos) = system::tetrahedra_with(hull, rule)?;
    let mut sys = system::assemble_with(&tets, np, options.face_beta.or_env())?;
    sys.star_tau = options.star_tau;
    sys.hessian_cost = options.hessian_cost;
    sys.sign_targets = options.sign_targets;
    sys.joint_sign_rounds = options.joint_sign_rounds;
    sys.joint_sign_fit = options.joint_sign_fit;
    sys.joint_sign_boundary = options.joint_sign_boundary;
    sys.joint_meet_tolerance = options.joint_meet_tolerance;
    sys.joint_meet_stall = options.joint_meet_stall;
    sys.joint_local_meet = options.joint_local_meet;
    sys.precise_pivot = options.precise_pivot;
    if let Some(path) = resume::restage_requested() {
        // Exploration: the joint group's values read back, the stages after it solved again.
        sys.preset = Some(resume::slot_values(&sys, &tets, &path)?);
    }
    if !zero_points.is_empty() {
        sys.require_zero_bases(&tets, &flat::zero_triangles(hull, zero_points));
    }
    let hessian_fit = if options.hessian_signs {
        signs::fit_hessians(&tets, np, &mut jets, &|t, l| sys.required_sign(t, l))
    } else {
        signs::HessianFit::default()
    };
    sys.hessian_normal = options.hessian_normal;
    sys.column_points = column_points(options, hull, &tets)?;
    sys.held = normalpart::rows(&sys, &tets, &jets);
    let target = |t: usize, l: [u8; 4]| target_weight(&tets[t], l, &jets, np, options.lift);
    let (mut value, mut stats) = match resume::requested() {
        // Exploration: the solve's result read back from an exported complex.
        Some(path) => (
            resume::slot_values(&sys, &tets, &path)?,
            system::SolveStats::default(),
        ),
        None => sys.solve(
            &tets,
            &jets,
            nt,
            &target,
            options.signs,
            options.joint_stars,
            options.relax_stars,
            options.consistent_stars,
            options.hessian_signs,
        )?,
    };
    stats.normal_rows = sys.held.len();
    if options.sign_rounds > 0 || options.sign_program {
        stats.sign_projection =
            project::project_signs(&sys, &mut value, options.sign_rounds, options.sign_program);
    }
    if options.repair_holes {
        let reach = holes::Reach {
            rings: std::env::var("APATCH_HOLE_RINGS")
                .ok()
                .and_then(|x| x.parse().ok())
                .unwrap_or(2),
            // Exploration overrides (`APATCH_HOLE_RINGS`, `APATCH_HOLE_STARS=0`); the defaults
            // are the measured best on the torus (docs/quintic.md).
            stars: std::env::var("APATCH_HOLE_STARS").map_or(true, |v| v != "0"),
            hessians: options.repair_hessians == HessianRepair::All
                || std::env::var("APATCH_HOLE_HESSIANS").is_ok_and(|v| v != "0"),
        };
        let last = options.repair_hessians != HessianRepair::Off;
        let plan = holes::Plan {
            reach,
            widen: options.repair_widen,
            hessian_passes: last,
            pins: holes::pin_modes(options.repair_elevate, &options.repair_margins),
        };
        stats.hole_repair = holes::repair(
            &sys,
            &tets,
            &mut value,
            &plan,
            checkpoint::requested().as_deref(),
        )?;
        if std::env::var_os("APATCH_SIGN_TRACE").is_some() {
            // Opt-in exploration on stderr (results unaffected).
            eprintln!("quintic-c2 hole repair: {:?}", stats.hole_repair);
        }
    }
    stats.signs.base_conflicts = signs::base_conflicts(hull).len();
    stats.lu_completed = *lu_completed;
    stats.tangent_moved = *tangent_moved;
    stats.slivers_found = slivers.len();
    stats.slivers_thickened = slivers.iter().filter(|s| s.after > s.before).count();
    stats.hessian_fit = hessian_fit;
    let mut complex = PatchComplex::new("quintic-c2");
    complex.continuity = Some(2);
    complex.vertices = hull.points.iter().map(|p| p.to_array()).collect();
    complex.normals = hull
        .normals
        .iter()
        .map(|n| n.normalize().to_array())
        .collect();
    for (t, tet) in tets.iter().enumerate() {
        complex.patches.push(patch_of(tet, sys.weights(t, &value)));
    }
    Ok((complex, stats))
}

/// The patch of hull tetrahedron `tet` with its 56 `weights`.
fn patch_of(tet: &system::HullTet, weights: Vec<f64>) -> Patch {
    Patch {
        tet: tet.pts.map(|p| p.to_array()),
        degree: system::N as u8,
        weights,
        rational: Vec::new(),
        sheet: SheetRule::Any,
        role: tet.role,
        element: tet.element,
        // Face tetrahedra: a j-patch for the apex; edge tetrahedra: single sheeted between
        // [p_i p_j] and [q s] (the shapes the cubic scheme promises too; `apatch check`
        // samples both).
        jvertex: (tet.role == crate::complex::Role::Face).then_some(3),
        jedge: (tet.role == crate::complex::Role::Edge).then_some([0, 1]),
    }
}

/// The points of T whose whole column H n is held: those flat to
/// [`QuinticOptions::hessian_column_flat`], [`QuinticOptions::hessian_column_points`] and the
/// exploration list `APATCH_HESSIAN_COLUMN_AT`, sorted.
///
/// # Errors
/// A listed point that is not a point of T.
fn column_points(
    options: &QuinticOptions,
    hull: &SimplicialHull,
    tets: &[system::HullTet],
) -> Result<Vec<u32>> {
    let np = hull.points.len() as u32;
    if let Some(&p) = options.hessian_column_points.iter().find(|&&p| p >= np) {
        return Err(Error::Invalid(format!(
            "`scheme.hessian_column_points`: {p} is not a point of T (the hull has {np}: 0..{})",
            np.saturating_sub(1)
        )));
    }
    let mut points = normalpart::column_points_from_env(np);
    points.extend(&options.hessian_column_points);
    if let Some(degrees) = options.hessian_column_flat {
        points.extend(normalpart::flat_points(tets, &hull.normals, degrees));
    }
    points.sort_unstable();
    points.dedup();
    if !points.is_empty() && std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
        eprintln!("quintic-c2 column H n held at {} points of T", points.len());
    }
    Ok(points)
}

/// The target of the weight at multi-index `l` of `tet`: the blend of the Taylor polynomials
/// of the tetrahedron's points of T, each weighted by its multiplicity + ½, evaluated as the
/// degree-5 blossom at the weight's domain point.
fn target_weight(tet: &system::HullTet, l: [u8; 4], jets: &[jets::Jet], np: u32, lift: f64) -> f64 {
    let args = jets::domain_args(&tet.pts, l);
    let mut sum = 0.0;
    let mut wsum = 0.0;
    for k in 0..4 {
        if tet.gid[k] < np {
            let w = f64::from(l[k]) + 0.5;
            sum += w * jets[tet.gid[k] as usize].blossom5(&args);
            wsum += w;
        }
    }
    let blend = sum / wsum;
    if lift == 0.0 {
        return blend;
    }
    // Lift: the weights toward the tetrahedron's vertices off T move further to the side they
    // lie on (height above T along the mean normal, quadratic in the share of the domain
    // point off T), which keeps lines toward the apex and the midpoint from turning back.
    let hull_k: Vec<usize> = (0..4).filter(|&k| tet.gid[k] < np).collect();
    let c = hull_k.iter().map(|&k| tet.pts[k]).sum::<DVec3>() / hull_k.len() as f64;
    let n = hull_k
        .iter()
        .map(|&k| jets[tet.gid[k] as usize].g)
        .sum::<DVec3>()
        .normalize_or_zero();
    let extra: f64 = (0..4)
        .filter(|&k| tet.gid[k] >= np)
        .map(|k| (f64::from(l[k]) / 5.0).powi(2) * n.dot(tet.pts[k] - c))
        .sum();
    blend + lift * extra
}

fn validate(hull: &SimplicialHull) -> Result<()> {
    let np = hull.points.len();
    if hull.normals.len() != np || hull.apexes.len() != hull.triangles.len() {
        return Err(Error::Invalid(
            "quintic-c2: hull arrays have inconsistent lengths".into(),
        ));
    }
    for (t, tri) in hull.triangles.iter().enumerate() {
        if tri.iter().any(|&v| v as usize >= np) {
            return Err(Error::Invalid(format!(
                "quintic-c2: hull triangle {t} names a point out of range"
            )));
        }
        if hull.apexes[t].iter().all(Option::is_none) {
            return Err(Error::Invalid(format!(
                "quintic-c2: hull triangle {t} has no face tetrahedron"
            )));
        }
    }
    for (i, n) in hull.normals.iter().enumerate() {
        if n.length().is_nan() || n.length() <= 0.0 || !hull.points[i].is_finite() {
            return Err(Error::Invalid(format!(
                "quintic-c2: hull point {i} has no usable normal or position"
            )));
        }
    }
    Ok(())
}

/// Builds the `quintic-c2` patch complex of `mesh` with unit vertex normals `normals`; `scheme` is
/// the scene's `[scheme]` table (its keys are this scheme's options), `scene` the scene file
/// named in errors.
///
/// The hull is `hull::inner::build` with the inner-hull keys of the same table
/// ([`crate::hull::inner::InnerOptions::from_toml`]), as for `cubic-c1`.
///
/// # Errors
/// Unknown or bad options, and meshes the scheme cannot build, naming the file and element.
pub fn build_from_scene(
    mesh: &Mesh,
    normals: &[DVec3],
    scheme: &toml::Table,
    scene: &Path,
) -> anyhow::Result<PatchComplex> {
    let opts = QuinticOptions::from_toml(scheme, scene)?;
    let inner = crate::hull::inner::InnerOptions::from_toml(scheme, scene)?;
    let hull = crate::hull::inner::build(mesh, normals, &inner)?;
    Ok(build(&hull, &opts)?)
}
