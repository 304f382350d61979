//! Bernstein certificates for the lower bounds of Step 6: whole-tetrahedron proofs, from the
//! layer weights alone, that no shooting line needs a free parameter above a value β.
//!
//! Along a shooting line the cubic is P + b·D (see [`super::bound`]). Its coefficient p_s is a
//! polynomial in the base point whose Bernstein coefficients are the tetrahedron's weights of
//! layer s (λ_4 = s for a face piece, λ_3 + λ_4 = s for an edge tetrahedron, plus the rational
//! terms). [`super::bound::threshold_at`] at t* = 1 does not exceed β exactly when
//! D_3 > 0, D_2 > 0, p_3 + β d_3 ≥ 0 and p_2 + β d_2 ≥ 0 (first case of Lemma 2.3 with the
//! whole segment). A polynomial is ≥ 0 (> 0) on its domain when all its Bernstein
//! coefficients are, so when the top two layers of the weights at f = σ(B + β) are ≥ 0
//! (times σ) and those of ∂/∂b are > 0, *every* shooting line of the tetrahedron — not only
//! the sampled ones — is satisfied at β, and the lemma's lower bound of the whole tetrahedron
//! is at most β. The sampled bound then cannot exceed β either, so the samples are skipped:
//! the result is the same, only cheaper.
//!
//! The base layer gives the same kind of proof for the sign test of the face promotion: when
//! σ times every layer-0 coefficient is ≤ a tolerance, F has the right sign on the whole face.

use super::weights::{cubic_indices, N3};

/// Layer of each cubic weight in a face piece (λ_4) and in an edge tetrahedron (λ_3 + λ_4).
fn layers() -> &'static ([u8; N3], [u8; N3]) {
    static L: std::sync::OnceLock<([u8; N3], [u8; N3])> = std::sync::OnceLock::new();
    L.get_or_init(|| {
        let idx = cubic_indices();
        (
            std::array::from_fn(|k| idx[k][3]),
            std::array::from_fn(|k| idx[k][2] + idx[k][3]),
        )
    })
}

/// Whether every shooting line of a face piece is satisfied at b = β: `w` are the piece's
/// weights at f_0003 = σ(B + β) (B the base value the bound is measured from), `dw` their
/// derivative by f_0003. The rational term of a face sits in layer 0 and plays no part.
#[must_use]
pub fn face_top(w: &[f64; N3], dw: &[f64; N3], sigma: f64) -> bool {
    let (face, _) = layers();
    (0..N3).all(|k| face[k] < 2 || (sigma * w[k] >= 0.0 && dw[k] > 0.0))
}

/// Whether σ·F ≤ `tol` on the whole base triangle of a face piece: σ times every layer-0
/// coefficient is ≤ `tol`; the rational term (4.1) adds a convex blend of `rat` to the
/// coefficient of B_1110, so each of w_1110 + rat_s is tested.
#[must_use]
pub fn face_base_below(w: &[f64; N3], rat: Option<&[f64; 3]>, sigma: f64, tol: f64) -> bool {
    let (face, _) = layers();
    static K1110: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    let k1110 = *K1110.get_or_init(|| super::weights::ix([1, 1, 1, 0]));
    (0..N3).all(|k| {
        if face[k] != 0 {
            return true;
        }
        if k == k1110 {
            if let Some(r) = rat {
                return r.iter().all(|&x| sigma * (w[k] + x) <= tol);
            }
        }
        sigma * w[k] <= tol
    })
}

/// Bernstein coefficients (degree 1 in x, 3 in y; `[i][j]` for x^i, y^j) of layer 2 of an
/// edge tetrahedron's shooting cubics, rational terms included, and those (degree 3 in y) of
/// layer 3. x is the weight of p_i in the base point, y that of apex A in the top point.
fn edge_top_coeffs(w: &[f64; N3], r: &[f64; 4]) -> ([[f64; 4]; 2], [f64; 4]) {
    let idx = cubic_indices();
    let (_, edge) = layers();
    let mut c2 = [[0.0; 3]; 2];
    let mut c3 = [0.0; 4];
    for k in 0..N3 {
        let l = idx[k];
        match edge[k] {
            2 => c2[usize::from(l[0])][usize::from(l[2])] = w[k],
            3 => c3[usize::from(l[2])] = w[k],
            _ => {}
        }
    }
    // Degree elevation 2 → 3 in y, then x·2y(1−y)(r_0 y + r_1 (1−y)) = x·(2/3)(r_0 B³_2 + r_1 B³_1)
    // and the same with (1 − x), r_2, r_3.
    let elev = |c: [f64; 3], ra: f64, rb: f64| {
        [
            c[0],
            (c[0] + 2.0 * c[1]) / 3.0 + 2.0 / 3.0 * rb,
            (2.0 * c[1] + c[2]) / 3.0 + 2.0 / 3.0 * ra,
            c[2],
        ]
    };
    ([elev(c2[0], r[2], r[3]), elev(c2[1], r[0], r[1])], c3)
}

