//! The rational C¹ A-patch scheme of Xu, Huang and Bajaj (2001).
//!
//! Input: a triangulation with unit vertex normals. Output: a [`PatchComplex`] (scheme
//! `rational-c1`) with one cubic patch (plus rational terms) per face and edge tetrahedron of the
//! outer hull ([`crate::hull::outer`]), three per side of a nonconvex face, and one planar
//! patch per zero-convex face.
//!
//! Scene usage (the `[scheme]` table):
//! ```toml
//! [scheme]
//! type = "rational-c1"
//! free = "default"            # or "quadric", or { offset = 0.5 }
//! epsilon = 0.05              # hull ε relative to each face's longest edge
//! refine_rounds = 4           # bound on the rounds of butterfly refinement
//! bound_samples = 8           # grid of the promotion sign test (and optional bound seeds)
//! bound_tolerance = 1e-4      # accuracy of the certified lower bounds (× longest edge)
//! bound_margin = 0.001        # f_0003 exceeds its bound by this × the face's longest edge
//! faces = { "12" = { offset = 2.0 }, "40" = "quadric" }   # per input-triangle overrides
//! ```
//!
//! ## Patches
//! - Convex face (positive or negative): `Role::Face`, tetrahedron [p_0 p_1 p_2 u] (or v) in the
//!   triangle's vertex order, the cubic plus the rational term (4.1) on B_1110 with monomials
//!   α_2α_3, α_1α_3, α_1α_2 (one per side face, 1-based as in the paper). Sheet rule
//!   `Shooting { base: [0,1,2], top: [3] }`.
//! - Nonconvex face: per side three `Role::Face` sub-tetrahedra [p_a p_b c u] for the triangle's
//!   edges (a, b) = (0,1), (1,2), (2,0) (c = centroid), polynomial only. Every shooting line of
//!   the whole face tetrahedron from q ∈ [p_a p_b c] to u lies in that sub-tetrahedron, so the
//!   same rule `Shooting { base: [0,1,2], top: [3] }` applies per sub-tetrahedron.
//! - Edge: `Role::Edge`, element = edge index (numbering in [`crate::hull::outer`]),
//!   tetrahedron [p_i p_j u_A u_B] where (p_i, p_j) is the edge's stored orientation and A, B
//!   its first and second triangle; rational terms (4.3) on B_1011 and B_0111 blending by α_3
//!   (A's side face) and α_4 (B's side face). Sheet rule `Shooting { base: [0,1], top: [2,3] }`.
//! - Zero-convex face: `Role::Planar`, degree 1 on [p_0 p_1 p_2 c + ε n_f] with weights
//!   (0, 0, 0, ε): F(x) = (x − c)·n_f, so the surface is the face itself (the base of the
//!   tetrahedron; tracers accept the zero at the entry/exit point).
//!
//! Sign convention: F < 0 inside (opposite the normals), F > 0 outside. The top weight f_0003
//! is positive on the positive side (u) and negative on the negative side (v). The shooting rule
//! of (4.5)–(4.7) also requires F(q) ≤ 0 at the base point for positive-side tetrahedra and
//! F(q) ≥ 0 for negative-side ones, i.e. F(q) and the weight at the top vertex (any top vertex)
//! do not have the same strict sign.
//!
//! ## How the weights are made (deviations from the paper marked)
//! Steps 1–4 as in the paper; the number 2 and 3 weights come from one affine "edge blossom" per
//! mesh edge ([`crate::hull::outer::EdgeBlossom`], the closed form of the directional-derivative
//! interpolation (4.10)–(4.12) and Step 4). Step 5 by the least squares (4.13)/(4.14); for a
//! nonconvex face the Clough–Tocher values (see [`weights::nonconvex_pieces`]). Step 6 lower
//! bounds B_ijk and B_ijkl of Lemma 2.3 as certificates over *every* shooting line
//! ([`cover`]: Bernstein subdivision of the base triangle / the edge tetrahedron's (x, y)
//! square), never below the exact bound and at most `bound_tolerance` × the longest edge
//! above the bound of a line the subdivision sampled (unless its budget of 2^−24 / 20 000
//! sub-domains runs out, when it stays safe but may be looser); taken ≥ 0, plus
//! `bound_margin`. A face or edge tetrahedron whose top two weight layers prove the bound
//! ([`certify`]) is settled without subdivision. Known gap: where the Bernstein coefficients
//! of D_2 or D_3 are not all positive on a sub-domain at its deepest level (D vanishes on the
//! domain's boundary; seen on edge tetrahedra of bunny, nut, spot), no t* certifies it and
//! that tetrahedron falls back to the old sampled bound (`bound_samples` grid).
//! Steps 7, 9 by the C¹ conditions (2.3). Step 8 and the `free` choices in
//! [`Free`]. After the choice, every edge tetrahedron is checked again with the chosen values
//! and both faces are raised if needed (the paper's bound is taken along f_A − B_A = f_B − B_B
//! only). Positive (negative) convex faces on which F > 0 (< 0) somewhere are treated as
//! nonconvex (the paper's rule would put the surface outside the hull); they are counted in
//! [`RationalBuild::promoted_faces`].
//!
//! Fallback for bad normals: a vertex normal that is not strictly above one of its triangles
//! (Loop limit normals at sharp creases, angle normals at saddle corners of coarse cages) is
//! replaced by the angle-weighted normal of its triangles when that one is above all of them,
//! else by the "above-face" normal (the angle normal rotated towards the direction maximising
//! min n · n_f over its triangles, [`crate::hull::inner::above::make_above`]); both are counted
//! in [`RationalBuild::replaced_normals`]. Only when no direction is above all its triangles
//! does the build fail naming the triangle.

pub mod bound;
pub mod certify;
pub mod cover;
pub mod eval;
pub mod quadric;
pub mod weights;

use crate::complex::{Patch, PatchComplex, RationalTerm, Role, SheetRule};
use crate::error::{Error, Result};
use crate::hull::inner::above;
use crate::hull::outer::{
    self,
    refine::{RefineMesh, SplitRule},
    Convexity, HullOptions, OuterHull, NO_FACE,
};
use glam::DVec3;
use rayon::prelude::*;
use std::path::Path;
use weights::{convex_piece, nonconvex_pieces, EdgeFrame, FaceData, Piece, N3};

/// The choice of the free parameter f_0003 of a face side (Step 8, §5.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Free {
    /// Step 8: the linear function's value p_0001, raised to the lower bound if needed.
    Default,
    /// f_0003 = B + offset (offset > 0): the surface family of Fig. 2.
    Offset(f64),
    /// The value at u (v) of a quadric fitted to the face's neighbourhood (positions and
    /// normals), raised to the lower bound if needed: reproduces quadrics (Theorem 4.2).
    Quadric,
}

/// Options of the rational C¹ scheme (see the module docs for the scene keys).
#[derive(Clone, Debug, PartialEq)]
pub struct RationalOptions {
    /// The free-parameter choice for every face.
    pub free: Free,
    /// Per input-triangle overrides of `free`.
    pub face_free: Vec<(u32, Free)>,
    /// Hull ε relative to each face's longest edge.
    pub epsilon: f64,
    /// Maximum rounds of local butterfly refinement.
    pub refine_rounds: usize,
    /// Grid resolution (points per edge of the base triangle) of the promotion sign test; the
    /// lower bounds are certified by subdivision and do not depend on it.
    pub bound_samples: usize,
    /// Margin above the lower bound, relative to the face's longest edge.
    pub bound_margin: f64,
    /// Accuracy of the certified lower bounds, relative to the face's longest edge: each
    /// bound is ≥ the exact one and, unless the subdivision budget runs out, at most this
    /// above the largest bound of a sampled shooting line.
    pub bound_tolerance: f64,
}

impl Default for RationalOptions {
    fn default() -> Self {
        RationalOptions {
            free: Free::Default,
            face_free: Vec::new(),
            epsilon: 0.05,
            refine_rounds: 4,
            bound_samples: 8,
            bound_margin: 1e-3,
            bound_tolerance: 1e-4,
        }
    }
}

