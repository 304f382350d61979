//! C¹ cubic A-patches on the inner simplicial hull (Bajaj, Chen, Xu 1994, §6–7).
//!
//! Input: a smoothable simplicial hull ([`SimplicialHull`], from [`crate::hull::inner`] or a
//! test hull). Output: a [`PatchComplex`] (scheme `cubic-c1`) with one cubic per face
//! tetrahedron (`Role::Face`, tetrahedron [v0 v1 v2 q], element = the hull triangle's input
//! element, j-vertex 3 = the apex) and per edge tetrahedron (`Role::Edge`, [p_i p_j q s],
//! element = the hull edge, single sheeted between its opposite edges [p_i p_j] and [q s]).
//! The surface passes through every point of T with normal n, and approximates the polyhedron
//! (corners are cut) rather than interpolating its vertices. How each weight is fixed, and by
//! which equation, is tabled in [`weights`].
//! Before the weights, [`prepare_hull`] completes L-U pairs ([`sided`]) and moves apexes that
//! lie beyond a tangent plane of their triangle to their own side ([`tangent`]).
//!
//! Scene usage (the `[scheme]` table):
//! ```toml
//! [scheme]
//! type = "cubic-c1"
//! alpha = 0.5            # pseudo-centroid C0 = αV + (1−α)V̄ of non-trihedral vertices (§7.1)
//! level = 0.5            # where the surface crosses centroid → apex in face tetrahedra (§7.1)
//! center = 1.0           # number 2 weights: this × the quadratic-precision value
//! levels = { "7" = 0.9 } # per input element (vertex) overrides of `level` (§7 free weights)
//! free = "fair"          # numbers 4 and 6: "fair" (default without `level`) or "level"
//! ```
//!
//! Free weights (issue 7): by default the numbers 4 and 6 of every face tetrahedron standing
//! on a pseudo-centroid (a non-trihedral corner, where the apex is a construction of the hull)
//! start from the fair target of [`fair`] (the blend of the quadratic Taylor polynomials at T's
//! points) instead of the `level` rule, which ties the bulge of each triangle to its apex's
//! distance and made the surfaces lumpy; trihedral corner triangles (apex = the polyhedron's
//! vertex, §7.1's shape control) and elements in `levels` keep the level rule, and a scene that
//! sets `level` gets the level rule everywhere. [`fairness`] measures the result.

pub mod fair;
pub mod fairness;
pub mod flat;
pub mod pocket;
pub mod sided;
pub mod tangent;
pub mod weights;

use crate::complex::{Patch, PatchComplex, Role};
use crate::error::{Error, Result};
use crate::hull::inner::InnerOptions;
use crate::hull::simplicial::{Side, SimplicialHull};
use crate::mesh::Mesh;
use anyhow::{anyhow, Context};
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;
use weights::{bary_in, e3, gradient_weight, ix, level_height, level_mean, EdgeBlossom};

/// Largest group of coupled flat-edge equations solved (a dense m×m elimination).
pub const MAX_FLAT_GROUP: usize = 1500;

/// Shape control of the cubic scheme (§7.1 and the free weights of §6).
#[derive(Clone, Debug, PartialEq)]
pub struct CubicOptions {
    /// Default parameter in (0, 1) at which F vanishes on the segment from a face
    /// tetrahedron's base centroid to its apex: small values cut the corners deeply (the
    /// surface near T), values near 1 reach toward the apex (the polyhedron's corner for
    /// trihedral vertices).
    pub level: f64,
    /// Per input element (the hull triangle's `element`) overrides of `level`.
    pub levels: HashMap<u32, f64>,
    /// Scale of the number 2 weights relative to the quadratic-precision choice (1 = a
    /// quadratic is reproduced on T's triangles; 0 = flatter, > 1 = rounder).
    pub center: f64,
    /// |∇F| at the points of T (the weights scale with it; the surface does not).
    pub gradient_scale: f64,
    /// Give single-sided triangles of T that are not convex for their side the partner
    /// tetrahedron of an L-U pair (Definition 3.6 (4); [`sided`]) before building. Without it the
    /// surface leaves the hull through their bases (holes).
    pub complete_lu_pairs: bool,
    /// How the free weights of numbers 4 and 6 are chosen (see the module documentation).
    pub free: FreeWeights,
    /// Move apexes that lie beyond a tangent plane at one of their triangle's points (allowed
    /// for L-U pairs by Definition 3.5) to their own side of all three ([`tangent`]). Without
    /// it the surface leaves the hull through the edge tetrahedra's outer faces there (holes).
    pub contain_tangents: bool,
    /// After those changes, run the hull's apex search again on what they made overlap
    /// ([`crate::hull::inner::search_apexes`], keeping this scheme's tangent slopes); set from
    /// the hull's `apex_search` key.
    pub search_apexes: bool,
}