/// Whether every shooting line of an edge tetrahedron is satisfied at b = β: `w`, `r` are its
/// weights and rational weights at f_A = σ(B_A + β), f_B = σ(B_B + β); `dw`, `dr` their
/// derivative along b.
#[must_use]
pub fn edge_top(w: &[f64; N3], r: &[f64; 4], dw: &[f64; N3], dr: &[f64; 4], sigma: f64) -> bool {
    let (q2, q3) = edge_top_coeffs(w, r);
    let (d2, d3) = edge_top_coeffs(dw, dr);
    q3.iter().all(|&x| sigma * x >= 0.0)
        && d3.iter().all(|&x| x > 0.0)
        && q2.iter().flatten().all(|&x| sigma * x >= 0.0)
        && d2.iter().flatten().all(|&x| x > 0.0)
}

#[cfg(test)]
mod tests {
    use super::super::bound::threshold_at;
    use super::*;

    use super::super::tests::Rng;

    /// The edge shooting cubic at (x, y) straight from the definition (4.9): Bernstein
    /// products of every weight, independent of the layer bookkeeping above.
    fn edge_line(w: &[f64; N3], r: &[f64; 4], x: f64, y: f64) -> [f64; 4] {
        let bin = |n: u8, k: u8, s: f64| -> f64 {
            let c = [
                [1.0, 0.0, 0.0, 0.0],
                [1.0, 1.0, 0.0, 0.0],
                [1.0, 2.0, 1.0, 0.0],
                [1.0, 3.0, 3.0, 1.0],
            ][usize::from(n)][usize::from(k)];
            c * s.powi(i32::from(k)) * (1.0 - s).powi(i32::from(n - k))
        };
        let mut b = [0.0; 4];
        for (k, l) in cubic_indices().iter().enumerate() {
            let s = l[2] + l[3];
            b[usize::from(s)] += w[k] * bin(3 - s, l[0], x) * bin(s, l[2], y);
        }
        let b21 = 2.0 * y * (1.0 - y);
        b[2] += x * b21 * (r[0] * y + r[1] * (1.0 - y))
            + (1.0 - x) * b21 * (r[2] * y + r[3] * (1.0 - y));
        b
    }

    /// A certified edge tetrahedron has no shooting line (dense 41 × 41 grid of lines, 64
    /// values of t*) whose best threshold exceeds β = 0; and the certificate is not vacuous:
    /// a good share of the random cases is certified.
    #[test]
    fn edge_certificate_holds_on_dense_lines() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        let mut certified = 0;
        for _ in 0..400 {
            // Top layers mostly positive (some cases certified), the rest anything.
            let w: [f64; N3] = std::array::from_fn(|k| {
                if layers().1[k] >= 2 {
                    0.5 * rng.next() + 0.45
                } else {
                    rng.next()
                }
            });
            let r: [f64; 4] = std::array::from_fn(|_| 0.2 * rng.next());
            let dw: [f64; N3] = std::array::from_fn(|k| {
                if layers().1[k] >= 2 {
                    rng.next().abs() + 0.05
                } else {
                    0.0
                }
            });
            let dr: [f64; 4] = std::array::from_fn(|_| 0.01 * rng.next());
            if !edge_top(&w, &r, &dw, &dr, 1.0) {
                continue;
            }
            certified += 1;
            for i in 0..=40 {
                for j in 0..=40 {
                    let (x, y) = (f64::from(i) / 40.0, f64::from(j) / 40.0);
                    let p = edge_line(&w, &r, x, y);
                    let d = edge_line(&dw, &dr, x, y);
                    assert!(d[0] == 0.0 && d[1] == 0.0);
                    let best = (1..=64)
                        .map(|k| threshold_at(p, d, f64::from(k) / 64.0))
                        .fold(f64::INFINITY, f64::min);
                    // Rounding of the sums only (coefficients are O(1)).
                    assert!(best <= 1e-12, "x={x} y={y} p={p:?} d={d:?} best={best}");
                }
            }
        }
        assert!(certified > 40, "only {certified} of 400 certified");
    }

    #[test]
    fn face_certificates_match_the_layers() {
        let idx = cubic_indices();
        let dw: [f64; N3] = std::array::from_fn(|k| match idx[k][3] {
            3 => 1.0,
            2 => 1.0 / 3.0,
            _ => 0.0,
        });
        let mut w = [0.0; N3];
        for (k, l) in idx.iter().enumerate() {
            w[k] = match l[3] {
                0 => -0.1,
                1 => 0.2,
                _ => 0.05,
            };
        }
        assert!(face_top(&w, &dw, 1.0));
        assert!(!face_top(&w, &dw, -1.0));
        assert!(face_base_below(&w, Some(&[0.05, 0.0, -0.3]), 1.0, 0.0));
        assert!(!face_base_below(&w, Some(&[0.15, 0.0, -0.3]), 1.0, 0.0));
        w[super::super::weights::ix([1, 0, 0, 2])] = -1e-3;
        assert!(!face_top(&w, &dw, 1.0));
    }
}