fn parse_free(v: &toml::Value, key: &str, file: &Path) -> Result<Free> {
    let bad = |msg: String| Error::Input {
        path: file.to_path_buf(),
        message: format!("[scheme] {key}: {msg}"),
    };
    match v {
        toml::Value::String(s) if s == "default" => Ok(Free::Default),
        toml::Value::String(s) if s == "quadric" => Ok(Free::Quadric),
        toml::Value::Table(t) => {
            if let Some(k) = t.keys().find(|k| k.as_str() != "offset") {
                return Err(bad(format!("unknown key `{k}` (expected `offset`)")));
            }
            let off = t
                .get("offset")
                .and_then(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                .ok_or_else(|| bad("expected { offset = <number> }".into()))?;
            if off.is_nan() || off <= 0.0 || !off.is_finite() {
                return Err(bad(format!("offset must be a positive number, got {off}")));
            }
            Ok(Free::Offset(off))
        }
        other => Err(bad(format!(
            "expected \"default\", \"quadric\" or {{ offset = <number> }}, got {other}"
        ))),
    }
}

impl RationalOptions {
    /// Reads the scheme's keys from the scene's `[scheme]` table (all keys except `type`);
    /// unknown keys / bad values -> error naming the key and `file`.
    pub fn from_toml(table: &toml::Table, file: &Path) -> Result<RationalOptions> {
        let mut o = RationalOptions::default();
        let err = |key: &str, msg: &str| Error::Input {
            path: file.to_path_buf(),
            message: format!("[scheme] {key}: {msg}"),
        };
        let num = |key: &str, v: &toml::Value| -> Result<f64> {
            v.as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .filter(|x| x.is_finite())
                .ok_or_else(|| err(key, "expected a number"))
        };
        for (key, v) in table {
            match key.as_str() {
                "type" => {}
                "free" => o.free = parse_free(v, key, file)?,
                "epsilon" => {
                    o.epsilon = num(key, v)?;
                    if o.epsilon.is_nan() || o.epsilon <= 0.0 {
                        return Err(err(key, "must be > 0"));
                    }
                }
                "refine_rounds" => {
                    o.refine_rounds = v
                        .as_integer()
                        .filter(|&i| (0..=64).contains(&i))
                        .ok_or_else(|| err(key, "expected an integer in 0..=64"))?
                        as usize;
                }
                "bound_samples" => {
                    o.bound_samples = v
                        .as_integer()
                        .filter(|&i| (2..=256).contains(&i))
                        .ok_or_else(|| err(key, "expected an integer in 2..=256"))?
                        as usize;
                }
                "bound_margin" => {
                    o.bound_margin = num(key, v)?;
                    if o.bound_margin.is_nan() || o.bound_margin <= 0.0 {
                        return Err(err(key, "must be > 0"));
                    }
                }
                "bound_tolerance" => {
                    o.bound_tolerance = num(key, v)?;
                    if o.bound_tolerance.is_nan() || o.bound_tolerance <= 0.0 {
                        return Err(err(key, "must be > 0"));
                    }
                }
                "faces" => {
                    let t = v
                        .as_table()
                        .ok_or_else(|| err(key, "expected a table { \"<triangle>\" = <free> }"))?;
                    for (fk, fv) in t {
                        let idx: u32 = fk
                            .parse()
                            .map_err(|_| err(key, &format!("`{fk}` is not a triangle index")))?;
                        o.face_free
                            .push((idx, parse_free(fv, &format!("faces.{fk}"), file)?));
                    }
                }
                other => return Err(err(other, "unknown key")),
            }
        }
        Ok(o)
    }
}

/// Counts by [`Convexity`]: positive, zero, negative, nonconvex.
pub type ClassCounts = [usize; 4];

/// The result of [`build`]: the complex and statistics.
#[derive(Clone, Debug)]
pub struct RationalBuild {
    /// The patches.
    pub complex: PatchComplex,
    /// How many edges were split by the local refinement of §3.1.
    pub refined_edges: usize,
    /// The (possibly refined) triangles; `complex.vertices`/`normals` match them.
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the input triangle it came from.
    pub origin: Vec<u32>,
    /// Faces by class (positive, zero, negative, nonconvex), after promotion.
    pub faces_by_class: ClassCounts,
    /// Edges by class.
    pub edges_by_class: ClassCounts,
    /// Convex faces treated as nonconvex because F had the wrong sign on them.
    pub promoted_faces: usize,
    /// Per triangle, [positive side, negative side]: the lower bound B (including edge bounds)
    /// of σ·f_0003 (σ = +1 for u, −1 for v); NaN where the side does not exist.
    pub lower_bounds: Vec<[f64; 2]>,
    /// Per triangle, the chosen f_0003 of each side (NaN where absent).
    pub free_values: Vec<[f64; 2]>,
    /// Face sides raised after the final edge check.
    pub raised_faces: usize,
    /// Vertex normals replaced by the fallback (see the module docs); `complex.normals` holds
    /// the replacements.
    pub replaced_normals: usize,
}

fn class_index(c: Convexity) -> usize {
    match c {
        Convexity::Positive => 0,
        Convexity::Zero => 1,
        Convexity::Negative => 2,
        Convexity::Nonconvex => 3,
    }
}

/// A face piece as the build keeps it: a [`Piece`] without `dw`, which is the same for every
/// piece ([`weights::piece_dw`]): 288 instead of 448 bytes, for the ~350k pieces of a
/// 100k-triangle model that every later stage reads.
#[derive(Clone, Debug)]
struct SidePiece {
    pts: [DVec3; 4],
    w0: [f64; N3],
    rat: Option<[f64; 3]>,
}

impl SidePiece {
    /// ∂ weights / ∂ f_0003 ([`Piece::dw`]).
    #[inline]
    fn dw(&self) -> &'static [f64; N3] {
        weights::piece_dw()
    }

    /// The weights for a given f_0003 ([`Piece::weights`], the same arithmetic).
    #[inline]
    fn weights(&self, f: f64) -> [f64; N3] {
        let dw = self.dw();
        std::array::from_fn(|k| self.w0[k] + f * dw[k])
    }
}

impl From<Piece> for SidePiece {
    fn from(p: Piece) -> Self {
        debug_assert!(p.dw == *weights::piece_dw(), "every piece has the same dw");
        SidePiece {
            pts: p.pts,
            w0: p.w0,
            rat: p.rat,
        }
    }
}

/// One side of one face: its pieces and free parameter.
#[derive(Clone, Debug)]
struct Side {
    sigma: f64,
    pieces: Vec<SidePiece>,
    bound: f64,
    f: f64,
    margin: f64,
    edge_extra: f64,
}

/// Multinomial factors 3!/(λ1!λ2!λ3!) of the base part of each cubic multi-index.
fn base_factor(l: [u8; 4]) -> f64 {
    let f = |k: u8| -> f64 { [1.0, 1.0, 2.0, 6.0][usize::from(k)] };
    f(l[0] + l[1] + l[2]) / (f(l[0]) * f(l[1]) * f(l[2]))
}

/// Shooting cubic (4.8) of a face piece at base barycentrics `a` (of local 0, 1, 2).
fn face_shooting(w: &[f64; N3], rat: Option<&[f64; 3]>, a: [f64; 3]) -> [f64; 4] {
    let mut b = [0.0; 4];
    let pw = |s: f64| [1.0, s, s * s, s * s * s];
    let p = [pw(a[0]), pw(a[1]), pw(a[2])];
    for (k, &l) in weights::cubic_indices().iter().enumerate() {
        let m = base_factor(l)
            * p[0][usize::from(l[0])]
            * p[1][usize::from(l[1])]
            * p[2][usize::from(l[2])];
        b[usize::from(l[3])] += w[k] * m;
    }
    if let Some(r) = rat {
        let den = a[1] * a[2] + a[0] * a[2] + a[0] * a[1];
        if den > 0.0 {
            let num = r[0] * a[1] * a[2] + r[1] * a[0] * a[2] + r[2] * a[0] * a[1];
            b[0] += num / den * 6.0 * a[0] * a[1] * a[2];
        }
    }
    b
}