impl Default for CubicOptions {
    fn default() -> Self {
        CubicOptions {
            level: 0.5,
            levels: HashMap::new(),
            center: 1.0,
            gradient_scale: 1.0,
            complete_lu_pairs: true,
            contain_tangents: true,
            free: FreeWeights::Fair,
            search_apexes: false,
        }
    }
}

/// The choice of the free weights a_e_k+2e_q (number 4) and F(q) (number 6) of the face
/// tetrahedra, before the sign conditions raise them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FreeWeights {
    /// From the fair target ([`fair::FairTarget`]) on face tetrahedra standing on a
    /// pseudo-centroid, the level rule elsewhere (trihedral corners, elements in `levels`).
    Fair,
    /// The level rule everywhere: one value per face tetrahedron putting the zero of F at
    /// `level` on the segment from the base's centroid to the apex (§7.1).
    Level,
}

/// What [`build`] made, besides the complex.
#[derive(Clone, Debug, PartialEq)]
pub struct CubicBuild {
    /// The patches.
    pub complex: PatchComplex,
    /// Edges of T where the adjacent triangles are coplanar (the paper's singular case): the
    /// number 2 weights of the triangles there are adjusted ([`flat`]).
    pub flat_edges: usize,
    /// Flat-edge equations in groups too large to solve (larger than [`MAX_FLAT_GROUP`]); C¹
    /// may fail there.
    pub flat_unsolved: usize,
    /// Number 4 / 6 weights raised above the `level` rule for the sign conditions.
    pub raised: usize,
    /// Edge tetrahedra whose midpoint s is not on the apex side of the face tetrahedron's base
    /// (the sign conditions cannot be enforced there; `check` measures the sheets).
    pub unsigned: usize,
    /// Triangles of T given a partner apex ([`sided::complete_lu_pairs`]).
    pub lu_completed: Vec<usize>,
    /// Constraints on number 2 weights against pockets next to edges ([`pocket`]).
    pub pocket_constraints: usize,
    /// Apexes moved to their side of their triangle's tangent planes ([`tangent`]), as
    /// (triangle, side).
    pub tangent_moved: Vec<(usize, Side)>,
    /// Apexes beyond a tangent plane that could not be moved (a vertex normal nearly in the
    /// triangle's plane).
    pub tangent_stuck: usize,
    /// Face tetrahedra whose numbers 4 and 6 started from the fair target ([`FreeWeights::Fair`]).
    pub fair_faces: usize,
}

/// Weights of the face tetrahedron of one (triangle, side).
struct FaceWeights {
    w: [f64; 20],
}

/// The hull the patches are built on ([`prepare_hull`]) and what was changed.
#[derive(Clone, Debug)]
pub struct PreparedHull {
    /// The input hull with L-U partners added and apexes moved.
    pub hull: SimplicialHull,
    /// Triangles given a partner apex ([`sided::complete_lu_pairs`]).
    pub lu_completed: Vec<usize>,
    /// Apexes moved to their side of the tangent planes ([`tangent::contain_tangents`]).
    pub tangent_moved: Vec<(usize, Side)>,
    /// Apexes beyond a tangent plane that could not be moved.
    pub tangent_stuck: usize,
    /// The apex search's log ([`CubicOptions::search_apexes`]; empty when off or not kept).
    pub reapex: crate::hull::inner::reapex::Search,
}

/// What [`prepare_hull`] changed, by step (counts; the hull itself left out), for reports:
/// `apatch check`'s `cubic steps` line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PrepareSteps {
    /// Triangles given a partner apex ([`sided::complete_lu_pairs`]).
    pub lu_completed: usize,
    /// Apexes moved to their side of the tangent planes ([`tangent::contain_tangents`]).
    pub tangent_moved: usize,
    /// Apexes beyond a tangent plane that could not be moved.
    pub tangent_stuck: usize,
    /// The second apex search's log, on the apexes these moves made overlap.
    pub reapex: crate::hull::inner::reapex::Search,
}

impl PreparedHull {
    /// The counts of [`PrepareSteps`].
    #[must_use]
    pub fn steps(&self) -> PrepareSteps {
        PrepareSteps {
            lu_completed: self.lu_completed.len(),
            tangent_moved: self.tangent_moved.len(),
            tangent_stuck: self.tangent_stuck,
            reapex: self.reapex.clone(),
        }
    }
}

