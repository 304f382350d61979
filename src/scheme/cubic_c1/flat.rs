//! Number 2 weights where T is flat at an edge (the paper's singular case, "coplanar adjacent
//! triangles", §4 end): the edge blossom A_e is then an affine function on the common plane and
//! its four known values (the number 1 weights at p_i, p_j and the two triangles' number 2
//! weights) must agree: A(p_m') = (1 − a − b)·A(p_i) + a·A(p_j) + b·A(p_m) with
//! p_m' = p_i + a(p_j − p_i) + b(p_m − p_i). Each flat edge gives this one linear equation in
//! the two number 2 weights. The weights closest (least squares) to the default choice that
//! satisfy all of them are found per connected group of triangles by Gaussian elimination with
//! partial pivoting (dependent equations of a consistent group are dropped).

use glam::DVec3;

/// A flat-edge equation: `center[to] − b·center[from] = rhs`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatEquation {
    /// The triangle whose third point is p_m.
    pub from: usize,
    /// The triangle whose third point is p_m'.
    pub to: usize,
    /// b.
    pub b: f64,
    /// (1 − a − b)·A(p_i) + a·A(p_j).
    pub rhs: f64,
}

/// Relative distance of p_m' from the plane (p_i, p_j, p_m) below which the edge is flat:
/// beyond it the 3×3 blossom system is solved exactly (with slopes up to ~1e9 times the data).
pub const FLAT_TOLERANCE: f64 = 1e-9;

/// The plane coordinates (a, b) of `pm2` in the frame (p_i; p_j − p_i, p_m − p_i) when it lies
/// on that plane (relative distance ≤ [`FLAT_TOLERANCE`]).
#[must_use]
pub fn flat_coords(pi: DVec3, pj: DVec3, pm: DVec3, pm2: DVec3) -> Option<(f64, f64)> {
    let (u, v, w) = (pj - pi, pm - pi, pm2 - pi);
    let n = u.cross(v);
    let scale = u.length().max(v.length()).max(w.length());
    if n.length() == 0.0 || (n.normalize().dot(w)).abs() > FLAT_TOLERANCE * scale {
        return None;
    }
    // Normal equations of [u v]·(a, b) = w.
    let (uu, uv, vv, uw, vw) = (u.dot(u), u.dot(v), v.dot(v), u.dot(w), v.dot(w));
    let det = uu * vv - uv * uv;
    Some(((vv * uw - uv * vw) / det, (uu * vw - uv * uw) / det))
}

