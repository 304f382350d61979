//! Seeded perturbations of single weights of a global-quadric complex: `check` must report a
//! value or gradient jump exactly when the weight can cause one (it lies on, or next to, a face
//! shared with another patch), and name the perturbed patch.

use apatch::bb::multi_indices;
use apatch::check::{check, CheckOptions};
use apatch::fixtures::{quadric_complex, Quadric};
use glam::DVec3;

/// A small deterministic generator (64-bit LCG, high bits).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn single_weight_perturbations_are_found_exactly_when_they_matter() {
    let q = Quadric::ellipsoid(DVec3::new(0.1, -0.1, 0.05), DVec3::new(0.8, 0.6, 0.7));
    let base = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 2, 6);
    let clean = check(&base, &CheckOptions::default());
    assert!(clean.passed(), "{clean}");

    // Which faces (by opposite local vertex) of each patch are shared: count face keys.
    let key = |p: &apatch::complex::Patch, opposite: usize| {
        let mut k: Vec<[u64; 3]> = (0..4)
            .filter(|&i| i != opposite)
            .map(|i| p.tet[i].map(|x| (x + 0.0).to_bits()))
            .collect();
        k.sort();
        k
    };
    let mut counts = std::collections::HashMap::new();
    for p in &base.patches {
        for o in 0..4 {
            *counts.entry(key(p, o)).or_insert(0) += 1;
        }
    }

    let indices = multi_indices(6);
    let mut rng = Lcg(0x5eed);
    let (mut value_cases, mut gradient_cases, mut silent_cases) = (0, 0, 0);
    for _ in 0..150 {
        let pi = rng.below(base.patches.len());
        let k = rng.below(indices.len());
        let lambda = indices[k];
        let shared: Vec<bool> = (0..4)
            .map(|o| counts[&key(&base.patches[pi], o)] == 2)
            .collect();
        // On a shared face: λ_o = 0; one layer in: λ_o = 1.
        let on_face = (0..4).any(|o| shared[o] && lambda[o] == 0);
        let next_to_face = (0..4).any(|o| shared[o] && lambda[o] <= 1);

        let mut c = base.clone();
        c.patches[pi].weights[k] += 1e-5;
        let r = check(&c, &CheckOptions::default());
        if on_face {
            value_cases += 1;
            assert!(r.value_jump.worst > 1e-8, "patch {pi} λ {lambda:?}: {r}");
            assert!(
                r.value_jump.at.as_ref().unwrap().patches.contains(&pi),
                "{r}"
            );
        }
        if next_to_face {
            gradient_cases += 1;
            assert!(r.gradient_jump.worst > 1e-8, "patch {pi} λ {lambda:?}: {r}");
            assert!(
                r.gradient_jump.at.as_ref().unwrap().patches.contains(&pi),
                "{r}"
            );
            assert!(!r.passed());
        } else {
            silent_cases += 1;
            // Cannot move F or ∇F on any shared face: rounding only.
            assert!(r.value_jump.worst < 1e-13, "patch {pi} λ {lambda:?}: {r}");
            assert!(
                r.gradient_jump.worst < 1e-12,
                "patch {pi} λ {lambda:?}: {r}"
            );
            assert!(r.passed(), "{r}");
        }
    }
    // The draws cover every kind of case.
    assert!(value_cases > 0 && gradient_cases > value_cases && silent_cases > 0);
}