/// The changes the cubic scheme makes to a hull's apexes before building (as `options` ask):
/// L-U partners for single-sided triangles not convex for their side ([`sided`]), then apexes
/// moved to their side of their triangle's tangent planes ([`tangent`]), then, with
/// `search_apexes`, the hull's apex search on what those moves made overlap.
/// `hull::inner::verify` applies to the result as to any hull.
#[must_use]
pub fn prepare_hull(hull: &SimplicialHull, options: &CubicOptions) -> PreparedHull {
    let (completed, lu_completed) = if options.complete_lu_pairs {
        sided::complete_lu_pairs(hull)
    } else {
        (hull.clone(), Vec::new())
    };
    let (hull, tangent_moved, tangent_stuck) = if options.contain_tangents {
        tangent::contain_tangents(&completed)
    } else {
        (completed, Vec::new(), 0)
    };
    let (hull, reapex) = if options.search_apexes {
        crate::hull::inner::search_apexes(hull, true)
    } else {
        (hull, Default::default())
    };
    PreparedHull {
        hull,
        lu_completed,
        tangent_moved,
        tangent_stuck,
        reapex,
    }
}

/// Builds the cubic C¹ complex on `hull`.
///
/// # Errors
/// A hull edge shared by more than three triangles, non-finite data, or degenerate tetrahedra
/// (each named).
pub fn build(hull: &SimplicialHull, options: &CubicOptions) -> Result<PatchComplex> {
    build_full(hull, options).map(|b| b.complex)
}