/// Shooting cubic (4.9) of an edge tetrahedron [p_i p_j u_A u_B] at q = x p_i + (1−x) p_j,
/// top point y u_A + (1−y) u_B.
fn edge_shooting(w: &[f64; N3], rat: &[f64; 4], x: f64, y: f64) -> [f64; 4] {
    const C: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0],
        [1.0, 2.0, 1.0, 0.0],
        [1.0, 3.0, 3.0, 1.0],
    ];
    let pw = |s: f64| [1.0, s, s * s, s * s * s];
    let (px, qx, py, qy) = (pw(x), pw(1.0 - x), pw(y), pw(1.0 - y));
    let mut b = [0.0; 4];
    for (k, &l) in weights::cubic_indices().iter().enumerate() {
        let s = usize::from(l[2] + l[3]);
        let (i, j) = (usize::from(l[0]), usize::from(l[2]));
        let bx = C[3 - s][i] * px[i] * qx[3 - s - i];
        let by = C[s][j] * py[j] * qy[s - j];
        b[s] += w[k] * bx * by;
    }
    let b21 = 2.0 * y * (1.0 - y);
    b[2] += x * b21 * (rat[0] * y + rat[1] * (1.0 - y))
        + (1.0 - x) * b21 * (rat[2] * y + rat[3] * (1.0 - y));
    b
}

/// Shooting-cubic bases tabulated on a sample grid: per sample, the factor of every cubic
/// weight (added to coefficient `slot[k]`) and of every rational weight.
struct Tab {
    slot: [usize; N3],
    rat_slot: usize,
    basis: Vec<([f64; N3], [f64; 4])>,
}

impl Tab {
    fn face(grid: &[[f64; 3]]) -> Tab {
        let basis = grid
            .iter()
            .map(|&a| {
                let mut w = [0.0; N3];
                let mut out = [0.0; N3];
                for k in 0..N3 {
                    w[k] = 1.0;
                    out[k] = face_shooting(&w, None, a).iter().sum();
                    w[k] = 0.0;
                }
                let den = a[1] * a[2] + a[0] * a[2] + a[0] * a[1];
                let bb = 6.0 * a[0] * a[1] * a[2];
                let r = if den > 0.0 {
                    [
                        a[1] * a[2] / den * bb,
                        a[0] * a[2] / den * bb,
                        a[0] * a[1] / den * bb,
                        0.0,
                    ]
                } else {
                    [0.0; 4]
                };
                (out, r)
            })
            .collect();
        let slot = std::array::from_fn(|k| usize::from(weights::cubic_indices()[k][3]));
        Tab {
            slot,
            rat_slot: 0,
            basis,
        }
    }

    fn edge(grid: &[(f64, f64)]) -> Tab {
        let basis = grid
            .iter()
            .map(|&(x, y)| {
                let mut w = [0.0; N3];
                let mut out = [0.0; N3];
                for k in 0..N3 {
                    w[k] = 1.0;
                    out[k] = edge_shooting(&w, &[0.0; 4], x, y).iter().sum();
                    w[k] = 0.0;
                }
                let mut r = [0.0; 4];
                for (k, rk) in r.iter_mut().enumerate() {
                    let mut e = [0.0; 4];
                    e[k] = 1.0;
                    *rk = edge_shooting(&[0.0; N3], &e, x, y)[2];
                }
                (out, r)
            })
            .collect();
        let slot = std::array::from_fn(|k| {
            let l = weights::cubic_indices()[k];
            usize::from(l[2] + l[3])
        });
        Tab {
            slot,
            rat_slot: 2,
            basis,
        }
    }

    #[inline]
    fn eval(&self, i: usize, w: &[f64; N3], rat: &[f64; 4], sigma: f64) -> [f64; 4] {
        let (bw, br) = &self.basis[i];
        let mut b = [0.0; 4];
        for k in 0..N3 {
            b[self.slot[k]] += w[k] * bw[k];
        }
        b[self.rat_slot] += rat[0] * br[0] + rat[1] * br[1] + rat[2] * br[2] + rat[3] * br[3];
        b.map(|x| sigma * x)
    }
}

/// Barycentric sample points of a triangle, `n` intervals per edge.
fn tri_grid(n: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::with_capacity((n + 1) * (n + 2) / 2);
    for i in 0..=n {
        for j in 0..=n - i {
            let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
            v.push([a, b, (1.0 - a - b).max(0.0)]);
        }
    }
    v
}

/// Lower bound of σ f_0003 for one face side (Step 6, first part), taken ≥ 0: a certificate
/// (see [`cover`]), never below the exact bound of Lemma 2.3 over every shooting line of the
/// side, and within `tol` of the largest sampled line's bound when the search converges.
///
/// Pieces whose top layers certify b = 0 ([`certify::face_top`]) are skipped; the others are
/// first sampled at the base points of `tab` (a cheap lower estimate that lets the
/// subdivision stop early), then covered by [`cover::sup_bound`].
fn face_bound(side: &Side, tab: &Tab, cover_opts: &cover::CoverOptions) -> f64 {
    const D: [f64; 4] = [0.0, 0.0, 1.0 / 3.0, 1.0];
    let mut best = 0.0f64;
    for pc in &side.pieces {
        if certify::face_top(&pc.w0, pc.dw(), side.sigma) {
            continue;
        }
        // The seed sampling is only a head start for the subdivision's lower estimate; the
        // subdivision samples the centres of its sub-triangles itself.
        let seed = if SEED_SAMPLING {
            let r = pc.rat.map_or([0.0; 4], |r| [r[0], r[1], r[2], 0.0]);
            let lines = (0..tab.basis.len()).map(|i| (tab.eval(i, &pc.w0, &r, side.sigma), D));
            bound::max_lemma_bound(lines, best)
        } else {
            best
        };
        let (fam, root) = cover::FaceFamily::new(&pc.w0, pc.rat.as_ref(), side.sigma);
        let c = cover::sup_bound(&fam, root, best, seed, cover_opts);
        best = if c.uncertified {
            // No t* certifies some sub-triangle (D vanishes on it): the certified rest, and
            // the old sampled bound for the lines there.
            let r = pc.rat.map_or([0.0; 4], |r| [r[0], r[1], r[2], 0.0]);
            let lines = (0..tab.basis.len()).map(|i| (tab.eval(i, &pc.w0, &r, side.sigma), D));
            bound::max_lemma_bound(lines, best.max(c.value))
        } else {
            c.value
        };
    }
    best
}

/// The subdivision budget of the certified bounds for a face (or edge) whose longest edge is
/// `longest`: tolerance `bound_tolerance` × `longest`.
fn cover_opts(opts: &RationalOptions, longest: f64) -> cover::CoverOptions {
    cover::CoverOptions {
        tol: opts.bound_tolerance * longest,
        max_depth: COVER_MAX_DEPTH,
        max_nodes: COVER_MAX_NODES,
    }
}

/// Whether the certified bounds start from a grid sampling (`bound_samples`) of the lines.
const SEED_SAMPLING: bool = false;

/// Deepest subdivision of the certified bounds (sub-domains 2^−24 of the base).
const COVER_MAX_DEPTH: u32 = 24;
/// Most sub-domains examined per certified bound.
const COVER_MAX_NODES: usize = 20_000;

/// An edge tetrahedron under construction (kept small: ~300k of them live through the whole
/// build of a 100k-triangle model; the weights of ∂/∂b are recomputed where needed by
/// [`EdgeTet::dw`], which is cheaper than storing them).
struct EdgeTet {
    edge: u32,
    faces: [u32; 2],
    side: u8,
    piece: [u8; 2],
    /// False for a degenerate pair (no frame): the build reports the first one.
    ok: bool,
    frame: EdgeFrame,
}

