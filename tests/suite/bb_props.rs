//! Property tests of the `bb` module against independent computations: power-basis sums,
//! finite differences, pointwise evaluation along segments, and dense sampling + bisection.
//! Seeded (fixed proptest seed, no persistence) so every run checks the same cases.

use apatch::bb::{multi_indices, num_coeffs, poly, uni, BbPoly, Tet};
use apatch::complex::{Patch, RationalTerm};
use apatch::fixtures::{plain_patch, UNIT_TET};
use glam::{DMat3, DVec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x0b0b_2001),
        failure_persistence: None,
        ..Config::default()
    }
}

// ---- independent truth ----------------------------------------------------------------------

fn fact(k: u32) -> f64 {
    (1..=k).map(f64::from).product()
}

/// Σ c_λ n!/λ! α^λ term by term (no de Casteljau).
fn power_eval(n: usize, c: &[f64], a: [f64; 4]) -> f64 {
    multi_indices(n)
        .iter()
        .zip(c)
        .map(|(l, w)| {
            let mut m = fact(n as u32);
            for i in 0..4 {
                m *= a[i].powi(i32::from(l[i])) / fact(u32::from(l[i]));
            }
            w * m
        })
        .sum()
}

/// Σ_k c_k C(n,k) t^k (1−t)^(n−k) term by term.
fn power_uni(c: &[f64], t: f64) -> f64 {
    let n = c.len() - 1;
    c.iter()
        .enumerate()
        .map(|(k, ck)| {
            let binom = fact(n as u32) / (fact(k as u32) * fact((n - k) as u32));
            ck * binom * t.powi(k as i32) * (1.0 - t).powi((n - k) as i32)
        })
        .sum()
}

fn lerp4(a0: [f64; 4], a1: [f64; 4], s: f64) -> [f64; 4] {
    std::array::from_fn(|i| (1.0 - s) * a0[i] + s * a1[i])
}

fn max_abs(c: &[f64]) -> f64 {
    c.iter().fold(0.0, |m, x| m.max(x.abs()))
}

// ---- strategies -----------------------------------------------------------------------------

/// A degree 1..=7 and coefficients in [−1, 1].
fn bb_poly() -> impl Strategy<Value = (usize, Vec<f64>)> {
    (1usize..=7).prop_flat_map(|n| {
        proptest::collection::vec(-1.0f64..1.0, num_coeffs(n)).prop_map(move |c| (n, c))
    })
}

/// Barycentric coordinates of a point inside the tetrahedron.
fn bary_inside() -> impl Strategy<Value = [f64; 4]> {
    [0.01f64..1.0, 0.01f64..1.0, 0.01f64..1.0, 0.01f64..1.0].prop_map(|w| {
        let s: f64 = w.iter().sum();
        w.map(|x| x / s)
    })
}

/// Barycentric coordinates of a point near the tetrahedron (up to 0.3 outside).
fn bary_near() -> impl Strategy<Value = [f64; 4]> {
    [-0.3f64..1.0, -0.3f64..1.0, -0.3f64..1.0].prop_map(|[a, b, c]| [a, b, c, 1.0 - a - b - c])
}

/// Ratio of |det| to the longest edge cubed (regular tetrahedron: 0.707).
fn shape_quality(v: &[DVec3; 4]) -> f64 {
    let det = DMat3::from_cols(v[0] - v[3], v[1] - v[3], v[2] - v[3]).determinant();
    let mut l: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l = l.max((v[i] - v[j]).length());
        }
    }
    det.abs() / l.powi(3)
}

/// A random, not too flat tetrahedron of size 0.1..10 somewhere in [−10, 10]³.
fn tet() -> impl Strategy<Value = Tet> {
    (
        proptest::array::uniform4(proptest::array::uniform3(-1.0f64..1.0)),
        0.1f64..10.0,
        proptest::array::uniform3(-10.0f64..10.0),
    )
        .prop_map(|(p, scale, off)| {
            p.map(|q| DVec3::from_array(q) * scale + DVec3::from_array(off))
        })
        .prop_filter("well-shaped tetrahedron", |v| shape_quality(v) > 0.05)
        .prop_map(|v| Tet::new(v).expect("well-shaped tetrahedra are accepted"))
}

