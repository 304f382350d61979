//! Certified Lemma 2.3 bounds over a whole family of shooting lines, by Bernstein subdivision.
//!
//! The lines of a face piece are parametrised by their base point a in the base triangle, those
//! of an edge tetrahedron by (x, y) ∈ [0, 1]² (see [`super::edge_shooting`]). Along the line
//! at parameter a the shooting cubic is P(a) + b·D(a) (see [`super::bound`]); each of its
//! Bernstein coefficients p_s(a), d_s(a) is a polynomial in a (the face's rational term (4.1)
//! is a rational function, handled below), and d_0 = d_1 = 0.
//!
//! For a fixed t* the de Casteljau values P_k(a, t*), D_k(a, t*) are polynomials in a, and the
//! threshold of Lemma 2.3 at t* ([`super::bound::threshold_at`]) is max(−P_2/D_2, −P_3/D_3)
//! (first case), or −P_3/D_3 where P_1 ≤ 0 (second case). Over a sub-domain S, written in the
//! Bernstein basis of S with coefficients c_i (for −P_k) and e_i > 0 (for D_k),
//!   sup_S (−P_k / D_k) ≤ max_i c_i / e_i
//! (the ratio is a weighted mean of the c_i / e_i with weights e_i B_i / Σ e_j B_j), and
//! sup_S P_1 ≤ max_i of P_1's coefficients (and, as lines with p_0 > 0 ask for nothing,
//! also ≤ t*·max_i of p_1's). So every t* gives, per sub-domain, a number U(S)
//! with b_min(a) ≤ U(S) for every a ∈ S: a *certificate*, not a sample. We take the smallest
//! U(S) over a few t* (the best t* at the centre of S, the parent's, the largest t* where
//! the second case is certified, a fixed grid and a golden-section refinement).
//!
//! [`sup_bound`] runs a best-first branch and bound over the sub-domains (triangles split at
//! the edge midpoints into 4, squares into 4): a sub-domain is dropped when U(S) ≤ the floor
//! (its lines ask for nothing above the floor), and the search stops when the largest open
//! U(S) is within `tol` of the largest value L met at a sampled line (centres of the
//! sub-domains, plus a seed), or when the depth or node budget runs out. The result is the
//! largest U(S) left open (or the floor), so it is **never below the exact bound**
//! sup_a b_min(a), whatever happens; when [`Certified::converged`] it is at most L + `tol`,
//! and L exceeds the exact bound only by the t*-accuracy of [`super::bound::lemma_bound`]
//! (~1e-5 of the coefficient scale).
//!
//! The face's rational term adds g(a)·B³_111(a) to p_0, where g = Σ α_i r_i is a convex blend
//! of the rational weights with α_i = a_j a_k / (a_1a_2 + a_0a_2 + a_0a_1). Over S, g lies in
//! [min, max] of num_i / den_i (the same weighted-mean argument, numerator and denominator in
//! the quadratic Bernstein basis of S) when every den_i > 0, else in [min r, max r]; with
//! B³_111 ≥ 0 this gives polynomials p_0^lo ≤ p_0 ≤ p_0^hi on S, used where P_k needs a lower
//! (P_2, P_3) or an upper (P_1) bound.

use super::bound::lemma_bound_arg;
use super::weights::{cubic_indices, N3};
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::sync::OnceLock;

/// Stopping rules of [`sup_bound`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoverOptions {
    /// Stop when the certified value is within this of the best sampled value.
    pub tol: f64,
    /// Largest subdivision depth (sub-domains of size 2^−depth).
    pub max_depth: u32,
    /// Largest number of sub-domains examined.
    pub max_nodes: usize,
}

/// The result of [`sup_bound`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Certified {
    /// A value ≥ max(floor, b_min(a)) for every line a of the family (always).
    pub value: f64,
    /// The largest b_min met at a sampled line (or the seed), ≤ `value` up to the t*-accuracy.
    pub sampled: f64,
    /// Sub-domains examined.
    pub nodes: usize,
    /// Some sub-domain had no finite certificate (D_k not certifiably positive there) and was
    /// given up: `value` covers the rest, those lines only through their sampled centres, so
    /// the caller adds a grid sampling of the family (the bound before certificates).
    pub uncertified: bool,
    /// Whether `value` ≤ max(floor, sampled) + tol (the budget did not run out first).
    pub converged: bool,
}

/// Bernstein coefficients, over one sub-domain, of the shooting cubics' coefficients (the
/// first `n` of 16 slots are used: 10 for a triangle, 16 for a square).
#[derive(Clone, Copy, Debug)]
pub struct Bundle {
    /// Lower and upper polynomial bounds of p_0.
    pub p0: [[f64; 16]; 2],
    /// p_1, p_2, p_3.
    pub p: [[f64; 16]; 3],
    /// d_2, d_3.
    pub d: [[f64; 16]; 2],
}

