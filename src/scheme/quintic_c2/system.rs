//! The tetrahedra of the hull, their quintic weights as shared unknowns ("slots"), the C1 and C2
//! conditions of Lemma 2.3 across every shared face as linear equations, and their solution in
//! the order of the 1994 scheme.
//!
//! A slot is one BB weight at one domain point; weights of different tetrahedra at the same
//! domain point (the same multiset of vertices of a common face) are one slot, which is C0
//! (2.7). For every face shared by tetrahedra A and B, with B's opposite vertex at barycentric
//! β in A, the C1 and C2 conditions (2.8), (2.9) read, for r = 1, 2 and every μ on the face
//! with |μ| = 5 − r,
//!   b_{r·e_B + μ} = Σ_{|γ| = r} r!/γ! · β^γ · a_{μ + γ}.
//! They are written once per face, from the face tetrahedron to its edge tetrahedron (so every
//! weight of an edge tetrahedron within distance 2 of that face is defined by the face
//! tetrahedron), from one edge tetrahedron to its partner (β = (0, 0, −1, 2): the collinear
//! case (2.10), (2.11)), and from the outer to the inner tetrahedron of an L-U pair.
//!
//! Slots are solved in stages, the order of §6 of the paper; every equation is solved at the
//! stage of its last unknown, each connected group of unknowns at once (dense, closest to the
//! target weights, see [`super::dense`]):
//! 1. jets: weights within distance 2 of a point p of T (λ_p ≥ 3) — number 0, 1, 2 weights.
//! 2. the middle of each edge [p_i p_j] of T (λ_i = λ_j = 2): number 3 weights (free, on T) and
//!    number 4 weights (their C1 partners, the 2×2 system (6.13)).
//! 3. the star of each point p of T (λ_p = 2, the other points of T at most 1): the coupled
//!    vertex systems of appendices D (number 5, 6, 7: the second derivatives across the edges
//!    at p) and E (number 9: the third-order condition at p), closed around p.
//! 4. weights far from T's points on each face tetrahedron alone or on its edges to the apex
//!    (number 8 a_1112, number 12, 13, 16: free; for an L-U pair the inner ones within
//!    distance 2 of T are C1/C2 partners of the outer ones).
//! 5. the middles of the faces [p_i p_j q] (λ_i = λ_j = 1): number 10 (one free per edge, the
//!    paper's b_3110) and 11.
//! 6. everything else in the edge tetrahedra (number 14, 15, 17 and the free ones of λ4 > 2).

use super::beta::FaceBeta;
use super::jets::Jet;
use super::signs::{self, SignStats};
use super::{cholesky, dense, sparse, supernodal};
use crate::bb::{multi_indices, Tet};
use crate::complex::Role;
use crate::error::{Error, Result};
use crate::hull::simplicial::{EdgePoint, Side, SimplicialHull};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

/// Degree of the scheme.
pub const N: usize = 5;
/// Weights per patch: C(8, 3).
pub const NW: usize = 56;
/// Largest group solved by the dense QR ([`dense`]); larger ones go to [`cholesky`].
pub const DENSE_LIMIT: usize = 1000;
/// Rounds of relaxing the stars whose weights miss Theorem 2.1's signs ([`System::solve`]).
const RELAX_ROUNDS: usize = 4;

/// One tetrahedron of the hull with its vertices as global ids.
#[derive(Clone, Debug)]
pub struct HullTet {
    /// Global vertex ids: points of T are 0..P, then apexes, then edge midpoints.
    pub gid: [u32; 4],
    /// Vertex positions.
    pub pts: [DVec3; 4],
    /// Face or edge tetrahedron.
    pub role: Role,
    /// The input element (from the hull's `element` of the triangle).
    pub element: u32,
    /// Hull triangle the tetrahedron belongs to (the one it is glued to for edge tetrahedra).
    pub triangle: u32,
    /// Side of T.
    pub side: Side,
}

/// The tetrahedra of `hull`: every face tetrahedron, then every edge tetrahedron.
///
/// # Errors
/// A non-manifold T.
pub fn tetrahedra(hull: &SimplicialHull) -> Result<(Vec<HullTet>, Vec<DVec3>)> {
    tetrahedra_with(hull, EdgePoint::Midpoint)
}

/// [`tetrahedra`] with the edge tetrahedra's shared points placed by `rule`
/// ([`SimplicialHull::edge_tets_with`]).
///
/// # Errors
/// A non-manifold T.
pub fn tetrahedra_with(
    hull: &SimplicialHull,
    rule: EdgePoint,
) -> Result<(Vec<HullTet>, Vec<DVec3>)> {
    let np = hull.points.len() as u32;
    let nt = hull.triangles.len() as u32;
    let apex = |t: u32, side: Side| np + 2 * t + side as u32;
    let edges = hull.edges().map_err(Error::Invalid)?;
    let mid = |e: u32, side: Side| np + 2 * nt + 2 * e + side as u32;
    let mut pos: Vec<DVec3> = hull.points.clone();
    pos.resize((np + 2 * nt + 2 * edges.len() as u32) as usize, DVec3::NAN);
    let mut tets = Vec::new();
    for (t, tri) in hull.triangles.iter().enumerate() {
        for side in Side::BOTH {
            if let Some(q) = hull.apexes[t][side as usize] {
                let g = apex(t as u32, side);
                pos[g as usize] = q;
                tets.push(HullTet {
                    gid: [tri[0], tri[1], tri[2], g],
                    pts: [
                        hull.points[tri[0] as usize],
                        hull.points[tri[1] as usize],
                        hull.points[tri[2] as usize],
                        q,
                    ],
                    role: Role::Face,
                    element: hull.element.get(t).copied().unwrap_or(t as u32),
                    triangle: t as u32,
                    side,
                });
            }
        }
    }
    for et in hull.edge_tets_with(rule).map_err(Error::Invalid)? {
        let e = &edges[et.edge as usize];
        let s = mid(et.edge, et.side);
        pos[s as usize] = et.tet[3];
        tets.push(HullTet {
            gid: [e.v[0], e.v[1], apex(et.face, et.side), s],
            pts: et.tet,
            role: Role::Edge,
            element: hull
                .element
                .get(et.face as usize)
                .copied()
                .unwrap_or(et.face),
            triangle: et.face,
            side: et.side,
        });
    }
    Ok((tets, pos))
}

/// Key of a domain point: its vertices (global ids) with multiplicities, sorted, packed.
fn key(gid: &[u32; 4], lambda: [u8; 4]) -> u128 {
    let mut e: [(u32, u8); 4] = [(u32::MAX, 0); 4];
    for k in 0..4 {
        if lambda[k] > 0 {
            e[k] = (gid[k], lambda[k]);
        }
    }
    e.sort_unstable();
    let mut out: u128 = 0;
    for (g, m) in e {
        if m > 0 {
            out = (out << 32) | (u128::from(g) << 3) | u128::from(m);
        }
    }
    out
}

/// Unpacks a key into (global id, multiplicity) pairs.
pub(super) fn unkey(mut k: u128) -> Vec<(u32, u8)> {
    let mut v = Vec::new();
    while k != 0 {
        let e = (k & 0xffff_ffff) as u32;
        v.push((e >> 3, (e & 7) as u8));
        k >>= 32;
    }
    v
}

/// A face of the hull (sorted global ids) with its tetrahedra and their opposite vertices.
type FaceUsers = ([u32; 3], Vec<(u32, usize)>);

/// A linear equation Σ c·x_slot = 0.
pub(super) struct Equation {
    pub(super) terms: Vec<(u32, f64)>,
}

/// The whole linear system of the scheme.
pub struct System {
    /// Slot of every weight of every tetrahedron.
    pub slot_of: Vec<[u32; NW]>,
    /// Domain-point key of every slot.
    pub(super) keys: Vec<u128>,
    /// One tetrahedron and multi-index per slot (for targets).
    home: Vec<(u32, [u8; 4])>,
    /// Domain point of every slot (where [`super::localmeet`] finds a row's neighbours).
    pos: Vec<DVec3>,
    pub(super) equations: Vec<Equation>,
    /// Number of points of T (global ids below are points of T).
    pub(super) np: u32,
    /// Sign Theorem 2.1 asks of every slot ([`signs::required`] combined over its tetrahedra).
    pub(super) req: Vec<i8>,
    /// Slots on a boundary face of the hull (a face of one tetrahedron only).
    pub(super) boundary: Vec<bool>,
    /// Near-null threshold of the star systems (`QuinticOptions::star_tau`, 0 = off): the
    /// left singular vectors u of a star whose σ ≤ this × σ_max give conditions uᵀc = 0 on
    /// the weights solved before it, so the star does not amplify their noise by 1/σ.
    pub star_tau: f64,
    /// Margin, in medians of their |target|, by which the targets of a group's signed weights
    /// are moved into their sign before it is solved (`QuinticOptions::sign_targets`, 0 = off).
    pub sign_targets: f64,
    /// Rounds of alternating projections between Theorem 2.1's signs and the equations of each
    /// group too large to pin, with its one factor (`QuinticOptions::joint_sign_rounds`, 0 =
    /// off).
    pub joint_sign_rounds: usize,
    /// Rounds of the split sign program in each group too large to pin, after its dropped
    /// rows are met (`QuinticOptions::joint_sign_fit`, 0 = off).
    pub joint_sign_fit: usize,
    /// Cost of a boundary slot's sign miss in the split sign program, in units of an inner
    /// one's (`QuinticOptions::joint_sign_boundary`, 1 = all alike).
    pub joint_sign_boundary: f64,
    /// The miss, relative to a group's scale, to which the meet after its split sign program
    /// meets the dropped rows (`QuinticOptions::joint_meet_tolerance`; 0 = the solve's).
    pub joint_meet_tolerance: f64,
    /// The joint group's meet before the sign fit stops after this many rounds in a row that
    /// did not lower its residual (`QuinticOptions::joint_meet_stall`; `None`: every round).
    pub joint_meet_stall: Option<usize>,
    /// Whether the rows a group's sign fit leaves missed are met region by region
    /// (`QuinticOptions::joint_local_meet`, [`super::localmeet`]) instead of by its factor.
    pub joint_local_meet: bool,
    /// Rows holding the normal part of the relaxed points' Hessians
    /// (`QuinticOptions::hessian_normal`, [`super::normalpart`]): solved with the scheme's
    /// equations, in the group of their last unknowns.
    pub(super) held: Vec<Equation>,
    /// What a relaxed Hessian weight's change costs in a group's least change, the others'
    /// being 1 (`QuinticOptions::hessian_cost`).
    pub hessian_cost: f64,
    /// What [`Self::held`] holds, so that the hole repair's freed Hessians keep it too.
    pub hessian_normal: super::normalpart::HessianNormal,
    /// Points of T (sorted) whose whole normal column H n is held whatever
    /// [`Self::hessian_normal`] says: the flat points of `QuinticOptions::hessian_column_flat`,
    /// those of `hessian_column_points` and of the exploration `APATCH_HESSIAN_COLUMN_AT`.
    pub column_points: Vec<u32>,
    /// The double-double factor's one drop threshold for groups beyond the in-house factor
    /// (`QuinticOptions::precise_pivot`; `None`: [`super::cholesky::PRECISE_PIVOT`], then
    /// [`super::supernodal::PRECISE_RETRY_PIVOT`]).
    pub precise_pivot: Option<f64>,
    /// Exploration (`APATCH_QUINTIC_RESTAGE=patches.json`, [`super::resume`]): every slot's
    /// value in a complex exported from this scene; groups too large to pin take their values
    /// from it instead of being solved, so the stages after fandisk's joint group (~80 min)
    /// can be tried again in minutes.
    pub preset: Option<Vec<f64>>,
}

/// Builds the slots and the C1/C2 equations of every shared face, with the f64 β
/// ([`FaceBeta::F64`], unless `APATCH_FACE_BETA` names another).
///
/// # Errors
/// A face shared by more than two tetrahedra, or a degenerate tetrahedron.
pub fn assemble(tets: &[HullTet], np: u32) -> Result<System> {
    assemble_with(tets, np, FaceBeta::default().or_env())
}