/// [`build`] with its counters.
///
/// # Errors
/// As [`build`].
pub fn build_full(hull: &SimplicialHull, options: &CubicOptions) -> Result<CubicBuild> {
    validate(hull, options)?;
    let prepared = prepare_hull(hull, options);
    let hull = &prepared.hull;
    let c = options.gradient_scale;
    let p = &hull.points;
    let g: Vec<DVec3> = hull.normals.iter().map(|n| c * *n).collect();
    let edges = hull.edges().map_err(Error::Invalid)?;
    let edge_tets = hull.edge_tets().map_err(Error::Invalid)?;
    let nt = hull.triangles.len();
    let mut out = CubicBuild {
        complex: PatchComplex::new("cubic-c1"),
        flat_edges: 0,
        flat_unsolved: 0,
        raised: 0,
        unsigned: 0,
        lu_completed: prepared.lu_completed,
        pocket_constraints: 0,
        tangent_moved: prepared.tangent_moved,
        tangent_stuck: prepared.tangent_stuck,
        fair_faces: 0,
    };

    // Number 2: a_1110 per triangle (shared by both sides of an L-U pair), quadratic precision.
    let mut center: Vec<f64> = hull
        .triangles
        .iter()
        .map(|tri| {
            let mut s = 0.0;
            for k in 0..3 {
                for l in 0..3 {
                    if k != l {
                        let (a, b) = (tri[k] as usize, tri[l] as usize);
                        s += gradient_weight(p[a], g[a], p[b]);
                    }
                }
            }
            options.center * s / 4.0
        })
        .collect();
    let target = (options.free == FreeWeights::Fair).then(|| fair::FairTarget::new(hull, c));

    // Number 2 where T is flat at an edge: the least change making the blossoms exist.
    let mut flat_eqs = Vec::new();
    for e in &edges {
        let [t0, t1] = e.faces;
        if t1 == u32::MAX {
            continue;
        }
        let [i, j] = e.v.map(|v| v as usize);
        let third = |t: u32| {
            hull.triangles[t as usize]
                .iter()
                .map(|&v| v as usize)
                .find(|&v| v != i && v != j)
                .unwrap_or(i)
        };
        let (m0, m1) = (p[third(t0)], p[third(t1)]);
        if let Some((a, b)) = flat::flat_coords(p[i], p[j], m0, m1) {
            let ai = gradient_weight(p[i], g[i], p[j]);
            let aj = gradient_weight(p[j], g[j], p[i]);
            // The edge blossom takes its slope across the plane from the prior (see the
            // blossom fit below): p_m' lies off the plane by up to the flat tolerance, and
            // A(p_m') includes that slope times its offset (the nut: 1e-10, a C¹ jump of 1e-9).
            let across = (p[j] - p[i])
                .cross(m0 - p[i])
                .try_normalize()
                .map_or(0.0, |n| ((g[i] + g[j]) / 6.0).dot(n) * n.dot(m1 - p[i]));
            flat_eqs.push(flat::FlatEquation {
                from: t0 as usize,
                to: t1 as usize,
                b,
                rhs: (1.0 - a - b) * ai + a * aj + across,
            });
        }
    }
    out.flat_edges = flat_eqs.len();
    out.flat_unsolved = flat::adjust(&mut center, &flat_eqs, MAX_FLAT_GROUP);

    // Number 2 next to edges on the side they do not ask for: no pocket of F there.
    let mut frozen = vec![false; nt];
    for eq in &flat_eqs {
        frozen[eq.from] = true;
        frozen[eq.to] = true;
    }
    out.pocket_constraints = pocket::clear_pockets(hull, &edges, &g, &frozen, &mut center);

    // Number 3: the edge blossoms.
    let mut blossom: HashMap<(u32, u32), EdgeBlossom> = HashMap::new();
    for e in &edges {
        let [i, j] = e.v;
        let (pi, pj) = (p[i as usize], p[j as usize]);
        let mut known = vec![(pj, gradient_weight(pj, g[j as usize], pi))];
        for &t in &e.faces {
            if t != u32::MAX {
                let tri = hull.triangles[t as usize];
                let m = tri.iter().copied().find(|&v| v != i && v != j).unwrap_or(i);
                known.push((p[m as usize], center[t as usize]));
            }
        }
        let prior = (g[i as usize] + g[j as usize]) / 6.0;
        let b = EdgeBlossom::fit(pi, gradient_weight(pi, g[i as usize], pj), &known, prior);
        blossom.insert((i.min(j), i.max(j)), b);
    }
    let edge_blossom = |a: u32, b: u32| blossom[&(a.min(b), a.max(b))];

    // Face tetrahedra weights up to level 1, and the level rule for numbers 4 and 6.
    let mut faces: Vec<[Option<FaceWeights>; 2]> = (0..nt).map(|_| [None, None]).collect();
    for (t, tri) in hull.triangles.iter().enumerate() {
        for side in Side::BOTH {
            let Some(tet) = hull.face_tet(t, side) else {
                continue;
            };
            let sigma = sign(side);
            let q = tet[3];
            let mut w = [0.0; 20];
            for k in 0..3 {
                let gk = g[tri[k] as usize];
                for l in 0..4 {
                    if l != k {
                        w[ix(e3(k, k, l))] = gradient_weight(tet[k], gk, tet[l]);
                    }
                }
            }
            w[ix([1, 1, 1, 0])] = center[t];
            for (k, l) in [(0, 1), (1, 2), (0, 2)] {
                w[ix(e3(k, l, 3))] = edge_blossom(tri[k], tri[l]).at(q);
            }
            let level = options
                .levels
                .get(&hull.element[t])
                .copied()
                .unwrap_or(options.level);
            let h = level_height(level_mean(&w, 0), level_mean(&w, 1), level);
            let base = (tet[0] + tet[1] + tet[2]) / 3.0;
            let h_min = 1e-3 * c * (q - base).length();
            let h = sigma * (sigma * h).max(h_min).max(j_line_height(&w, sigma));
            for k in 0..3 {
                w[ix(e3(k, 3, 3))] = h;
            }
            w[ix([0, 0, 0, 3])] = h;
            // The fair target where the apex is the hull's construction (a pseudo-centroid's
            // triangles), each weight kept at least as high (σ-wise) as the level rule's
            // floors: the j-line bound (which holds for any levels ≥ 2 above it) and h_min.
            let pseudo = tri.iter().any(|&v| {
                matches!(
                    hull.origins.get(v as usize),
                    Some(crate::hull::simplicial::PointOrigin::PseudoCentroid { .. })
                )
            });
            if let (Some(target), true) = (
                &target,
                pseudo && !options.levels.contains_key(&hull.element[t]),
            ) {
                out.fair_faces += 1;
                let floor = h_min.max(j_line_height(&w, sigma));
                for k in 0..3 {
                    let pts: Vec<(u32, u8)> = (0..3).map(|l| (tri[l], u8::from(l == k))).collect();
                    let v = target.weight([tet[k], q, q], &pts);
                    w[ix(e3(k, 3, 3))] = sigma * (sigma * v).max(floor);
                }
                let v = target.weight([q, q, q], &tri.map(|l| (l, 0)));
                w[ix([0, 0, 0, 3])] = sigma * (sigma * v).max(floor);
            }
            faces[t][side as usize] = Some(FaceWeights { w });
        }
    }

    // Sign conditions through the edge tetrahedra: raise number 4 (for w_1011, w_0111 ≥ 0)
    // and then number 6 (for w_0021 ≥ 0); signs mirrored on the inner side.
    let local = |t: usize, v: u32| {
        hull.triangles[t]
            .iter()
            .position(|&x| x == v)
            .expect("edge point in its triangle")
    };
    let betas: Vec<[f64; 4]> = edge_tets
        .iter()
        .map(|et| {
            let tet = hull.face_tet(et.face as usize, et.side).expect("face tet");
            bary_in(tet, et.tet[3]).ok_or_else(|| {
                Error::Invalid(format!(
                    "face tetrahedron of hull triangle {} is degenerate",
                    et.face
                ))
            })
        })
        .collect::<Result<_>>()?;
    for pass in 0..2 {
        for (et, beta) in edge_tets.iter().zip(&betas) {
            let t = et.face as usize;
            let sigma = sign(et.side);
            let e = edges[et.edge as usize];
            let (li, lj) = (local(t, e.v[0]), local(t, e.v[1]));
            let lm = 3 - li - lj;
            let fw = faces[t][et.side as usize].as_mut().expect("face weights");
            let w = &mut fw.w;
            if beta[3] <= 0.0 {
                if pass == 0 {
                    out.unsigned += 1;
                }
                continue;
            }
            if pass == 0 {
                for (k, o) in [(li, lj), (lj, li)] {
                    // (2.8): w_(e_k+e_q+e_s) = β_k a_2e_k+e_q + β_o a_(k,o,q) + β_m a_(k,m,q)
                    //                          + β_q a_e_k+2e_q.
                    let rest = beta[k] * w[ix(e3(k, k, 3))]
                        + beta[o] * w[ix(e3(k, o, 3))]
                        + beta[lm] * w[ix(e3(k, lm, 3))];
                    let need = -sigma * rest / beta[3];
                    let cur = &mut w[ix(e3(k, 3, 3))];
                    if sigma * *cur < need {
                        *cur = sigma * need;
                        out.raised += 1;
                    }
                }
            } else {
                // (2.8): w_0021 = Σ_k β_k a_e_k+2e_q + β_q F(q).
                let rest: f64 = (0..3).map(|k| beta[k] * w[ix(e3(k, 3, 3))]).sum();
                let need = -sigma * rest / beta[3];
                let cur = &mut w[ix([0, 0, 0, 3])];
                if sigma * *cur < need {
                    *cur = sigma * need;
                    out.raised += 1;
                }
            }
        }
    }

    // Face patches.
    for (t, sides) in faces.iter().enumerate() {
        for side in Side::BOTH {
            if let Some(fw) = &sides[side as usize] {
                let tet = hull.face_tet(t, side).expect("face tet");
                out.complex
                    .patches
                    .push(patch(tet, &fw.w, Role::Face, hull.element[t]));
            }
        }
    }

    // Edge tetrahedra, in pairs (edge_tets lists both of a pair together).
    let mut own: Vec<[f64; 20]> = Vec::with_capacity(edge_tets.len());
    for (et, beta) in edge_tets.iter().zip(&betas) {
        let t = et.face as usize;
        let e = edges[et.edge as usize];
        let (i, j) = (e.v[0], e.v[1]);
        let (li, lj) = (local(t, i), local(t, j));
        let lm = 3 - li - lj;
        let a = &faces[t][et.side as usize].as_ref().expect("face weights").w;
        let [pi, pj, q, s] = et.tet;
        let (gi, gj) = (g[i as usize], g[j as usize]);
        let blossom = edge_blossom(i, j);
        let mut w = [0.0; 20];
        // Number 1 (2.5).
        w[ix([2, 1, 0, 0])] = gradient_weight(pi, gi, pj);
        w[ix([1, 2, 0, 0])] = gradient_weight(pj, gj, pi);
        w[ix([2, 0, 1, 0])] = gradient_weight(pi, gi, q);
        w[ix([0, 2, 1, 0])] = gradient_weight(pj, gj, q);
        w[ix([2, 0, 0, 1])] = gradient_weight(pi, gi, s);
        w[ix([0, 2, 0, 1])] = gradient_weight(pj, gj, s);
        // Number 3: the edge blossom (C⁰ with the face tetrahedron, (2.10) with the partner).
        w[ix([1, 1, 1, 0])] = blossom.at(q);
        w[ix([1, 1, 0, 1])] = blossom.at(s);
        // C⁰ with the face tetrahedron: its level-2 and apex weights.
        w[ix([1, 0, 2, 0])] = a[ix(e3(li, 3, 3))];
        w[ix([0, 1, 2, 0])] = a[ix(e3(lj, 3, 3))];
        w[ix([0, 0, 3, 0])] = a[ix([0, 0, 0, 3])];
        // Number 5 (2.8).
        for (k, o, mu) in [(li, lj, [1, 0, 1, 1]), (lj, li, [0, 1, 1, 1])] {
            w[ix(mu)] = beta[k] * a[ix(e3(k, k, 3))]
                + beta[o] * a[ix(e3(k, o, 3))]
                + beta[lm] * a[ix(e3(k, lm, 3))]
                + beta[3] * a[ix(e3(k, 3, 3))];
        }
        // Number 7 (2.8).
        w[ix([0, 0, 2, 1])] = (0..3).map(|k| beta[k] * a[ix(e3(k, 3, 3))]).sum::<f64>()
            + beta[3] * a[ix([0, 0, 0, 3])];
        // Free: w_0012 = w_0021.
        w[ix([0, 0, 1, 2])] = w[ix([0, 0, 2, 1])];
        own.push(w);
    }
    // (2.10) across [p_i p_j s]: averages over the pair (edge_tets holds pairs consecutively).
    let mut k = 0;
    while k < own.len() {
        let paired = k + 1 < own.len()
            && edge_tets[k + 1].edge == edge_tets[k].edge
            && edge_tets[k + 1].side == edge_tets[k].side;
        let (a, b) = if paired { (k, k + 1) } else { (k, k) };
        for (mu, from) in [
            ([1, 0, 0, 2], [1, 0, 1, 1]),
            ([0, 1, 0, 2], [0, 1, 1, 1]),
            ([0, 0, 0, 3], [0, 0, 1, 2]),
        ] {
            let avg = 0.5 * (own[a][ix(from)] + own[b][ix(from)]);
            own[a][ix(mu)] = avg;
            own[b][ix(mu)] = avg;
        }
        k += if paired { 2 } else { 1 };
    }
    for (et, w) in edge_tets.iter().zip(&own) {
        out.complex
            .patches
            .push(patch(et.tet, w, Role::Edge, et.edge));
    }

    out.complex.vertices = p.iter().map(|x| x.to_array()).collect();
    out.complex.normals = hull.normals.iter().map(|x| x.to_array()).collect();
    for (n, patch) in out.complex.patches.iter().enumerate() {
        crate::complex_io::validate_patch(patch).map_err(|m| {
            Error::Invalid(format!("cubic-c1 patch {n} ({}): {m}", patch.role.name()))
        })?;
    }
    Ok(out)
}