/// Moves `center` (the number 2 weights) the least (in the sum of squares) so that every
/// equation holds; groups larger than `max_group` equations are left alone (returned count).
pub fn adjust(center: &mut [f64], equations: &[FlatEquation], max_group: usize) -> usize {
    // Union-find over triangles.
    let mut parent: Vec<usize> = (0..center.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for e in equations {
        let (a, b) = (find(&mut parent, e.from), find(&mut parent, e.to));
        parent[a] = b;
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (k, e) in equations.iter().enumerate() {
        let r = find(&mut parent, e.from);
        groups.entry(r).or_default().push(k);
    }
    let mut skipped = 0;
    for eqs in groups.values() {
        if eqs.len() > max_group {
            skipped += eqs.len();
            continue;
        }
        let mut tris: Vec<usize> = eqs
            .iter()
            .flat_map(|&k| [equations[k].from, equations[k].to])
            .collect();
        tris.sort_unstable();
        tris.dedup();
        let col = |t: usize| tris.binary_search(&t).expect("triangle of the group");
        let m = eqs.len();
        // Rows of E as (column, value) pairs.
        let rows: Vec<[(usize, f64); 2]> = eqs
            .iter()
            .map(|&k| {
                let e = equations[k];
                [(col(e.to), 1.0), (col(e.from), -e.b)]
            })
            .collect();
        let d: Vec<f64> = tris.iter().map(|&t| center[t]).collect();
        let residual: Vec<f64> = eqs
            .iter()
            .zip(&rows)
            .map(|(&k, r)| equations[k].rhs - r.iter().map(|&(c, v)| v * d[c]).sum::<f64>())
            .collect();
        // E Eᵀ.
        let mut a = vec![vec![0.0; m]; m];
        for i in 0..m {
            for j in 0..m {
                let mut s = 0.0;
                for &(ci, vi) in &rows[i] {
                    for &(cj, vj) in &rows[j] {
                        if ci == cj {
                            s += vi * vj;
                        }
                    }
                }
                a[i][j] = s;
            }
        }
        let y = solve(a, residual);
        let mut c = d;
        for (r, yk) in rows.iter().zip(&y) {
            for &(ci, vi) in r {
                c[ci] += vi * yk;
            }
        }
        for (k, &t) in tris.iter().enumerate() {
            center[t] = c[k];
        }
    }
    skipped
}

/// Solves the symmetric positive semi-definite system a·y = r by Gaussian elimination with
/// partial pivoting; a pivot below 1e-12 of the largest diagonal marks a dependent equation,
/// whose unknown is set to 0.
#[must_use]
pub fn solve(mut a: Vec<Vec<f64>>, mut r: Vec<f64>) -> Vec<f64> {
    let m = r.len();
    let big = (0..m).fold(0.0f64, |x, i| x.max(a[i][i].abs()));
    let tiny = 1e-12 * big.max(f64::MIN_POSITIVE);
    let mut pivot_of = vec![usize::MAX; m]; // column → row holding its pivot
    let mut used = vec![false; m];
    for col in 0..m {
        let Some(p) = (0..m)
            .filter(|&i| !used[i])
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
        else {
            break;
        };
        if a[p][col].abs() <= tiny {
            continue;
        }
        used[p] = true;
        pivot_of[col] = p;
        for i in 0..m {
            if i != p && a[i][col] != 0.0 {
                let f = a[i][col] / a[p][col];
                let pivot_row = a[p].clone();
                for (x, y) in a[i].iter_mut().zip(&pivot_row).skip(col) {
                    *x -= f * y;
                }
                r[i] -= f * r[p];
            }
        }
    }
    (0..m)
        .map(|col| match pivot_of[col] {
            usize::MAX => 0.0,
            p => r[p] / a[p][col],
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two flat equations chained through triangle 1: after the adjustment both hold, and the
    /// change is orthogonal to the constraints' null space (least squares: moving along the
    /// null space would only add to the change).
    #[test]
    fn adjust_meets_equations_minimally() {
        let mut c = vec![1.0, -2.0, 0.5];
        let eqs = [
            FlatEquation {
                from: 0,
                to: 1,
                b: 0.5,
                rhs: 0.25,
            },
            FlatEquation {
                from: 1,
                to: 2,
                b: -1.0,
                rhs: 1.0,
            },
        ];
        let d = c.clone();
        assert_eq!(adjust(&mut c, &eqs, 10), 0);
        for e in &eqs {
            // Round-off of a 2×2 elimination.
            assert!((c[e.to] - e.b * c[e.from] - e.rhs).abs() < 1e-14);
        }
        // Null space of E = [[-0.5, 1, 0], [0, 1, 1]]: (2, 1, -1). The change is orthogonal.
        let dc: f64 = (0..3).map(|k| (c[k] - d[k]) * [2.0, 1.0, -1.0][k]).sum();
        assert!(dc.abs() < 1e-14);
    }

    /// The plane coordinates reproduce the point; an off-plane point is not flat.
    #[test]
    fn flat_coords_in_plane() {
        let (pi, pj, pm) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let (a, b) = flat_coords(pi, pj, pm, DVec3::new(0.3, -0.7, 0.0)).unwrap();
        assert!((a - 0.3).abs() < 1e-15 && (b + 0.7).abs() < 1e-15);
        assert!(flat_coords(pi, pj, pm, DVec3::new(0.3, -0.7, 1e-3)).is_none());
    }
}
