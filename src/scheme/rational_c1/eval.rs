//! Reference evaluation of a [`Patch`] (value and gradient in world coordinates, including the
//! rational terms), used by this scheme's own measurements and tests. Direct sums over the
//! Bernstein basis: slow but simple; the tracer has its own compiled form.

use crate::bb::multi_indices;
use crate::complex::Patch;
use glam::{DMat3, DVec3};

/// Barycentric coordinates of x in the patch's tetrahedron and their world gradients.
#[must_use]
pub fn bary_and_grads(tet: &[DVec3; 4], x: DVec3) -> ([f64; 4], [DVec3; 4]) {
    let m = DMat3::from_cols(tet[1] - tet[0], tet[2] - tet[0], tet[3] - tet[0]);
    let inv = m.inverse();
    let y = inv * (x - tet[0]);
    let r = inv.transpose();
    let g1 = r.x_axis;
    let g2 = r.y_axis;
    let g3 = r.z_axis;
    (
        [1.0 - y.x - y.y - y.z, y.x, y.y, y.z],
        [-(g1 + g2 + g3), g1, g2, g3],
    )
}

fn fact(n: u8) -> f64 {
    (1..=u32::from(n)).map(f64::from).product()
}

fn bern(l: [u8; 4], a: [f64; 4]) -> (f64, [f64; 4]) {
    let n: u8 = l.iter().sum();
    let c = fact(n) / l.iter().map(|&k| fact(k)).product::<f64>();
    let pw = |k: usize, e: u8| if e == 0 { 1.0 } else { a[k].powi(i32::from(e)) };
    let v = c * (0..4).map(|k| pw(k, l[k])).product::<f64>();
    let d = std::array::from_fn(|i| {
        if l[i] == 0 {
            0.0
        } else {
            c * f64::from(l[i])
                * (0..4)
                    .map(|k| if k == i { pw(k, l[k] - 1) } else { pw(k, l[k]) })
                    .product::<f64>()
        }
    });
    (v, d)
}

/// F and ∂F/∂α_i of the patch at barycentric α (α need not sum to 1: the homogeneous form).
#[must_use]
pub fn value_dalpha(patch: &Patch, a: [f64; 4]) -> (f64, [f64; 4]) {
    let mut v = 0.0;
    let mut d = [0.0; 4];
    for (w, l) in patch
        .weights
        .iter()
        .zip(multi_indices(usize::from(patch.degree)))
    {
        let (b, db) = bern(l, a);
        v += w * b;
        for i in 0..4 {
            d[i] += w * db[i];
        }
    }
    for term in &patch.rational {
        let (b, db) = bern(term.index, a);
        let (mut num, mut den) = (0.0, 0.0);
        let (mut dnum, mut dden) = ([0.0; 4], [0.0; 4]);
        for &(w, mu) in &term.terms {
            let (m, dm) = bern(mu, a);
            // bern includes a multinomial factor; divide it out to get the plain monomial.
            let n: u8 = mu.iter().sum();
            let c = fact(n) / mu.iter().map(|&k| fact(k)).product::<f64>();
            num += w * m / c;
            den += m / c;
            for i in 0..4 {
                dnum[i] += w * dm[i] / c;
                dden[i] += dm[i] / c;
            }
        }
        if den > 0.0 {
            let r = num / den;
            v += r * b;
            for i in 0..4 {
                d[i] += r * db[i] + b * (dnum[i] * den - num * dden[i]) / (den * den);
            }
        }
    }
    (v, d)
}

/// F(x) and ∇F(x) in world coordinates.
#[must_use]
pub fn value_gradient(patch: &Patch, x: DVec3) -> (f64, DVec3) {
    let tet = patch.tet_points();
    let (a, g) = bary_and_grads(&tet, x);
    let (v, d) = value_dalpha(patch, a);
    let grad = (0..4).map(|i| d[i] * g[i]).sum();
    (v, grad)
}