/// [`assemble`] with the rows' β of the shared faces computed as `face_beta` asks
/// (`[scheme] face_beta`).
///
/// # Errors
/// As [`assemble`].
pub fn assemble_with(tets: &[HullTet], np: u32, face_beta: FaceBeta) -> Result<System> {
    let mi = multi_indices(N);
    let mut map: HashMap<u128, u32> = HashMap::new();
    let mut keys = Vec::new();
    let mut home = Vec::new();
    let mut slot_of = Vec::with_capacity(tets.len());
    for (t, tet) in tets.iter().enumerate() {
        let mut s = [0u32; NW];
        for (i, &l) in mi.iter().enumerate() {
            let k = key(&tet.gid, l);
            s[i] = *map.entry(k).or_insert_with(|| {
                keys.push(k);
                home.push((t as u32, l));
                (keys.len() - 1) as u32
            });
        }
        slot_of.push(s);
    }
    // Theorem 2.1's signs per slot; a triangle with face tetrahedra on both sides is an L-U
    // pair, whose shared base carries none.
    let mut sides: HashMap<u32, u8> = HashMap::new();
    for tet in tets.iter().filter(|t| t.role == Role::Face) {
        *sides.entry(tet.triangle).or_insert(0) += 1;
    }
    let mut req = vec![0i8; keys.len()];
    for (t, tet) in tets.iter().enumerate() {
        let double = tet.role == Role::Face && sides.get(&tet.triangle).copied() == Some(2);
        for (i, &l) in mi.iter().enumerate() {
            let s = slot_of[t][i] as usize;
            req[s] = signs::combine(req[s], signs::required(tet, l, double));
        }
    }
    // Faces → (tetrahedron, local opposite vertex).
    let mut faces: HashMap<[u32; 3], Vec<(u32, usize)>> = HashMap::new();
    for (t, tet) in tets.iter().enumerate() {
        for opp in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&k| k != opp).map(|k| tet.gid[k]).collect();
            f.sort_unstable();
            faces
                .entry([f[0], f[1], f[2]])
                .or_default()
                .push((t as u32, opp));
        }
    }
    let mut face_list: Vec<FaceUsers> = faces.into_iter().collect();
    face_list.sort_unstable_by_key(|(f, _)| *f);
    let mut equations = Vec::new();
    let mut stable_swaps = 0usize;
    let mut boundary = vec![false; keys.len()];
    for (f, users) in face_list {
        match users.len() {
            1 => {
                // A boundary face of the hull: the surface must not cross it (a hole).
                let (t, opp) = users[0];
                for (i, l) in mi.iter().enumerate() {
                    if l[opp] == 0 {
                        boundary[slot_of[t as usize][i] as usize] = true;
                    }
                }
                continue;
            }
            2 => {}
            _ => {
                return Err(Error::Invalid(format!(
                    "quintic-c2: the face with vertices {f:?} is shared by {} tetrahedra",
                    users.len()
                )))
            }
        }
        // A defines B: face → edge, outer → inner, else the first.
        let (mut a, mut b) = (users[0], users[1]);
        let (ta, tb) = (&tets[a.0 as usize], &tets[b.0 as usize]);
        let swap = (ta.role == Role::Edge && tb.role == Role::Face)
            || (ta.role == tb.role && ta.role == Role::Face && ta.side == Side::Inner);
        if swap {
            std::mem::swap(&mut a, &mut b);
        }
        // Stable direction: a sliver A (apex nearly in its base's plane; the nut's hull has
        // L-U pairs 5e-8 of their size high) puts B's opposite vertex at barycentrics ~1e5 in
        // A, so the C2 rows carry β² ~ 1e10 and the group's normal matrix is singular to
        // rounding. The conditions of a face are symmetric (C1 and C2 either way span the same
        // equations), so such a face is written from B, whose barycentrics of A's vertex are
        // O(1) when B is thick.
        let g = spread(tets, a, b);
        if g > STABLE_SPREAD && spread(tets, b, a) < g {
            std::mem::swap(&mut a, &mut b);
            stable_swaps += 1;
        }
        face_equations(tets, &slot_of, a, b, &mi, face_beta, &mut equations)?;
    }
    if stable_swaps > 0 && std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
        // Opt-in report on stderr (exploration; results unaffected).
        eprintln!("quintic-c2: {stable_swaps} faces written from the thicker tetrahedron");
    }
    let pos = home
        .iter()
        .map(|&(t, l)| {
            let p = &tets[t as usize].pts;
            (0..4).map(|v| p[v] * f64::from(l[v])).sum::<DVec3>() / N as f64
        })
        .collect();
    Ok(System {
        slot_of,
        keys,
        home,
        pos,
        equations,
        np,
        req,
        boundary,
        star_tau: 0.0,
        sign_targets: 0.0,
        joint_sign_rounds: 0,
        joint_sign_fit: 0,
        joint_sign_boundary: 1.0,
        joint_meet_tolerance: 0.0,
        joint_meet_stall: None,
        joint_local_meet: false,
        precise_pivot: None,
        preset: None,
        held: Vec::new(),
        hessian_normal: super::normalpart::HessianNormal::Free,
        column_points: Vec::new(),
        hessian_cost: 1.0,
    })
}

/// Unknowns free in one region of the local meet ([`super::localmeet`]): on fandisk
/// (session 64) ~2000 around a missed row met it to ~1e-14, with a dense factor of ~2300 rows.
/// `APATCH_LOCAL_MEET_SIZE` overrides it (exploration).
pub const LOCAL_MEET_SIZE: usize = 2000;

/// Longest move of one region of the local meet, relative to the group's scale: the fit
/// leaves its signed weights ~1e-5 inside their signs, and fandisk's regions move by at most
/// ~3e-7, so a region asking more is not meeting rounding-level misses and is refused.
pub const LOCAL_MEET_MOVE: f64 = 1e-4;

/// Largest |barycentric| of B's opposite vertex in A above which a face's C1/C2 equations are
/// written from the other side when that side's is smaller ([`assemble`]). Adjacent thick
/// tetrahedra give O(1)–O(10) (2 for the collinear edge-tetrahedron pairs); the shipped
/// quintic scenes stay below it, so their equations are unchanged.
pub const STABLE_SPREAD: f64 = 1e3;

/// Largest |barycentric| of `b`'s opposite vertex in `a`'s tetrahedron (∞ when `a` is
/// degenerate).
fn spread(tets: &[HullTet], a: (u32, usize), b: (u32, usize)) -> f64 {
    Tet::new(tets[a.0 as usize].pts).map_or(f64::INFINITY, |t| {
        t.bary(tets[b.0 as usize].pts[b.1])
            .iter()
            .fold(0.0_f64, |m, x| m.max(x.abs()))
    })
}

/// The C1 and C2 equations across the face shared by `a` and `b` (tetrahedron, opposite local
/// vertex), B's weights defined from A's.
fn face_equations(
    tets: &[HullTet],
    slot_of: &[[u32; NW]],
    a: (u32, usize),
    b: (u32, usize),
    mi: &[[u8; 4]],
    face_beta: FaceBeta,
    out: &mut Vec<Equation>,
) -> Result<()> {
    let (ta, tb) = (&tets[a.0 as usize], &tets[b.0 as usize]);
    let tet = Tet::new(ta.pts).ok_or_else(|| {
        Error::Invalid(format!(
            "quintic-c2: degenerate tetrahedron {:?} (hull triangle {})",
            ta.pts, ta.triangle
        ))
    })?;
    let beta = super::beta::of_face(&tet, tb.pts[b.1], face_beta);
    // Local index in B of each of A's vertices (A's opposite vertex has none).
    let mut to_b = [usize::MAX; 4];
    for (ka, slot) in to_b.iter_mut().enumerate() {
        if ka != a.1 {
            *slot = (0..4)
                .find(|&kb| tb.gid[kb] == ta.gid[ka])
                .expect("shared face");
        }
    }
    let index = |l: [u8; 4]| crate::bb::index_of(l);
    for r in 1..=2u8 {
        let gammas = multi_indices(usize::from(r));
        for mu in mi.iter().filter(|l| l[a.1] == r) {
            // mu here runs over A-indices with r at A's opposite vertex: strip it to get the face
            // part, then form B's index with r at B's opposite vertex.
            let mut face = *mu;
            face[a.1] = 0;
            let mut lb = [0u8; 4];
            for ka in 0..4 {
                if ka != a.1 {
                    lb[to_b[ka]] = face[ka];
                }
            }
            lb[b.1] = r;
            let mut terms: Vec<(u32, f64)> = vec![(slot_of[b.0 as usize][index(lb)], 1.0)];
            for g in &gammas {
                let coef = super::beta::coefficient(&beta, *g, face_beta);
                if coef == 0.0 {
                    continue;
                }
                let mut la = face;
                for k in 0..4 {
                    la[k] += g[k];
                }
                terms.push((slot_of[a.0 as usize][index(la)], -coef));
            }
            let mut merged = super::sparse::merged(terms);
            merged.retain(|t| t.1 != 0.0);
            if !merged.is_empty() {
                out.push(Equation { terms: merged });
            }
        }
    }
    Ok(())
}

/// Stage of a slot (0 = known from the jets), see the module documentation, and the point or
/// points of T it is attached to (for messages).
pub(super) fn stage(key: u128, np: u32) -> (u8, Vec<u32>) {
    let parts = unkey(key);
    let hull: Vec<(u32, u8)> = parts.iter().copied().filter(|p| p.0 < np).collect();
    let pts: Vec<u32> = hull.iter().map(|p| p.0).collect();
    if hull.iter().any(|p| p.1 >= 3) {
        return (0, pts);
    }
    let twos = hull.iter().filter(|p| p.1 == 2).count();
    if twos == 2 {
        return (1, pts);
    }
    if twos == 1 {
        let v = hull
            .iter()
            .find(|p| p.1 == 2)
            .map(|p| p.0)
            .into_iter()
            .collect();
        return (2, v);
    }
    let ones = hull.len();
    // Apexes have ids below the edge midpoints; "mid" = any non-apex, non-T vertex is detected by
    // the caller's id ranges, see `is_mid`.
    (if ones == 2 { 4 } else { 5 }, pts)
}

/// What the solve measured.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SolveStats {
    /// Unknown slots (after C0 sharing), jets excluded.
    pub unknowns: usize,
    /// Equations.
    pub equations: usize,
    /// Largest connected group solved at once.
    pub largest_group: usize,
    /// Largest |residual| of any equation after all stages, relative to the largest weight.
    pub max_residual: f64,
    /// Points of T whose star needed its edge middles or Hessian relaxed (not in general
    /// position).
    pub relaxed_points: usize,
    /// Whether the staged solve failed and every weight was solved at once (one group per
    /// connected component of the equations), see [`System::solve`].
    pub global: bool,
    /// Groups above [`DENSE_LIMIT`] unknowns, solved by [`cholesky`] (sparse direct).
    pub sparse_groups: usize,
    /// How the weights meet Theorem 2.1's sign conditions ([`signs`]).
    pub signs: SignStats,
    /// Triangles of T given the partner apex of an L-U pair before building
    /// (`QuinticOptions::complete_lu_pairs`).
    pub lu_completed: usize,
    /// Apexes moved to their side of their triangle's tangent planes before building
    /// (`QuinticOptions::contain_tangents`).
    pub tangent_moved: usize,
    /// Sides of edges of T whose edge tetrahedra were slivers
    /// (`QuinticOptions::thicken_edges`, [`super::slivers`]).
    pub slivers_found: usize,
    /// Of those, the ones whose apexes were moved apart to the bound.
    pub slivers_thickened: usize,
    /// Points of T whose stars were relaxed (solved with their edge middles and Hessian)
    /// because their determined weights missed Theorem 2.1's signs
    /// (`QuinticOptions::relax_stars`).
    pub relaxed_for_signs: usize,
    /// Consistency conditions of singular stars imposed on the edge middles
    /// (`QuinticOptions::consistent_stars`).
    pub consistency_conditions: usize,
    /// What [`signs::fit_hessians`] changed (`QuinticOptions::hessian_signs`).
    pub hessian_fit: signs::HessianFit,
    /// What [`super::holes::repair`] changed (`QuinticOptions::repair_holes`).
    pub hole_repair: super::holes::HoleRepair,
    /// What [`super::project::project_signs`] did (`QuinticOptions::sign_rounds`).
    pub sign_projection: super::project::SignProjection,
    /// Rows holding the normal part of the points' Hessians
    /// (`QuinticOptions::hessian_normal`).
    pub normal_rows: usize,
}

/// One point's vertex-star system ([`System::star_systems`]).
#[derive(Clone, Debug)]
pub struct StarSystem {
    /// The point of T at the star's centre.
    pub point: u32,
    /// Equations.
    pub rows: usize,
    /// Unknown weights.
    pub cols: usize,
    /// The coefficients of the unknowns, row-major `rows` × `cols`.
    pub matrix: Vec<f64>,
    /// Per unknown, one tetrahedron holding it and its multi-index there.
    pub unknowns: Vec<(u32, [u8; 4])>,
}

/// The pseudo-stage of [`Failure`]s that carry a solved star's near-null conditions
/// (`System::star_tau`), not a failure.
const NEAR_NULL: u8 = 7;

/// The largest residual of the scheme's C1/C2 equations, each relative to its own terms
/// (`System::scheme_residual`), with which a pass whose near-null conditions could not all be
/// met is kept: the 1e-9 a consistent group is held to ([`consistent`]). (On the nut with
/// curvature 0.4 a pass at 2.6e-8 gave Hessian jumps of 2.3e-7; the kept passes measure
/// 7.3e-10 and 9.8e-10 and give 8e-9.)
pub(super) const NEAR_NULL_RESIDUAL: f64 = 1e-9;

/// The condition Σ_i y_i·(known part of equation `eqs[i]`) = 0 over the weights outside the
/// group (`col`): what the known weights must meet so that the group's right-hand side has no
/// component along y. `None` when it cancels to nothing.
fn known_condition(
    all: &[&Equation],
    eqs: &[usize],
    col: &HashMap<u32, usize>,
    y: &[f64],
) -> Option<Equation> {
    let mut terms: Vec<(u32, f64)> = Vec::new();
    for (i, &e) in eqs.iter().enumerate() {
        if y[i] == 0.0 {
            continue;
        }
        for &(s, k) in &all[e].terms {
            if !col.contains_key(&s) {
                terms.push((s, y[i] * k));
            }
        }
    }
    terms.sort_unstable_by_key(|t| t.0);
    let mut merged: Vec<(u32, f64)> = Vec::new();
    for (s, k) in terms {
        match merged.last_mut() {
            Some(last) if last.0 == s => last.1 += k,
            _ => merged.push((s, k)),
        }
    }
    let big = merged.iter().fold(0.0_f64, |a, t| a.max(t.1.abs()));
    // Cancellation of the dependency's rounding.
    merged.retain(|t| t.1.abs() > 1e-12 * big);
    (!merged.is_empty()).then_some(Equation { terms: merged })
}