/// Steps per edge of the base lattice [`j_line_height`] bounds over.
pub const J_LINE_RES: usize = 12;

/// Smallest σ·h (all level-2 and apex weights = h) for which no line from the apex to a base
/// lattice point meets F = 0 twice, where the base is not one-signed (an L-U pair's nonconvex
/// triangle): on the line, F has Bernstein coefficients (F(b), B(b, b, q), h, h); where F(b)
/// has the apex's sign and B(b, b, q) the other, F/(1 − t) ≥ F(b)(1 − t)² + 3B t(1 − t) +
/// 3h t², which stays one-signed when h ≥ 0.75 B² / F(b). Base points with |F(b)| below 1% of
/// the largest base weight (where the surface meets the base) are skipped.
/// The bound is taken over the base lattice with [`J_LINE_RES`] steps per edge (a sampled
/// sufficient condition, like `check`'s lattice of j-lines).
fn j_line_height(w: &[f64; 20], sigma: f64) -> f64 {
    const RES: usize = J_LINE_RES;
    // The weights in the lattice sums' order, looked up once.
    let mut w0 = [0.0; 27];
    let mut w1 = [0.0; 9];
    for k in 0..3 {
        for l in 0..3 {
            for m in 0..3 {
                w0[9 * k + 3 * l + m] = w[ix(e3(k, l, m))];
            }
            w1[3 * k + l] = w[ix(e3(k, l, 3))];
        }
    }
    // By the convex hull property of Bernstein coefficients, F(b) can only have the apex's
    // sign where some base weight has it, and B(b, b, q) only the other sign where some
    // λ3 = 1 weight has; without both no lattice point can raise the bound (this skips the
    // lattice on the ordinary, one-signed bases: same result, far less work).
    if !w0.iter().any(|&x| sigma * x > 0.0) || !w1.iter().any(|&x| sigma * x < 0.0) {
        return 0.0;
    }
    let base_max = (0..3)
        .flat_map(|k| (0..3).map(move |l| (k, l)))
        .map(|(k, l)| w[ix(e3(k, k, l))].abs())
        .fold(w[ix([1, 1, 1, 0])].abs(), f64::max);
    let mut need: f64 = 0.0;
    for i in 0..=RES {
        for j in 0..=RES - i {
            let b = [i as f64, j as f64, (RES - i - j) as f64].map(|x| x / RES as f64);
            let mut c0 = 0.0;
            let mut c1 = 0.0;
            for k in 0..3 {
                for l in 0..3 {
                    for m in 0..3 {
                        c0 += b[k] * b[l] * b[m] * w0[9 * k + 3 * l + m];
                    }
                    c1 += b[k] * b[l] * w1[3 * k + l];
                }
            }
            let (c0, c1) = (sigma * c0, sigma * c1);
            if c0 > 0.01 * base_max && c1 < 0.0 {
                need = need.max(0.75 * c1 * c1 / c0);
            }
        }
    }
    need
}

