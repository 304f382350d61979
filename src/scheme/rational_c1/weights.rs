//! The weights of the face and edge cubics, §4.2 Steps 1–5, 7 and 9.
//!
//! Every weight next to a mesh edge [p_a p_b] is the value b(p_a, p_b, w) of one affine function
//! of the third point w ([`EdgeBlossom`]); this makes the number 2 and number 3 weights of
//! Steps 3–4 consistent across every tetrahedron containing the edge, which is what the C¹
//! conditions (2.3) across face/edge tetrahedron faces require.
//!
//! Weights of a face piece are affine in its free parameter f = f_0003 (Step 5: the number 4
//! weights are (f + 2 q_{e_a+e_4})/3), so a piece stores `w0` (f = 0) and `dw` (∂/∂f).

use crate::bb::index_of;
use crate::hull::outer::EdgeBlossom;
use glam::{DMat3, DVec3};
use std::sync::OnceLock;

/// Number of cubic weights.
pub const N3: usize = 20;

/// The 20 cubic multi-indices in the crate's order (computed once).
#[must_use]
pub fn cubic_indices() -> &'static [[u8; 4]] {
    static IDX: OnceLock<Vec<[u8; 4]>> = OnceLock::new();
    IDX.get_or_init(|| crate::bb::multi_indices(3))
}

/// Index of the cubic weight with multi-index λ.
#[inline]
#[must_use]
pub fn ix(l: [u8; 4]) -> usize {
    index_of(l)
}

/// One cubic piece on the positive or negative side of a face: the face tetrahedron
/// [p_0 p_1 p_2 apex] (convex face) or one of the three sub-tetrahedra [p_a p_b c apex] of a
/// nonconvex face.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// Vertices; local 3 is the apex (u or v).
    pub pts: [DVec3; 4],
    /// Weights with f_0003 = 0.
    pub w0: [f64; N3],
    /// ∂ weights / ∂ f_0003.
    pub dw: [f64; N3],
    /// Rational weights of (4.1): for the side face opposite local vertex s (s = 0, 1, 2), the
    /// weight blended by the monomial of that face (None for sub-tetrahedra).
    pub rat: Option<[f64; 3]>,
}

/// ∂ weights / ∂ f_0003, the same for every piece of both kinds (Step 5): 1/3 at the number 4
/// weights f_1002, f_0102, f_0012, 1 at f_0003, 0 elsewhere (`Piece::dw` of each piece; the
/// build keeps pieces without it).
#[must_use]
pub fn piece_dw() -> &'static [f64; N3] {
    static DW: OnceLock<[f64; N3]> = OnceLock::new();
    DW.get_or_init(|| {
        let mut dw = [0.0; N3];
        for l in [[1, 0, 0, 2], [0, 1, 0, 2], [0, 0, 1, 2]] {
            dw[ix(l)] = 1.0 / 3.0;
        }
        dw[ix([0, 0, 0, 3])] = 1.0;
        dw
    })
}

impl Piece {
    /// The weights for a given f_0003.
    #[must_use]
    pub fn weights(&self, f: f64) -> [f64; N3] {
        std::array::from_fn(|k| self.w0[k] + f * self.dw[k])
    }
}

