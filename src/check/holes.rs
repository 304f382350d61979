//! Holes: the surface must not leave the union of the tetrahedra.
//!
//! A face of one patch only (a boundary face of the hull: the base of a single-sided face
//! tetrahedron, the outer faces of edge tetrahedra, the free faces of an L-U pair) has nothing
//! on its other side, so where the zero set of a single-sheeted patch ([`SheetRule::Any`])
//! reaches such a face the surface ends there: a hole. Sound test: F restricted to every
//! boundary face must not take both strict signs.
//!
//! The restriction of a degree-n patch to the face opposite vertex m is the bivariate BB
//! polynomial with the weights λ_m = 0. All of one sign (up to round-off) is a certificate;
//! otherwise the face is split into four sub-triangles (their coefficients are blossom values
//! at the sub-triangle's corners) down to [`MAX_DEPTH`] levels: a sub-triangle whose coefficients
//! are one-signed with some non-zero has F of that strict sign in its interior (the Bernstein
//! basis is positive there), so two sub-triangles of opposite strict signs, or two sampled
//! values of opposite strict signs, prove a crossing. Faces neither certified nor proven to cross
//! are counted as uncertified (information).
//!
//! Patches with a shooting sheet rule (the 2001 scheme) are skipped: only their first root along
//! each shooting line is surface, so F may change sign on their boundary faces beyond it.

use super::anatomy::{anatomy, HeldBy};
use super::eval::PatchEval;
use super::faces::PointKey;
use super::{CrossedFace, HoleStats, Location};
use crate::bb::index_of;
use crate::complex::SheetRule;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashSet;

/// Levels of four-way subdivision tried before a face counts as uncertified.
pub const MAX_DEPTH: usize = 5;

/// |F| (or a coefficient) at or below this fraction of the patch's largest weight counts as
/// zero: far above the round-off of the weights (1e-16 relative), far below any value the
/// schemes set on purpose (zero-convex faces have F ≡ 0 up to round-off on T).
const ZERO: f64 = 1e-12;

/// Steps per edge of the lattice sampled on every face that is not certified at once.
const LATTICE: usize = 12;

/// The verdict on one boundary face.
#[derive(Default)]
struct FaceVerdict {
    certified: bool,
    crossing: bool,
    /// min(largest F, −smallest F) / S over the evidence (the depth of the crossing).
    depth: f64,
    /// A point of the minority sign.
    point: [f64; 3],
}