/// A group whose equations could not be met in one pass.
struct Failure {
    stage: u8,
    points: Vec<u32>,
    message: String,
    /// For a singular group: the conditions its known weights must meet for it to be
    /// consistent (one per dependent equation, Σ coefficient · known slot = 0).
    consistency: Vec<Equation>,
}

/// One connected group of a stage's unknowns, set up for its solve ([`System::solve_group`]).
struct Group {
    /// The group's own equations (its first `m` rows; sign pins are appended after them).
    m: usize,
    /// Unknown slots, in column order.
    unk: Vec<u32>,
    /// Its equations (indices into the pass's equations), in row order.
    eqs: Vec<usize>,
    /// Column of each unknown slot.
    col: HashMap<u32, usize>,
    /// Coefficients of the unknowns per equation.
    rows: Vec<sparse::Row>,
    /// Right-hand sides: minus the known weights' terms.
    c: Vec<f64>,
    /// Target of each unknown.
    tgt: Vec<f64>,
    /// Largest |datum| (right-hand side or target).
    scale: f64,
    /// `scale`, or the largest sum of |known terms| of one row if larger: what a residual is
    /// measured against ([`consistent`]). A right-hand side that is the small difference of
    /// large known weights (a star on a flat part of the model: data 2e-3 from weights of
    /// 0.1) is only as accurate as those weights, which their own groups met to 1e-9 of
    /// *their* scale; against `scale` alone fandisk's flat stars missed by 2e-12 of 2e-12.
    reach: f64,
    /// Whether it is solved in the parallel phase of its stage: its sign conditions read no
    /// other group of the stage, and it is dense.
    parallel: bool,
}

/// A group's solution with the sign pins it made and gave up ([`pin_signs`]).
type GroupSolution = (dense::Solution, usize, usize);

impl System {
    /// What is held of point `p`'s Hessian: the whole column at [`Self::column_points`], the
    /// scene's [`Self::hessian_normal`] elsewhere.
    #[must_use]
    pub fn hessian_normal_at(&self, p: u32) -> super::normalpart::HessianNormal {
        if self.column_points.binary_search(&p).is_ok() {
            super::normalpart::HessianNormal::Column
        } else {
            self.hessian_normal
        }
    }