impl Bundle {
    const ZERO: Bundle = Bundle {
        p0: [[0.0; 16]; 2],
        p: [[0.0; 16]; 3],
        d: [[0.0; 16]; 2],
    };
}

/// The coefficient-wise certificate of one sub-domain at one t*: a value ≥ the threshold of
/// Lemma 2.3 at t* on every line of the sub-domain (∞ when t* gives none).
#[must_use]
pub fn certificate(b: &Bundle, n: usize, t: f64) -> f64 {
    let s = 1.0 - t;
    let (s2, st, t2) = (s * s, s * t, t * t);
    let (s3, s2t, st2, t3) = (s2 * s, s2 * t, s * t2, t2 * t);
    let mut case1 = f64::NEG_INFINITY;
    let mut last = f64::NEG_INFINITY;
    let mut p1_max = f64::NEG_INFINITY;
    let mut p1_top = f64::NEG_INFINITY;
    for i in 0..n {
        let (lo, hi) = (b.p0[0][i], b.p0[1][i]);
        let (p1, p2, p3) = (b.p[0][i], b.p[1][i], b.p[2][i]);
        let (d2, d3) = (b.d[0][i], b.d[1][i]);
        // D_2 = d_2 t², D_3 = 3 d_2 s t² + d_3 t³ (d_0 = d_1 = 0).
        let e2 = d2 * t2;
        let e3 = 3.0 * d2 * st2 + d3 * t3;
        if !(e2 > 0.0 && e3 > 0.0) {
            return f64::INFINITY;
        }
        let q2 = lo * s2 + 2.0 * p1 * st + p2 * t2;
        let q3 = lo * s3 + 3.0 * p1 * s2t + 3.0 * p2 * st2 + p3 * t3;
        last = last.max(-q3 / e3);
        case1 = case1.max(-q2 / e2);
        p1_max = p1_max.max(hi * s + p1 * t);
        p1_top = p1_top.max(p1);
    }
    // Lines with p_0 > 0 ask for nothing, so on the others P_1 ≤ p_1 t as well.
    if p1_max.min(p1_top * t) <= 0.0 {
        last
    } else {
        case1.max(last)
    }
}

/// The largest t* at which every coefficient of P_1 (upper bound) is ≤ 0, if any: the
/// second case of the lemma is certified on [0, t*].
fn case2_limit(b: &Bundle, n: usize) -> Option<f64> {
    if (0..n).all(|i| b.p[0][i] <= 0.0) {
        return Some(1.0);
    }
    let mut lim = 1.0f64;
    for i in 0..n {
        let (hi, p1) = (b.p0[1][i], b.p[0][i]);
        // P_1 = hi (1 − t) + p_1 t ≤ 0.
        if hi > 0.0 {
            return None;
        }
        if p1 > 0.0 {
            lim = lim.min(-hi / (p1 - hi));
        }
    }
    (lim > 0.0).then_some(lim * (1.0 - 1e-12))
}

/// Candidate values of t* besides the node's own: 1, j/8 and 2^−k down to 2^−10.
const T_GRID: [f64; 14] = [
    1.0,
    0.875,
    0.75,
    0.625,
    0.5,
    0.375,
    0.25,
    0.125,
    0.0625,
    0.03125,
    0.015625,
    0.0078125,
    0.00390625,
    0.0009765625,
];

/// The smallest [`certificate`] found over t*: the centre's best t* `tc`, the parent's `tp`,
/// the second case's limit, a fixed grid, then 10 golden-section steps around the best grid
/// value; it stops as soon as a value ≤ `floor` is found. Returns the value and its t*.
/// (Any t* gives a valid certificate; the search only makes it tighter.)
fn best_certificate(b: &Bundle, n: usize, tc: f64, tp: f64, floor: f64) -> (f64, f64) {
    let mut best = (f64::INFINITY, tc);
    let consider = |t: f64, best: &mut (f64, f64)| {
        if t > 0.0 && t <= 1.0 {
            let u = certificate(b, n, t);
            if u < best.0 {
                *best = (u, t);
            }
        }
    };
    consider(tc, &mut best);
    if best.0 <= floor {
        // Settled: the node's lines need nothing above the floor.
        return best;
    }
    consider(tp, &mut best);
    if let Some(l) = case2_limit(b, n) {
        consider(l.min(tc), &mut best);
        consider(l, &mut best);
    }
    if best.0 <= floor {
        return best;
    }
    let mut grid_best = (f64::INFINITY, 0usize);
    for (k, &t) in T_GRID.iter().enumerate() {
        let u = certificate(b, n, t);
        if u < grid_best.0 {
            grid_best = (u, k);
        }
        if u < best.0 {
            best = (u, t);
        }
    }
    if grid_best.0.is_finite() {
        let k = grid_best.1;
        let hi = if k == 0 { 1.0 } else { T_GRID[k - 1] };
        let lo = T_GRID.get(k + 1).copied().unwrap_or(0.0);
        let (mut lo, mut hi) = (lo, hi);
        let g = 0.618_033_988_749_894_9;
        for _ in 0..10 {
            let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            let (f1, f2) = (certificate(b, n, x1), certificate(b, n, x2));
            if f1.min(f2) < best.0 {
                best = if f1 < f2 { (f1, x1) } else { (f2, x2) };
            }
            if f1 < f2 {
                hi = x2;
            } else {
                lo = x1;
            }
        }
    }
    best
}