/// Examines the boundary faces `boundary` ((patch position in `evals`, the face's opposite
/// tetrahedron-local vertex)); each crossed face's [`anatomy`] is judged with the complex's
/// interpolated vertices (`surface`, [`super::faces::point_key`]s) and `continuity`.
pub(super) fn measure(
    evals: &[PatchEval<'_>],
    boundary: &[(u32, u8)],
    surface: &HashSet<PointKey>,
    continuity: u8,
) -> HoleStats {
    boundary
        .par_iter()
        .map(|&(p, opp)| {
            let e = &evals[p as usize];
            let mut s = HoleStats::default();
            if !matches!(e.patch.sheet, SheetRule::Any) {
                s.skipped += 1;
                return s;
            }
            s.boundary_faces += 1;
            if e.has_no_zero() {
                s.certified += 1;
                return s;
            }
            let v = face_verdict(e, opp);
            if v.crossing {
                s.crossing += 1;
                s.crossing_by_role
                    .insert(e.patch.role.name().to_string(), 1);
                let a = if e.patch.rational.is_empty() {
                    Some(anatomy(
                        e.patch,
                        usize::from(opp),
                        surface,
                        continuity,
                        ZERO,
                    ))
                } else {
                    None
                };
                let held_by = a.as_ref().map_or(HeldBy::Unsigned, |a| a.held_by);
                s.crossing_by_cause.insert(held_by.name().to_string(), 1);
                s.worst = v.depth;
                s.crossing_at = Some(Location::new(&[e], v.point, None));
                let tet = e.patch.tet_points();
                let mut corners = [[0.0; 3]; 3];
                for (c, k) in corners
                    .iter_mut()
                    .zip((0..4).filter(|&k| k != usize::from(opp)))
                {
                    *c = tet[k].to_array();
                }
                s.faces.push(CrossedFace {
                    patch: e.id,
                    element: e.element(),
                    corners,
                    depth: v.depth,
                    point: v.point,
                    sign: a.as_ref().map_or(0, |a| a.sign),
                    against: a
                        .as_ref()
                        .filter(|a| a.held_by != HeldBy::Unsigned)
                        .map(|a| a.index),
                    against_share: a.as_ref().map_or(0.0, |a| a.share),
                    against_order: a.as_ref().map(|a| a.order),
                    held_by: held_by.name().to_string(),
                });
            } else if v.certified {
                s.certified += 1;
            } else {
                s.uncertified += 1;
            }
            s
        })
        .reduce(HoleStats::default, merge)
}

fn merge(a: HoleStats, b: HoleStats) -> HoleStats {
    let b_worse = b.worst > a.worst || (a.crossing_at.is_none() && b.crossing_at.is_some());
    let (worst, crossing_at) = if b_worse {
        (b.worst, b.crossing_at)
    } else {
        (a.worst, a.crossing_at)
    };
    let mut faces = a.faces;
    faces.extend(b.faces);
    let mut crossing_by_role = a.crossing_by_role;
    for (k, v) in b.crossing_by_role {
        *crossing_by_role.entry(k).or_insert(0) += v;
    }
    let mut crossing_by_cause = a.crossing_by_cause;
    for (k, v) in b.crossing_by_cause {
        *crossing_by_cause.entry(k).or_insert(0) += v;
    }
    HoleStats {
        crossing_by_role,
        crossing_by_cause,
        boundary_faces: a.boundary_faces + b.boundary_faces,
        certified: a.certified + b.certified,
        crossing: a.crossing + b.crossing,
        uncertified: a.uncertified + b.uncertified,
        skipped: a.skipped + b.skipped,
        worst,
        crossing_at,
        faces,
    }
}

/// Bivariate BB coefficients of degree n, index i·(n+1) + j for (i, j, n − i − j).
#[derive(Clone)]
struct Tri {
    n: usize,
    c: Vec<f64>,
}

impl Tri {
    /// The blossom with `args` (face barycentric 3-vectors, n of them).
    fn blossom(&self, args: &[[f64; 3]]) -> f64 {
        let n = self.n;
        let w = n + 1;
        let mut c = self.c.clone();
        for (step, a) in args.iter().enumerate() {
            let d = n - step;
            for i in 0..d {
                for j in 0..d - i {
                    c[i * w + j] =
                        a[0] * c[(i + 1) * w + j] + a[1] * c[i * w + j + 1] + a[2] * c[i * w + j];
                }
            }
        }
        c[0]
    }

    /// The coefficients on the sub-triangle with corners `k` (face barycentrics).
    fn sub(&self, k: &[[f64; 3]; 3]) -> Tri {
        let n = self.n;
        let w = n + 1;
        let mut c = vec![0.0; w * w];
        let mut args = Vec::with_capacity(n);
        for i in 0..=n {
            for j in 0..=n - i {
                args.clear();
                args.extend(std::iter::repeat_n(k[0], i));
                args.extend(std::iter::repeat_n(k[1], j));
                args.extend(std::iter::repeat_n(k[2], n - i - j));
                c[i * w + j] = self.blossom(&args);
            }
        }
        Tri { n, c }
    }

    /// The coefficients that exist (i + j ≤ n).
    fn coeffs(&self) -> impl Iterator<Item = f64> + '_ {
        let w = self.n + 1;
        (0..=self.n).flat_map(move |i| (0..=self.n - i).map(move |j| self.c[i * w + j]))
    }

    /// +1 / −1 when every coefficient is ≥ −zero / ≤ zero and some exceeds zero in magnitude;
    /// 0 when all are within zero (F ≡ 0 up to round-off); `None` when of both signs.
    fn sign(&self, zero: f64) -> Option<i8> {
        let (mut pos, mut neg) = (false, false);
        for x in self.coeffs() {
            pos |= x > zero;
            neg |= x < -zero;
        }
        match (pos, neg) {
            (true, true) => None,
            (true, false) => Some(1),
            (false, true) => Some(-1),
            (false, false) => Some(0),
        }
    }
}