    /// Solves every slot: jets, then the stages, each group closest to its target
    /// (`target(slot's tetrahedron, multi-index)`).
    ///
    /// Where a vertex star's system is singular and inconsistent (T not in general position
    /// around that point, e.g. coplanar triangles), the solve is repeated with the number 3/4
    /// weights of the edges at that point solved together with the star, and if that is not
    /// enough, with the point's Hessian (number 2 weights) chosen by the system too (closest to
    /// the estimated one). If a group still cannot be met, or a later stage (face middles, edge
    /// tetrahedra) is inconsistent with the free weights fixed before it, every unknown is solved
    /// at once instead, closest to its target ([`SolveStats::global`]).
    ///
    /// With `pin`, Theorem 2.1's signs are enforced where the groups allow ([`pin_signs`]);
    /// with `joint_stars`, every point starts relaxed at level 2; with `consistent_faces`, a
    /// singular face-middle or edge-tetrahedron group that the weights before it make
    /// inconsistent imposes its consistency conditions on them before the global fallback; with `relax_stars`, points
    /// whose star weights miss Theorem 2.1's signs are relaxed the same way and the whole
    /// solve repeated, while the number of misses falls (at most `RELAX_ROUNDS` rounds); with
    /// `System::star_tau` > 0, the stars' near-null conditions are imposed after the first pass
    /// without failures and kept while the scheme's own equations hold.
    ///
    /// # Errors
    /// A group whose equations cannot be met even so, naming where.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        tets: &[HullTet],
        jets: &[Jet],
        nt: u32,
        target: &dyn Fn(usize, [u8; 4]) -> f64,
        pin: bool,
        joint_stars: bool,
        relax_stars: bool,
        consistent_stars: bool,
        consistent_faces: bool,
    ) -> Result<(Vec<f64>, SolveStats)> {
        let mut level: HashMap<u32, u8> = HashMap::new();
        if joint_stars {
            // Every star with its edge middles and its point's Hessian, closest to the
            // targets and the estimates: the stars' square systems get free dimensions.
            // Exploration (`APATCH_JOINT_LEVEL=1`): the stars joined with their edge middles
            // only, every Hessian kept at its estimate until a failing group relaxes it.
            let joint_level = std::env::var("APATCH_JOINT_LEVEL")
                .ok()
                .and_then(|v| v.parse::<u8>().ok())
                .filter(|&l| (1..=2).contains(&l))
                .unwrap_or(2);
            for p in 0..self.np {
                level.insert(p, joint_level);
            }
        }
        let (mut value, mut stats) = self.solve_levels(
            tets,
            jets,
            nt,
            target,
            &mut level,
            pin,
            (consistent_stars, consistent_faces),
        )?;
        if std::env::var_os("APATCH_HELD_TRACE").is_some() {
            // Opt-in exploration on stderr (results unaffected): how closely the scheme's rows
            // and the held normal rows (`hessian_normal`) are met.
            eprintln!(
                "quintic-c2 held: scheme residual {:.2e}, held rows {:.2e}",
                self.scheme_residual(&value),
                self.held_residual(&value)
            );
        }
        if !relax_stars {
            return Ok((value, stats));
        }
        // Theorem 2.1 misses of determined star weights: relax those stars (solve them with
        // their edge middles and Hessians, closest to the targets), keep the result while the
        // misses fall.
        let at2 = |l: &HashMap<u32, u8>| l.values().filter(|l| **l >= 2).count();
        let before = at2(&level);
        let mut misses = self.star_misses(&value);
        for _round in 0..RELAX_ROUNDS {
            let miss = std::mem::take(&mut misses);
            let mut trial = level.clone();
            let mut grew = false;
            for p in miss {
                let l = trial.entry(p).or_insert(0);
                if *l < 2 {
                    *l = 2;
                    grew = true;
                }
            }
            if !grew {
                break;
            }
            let Ok((v, s)) = self.solve_levels(
                tets,
                jets,
                nt,
                target,
                &mut trial,
                pin,
                (consistent_stars, consistent_faces),
            ) else {
                break;
            };
            let trial_misses = self.star_misses(&v);
            if self.boundary_misses(&v) >= self.boundary_misses(&value) {
                break;
            }
            (value, stats, level, misses) = (v, s, trial, trial_misses);
        }
        stats.relaxed_for_signs = at2(&level) - before;
        Ok((value, stats))
    }

    /// The homogeneous matrix of every point's vertex-star system (appendices D and E: the
    /// slots with the point at multiplicity 2 and the other points of T at most 1, and the
    /// C1/C2 equations whose last unknowns they are, as the staged solve groups them when no
    /// star is relaxed), one per point of T with a star, in point order. A diagnostic: the
    /// paper's systems are square and nonsingular for points in general position.
    #[must_use]
    pub fn star_systems(&self) -> Vec<StarSystem> {
        let np = self.np;
        let stage_of: Vec<u8> = self.keys.iter().map(|&k| stage(k, np).0).collect();
        let centre = |s: usize| {
            unkey(self.keys[s])
                .into_iter()
                .find(|p| p.0 < np && p.1 == 2)
                .map(|p| p.0)
        };
        let mut cols: HashMap<u32, Vec<u32>> = HashMap::new();
        for (s, &st) in stage_of.iter().enumerate() {
            if st == 2 {
                if let Some(p) = centre(s) {
                    cols.entry(p).or_default().push(s as u32);
                }
            }
        }
        let mut rows: HashMap<u32, Vec<usize>> = HashMap::new();
        for (e, eq) in self.equations.iter().enumerate() {
            if eq.terms.iter().any(|t| stage_of[t.0 as usize] > 2) {
                continue;
            }
            if let Some(t) = eq.terms.iter().find(|t| stage_of[t.0 as usize] == 2) {
                if let Some(p) = centre(t.0 as usize) {
                    rows.entry(p).or_default().push(e);
                }
            }
        }
        let mut points: Vec<u32> = cols.keys().copied().collect();
        points.sort_unstable();
        points
            .into_iter()
            .map(|p| {
                let unk = &cols[&p];
                let col: HashMap<u32, usize> =
                    unk.iter().enumerate().map(|(i, s)| (*s, i)).collect();
                let eqs = rows.get(&p).cloned().unwrap_or_default();
                let (m, n) = (eqs.len(), unk.len());
                let mut a = vec![0.0; m * n];
                for (i, &e) in eqs.iter().enumerate() {
                    for &(s, k) in &self.equations[e].terms {
                        if let Some(&j) = col.get(&s) {
                            a[i * n + j] += k;
                        }
                    }
                }
                StarSystem {
                    point: p,
                    rows: m,
                    cols: n,
                    matrix: a,
                    unknowns: unk.iter().map(|&s| self.home[s as usize]).collect(),
                }
            })
            .collect()
    }

    /// The largest residual of the scheme's own C1/C2 equations (not the added conditions)
    /// in `value`, each relative to the size of its own terms (Σ|c·x|; weights below 1e-12 of
    /// the largest count as that): the checker measures jumps relative to the local size of F,
    /// so a residual small against the largest weight can still be a jump where F is small.
    fn scheme_residual(&self, value: &[f64]) -> f64 {
        let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
        (0..self.equations.len())
            .map(|e| self.relative_residual(e, value, wmax))
            .fold(0.0, f64::max)
    }

    /// The largest residual of the held normal rows ([`Self::held`]) in `value`, each relative
    /// to the size of its terms.
    fn held_residual(&self, value: &[f64]) -> f64 {
        self.held
            .iter()
            .map(|eq| {
                let (r, size) = eq.terms.iter().fold((0.0_f64, 0.0_f64), |(r, z), (s, c)| {
                    let t = c * value[*s as usize];
                    (r + t, z + t.abs())
                });
                r.abs() / size.max(1e-300)
            })
            .fold(0.0, f64::max)
    }

    /// Equation `e`'s residual in `value` relative to the size of its terms, as
    /// [`Self::scheme_residual`] measures it (`wmax`: the largest |weight|).
    pub(super) fn relative_residual(&self, e: usize, value: &[f64], wmax: f64) -> f64 {
        self.relative_residual_moved(e, value, value, wmax)
    }

    /// [`Self::relative_residual`] in `value` with each term's size the larger of its sizes in
    /// `value` and in `before`: for a move that takes terms to (near) zero, whose equation is
    /// then met to the rounding of the move rather than of the new, tiny terms (the hole
    /// repair's elevated pins). With `before` = `value` it is `relative_residual`, bit for bit.
    pub(super) fn relative_residual_moved(
        &self,
        e: usize,
        value: &[f64],
        before: &[f64],
        wmax: f64,
    ) -> f64 {
        let (r, size) = self.equations[e]
            .terms
            .iter()
            .fold((0.0, 0.0), |(r, size), (s, c)| {
                let (x, x0) = (value[*s as usize], before[*s as usize]);
                (
                    r + c * x,
                    size + c.abs() * x.abs().max(x0.abs()).max(1e-12 * wmax),
                )
            });
        r.abs() / size
    }

    /// Whether slot `s` misses Theorem 2.1's sign in `value` (`tiny`: zero up to rounding).
    fn misses(&self, value: &[f64], s: usize, tiny: f64) -> bool {
        let r = self.req[s];
        (r == 1 || r == -1) && f64::from(r) * value[s] < -tiny
    }

    /// Weights on boundary faces of the hull that miss Theorem 2.1's sign in `value`: where
    /// the surface may cross the boundary (a hole).
    fn boundary_misses(&self, value: &[f64]) -> usize {
        let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
        // As in `sign_stats`: weights this small are zero up to the solves' rounding.
        let tiny = 1e-12 * wmax;
        (0..value.len())
            .filter(|&s| self.boundary[s] && self.misses(value, s, tiny))
            .count()
    }

    /// Points of T whose star (or edge middle) weights on boundary faces of the hull miss
    /// Theorem 2.1's sign in `value`: the points at multiplicity 2 of every such slot that no
    /// point has at multiplicity ≥ 3 (those are jets).
    fn star_misses(&self, value: &[f64]) -> Vec<u32> {
        let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
        // As in `sign_stats`: weights this small are zero up to the solves' rounding.
        let tiny = 1e-12 * wmax;
        let mut out = Vec::new();
        for s in 0..value.len() {
            if !self.boundary[s] || !self.misses(value, s, tiny) {
                continue;
            }
            let parts = unkey(self.keys[s]);
            let hull: Vec<(u32, u8)> = parts.into_iter().filter(|p| p.0 < self.np).collect();
            if hull.iter().any(|p| p.1 >= 3) {
                continue;
            }
            out.extend(hull.iter().filter(|p| p.1 == 2).map(|p| p.0));
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The staged solve with the relaxed points `level` (raised where a group fails), falling
    /// back to solving every unknown at once; see [`System::solve`].
    #[allow(clippy::too_many_arguments)]
    fn solve_levels(
        &self,
        tets: &[HullTet],
        jets: &[Jet],
        nt: u32,
        target: &dyn Fn(usize, [u8; 4]) -> f64,
        level: &mut HashMap<u32, u8>,
        pin: bool,
        (consistent, consistent_faces): (bool, bool),
    ) -> Result<(Vec<f64>, SolveStats)> {
        let mut first_failure = None;
        let mut extra: Vec<Equation> = Vec::new();
        let mut conditioned: std::collections::HashSet<Vec<u32>> = Default::default();
        // Near-null conditions of nearly singular stars (`star_tau`): imposed only after a
        // pass without failures, and dropped for good if the pass after them fails (they can
        // make the edge-middle group inconsistent).
        // Where in `extra` the near-null conditions begin, once imposed.
        let mut near_start: Option<usize> = None;
        let mut near_off = self.star_tau <= 0.0;
        // The stars' singular vectors are only needed from a pass without failures (earlier
        // ones change the stars' data): the first pass after one computes them.
        let mut prev_failed = true;
        let mut near_asked = false;
        // Two more passes with near-null conditions: one to find them, one to impose them.
        let passes = if near_off { 6 } else { 8 };
        for pass in 0..passes {
            crate::progress::report(|| {
                format!(
                    "quintic-c2 solve: pass {} ({} conditions, {} points relaxed)",
                    pass + 1,
                    extra.len(),
                    level.len()
                )
            });
            let imposed = near_start.is_some();
            let want_near = !near_off && !imposed && !prev_failed;
            near_asked |= want_near;
            let (value, mut stats, mut failures) =
                self.solve_pass(tets, jets, nt, target, level, false, pin, &extra, want_near);
            if std::env::var_os("APATCH_SIGN_TRACE").is_some() {
                // Opt-in exploration on stderr (results unaffected).
                let near = failures.iter().filter(|f| f.stage == NEAR_NULL).count();
                let mut other = [0usize; 8];
                for f in failures.iter().filter(|f| f.stage != NEAR_NULL) {
                    other[usize::from(f.stage)] += 1;
                }
                for f in failures.iter().filter(|f| f.stage != NEAR_NULL).take(20) {
                    eprintln!("quintic-c2 failure (pass stage {}): {}", f.stage, f.message);
                }
                eprintln!(
                    "quintic-c2 pass: {} + {} near-null conditions imposed; nearly singular stars {near}, failures by stage {other:?}",
                    near_start.unwrap_or(extra.len()),
                    extra.len() - near_start.unwrap_or(extra.len())
                );
            }
            let failed = failures.iter().any(|f| f.stage != NEAR_NULL);
            if let (true, Some(start)) = (failed, near_start) {
                // The near-null conditions are wishes, the scheme's equations are not: a pass
                // whose only failures are groups that could not meet every wish is kept when
                // every C1/C2 equation still holds as closely as a consistent group must.
                let residual = self.scheme_residual(&value);
                if std::env::var_os("APATCH_SIGN_TRACE").is_some() {
                    eprintln!("quintic-c2 near-null pass: scheme residual {residual:.3e}");
                }
                if residual <= NEAR_NULL_RESIDUAL {
                    stats.relaxed_points = level.len();
                    stats.consistency_conditions = extra.len();
                    stats.max_residual = residual;
                    return Ok((value, stats));
                }
                extra.truncate(start);
                near_start = None;
                near_off = true;
                continue;
            }
            prev_failed = failed;
            if near_off || failed || imposed {
                failures.retain(|f| f.stage != NEAR_NULL);
            }
            if failures.is_empty() && !near_off && !near_asked {
                // A solution, but the stars' singular vectors were not looked at yet.
                continue;
            }
            if failures.is_empty() {
                stats.relaxed_points = level.len();
                stats.consistency_conditions = extra.len();
                return Ok((value, stats));
            }
            let message = failures
                .iter()
                .find(|f| f.stage != NEAR_NULL)
                .map(|f| f.message.clone());
            if first_failure.is_none() {
                first_failure.clone_from(&message);
            }
            let mut bumped = false;
            let last_message = message.unwrap_or_default();
            for f in failures {
                // A nearly singular star (after a pass without failures): its near-null
                // conditions.
                if f.stage == NEAR_NULL {
                    near_start.get_or_insert(extra.len());
                    extra.extend(f.consistency);
                    bumped = true;
                    continue;
                }
                // A singular star whose consistency conditions were not imposed yet: impose
                // them on the weights solved before it (edge middles) instead of relaxing it.
                if consistent
                    && f.stage == 3
                    && !f.consistency.is_empty()
                    && conditioned.insert(f.points.clone())
                {
                    extra.extend(f.consistency);
                    bumped = true;
                    continue;
                }
                // A singular later group (face middles, far face weights, edge tetrahedra)
                // whose right-hand side the weights solved before it miss: impose its
                // consistency conditions on those weights (they join the groups of their last
                // unknowns) instead of solving everything at once.
                if consistent_faces
                    && f.stage >= 4
                    && !f.consistency.is_empty()
                    && conditioned.insert(f.points.clone())
                {
                    extra.extend(f.consistency);
                    bumped = true;
                    continue;
                }
                match f.stage {
                    1 => {
                        for p in &f.points {
                            let l = level.entry(*p).or_insert(0);
                            if *l == 0 {
                                *l = 1;
                                bumped = true;
                            }
                        }
                    }
                    2 | 3 => {
                        for p in &f.points {
                            let l = level.entry(*p).or_insert(0);
                            if *l < 2 {
                                *l += 1;
                                bumped = true;
                            }
                        }
                    }
                    _ => {}
                }
            }
            if !bumped {
                first_failure = Some(last_message);
                break;
            }
        }
        // The staged solve fixed free weights that a later stage cannot live with (e.g. the
        // number 10 system of an edge whose apexes lie in the planes of its points' faces, as on
        // cube_poly): solve every unknown at once, each connected group closest to its targets
        // (without the near-null conditions).
        if let Some(start) = near_start {
            extra.truncate(start);
        }
        crate::progress::report(|| "quintic-c2 solve: every weight at once".into());
        let (value, mut stats, mut failures) =
            self.solve_pass(tets, jets, nt, target, level, true, pin, &extra, false);
        failures.retain(|f| f.stage != NEAR_NULL);
        if failures.is_empty() {
            stats.relaxed_points = level.len();
            stats.consistency_conditions = extra.len();
            stats.global = true;
            return Ok((value, stats));
        }
        let staged = first_failure.unwrap_or_default();
        Err(Error::Invalid(format!(
            "{staged}; solving all weights at once does not help either: {}",
            failures[0].message
        )))
    }

    #[allow(clippy::too_many_lines, clippy::too_many_arguments)]
    fn solve_pass(
        &self,
        tets: &[HullTet],
        jets: &[Jet],
        nt: u32,
        target: &dyn Fn(usize, [u8; 4]) -> f64,
        level: &HashMap<u32, u8>,
        global: bool,
        pin: bool,
        extra: &[Equation],
        near: bool,
    ) -> (Vec<f64>, SolveStats, Vec<Failure>) {
        // The scheme's equations, then the consistency conditions of singular stars
        // (`QuinticOptions::consistent_stars`).
        let all: Vec<&Equation> = self
            .equations
            .iter()
            .chain(&self.held)
            .chain(extra)
            .collect();
        let ns = self.keys.len();
        let np = self.np;
        let first_mid = np + 2 * nt;
        let lv = |p: u32| level.get(&p).copied().unwrap_or(0);
        let mut stage_of = vec![0u8; ns];
        let mut value = vec![0.0; ns];
        let mut known = vec![false; ns];
        let mut failures = Vec::new();
        let mut relaxed_jet = vec![false; ns];
        for s in 0..ns {
            let (mut st, pts) = stage(self.keys[s], np);
            let parts = unkey(self.keys[s]);
            let has_mid = parts.iter().any(|p| p.0 >= first_mid);
            let hull_sum: u32 = parts
                .iter()
                .filter(|p| p.0 < np)
                .map(|p| u32::from(p.1))
                .sum();
            if st == 5 && !has_mid && hull_sum != 2 {
                st = 3;
            }
            // Pass stages: 1 middles, 2 relaxed stars, 3 stars, 4 far face weights, 5 face
            // middles, 6 the rest of the edge tetrahedra.
            if st >= 2 {
                st += 1;
            }
            // Relaxed points: their stars, their edge middles (level 1) and Hessian weights
            // (level 2) are solved together, before the other stars.
            if (st == 1 || st == 3) && pts.iter().any(|&p| lv(p) >= 1) {
                st = 2;
            }
            if st == 0 {
                let (t, l) = self.home[s];
                let tet = &tets[t as usize];
                let k = (0..4).find(|&k| l[k] >= 3).expect("jet slot");
                let jet = &jets[tet.gid[k] as usize];
                value[s] = jet.blossom5(&super::jets::domain_args(&tet.pts, l));
                if l[k] == 3 && lv(tet.gid[k]) >= 2 {
                    st = 2;
                    relaxed_jet[s] = true;
                } else {
                    known[s] = true;
                }
            }
            stage_of[s] = if global { st.min(1) } else { st };
        }
        // Each equation is solved at the stage of its last unknown.
        let mut by_stage: Vec<Vec<usize>> = vec![Vec::new(); 7];
        for (e, eq) in all.iter().enumerate() {
            let st = eq
                .terms
                .iter()
                .map(|t| stage_of[t.0 as usize])
                .max()
                .unwrap_or(0);
            by_stage[usize::from(st)].push(e);
        }
        // Equations of each slot (for the look-ahead sign conditions).
        let mut eqs_of: Vec<Vec<u32>> = vec![Vec::new(); if pin { ns } else { 0 }];
        if pin {
            for (e, eq) in self.equations.iter().enumerate() {
                for t in &eq.terms {
                    eqs_of[t.0 as usize].push(e as u32);
                }
            }
        }
        let mut stats = SolveStats {
            unknowns: known.iter().filter(|k| !**k).count(),
            equations: self.equations.len(),
            ..SolveStats::default()
        };
        let trace = std::env::var_os("APATCH_SIGN_TRACE").is_some();
        for st in 1..=6u8 {
            let mut dev = (0.0_f64, 0.0_f64, 0.0_f64, 0usize, 0usize, 0usize);
            // Union-find over this stage's unknowns, joined by this stage's equations.
            let mut parent: HashMap<u32, u32> = HashMap::new();
            fn find(p: &mut HashMap<u32, u32>, x: u32) -> u32 {
                let mut r = x;
                while let Some(&q) = p.get(&r) {
                    if q == r {
                        break;
                    }
                    r = q;
                }
                let mut y = x;
                while y != r {
                    let q = p[&y];
                    p.insert(y, r);
                    y = q;
                }
                r
            }
            for s in 0..ns as u32 {
                if stage_of[s as usize] == st {
                    parent.insert(s, s);
                }
            }
            for &e in &by_stage[usize::from(st)] {
                let us: Vec<u32> = all[e]
                    .terms
                    .iter()
                    .map(|t| t.0)
                    .filter(|s| stage_of[*s as usize] == st)
                    .collect();
                for w in us.windows(2) {
                    let (a, b) = (find(&mut parent, w[0]), find(&mut parent, w[1]));
                    if a != b {
                        parent.insert(a, b);
                    }
                }
            }
            let mut groups: HashMap<u32, (Vec<u32>, Vec<usize>)> = HashMap::new();
            let mut members: Vec<u32> = parent.keys().copied().collect();
            members.sort_unstable();
            for s in members {
                let r = find(&mut parent, s);
                groups.entry(r).or_default().0.push(s);
            }
            for &e in &by_stage[usize::from(st)] {
                let s = all[e]
                    .terms
                    .iter()
                    .map(|t| t.0)
                    .find(|s| stage_of[*s as usize] == st)
                    .expect("stage equation has an unknown");
                let r = find(&mut parent, s);
                groups.get_mut(&r).expect("group").1.push(e);
            }
            let mut glist: Vec<(Vec<u32>, Vec<usize>)> = groups.into_values().collect();
            glist.sort_unstable_by_key(|g| g.0[0]);
            crate::progress::report(|| {
                let what = [
                    "edge middles",
                    "relaxed stars",
                    "vertex stars",
                    "far face weights",
                    "face middles",
                    "edge tetrahedra",
                ][usize::from(st - 1)];
                format!("quintic-c2 solve: {what} ({} groups)", glist.len())
            });
            // Set up every group (serially: the targets come from a caller's closure). They read
            // only weights of earlier stages: an equation's unknowns of this stage are all in its
            // group.
            let groups: Vec<Group> = glist
                .into_iter()
                .map(|(unk, eqs)| {
                    let col: HashMap<u32, usize> =
                        unk.iter().enumerate().map(|(i, s)| (*s, i)).collect();
                    let mut rows: Vec<sparse::Row> = Vec::with_capacity(eqs.len() + unk.len());
                    let mut c = vec![0.0; eqs.len()];
                    let mut known_size = 0.0_f64;
                    for (i, &e) in eqs.iter().enumerate() {
                        let mut row = Vec::new();
                        let mut size = 0.0;
                        for &(s, k) in &all[e].terms {
                            match col.get(&s) {
                                Some(&j) => row.push((j, k)),
                                None => {
                                    c[i] -= k * value[s as usize];
                                    size += (k * value[s as usize]).abs();
                                }
                            }
                        }
                        known_size = known_size.max(size);
                        rows.push(row);
                    }
                    let tgt: Vec<f64> = unk
                        .iter()
                        .map(|&s| {
                            let (t, l) = self.home[s as usize];
                            if relaxed_jet[s as usize] {
                                // A relaxed Hessian weight: its estimate.
                                value[s as usize]
                            } else {
                                target(t as usize, l)
                            }
                        })
                        .collect();
                    let scale = c
                        .iter()
                        .chain(tgt.iter())
                        .fold(1e-300_f64, |acc, x| acc.max(x.abs()));
                    // Solved in parallel unless its sign conditions read another group of this
                    // stage (solved before it or not, as in serial order) or it is sparse
                    // (one large factorisation at a time).
                    let parallel = unk.len() <= DENSE_LIMIT
                        && !(pin
                            && unk.iter().any(|&s| {
                                eqs_of[s as usize].iter().any(|&e| {
                                    self.equations[e as usize].terms.iter().any(|t| {
                                        stage_of[t.0 as usize] == st && !col.contains_key(&t.0)
                                    })
                                })
                            }));
                    Group {
                        m: eqs.len(),
                        unk,
                        eqs,
                        col,
                        rows,
                        c,
                        tgt,
                        scale,
                        reach: scale.max(known_size),
                        parallel,
                    }
                })
                .collect();
            // Groups of one stage have disjoint unknowns: solved in parallel (ordered collect:
            // the same bits whatever the thread count), the others below in order.
            let mut groups = groups;
            let solved: Vec<Option<GroupSolution>> = {
                let (value, known, stage_of, eqs_of) = (&value, &known, &stage_of, &eqs_of);
                groups
                    .par_iter_mut()
                    .map(|g| {
                        g.parallel
                            .then(|| self.solve_group(g, value, known, stage_of, st, eqs_of, pin))
                    })
                    .collect()
            };
            // Stars whose near-null conditions are wanted: (group, index of its placeholder in
            // `failures`), factored together after the stage.
            let mut near_jobs: Vec<(usize, usize)> = Vec::new();
            for (gi, (g, pre)) in groups.iter_mut().zip(solved).enumerate() {
                let (m, n) = (g.m, g.unk.len());
                stats.largest_group = stats.largest_group.max(n);
                if n > DENSE_LIMIT {
                    stats.sparse_groups += 1;
                }
                let (sol, pinned, given_up) = match pre {
                    Some(s) => s,
                    None => self.solve_group(g, &value, &known, &stage_of, st, &eqs_of, pin),
                };
                stats.signs.pinned += pinned;
                stats.signs.given_up += given_up;
                let unk = &g.unk;
                let where_ = || group_points(unk.iter().copied(), st, np, &self.keys);
                let tight = n > DENSE_LIMIT && !large_consistent(&sol, g.reach);
                if !consistent(&sol, g.reach) || tight {
                    // A large group names the points of its unmet rows only: relaxing every
                    // point of a group that spans the model (fandisk's edge middles with the
                    // stars' consistency conditions: 197322 rows, a few unmet by 1e-9) made
                    // the next pass's relaxed group the whole model (1.3M equations).
                    let pts = if n > DENSE_LIMIT {
                        unmet_points(g, &sol.x, st, np, &self.keys)
                    } else {
                        where_()
                    };
                    if n > DENSE_LIMIT
                        && sol.residual.is_finite()
                        && std::env::var_os("APATCH_SOLVE_TRACE").is_some()
                    {
                        // Opt-in list of a large group's unmet rows on stderr (exploration;
                        // results unaffected): each row missed by more than 1e-9 of the reach,
                        // its miss over the reach and the points of T it names (not for a
                        // group left unsolved, whose every row is missed).
                        trace_unmet(g, &sol.x, st, np, &self.keys, jets);
                    }
                    let shown = brief(&pts);
                    let what = match st {
                        1 if global => format!("every weight at hull points {shown}"),
                        1 => format!("the middle of hull edge {shown}"),
                        // Pass stages: 2 relaxed stars, 3 stars, 4 far face weights, 5 face
                        // middles, 6 the rest of the edge tetrahedra.
                        2 | 3 => format!("the star of hull point(s) {shown}"),
                        4 => {
                            format!("the far weights of the face tetrahedra at hull points {shown}")
                        }
                        5 => format!("the face middles at hull points {shown}"),
                        _ => format!("the edge tetrahedra at hull points {shown}"),
                    };
                    // What the known weights must meet for this group to be consistent:
                    // the dependencies y of its rows (yᵀA = 0) applied to their known terms.
                    let mut consistency = Vec::new();
                    if n <= DENSE_LIMIT {
                        let mut a = vec![0.0; m * n];
                        for (i, row) in g.rows.iter().enumerate().take(m) {
                            for &(j, k) in row {
                                a[i * n + j] += k;
                            }
                        }
                        if trace && st == 3 {
                            // Opt-in exploration: the star's smallest singular values (rows
                            // scaled to unit norm) and how far its data miss each direction.
                            let (u, norm) = unit_rows(g);
                            let cu: Vec<f64> =
                                g.c[..m].iter().zip(&norm).map(|(c, r)| c / r).collect();
                            let small: Vec<String> = dense::near_null_left(&u, m, n, 1e-5)
                                .iter()
                                .map(|(sg, v)| {
                                    let uc: f64 = v.iter().zip(&cu).map(|(a, b)| a * b).sum();
                                    format!("{sg:.1e}:{uc:.1e}")
                                })
                                .collect();
                            // Where the star's centre is: a slot's tetrahedron vertex at
                            // multiplicity 2.
                            let (t, l) = self.home[g.unk[0] as usize];
                            let at = (0..4).find(|&k| l[k] == 2).map(|k| tets[t as usize].pts[k]);
                            eprintln!(
                                "quintic-c2 failing star {:?} at {at:?}: {m}x{n} rank {} residual {:.2e} reach {:.2e}; sigma:u.c {}",
                                where_(),
                                sol.rank,
                                sol.residual,
                                g.reach,
                                small.join(" ")
                            );
                        }
                        for y in dense::dependencies(&a, m, n, 1e-11) {
                            consistency.extend(known_condition(&all, &g.eqs, &g.col, &y));
                        }
                    }
                    let message = if sol.residual == f64::INFINITY {
                        format!(
                            "quintic-c2: the C1/C2 system of {what} is too large to solve at once ({m} equations, {n} unknowns; the supernodal factor is tried up to {} values)",
                            supernodal::MAX_VALUES
                        )
                    } else {
                        format!(
                            "quintic-c2: the C1/C2 system of {what} is singular ({m} equations, {n} unknowns, rank {}, residual {:.3e}): points of T are not in general position",
                            sol.rank, sol.residual
                        )
                    };
                    failures.push(Failure {
                        consistency,
                        stage: st,
                        points: pts,
                        message,
                    });
                }
                // A star solved exactly but nearly singular: the conditions that keep it from
                // amplifying its data's noise (`star_tau`), for the next pass; a placeholder
                // keeps its place among the failures.
                if st == 3 && near && n <= DENSE_LIMIT && consistent(&sol, g.reach) {
                    near_jobs.push((gi, failures.len()));
                    failures.push(Failure {
                        stage: NEAR_NULL,
                        points: where_(),
                        message: String::new(),
                        consistency: Vec::new(),
                    });
                }
                for (j, &s) in unk.iter().enumerate() {
                    if sol.x[j].is_finite() {
                        value[s as usize] = sol.x[j];
                        if trace {
                            let d = (sol.x[j] - g.tgt[j]).abs();
                            dev.0 = dev.0.max(d);
                            dev.1 += d;
                            dev.2 += g.tgt[j].abs();
                            dev.3 += 1;
                            let r = self.req[s as usize];
                            if (r == 1 || r == -1) && f64::from(r) * g.tgt[j] < 0.0 {
                                dev.4 += 1;
                            }
                            if (r == 1 || r == -1) && f64::from(r) * sol.x[j] < 0.0 {
                                dev.5 += 1;
                            }
                        }
                    }
                    known[s as usize] = true;
                }
            }
            if !near_jobs.is_empty() {
                // The stars' singular vectors, all at once in parallel (they depend on the
                // groups' rows only), then their conditions in their places.
                let conds: Vec<Vec<Equation>> = near_jobs
                    .par_iter()
                    .map(|&(gi, _)| Self::near_null_conditions(&groups[gi], &all, self.star_tau))
                    .collect();
                for (&(_, at), conds) in near_jobs.iter().zip(conds) {
                    failures[at].consistency = conds;
                }
                failures.retain(|f| f.stage != NEAR_NULL || !f.consistency.is_empty());
            }
            if trace {
                // Opt-in exploration on stderr (results unaffected).
                eprintln!(
                    "quintic-c2 stage {st}: {} weights, |x - target| max {:.2e} mean {:.2e}, mean |target| {:.2e}; sign misses: targets {}, solution {}",
                    dev.3,
                    dev.0,
                    dev.1 / dev.3.max(1) as f64,
                    dev.2 / dev.3.max(1) as f64,
                    dev.4,
                    dev.5
                );
            }
        }
        let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
        stats.max_residual = all
            .iter()
            .map(|eq| {
                eq.terms
                    .iter()
                    .map(|(s, c)| c * value[*s as usize])
                    .sum::<f64>()
                    .abs()
            })
            .fold(0.0, f64::max)
            / wmax;
        if let Some(path) = std::env::var_os("APATCH_SLOT_DUMP") {
            // Opt-in exploration: per tetrahedron and weight, its slot's stage and required
            // sign (i8 each, 2 × 56 bytes a tetrahedron, in the complex's patch order).
            let mut bytes = Vec::with_capacity(self.slot_of.len() * NW * 2);
            for slots in &self.slot_of {
                for &s in slots {
                    bytes.push(stage_of[s as usize]);
                    bytes.push(self.req[s as usize] as u8);
                }
            }
            if let Err(e) = std::fs::write(&path, bytes) {
                eprintln!("quintic-c2: slot dump not written: {e}");
            }
        }
        let (pinned, given_up) = (stats.signs.pinned, stats.signs.given_up);
        stats.signs = self.sign_stats(&value, &stage_of);
        stats.signs.pinned = pinned;
        stats.signs.given_up = given_up;
        (value, stats, failures)
    }

    /// Solves one group closest to its targets, with Theorem 2.1's signs pinned where it can
    /// (`pin`, [`pin_signs`], which append their pins to the group's rows). Reads `value` and
    /// `known` only through [`System::sign_conditions`].
    #[allow(clippy::too_many_arguments)]
    fn solve_group(
        &self,
        g: &mut Group,
        value: &[f64],
        known: &[bool],
        stage_of: &[u8],
        st: u8,
        eqs_of: &[Vec<u32>],
        pin: bool,
    ) -> GroupSolution {
        if let Some(v) = self
            .preset
            .as_ref()
            .filter(|_| g.unk.len() > PIN_MAX_UNKNOWNS)
        {
            // Exploration: the group's values as an earlier run of this scene left them, or
            // (`APATCH_RESTAGE_FIT=file`, what `APATCH_JOINT_FIT_SAVE` wrote) its sign fit's.
            let fitted = std::env::var_os("APATCH_RESTAGE_FIT").and_then(|path| {
                cholesky::read_fit(std::path::Path::new(&path), g.unk.len())
                    .map_err(|e| eprintln!("quintic-c2: saved sign fit not used: {e}"))
                    .ok()
            });
            let mut x: Vec<f64> = match fitted {
                Some((_, x)) => x,
                None => g.unk.iter().map(|&s| v[s as usize]).collect(),
            };
            if self.joint_local_meet && std::env::var_os("APATCH_RESTAGE_FIT").is_some() {
                // A saved fit taken up: its missed rows met as the run would meet them.
                self.meet_locally(g, &mut x);
            }
            let residual = g
                .rows
                .iter()
                .zip(&g.c)
                .map(|(row, c)| (row.iter().map(|&(j, k)| k * x[j]).sum::<f64>() - c).abs())
                .fold(0.0, f64::max);
            if let Some(path) = std::env::var_os("APATCH_ROW_DUMP") {
                // Opt-in exploration: the group's rows these values miss beyond its solve's
                // tolerance, one line each: row, residual, |row|, then every term's
                // tetrahedron (the complex's patch order), multi-index and coefficient.
                let tol = 1e-13 * g.scale;
                let mut out = String::new();
                for (i, (row, c)) in g.rows.iter().zip(&g.c).enumerate().take(g.m) {
                    let r = row.iter().map(|&(j, k)| k * x[j]).sum::<f64>() - c;
                    if r.abs() > tol {
                        out.push_str(&self.row_line(g, i, r, false));
                    }
                }
                if let Err(e) = std::fs::write(&path, out) {
                    eprintln!("quintic-c2: row dump not written: {e}");
                }
            }
            if let Some(path) = std::env::var_os("APATCH_ROW_LOCAL") {
                // Opt-in exploration: every row of the group with a term in the tetrahedra the
                // file lists (ids, whitespace-separated), in the dump's format with each term's
                // column in the group after its coefficient, written to the file's name +
                // ".rows": a region's rows, to look for their near dependencies.
                let tets: HashSet<u32> = std::fs::read_to_string(&path)
                    .unwrap_or_default()
                    .split_whitespace()
                    .filter_map(|w| w.parse().ok())
                    .collect();
                let mut out = String::new();
                for (i, (row, c)) in g.rows.iter().zip(&g.c).enumerate().take(g.m) {
                    if row
                        .iter()
                        .any(|&(j, _)| tets.contains(&self.home[g.unk[j] as usize].0))
                    {
                        let r = row.iter().map(|&(j, k)| k * x[j]).sum::<f64>() - c;
                        out.push_str(&self.row_line(g, i, r, true));
                    }
                }
                let mut to = path.clone();
                to.push(".rows");
                if let Err(e) = std::fs::write(&to, out) {
                    eprintln!("quintic-c2: local row dump not written: {e}");
                }
            }
            let rank = g.m.min(x.len());
            return (dense::Solution { x, rank, residual }, 0, 0);
        }
        if self.sign_targets > 0.0 {
            self.move_targets_into_signs(g);
        }
        // Groups too large to pin: the signs with their one factor (alternating projections, the
        // split sign program).
        let signs = (pin
            && (self.joint_sign_rounds > 0 || self.joint_sign_fit > 0)
            && g.unk.len() > PIN_MAX_UNKNOWNS)
            .then(|| self.sign_box(g));
        // The group's relaxed Hessian weights priced by `hessian_cost` (or, for exploration,
        // `APATCH_HESSIAN_WEIGHT`), if it has any and the price is not 1.
        let np = self.np;
        let cost = hessian_weight().unwrap_or(self.hessian_cost);
        let weights = (cost != 1.0).then_some(cost).and_then(|w| {
            let cw: Vec<f64> = g
                .unk
                .iter()
                .map(|&s| {
                    let jet = unkey(self.keys[s as usize])
                        .iter()
                        .any(|p| p.0 < np && p.1 == 3);
                    if jet {
                        w
                    } else {
                        1.0
                    }
                })
                .collect();
            cw.iter().any(|&x| x != 1.0).then_some(cw)
        });
        let mut sol = match weights.as_ref() {
            None => solve_rows_signed(
                &g.rows,
                g.unk.len(),
                &g.c,
                &g.tgt,
                g.scale,
                signs.as_ref(),
                self.precise_pivot,
            ),
            Some(cw) => solve_rows_weighted(
                &g.rows,
                &g.c,
                &g.tgt,
                cw,
                g.scale,
                signs.as_ref(),
                self.precise_pivot,
            ),
        };
        if signs.is_some() && self.joint_local_meet && sol.x.iter().all(|v| v.is_finite()) {
            sol.residual = self.meet_locally(g, &mut sol.x);
        }
        let (mut pinned, mut given_up) = (0, 0);
        // Beyond the in-house factor a group goes to the supernodal one, and every pin round
        // would factor it again (fandisk's joint group: 17 minutes, 16.5 GB each).
        if pin && g.unk.len() <= PIN_MAX_UNKNOWNS && consistent(&sol, g.reach) {
            let conds = self.sign_conditions(&g.unk, &g.col, value, known, stage_of, st, eqs_of);
            // Opt-in exploration on stderr (`APATCH_PIN_TRACE`; results unaffected): each
            // group's conditions missed before and after its pins, at the pins' rounding.
            let trace = std::env::var_os("APATCH_PIN_TRACE").is_some();
            let tiny = 1e-9 * g.scale;
            let missed = |x: &[f64]| conds.iter().filter(|k| k.value(x) < -tiny).count();
            let before = if trace { missed(&sol.x) } else { 0 };
            (pinned, given_up) = pin_signs(
                &mut sol,
                &mut g.rows,
                &mut g.c,
                &conds,
                &g.tgt,
                weights.as_deref(),
                g.scale,
            );
            if trace {
                let own = conds
                    .iter()
                    .filter(|k| k.row.len() == 1 && k.offset == 0.0)
                    .count();
                eprintln!(
                    "quintic-c2 pins: stage {st} unknowns {} conditions {} (own {own}) missed {before} -> {} pinned {pinned} given up {given_up}",
                    g.unk.len(),
                    conds.len(),
                    missed(&sol.x)
                );
            }
        }
        (sol, pinned, given_up)
    }

    /// Exploration dumps (`APATCH_ROW_DUMP`, `APATCH_ROW_LOCAL`): row `i` of `g` with its
    /// residual `r` and norm, then every term's tetrahedron, multi-index and coefficient (and,
    /// with `columns`, its column in the group); one line.
    fn row_line(&self, g: &Group, i: usize, r: f64, columns: bool) -> String {
        let row = &g.rows[i];
        let norm = row.iter().map(|t| t.1 * t.1).sum::<f64>().sqrt();
        let mut line = format!("{i} {r:e} {norm:e}");
        for &(j, k) in row {
            let (t, l) = self.home[g.unk[j] as usize];
            line.push_str(&format!(" {t}:{}{}{}{}:{k:e}", l[0], l[1], l[2], l[3]));
            if columns {
                line.push_str(&format!(":{j}"));
            }
        }
        line.push('\n');
        line
    }

    /// Meets the rows of `g` that `x` misses beyond the solve's tolerance region by region
    /// ([`super::localmeet`]); returns the largest miss left.
    fn meet_locally(&self, g: &Group, x: &mut [f64]) -> f64 {
        let pos: Vec<DVec3> = g.unk.iter().map(|&s| self.pos[s as usize]).collect();
        let size = std::env::var("APATCH_LOCAL_MEET_SIZE")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(LOCAL_MEET_SIZE);
        let out = super::localmeet::meet(
            &g.rows[..g.m],
            &g.c[..g.m],
            x,
            &pos,
            1e-13 * g.scale,
            size,
            LOCAL_MEET_MOVE * g.scale,
        );
        if std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
            // Opt-in report on stderr (exploration; results unaffected).
            eprintln!(
                "quintic-c2 local meet: {} unknowns, rows missed {} -> {} (worst {:.2e} -> {:.2e}), {} regions of {size}, {} kept, largest move {:.2e}",
                g.unk.len(),
                out.missed_before,
                out.missed_after,
                out.worst_before,
                out.worst_after,
                out.regions,
                out.kept,
                out.largest_move
            );
        }
        out.worst_after
    }

    /// The sign box of `g`'s own weights that Theorem 2.1 asks a sign of, its margin
    /// [`System::sign_targets`] (or 1 where that is off) × the median of their |target|, as
    /// [`System::move_targets_into_signs`] (the box the targets were moved into).
    fn sign_box(&self, g: &Group) -> cholesky::SignBox {
        let signed: Vec<(usize, f64)> = g
            .unk
            .iter()
            .enumerate()
            .filter_map(|(j, &s)| {
                let r = self.req[s as usize];
                (r == 1 || r == -1).then_some((j, f64::from(r)))
            })
            .collect();
        let mut size: Vec<f64> = signed.iter().map(|&(j, _)| g.tgt[j].abs()).collect();
        let median = if size.is_empty() {
            0.0
        } else {
            let mid = size.len() / 2;
            *size.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let per = if self.sign_targets > 0.0 {
            self.sign_targets
        } else {
            1.0
        };
        let cost = if self.joint_sign_boundary == 1.0 {
            Vec::new()
        } else {
            signed
                .iter()
                .map(|&(j, _)| {
                    if self.boundary[g.unk[j] as usize] {
                        self.joint_sign_boundary
                    } else {
                        1.0
                    }
                })
                .collect()
        };
        cholesky::SignBox {
            signed,
            cost,
            margin: per * median,
            rounds: self.joint_sign_rounds,
            fit: self.joint_sign_fit,
            // With the local meet, the factor's meet after the fit is skipped (and the fit
            // kept): the regions meet what it leaves.
            meet_tol: if self.joint_local_meet {
                f64::INFINITY
            } else {
                self.joint_meet_tolerance * g.scale
            },
            meet_stall: self.joint_meet_stall,
        }
    }

    /// Moves the targets of `g`'s weights that Theorem 2.1 asks a sign of to at least
    /// [`System::sign_targets`] × the median of their |target| on that side (the sign box of
    /// `project`, applied to the targets instead of the solution).
    fn move_targets_into_signs(&self, g: &mut Group) {
        let cholesky::SignBox { signed, margin, .. } = self.sign_box(g);
        for (j, sign) in signed {
            if sign * g.tgt[j] < margin {
                g.tgt[j] = sign * margin;
            }
        }
    }

    /// A solved star's near-null conditions (`tau`: `star_tau`): the left singular vectors u
    /// of its rows scaled to unit norm with σ ≤ `tau` × σ_max, each as the condition uᵀc = 0 on
    /// the known weights its right-hand side reads ([`known_condition`]).
    fn near_null_conditions(g: &Group, all: &[&Equation], tau: f64) -> Vec<Equation> {
        let (a, norm) = unit_rows(g);
        dense::near_null_left(&a, g.m, g.unk.len(), tau)
            .into_iter()
            .filter_map(|(_, u)| {
                // uᵀ(row_i / |row_i|): the condition on the unscaled equations.
                let y: Vec<f64> = u.iter().zip(&norm).map(|(u, r)| u / r).collect();
                known_condition(all, &g.eqs, &g.col, &y)
            })
            .collect()
    }

    /// Theorem 2.1's sign conditions on the group `unk` (columns `col`) at stage `st`: its own
    /// unknowns with a sign, and later weights that a single equation fixes from this group's
    /// unknowns and known weights (so the group can keep them signed, which their own stage
    /// could not: they are determined there).
    #[allow(clippy::too_many_arguments)]
    fn sign_conditions(
        &self,
        unk: &[u32],
        col: &HashMap<u32, usize>,
        value: &[f64],
        known: &[bool],
        stage_of: &[u8],
        st: u8,
        eqs_of: &[Vec<u32>],
    ) -> Vec<SignCondition> {
        let mut out = Vec::new();
        for (j, &s) in unk.iter().enumerate() {
            let r = self.req[s as usize];
            if r == 1 || r == -1 {
                out.push(SignCondition {
                    row: vec![(j, 1.0)],
                    offset: 0.0,
                    sign: f64::from(r),
                });
            }
        }
        let mut seen: Vec<u32> = unk
            .iter()
            .flat_map(|&s| eqs_of[s as usize].iter().copied())
            .collect();
        seen.sort_unstable();
        seen.dedup();
        let mut later_seen: HashMap<u32, ()> = HashMap::new();
        for e in seen {
            let eq = &self.equations[e as usize];
            let mut later: Option<(u32, f64)> = None;
            let mut ok = true;
            let mut row: sparse::Row = Vec::new();
            let mut offset = 0.0;
            for &(s, k) in &eq.terms {
                if let Some(&j) = col.get(&s) {
                    row.push((j, k));
                } else if known[s as usize] {
                    offset += k * value[s as usize];
                } else if later.is_none() && stage_of[s as usize] > st {
                    later = Some((s, k));
                } else {
                    ok = false;
                    break;
                }
            }
            let Some((b, kb)) = later else { continue };
            let r = self.req[b as usize];
            // One condition per later weight; the defining equations have coefficient 1 on it.
            if !ok || row.is_empty() || !(r == 1 || r == -1) || kb.abs() < 0.5 {
                continue;
            }
            if later_seen.insert(b, ()).is_some() {
                continue;
            }
            // k_b·b + row·x + offset = 0  ⇒  b = −(row·x + offset)/k_b.
            for t in &mut row {
                t.1 /= -kb;
            }
            out.push(SignCondition {
                row,
                offset: -offset / kb,
                sign: f64::from(r),
            });
        }
        out
    }

    /// Theorem 2.1's signs of the solved `value`s, violations by the stage that fixed them.
    fn sign_stats(&self, value: &[f64], stage_of: &[u8]) -> SignStats {
        let mut st = SignStats::default();
        let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
        // A weight this small relative to the largest is zero up to the rounding of the
        // solves (residuals ≤ 1e-12 relative): it meets either sign.
        let tiny = 1e-12 * wmax;
        let mut bad = vec![false; value.len()];
        for (s, &r) in self.req.iter().enumerate() {
            match r {
                0 => {}
                signs::CONFLICT => st.conflicts += 1,
                _ => {
                    st.constrained += 1;
                    if f64::from(r) * value[s] < -tiny {
                        bad[s] = true;
                        st.violated_by_stage[usize::from(stage_of[s].min(6))] += 1;
                    }
                }
            }
        }
        st.violating_patches = self
            .slot_of
            .iter()
            .filter(|slots| slots.iter().any(|&s| bad[s as usize]))
            .count();
        st
    }

    /// Adds the signs a zero base asks: on the face tetrahedra of the triangles `zero` (zero
    /// coplanar groups, where F ≡ 0 on the base) the base is the sheet, so every level-1
    /// weight must have the apex's side's sign too (Theorem 2.1 for F/λ_q, whose levels are
    /// F's levels 1–5 with k = 0). Without it the level-1 weights are free (k = 1) and where
    /// they turn, F/λ_q vanishes between base and apex: a second sheet, and the base seen
    /// from behind (the nut quintic's crack).
    pub fn require_zero_bases(&mut self, tets: &[HullTet], zero: &HashSet<u32>) {
        let mi = multi_indices(N);
        for (t, tet) in tets.iter().enumerate() {
            if tet.role != Role::Face || !zero.contains(&tet.triangle) {
                continue;
            }
            let s = signs::side_sign(tet.side);
            for (i, l) in mi.iter().enumerate() {
                if l[3] == 1 {
                    let k = self.slot_of[t][i] as usize;
                    self.req[k] = signs::combine(self.req[k], s);
                }
            }
        }
    }

    /// The sign Theorem 2.1 asks of the weight at multi-index `l` of tetrahedron `t`, combined
    /// over every tetrahedron sharing it: +1, −1, 0 for none, or [`signs::CONFLICT`].
    #[must_use]
    pub fn required_sign(&self, t: usize, l: [u8; 4]) -> i8 {
        self.req[self.slot_of[t][crate::bb::index_of(l)] as usize]
    }

    /// Largest |coefficient| of the C1/C2 equations (each has coefficient 1 on the weight it
    /// defines): how far the rows are from the O(1) barycentrics of thick tetrahedra.
    #[must_use]
    pub fn max_coefficient(&self) -> f64 {
        self.equations
            .iter()
            .flat_map(|e| e.terms.iter())
            .fold(0.0_f64, |m, t| m.max(t.1.abs()))
    }

    /// The 56 weights of tetrahedron `t` from the slot values.
    #[must_use]
    pub fn weights(&self, t: usize, value: &[f64]) -> Vec<f64> {
        self.slot_of[t].iter().map(|&s| value[s as usize]).collect()
    }
}

/// The group's own rows (its first `m`) each over its norm, dense row-major, with the norms.
fn unit_rows(g: &Group) -> (Vec<f64>, Vec<f64>) {
    let (m, n) = (g.m, g.unk.len());
    let mut a = vec![0.0; m * n];
    let mut norm = vec![0.0_f64; m];
    for (i, row) in g.rows.iter().enumerate().take(m) {
        norm[i] = row
            .iter()
            .map(|t| t.1 * t.1)
            .sum::<f64>()
            .sqrt()
            .max(1e-300);
        for &(j, k) in row {
            a[i * n + j] += k / norm[i];
        }
    }
    (a, norm)
}

/// `pts` for a message: all of them up to 12, else the first 12 and how many there are.
fn brief(pts: &[u32]) -> String {
    if pts.len() <= 12 {
        format!("{pts:?}")
    } else {
        let head: Vec<String> = pts[..12].iter().map(u32::to_string).collect();
        format!("[{}, … ({} points)]", head.join(", "), pts.len())
    }
}

/// The points of the unknowns (the stars' centres at stages 2 and 3) in the rows of group `g`
/// that `x` misses by more than [`consistent`] allows, sorted; all of the group's points if
/// none does (a non-finite solution).
fn unmet_points(g: &Group, x: &[f64], st: u8, np: u32, keys: &[u128]) -> Vec<u32> {
    let finite = x.iter().all(|v| v.is_finite());
    let mut cols: Vec<usize> = Vec::new();
    for (i, row) in g.rows.iter().take(g.m).enumerate() {
        if !finite || unmet_row(g, x, i).is_some() {
            cols.extend(row.iter().map(|t| t.0));
        }
    }
    if cols.is_empty() {
        cols = (0..g.unk.len()).collect();
    }
    group_points(cols.into_iter().map(|j| g.unk[j]), st, np, keys)
}

/// How far `x` misses row `i` of group `g` (A x − c), if by more than [`consistent`] allows
/// (1e-9 of the group's reach) or by NaN.
fn unmet_row(g: &Group, x: &[f64], i: usize) -> Option<f64> {
    let r: f64 = g.rows[i].iter().map(|&(j, k)| k * x[j]).sum::<f64>() - g.c[i];
    let rel = large_tolerance().map_or(CONSISTENT, |t| t.min(CONSISTENT));
    (r.is_nan() || r.abs() > rel * g.reach).then_some(r)
}

/// Exploration (`APATCH_HESSIAN_WEIGHT=w`): in a group with relaxed Hessians (the joint stars),
/// each relaxed Hessian weight's distance from its estimate counts w times the others', so the
/// solve moves the jets (fitted into Theorem 2.1's signs by `hessian_signs`) only as far as the
/// stars' equations need: between the Hessians free (w = 1) and fixed (`APATCH_JOINT_LEVEL=1`).
/// Overrides the scene's `hessian_cost`; the sign pins of a small group re-solve it in the same
/// norm (since session 68; before, unweighted, which undid the weight wherever pins were taken).
fn hessian_weight() -> Option<f64> {
    std::env::var("APATCH_HESSIAN_WEIGHT")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|w| w.is_finite() && *w > 0.0)
}