/// A family of shooting lines over a subdivisible domain.
pub trait Family {
    /// One sub-domain with its polynomials.
    type Node;
    /// Number of Bernstein coefficients per polynomial (≤ 16).
    const N: usize;
    /// The bundle of bounds over the node.
    fn bundle(&self, node: &Self::Node) -> Bundle;
    /// The shooting cubic (P, D) at the node's centre.
    fn centre(&self, node: &Self::Node) -> ([f64; 4], [f64; 4]);
    /// The four children.
    fn split(&self, node: &Self::Node) -> [Self::Node; 4];
}

struct Open<T> {
    u: f64,
    seq: usize,
    depth: u32,
    t: f64,
    node: T,
}

impl<T> PartialEq for Open<T> {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl<T> Eq for Open<T> {}
impl<T> PartialOrd for Open<T> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl<T> Ord for Open<T> {
    fn cmp(&self, o: &Self) -> Ordering {
        // Largest U first; ties by creation order (deterministic).
        self.u.total_cmp(&o.u).then(o.seq.cmp(&self.seq))
    }
}

/// The state of one branch and bound.
struct Search<'a, F: Family> {
    fam: &'a F,
    opts: &'a CoverOptions,
    floor: f64,
    heap: BinaryHeap<Open<F::Node>>,
    sampled: f64,
    stuck: f64,
    nodes: usize,
    seq: usize,
    /// Whether some sub-domain was given up as uncertifiable (see [`UNCERTIFIED_DEPTH`]).
    uncertified: bool,
}

/// Depth from which a sub-domain whose every certificate is +∞ (some derivative coefficient
/// e_i ≤ 0 there, so Lemma 2.3's ratio bound does not exist) is given up: its lines count
/// through their sampled centres only, as in the sampled bound before certificates. Without
/// this cut such a sub-domain is split until the node budget runs out, for nothing.
const UNCERTIFIED_DEPTH: u32 = 4;

impl<F: Family> Search<'_, F> {
    /// Examines one node: samples its centre, certifies it, keeps it open unless settled.
    fn visit(&mut self, node: F::Node, depth: u32, t_parent: f64) {
        self.nodes += 1;
        let (p, d) = self.fam.centre(&node);
        let (v, tc) = lemma_bound_arg(p, d);
        if v.is_finite() {
            self.sampled = self.sampled.max(v);
        }
        let b = self.fam.bundle(&node);
        let (u, t) = best_certificate(&b, F::N, tc, t_parent, self.floor);
        if u <= self.floor {
            return;
        }
        if u == f64::INFINITY && depth >= UNCERTIFIED_DEPTH {
            self.uncertified = true;
            return;
        }
        if depth >= self.opts.max_depth {
            self.stuck = self.stuck.max(u);
            return;
        }
        self.seq += 1;
        self.heap.push(Open {
            u,
            seq: self.seq,
            depth,
            t,
            node,
        });
    }
}

/// Certified max(floor, sup over the family of b_min) (see the module docs). `seed` is a
/// sampled value (e.g. the maximum over a grid of lines) that starts the lower estimate L.
pub fn sup_bound<F: Family>(
    fam: &F,
    root: F::Node,
    floor: f64,
    seed: f64,
    opts: &CoverOptions,
) -> Certified {
    let mut s = Search {
        fam,
        opts,
        floor,
        heap: BinaryHeap::new(),
        sampled: seed,
        stuck: floor,
        nodes: 0,
        seq: 0,
        uncertified: false,
    };
    s.visit(root, 0, 0.5);
    let mut converged = true;
    while let Some(top) = s.heap.peek() {
        if top.u <= (s.sampled + opts.tol).max(s.stuck) {
            break;
        }
        if s.nodes + 4 > opts.max_nodes {
            converged = false;
            break;
        }
        let top = s.heap.pop().expect("peeked");
        for c in fam.split(&top.node) {
            s.visit(c, top.depth + 1, top.t);
        }
    }
    let open = s.heap.peek().map_or(f64::NEG_INFINITY, |o| o.u);
    let mut value = floor.max(s.stuck).max(open);
    let mut uncertified = s.uncertified;
    if !value.is_finite() {
        // Left open at +∞ (the node budget ran out first): as uncertified.
        value = floor.max(s.stuck).max(s.sampled);
        uncertified = true;
    }
    if value > floor.max(s.sampled) + opts.tol || uncertified {
        converged = false;
    }
    Certified {
        value,
        sampled: s.sampled,
        nodes: s.nodes,
        uncertified,
        converged,
    }
}