/// Evidence gathered on one face: the extreme values of each strict sign and where.
struct Evidence {
    zero: f64,
    pos: (f64, [f64; 3]),
    neg: (f64, [f64; 3]),
}

impl Evidence {
    fn add(&mut self, f: f64, at: [f64; 3]) {
        if f > self.zero && f > self.pos.0 {
            self.pos = (f, at);
        }
        if f < -self.zero && -f > self.neg.0 {
            self.neg = (-f, at);
        }
    }

    /// Records `f` as evidence of its strict sign even below the zero threshold (a certified
    /// sub-triangle's interior).
    fn force(&mut self, f: f64, at: [f64; 3]) {
        if f > 0.0 && self.pos.0 == 0.0 {
            self.pos = (f, at);
        }
        if f < 0.0 && self.neg.0 == 0.0 {
            self.neg = (-f, at);
        }
    }

    fn crossing(&self) -> bool {
        self.pos.0 > 0.0 && self.neg.0 > 0.0
    }
}

fn face_verdict(e: &PatchEval<'_>, opp: u8) -> FaceVerdict {
    let p = e.patch;
    let n = usize::from(p.degree);
    let verts: Vec<usize> = (0..4).filter(|&k| k != usize::from(opp)).collect();
    let tet = p.tet_points();
    let world = |b: [f64; 3]| -> [f64; 3] {
        (0..3)
            .map(|m| b[m] * tet[verts[m]])
            .sum::<DVec3>()
            .to_array()
    };
    let alpha = |b: [f64; 3]| {
        let mut a = [0.0; 4];
        for m in 0..3 {
            a[verts[m]] = b[m];
        }
        a
    };
    let s = e.weight_scale().max(f64::MIN_POSITIVE);
    let zero = ZERO * s;
    let mut ev = Evidence {
        zero,
        pos: (0.0, [0.0; 3]),
        neg: (0.0, [0.0; 3]),
    };
    let finish = |ev: &Evidence, certified: bool| {
        if ev.crossing() {
            // The minority sign is the one with the smaller extreme.
            let (depth, point) = if ev.pos.0 <= ev.neg.0 {
                (ev.pos.0, ev.pos.1)
            } else {
                (ev.neg.0, ev.neg.1)
            };
            FaceVerdict {
                certified: false,
                crossing: true,
                depth: depth / s,
                point: world(point),
            }
        } else {
            FaceVerdict {
                certified,
                ..FaceVerdict::default()
            }
        }
    };

    // Rational terms: no coefficient certificate, sampling only.
    if !p.rational.is_empty() {
        sample_lattice(&mut ev, &|b| e.value(alpha(b)));
        return finish(&ev, false);
    }
    let face = face_coefficients(n, &p.weights, usize::from(opp));
    let all_certified = judge(&face, &mut ev, |b| e.value(alpha(b)));
    finish(&ev, all_certified)
}

/// The bivariate coefficients of the face opposite local vertex `opp` of a degree-`n` patch
/// with BB `weights` (the weights with λ_opp = 0).
fn face_coefficients(n: usize, weights: &[f64], opp: usize) -> Tri {
    let verts: Vec<usize> = (0..4).filter(|&k| k != opp).collect();
    let w = n + 1;
    let mut c = vec![0.0; w * w];
    for i in 0..=n {
        for j in 0..=n - i {
            let mut l = [0u8; 4];
            l[verts[0]] = i as u8;
            l[verts[1]] = j as u8;
            l[verts[2]] = (n - i - j) as u8;
            c[i * w + j] = weights[index_of(l)];
        }
    }
    Tri { n, c }
}

