//! Sheet uniqueness, by sampling lines through the patches that can vanish.
//!
//! - Shooting patches ([`SheetRule::Shooting`]): lines from lattice points q of the base simplex
//!   to lattice points u of the top simplex, φ(t) = F((1−t)q + t·u). The minimal root in [0, 1)
//!   must be simple: |φ′| > tolerance · S there (S = the patch's largest weight). Roots are found
//!   from sign changes between samples (refined by bisection) and from sampled local minima of
//!   |φ| whose critical point (bisection on φ′) has |φ| ≤ tolerance · S (touching roots).
//! - Single-sheet patches ([`SheetRule::Any`], degree ≥ 2): lines from each tetrahedron vertex to
//!   lattice points of the opposite face; a line whose samples change sign more than once crosses
//!   F = 0 more than once. (Touching roots and pairs of roots between two samples are not seen.)

use super::eval::PatchEval;
use super::{CheckOptions, JSheet, Location, SheetStats};
use crate::bb::rational::segment_poly;
use crate::bb::{index_of, multi_indices, uni};
use crate::complex::{Patch, SheetRule};
use rayon::prelude::*;

/// Bisection steps on [0, 1]-subintervals: 2⁻⁶⁰ is below f64 resolution of t.
const BISECTIONS: usize = 60;