// ---------------------------------------------------------------------------------------
// Triangles (face pieces).

/// Multi-indices (i, j, k), i + j + k = n, in a fixed order.
fn tri_indices(n: u8) -> Vec<[u8; 3]> {
    let mut v = Vec::new();
    for i in (0..=n).rev() {
        for j in (0..=n - i).rev() {
            v.push([i, j, n - i - j]);
        }
    }
    v
}

fn fact(n: u8) -> f64 {
    (1..=u32::from(n)).map(f64::from).product()
}

/// Blossom of a triangle Bernstein polynomial of degree n at the barycentric points `u`.
fn tri_blossom(c: &[f64], n: u8, u: &[[f64; 3]]) -> f64 {
    let mut cur: Vec<f64> = c.to_vec();
    let mut deg = n;
    for x in u {
        let lower = tri_indices(deg - 1);
        let upper = tri_indices(deg);
        let pos = |l: [u8; 3]| upper.iter().position(|&m| m == l).expect("index");
        cur = lower
            .iter()
            .map(|l| {
                (0..3)
                    .map(|i| {
                        let mut m = *l;
                        m[i] += 1;
                        x[i] * cur[pos(m)]
                    })
                    .sum()
            })
            .collect();
        deg -= 1;
    }
    cur[0]
}

/// Restriction matrices of the 4 midpoint children (rows: child coefficient, columns: parent).
fn tri_split_mats(n: u8) -> Vec<Vec<Vec<f64>>> {
    let idx = tri_indices(n);
    let e = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mid =
        |a: usize, b: usize| -> [f64; 3] { std::array::from_fn(|k| 0.5 * (e[a][k] + e[b][k])) };
    let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
    let children = [
        [e[0], m01, m20],
        [m01, e[1], m12],
        [m20, m12, e[2]],
        [m12, m20, m01],
    ];
    children
        .iter()
        .map(|v| {
            idx.iter()
                .map(|mu| {
                    let pts: Vec<[f64; 3]> = (0..3)
                        .flat_map(|i| std::iter::repeat_n(v[i], usize::from(mu[i])))
                        .collect();
                    (0..idx.len())
                        .map(|col| {
                            let mut c = vec![0.0; idx.len()];
                            c[col] = 1.0;
                            tri_blossom(&c, n, &pts)
                        })
                        .collect()
                })
                .collect()
        })
        .collect()
}

struct TriTables {
    /// Child restriction matrices, degree 3 (10 × 10) and 2 (6 × 6).
    split3: Vec<[[f64; 10]; 10]>,
    split2: Vec<[[f64; 6]; 6]>,
    /// Per cubic weight: its layer and its degree-3 triangle coefficients.
    elev: Vec<(usize, [f64; 10])>,
    /// Index of (1, 1, 1) in the degree-3 order and of (0,1,1), (1,0,1), (1,1,0) in degree 2.
    i111: usize,
    i2: [usize; 3],
    /// Values of the degree-3 and degree-2 basis functions at the centre (1/3, 1/3, 1/3).
    c3: [f64; 10],
    c2: [f64; 6],
}