/// Exploration (`APATCH_LARGE_CONSISTENT=r`): a large group counts as met only if it misses
/// its rows by at most `r` of its reach, and names the points of the rows it misses by more
/// (so that the next pass relaxes them), instead of [`consistent`]'s 1e-9.
/// Read once: [`unmet_row`] asks for every row of a group.
fn large_tolerance() -> Option<f64> {
    static TOLERANCE: std::sync::OnceLock<Option<f64>> = std::sync::OnceLock::new();
    *TOLERANCE.get_or_init(|| {
        std::env::var("APATCH_LARGE_CONSISTENT")
            .ok()
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|r| r.is_finite() && *r > 0.0)
    })
}

/// [`consistent`] with the tolerance of [`large_tolerance`] where one is set.
fn large_consistent(sol: &dense::Solution, reach: f64) -> bool {
    large_tolerance().is_none_or(|r| consistent_within(sol, reach, r))
}

/// Prints every row of `g` that `x` misses by more than 1e-9 of the group's reach
/// ([`unmet_row`]): the miss over the reach, the row's length and the points of T it names
/// with their positions (`APATCH_SOLVE_TRACE`, exploration).
fn trace_unmet(g: &Group, x: &[f64], st: u8, np: u32, keys: &[u128], jets: &[Jet]) {
    for (i, row) in g.rows.iter().take(g.m).enumerate() {
        if let Some(r) = unmet_row(g, x, i) {
            let pts = group_points(row.iter().map(|t| g.unk[t.0]), st, np, keys);
            let at: Vec<String> = pts
                .iter()
                .map(|&p| {
                    let q = jets.get(p as usize).map_or(DVec3::NAN, |j| j.p);
                    format!("{p} ({:.4}, {:.4}, {:.4})", q.x, q.y, q.z)
                })
                .collect();
            eprintln!(
                "quintic-c2 unmet row {i}: miss {:.2e} of the reach, {} terms, points {}",
                r.abs() / g.reach,
                row.len(),
                at.join(" ")
            );
        }
    }
}