impl EdgeTet {
    /// The face sides A and B and their pieces this edge tetrahedron joins.
    #[inline]
    fn sides<'a>(&self, faces: &'a [FaceOut]) -> [(&'a Side, &'a SidePiece); 2] {
        let s = usize::from(self.side);
        [0, 1].map(|k| {
            let side = faces[self.faces[k] as usize].sides[s]
                .as_ref()
                .expect("side exists");
            (side, &side.pieces[usize::from(self.piece[k])])
        })
    }

    /// Weights and rational weights of ∂/∂b along f_A = σ(B_A + b), f_B = σ(B_B + b).
    #[inline]
    fn dw(&self, faces: &[FaceOut]) -> ([f64; N3], [f64; 4]) {
        let [(_, pa), (_, pb)] = self.sides(faces);
        self.frame.weights(pa.dw(), pb.dw())
    }
}

/// One face of the build: its class and its sides (pieces, bounds, free values).
struct FaceOut {
    class: Convexity,
    promoted: bool,
    sides: [Option<Side>; 2],
}

/// Builds the rational C¹ complex (see the module docs).
///
/// `positions`, `triangles` (vertex indices) and `normals` (unit, one per vertex, pointing to
/// the outside) describe a manifold triangulation, open or closed.
pub fn build(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    opts: &RationalOptions,
) -> Result<RationalBuild> {
    if triangles.is_empty() {
        return Err(Error::Invalid("the mesh has no triangles".into()));
    }
    outer::validate_normals(positions, normals)?;
    let hopts = HullOptions {
        epsilon: opts.epsilon,
    };
    // §3.1: build, refine where adjacent face tetrahedra intersect, repeat. Butterfly splits
    // first (the paper's rule); when they do not converge within the bound, start again with
    // midpoint splits, which make no new folds (see `outer::refine`).
    let t0 = std::time::Instant::now();
    let (mesh, hull, refined, replaced_normals) = match refine_hull(
        positions,
        triangles,
        normals,
        &hopts,
        opts,
        SplitRule::Butterfly,
    ) {
        Err(e @ Error::Invalid(_)) if e.to_string().contains(STILL_INTERSECT) => refine_hull(
            positions,
            triangles,
            normals,
            &hopts,
            opts,
            SplitRule::Midpoint,
        )
        .map_err(|e2| {
            Error::Invalid(format!(
                "{e}; with midpoint splits instead of butterfly points: {e2}"
            ))
        })?,
        other => other?,
    };
    let RefineMesh {
        positions,
        normals,
        triangles,
        origin,
    } = mesh;
    stage_time("refine_hull", t0);
    let mut b = assemble(
        &positions, &triangles, &normals, &origin, &hull, refined, opts,
    )?;
    stage_time("total", t0);
    b.replaced_normals = replaced_normals;
    Ok(b)
}

/// Prints the time since `since` for a build stage to stderr when the environment variable
/// `APATCH_STAGE_TIMES` is set (profiling aid: which stages are serial, see
/// `tests/suite/rational_throughput.rs`); nothing otherwise.
fn stage_time(name: &str, since: std::time::Instant) {
    if std::env::var_os("APATCH_STAGE_TIMES").is_some() {
        eprintln!(
            "stage {name}: {:.1} ms wall, process CPU {:.1} ms",
            since.elapsed().as_secs_f64() * 1e3,
            process_cpu_ns() as f64 * 1e-6
        );
    }
}

/// CPU time of all threads of this process so far, in nanoseconds (the sum of the first fields
/// of `/proc/self/task/*/schedstat`; 0 where that is missing). For [`stage_time`] only: on the
/// shared machine the CPU time of a stage is a steadier measure than its wall time.
fn process_cpu_ns() -> u64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    dir.flatten()
        .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

/// Start of the error [`refine_hull`] gives when the round bound is reached.
const STILL_INTERSECT: &str = "face tetrahedra still intersect after";

/// The refinement loop of §3.1 with one split rule: the refined mesh, its hull, the number of
/// split edges and of replaced normals.
fn refine_hull(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    hopts: &HullOptions,
    opts: &RationalOptions,
    rule: SplitRule,
) -> Result<(RefineMesh, OuterHull, usize, usize)> {
    let mut mesh = RefineMesh {
        positions: positions.to_vec(),
        normals: normals.to_vec(),
        triangles: triangles.to_vec(),
        origin: (0..triangles.len() as u32).collect(),
    };
    let mut refined = 0;
    let mut rounds = 0;
    let t0 = std::time::Instant::now();
    let mut replaced_normals = repair_normals(&mesh.positions, &mesh.triangles, &mut mesh.normals);
    stage_time("repair", t0);
    let hull = loop {
        let t0 = std::time::Instant::now();
        let hull = outer::build(&mesh.positions, &mesh.triangles, &mesh.normals, hopts)
            .map_err(|e| {
                if rounds == 0 {
                    e
                } else {
                    Error::Invalid(format!(
                        "after {refined} edges were refined because adjacent face tetrahedra intersected (§3.1): {e}"
                    ))
                }
            })?;
        stage_time("outer::build", t0);
        let t0 = std::time::Instant::now();
        let bad = hull.bad_edges(&mesh.positions, &mesh.triangles);
        stage_time("bad_edges", t0);
        if bad.is_empty() {
            break hull;
        }
        if rounds >= opts.refine_rounds {
            let e = hull.edges[bad[0] as usize];
            return Err(Error::Invalid(format!(
                "{STILL_INTERSECT} {} rounds of refinement ({} edges, e.g. \
                 the edge between vertices {} and {}); try a smaller `epsilon` or smoother normals",
                opts.refine_rounds,
                bad.len(),
                e.v[0],
                e.v[1]
            )));
        }
        let n = outer::refine::split_edges_with(&mut mesh, &bad, rule)?;
        refined += n;
        rounds += 1;
        replaced_normals += repair_normals(&mesh.positions, &mesh.triangles, &mut mesh.normals);
    };
    Ok((mesh, hull, refined, replaced_normals))
}

/// The documented fallback for vertex normals that are not strictly above every triangle
/// around them (n_ijk · n_l ≤ 1e-9, which §3.1 cannot handle; Loop limit normals do this at
/// sharp creases, angle-weighted ones at saddle-like corners of coarse cages): such a normal is
/// replaced by the normalised angle-weighted sum of its triangles' normals (each oriented to the
/// side of its corners' normals) when that one is above all of them; otherwise by the
/// "above-face" normal of [`above::make_above`]: the angle-weighted sum rotated towards the unit
/// direction maximising min_f n · n_f over the vertex's triangles, far enough to clear
/// [`above::ABOVE_MARGIN`]. Only when no direction is above all the triangles (they wrap round
/// more than a hemisphere) is the normal left for [`outer::build`] to report. Returns how many
/// normals were replaced.
fn repair_normals(positions: &[DVec3], triangles: &[[u32; 3]], normals: &mut [DVec3]) -> usize {
    let nv = positions.len();
    if nv != normals.len() || triangles.iter().flatten().any(|&i| i as usize >= nv) {
        return 0;
    }
    // Each triangle's unit normal on the side of its corners' normals.
    let oriented = |tri: &[u32; 3], normals: &[DVec3]| -> Option<DVec3> {
        let p = tri.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize()?;
        let s: DVec3 = tri.iter().map(|&i| normals[i as usize]).sum();
        Some(if n.dot(s) < 0.0 { -n } else { n })
    };
    let nf: Vec<Option<DVec3>> = triangles.iter().map(|t| oriented(t, normals)).collect();
    let mut bad = vec![false; nv];
    for (tri, f) in triangles.iter().zip(&nf) {
        let Some(f) = f else { continue };
        for &v in tri {
            if f.dot(normals[v as usize]) <= 1e-9 {
                bad[v as usize] = true;
            }
        }
    }
    if !bad.contains(&true) {
        return 0;
    }
    let mut sum = vec![DVec3::ZERO; nv];
    for (tri, f) in triangles.iter().zip(&nf) {
        let Some(f) = f else { continue };
        for c in 0..3 {
            let v = tri[c] as usize;
            if bad[v] {
                let p = positions[v];
                let a = (positions[tri[(c + 1) % 3] as usize] - p).normalize_or_zero();
                let b = (positions[tri[(c + 2) % 3] as usize] - p).normalize_or_zero();
                sum[v] += *f * a.dot(b).clamp(-1.0, 1.0).acos();
            }
        }
    }
    // The unit normals of the triangles around each bad vertex.
    let mut fans: Vec<Vec<DVec3>> = vec![Vec::new(); nv];
    for (tri, f) in triangles.iter().zip(&nf) {
        let Some(f) = f else { continue };
        for &v in tri {
            if bad[v as usize] {
                fans[v as usize].push(*f);
            }
        }
    }
    let mut count = 0;
    for v in 0..nv {
        if !bad[v] {
            continue;
        }
        let angle = sum[v].normalize_or_zero();
        let n = if angle != DVec3::ZERO && above::clearance(angle, &fans[v]) > 1e-9 {
            Some(angle)
        } else {
            above::make_above(angle, &fans[v])
        };
        if let Some(n) = n.filter(|n| n.is_normalized()) {
            normals[v] = n;
            count += 1;
        }
    }
    count
}