/// Measures every patch.
pub(super) fn measure(evals: &[PatchEval<'_>], opts: &CheckOptions) -> SheetStats {
    evals
        .par_iter()
        .map(|e| patch_sheets(e, opts, SheetStats::default()))
        .reduce(SheetStats::default, merge)
}

fn merge(a: SheetStats, b: SheetStats) -> SheetStats {
    let b_smaller = match (a.min_root_slope, b.min_root_slope) {
        (None, Some(_)) => true,
        (Some(x), Some(y)) => y < x || (y.is_nan() && !x.is_nan()),
        _ => false,
    };
    let (min_root_slope, min_root_slope_at) = if b_smaller {
        (b.min_root_slope, b.min_root_slope_at)
    } else {
        (a.min_root_slope, a.min_root_slope_at)
    };
    let mut j_sheets = a.j_sheets;
    j_sheets.extend(b.j_sheets);
    SheetStats {
        shooting_patches: a.shooting_patches + b.shooting_patches,
        shooting_lines: a.shooting_lines + b.shooting_lines,
        non_simple: a.non_simple + b.non_simple,
        min_root_slope,
        min_root_slope_at,
        vertex_lines: a.vertex_lines + b.vertex_lines,
        multi_root_lines: a.multi_root_lines + b.multi_root_lines,
        multi_root_at: a.multi_root_at.or(b.multi_root_at),
        multi_sheet_patches: a.multi_sheet_patches + b.multi_sheet_patches,
        multi_sheet_at: a.multi_sheet_at.or(b.multi_sheet_at),
        j_patches: a.j_patches + b.j_patches,
        j_lines: a.j_lines + b.j_lines,
        j_multi_lines: a.j_multi_lines + b.j_multi_lines,
        j_multi_patches: a.j_multi_patches + b.j_multi_patches,
        j_multi_at: a.j_multi_at.or(b.j_multi_at),
        j_sheets,
    }
}

/// Interior lattice points of the simplex on `verts` (tetrahedron-local indices), `res` steps per
/// edge, as barycentric 4-vectors; a single vertex gives itself.
pub(crate) fn simplex_lattice(verts: &[u8], res: usize) -> Vec<[f64; 4]> {
    let res = res.max(verts.len() + 1);
    let mut out = Vec::new();
    let mut put = |w: &[usize]| {
        let mut a = [0.0; 4];
        for (v, &k) in verts.iter().zip(w) {
            a[usize::from(*v)] = k as f64 / res as f64;
        }
        out.push(a);
    };
    match verts.len() {
        1 => put(&[res]),
        2 => (1..res).for_each(|i| put(&[i, res - i])),
        _ => {
            for i in 1..res {
                for j in 1..res - i {
                    put(&[i, j, res - i - j]);
                }
            }
        }
    }
    out
}

fn lerp(q: &[f64; 4], u: &[f64; 4], t: f64) -> [f64; 4] {
    std::array::from_fn(|i| (1.0 - t) * q[i] + t * u[i])
}

fn point(e: &PatchEval<'_>, alpha: [f64; 4]) -> [f64; 3] {
    let v = e.patch.tet_points();
    (0..4)
        .map(|i| alpha[i] * v[i])
        .sum::<glam::DVec3>()
        .to_array()
}

fn patch_sheets(e: &PatchEval<'_>, opts: &CheckOptions, mut stats: SheetStats) -> SheetStats {
    if e.has_no_zero() {
        return stats;
    }
    let n = opts.line_samples.max(4);
    j_lines(e, opts, n, &mut stats);
    match &e.patch.sheet {
        SheetRule::Shooting { base, top } => {
            stats.shooting_patches += 1;
            let s = e.weight_scale().max(f64::MIN_POSITIVE);
            let tol = opts.simple_root_tolerance;
            for q in simplex_lattice(base, opts.sheet_resolution) {
                for u in simplex_lattice(top, opts.sheet_resolution) {
                    stats.shooting_lines += 1;
                    if let Some((t, slope)) = minimal_root(e, &q, &u, n, tol * s) {
                        let rel = slope / s;
                        if rel <= tol || rel.is_nan() {
                            stats.non_simple += 1;
                        }
                        let smaller = stats
                            .min_root_slope
                            .is_none_or(|m| rel < m || (rel.is_nan() && !m.is_nan()));
                        if smaller {
                            stats.min_root_slope = Some(rel);
                            stats.min_root_slope_at =
                                Some(Location::new(&[e], point(e, lerp(&q, &u, t)), None));
                        }
                    }
                }
            }
        }
        SheetRule::Any if e.patch.degree >= 2 => {
            let mut apexes_with_multi_roots = 0;
            for apex in 0..4u8 {
                let mut multi = false;
                let face: Vec<u8> = (0..4u8).filter(|&k| k != apex).collect();
                let mut a = [0.0; 4];
                a[usize::from(apex)] = 1.0;
                for q in simplex_lattice(&face, opts.sheet_resolution) {
                    stats.vertex_lines += 1;
                    let (roots, first) = count_sign_changes(e, &a, &q, n);
                    if roots > 1 {
                        multi = true;
                        stats.multi_root_lines += 1;
                        if stats.multi_root_at.is_none() {
                            stats.multi_root_at =
                                Some(Location::new(&[e], point(e, lerp(&a, &q, first)), None));
                        }
                    }
                }
                apexes_with_multi_roots += usize::from(multi);
            }
            if apexes_with_multi_roots == 4 {
                stats.multi_sheet_patches += 1;
                if stats.multi_sheet_at.is_none() {
                    stats.multi_sheet_at = stats.multi_root_at.clone();
                }
            }
        }
        SheetRule::Any => {}
    }
    stats
}

/// Barycentric lattice points of one simplex of a tetrahedron.
pub(crate) type Lattice = Vec<[f64; 4]>;

/// The ends of a patch's j-lines as barycentric lattice points, `res` steps per edge: the
/// j-vertex and the opposite face, or the j-edge and the opposite edge; `None` when the patch
/// promises neither. Shared by the sheet check and the distance sampling.
pub(crate) fn j_line_ends(p: &Patch, res: usize) -> Option<(Lattice, Lattice)> {
    match (p.jvertex, p.jedge) {
        (Some(j), _) if j < 4 => {
            let face: Vec<u8> = (0..4u8).filter(|&k| k != j).collect();
            Some((simplex_lattice(&[j], res), simplex_lattice(&face, res)))
        }
        (_, Some([a, b])) if a < 4 && b < 4 && a != b => {
            let other: Vec<u8> = (0..4u8).filter(|&k| k != a && k != b).collect();
            Some((simplex_lattice(&[a, b], res), simplex_lattice(&other, res)))
        }
        _ => None,
    }
}

/// The 1994 single-sheet promise: lines from the j-vertex through the opposite face, or
/// between the j-edge and the opposite edge, meet F = 0 at most once away from their ends, and
/// not at all between their ends when F vanishes at the far end (a zero face: the flat
/// triangle of a zero coplanar group is itself the sheet).
fn j_lines(e: &PatchEval<'_>, opts: &CheckOptions, n: usize, stats: &mut SheetStats) {
    let Some((from, to)) = j_line_ends(e.patch, opts.sheet_resolution) else {
        return;
    };
    stats.j_patches += 1;
    let before = stats.j_multi_lines;
    let mut first: Option<[f64; 3]> = None;
    if let Some(j) = e.patch.jvertex.filter(|_| e.patch.rational.is_empty()) {
        let (n, w) = (usize::from(e.patch.degree), &e.patch.weights);
        if zero_face_turns(n, w, usize::from(j)) {
            // Every j-line through the face's points of the wrong sign meets F = 0 twice;
            // counted as one line, placed at the face's centroid.
            stats.j_multi_lines += 1;
            let mut c = [1.0 / 3.0; 4];
            c[usize::from(j)] = 0.0;
            first = Some(point(e, c));
        }
    }
    for a in &from {
        for b in &to {
            stats.j_lines += 1;
            if let Some(t) = interior_roots_beyond_one(e, a, b, n) {
                stats.j_multi_lines += 1;
                first.get_or_insert_with(|| point(e, lerp(a, b, t)));
            }
        }
    }
    if let Some(p) = first {
        stats.j_multi_patches += 1;
        stats
            .j_multi_at
            .get_or_insert_with(|| Location::new(&[e], p, None));
        stats.j_sheets.push(JSheet {
            patch: e.id,
            element: e.element(),
            lines: stats.j_multi_lines - before,
            point: p,
        });
    }
}

/// Whether F of a polynomial patch (degree `n` ≥ 2, BB `weights`) vanishes on the whole face
/// opposite local vertex `j` (every weight there within 1e-12 of the largest) while F/λ_j
/// takes both strict signs on that face ([`crate::check::holes::polynomial_face_crossed`]'s
/// evidence: coefficients, lattice, subdivision).
///
/// Such a face is itself a sheet (the flat triangle of a zero coplanar group), and F/λ_j,
/// whose BB weights are n·b_{μ+e_j}/(μ_j + 1), is the derivative of F off the face: where it
/// takes the apex's other sign the j-lines meet F = 0 a second time between face and apex,
/// and rays see the face from behind. The j-line lattice alone missed such turns on four nut
/// quintic patches (session 28); this test is exact on the face.
#[must_use]
pub(crate) fn zero_face_turns(n: usize, weights: &[f64], j: usize) -> bool {
    if n < 2 || j > 3 {
        return false;
    }
    let scale = weights.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    // The checker's zero: far above the solves' rounding (1e-16 relative), far below any
    // weight a scheme sets on purpose.
    let tiny = 1e-12 * scale;
    let zero_face = multi_indices(n)
        .iter()
        .filter(|l| l[j] == 0)
        .all(|&l| weights[index_of(l)].abs() <= tiny);
    if !zero_face {
        return false;
    }
    let g: Vec<f64> = multi_indices(n - 1)
        .iter()
        .map(|&mu| {
            let mut l = mu;
            l[j] += 1;
            n as f64 * weights[index_of(l)] / f64::from(l[j])
        })
        .collect();
    crate::check::holes::polynomial_face_crossed(n - 1, &g, j)
}

/// `Some(t)` (t the first sample past the first root) when F on the segment from `a` to `b`
/// has more than one root in (0, 1) once roots at the ends are divided out: Descartes' rule
/// on the Bernstein coefficients decides ≤ 1 root; otherwise the deflated polynomial is
/// sampled at `n` + 1 points.
fn interior_roots_beyond_one(
    e: &PatchEval<'_>,
    a: &[f64; 4],
    b: &[f64; 4],
    n: usize,
) -> Option<f64> {
    let (c, len, _) = segment(e, a, b);
    roots_beyond_one(c, len, n)
}

/// `Some(t)` (t the first sample past the first root) when the univariate Bernstein
/// polynomial `c[..len]` on [0, 1] has more than one root in [0, 1] apart from a root at 0
/// (see [`interior_roots_beyond_one`]); shared with the quintic scheme's repair, which must
/// judge a patch's j-lines as this check does.
///
/// A root at 0 (the j-vertex on the surface, a zero-convex j-edge) is shared by every line of
/// the patch and divided out. A root at 1 is divided out too but still counts: the far end
/// lies on the surface (the base of a face tetrahedron on a zero coplanar group, where F ≡ 0),
/// so any root between the ends is a second sheet. Rays then meet that second sheet or the
/// base from behind: the nut quintic's crack (session 28) was such a patch, whose level-1
/// weights changed sign over its zero base.
pub(crate) fn roots_beyond_one(mut c: [f64; 16], mut len: usize, n: usize) -> Option<f64> {
    let scale = c[..len].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // An end coefficient this small relative to the rest is a root at the end (the j-vertex on
    // the surface, a zero-convex edge): 1e-12 is far above the round-off of the weights (1e-16
    // relative) and far below any weight the schemes set on purpose.
    let tiny = 1e-12 * scale;
    while len > 1 && c[0].abs() <= tiny {
        len = uni::deflate_at_zero(&mut c, len);
    }
    let mut far_root = false;
    while len > 1 && c[len - 1].abs() <= tiny {
        far_root = true;
        // (1 − t)·B^(m−1)_k = ((m − k)/m)·B^m_k.
        let m = (len - 1) as f64;
        for (k, x) in c[..len - 1].iter_mut().enumerate() {
            *x *= m / (m - k as f64);
        }
        len -= 1;
    }
    let mut changes = 0;
    let mut prev: Option<bool> = None;
    for &x in &c[..len] {
        if x.abs() > tiny {
            changes += usize::from(prev.is_some_and(|q| q != (x > 0.0)));
            prev = Some(x > 0.0);
        }
    }
    // Roots allowed between the ends: one, or none beside a root at the far end.
    let allowed = usize::from(!far_root);
    if changes <= allowed {
        return None;
    }
    let mut prev: Option<bool> = None;
    let mut count = 0;
    let mut first = 0.0;
    for k in 0..=n {
        let t = k as f64 / n as f64;
        let f = uni::eval(&c[..len], t);
        if f == 0.0 || f.is_nan() {
            continue;
        }
        if prev.is_some_and(|p| p != (f > 0.0)) {
            if count == 0 {
                first = t;
            }
            count += 1;
        }
        prev = Some(f > 0.0);
    }
    (count > allowed).then_some(first)
}

/// Bernstein coefficients of F·(rational denominators) along the segment from `a` to `b`
/// (`bb::rational::segment_poly`; the denominators are positive inside, so roots and signs
/// are F's), and the number of sign changes among them (zeros skipped). By Descartes' rule for
/// the Bernstein basis, the number of roots in (0, 1) counted with multiplicity is at most that
/// and of the same parity.
fn segment(e: &PatchEval<'_>, a: &[f64; 4], b: &[f64; 4]) -> ([f64; 16], usize, usize) {
    let p = e.patch;
    let mut c = [0.0; 16];
    let len = segment_poly(
        usize::from(p.degree),
        &p.weights,
        &p.rational,
        *a,
        *b,
        &mut c,
    );
    let mut changes = 0;
    let mut prev: Option<bool> = None;
    for &x in &c[..len] {
        if x != 0.0 {
            let pos = x > 0.0;
            changes += usize::from(prev.is_some_and(|q| q != pos));
            prev = Some(pos);
        }
    }
    (c, len, changes)
}

/// Sign changes of F along the segment from `a` to `b`, and the parameter of the first.
///
/// With at most one sign change among the segment's Bernstein coefficients there are that many
/// roots in (0, 1); otherwise F is sampled at N + 1 points.
fn count_sign_changes(e: &PatchEval<'_>, a: &[f64; 4], b: &[f64; 4], n: usize) -> (usize, f64) {
    let (_, _, changes) = segment(e, a, b);
    if changes <= 1 {
        // At most one root: its position is never reported.
        return (changes, 0.0);
    }
    let mut prev: Option<bool> = None;
    let mut count = 0;
    let mut first = 0.0;
    for k in 0..=n {
        let t = k as f64 / n as f64;
        let f = e.value(lerp(a, b, t));
        if f == 0.0 || f.is_nan() {
            continue;
        }
        let pos = f > 0.0;
        if prev.is_some_and(|p| p != pos) {
            if count == 0 {
                first = t;
            }
            count += 1;
        }
        prev = Some(pos);
    }
    (count, first)
}

/// The minimal root of φ(t) = F((1−t)q + t·u) in [0, 1) and |φ′| there; `touch` is the |φ| at
/// a critical point below which it counts as a (double) root.
fn minimal_root(
    e: &PatchEval<'_>,
    q: &[f64; 4],
    u: &[f64; 4],
    n: usize,
    touch: f64,
) -> Option<(f64, f64)> {
    let phi = |t: f64| e.value(lerp(q, u, t));
    let dphi = |t: f64| {
        let j = e.bary_jet(lerp(q, u, t));
        (0..4).map(|i| j.grad[i] * (u[i] - q[i])).sum::<f64>()
    };
    let root_at = |t: f64| Some((t, dphi(t).abs()));
    // Fast path: no sign change in the Bernstein coefficients → no root in (0, 1); exactly one
    // (with non-zero end coefficients) → exactly one root, simple by Descartes' rule.
    let (mut c, mut len, changes) = segment(e, q, u);
    // Divide out (1 − t) and t factors (the cleared denominators vanish at top or base vertices
    // and edges): (1 − t)·B^(m−1)_k = ((m − k)/m)·B^m_k and t·B^(m−1)_k = ((k + 1)/m)·B^m_(k+1),
    // so the quotient keeps the signs of the remaining coefficients.
    while len > 1 && c[len - 1] == 0.0 {
        let m = (len - 1) as f64;
        for (k, x) in c[..len - 1].iter_mut().enumerate() {
            *x *= m / (m - k as f64);
        }
        len -= 1;
    }
    if phi(0.0) != 0.0 {
        while len > 1 && c[0] == 0.0 {
            let m = (len - 1) as f64;
            for k in 0..len - 1 {
                c[k] = c[k + 1] * m / (k as f64 + 1.0);
            }
            len -= 1;
        }
    }
    if len > 1 && c[0] != 0.0 && changes <= 1 {
        if changes == 0 {
            return None;
        }
        let t = illinois(&c[..len]);
        return root_at(t);
    }
    let ts: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
    let f: Vec<f64> = ts.iter().map(|&t| phi(t)).collect();
    for k in 0..n {
        if f[k] == 0.0 {
            return root_at(ts[k]);
        }
        if f[k + 1] != 0.0 && (f[k] > 0.0) != (f[k + 1] > 0.0) {
            return root_at(bisect(&phi, ts[k], ts[k + 1]));
        }
        // A sampled local minimum of |φ| at k + 1: look for a touching root (or two roots
        // between samples) at the critical point.
        if k + 2 <= n && f[k + 1].abs() <= f[k].abs() && f[k + 1].abs() <= f[k + 2].abs() {
            let (d0, d1) = (dphi(ts[k]), dphi(ts[k + 2]));
            if (d0 > 0.0) != (d1 > 0.0) {
                let tc = bisect(&dphi, ts[k], ts[k + 2]);
                let v = phi(tc);
                if v == 0.0 {
                    return root_at(tc);
                }
                if (v > 0.0) != (f[k] > 0.0) {
                    return root_at(bisect(&phi, ts[k], tc));
                }
                if v.abs() <= touch {
                    return root_at(tc);
                }
            }
        }
    }
    None
}

/// The root of a Bernstein polynomial with one sign change on [0, 1] (c[0], c[last] of opposite
/// signs): Illinois regula falsi, stopped when the bracket stops shrinking or is below 1e-15.
fn illinois(c: &[f64]) -> f64 {
    let (mut a, mut b) = (0.0f64, 1.0f64);
    let (mut fa, mut fb) = (c[0], c[c.len() - 1]);
    let mut side = 0i8;
    for _ in 0..100 {
        if b - a <= 1e-15 {
            break;
        }
        let mut t = (a * fb - b * fa) / (fb - fa);
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
        let ft = uni::eval(c, t);
        if ft == 0.0 {
            return t;
        }
        if (ft > 0.0) == (fa > 0.0) {
            a = t;
            fa = ft;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = t;
            fb = ft;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}

/// A sign change of `g` in [lo, hi] (g(lo), g(hi) of opposite signs), by bisection.
fn bisect(g: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let lo_pos = g(lo) > 0.0;
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        let v = g(mid);
        if v == 0.0 {
            return mid;
        }
        if (v > 0.0) == lo_pos {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