/// The points of T that the slots `slots` of a group at pass stage `st` name, sorted: the
/// stars' centres (points at multiplicity 2) at stages 2 and 3, else every point of T in them.
fn group_points(slots: impl Iterator<Item = u32>, st: u8, np: u32, keys: &[u128]) -> Vec<u32> {
    let mut pts: Vec<u32> = slots
        .flat_map(|s| {
            let key = keys[s as usize];
            if st == 2 || st == 3 {
                unkey(key)
                    .into_iter()
                    .filter(|p| p.0 < np && p.1 >= 2)
                    .map(|p| p.0)
                    .collect()
            } else {
                stage(key, np).1
            }
        })
        .collect();
    pts.sort_unstable();
    pts.dedup();
    pts
}

/// Whether a group's solution meets its equations (to 1e-9 of `scale`, the group's reach: far
/// above the rounding of the solves, far below any inconsistency the systems have shown).
fn consistent(sol: &dense::Solution, scale: f64) -> bool {
    consistent_within(sol, scale, CONSISTENT)
}

/// How far a group may miss its rows and count as met: this share of its reach.
const CONSISTENT: f64 = 1e-9;

/// Whether `sol` is finite and meets its rows to `rel` of `scale`.
fn consistent_within(sol: &dense::Solution, scale: f64, rel: f64) -> bool {
    !(sol.residual.is_nan() || sol.residual > rel * scale || sol.x.iter().any(|x| !x.is_finite()))
}