#[cfg(test)]
mod repair_normals_tests {
    use super::*;

    /// A triangle with corner 0 at the origin, lying in the plane with unit normal `n` (wound so
    /// its geometric normal is `n`), with corner angle `angle` there.
    fn wedge(
        n: DVec3,
        angle: f64,
        positions: &mut Vec<DVec3>,
        normals: &mut Vec<DVec3>,
    ) -> [u32; 3] {
        let e1 = n.any_orthonormal_vector();
        let e2 = n.cross(e1);
        let (s, c) = (0.5 * angle).sin_cos();
        let (a, b) = (c * e2 - s * e1, c * e2 + s * e1);
        let (a, b) = if a.cross(b).dot(n) > 0.0 {
            (a, b)
        } else {
            (b, a)
        };
        let i = positions.len() as u32;
        positions.extend([a, b]);
        // The other corners' normals are the face's own: above it, and they orient it.
        normals.extend([n, n]);
        [0, i, i + 1]
    }

    /// A vertex fan (a wide triangle tilted 60° one way, a narrow one tilted 60° the other) whose
    /// angle-weighted normal is below the narrow triangle, while the axis between them is 30°
    /// above both: the old fallback (angle-weighted sum only) left the normal, the above-face
    /// normal fixes it. Independent truth: the triangles' normals from their own corners.
    #[test]
    fn angle_normal_below_a_triangle_is_replaced_by_an_above_face_normal() {
        let t = 60f64.to_radians();
        let wide = DVec3::new(t.sin(), 0.0, t.cos());
        let narrow = DVec3::new(-t.sin(), 0.0, t.cos());
        let mut positions = vec![DVec3::ZERO];
        let mut normals = vec![DVec3::ZERO];
        let triangles = vec![
            wedge(wide, 150f64.to_radians(), &mut positions, &mut normals),
            wedge(narrow, 10f64.to_radians(), &mut positions, &mut normals),
        ];
        let angle_normal = (150.0 * wide + 10.0 * narrow).normalize();
        normals[0] = angle_normal;
        let face_normals: Vec<DVec3> = triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| positions[i as usize]);
                (p[1] - p[0]).cross(p[2] - p[0]).normalize()
            })
            .collect();
        // Precondition: the angle-weighted normal is below the narrow triangle.
        assert!(angle_normal.dot(face_normals[1]) < 0.0);
        let replaced = repair_normals(&positions, &triangles, &mut normals);
        assert_eq!(replaced, 1);
        let n = normals[0];
        // Unit length up to rounding of normalize().
        assert!((n.length() - 1.0).abs() < 1e-12);
        for f in &face_normals {
            assert!(
                n.dot(*f) >= above::ABOVE_MARGIN,
                "{n} · {f} = {}",
                n.dot(*f)
            );
        }
        // The other corners were already above their only triangle: untouched.
        assert_eq!(&normals[1..], &[wide, wide, narrow, narrow]);
    }

    /// Triangles wrapping round more than a hemisphere: no normal is above all of them, so the
    /// normal is left for the hull build to report (never a silently wrong surface).
    #[test]
    fn no_above_face_normal_leaves_the_normal() {
        let mut positions = vec![DVec3::ZERO];
        let mut normals = vec![DVec3::Z];
        let triangles: Vec<[u32; 3]> = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y]
            .iter()
            .map(|&n| wedge(n, 1.0, &mut positions, &mut normals))
            .collect();
        assert_eq!(repair_normals(&positions, &triangles, &mut normals), 0);
        assert_eq!(normals[0], DVec3::Z);
    }
}