/// Gathers into `ev` the evidence on `face` (F's values by `value`, at face barycentrics):
/// its coefficients, a lattice, then subdivision. Returns whether every part was certified
/// one-signed (false: some sub-triangle at [`MAX_DEPTH`] still had coefficients of both signs).
fn judge(face: &Tri, ev: &mut Evidence, value: impl Fn([f64; 3]) -> f64) -> bool {
    let zero = ev.zero;
    if face.sign(zero).is_some() {
        return true;
    }
    sample_lattice(ev, &value);
    if ev.crossing() {
        return false;
    }
    // Subdivision: certify sub-triangles (coefficients from the face's blossom at their
    // corners), remember their strict signs and where.
    let corners = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut stack = vec![(corners, 0usize)];
    let mut all_certified = true;
    while let Some((k, depth)) = stack.pop() {
        let t = if depth == 0 {
            face.clone()
        } else {
            face.sub(&k)
        };
        for (b, f) in k.iter().zip(corner_values(&t)) {
            ev.add(f, *b);
        }
        match t.sign(zero) {
            Some(0) => {}
            Some(sg) => {
                // F has the strict sign sg inside: record its centroid for that sign even when
                // |F| there is below the zero threshold.
                let mid: [f64; 3] = std::array::from_fn(|m| (k[0][m] + k[1][m] + k[2][m]) / 3.0);
                let f = value(mid).abs().max(f64::MIN_POSITIVE);
                ev.force(f64::from(sg) * f, mid);
            }
            None if depth >= MAX_DEPTH => all_certified = false,
            None => {
                let m = |a: [f64; 3], b: [f64; 3]| std::array::from_fn(|x| 0.5 * (a[x] + b[x]));
                let (m01, m12, m02) = (m(k[0], k[1]), m(k[1], k[2]), m(k[0], k[2]));
                for sub in [
                    [k[0], m01, m02],
                    [m01, k[1], m12],
                    [m02, m12, k[2]],
                    [m12, m02, m01],
                ] {
                    stack.push((sub, depth + 1));
                }
            }
        }
        if ev.crossing() {
            break;
        }
    }
    all_certified
}

/// Whether F of a polynomial patch (degree `n`, BB `weights`) takes both strict signs on the
/// face opposite local vertex `opp`, by the evidence `apatch check` gathers (values within
/// 1e-12 of the largest weight count as zero): what a scheme's repair must see to agree with
/// the check's "holes".
#[must_use]
pub fn polynomial_face_crossed(n: usize, weights: &[f64], opp: usize) -> bool {
    let s = weights.iter().fold(0.0_f64, |a, w| a.max(w.abs()));
    let mut ev = Evidence {
        zero: ZERO * s.max(f64::MIN_POSITIVE),
        pos: (0.0, [0.0; 3]),
        neg: (0.0, [0.0; 3]),
    };
    let face = face_coefficients(n, weights, opp);
    judge(&face, &mut ev, |b| face.blossom(&vec![b; n]));
    ev.crossing()
}

/// F at the corners of a triangle: its corner coefficients, in corner order.
fn corner_values(t: &Tri) -> [f64; 3] {
    let w = t.n + 1;
    [t.c[t.n * w], t.c[t.n], t.c[0]]
}