/// A group's weights closest to `tgt` subject to `rows`·x = `c`: dense up to
/// [`DENSE_LIMIT`] unknowns, else sparse direct ([`cholesky`]).
fn solve_rows(
    rows: &[sparse::Row],
    n: usize,
    c: &[f64],
    tgt: &[f64],
    scale: f64,
) -> dense::Solution {
    solve_rows_signed(rows, n, c, tgt, scale, None, None)
}

/// [`solve_rows_signed`] closest to `tgt` in the weighted norm Σ w_j² (x_j − t_j)² (`cw`: one
/// positive weight per unknown): the plain least change in y = W x, whose columns are the
/// rows' divided by w_j and whose targets are w_j t_j.
fn solve_rows_weighted(
    rows: &[sparse::Row],
    c: &[f64],
    tgt: &[f64],
    cw: &[f64],
    scale: f64,
    signs: Option<&cholesky::SignBox>,
    pivot: Option<f64>,
) -> dense::Solution {
    let scaled: Vec<sparse::Row> = rows
        .iter()
        .map(|r| r.iter().map(|&(j, k)| (j, k / cw[j])).collect())
        .collect();
    let ty: Vec<f64> = tgt.iter().zip(cw).map(|(t, w)| t * w).collect();
    let scale = ty.iter().fold(scale, |a, t| a.max(t.abs()));
    let mut sol = solve_rows_signed(&scaled, tgt.len(), c, &ty, scale, signs, pivot);
    for (x, w) in sol.x.iter_mut().zip(cw) {
        *x /= w;
    }
    sol
}

/// [`solve_rows`], with Theorem 2.1's `signs` taken by alternating projections where the group
/// goes to the supernodal factor ([`supernodal::solve_near_signed`]), whose double-double
/// factor drops rows at `pivot` if given.
fn solve_rows_signed(
    rows: &[sparse::Row],
    n: usize,
    c: &[f64],
    tgt: &[f64],
    scale: f64,
    signs: Option<&cholesky::SignBox>,
    pivot: Option<f64>,
) -> dense::Solution {
    let m = rows.len();
    if n <= DENSE_LIMIT {
        let mut a = vec![0.0; m * n];
        for (i, row) in rows.iter().enumerate() {
            for &(j, k) in row {
                a[i * n + j] += k;
            }
        }
        dense::solve_near(&a, m, n, c, tgt, 1e-11)
    } else {
        // Sparse direct: minimum-degree Cholesky of Â Âᵀ with refinement (Craig's method,
        // `sparse`, needed thousands of iterations on the knot's coupled groups).
        let t = std::time::Instant::now();
        if let Some(dir) = std::env::var_os("APATCH_SOLVE_DUMP") {
            // Opt-in dump of the large groups for offline solver experiments.
            dump_group(std::path::Path::new(&dir), rows, n, c, tgt, scale);
        }
        let limits = (
            cholesky::MAX_FACTOR_ROWS,
            cholesky::MAX_FACTOR_ENTRIES,
            supernodal::MAX_VALUES,
        );
        let sol = solve_sparse(rows, n, c, tgt, 1e-13 * scale, limits, signs, pivot);
        if std::env::var_os("APATCH_SOLVE_TRACE").is_some() {
            // Opt-in timing of the large groups on stderr (exploration; results unaffected).
            eprintln!(
                "quintic-c2 sparse group: {m} equations, {n} unknowns, rank {}, residual {:.2e} (scale {scale:.2e}), {:.2} s",
                sol.rank,
                sol.residual,
                t.elapsed().as_secs_f64()
            );
        }
        sol
    }
}

/// [`cholesky::solve_near`] within `(max rows, max factor entries, _)`; a group beyond either
/// is solved by the supernodal factor ([`supernodal::solve_near`]) within `(_, _, max
/// supernodal values)`, and left unsolved (its targets, infinite residual) beyond that too,
/// which the caller reports as too large: a factor that does not fit in memory would end the
/// process instead of the scene.
#[allow(clippy::too_many_arguments)]
fn solve_sparse(
    rows: &[sparse::Row],
    n: usize,
    c: &[f64],
    tgt: &[f64],
    tol: f64,
    (max_rows, max_entries, max_values): (usize, usize, usize),
    signs: Option<&cholesky::SignBox>,
    pivot: Option<f64>,
) -> dense::Solution {
    if let Some(o) = cholesky::Ordering::within(rows, n, (max_rows, max_entries)) {
        return cholesky::solve_near_ordered(rows, n, c, tgt, tol, &o);
    }
    supernodal::solve_near_signed(rows, n, c, tgt, tol, max_values, signs, pivot)
        .unwrap_or_else(|| dense::Solution::unsolved(tgt))
}

/// Writes one group (`rows`, `c`, `tgt`, `scale`) as little-endian binary to a new numbered
/// file in `dir` (exploration only, `APATCH_SOLVE_DUMP`): m, n as u64, `scale`, then per row
/// its length (u64) and (column u64, coefficient f64) pairs, then c and tgt.
fn dump_group(
    dir: &std::path::Path,
    rows: &[sparse::Row],
    n: usize,
    c: &[f64],
    tgt: &[f64],
    scale: f64,
) {
    let mut b: Vec<u8> = Vec::new();
    b.extend((rows.len() as u64).to_le_bytes());
    b.extend((n as u64).to_le_bytes());
    b.extend(scale.to_le_bytes());
    for r in rows {
        b.extend((r.len() as u64).to_le_bytes());
        for &(j, a) in r {
            b.extend((j as u64).to_le_bytes());
            b.extend(a.to_le_bytes());
        }
    }
    for v in c.iter().chain(tgt) {
        b.extend(v.to_le_bytes());
    }
    let _ = std::fs::create_dir_all(dir);
    for k in 0.. {
        let f = dir.join(format!("group{k:03}.bin"));
        if !f.exists() {
            let _ = std::fs::write(f, b);
            break;
        }
    }
}