fn tri_tables() -> &'static TriTables {
    static T: OnceLock<TriTables> = OnceLock::new();
    T.get_or_init(|| {
        let conv3 = |m: Vec<Vec<f64>>| -> [[f64; 10]; 10] {
            std::array::from_fn(|r| std::array::from_fn(|c| m[r][c]))
        };
        let conv2 = |m: Vec<Vec<f64>>| -> [[f64; 6]; 6] {
            std::array::from_fn(|r| std::array::from_fn(|c| m[r][c]))
        };
        let i3 = tri_indices(3);
        let elev = cubic_indices()
            .iter()
            .map(|l| {
                let s = l[3];
                let m = 3 - s;
                let lam = [l[0], l[1], l[2]];
                let mut out = [0.0; 10];
                for nu in tri_indices(s) {
                    let mu = [lam[0] + nu[0], lam[1] + nu[1], lam[2] + nu[2]];
                    let k = i3.iter().position(|&x| x == mu).expect("index");
                    let num = fact(m) * fact(s) * mu.iter().map(|&x| fact(x)).product::<f64>();
                    let den = lam.iter().chain(&nu).map(|&x| fact(x)).product::<f64>() * 6.0;
                    out[k] += num / den;
                }
                (usize::from(s), out)
            })
            .collect();
        let i2 = tri_indices(2);
        let pos2 = |m: [u8; 3]| i2.iter().position(|&x| x == m).expect("index");
        TriTables {
            split3: tri_split_mats(3).into_iter().map(conv3).collect(),
            split2: tri_split_mats(2).into_iter().map(conv2).collect(),
            elev,
            i111: i3.iter().position(|&x| x == [1, 1, 1]).expect("index"),
            i2: [pos2([0, 1, 1]), pos2([1, 0, 1]), pos2([1, 1, 0])],
            c3: std::array::from_fn(|k| centre_value(i3[k], 3)),
            c2: std::array::from_fn(|k| centre_value(i2[k], 2)),
        }
    })
}

/// A sub-triangle of a face piece's base: σ-scaled p_0 (polynomial part), B³_111, p_1..p_3
/// (degree 3) and the rational blend's numerator and denominator (degree 2).
#[derive(Clone, Debug)]
pub struct TriNode {
    q: [[f64; 10]; 5],
    num: [f64; 6],
    den: [f64; 6],
}

/// The shooting lines of one face piece (D = (0, 0, 1/3, 1), the paper's β = 1).
#[derive(Clone, Debug)]
pub struct FaceFamily {
    /// σ × the rational weights (bounds of the blend where the ratio test fails).
    r: Option<[f64; 3]>,
}

impl FaceFamily {
    /// The family of a face piece with weights `w` (at the free value of interest), rational
    /// weights `rat`, on side σ; and its root node (the whole base triangle).
    #[must_use]
    pub fn new(w: &[f64; N3], rat: Option<&[f64; 3]>, sigma: f64) -> (FaceFamily, TriNode) {
        let tt = tri_tables();
        let mut q = [[0.0; 10]; 5];
        for (k, (s, e)) in tt.elev.iter().enumerate() {
            let slot = if *s == 0 { 0 } else { s + 1 };
            for i in 0..10 {
                q[slot][i] += sigma * w[k] * e[i];
            }
        }
        q[1][tt.i111] = 1.0;
        let mut num = [0.0; 6];
        let mut den = [0.0; 6];
        let r = rat.map(|r| r.map(|x| sigma * x));
        if let Some(r) = r {
            for m in 0..3 {
                num[tt.i2[m]] = 0.5 * r[m];
                den[tt.i2[m]] = 0.5;
            }
        }
        (FaceFamily { r }, TriNode { q, num, den })
    }

    /// The range of the rational blend g over the node.
    fn blend(&self, n: &TriNode) -> (f64, f64) {
        let Some(r) = self.r else { return (0.0, 0.0) };
        if n.den.iter().all(|&d| d > 0.0) {
            (0..6).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), i| {
                let g = n.num[i] / n.den[i];
                (lo.min(g), hi.max(g))
            })
        } else {
            (r[0].min(r[1]).min(r[2]), r[0].max(r[1]).max(r[2]))
        }
    }
}

/// B^n_μ(1/3, 1/3, 1/3) = n!/μ! / 3^n.
fn centre_value(mu: [u8; 3], n: u8) -> f64 {
    fact(n) / mu.iter().map(|&k| fact(k)).product::<f64>() / 3f64.powi(i32::from(n))
}