/// Samples the face's lattice (boundary included) into `ev`.
fn sample_lattice(ev: &mut Evidence, f: &impl Fn([f64; 3]) -> f64) {
    for i in 0..=LATTICE {
        for j in 0..=LATTICE - i {
            let b = [
                i as f64 / LATTICE as f64,
                j as f64 / LATTICE as f64,
                (LATTICE - i - j) as f64 / LATTICE as f64,
            ];
            ev.add(f(b), b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic on a triangle with deterministic pseudo-random coefficients.
    fn cubic() -> Tri {
        let mut x = 0x9e37_79b9_u64;
        let c = (0..16)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x % 2001) as f64 / 1000.0 - 1.0
            })
            .collect();
        Tri { n: 3, c }
    }

    /// Direct evaluation: Σ c_ijk · 3!/(i!j!k!) · b0^i b1^j b2^k.
    fn eval(t: &Tri, b: [f64; 3]) -> f64 {
        let f = |k: usize| (1..=k).product::<usize>() as f64;
        let n = t.n;
        let mut s = 0.0;
        for i in 0..=n {
            for j in 0..=n - i {
                let k = n - i - j;
                s += t.c[i * (n + 1) + j] * f(n) / (f(i) * f(j) * f(k))
                    * b[0].powi(i as i32)
                    * b[1].powi(j as i32)
                    * b[2].powi(k as i32);
            }
        }
        s
    }

    /// The sub-triangle's coefficients describe the same polynomial: F at a point of the
    /// sub-triangle equals the sub-triangle's polynomial at that point's local barycentrics.
    #[test]
    fn subtriangle_coefficients_match_direct_evaluation() {
        let t = cubic();
        let k = [[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.25, 0.25, 0.5]];
        let s = t.sub(&k);
        for l in [[0.2, 0.3, 0.5], [1.0, 0.0, 0.0], [0.1, 0.8, 0.1]] {
            let b: [f64; 3] = std::array::from_fn(|m| (0..3).map(|q| l[q] * k[q][m]).sum());
            // Round-off of a few dozen products of O(1) numbers.
            assert!((eval(&s, l) - eval(&t, b)).abs() < 1e-13);
        }
        // The blossom on the diagonal is F.
        let b = [0.3, 0.3, 0.4];
        assert!((t.blossom(&[b, b, b]) - eval(&t, b)).abs() < 1e-13);
    }

    #[test]
    fn sign_of_coefficients() {
        let mut t = Tri {
            n: 2,
            c: vec![0.0; 9],
        };
        assert_eq!(t.sign(1e-12), Some(0));
        t.c[0] = -1.0;
        t.c[1] = -2.0;
        assert_eq!(t.sign(1e-12), Some(-1));
        t.c[3] = 0.5;
        assert_eq!(t.sign(1e-12), None);
    }

    /// The 56 BB weights of the quintic (b₀ − c·S)² S³ − ε S⁵ on a tetrahedron (S = Σ bₘ ≡ 1):
    /// a weight is the average of the factors' coefficients over the orderings of its indices,
    /// here (b₀ − c)² − ε averaged over the 20 ordered pairs of index positions.
    fn band_weights(c: f64, eps: f64) -> Vec<f64> {
        crate::bb::multi_indices(5)
            .into_iter()
            .map(|l| {
                let seq: Vec<usize> = (0..4).flat_map(|m| vec![m; usize::from(l[m])]).collect();
                let lin = |m: usize| if m == 0 { 1.0 - c } else { -c };
                let mut sum = 0.0;
                for i in 0..5 {
                    for j in 0..5 {
                        if i != j {
                            sum += lin(seq[i]) * lin(seq[j]);
                        }
                    }
                }
                sum / 20.0 - eps
            })
            .collect()
    }

    /// F = (b₀ − 3/8)² − 1e-5 is negative only in a band 0.0063 wide around b₀ = 3/8, between
    /// the points of a 30-step lattice (b₀ = 11/30, 12/30), but the subdivision's corners reach
    /// b₀ = 3/8: the face opposite vertex 3 is crossed, by brute force and by the verdict.
    /// With +1e-5 it is positive everywhere and not crossed.
    #[test]
    fn thin_pocket_between_lattice_points_is_a_crossing() {
        let n = 5;
        let w = band_weights(0.375, 1e-5);
        let value = |b: [f64; 4]| crate::bb::poly::eval(n, &w, b);
        // Independent truth: a fine lattice on the face sees both signs.
        let steps = 800;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=steps {
            for j in 0..=steps - i {
                let b = [i as f64, j as f64, (steps - i - j) as f64, 0.0].map(|x| x / steps as f64);
                lo = lo.min(value(b));
                hi = hi.max(value(b));
            }
        }
        assert!(lo < 0.0 && hi > 0.0, "{lo} {hi}");
        // The 30-step lattice alone does not.
        let coarse = (0..=30).all(|i| {
            (0..=30 - i).all(|j| value([i, j, 30 - i - j, 0].map(|x| f64::from(x) / 30.0)) > 0.0)
        });
        assert!(coarse);
        assert!(polynomial_face_crossed(n, &w, 3));
        assert!(!polynomial_face_crossed(n, &band_weights(0.375, -1e-5), 3));
        // The face opposite vertex 0 has b₀ = 0: F = 0.375² − 1e-5 there, one-signed.
        assert!(!polynomial_face_crossed(n, &w, 0));
    }
}