fn sign(side: Side) -> f64 {
    match side {
        Side::Outer => 1.0,
        Side::Inner => -1.0,
    }
}

fn patch(tet: [DVec3; 4], w: &[f64; 20], role: Role, element: u32) -> Patch {
    Patch {
        tet: tet.map(|v| v.to_array()),
        degree: 3,
        weights: w.to_vec(),
        rational: Vec::new(),
        sheet: crate::complex::SheetRule::Any,
        role,
        element,
        // Face tetrahedra: a j-patch for the apex; edge tetrahedra: single sheeted between
        // [p_i p_j] and [q s] (see `weights`).
        jvertex: (role == Role::Face).then_some(3),
        jedge: (role == Role::Edge).then_some([0, 1]),
    }
}

fn validate(hull: &SimplicialHull, options: &CubicOptions) -> Result<()> {
    let bad_level = |l: f64| !(l > 0.0 && l < 1.0);
    if bad_level(options.level) {
        return Err(Error::Invalid(format!(
            "cubic-c1: level {} is not in (0, 1)",
            options.level
        )));
    }
    if let Some((e, l)) = options.levels.iter().find(|(_, &l)| bad_level(l)) {
        return Err(Error::Invalid(format!(
            "cubic-c1: levels.{e} = {l} is not in (0, 1)"
        )));
    }
    if !(options.center.is_finite() && options.gradient_scale > 0.0) {
        return Err(Error::Invalid(
            "cubic-c1: center must be finite and gradient_scale positive".into(),
        ));
    }
    if hull.normals.len() != hull.points.len()
        || hull.apexes.len() != hull.triangles.len()
        || hull.element.len() != hull.triangles.len()
    {
        return Err(Error::Invalid("cubic-c1: inconsistent hull arrays".into()));
    }
    for (t, tri) in hull.triangles.iter().enumerate() {
        if tri.iter().any(|&v| v as usize >= hull.points.len()) {
            return Err(Error::Invalid(format!(
                "cubic-c1: hull triangle {t} has a point index out of range"
            )));
        }
        if hull.apexes[t].iter().all(Option::is_none) {
            return Err(Error::Invalid(format!(
                "cubic-c1: hull triangle {t} has no face tetrahedron"
            )));
        }
    }
    if let Some(k) = (0..hull.points.len())
        .find(|&k| !(hull.points[k].is_finite() && hull.normals[k].is_finite()))
    {
        return Err(Error::Invalid(format!(
            "cubic-c1: hull point {k} or its normal is not finite"
        )));
    }
    Ok(())
}