fn dot<const M: usize>(a: &[f64; M], b: &[f64; M]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Family for FaceFamily {
    type Node = TriNode;
    const N: usize = 10;

    fn bundle(&self, n: &TriNode) -> Bundle {
        let (glo, ghi) = self.blend(n);
        let mut b = Bundle::ZERO;
        for i in 0..10 {
            b.p0[0][i] = n.q[0][i] + glo * n.q[1][i];
            b.p0[1][i] = n.q[0][i] + ghi * n.q[1][i];
            for k in 0..3 {
                b.p[k][i] = n.q[k + 2][i];
            }
            b.d[0][i] = 1.0 / 3.0;
            b.d[1][i] = 1.0;
        }
        b
    }

    fn centre(&self, n: &TriNode) -> ([f64; 4], [f64; 4]) {
        let tt = tri_tables();
        let den = dot(&n.den, &tt.c2);
        let g = if self.r.is_some() && den > 0.0 {
            dot(&n.num, &tt.c2) / den
        } else {
            0.0
        };
        let p0 = dot(&n.q[0], &tt.c3) + g * dot(&n.q[1], &tt.c3);
        (
            [
                p0,
                dot(&n.q[2], &tt.c3),
                dot(&n.q[3], &tt.c3),
                dot(&n.q[4], &tt.c3),
            ],
            [0.0, 0.0, 1.0 / 3.0, 1.0],
        )
    }

    fn split(&self, n: &TriNode) -> [TriNode; 4] {
        let tt = tri_tables();
        std::array::from_fn(|c| {
            let m3 = &tt.split3[c];
            let m2 = &tt.split2[c];
            let mul3 = |x: &[f64; 10]| -> [f64; 10] {
                std::array::from_fn(|r| (0..10).map(|j| m3[r][j] * x[j]).sum())
            };
            let mul2 = |x: &[f64; 6]| -> [f64; 6] {
                std::array::from_fn(|r| (0..6).map(|j| m2[r][j] * x[j]).sum())
            };
            TriNode {
                q: std::array::from_fn(|k| mul3(&n.q[k])),
                num: mul2(&n.num),
                den: mul2(&n.den),
            }
        })
    }
}

// ---------------------------------------------------------------------------------------
// Squares (edge tetrahedra).

/// Univariate degree-3 halves: rows of the left and right restriction matrices.
const HALF: [[[f64; 4]; 4]; 2] = [
    [
        [1.0, 0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0, 0.0],
        [0.25, 0.5, 0.25, 0.0],
        [0.125, 0.375, 0.375, 0.125],
    ],
    [
        [0.125, 0.375, 0.375, 0.125],
        [0.0, 0.25, 0.5, 0.25],
        [0.0, 0.0, 0.5, 0.5],
        [0.0, 0.0, 0.0, 1.0],
    ],
];

/// A sub-square of an edge tetrahedron's (x, y) domain: p_0..p_3, d_2, d_3 as bicubic
/// Bernstein coefficients `[i * 4 + j]` (x degree i, y degree j).
#[derive(Clone, Debug)]
pub struct SquareNode {
    q: [[f64; 16]; 6],
}

/// The shooting lines of one edge tetrahedron.
#[derive(Clone, Debug)]
pub struct EdgeFamily;

fn binom(n: u8, k: u8) -> f64 {
    fact(n) / (fact(k) * fact(n - k))
}

/// Coefficient of B^3_j in the degree elevation of B^m_i.
fn elev1(m: u8, i: u8, j: u8) -> f64 {
    if j < i || j - i > 3 - m {
        return 0.0;
    }
    binom(m, i) * binom(3 - m, j - i) / binom(3, j)
}

/// Per cubic weight its layer and bicubic coefficients; per rational weight its coefficients.
type EdgeTables = (Vec<(usize, [f64; 16])>, [[f64; 16]; 4]);

fn edge_tables() -> &'static EdgeTables {
    static T: OnceLock<EdgeTables> = OnceLock::new();
    T.get_or_init(|| {
        let tensor = |mx: u8, ix: u8, my: u8, iy: u8| -> [f64; 16] {
            std::array::from_fn(|k| {
                let (jx, jy) = ((k / 4) as u8, (k % 4) as u8);
                elev1(mx, ix, jx) * elev1(my, iy, jy)
            })
        };
        let w = cubic_indices()
            .iter()
            .map(|l| {
                let s = l[2] + l[3];
                (usize::from(s), tensor(3 - s, l[0], s, l[2]))
            })
            .collect();
        // x·2y(1−y)(r_0 y + r_1 (1−y)) + (1−x)·2y(1−y)(r_2 y + r_3 (1−y)) with
        // 2y²(1−y) = (2/3) B³_2(y), 2y(1−y)² = (2/3) B³_1(y).
        let scale = |mut a: [f64; 16], f: f64| {
            a.iter_mut().for_each(|x| *x *= f);
            a
        };
        let r = [
            scale(tensor(1, 1, 3, 2), 2.0 / 3.0),
            scale(tensor(1, 1, 3, 1), 2.0 / 3.0),
            scale(tensor(1, 0, 3, 2), 2.0 / 3.0),
            scale(tensor(1, 0, 3, 1), 2.0 / 3.0),
        ];
        (w, r)
    })
}

impl EdgeFamily {
    /// The root node of an edge tetrahedron with weights `w`, rational weights `r` (σ-scaled
    /// by `sigma`) and b-derivatives `dw`, `dr`.
    #[must_use]
    pub fn root(
        w: &[f64; N3],
        r: &[f64; 4],
        dw: &[f64; N3],
        dr: &[f64; 4],
        sigma: f64,
    ) -> SquareNode {
        let (tw, tr) = edge_tables();
        let mut q = [[0.0; 16]; 6];
        for (k, (s, e)) in tw.iter().enumerate() {
            for i in 0..16 {
                q[*s][i] += sigma * w[k] * e[i];
                if *s >= 2 {
                    q[*s + 2][i] += dw[k] * e[i];
                }
            }
        }
        for m in 0..4 {
            for i in 0..16 {
                q[2][i] += sigma * r[m] * tr[m][i];
                q[4][i] += dr[m] * tr[m][i];
            }
        }
        SquareNode { q }
    }
}