/// Solves the square system `a x = b` (n ≤ 16) by Gaussian elimination with partial pivoting.
/// Returns None when singular.
#[must_use]
pub fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..n {
            let m = a[r][col] / a[col][col];
            if m != 0.0 {
                let (top, bottom) = a.split_at_mut(r);
                for (x, y) in bottom[0][col..n].iter_mut().zip(&top[col][col..n]) {
                    *x -= m * y;
                }
                b[r] -= m * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// Least-squares rows of Step 5 and Step 8, computed once.
struct LsRows {
    /// The 16 (λ4 ≤ 1) cubic multi-indices used as data.
    data: Vec<[u8; 4]>,
    /// q_{e_a+e_4} (a = 0, 1, 2) as rows over the data.
    q_apex: [[f64; 16]; 3],
    /// p_0001 of (4.16) as a row over the data.
    p_apex: [f64; 16],
}

fn ls_rows() -> &'static LsRows {
    static ROWS: OnceLock<LsRows> = OnceLock::new();
    ROWS.get_or_init(|| {
        let data: Vec<[u8; 4]> = crate::bb::multi_indices(3)
            .into_iter()
            .filter(|l| l[3] <= 1)
            .collect();
        let unk2: Vec<[u8; 4]> = crate::bb::multi_indices(2)
            .into_iter()
            .filter(|l| l[3] <= 1)
            .collect();
        // (4.13): f_λ = 1/3 Σ λ_i q_{λ−e_i}.
        let elev = |lam: [u8; 4], unk: &[[u8; 4]], scale: f64| -> Vec<f64> {
            let mut row = vec![0.0; unk.len()];
            for i in 0..4 {
                if lam[i] > 0 {
                    let mut m = lam;
                    m[i] -= 1;
                    if let Some(k) = unk.iter().position(|&u| u == m) {
                        row[k] += f64::from(lam[i]) * scale;
                    }
                }
            }
            row
        };
        let m: Vec<Vec<f64>> = data.iter().map(|&l| elev(l, &unk2, 1.0 / 3.0)).collect();
        // Pseudo-inverse rows: (MᵀM)⁻¹ Mᵀ.
        let pinv = pinv(&m);
        let q_of = |mu: [u8; 4]| -> [f64; 16] {
            let k = unk2.iter().position(|&u| u == mu).unwrap_or(0);
            std::array::from_fn(|j| pinv[k][j])
        };
        let q_apex = [q_of([1, 0, 0, 1]), q_of([0, 1, 0, 1]), q_of([0, 0, 1, 1])];
        // (4.16): q_μ = 1/2 Σ μ_i p_{μ−e_i}, unknown linear p.
        let unk1 = crate::bb::multi_indices(1);
        let l: Vec<Vec<f64>> = unk2.iter().map(|&mu| elev(mu, &unk1, 0.5)).collect();
        let lp = pinv_rows(&l);
        let p4 = &lp[3]; // p_0001 over the q's
        let p_apex: [f64; 16] =
            std::array::from_fn(|j| (0..unk2.len()).map(|k| p4[k] * pinv[k][j]).sum());
        LsRows {
            data,
            q_apex,
            p_apex,
        }
    })
}

fn pinv_rows(m: &[Vec<f64>]) -> Vec<Vec<f64>> {
    pinv(m)
}

/// (MᵀM)⁻¹Mᵀ for a full-column-rank M (rows × cols), as cols rows of length rows.
fn pinv(m: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let rows = m.len();
    let cols = m[0].len();
    let mtm: Vec<Vec<f64>> = (0..cols)
        .map(|i| {
            (0..cols)
                .map(|j| (0..rows).map(|r| m[r][i] * m[r][j]).sum())
                .collect()
        })
        .collect();
    let mut out = vec![vec![0.0; rows]; cols];
    for r in 0..rows {
        let rhs: Vec<f64> = (0..cols).map(|i| m[r][i]).collect();
        let x = solve(mtm.clone(), rhs).unwrap_or_else(|| vec![0.0; cols]);
        for i in 0..cols {
            out[i][r] = x[i];
        }
    }
    out
}

/// Data of one face needed by its pieces.
#[derive(Clone, Copy, Debug)]
pub struct FaceData {
    /// Corner positions.
    pub p: [DVec3; 3],
    /// Corner unit normals.
    pub n: [DVec3; 3],
    /// Edge blossoms of (p0 p1), (p1 p2), (p2 p0).
    pub eb: [EdgeBlossom; 3],
}

impl FaceData {
    /// Prepares the face.
    #[must_use]
    pub fn new(p: [DVec3; 3], n: [DVec3; 3]) -> Self {
        let eb = [
            EdgeBlossom::new(p[0], p[1], n[0], n[1]),
            EdgeBlossom::new(p[1], p[2], n[1], n[2]),
            EdgeBlossom::new(p[2], p[0], n[2], n[0]),
        ];
        FaceData { p, n, eb }
    }

    /// b(p_a, p_b, w) for corners a ≠ b.
    #[must_use]
    pub fn edge_at(&self, a: usize, b: usize, w: DVec3) -> f64 {
        let k = match (a.min(b), a.max(b)) {
            (0, 1) => 0,
            (1, 2) => 1,
            _ => 2,
        };
        self.eb[k].at(w)
    }

    /// Number 1 weight at corner a towards w: (w − p_a)·n_a / 3.
    #[must_use]
    pub fn corner_at(&self, a: usize, w: DVec3) -> f64 {
        (w - self.p[a]).dot(self.n[a]) / 3.0
    }

    /// The 16 layer-0/1 weights of the whole face tetrahedron [p0 p1 p2 apex] (polynomial
    /// part; f_1110 is the mean of the three edge values, Step 3) in the order of the
    /// least-squares data, plus f_1110 and the three edge values b_12(p0), b_20(p1), b_01(p2).
    fn full_layers(&self, apex: DVec3) -> ([f64; 16], f64, [f64; 3]) {
        let rows = ls_rows();
        let pts = [self.p[0], self.p[1], self.p[2], apex];
        let mid = [
            self.edge_at(1, 2, self.p[0]),
            self.edge_at(0, 2, self.p[1]),
            self.edge_at(0, 1, self.p[2]),
        ];
        let f1110 = (mid[0] + mid[1] + mid[2]) / 3.0;
        let mut d = [0.0; 16];
        for (k, l) in rows.data.iter().enumerate() {
            d[k] = self.layer01(l, &pts, f1110);
        }
        (d, f1110, mid)
    }

    /// A layer-0/1 weight of [p0 p1 p2 apex] by the rules of Steps 1–4.
    fn layer01(&self, l: &[u8; 4], pts: &[DVec3; 4], f1110: f64) -> f64 {
        // The corners (local 0..=2) present in λ, in order; no allocation (hot path).
        let mut corners = [0usize; 3];
        let mut nc = 0;
        for (i, &li) in l.iter().take(3).enumerate() {
            if li > 0 {
                corners[nc] = i;
                nc += 1;
            }
        }
        match (l[3], nc) {
            // Vertex (Step 1) or corner weights (Step 2).
            (_, 1) => {
                let a = corners[0];
                if l[a] == 3 {
                    0.0
                } else {
                    let b = (0..4).find(|&b| b != a && l[b] > 0).unwrap_or(3);
                    self.corner_at(a, pts[b])
                }
            }
            // Edge weights in the face (Step 2) or towards the apex (Step 4).
            (0, 2) => {
                let (a, b) = (corners[0], corners[1]);
                if l[a] == 2 {
                    self.corner_at(a, pts[b])
                } else {
                    self.corner_at(b, pts[a])
                }
            }
            (1, 2) => self.edge_at(corners[0], corners[1], pts[3]),
            // f_1110 (Step 3).
            _ => f1110,
        }
    }
}

/// The piece of a convex face: [p0 p1 p2 apex] with the rational term of (4.1).
#[must_use]
pub fn convex_piece(fd: &FaceData, apex: DVec3) -> Piece {
    let pts = [fd.p[0], fd.p[1], fd.p[2], apex];
    let rows = ls_rows();
    let (d, f1110, mid) = fd.full_layers(apex);
    let mut w0 = [0.0; N3];
    let mut dw = [0.0; N3];
    for (k, l) in rows.data.iter().enumerate() {
        w0[ix(*l)] = d[k];
    }
    // Step 5: number 4 weights from the least-squares quadratic, (4.14).
    for a in 0..3 {
        let q: f64 = (0..16).map(|j| rows.q_apex[a][j] * d[j]).sum();
        let mut l = [0u8, 0, 0, 2];
        l[a] = 1;
        w0[ix(l)] = 2.0 * q / 3.0;
        dw[ix(l)] = 1.0 / 3.0;
    }
    dw[ix([0, 0, 0, 3])] = 1.0;
    let _ = pts;
    Piece {
        pts,
        w0,
        dw,
        rat: Some(mid.map(|m| m - f1110)),
    }
}

/// The three pieces of a nonconvex face (the split of §4.1 at the centroid c): for each edge
/// (a, b) ∈ {(0,1), (1,2), (2,0)}, the sub-tetrahedron [p_a p_b c apex]. The weights inside the
/// face are the cubic Clough–Tocher ones, layer 1 the quadratic C¹ spline on the same split,
/// layer 2 linear, all from the data of Steps 1–4 (Step 5: "determined by the Clough–Tocher
/// scheme"); the number 4 weights come from the same least-squares quadratic as a convex face.
#[must_use]
pub fn nonconvex_pieces(fd: &FaceData, apex: DVec3) -> [Piece; 3] {
    let rows = ls_rows();
    let c = (fd.p[0] + fd.p[1] + fd.p[2]) / 3.0;
    let (d, _, _) = fd.full_layers(apex);
    let q: [f64; 3] = std::array::from_fn(|a| (0..16).map(|j| rows.q_apex[a][j] * d[j]).sum());
    // Per corner a: (p_a c c) and (p_a c u), the averages over the three sub-triangles at p_a.
    let others = |a: usize| [(a + 1) % 3, (a + 2) % 3];
    let pcc: [f64; 3] = std::array::from_fn(|a| {
        let [b, x] = others(a);
        (fd.corner_at(a, c) + fd.edge_at(a, b, c) + fd.edge_at(a, x, c)) / 3.0
    });
    let pcu: [f64; 3] = std::array::from_fn(|a| {
        let [b, x] = others(a);
        (fd.corner_at(a, apex) + fd.edge_at(a, b, apex) + fd.edge_at(a, x, apex)) / 3.0
    });
    let ccc = (pcc[0] + pcc[1] + pcc[2]) / 3.0;
    let ccu = (pcu[0] + pcu[1] + pcu[2]) / 3.0;
    let puu: [f64; 3] = std::array::from_fn(|a| 2.0 * q[a] / 3.0);
    let cuu = (puu[0] + puu[1] + puu[2]) / 3.0;
    std::array::from_fn(|k| {
        let (a, b) = (k, (k + 1) % 3);
        let pts = [fd.p[a], fd.p[b], c, apex];
        let mut w0 = [0.0; N3];
        let mut dw = [0.0; N3];
        // Corners and edge of the mesh.
        w0[ix([2, 1, 0, 0])] = fd.corner_at(a, fd.p[b]);
        w0[ix([1, 2, 0, 0])] = fd.corner_at(b, fd.p[a]);
        w0[ix([2, 0, 1, 0])] = fd.corner_at(a, c);
        w0[ix([0, 2, 1, 0])] = fd.corner_at(b, c);
        w0[ix([2, 0, 0, 1])] = fd.corner_at(a, apex);
        w0[ix([0, 2, 0, 1])] = fd.corner_at(b, apex);
        w0[ix([1, 1, 1, 0])] = fd.edge_at(a, b, c);
        w0[ix([1, 1, 0, 1])] = fd.edge_at(a, b, apex);
        // Clough–Tocher interior.
        w0[ix([1, 0, 2, 0])] = pcc[a];
        w0[ix([0, 1, 2, 0])] = pcc[b];
        w0[ix([0, 0, 3, 0])] = ccc;
        w0[ix([1, 0, 1, 1])] = pcu[a];
        w0[ix([0, 1, 1, 1])] = pcu[b];
        w0[ix([0, 0, 2, 1])] = ccu;
        w0[ix([1, 0, 0, 2])] = puu[a];
        w0[ix([0, 1, 0, 2])] = puu[b];
        w0[ix([0, 0, 1, 2])] = cuu;
        for l in [[1, 0, 0, 2], [0, 1, 0, 2], [0, 0, 1, 2]] {
            dw[ix(l)] = 1.0 / 3.0;
        }
        dw[ix([0, 0, 0, 3])] = 1.0;
        Piece {
            pts,
            w0,
            dw,
            rat: None,
        }
    })
}

/// p_0001 of Step 8 (the linear function approximating the cubic's data) for the face
/// tetrahedron [p0 p1 p2 apex].
#[must_use]
pub fn linear_apex_value(fd: &FaceData, apex: DVec3) -> f64 {
    let rows = ls_rows();
    let (d, _, _) = fd.full_layers(apex);
    (0..16).map(|j| rows.p_apex[j] * d[j]).sum()
}

/// Barycentric coordinates of x in the tetrahedron t (None when degenerate).
#[must_use]
pub fn bary(t: &[DVec3; 4], x: DVec3) -> Option<[f64; 4]> {
    let m = DMat3::from_cols(t[1] - t[0], t[2] - t[0], t[3] - t[0]);
    let det = m.determinant();
    let scale = (t[1] - t[0]).length() * (t[2] - t[0]).length() * (t[3] - t[0]).length();
    if det.is_nan() || det.abs() <= 1e-14 * scale {
        return None;
    }
    let y = m.inverse() * (x - t[0]);
    Some([1.0 - y.x - y.y - y.z, y.x, y.y, y.z])
}

/// Index tables of an [`EdgeFrame`] (the gather `copy` and the first-layer indices `c1`).
type FrameTables = ([(u8, u8); N3], [[u8; 4]; 6]);

/// The index tables of an [`EdgeFrame`] for the local positions `[i, j, 3]` of p_i, p_j in
/// pieces A and B: they depend on (i, j) of each piece only, so all 9 × 9 are computed once
/// and looked up (building them per edge tetrahedron was a visible cost on large meshes).
fn frame_tables(a_loc: [usize; 3], b_loc: [usize; 3]) -> FrameTables {
    static TABLES: OnceLock<Vec<FrameTables>> = OnceLock::new();
    let key = |loc: [usize; 3]| loc[0] * 3 + loc[1];
    let all = TABLES.get_or_init(|| {
        let locs: Vec<[usize; 3]> = (0..9).map(|k| [k / 3, k % 3, 3]).collect();
        locs.iter()
            .flat_map(|&a| locs.iter().map(move |&b| compute_frame_tables(a, b)))
            .collect()
    });
    all[key(a_loc) * 9 + key(b_loc)]
}

/// Computes the tables of [`frame_tables`] (see [`EdgeFrame::weights`] for their use).
fn compute_frame_tables(a_loc: [usize; 3], b_loc: [usize; 3]) -> FrameTables {
    let map = |loc: &[usize; 3], c: [u8; 3]| -> [u8; 4] {
        let mut l = [0u8; 4];
        for k in 0..3 {
            l[loc[k]] += c[k];
        }
        l
    };
    let mut copy = [(2u8, 0u8); N3];
    for (k, &l) in cubic_indices().iter().enumerate() {
        if l[3] == 0 {
            copy[k] = (0, ix(map(&a_loc, [l[0], l[1], l[2]])) as u8);
        } else if l[2] == 0 {
            copy[k] = (1, ix(map(&b_loc, [l[0], l[1], l[3]])) as u8);
        }
    }
    // First layer across the face shared with a piece: w(face multiset + e_r), r = 0..3.
    let c1 = |loc: &[usize; 3], c: [u8; 3]| -> [u8; 4] {
        let base = map(loc, c);
        std::array::from_fn(|r| {
            let mut l = base;
            l[r] += 1;
            ix(l) as u8
        })
    };
    (
        copy,
        [
            c1(&a_loc, [0, 0, 2]),
            c1(&b_loc, [0, 0, 2]),
            c1(&a_loc, [1, 0, 1]),
            c1(&b_loc, [1, 0, 1]),
            c1(&a_loc, [0, 1, 1]),
            c1(&b_loc, [0, 1, 1]),
        ],
    )
}

/// How the edge tetrahedron [p_i p_j apexA apexB] sits against its two face pieces.
#[derive(Clone, Copy, Debug, Default)]
pub struct EdgeFrame {
    /// Local indices in piece A of p_i, p_j and A's apex.
    pub a_loc: [usize; 3],
    /// Local indices in piece B of p_i, p_j and B's apex.
    pub b_loc: [usize; 3],
    /// Barycentric coordinates of apexB in piece A's tetrahedron.
    pub beta_a: [f64; 4],
    /// Barycentric coordinates of apexA in piece B's tetrahedron.
    pub beta_b: [f64; 4],
    /// Precomputed gather of [`EdgeFrame::weights`]: per edge weight, the piece (0 = A,
    /// 1 = B, 2 = computed by (2.3)) and the index in it.
    copy: [(u8, u8); N3],
    /// The four weights of piece A (B) blended by β_a (β_b) for f_0021 (f_0012) and the four
    /// rational weights, in the order of [`EdgeFrame::weights`].
    c1: [[u8; 4]; 6],
}

impl EdgeFrame {
    /// Sets the frame up; None when a piece's tetrahedron is degenerate or does not contain
    /// p_i and p_j.
    #[must_use]
    pub fn new(a: &Piece, b: &Piece, pi: DVec3, pj: DVec3) -> Option<Self> {
        Self::from_tets(&a.pts, &b.pts, pi, pj)
    }

    /// [`EdgeFrame::new`] from the pieces' tetrahedra (`Piece::pts`) alone.
    #[must_use]
    pub fn from_tets(a: &[DVec3; 4], b: &[DVec3; 4], pi: DVec3, pj: DVec3) -> Option<Self> {
        let loc = |pts: &[DVec3; 4]| -> Option<[usize; 3]> {
            let i = (0..3).find(|&k| pts[k] == pi)?;
            let j = (0..3).find(|&k| pts[k] == pj)?;
            Some([i, j, 3])
        };
        let (a_loc, b_loc) = (loc(a)?, loc(b)?);
        let (copy, c1) = frame_tables(a_loc, b_loc);
        Some(EdgeFrame {
            a_loc,
            b_loc,
            beta_a: bary(a, b[3])?,
            beta_b: bary(b, a[3])?,
            copy,
            c1,
        })
    }

    /// The edge tetrahedron's weights (order p_i, p_j, apexA, apexB) and rational weights
    /// [A-side of (p_i apexA apexB), B-side of it, A-side of (p_j apexA apexB), B-side of it],
    /// from the weights of pieces A and B (linear in them): Step 7 (number 5 weights zero, the
    /// rational ones by (2.3)) and Step 9 (number 7 weights by (2.3)).
    #[must_use]
    pub fn weights(&self, wa: &[f64; N3], wb: &[f64; N3]) -> ([f64; N3], [f64; 4]) {
        // A branch-free gather (the sources differ from frame to frame, so a `match` on
        // them mispredicted): source 2 reads the zero of the number 5 weights, or a value
        // that the blends below overwrite.
        let zero = [0.0; N3];
        let src = [wa, wb, &zero];
        let e: [f64; N3] = std::array::from_fn(|k| {
            let (s, i) = self.copy[k];
            src[usize::from(s)][usize::from(i)]
        });
        let mut e = e;
        // Σ_r β_r w(face multiset + e_r), alternating A and B.
        let blend = |k: usize| -> f64 {
            let (w, beta) = if k.is_multiple_of(2) {
                (wa, &self.beta_a)
            } else {
                (wb, &self.beta_b)
            };
            (0..4)
                .map(|r| beta[r] * w[usize::from(self.c1[k][r])])
                .sum()
        };
        e[edge_ix().0] = blend(0);
        e[edge_ix().1] = blend(1);
        (e, [blend(2), blend(3), blend(4), blend(5)])
    }
}

/// Indices of f_0021 and f_0012 (computed once).
fn edge_ix() -> (usize, usize) {
    static I: OnceLock<(usize, usize)> = OnceLock::new();
    *I.get_or_init(|| (ix([0, 0, 2, 1]), ix([0, 0, 1, 2])))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every piece, convex or nonconvex, has the `dw` of [`piece_dw`] (the build keeps pieces
    /// without it), and it is 1/3 at the three number 4 weights, 1 at f_0003, 0 elsewhere.
    #[test]
    fn every_piece_has_the_shared_dw() {
        let dw = piece_dw();
        let third: Vec<usize> = (0..N3).filter(|&k| dw[k] == 1.0 / 3.0).collect();
        assert_eq!(third.len(), 3);
        assert!(third.iter().all(|&k| cubic_indices()[k][3] == 2));
        assert_eq!(dw[ix([0, 0, 0, 3])], 1.0);
        assert_eq!(dw.iter().filter(|&&x| x != 0.0).count(), 4);
        let p = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(0.2, 0.9, 0.1),
        ];
        let n = [
            DVec3::new(0.1, -0.2, 1.0).normalize(),
            DVec3::new(0.3, 0.1, 1.0).normalize(),
            DVec3::new(-0.2, 0.2, 1.0).normalize(),
        ];
        let fd = FaceData::new(p, n);
        let c = (p[0] + p[1] + p[2]) / 3.0;
        for apex in [c + 0.3 * DVec3::Z, c - 0.3 * DVec3::Z] {
            assert_eq!(convex_piece(&fd, apex).dw, *dw);
            for pc in nonconvex_pieces(&fd, apex) {
                assert_eq!(pc.dw, *dw);
            }
        }
    }
}