/// Largest group (unknowns) whose signs are pinned: the in-house factor's row limit. Larger
/// groups are solved by the supernodal factor, whose every pin round is another full factor.
const PIN_MAX_UNKNOWNS: usize = cholesky::MAX_FACTOR_ROWS;

/// Rounds of [`pin_signs`] per group.
const PIN_ROUNDS: usize = 8;
/// How much larger than the unpinned solution's largest weight (or the group's data) a pinned
/// solution's weights may grow.
const PIN_GROWTH: f64 = 2.0;
/// Pins tried one at a time per group when a round's pins together are inconsistent.
const PIN_SINGLE_TRIES: usize = 48;

/// One of Theorem 2.1's sign conditions on a group: `sign` · (`row`·x + `offset`) ≥ 0, where
/// x are the group's unknowns: one of them (`row` = x_j), or a later weight that one equation
/// fixes from this group and known weights (look-ahead).
pub(crate) struct SignCondition {
    row: sparse::Row,
    offset: f64,
    sign: f64,
}

impl SignCondition {
    fn value(&self, x: &[f64]) -> f64 {
        self.sign * (self.row.iter().map(|&(j, a)| a * x[j]).sum::<f64>() + self.offset)
    }
}

/// Theorem 2.1's signs within one group (an active set): every condition the solution `sol`
/// misses is pinned (its quantity set to its sign × a margin of 1e-6 of the group's scale, so
/// rounding cannot flip it), and the group is solved again closest to the same targets, until
/// no condition is missed. Pins that the equations cannot live with (the group turns
/// inconsistent, or other weights would have to grow past [`PIN_GROWTH`]) are tried one at a
/// time and the ones that still conflict are given up. Returns (pinned, given up).
fn pin_signs(
    sol: &mut dense::Solution,
    rows: &mut Vec<sparse::Row>,
    c: &mut Vec<f64>,
    conds: &[SignCondition],
    tgt: &[f64],
    cw: Option<&[f64]>,
    scale: f64,
) -> (usize, usize) {
    let n = tgt.len();
    // Each re-solve in the norm the group's first solve used.
    let solve_rows = |rows: &[sparse::Row], n: usize, c: &[f64], tgt: &[f64], scale: f64| match cw {
        None => solve_rows(rows, n, c, tgt, scale),
        Some(cw) => solve_rows_weighted(rows, c, tgt, cw, scale, None, None),
    };
    let margin = 1e-6 * scale;
    // Rounding of the solves (residual ≤ 1e-9 scale is accepted as consistent).
    let tiny = 1e-9 * scale;
    let mut done = vec![false; conds.len()];
    let (mut pinned, mut given_up) = (0, 0);
    // A pin that is nearly dependent on the equations is met only by moving other weights far
    // (weights of 20× the data were seen): such a solution is refused like an inconsistent one.
    let bound = PIN_GROWTH * sol.x.iter().fold(scale, |a, x| a.max(x.abs()));
    let acceptable =
        |s: &dense::Solution| consistent(s, scale) && s.x.iter().all(|x| x.abs() <= bound);
    let misses = |x: &[f64], done: &[bool]| -> Vec<usize> {
        let mut v: Vec<usize> = (0..conds.len())
            .filter(|&k| !done[k] && conds[k].value(x) < -tiny)
            .collect();
        // Largest miss first.
        v.sort_by(|&a, &b| conds[a].value(x).total_cmp(&conds[b].value(x)));
        v
    };
    let push = |rows: &mut Vec<sparse::Row>, c: &mut Vec<f64>, k: usize| {
        rows.push(conds[k].row.clone());
        c.push(conds[k].sign * margin - conds[k].offset);
    };
    for _ in 0..PIN_ROUNDS {
        let miss = misses(&sol.x, &done);
        if miss.is_empty() {
            break;
        }
        let m0 = rows.len();
        for &k in &miss {
            push(rows, c, k);
        }
        let all = solve_rows(rows, n, c, tgt, scale);
        if acceptable(&all) {
            *sol = all;
            pinned += miss.len();
            for &j in &miss {
                done[j] = true;
            }
            continue;
        }
        rows.truncate(m0);
        c.truncate(m0);
        for (tries, &j) in miss.iter().enumerate() {
            done[j] = true;
            if tries >= PIN_SINGLE_TRIES {
                given_up += 1;
                continue;
            }
            push(rows, c, j);
            let one = solve_rows(rows, n, c, tgt, scale);
            if acceptable(&one) {
                *sol = one;
                pinned += 1;
            } else {
                rows.pop();
                c.pop();
                given_up += 1;
            }
        }
    }
    (pinned, given_up)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An edge tetrahedron pair [p_i, p_j, q0, s], [p_i, p_j, q1, s] with s the stored
    /// midpoint of the apexes (Def. 3.6 (5)(ii)): β = (0, 0, −1, 2). With `face_beta =
    /// "snapped"` the shared face's rows are the collinear case exactly, each C1 row B's
    /// weight = −(q0's) + 2 (s's) and each C2 row (q0²) − 4 (q0 s) + 4 (s²); with the f64 map
    /// they carry the midpoint's rounding as extra terms, which the snap removes without
    /// moving any coefficient by more than SNAP (1e-12) of the row's largest.
    #[test]
    fn snapped_rows_of_an_edge_pair_are_collinear() {
        // Coordinates whose midpoint does not round-trip (as in beta's tests).
        let (pi, pj) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.7, -0.1, 0.35));
        let (q0, q1) = (DVec3::new(0.41, 0.47, 0.9), DVec3::new(0.43, 0.13, -0.3));
        let s = 0.5 * (q0 + q1);
        let tet = |apex: DVec3, gid: u32| HullTet {
            gid: [0, 1, gid, 4],
            pts: [pi, pj, apex, s],
            role: Role::Edge,
            element: 0,
            triangle: 0,
            side: Side::Outer,
        };
        let tets = [tet(q0, 2), tet(q1, 3)];
        let rows = |mode| {
            let sys = assemble_with(&tets, 2, mode).unwrap();
            sys.equations
                .iter()
                .map(|e| {
                    let mut c: Vec<f64> = e.terms.iter().map(|t| t.1).collect();
                    c.sort_by(f64::total_cmp);
                    c
                })
                .collect::<Vec<_>>()
        };
        let snapped = rows(FaceBeta::Snapped);
        // 15 C1 rows (degree-4 face indices) and 10 C2 rows (degree 3).
        assert_eq!(snapped.len(), 25);
        let (c1, c2) = (vec![-2.0, 1.0, 1.0], vec![-4.0, -1.0, 1.0, 4.0]);
        assert_eq!(snapped.iter().filter(|r| **r == c1).count(), 15);
        assert_eq!(snapped.iter().filter(|r| **r == c2).count(), 10);
        let plain = rows(FaceBeta::F64);
        let extra = plain.iter().filter(|r| r.len() > 4).count();
        assert!(extra > 0, "the f64 rows should carry the rounding's terms");
        for (p, q) in plain.iter().zip(&snapped) {
            // The same rows up to terms below SNAP (1e-12) of the largest, 4.
            let kept: Vec<f64> = p.iter().copied().filter(|c| c.abs() > 4e-12).collect();
            assert_eq!(kept.len(), q.len(), "{p:?} vs {q:?}");
            for (a, b) in kept.iter().zip(q) {
                assert!((a - b).abs() <= 4e-12, "{p:?} vs {q:?}");
            }
        }
    }

    /// A group of three edge-middle slots over T's points 0–3 (`np` = 10) and two rows, of
    /// which `x` meets only the first.
    fn two_row_group() -> (Group, Vec<u128>) {
        let keys = vec![
            key(&[0, 1, 20, 21], [2, 2, 1, 0]),
            key(&[1, 2, 20, 21], [2, 2, 1, 0]),
            key(&[2, 3, 20, 21], [2, 2, 1, 0]),
        ];
        let g = Group {
            m: 2,
            unk: vec![0, 1, 2],
            eqs: vec![0, 1],
            col: (0..3).map(|j| (j as u32, j)).collect(),
            rows: vec![vec![(0, 1.0), (1, -1.0)], vec![(2, 1.0)]],
            c: vec![0.0, 1.0],
            tgt: vec![0.0; 3],
            scale: 1.0,
            reach: 1.0,
            parallel: false,
        };
        (g, keys)
    }

    /// The weighted least change against its closed form: for one row a·x = c, the x closest to
    /// t in Σ w_j² (x_j − t_j)² is t + W⁻² a (c − a·t) / (aᵀ W⁻² a); and a larger weight moves
    /// its unknown less.
    #[test]
    fn a_weighted_least_change_moves_the_heavy_unknowns_less() {
        let a = [1.0, 2.0, -1.0, 0.5];
        let rows = vec![a.iter().enumerate().map(|(j, &k)| (j, k)).collect()];
        let t = [0.3, -0.2, 0.1, 0.7];
        let c = [1.5];
        let w = [1.0, 10.0, 3.0, 1.0];
        let sol = solve_rows_weighted(&rows, &c, &t, &w, 1.0, None, None);
        let at: f64 = a.iter().zip(&t).map(|(a, t)| a * t).sum();
        let den: f64 = a.iter().zip(&w).map(|(a, w)| a * a / (w * w)).sum();
        for j in 0..4 {
            let want = t[j] + a[j] / (w[j] * w[j]) * (c[0] - at) / den;
            // A dense solve of a 1 × 4 system: rounding of a few products of order 1.
            assert!(
                (sol.x[j] - want).abs() < 1e-14,
                "x[{j}] {} vs {want}",
                sol.x[j]
            );
        }
        assert!(sol.residual < 1e-14);
        // Weights all 1: the plain least change.
        let plain = solve_rows(&rows, 4, &c, &t, 1.0);
        let even = solve_rows_weighted(&rows, &c, &t, &[1.0; 4], 1.0, None, None);
        assert_eq!(plain.x, even.x);
        // The heavy unknown (w = 10, a = 2) moves less than the light one of the same sign
        // (w = 1, a = 1) though its coefficient is larger.
        assert!((sol.x[1] - t[1]).abs() < (sol.x[0] - t[0]).abs());
    }

    #[test]
    fn a_large_group_names_the_points_of_its_unmet_rows_only() {
        let (g, keys) = two_row_group();
        // Row 0 (slots 0, 1: points 0, 1, 2) is met; row 1 (slot 2: points 2, 3) is missed by
        // 0.5, far above the 1e-9 of `consistent`.
        let x = [0.25, 0.25, 0.5];
        assert_eq!(unmet_points(&g, &x, 1, 10, &keys), vec![2, 3]);
        // Met within 1e-9 × scale: no row is unmet, so every point is named (the caller only
        // asks for a group that `consistent` rejected, e.g. for a non-finite weight).
        let x = [0.25, 0.25, 1.0 + 1e-12];
        assert_eq!(unmet_points(&g, &x, 1, 10, &keys), vec![0, 1, 2, 3]);
        // A non-finite solution names every point.
        let x = [f64::NAN, 0.0, 1.0];
        assert_eq!(unmet_points(&g, &x, 1, 10, &keys), vec![0, 1, 2, 3]);
    }

    #[test]
    fn groups_beyond_the_factor_limits_go_to_the_supernodal_factor_or_are_left_unsolved() {
        // A chain x_i - x_{i+1} = 1: one sparse group whose factor has 2n - 1 entries.
        let n = 50;
        let rows: Vec<sparse::Row> = (0..n - 1).map(|i| vec![(i, 1.0), (i + 1, -1.0)]).collect();
        let c = vec![1.0; n - 1];
        let tgt = vec![0.0; n];
        let big = usize::MAX;
        let solved = solve_sparse(&rows, n, &c, &tgt, 1e-13, (1000, 1000, big), None, None);
        // Solved: the chain's rows hold to rounding (unit coefficients, values up to 25).
        assert!(solved.residual < 1e-12, "{}", solved.residual);
        assert!(consistent(&solved, 1.0));
        let entries = cholesky::Ordering::of(&rows, n).entries();
        for limits in [(n - 2, 1000), (1000, entries - 1)] {
            // Beyond the in-house factor: the supernodal one meets the same rows.
            let (r, e) = limits;
            let other = solve_sparse(&rows, n, &c, &tgt, 1e-13, (r, e, big), None, None);
            assert!(other.residual < 1e-12, "{limits:?}: {}", other.residual);
            for (a, b) in other.x.iter().zip(&solved.x) {
                // The same closest solution; values up to 25, rounding of 49 unit steps.
                assert!((a - b).abs() < 1e-12, "{a} vs {b}");
            }
            // Beyond both: left unsolved.
            let left = solve_sparse(&rows, n, &c, &tgt, 1e-13, (r, e, 10), None, None);
            assert_eq!(left.residual, f64::INFINITY, "{limits:?}");
            assert!(!consistent(&left, 1.0));
        }
        let fits = solve_sparse(&rows, n, &c, &tgt, 1e-13, (n - 1, entries, 10), None, None);
        assert!(fits.residual < 1e-12);
    }

    #[test]
    fn long_point_lists_are_cut_in_messages() {
        assert_eq!(brief(&[3, 5]), "[3, 5]");
        let many: Vec<u32> = (0..20).collect();
        assert_eq!(
            brief(&many),
            "[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, … (20 points)]"
        );
    }
}