impl Family for EdgeFamily {
    type Node = SquareNode;
    const N: usize = 16;

    fn bundle(&self, n: &SquareNode) -> Bundle {
        Bundle {
            p0: [n.q[0], n.q[0]],
            p: [n.q[1], n.q[2], n.q[3]],
            d: [n.q[4], n.q[5]],
        }
    }

    fn centre(&self, n: &SquareNode) -> ([f64; 4], [f64; 4]) {
        const H: [f64; 4] = [0.125, 0.375, 0.375, 0.125];
        let ev = |c: &[f64; 16]| -> f64 { (0..16).map(|k| c[k] * H[k / 4] * H[k % 4]).sum() };
        (
            [ev(&n.q[0]), ev(&n.q[1]), ev(&n.q[2]), ev(&n.q[3])],
            [0.0, 0.0, ev(&n.q[4]), ev(&n.q[5])],
        )
    }

    fn split(&self, n: &SquareNode) -> [SquareNode; 4] {
        std::array::from_fn(|c| {
            let (hx, hy) = (&HALF[c / 2], &HALF[c % 2]);
            SquareNode {
                q: std::array::from_fn(|k| {
                    let a = &n.q[k];
                    std::array::from_fn(|m| {
                        let (i, j) = (m / 4, m % 4);
                        let mut v = 0.0;
                        for ii in 0..4 {
                            for jj in 0..4 {
                                v += hx[i][ii] * hy[j][jj] * a[ii * 4 + jj];
                            }
                        }
                        v
                    })
                }),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::bound::threshold_at;
    use super::super::{edge_shooting, face_shooting};
    use super::*;

    use super::super::tests::Rng;

    /// A reference b_min of one line, from above but much finer in t* than
    /// [`lemma_bound_arg`]: the minimum of the threshold over 1024 values of t*, refined by
    /// 80 golden-section steps around the best one (to ~1e-15 in t*).
    fn fine_bound(p: [f64; 4], d: [f64; 4]) -> f64 {
        if p[0] > 0.0 {
            return f64::NEG_INFINITY;
        }
        let f = |t: f64| threshold_at(p, d, t);
        let n = 1024;
        let (k, best) = (1..=n)
            .map(|k| (k, f(f64::from(k) / f64::from(n))))
            .fold((1, f64::INFINITY), |a, x| if x.1 < a.1 { x } else { a });
        let (mut lo, mut hi) = (
            f64::from(k - 1) / f64::from(n),
            (f64::from(k + 1) / f64::from(n)).min(1.0),
        );
        let g = 0.618_033_988_749_894_9;
        let mut out = best;
        for _ in 0..80 {
            let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
            let (f1, f2) = (f(x1), f(x2));
            out = out.min(f1).min(f2);
            if f1 < f2 {
                hi = x2;
            } else {
                lo = x1;
            }
        }
        out
    }

    /// The centre of every node (root and two levels of children) carries the shooting cubic
    /// that [`face_shooting`] computes at that point: the tables (degree elevation, subdivision,
    /// rational blend) are right. Children of child k of the root are followed by barycentrics.
    #[test]
    fn face_nodes_match_face_shooting() {
        let mut rng = Rng(0x5eed_0001_f00d_cafe);
        let w: [f64; N3] = std::array::from_fn(|_| rng.next());
        let rat = [rng.next(), rng.next(), rng.next()];
        for sigma in [1.0, -1.0] {
            let (fam, root) = FaceFamily::new(&w, Some(&rat), sigma);
            // Vertices (barycentric in the base) of each node, children as in tri_split_mats.
            let corners = |v: [[f64; 3]; 3], c: usize| -> [[f64; 3]; 3] {
                let mid = |a: usize, b: usize| -> [f64; 3] {
                    std::array::from_fn(|k| 0.5 * (v[a][k] + v[b][k]))
                };
                let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
                [
                    [v[0], m01, m20],
                    [m01, v[1], m12],
                    [m20, m12, v[2]],
                    [m12, m20, m01],
                ][c]
            };
            let mut stack = vec![(root, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], 0)];
            let mut seen = 0;
            while let Some((n, v, depth)) = stack.pop() {
                seen += 1;
                let a: [f64; 3] = std::array::from_fn(|k| (v[0][k] + v[1][k] + v[2][k]) / 3.0);
                let want = face_shooting(&w, Some(&rat), a).map(|x| sigma * x);
                let (got, d) = fam.centre(&n);
                assert_eq!(d, [0.0, 0.0, 1.0 / 3.0, 1.0]);
                for k in 0..4 {
                    // Sums of ~20 O(1) terms through ≤ 3 subdivisions: rounding only.
                    assert!(
                        (got[k] - want[k]).abs() < 1e-12,
                        "{got:?} {want:?} at {a:?}"
                    );
                }
                if depth < 2 {
                    for (c, child) in fam.split(&n).into_iter().enumerate() {
                        stack.push((child, corners(v, c), depth + 1));
                    }
                }
            }
            assert_eq!(seen, 21);
        }
    }

    /// The same for an edge tetrahedron's square against [`edge_shooting`].
    #[test]
    fn square_nodes_match_edge_shooting() {
        let mut rng = Rng(0x5eed_0002_f00d_cafe);
        let w: [f64; N3] = std::array::from_fn(|_| rng.next());
        let r: [f64; 4] = std::array::from_fn(|_| rng.next());
        // ∂/∂b lives in layers 2 and 3 only (d_0 = d_1 = 0, as in the scheme).
        let dw: [f64; N3] = std::array::from_fn(|k| {
            let l = cubic_indices()[k];
            if l[2] + l[3] >= 2 {
                rng.next()
            } else {
                0.0
            }
        });
        let dr: [f64; 4] = std::array::from_fn(|_| rng.next());
        let root = EdgeFamily::root(&w, &r, &dw, &dr, -1.0);
        let mut stack = vec![(root, (0.0, 1.0, 0.0, 1.0), 0)];
        while let Some((n, (x0, x1, y0, y1), depth)) = stack.pop() {
            let (x, y) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            let want = edge_shooting(&w, &r, x, y).map(|v| -v);
            let dwant = edge_shooting(&dw, &dr, x, y);
            let (got, d) = EdgeFamily.centre(&n);
            for k in 0..4 {
                // Rounding only (O(1) terms).
                assert!((got[k] - want[k]).abs() < 1e-12, "{got:?} {want:?}");
                assert!((d[k] - dwant[k]).abs() < 1e-12, "{d:?} {dwant:?}");
            }
            if depth < 2 {
                for (c, child) in EdgeFamily.split(&n).into_iter().enumerate() {
                    let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
                    let xs = if c / 2 == 0 { (x0, xm) } else { (xm, x1) };
                    let ys = if c % 2 == 0 { (y0, ym) } else { (ym, y1) };
                    stack.push((child, (xs.0, xs.1, ys.0, ys.1), depth + 1));
                }
            }
        }
    }

    /// On random edge tetrahedra (the hard, uncertified kind: top layers of any sign), the
    /// certified value is ≥ the fine reference bound of every line of a dense 48 × 48 grid,
    /// and when converged at most `tol` + the reference's own t*-gap above their maximum.
    #[test]
    fn edge_cover_holds_on_dense_lines() {
        let mut rng = Rng(0x5eed_0003_f00d_cafe);
        let opts = CoverOptions {
            tol: 1e-4,
            max_depth: 14,
            max_nodes: 20_000,
        };
        let mut positive = 0;
        for _ in 0..60 {
            let w: [f64; N3] = std::array::from_fn(|_| rng.next());
            let r: [f64; 4] = std::array::from_fn(|_| 0.2 * rng.next());
            let dw: [f64; N3] = std::array::from_fn(|k| {
                if cubic_indices()[k][2] + cubic_indices()[k][3] >= 2 {
                    rng.next().abs() + 0.05
                } else {
                    0.0
                }
            });
            let dr = [0.0; 4];
            let root = EdgeFamily::root(&w, &r, &dw, &dr, 1.0);
            let c = sup_bound(&EdgeFamily, root, -1.0, f64::NEG_INFINITY, &opts);
            let mut dense = -1.0f64;
            for i in 0..=48 {
                for j in 0..=48 {
                    let (x, y) = (f64::from(i) / 48.0, f64::from(j) / 48.0);
                    let p = edge_shooting(&w, &r, x, y);
                    let d = edge_shooting(&dw, &dr, x, y);
                    dense = dense.max(fine_bound(p, d));
                }
            }
            if dense > -1.0 {
                positive += 1;
            }
            // Rounding of the O(1) coefficient sums only.
            assert!(c.value >= dense - 1e-12, "cover {c:?} < dense {dense}");
            if c.converged {
                // The dense grid can miss the true maximum by a little: 1e-2 (O(1) scale).
                assert!(
                    c.value <= dense + opts.tol + 1e-2,
                    "cover {c:?} dense {dense}"
                );
            }
        }
        assert!(positive > 10, "only {positive} of 60 cases above the floor");
    }
}