/// Reads the scheme options from a scene's `[scheme]` table: the hull's keys
/// ([`InnerOptions::KEYS`]) by [`InnerOptions::from_toml`], and this scheme's `level`, `center`,
/// `gradient_scale`, `levels`, `free` (`"fair"` or `"level"`, [`FreeWeights`]). Without `level`,
/// the hull's `trihedral_level` (in [0, 1]) is used, kept 0.02 away from the bottom and the top
/// (a level of exactly 0 or 1 puts the zero on a boundary of the tetrahedron). A table that sets
/// `level` and not `free` gets [`FreeWeights::Level`].
///
/// # Errors
/// Unknown keys and bad values, naming the scene file and the key.
pub fn options_from_toml(
    table: &toml::Table,
    scene: &Path,
) -> anyhow::Result<(CubicOptions, InnerOptions)> {
    let inner = InnerOptions::from_toml(table, scene)?;
    let mut o = CubicOptions {
        level: inner.trihedral_level.clamp(0.02, 0.98),
        search_apexes: inner.apex_search,
        ..CubicOptions::default()
    };
    let bad = |m: String| anyhow!("{}: {m}", scene.display());
    let num = |k: &str, v: &toml::Value| {
        v.as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .ok_or_else(|| {
                bad(format!(
                    "`scheme.{k}`: expected a number, found {}",
                    v.type_str()
                ))
            })
    };
    for (k, v) in table {
        match k.as_str() {
            "type" => {}
            k if InnerOptions::KEYS.contains(&k) => {}
            "level" => o.level = num(k, v)?,
            "center" => o.center = num(k, v)?,
            "gradient_scale" => o.gradient_scale = num(k, v)?,
            "free" => {
                o.free = match v.as_str() {
                    Some("fair") => FreeWeights::Fair,
                    Some("level") => FreeWeights::Level,
                    _ => {
                        return Err(bad(format!(
                            "`scheme.free`: expected \"fair\" or \"level\", found {v}"
                        )))
                    }
                };
            }
            "levels" => {
                let t = v.as_table().ok_or_else(|| {
                    bad("`scheme.levels` must be a table { \"element\" = level }".into())
                })?;
                for (e, l) in t {
                    let id: u32 = e.parse().map_err(|_| {
                        bad(format!("`scheme.levels`: key `{e}` is not an element id"))
                    })?;
                    o.levels.insert(id, num(&format!("levels.{e}"), l)?);
                }
            }
            _ => {
                return Err(bad(format!(
                    "unknown key `scheme.{k}` (cubic-c1 has {}, level, center, gradient_scale, \
                     levels, free)",
                    InnerOptions::KEYS.join(", ")
                )))
            }
        }
    }
    // A scene that asks for a `level` asks for the level rule (§7.1's shape control), unless it
    // names `free` itself.
    if table.contains_key("level") && !table.contains_key("free") {
        o.free = FreeWeights::Level;
    }
    Ok((o, inner))
}