fn max_grad(tet: &Tet) -> f64 {
    tet.grad.iter().fold(0.0, |m, g| m.max(g.length()))
}

// ---- trivariate -----------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn eval_matches_power_basis((n, c) in bb_poly(), a in bary_near()) {
        let p = BbPoly::new(n, c.clone());
        let (x, y) = (p.eval(a), power_eval(n, &c, a));
        // Coefficients ≤ 1 and |αi| ≤ 1.6: both sums are ≤ 6.4^n in size; rounding is a few
        // ulps of that.
        let tol = 1e-14 * 6.4f64.powi(n as i32);
        prop_assert!((x - y).abs() <= tol, "n={} {} vs {}", n, x, y);
    }

    #[test]
    fn blossom_is_symmetric_and_diagonal((n, c) in bb_poly(), a in bary_inside(), b in bary_inside()) {
        let p = BbPoly::new(n, c);
        // Diagonal: b(α,…,α) = F(α), rounding only.
        prop_assert!((p.blossom(&vec![a; n]) - p.eval(a)).abs() < 1e-13);
        // Symmetry: any order of the same arguments, rounding only.
        let mut args: Vec<[f64; 4]> = (0..n).map(|k| if k % 2 == 0 { a } else { b }).collect();
        let x = p.blossom(&args);
        args.reverse();
        prop_assert!((p.blossom(&args) - x).abs() < 1e-13);
    }

    #[test]
    fn elevation_keeps_the_function((n, c) in bb_poly(), a in bary_near()) {
        let p = BbPoly::new(n, c.clone());
        let q = p.elevate();
        prop_assert_eq!(q.degree, n + 1);
        prop_assert_eq!(q.coeffs.len(), num_coeffs(n + 1));
        // Values ≤ 6.4^n (see eval_matches_power_basis); rounding only.
        let tol = 1e-14 * 6.4f64.powi(n as i32 + 1);
        prop_assert!((q.eval(a) - power_eval(n, &c, a)).abs() <= tol);
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences(
        (n, c) in bb_poly(), t in tet(), a in bary_inside()
    ) {
        let p = BbPoly::new(n, c.clone());
        let x = t.point(a);
        let g_scale = max_grad(&t);
        let f = |y: DVec3| power_eval(n, &c, t.bary(y));
        let nf = n as f64;
        // h = 1e-4/(n·G): central differences then err by ≤ h²/6·n³(4G)³ ≈ 1e-7·n·G (|c| ≤ 1),
        // rounding adds ~1e-16·nG/1e-4; 1e-6·n·G covers both tenfold.
        let h = 1e-4 / (nf * g_scale);
        let g = p.gradient(&t, a);
        let tol_g = 1e-6 * nf * g_scale;
        for k in 0..3 {
            let e = DVec3::AXES[k] * h;
            let fd = (f(x + e) - f(x - e)) / (2.0 * h);
            prop_assert!((g[k] - fd).abs() <= tol_g, "n={} ∂{}: {} vs {}", n, k, g[k], fd);
        }
        // Hessian by central differences of the analytic gradient: error ≤ h²/6·n⁴(4G)⁴ ≈
        // 4e-7·n²G²; 1e-5·n²G² covers it.
        let hs = p.hessian(&t, a);
        let tol_h = 1e-5 * nf * nf * g_scale * g_scale;
        for k in 0..3 {
            let e = DVec3::AXES[k] * h;
            let col = (p.gradient(&t, t.bary(x + e)) - p.gradient(&t, t.bary(x - e))) / (2.0 * h);
            let got = hs.col(k);
            prop_assert!((got - col).abs().max_element() <= tol_h, "n={} col {}: {} vs {}", n, k, got, col);
            // Symmetry up to rounding.
            prop_assert!((hs.col(k) - hs.row(k)).abs().max_element() <= 1e-12 * tol_h / 1e-5);
        }
    }

    #[test]
    fn restriction_matches_pointwise_evaluation(
        (n, c) in bb_poly(), a0 in bary_near(), a1 in bary_near()
    ) {
        let mut out = [0.0; 16];
        let len = poly::restrict(n, &c, a0, a1, &mut out);
        prop_assert_eq!(len, n + 1);
        for k in 0..=8 {
            let s = k as f64 / 8.0;
            let want = power_eval(n, &c, lerp4(a0, a1, s));
            // Values ≤ 6.4^n (|αi| ≤ 1.6), rounding only.
            let tol = 1e-14 * 6.4f64.powi(n as i32);
            prop_assert!((uni::eval(&out[..len], s) - want).abs() <= tol, "n={} s={}", n, s);
        }
    }
}