#[allow(clippy::too_many_lines)]
fn assemble(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    normals: &[DVec3],
    origin: &[u32],
    hull: &OuterHull,
    refined_edges: usize,
    opts: &RationalOptions,
) -> Result<RationalBuild> {
    let nf = triangles.len();
    let tt = std::time::Instant::now();
    let grid = tri_grid(opts.bound_samples);
    let ftab = Tab::face(&grid);
    let fit = if opts.free == Free::Quadric || opts.face_free.iter().any(|f| f.1 == Free::Quadric) {
        Some(quadric::VertexFaces::new(positions.len(), triangles))
    } else {
        None
    };
    let free_of = |t: usize| -> Free {
        let o = origin[t];
        opts.face_free
            .iter()
            .rev()
            .find(|(i, _)| *i == o)
            .map_or(opts.free, |x| x.1)
    };

    // Faces: pieces, promotion, face bounds (parallel).
    let faces: Vec<FaceOut> = (0..nf)
        .into_par_iter()
        .map(|t| {
            let tri = triangles[t];
            let fh = &hull.faces[t];
            let p = tri.map(|i| positions[i as usize]);
            let n = tri.map(|i| normals[i as usize]);
            let fd = FaceData::new(p, n);
            let longest = fh.epsilon / opts.epsilon;
            let margin = opts.bound_margin * longest;
            let mut class = fh.class;
            let mut promoted = false;
            if class == Convexity::Zero {
                return FaceOut {
                    class,
                    promoted,
                    sides: [None, None],
                };
            }
            // Promotion: a convex face on which F has the wrong sign is treated as nonconvex.
            // (The piece it tests is kept for its side when the face stays convex.)
            let mut tested: Option<(DVec3, Piece)> = None;
            if class != Convexity::Nonconvex {
                let top = class == Convexity::Positive;
                let t_apex = if top { fh.t_max } else { fh.t_min };
                let apex = fh.centroid + t_apex * fh.normal;
                let pc = convex_piece(&fd, apex);
                let sigma = if top { 1.0 } else { -1.0 };
                let scale = pc.w0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                // The layer-0 certificate settles most faces without sampling (half the
                // tolerance: the sampled values round by far less than the other half).
                if !certify::face_base_below(&pc.w0, pc.rat.as_ref(), sigma, 0.5e-12 * scale)
                    && grid.iter().any(|&a| {
                        sigma * face_shooting(&pc.w0, pc.rat.as_ref(), a)[0] > 1e-12 * scale
                    })
                {
                    class = Convexity::Nonconvex;
                    promoted = true;
                } else {
                    tested = Some((apex, pc));
                }
            }
            let mut sides: [Option<Side>; 2] = [None, None];
            for (s, (has, t_apex, sigma)) in [
                (class.has_positive(), fh.t_max, 1.0),
                (class.has_negative(), fh.t_min, -1.0),
            ]
            .into_iter()
            .enumerate()
            {
                if !has {
                    continue;
                }
                let apex = fh.centroid + t_apex * fh.normal;
                let pieces: Vec<SidePiece> = if class == Convexity::Nonconvex {
                    nonconvex_pieces(&fd, apex).map(SidePiece::from).to_vec()
                } else {
                    let pc = match tested.take() {
                        Some((a, pc)) if a == apex => pc,
                        _ => convex_piece(&fd, apex),
                    };
                    vec![pc.into()]
                };
                let mut side = Side {
                    sigma,
                    pieces,
                    bound: 0.0,
                    f: 0.0,
                    margin,
                    edge_extra: 0.0,
                };
                side.bound = face_bound(&side, &ftab, &cover_opts(opts, longest));
                sides[s] = Some(side);
            }
            FaceOut {
                class,
                promoted,
                sides,
            }
        })
        .collect();

    stage_time("faces", tt);
    // Edge tetrahedra: frames and the b-derivative of their shooting cubics.
    let egrid: Vec<(f64, f64)> = {
        let n = opts.bound_samples;
        (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i as f64 / n as f64, j as f64 / n as f64)))
            .collect()
    };
    let etab = Tab::edge(&egrid);
    let piece_at = |t: usize, side: &Side, e: &outer::Edge| -> usize {
        if side.pieces.len() == 1 {
            return 0;
        }
        let tri = triangles[t];
        (0..3)
            .find(|&k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (a == e.v[0] && b == e.v[1]) || (a == e.v[1] && b == e.v[0])
            })
            .unwrap_or(0)
    };
    // The (edge, side) pairs with an edge tetrahedron, in edge order (cheap, sequential), then
    // their frames in parallel (indexed: the order of the sequential loop on any thread count).
    let faces_ref = &faces;
    let pairs: Vec<(u32, u8)> = hull
        .edges
        .iter()
        .enumerate()
        .filter(|(_, e)| e.faces[1] != NO_FACE && e.class != Convexity::Zero)
        .flat_map(|(ei, e)| {
            let [fa, fb] = e.faces.map(|f| f as usize);
            (0..2u8).filter_map(move |s| {
                let s_ = s as usize;
                (faces_ref[fa].sides[s_].is_some() && faces_ref[fb].sides[s_].is_some())
                    .then_some((ei as u32, s))
            })
        })
        .collect();
    // The edge tetrahedron of a pair (`ok` false: degenerate), each frame computed once.
    let etet = |&(ei, s): &(u32, u8)| -> EdgeTet {
        let e = &hull.edges[ei as usize];
        let [fa, fb] = e.faces;
        let (sa, sb) = (
            faces[fa as usize].sides[usize::from(s)]
                .as_ref()
                .expect("pairs have both sides"),
            faces[fb as usize].sides[usize::from(s)]
                .as_ref()
                .expect("pairs have both sides"),
        );
        let (ka, kb) = (piece_at(fa as usize, sa, e), piece_at(fb as usize, sb, e));
        let frame = EdgeFrame::from_tets(
            &sa.pieces[ka].pts,
            &sb.pieces[kb].pts,
            positions[e.v[0] as usize],
            positions[e.v[1] as usize],
        );
        EdgeTet {
            edge: ei,
            faces: [fa, fb],
            side: s,
            piece: [ka as u8, kb as u8],
            ok: frame.is_some(),
            frame: frame.unwrap_or_default(),
        }
    };
    // All of them straight into their vector (indexed: in place, in edge order on any thread
    // count), then the first degenerate one in edge order (as the sequential loop reported it).
    let etets: Vec<EdgeTet> = pairs.par_iter().map(etet).collect();
    if let Some(et) = etets.par_iter().find_first(|et| !et.ok) {
        let e = hull.edges[et.edge as usize];
        return Err(Error::Invalid(format!(
            "edge {} (vertices {}, {}): degenerate face tetrahedron",
            et.edge, e.v[0], e.v[1]
        )));
    }
    stage_time("etets", tt);
    let mut faces = faces;
    // Edge bounds (Step 6, second part) along f_A = σ(B_A + b), f_B = σ(B_B + b); only
    // positive ones are used, so the floor is 0 and the top-layer certificate at b = 0 skips
    // the sampling where it holds.
    let edge_bounds: Vec<f64> = etets
        .par_iter()
        .map(|et| {
            let [(sa, pa), (sb, pb)] = et.sides(&faces);
            let (dw, drat) = &et.dw(&faces);
            let wa = pa.weights(sa.sigma * sa.bound);
            let wb = pb.weights(sb.sigma * sb.bound);
            let (w0, r0) = et.frame.weights(&wa, &wb);
            if certify::edge_top(&w0, &r0, dw, drat, sa.sigma) {
                return 0.0;
            }
            let seed = if SEED_SAMPLING {
                let lines = (0..egrid.len()).map(|i| {
                    (
                        etab.eval(i, &w0, &r0, sa.sigma),
                        etab.eval(i, dw, drat, 1.0),
                    )
                });
                bound::max_lemma_bound(lines, 0.0)
            } else {
                0.0
            };
            // Certified over every line (x, y) of the tetrahedron (see `cover`).
            let root = cover::EdgeFamily::root(&w0, &r0, dw, drat, sa.sigma);
            let longest = sa.margin.max(sb.margin) / opts.bound_margin;
            let c = cover::sup_bound(
                &cover::EdgeFamily,
                root,
                0.0,
                seed,
                &cover_opts(opts, longest),
            );
            if c.uncertified {
                // No t* certifies some sub-square (D vanishes on it): the certified rest, and
                // the old sampled bound for the lines there.
                let lines = (0..egrid.len()).map(|i| {
                    (
                        etab.eval(i, &w0, &r0, sa.sigma),
                        etab.eval(i, dw, drat, 1.0),
                    )
                });
                bound::max_lemma_bound(lines, c.value.max(0.0))
            } else {
                c.value
            }
        })
        .collect();
    // (The bounds first: most are 0, and the edge tetrahedra are only read where they are not.)
    for (i, &be) in edge_bounds.iter().enumerate() {
        if be > 0.0 {
            let et = &etets[i];
            for k in 0..2 {
                if let Some(s) = faces[et.faces[k] as usize].sides[usize::from(et.side)].as_mut() {
                    // Third part of Step 6: B_ijk += B_ijkl (the largest over its edges).
                    s.edge_extra = s.edge_extra.max(be);
                }
            }
        }
    }
    stage_time("edge_bounds", tt);
    // Choose the free parameters (Step 8 / §5.3).
    faces.par_iter_mut().enumerate().for_each(|(t, fo)| {
        let free = free_of(t);
        // The face's data again (cheaper than keeping 300 bytes per face through the build).
        let fd = (free == Free::Default).then(|| {
            let tri = triangles[t];
            FaceData::new(
                tri.map(|i| positions[i as usize]),
                tri.map(|i| normals[i as usize]),
            )
        });
        for s in fo.sides.iter_mut().flatten() {
            s.bound += s.edge_extra;
            let apex = s.pieces[0].pts[3];
            let target = match free {
                Free::Default => {
                    s.sigma
                        * weights::linear_apex_value(fd.as_ref().expect("made for Default"), apex)
                }
                Free::Offset(b) => s.bound + b,
                Free::Quadric => {
                    let q = fit
                        .as_ref()
                        .and_then(|vf| quadric::fit_face(vf, positions, normals, triangles, t));
                    q.map_or(f64::NEG_INFINITY, |q| s.sigma * q.value(apex))
                }
            };
            s.f = s.sigma * target.max(s.bound + s.margin);
        }
    });
    stage_time("free", tt);
    // Final edge check with the chosen values; raise both faces where needed.
    // After the first round only the edge tetrahedra of a face side raised in the round before
    // can need more (the others see the same values again, and needed nothing), so each round
    // checks those only, in edge order: the same raises as checking all of them.
    let mut raised = vec![[false; 2]; nf];
    let mut active: Vec<u32> = (0..etets.len() as u32).collect();
    let mut rounds = 0;
    for _round in 0..4 {
        rounds += 1;
        let needs: Vec<f64> = active
            .par_iter()
            .map(|&i| {
                let et = &etets[i as usize];
                let [(sa, pa), (sb, pb)] = et.sides(&faces);
                let margin = sa.margin.max(sb.margin);
                let (dw, drat) = &et.dw(&faces);
                // Certificate at b = −margin: then the pruned maximum below is its floor.
                let shift = -sa.sigma * margin;
                let (wm, rm) = et
                    .frame
                    .weights(&pa.weights(sa.f + shift), &pb.weights(sb.f + shift));
                if certify::edge_top(&wm, &rm, dw, drat, sa.sigma) {
                    return 0.0;
                }
                let (w, r) = et.frame.weights(&pa.weights(sa.f), &pb.weights(sb.f));
                let seed = if SEED_SAMPLING {
                    let lines = (0..egrid.len())
                        .map(|i| (etab.eval(i, &w, &r, sa.sigma), etab.eval(i, dw, drat, 1.0)));
                    bound::max_lemma_bound(lines, -margin)
                } else {
                    -margin
                };
                // Certified over every line; no tolerance above the floor (a face is raised
                // only where some sub-square cannot be proved to need nothing).
                let root = cover::EdgeFamily::root(&w, &r, dw, drat, sa.sigma);
                let longest = sa.margin.max(sb.margin) / opts.bound_margin;
                let copts = cover::CoverOptions {
                    tol: 1e-12 * longest,
                    ..cover_opts(opts, longest)
                };
                let c = cover::sup_bound(&cover::EdgeFamily, root, -margin, seed, &copts);
                if c.uncertified {
                    // No t* certifies some sub-square (D vanishes on it): the old sampling
                    // there, the certificate elsewhere.
                    let lines = (0..egrid.len())
                        .map(|i| (etab.eval(i, &w, &r, sa.sigma), etab.eval(i, dw, drat, 1.0)));
                    bound::max_lemma_bound(lines, c.value.max(-margin)) + margin
                } else {
                    c.value + margin
                }
            })
            .collect();
        let mut any = false;
        let mut raised_now = vec![[false; 2]; nf];
        for (&i, &need) in active.iter().zip(&needs) {
            if need > 0.0 {
                let et = &etets[i as usize];
                any = true;
                for k in 0..2 {
                    let f = et.faces[k] as usize;
                    if let Some(s) = faces[f].sides[usize::from(et.side)].as_mut() {
                        s.f += s.sigma * need;
                        raised[f][usize::from(et.side)] = true;
                        raised_now[f][usize::from(et.side)] = true;
                    }
                }
            }
        }
        if !any {
            break;
        }
        active = (0..etets.len() as u32)
            .filter(|&i| {
                let et = &etets[i as usize];
                et.faces
                    .iter()
                    .any(|&f| raised_now[f as usize][usize::from(et.side)])
            })
            .collect();
    }

    stage_time(&format!("final_check ({rounds} rounds)"), tt);
    // Emit patches (in parallel; the order is the sequential one: faces, then edges).
    let mut complex = PatchComplex::new("rational-c1");
    complex.continuity = Some(1);
    complex.vertices = positions.iter().map(|p| p.to_array()).collect();
    complex.normals = normals.iter().map(|n| n.to_array()).collect();
    let face_sheet = SheetRule::Shooting {
        base: [0, 1, 2].into(),
        top: [3].into(),
    };
    let mut faces_by_class = [0; 4];
    let mut lower_bounds = vec![[f64::NAN; 2]; nf];
    let mut free_values = vec![[f64::NAN; 2]; nf];
    for (t, fo) in faces.iter().enumerate() {
        faces_by_class[class_index(fo.class)] += 1;
        for (s, side) in fo.sides.iter().enumerate() {
            if let Some(side) = side {
                lower_bounds[t][s] = side.bound;
                free_values[t][s] = side.f;
            }
        }
    }
    let zero_patch = |t: usize| -> Patch {
        let fh = &hull.faces[t];
        let tri = triangles[t];
        let apex = fh.centroid + fh.epsilon * fh.normal;
        Patch {
            tet: [
                positions[tri[0] as usize].to_array(),
                positions[tri[1] as usize].to_array(),
                positions[tri[2] as usize].to_array(),
                apex.to_array(),
            ],
            degree: 1,
            weights: vec![0.0, 0.0, 0.0, fh.epsilon],
            rational: Vec::new(),
            sheet: SheetRule::Any,
            role: Role::Planar,
            element: t as u32,
            jvertex: None,
            jedge: None,
        }
    };
    let face_piece_patch = |t: usize, side: &Side, pc: &SidePiece| -> Patch {
        let w = pc.weights(side.f);
        let rational = pc
            .rat
            .map(|r| {
                vec![RationalTerm {
                    index: [1, 1, 1, 0],
                    terms: [
                        (r[0], [0, 1, 1, 0]),
                        (r[1], [1, 0, 1, 0]),
                        (r[2], [1, 1, 0, 0]),
                    ]
                    .into(),
                }]
            })
            .unwrap_or_default();
        Patch {
            tet: pc.pts.map(|p| p.to_array()),
            degree: 3,
            weights: w.to_vec(),
            rational,
            sheet: face_sheet.clone(),
            role: Role::Face,
            element: t as u32,
            jvertex: None,
            jedge: None,
        }
    };
    let edge_patch = |et: &EdgeTet| -> Patch {
        let [(sa, pa), (sb, pb)] = et.sides(&faces);
        let (w, r) = et.frame.weights(&pa.weights(sa.f), &pb.weights(sb.f));
        let e = hull.edges[et.edge as usize];
        Patch {
            tet: [
                positions[e.v[0] as usize].to_array(),
                positions[e.v[1] as usize].to_array(),
                pa.pts[3].to_array(),
                pb.pts[3].to_array(),
            ],
            degree: 3,
            weights: w.to_vec(),
            rational: vec![
                RationalTerm {
                    index: [1, 0, 1, 1],
                    terms: [(r[0], [0, 0, 1, 0]), (r[1], [0, 0, 0, 1])].into(),
                },
                RationalTerm {
                    index: [0, 1, 1, 1],
                    terms: [(r[2], [0, 0, 1, 0]), (r[3], [0, 0, 0, 1])].into(),
                },
            ],
            sheet: SheetRule::Shooting {
                base: [0, 1].into(),
                top: [2, 3].into(),
            },
            role: Role::Edge,
            element: et.edge,
            jvertex: None,
            jedge: None,
        }
    };
    // Straight into the complex, no per-face vectors: one slot per face patch (its face and
    // its index among the face's patches), then an indexed parallel iterator over the slots and
    // the edge tetrahedra, which rayon writes in place into the reserved vector (the order of
    // the sequential loops: faces, then edges).
    let mut slots: Vec<(u32, u8)> = Vec::with_capacity(nf * 2);
    for (t, fo) in faces.iter().enumerate() {
        let n = if fo.class == Convexity::Zero {
            1
        } else {
            fo.sides.iter().flatten().map(|s| s.pieces.len()).sum()
        };
        slots.extend((0..n as u8).map(|k| (t as u32, k)));
    }
    let face_patch = |&(t, k): &(u32, u8)| -> Patch {
        let t = t as usize;
        let fo = &faces[t];
        if fo.class == Convexity::Zero {
            return zero_patch(t);
        }
        let (side, pc) = fo
            .sides
            .iter()
            .flatten()
            .flat_map(|s| s.pieces.iter().map(move |pc| (s, pc)))
            .nth(k as usize)
            .expect("slot within the face's patches");
        face_piece_patch(t, side, pc)
    };
    complex.patches.reserve_exact(slots.len() + etets.len());
    complex.patches.par_extend(
        slots
            .par_iter()
            .map(face_patch)
            .chain(etets.par_iter().map(edge_patch)),
    );
    stage_time("emit", tt);
    let mut edges_by_class = [0; 4];
    for e in &hull.edges {
        edges_by_class[class_index(e.class)] += 1;
    }
    let promoted_faces = faces.iter().filter(|f| f.promoted).count();
    // The pieces' ~150k small vectors are freed in parallel (a serial stage otherwise).
    faces.into_par_iter().for_each(drop);
    stage_time("free temporaries", tt);
    Ok(RationalBuild {
        complex,
        refined_edges,
        triangles: triangles.to_vec(),
        origin: origin.to_vec(),
        faces_by_class,
        edges_by_class,
        promoted_faces,
        lower_bounds,
        free_values,
        raised_faces: raised.iter().flatten().filter(|&&r| r).count(),
        replaced_normals: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Xorshift numbers in [−1, 1) for the randomised tests of this module and its children.
    pub(super) struct Rng(pub(super) u64);
    impl Rng {
        pub(super) fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
        pub(super) fn vec(&mut self) -> DVec3 {
            DVec3::new(self.next(), self.next(), self.next())
        }
    }

    /// One face side of a random test case, its longest edge and its fast bound.
    struct Case {
        side: Side,
        longest: f64,
        fast: f64,
    }

    /// Seeded random faces (corners in the unit cube, normals within ~35° of the face's),
    /// both sides, as one convex piece and as three nonconvex pieces, with the fast bound.
    fn random_cases() -> Vec<Case> {
        let mut rng = Rng(0x0ddb_a11c_afe5_eed5);
        let opts = RationalOptions::default();
        let tab = Tab::face(&tri_grid(opts.bound_samples));
        let mut out = Vec::new();
        for _ in 0..300 {
            let p = [rng.vec(), rng.vec(), rng.vec()];
            let Some(nf) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else {
                continue;
            };
            let n = [0; 3].map(|_| (nf + 0.6 * rng.vec()).normalize());
            if n.iter().any(|x| x.dot(nf) < 0.2) {
                continue;
            }
            let fd = FaceData::new(p, n);
            let longest = (0..3)
                .map(|k| (p[(k + 1) % 3] - p[k]).length())
                .fold(0.0, f64::max);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            for (sigma, t) in [(1.0, 0.3 * longest), (-1.0, -0.3 * longest)] {
                let apex = c + t * nf;
                for pieces in [
                    vec![convex_piece(&fd, apex).into()],
                    nonconvex_pieces(&fd, apex).map(SidePiece::from).to_vec(),
                ] {
                    let side = Side {
                        sigma,
                        pieces,
                        bound: 0.0,
                        f: 0.0,
                        margin: 0.0,
                        edge_extra: 0.0,
                    };
                    let fast = face_bound(&side, &tab, &cover_opts(&opts, longest));
                    out.push(Case {
                        side,
                        longest,
                        fast,
                    });
                }
            }
        }
        out
    }

    /// The plain maximum (floor 0) of [`bound::lemma_bound`] over the lines of `side` from the
    /// base points `grid`, each line straight from [`face_shooting`] (no tables, no pruning).
    fn plain_bound(side: &Side, grid: &[[f64; 3]]) -> f64 {
        const D: [f64; 4] = [0.0, 0.0, 1.0 / 3.0, 1.0];
        side.pieces
            .iter()
            .flat_map(|pc| {
                grid.iter().map(move |&a| {
                    let line = face_shooting(&pc.w0, pc.rat.as_ref(), a);
                    bound::lemma_bound(line.map(|x| side.sigma * x), D)
                })
            })
            .fold(0.0, f64::max)
    }

    /// The certified face bound is never below the grid sampling it starts from (the old
    /// bound), and the top-layer certificate and the subdivision are both exercised.
    #[test]
    fn face_bound_is_at_least_the_sampled_one() {
        let grid = tri_grid(RationalOptions::default().bound_samples);
        let (mut certified, mut covered) = (0, 0);
        for c in random_cases() {
            if c.side
                .pieces
                .iter()
                .all(|pc| certify::face_top(&pc.w0, pc.dw(), c.side.sigma))
            {
                certified += 1;
                assert_eq!(c.fast, 0.0);
            } else {
                covered += 1;
            }
            let plain = plain_bound(&c.side, &grid);
            let scale = c.side.pieces[0]
                .w0
                .iter()
                .fold(1e-300f64, |m, x| m.max(x.abs()));
            // The tabulated evaluation rounds differently from face_shooting (1e-12 of the
            // weights' scale, far above f64 rounding of 20-term sums).
            assert!(
                c.fast >= plain - 1e-12 * scale,
                "fast {} plain {plain}",
                c.fast
            );
        }
        assert!(certified > 20 && covered > 20, "{certified} {covered}");
    }

    /// The face bound is a certificate: on a dense grid (32 intervals per edge, 561 lines per
    /// piece) no line needs more, even without the scheme's margin (the old 8-interval
    /// sampling fails this: 7 of 1200 sides needed up to 0.6 % of the longest edge more); and
    /// it is tight: every subdivision converged to within `bound_tolerance` × the longest edge
    /// of a line it sampled.
    #[test]
    fn face_bound_covers_dense_sampling() {
        let dense = tri_grid(32);
        let opts = RationalOptions::default();
        let mut covered = 0;
        let cases = random_cases();
        for c in &cases {
            let d = plain_bound(&c.side, &dense);
            let scale = c.side.pieces[0]
                .w0
                .iter()
                .fold(1e-300f64, |m, x| m.max(x.abs()));
            // Only the t*-accuracy of lemma_bound (golden section, ~1e-5 of the coefficient
            // scale, from above) can put a sampled line above the certificate.
            assert!(
                d <= c.fast + 1e-5 * scale,
                "dense {d} > certified {} (longest {})",
                c.fast,
                c.longest
            );
        }
        for c in &cases {
            let scale = c.side.pieces[0]
                .w0
                .iter()
                .fold(1e-300f64, |m, x| m.max(x.abs()));
            // Tightness: each covered piece converged, so its bound is at most the tolerance
            // above a line the search sampled (the 32-interval grid can miss narrow peaks of
            // the bound near the zero curve of p_0; the subdivision does not).
            let tol = cover_opts(&opts, c.longest);
            for pc in &c.side.pieces {
                if certify::face_top(&pc.w0, pc.dw(), c.side.sigma) {
                    continue;
                }
                let (fam, root) = cover::FaceFamily::new(&pc.w0, pc.rat.as_ref(), c.side.sigma);
                let r = cover::sup_bound(&fam, root, 0.0, 0.0, &tol);
                assert!(r.converged, "{r:?}");
                assert!(r.value <= r.sampled.max(0.0) + tol.tol, "{r:?}");
                assert!(r.value <= c.fast + 1e-12 * scale, "{r:?} > {}", c.fast);
                covered += 1;
            }
        }
        assert!(covered > 100, "only {covered} pieces covered");
    }
}

#[cfg(test)]
mod thread_tests {
    use super::*;

    /// The build (certified bounds included) is bit-identical on 1 and 2 threads: every
    /// subdivision runs inside one face or edge, in a fixed order. A noisy sphere (10 %
    /// radial noise), so that some bounds are not settled by the top-layer certificates.
    #[test]
    fn build_is_identical_across_thread_counts() {
        let (v, f) = crate::fixtures::icosahedron();
        let (mut v, f) = crate::fixtures::subdivide_sphere(&v, &f, 2);
        let n = v.clone();
        let mut s = 99u64;
        for p in &mut v {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            *p *= 1.0 + 0.1 * (((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0);
        }
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| build(&v, &f, &n, &RationalOptions::default()).expect("builds"))
        };
        let (a, b) = (run(1), run(2));
        let bits = |x: &RationalBuild| -> Vec<u64> {
            x.lower_bounds
                .iter()
                .chain(&x.free_values)
                .flatten()
                .map(|v| v.to_bits())
                .chain(
                    x.complex
                        .patches
                        .iter()
                        .flat_map(|p| p.weights.iter().map(|w| w.to_bits())),
                )
                .collect()
        };
        assert_eq!(bits(&a), bits(&b));
        // Every bound is finite: edges whose lines cannot all be certified (48 here) fall
        // back to their sampled bound instead of +∞ (which made NaN weights).
        // (NaN marks a side that does not exist.)
        assert!(!a.lower_bounds.iter().flatten().any(|x| x.is_infinite()));
        assert!(a
            .complex
            .patches
            .iter()
            .all(|p| p.weights.iter().all(|w| w.is_finite())));
    }
}