/// Builds the `cubic-c1` patch complex of `mesh` with unit vertex normals `normals`; `scheme` is
/// the scene's `[scheme]` table (its keys are this scheme's options), `scene` the scene file
/// named in errors.
///
/// # Errors
/// Unknown or bad options, and meshes the scheme cannot build, naming the file and element.
pub fn build_from_scene(
    mesh: &Mesh,
    normals: &[DVec3],
    scheme: &toml::Table,
    scene: &Path,
) -> anyhow::Result<PatchComplex> {
    let (options, inner) = options_from_toml(scheme, scene)?;
    let hull = crate::hull::inner::build(mesh, normals, &inner)
        .with_context(|| format!("{}", scene.display()))?;
    build(&hull, &options).with_context(|| format!("{}", scene.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An unknown `[scheme]` key is an error naming the key and listing every key the scheme
    /// accepts, the hull's included (they were listed by hand and missed `planar_tolerance`).
    #[test]
    fn unknown_key_error_lists_every_accepted_key() {
        let table: toml::Table = toml::from_str("levl = 0.4").unwrap();
        let err = options_from_toml(&table, Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("scheme.levl"), "{err}");
        for k in InnerOptions::KEYS
            .iter()
            .chain(&["level", "center", "levels", "free"])
        {
            assert!(err.contains(k), "`{k}` missing from: {err}");
        }
        let quintic =
            crate::scheme::quintic_c2::QuinticOptions::from_toml(&table, Path::new("s.toml"))
                .unwrap_err()
                .to_string();
        for k in InnerOptions::KEYS
            .iter()
            .chain(&["curvature", "hessian_signs"])
        {
            assert!(quintic.contains(k), "`{k}` missing from: {quintic}");
        }
    }

    /// Sign changes of the cubic with Bernstein coefficients `c` sampled at 400 points of
    /// (0, 1) (values within 1e-14 of zero skipped: rounding of weights of size 1).
    fn crossings(c: [f64; 4]) -> usize {
        let mut prev: Option<bool> = None;
        let mut n = 0;
        for i in 1..400 {
            let t = i as f64 / 400.0;
            let s = 1.0 - t;
            let f = c[0] * s * s * s
                + 3.0 * c[1] * s * s * t
                + 3.0 * c[2] * s * t * t
                + c[3] * t * t * t;
            if f.abs() > 1e-14 {
                n += usize::from(prev.is_some_and(|p| p != (f > 0.0)));
                prev = Some(f > 0.0);
            }
        }
        n
    }

    /// A face tetrahedron (outer, σ = +1) whose base is positive (the apex's sign) while its
    /// level-1 weights are negative: with a small apex weight (1e-2) the lines from the apex dip below
    /// zero and come back (two crossings); with h = j_line_height they cross at most once,
    /// checked by sampling every line from the apex to a point of the bound's base lattice
    /// where F is at least 1% of the largest base weight.
    #[test]
    fn j_line_height_keeps_apex_lines_single_crossing() {
        let mut w = [0.0; 20];
        for k in 0..3 {
            for l in 0..3 {
                if k != l {
                    w[ix(e3(k, k, l))] = 1.0;
                }
                w[ix(e3(k, l, 3))] = -1.0;
            }
        }
        w[ix([1, 1, 1, 0])] = 1.0;
        let line = |w: &[f64; 20], h: f64, b: [f64; 3]| {
            let (mut c0, mut c1) = (0.0, 0.0);
            for k in 0..3 {
                for l in 0..3 {
                    for m in 0..3 {
                        c0 += b[k] * b[l] * b[m] * w[ix(e3(k, l, m))];
                    }
                    c1 += b[k] * b[l] * w[ix(e3(k, l, 3))];
                }
            }
            (c0, crossings([c0, c1, h, h]))
        };
        let h = j_line_height(&w, 1.0);
        assert!(h > 0.0);
        let centre = [1.0 / 3.0; 3];
        assert_eq!(line(&w, 1e-2, centre).1, 2);
        let r = J_LINE_RES;
        for i in 0..=r {
            for j in 0..=r - i {
                let b = [i, j, r - i - j].map(|x| x as f64 / r as f64);
                let (f, n) = line(&w, h, b);
                // The promise covers base points with F(b) ≥ 1% of the largest base weight (1
                // here); nearer the surface's meeting with the base it is not made.
                if f >= 0.01 {
                    assert!(n <= 1, "b = {b:?}");
                }
            }
        }
    }
}