// ---- univariate -----------------------------------------------------------------------------

/// Bernstein coefficients of Π (t − r).
fn from_roots(roots: &[f64]) -> Vec<f64> {
    roots
        .iter()
        .fold(vec![1.0], |acc, &r| uni::multiply(&acc, &[-r, 1.0 - r]))
}

/// The first root of f in [0, 1] by dense sampling and bisection (of `f` itself), if the
/// samples show a sign change or an exact zero.
fn sampled_first_root(f: impl Fn(f64) -> f64, samples: usize) -> Option<f64> {
    let mut t0 = 0.0;
    let mut f0 = f(0.0);
    if f0 == 0.0 {
        return Some(0.0);
    }
    for k in 1..=samples {
        let t1 = k as f64 / samples as f64;
        let f1 = f(t1);
        if f1 == 0.0 {
            return Some(t1);
        }
        if (f0 > 0.0) != (f1 > 0.0) {
            let (mut lo, mut hi) = (t0, t1);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if (f(mid) > 0.0) == (f0 > 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            return Some(0.5 * (lo + hi));
        }
        (t0, f0) = (t1, f1);
    }
    None
}

/// Checks a first-root answer against the sampled truth: same root to 1e-9, or an earlier
/// point where |f| is at rounding level (a touch or a pair of roots between two samples).
fn check_first_root(
    got: Option<f64>,
    truth: Option<f64>,
    f: impl Fn(f64) -> f64,
    scale: f64,
) -> Result<(), TestCaseError> {
    // Roots closer than 1e-9 to the sampled one are the same root (bisection reaches 1e-16;
    // the finder polishes simple roots to ~1e-15, ill-conditioned ones less well).
    const SAME_ROOT: f64 = 1e-9;
    // |f| at a legitimately reported touch: the policy's τ = 1e-13·max|c| plus the
    // difference between two evaluation schemes.
    let near_zero = 1e-11 * scale;
    match (got, truth) {
        (Some(r), Some(t)) if (r - t).abs() <= SAME_ROOT => Ok(()),
        (Some(r), Some(t)) if r < t && f(r).abs() <= near_zero => Ok(()),
        (Some(r), None) if f(r).abs() <= near_zero => Ok(()),
        (None, None) => Ok(()),
        (g, t) => Err(TestCaseError::fail(format!(
            "first root {g:?}, sampled {t:?}, f(got)={:?}",
            g.map(&f)
        ))),
    }
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn uni_ops_match_power_basis(
        a in proptest::collection::vec(-1.0f64..1.0, 1..9),
        b in proptest::collection::vec(-1.0f64..1.0, 1..9),
        t in 0.0f64..1.0, s in 0.0f64..1.0,
    ) {
        // Degree ≤ 8 sums of O(1) terms: rounding only.
        let tol = 1e-13;
        prop_assert!((uni::eval(&a, s) - power_uni(&a, s)).abs() < tol);
        let p = uni::multiply(&a, &b);
        prop_assert!((uni::eval(&p, s) - power_uni(&a, s) * power_uni(&b, s)).abs() < tol);
        let (l, r) = uni::subdivide(&a, t);
        prop_assert!((uni::eval(&l, s) - power_uni(&a, t * s)).abs() < tol);
        prop_assert!((uni::eval(&r, s) - power_uni(&a, t + (1.0 - t) * s)).abs() < tol);
        // Central difference with h = 1e-5: error ≤ h²/6·n³·8 + 1e-16/h ≈ 1e-9.
        let h = 1e-5;
        let fd = (power_uni(&a, s + h) - power_uni(&a, s - h)) / (2.0 * h);
        prop_assert!((uni::derivative_eval(&a, s) - fd).abs() < 1e-7);
    }

    #[test]
    fn first_root_of_known_roots(
        roots in proptest::collection::vec(-0.5f64..1.5, 1..8),
        double in proptest::bool::ANY, k in 1e-12f64..1e12, flip in proptest::bool::ANY,
    ) {
        let mut roots = roots;
        if double {
            roots.push(roots[0]);
        }
        let sign = if flip { -k } else { k };
        let c: Vec<f64> = from_roots(&roots).iter().map(|x| sign * x).collect();
        let want = roots.iter().copied().filter(|r| (0.0..=1.0).contains(r)).fold(f64::INFINITY, f64::min);
        let got = uni::first_root(&c);
        if want.is_finite() {
            let r = got.expect("a root in [0,1] was missed");
            // Touches to 1e-7 (refined to the extremum or to the first of the two roots that
            // rounding splits a double root into: √(1e-15)); simple roots to their condition
            // number: rounding of ~10 ulps of max|c| divided by |f′|. Any earlier answer must
            // be a near-zero of f (a touch of two nearby roots).
            let touch = roots.iter().filter(|&&x| x == want).count() > 1;
            let df = uni::derivative_eval(&c, want).abs();
            let tol = if touch { 1e-7 } else { 1e-14 + 1e-15 * max_abs(&c) / df };
            let f = uni::eval(&c, r).abs() / max_abs(&c);
            prop_assert!((r - want).abs() <= tol || (r < want && f <= 1e-11),
                "roots {:?}: got {} want {} |f|/s={}", roots, r, want, f);
        } else if let Some(r) = got {
            // Only a near-touch of a root just outside [0, 1] may be reported.
            prop_assert!(uni::eval(&c, r).abs() / max_abs(&c) <= 1e-11, "spurious root {} of {:?}", r, roots);
        }
    }

    #[test]
    fn first_root_of_restricted_patches(
        (n, c) in bb_poly(), a0 in bary_inside(), a1 in bary_inside(),
    ) {
        let mut out = [0.0; 16];
        let len = poly::restrict(n, &c, a0, a1, &mut out);
        let f = |s: f64| power_eval(n, &c, lerp4(a0, a1, s));
        let truth = sampled_first_root(f, 2000);
        check_first_root(uni::first_root(&out[..len]), truth, f, max_abs(&out[..len]))?;
        // Continuing after the first root finds the sampled next one.
        if let Some(r) = uni::first_root(&out[..len]) {
            let lo = r + 1e-6;
            if lo < 1.0 {
                let next = sampled_first_root(|s| f(lo + (1.0 - lo) * s), 2000).map(|s| lo + (1.0 - lo) * s);
                check_first_root(uni::first_root_in(&out[..len], lo, 1.0), next, f, max_abs(&out[..len]))?;
            }
        }
    }
}

// ---- patches with rational terms ------------------------------------------------------------

fn face_term(w: [f64; 3]) -> RationalTerm {
    RationalTerm {
        index: [1, 1, 1, 0],
        terms: [
            (w[0], [0, 1, 1, 0]),
            (w[1], [1, 0, 1, 0]),
            (w[2], [1, 1, 0, 0]),
        ]
        .into(),
    }
}

fn edge_terms(w: [f64; 4]) -> [RationalTerm; 2] {
    [
        RationalTerm {
            index: [1, 1, 0, 1],
            terms: [(w[0], [1, 0, 0, 0]), (w[1], [0, 0, 0, 1])].into(),
        },
        RationalTerm {
            index: [1, 0, 1, 1],
            terms: [(w[2], [1, 0, 0, 0]), (w[3], [0, 0, 0, 1])].into(),
        },
    ]
}

/// A cubic patch with a face term, edge terms, or both (two distinct denominators).
fn rational_patch() -> impl Strategy<Value = Patch> {
    (
        tet(),
        proptest::collection::vec(-1.0f64..1.0, num_coeffs(3)),
        proptest::array::uniform3(-1.0f64..1.0),
        proptest::array::uniform4(-1.0f64..1.0),
        0usize..3,
    )
        .prop_map(|(t, weights, wf, we, kind)| {
            let mut rational = Vec::new();
            if kind != 1 {
                rational.push(face_term(wf));
            }
            if kind != 0 {
                rational.extend(edge_terms(we));
            }
            Patch {
                rational,
                ..plain_patch(t.v, 3, weights)
            }
        })
}

/// Numerator, denominator and B_κ of a term, written out independently.
fn term_parts(term: &RationalTerm, a: [f64; 4]) -> (f64, f64, f64) {
    let mono = |mu: [u8; 4]| (0..4).map(|i| a[i].powi(i32::from(mu[i]))).product::<f64>();
    let num: f64 = term.terms.iter().map(|(w, mu)| w * mono(*mu)).sum();
    let den: f64 = term.terms.iter().map(|(_, mu)| mono(*mu)).sum();
    let k = term.index;
    let multinomial = fact(3) / (0..4).map(|i| fact(u32::from(k[i]))).product::<f64>();
    (num, den, multinomial * mono(k))
}

/// F (polynomial + rational terms) at barycentric `a`, independently of the crate.
fn patch_value(p: &Patch, a: [f64; 4]) -> f64 {
    let mut f = power_eval(3, &p.weights, a);
    for term in &p.rational {
        let (num, den, b) = term_parts(term, a);
        f += num / den * b;
    }
    f
}

/// Π of the distinct denominators at `a` (face and edge terms have different ones).
fn denominators(p: &Patch, a: [f64; 4]) -> f64 {
    let mut prod = 1.0;
    let mut seen: Vec<Vec<[u8; 4]>> = Vec::new();
    for term in &p.rational {
        let mut key: Vec<[u8; 4]> = term.terms.iter().map(|(_, m)| *m).collect();
        key.sort_unstable();
        if !seen.contains(&key) {
            prod *= term_parts(term, a).1;
            seen.push(key);
        }
    }
    prod
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn rational_value_matches_formula(p in rational_patch(), a in bary_inside()) {
        let t = p.tet().unwrap();
        let x = t.point(a);
        // O(1) terms; rounding plus the barycentric round trip of x.
        prop_assert!((p.value(x) - patch_value(&p, a)).abs() < 1e-11);
    }

    #[test]
    fn rational_derivatives_match_finite_differences(p in rational_patch(), a in bary_inside()) {
        let t = p.tet().unwrap();
        let x = t.point(a);
        let g_scale = max_grad(&t);
        // Barycentric coordinates ≥ 0.01/4 keep the quotient's derivatives bounded by
        // ~(1/min α)^k; h = 1e-6/G keeps the central-difference error h²·F‴ below ~1e-5·G.
        let h = 1e-6 / g_scale;
        let f = |y: DVec3| patch_value(&p, t.bary(y));
        let g = p.gradient(x);
        let hs = p.hessian(x);
        for k in 0..3 {
            let e = DVec3::AXES[k] * h;
            let fd = (f(x + e) - f(x - e)) / (2.0 * h);
            let tol = 1e-4 * g_scale * (1.0 + g.length() / g_scale);
            prop_assert!((g[k] - fd).abs() <= tol, "∂{}: {} vs {}", k, g[k], fd);
            let col = (p.gradient(x + e) - p.gradient(x - e)) / (2.0 * h);
            let tol_h = 1e-4 * g_scale * g_scale * (1.0 + hs.col(k).length() / (g_scale * g_scale));
            prop_assert!((hs.col(k) - col).abs().max_element() <= tol_h, "col {}: {} vs {}", k, hs.col(k), col);
        }
    }

    #[test]
    fn segment_poly_clears_denominators(p in rational_patch(), a0 in bary_inside(), a1 in bary_inside()) {
        let t = p.tet().unwrap();
        let (x0, x1) = (t.point(a0), t.point(a1));
        let mut out = [0.0; 16];
        let len = p.segment_poly(x0, x1, &mut out);
        prop_assert_eq!(len, p.segment_degree() + 1);
        let expect_degree = 3 + p.rational.iter().map(|r| if r.index == [1, 1, 1, 0] { 2 } else { 0 }).sum::<usize>()
            + usize::from(p.rational.iter().any(|r| r.index != [1, 1, 1, 0]));
        prop_assert_eq!(len, expect_degree + 1);
        for k in 0..=8 {
            let s = k as f64 / 8.0;
            let a = lerp4(a0, a1, s);
            let want = patch_value(&p, a) * denominators(&p, a);
            // O(1) values and denominators ≤ 3: rounding plus the barycentric round trip.
            prop_assert!((uni::eval(&out[..len], s) - want).abs() < 1e-11, "s={}", s);
        }
    }
}

fn unit_tet_patch(rational: Vec<RationalTerm>) -> Patch {
    Patch {
        rational,
        ..plain_patch(UNIT_TET, 3, vec![0.0; num_coeffs(3)])
    }
}

#[test]
fn rational_terms_are_finite_where_denominators_vanish() {
    let mut rational = vec![face_term([0.3, -0.7, 1.1])];
    rational.extend(edge_terms([0.5, -0.2, 0.9, 0.4]));
    let p = unit_tet_patch(rational);
    let v = p.tet_points();
    // The face denominator vanishes on the edges v1–v4, v2–v4, v3–v4 (two of α1..α3 zero),
    // the edge denominator α1 + α4 on the edge v2–v3.
    for (i, j) in [(0, 3), (1, 3), (2, 3), (1, 2)] {
        for s in [0.0, 0.25, 0.5, 1.0] {
            let x = v[i] * (1.0 - s) + v[j] * s;
            assert!(p.value(x).is_finite(), "value on edge {i}-{j}");
            assert!(p.gradient(x).is_finite(), "gradient on edge {i}-{j}");
            assert!(p.hessian(x).is_finite(), "Hessian on edge {i}-{j}");
        }
    }
}

#[test]
fn face_term_tends_to_zero_at_its_edges() {
    let p = unit_tet_patch(vec![face_term([0.3, -0.7, 1.1])]);
    // Near the edge v1–v4 (α2 = α3 = d → 0): B = 6α1α2α3 = O(d²) while N/D stays within
    // [min w, max w], so |F| ≤ 6·1.1·d²; the gradient is O(d).
    for d in [1e-3, 1e-6, 1e-9, 1e-150] {
        let x = DVec3::new(d, d, 0.4);
        let f = p.value(x);
        assert!(f.abs() <= 6.6 * d * d, "d={d}: F={f}");
        let g = p.gradient(x);
        // |∇(qB)| ≤ |B∇q| + |q∇B| ≤ 6d²·(2·1.8/(1.2d))·√2 + 1.1·6·0.6·d·√2 < 40d.
        assert!(g.length() <= 40.0 * d, "d={d}: ∇F={g}");
        assert!(p.hessian(x).is_finite());
    }
}

#[test]
fn quadric_fixture_is_reproduced() {
    // The fixtures' exact blossom weights: F must equal the quadric, ∇F its gradient.
    use apatch::fixtures::{quadric_patch, Quadric};
    let q = Quadric::sphere(DVec3::new(0.1, 0.2, -0.3), 0.8);
    let v = [
        DVec3::new(-1.0, -0.5, -0.2),
        DVec3::new(1.2, -0.4, 0.1),
        DVec3::new(0.1, 1.3, -0.1),
        DVec3::new(0.0, 0.2, 1.4),
    ];
    for n in 2..=7 {
        let p = quadric_patch(&q, v, n);
        for x in [
            DVec3::ZERO,
            DVec3::new(0.2, 0.1, 0.3),
            DVec3::new(-0.3, 0.4, 0.2),
        ] {
            // O(1) values: rounding only.
            assert!((p.value(x) - q.value(x)).abs() < 1e-12, "n={n}");
            assert!((p.gradient(x) - q.gradient(x)).length() < 1e-11, "n={n}");
            assert!((p.hessian(x) - q.a * 2.0)
                .abs()
                .to_cols_array()
                .iter()
                .all(|e| *e < 1e-10));
        }
    }
}

proptest! {
    #![proptest_config(config(64))]

    /// A line tangent to a sphere touches F = 0 in a double root: the policy reports the
    /// touching point, whichever way rounding tips the coefficients.
    #[test]
    fn tangent_rays_report_the_touching_point(
        dir in proptest::array::uniform3(-1.0f64..1.0), normal in proptest::array::uniform3(-1.0f64..1.0),
        n in 2usize..=7, s0 in 0.2f64..0.8,
    ) {
        use apatch::fixtures::{quadric_patch, Quadric};
        let (dir, normal) = (DVec3::from_array(dir), DVec3::from_array(normal));
        prop_assume!(dir.length() > 0.1 && normal.cross(dir).length() > 0.1);
        let (center, r) = (DVec3::new(0.1, 0.2, 0.3), 0.4);
        let dir = dir.normalize();
        let normal = (normal - dir * normal.dot(dir)).normalize();
        let touch = center + normal * r;
        // The segment passes through `touch` at parameter s0, tangent to the sphere.
        let (x0, x1) = (touch - dir * s0, touch + dir * (1.0 - s0));
        let v = [
            DVec3::new(-2.0, -2.0, -2.0),
            DVec3::new(3.0, -2.0, -2.0),
            DVec3::new(-2.0, 3.0, -2.0),
            DVec3::new(-2.0, -2.0, 3.0),
        ];
        let q = Quadric::sphere(center, r);
        let p = quadric_patch(&q, v, n);
        let mut out = [0.0; 16];
        let len = p.segment_poly(x0, x1, &mut out);
        let got = uni::first_root(&out[..len]);
        // Touches are refined to the extremum, or to the first of the two roots rounding
        // splits the double root into: √(rounding/f″) with rounding ≲ 1e-14 and f″ = 2.
        prop_assert!(got.is_some_and(|t| (t - s0).abs() < 1e-7), "got {:?}, want {}", got, s0);
        // Moving the line off the sphere by 1e-3 removes the root.
        let off = normal * 1e-3;
        let len = p.segment_poly(x0 + off, x1 + off, &mut out);
        prop_assert_eq!(uni::first_root(&out[..len]), None);
    }
}

#[test]
fn first_root_in_degenerate_intervals() {
    let c = from_roots(&[0.25, 0.75]);
    assert_eq!(uni::first_root_in(&c, 0.6, 0.4), None);
    assert_eq!(uni::first_root_in(&c, f64::NAN, 1.0), None);
    assert_eq!(uni::first_root_in(&c, 0.25, 0.25), Some(0.25));
    assert_eq!(uni::first_root_in(&c, 0.3, 0.3), None);
    // Clamped to [0, 1].
    assert!((uni::first_root_in(&c, -3.0, 0.5).unwrap() - 0.25).abs() < 1e-15);
}

proptest! {
    #![proptest_config(config(128))]

    /// World-space segments through random tetrahedra: the first root of `segment_poly`
    /// against F sampled along the segment (polynomial and rational patches alike).
    #[test]
    fn segment_poly_first_root_matches_sampled_value(
        p in rational_patch(), keep_rational in proptest::bool::ANY,
        a0 in bary_inside(), a1 in bary_inside(),
    ) {
        let mut p = p;
        if !keep_rational {
            p.rational.clear();
        }
        let t = p.tet().unwrap();
        let (x0, x1) = (t.point(a0), t.point(a1));
        let mut out = [0.0; 16];
        let len = p.segment_poly(x0, x1, &mut out);
        // Inside the tetrahedron the denominators are positive: the roots are F's.
        let f = |s: f64| patch_value(&p, lerp4(a0, a1, s));
        let truth = sampled_first_root(f, 2000);
        let g = |s: f64| uni::eval(&out[..len], s);
        check_first_root(uni::first_root(&out[..len]), truth, g, max_abs(&out[..len]))?;
    }
}
