//! Local repair of holes: boundary faces of the hull that the solved surface crosses
//! (`QuinticOptions::repair_holes`).
//!
//! A boundary face of the hull (the outer faces [p q s] of edge tetrahedra, the base of a
//! single-sided face tetrahedron) has no tetrahedron on its other side, so where F takes both
//! signs on it the surface ends there: a hole. On the fine knot (issue 8) the staged solve
//! leaves ~100 of them, where the weights on the face that Theorem 2.1 (k = 1) asks to have the
//! apex's sign do not. Most weights near such a face are not fixed by data but chosen closest
//! to targets stage by stage (far face weights, face middles, the rest of the edge tetrahedra:
//! every weight in which no point of T has multiplicity ≥ 2). This pass re-solves exactly those
//! weights of the tetrahedra around the face's points of T, *with every C1/C2 equation they
//! appear in* (the other weights held), closest to their solved values, with the face's
//! missing weights pinned to their sign ([`pin`]): C2 is kept exactly, and nothing changes away
//! from the holes. A repair is kept only if the face is no longer crossed and no other boundary
//! face of the re-solved tetrahedra becomes crossed.
//!
//! Where the pins as equations make the local group inconsistent, they become heavily weighted
//! targets instead ([`SOFT`]: the C1/C2 equations still hold exactly, the pinned weights come as
//! close as the equations allow, and the face test decides); faces still crossed after the
//! pass are tried again with one and two more rings ([`WIDEN`]). On the knot: 107 crossed
//! faces; hard pins at 2 rings leave 20, widened 14, with weighted pins 0 (48 repairs, 10
//! of them weighted).

use super::dense;
use super::system::{HullTet, System};
use crate::bb::{multi_indices, poly};
use std::collections::{HashMap, HashSet};

/// What [`repair`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HoleRepair {
    /// Boundary faces crossed (by [`crossed`]) after the solve.
    pub crossed_before: usize,
    /// Of those, faces whose repair was kept.
    pub repaired: usize,
    /// Boundary faces crossed after the repairs.
    pub crossed_after: usize,
    /// Weights pinned to their sign in the kept repairs.
    pub pinned: usize,
    /// Of the repairs kept, those kept only with a wider reach than asked ([`WIDEN`]).
    pub widened: usize,
    /// Of the repairs kept, those whose pins were met only as weighted targets ([`SOFT`]).
    pub soft: usize,
}

/// How far a repair reaches from the crossed face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reach {
    /// Rings of points of T around the face's points whose tetrahedra's late weights are
    /// re-solved (1: the tetrahedra at the face's points).
    pub rings: usize,
    /// Also re-solve the star and edge-middle weights of the points one ring less (with the
    /// jets held): the square star systems then gain the freedom of their edge middles.
    pub stars: bool,
}

/// Lattice steps per edge at which a boundary face is sampled for a sign change ([`crossed`]):
/// finer than the checker's first sampling (12), whose subdivision finds the rest.
const STEPS: usize = 30;
/// |F| at or below this share of the patch's largest weight is zero (the checker's threshold).
const ZERO: f64 = 1e-12;
/// Pinned weights are set to this share of the largest weight on their face, with their sign:
/// clearly signed (far above the solves' rounding), small against the face's data.
const MARGIN: f64 = 1e-3;
/// Faces still crossed after the pass at the asked reach are tried again with up to this many
/// more rings (each pass in tetrahedron order): a repair refused because its pins made the
/// local group inconsistent, or turned a neighbouring face, may succeed with more weights free.
pub const WIDEN: usize = 2;
/// Weight of a pinned weight's distance from its pin, against 1 for the others, when the pins
/// as equations make the local group inconsistent: the C1/C2 equations are then still met
/// exactly (the solved values meet them, so the group is consistent without pins) and the
/// pinned weights come as close to their pins as the equations let them, 1e4 times more
/// important in the squared change than any other weight. On the knot 1e2 repairs every face
/// and 1e3 leaves two: the weights square the condition of the local group, and at 1e3 its
/// residual (2.6e-9 of the data) missed the 1e-9 consistency standard.
const SOFT: f64 = 1e2;
/// Rounds of pinning per face (each pins the conditions the previous solution newly misses).
const ROUNDS: usize = 8;
/// A repair may not grow any re-solved weight beyond this multiple of the largest before.
const GROWTH: f64 = 2.0;
/// A re-solved group is consistent when its residual is at most this share of its data (the
/// staged solve's standard, `system::consistent`).
const CONSISTENT: f64 = 1e-9;

/// The boundary faces of the hull: (tetrahedron, local opposite vertex) of every face that
/// belongs to one tetrahedron only, in tetrahedron order.
#[must_use]
pub fn boundary_faces(tets: &[HullTet]) -> Vec<(u32, usize)> {
    let mut users: HashMap<[u32; 3], u32> = HashMap::new();
    let face = |t: &HullTet, opp: usize| {
        let mut f = [0u32; 3];
        for (c, k) in (0..4).filter(|&k| k != opp).enumerate() {
            f[c] = t.gid[k];
        }
        f.sort_unstable();
        f
    };
    for t in tets {
        for opp in 0..4 {
            *users.entry(face(t, opp)).or_insert(0) += 1;
        }
    }
    let mut out = Vec::new();
    for (k, t) in tets.iter().enumerate() {
        for opp in 0..4 {
            if users[&face(t, opp)] == 1 {
                out.push((k as u32, opp));
            }
        }
    }
    out
}

/// Whether F with the 56 `weights` takes both strict signs on the face opposite local vertex
/// `opp` (lattice of [`STEPS`] per edge; values within [`ZERO`] of the largest weight are zero).
/// A face whose own weights are one-signed is not crossed (the Bernstein basis is positive).
#[must_use]
pub fn crossed(weights: &[f64], opp: usize) -> bool {
    let big = weights.iter().fold(0.0_f64, |a, w| a.max(w.abs()));
    let zero = ZERO * big;
    let mi = multi_indices(5);
    let on_face = || mi.iter().zip(weights).filter(|(l, _)| l[opp] == 0);
    if on_face().all(|(_, w)| *w >= -zero) || on_face().all(|(_, w)| *w <= zero) {
        return false;
    }
    let others: Vec<usize> = (0..4).filter(|&k| k != opp).collect();
    let (mut pos, mut neg) = (false, false);
    for i in 0..=STEPS {
        for j in 0..=STEPS - i {
            let mut b = [0.0; 4];
            b[others[0]] = i as f64 / STEPS as f64;
            b[others[1]] = j as f64 / STEPS as f64;
            b[others[2]] = (STEPS - i - j) as f64 / STEPS as f64;
            let f = poly::eval(5, weights, b);
            pos |= f > zero;
            neg |= f < -zero;
            if pos && neg {
                return true;
            }
        }
    }
    false
}

/// Repairs the crossed boundary faces of the solved `value` (slots of `sys`) in place, one at
/// a time in tetrahedron order (see the module documentation).
#[must_use]
pub fn repair(sys: &System, tets: &[HullTet], value: &mut [f64], reach: Reach) -> HoleRepair {
    let np = sys.np;
    let boundary = boundary_faces(tets);
    let weights = |t: u32, value: &[f64]| -> Vec<f64> { sys.weights(t as usize, value) };
    let is_crossed = |&(t, opp): &(u32, usize), value: &[f64]| crossed(&weights(t, value), opp);
    let holes: Vec<(u32, usize)> = boundary
        .iter()
        .copied()
        .filter(|f| is_crossed(f, value))
        .collect();
    let mut out = HoleRepair {
        crossed_before: holes.len(),
        ..HoleRepair::default()
    };
    if holes.is_empty() {
        return out;
    }
    // Indexes: tetrahedra of each point of T, boundary faces of each tetrahedron, equations
    // of each slot.
    let mut tets_of: HashMap<u32, Vec<u32>> = HashMap::new();
    for (k, t) in tets.iter().enumerate() {
        for &g in t.gid.iter().filter(|&&g| g < np) {
            tets_of.entry(g).or_default().push(k as u32);
        }
    }
    let mut faces_of: HashMap<u32, Vec<usize>> = HashMap::new();
    for &(t, opp) in &boundary {
        faces_of.entry(t).or_default().push(opp);
    }
    let mut eqs_of: Vec<Vec<u32>> = vec![Vec::new(); sys.keys.len()];
    for (e, eq) in sys.equations.iter().enumerate() {
        for &(s, _) in &eq.terms {
            eqs_of[s as usize].push(e as u32);
        }
    }
    let mi = multi_indices(5);
    for extra in 0..=WIDEN {
        let reach = Reach {
            rings: reach.rings + extra,
            ..reach
        };
        for &(t, opp) in &holes {
            if !is_crossed(&(t, opp), value) {
                // Repaired with an earlier face, or in an earlier pass.
                continue;
            }
            if let Some((pinned, soft)) = repair_face(
                sys,
                tets,
                value,
                (t, opp),
                &tets_of,
                &faces_of,
                &eqs_of,
                &mi,
                reach,
            ) {
                out.repaired += 1;
                out.pinned += pinned;
                out.widened += usize::from(extra > 0);
                out.soft += usize::from(soft);
            }
        }
    }
    out.crossed_after = boundary.iter().filter(|f| is_crossed(f, value)).count();
    out
}

/// One face's repair; `Some(pins)` when kept (and `value` updated).
#[allow(clippy::too_many_arguments)]
fn repair_face(
    sys: &System,
    tets: &[HullTet],
    value: &mut [f64],
    (t, opp): (u32, usize),
    tets_of: &HashMap<u32, Vec<u32>>,
    faces_of: &HashMap<u32, Vec<usize>>,
    eqs_of: &[Vec<u32>],
    mi: &[[u8; 4]],
    reach: Reach,
) -> Option<(usize, bool)> {
    let np = sys.np;
    let tet = &tets[t as usize];
    // Points of T within `reach` edges of the face's points.
    let mut ring: Vec<u32> = (0..4)
        .filter(|&k| k != opp && tet.gid[k] < np)
        .map(|k| tet.gid[k])
        .collect();
    let mut inner: Vec<u32> = Vec::new();
    for r in 0..reach.rings {
        if r + 1 == reach.rings {
            inner.clone_from(&ring);
        }
        let grown: Vec<u32> = ring
            .iter()
            .flat_map(|p| tets_of[p].iter())
            .flat_map(|&k| tets[k as usize].gid)
            .filter(|&g| g < np)
            .collect();
        ring.extend(grown);
        ring.sort_unstable();
        ring.dedup();
    }
    if reach.rings == 0 {
        inner.clone_from(&ring);
    }
    let inner: HashSet<u32> = inner.into_iter().collect();
    // The tetrahedra around those points; their late slots, and with `stars` the star and
    // edge-middle slots whose points at multiplicity 2 are all within one ring less.
    let mut near: Vec<u32> = ring
        .iter()
        .flat_map(|p| tets_of[p].iter().copied())
        .collect();
    near.sort_unstable();
    near.dedup();
    let mut unk: Vec<u32> = near
        .iter()
        .flat_map(|&k| sys.slot_of[k as usize].iter().copied())
        .filter(|&s| {
            let parts = super::system::unkey(sys.keys[s as usize]);
            let hull = parts.iter().filter(|p| p.0 < np);
            if hull.clone().all(|p| p.1 <= 1) {
                return true;
            }
            reach.stars
                && hull.clone().all(|p| p.1 <= 2)
                && hull.filter(|p| p.1 == 2).all(|p| inner.contains(&p.0))
        })
        .collect();
    unk.sort_unstable();
    unk.dedup();
    if unk.is_empty() {
        return None;
    }
    let col: HashMap<u32, usize> = unk.iter().enumerate().map(|(i, &s)| (s, i)).collect();
    let mut eqs: Vec<u32> = unk
        .iter()
        .flat_map(|&s| eqs_of[s as usize].iter().copied())
        .collect();
    eqs.sort_unstable();
    eqs.dedup();
    let n = unk.len();
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::with_capacity(eqs.len());
    let mut c: Vec<f64> = Vec::with_capacity(eqs.len());
    for &e in &eqs {
        let mut row = Vec::new();
        let mut rhs = 0.0;
        for &(s, k) in &sys.equations[e as usize].terms {
            match col.get(&s) {
                Some(&j) => row.push((j, k)),
                None => rhs -= k * value[s as usize],
            }
        }
        rows.push(row);
        c.push(rhs);
    }
    let x0: Vec<f64> = unk.iter().map(|&s| value[s as usize]).collect();
    let scale = c.iter().chain(&x0).fold(1e-300_f64, |a, x| a.max(x.abs()));
    let bound = GROWTH * scale;
    // The boundary faces of the re-solved tetrahedra and whether each is crossed now.
    let faces: Vec<(u32, usize)> = near
        .iter()
        .flat_map(|&k| faces_of.get(&k).into_iter().flatten().map(move |&o| (k, o)))
        .collect();
    let crossed_now = |value: &[f64]| -> HashSet<(u32, usize)> {
        faces
            .iter()
            .copied()
            .filter(|&(k, o)| crossed(&sys.weights(k as usize, value), o))
            .collect()
    };
    let before = crossed_now(value);
    // Sign conditions: every late slot on a boundary face of the re-solved tetrahedra with a
    // sign from Theorem 2.1 (its face's weights), the crossed face's misses pinned first, then
    // whatever a solution newly misses among the ones met before.
    let sign = |s: u32| f64::from(sys.req[s as usize]);
    let has_sign = |s: u32| matches!(sys.req[s as usize], 1 | -1);
    let face_slots = |k: u32, o: usize| -> Vec<u32> {
        mi.iter()
            .enumerate()
            .filter(|(_, l)| l[o] == 0)
            .map(|(i, _)| sys.slot_of[k as usize][i])
            .collect()
    };
    let face_scale = |k: u32, o: usize, value: &[f64]| {
        face_slots(k, o)
            .iter()
            .fold(0.0_f64, |a, &s| a.max(value[s as usize].abs()))
    };
    let mut watched: Vec<(u32, f64)> = Vec::new();
    for &(k, o) in &faces {
        let m = MARGIN * face_scale(k, o, value);
        for s in face_slots(k, o) {
            if col.contains_key(&s) && has_sign(s) {
                watched.push((s, m));
            }
        }
    }
    watched.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
    watched.dedup_by_key(|w| w.0);
    let tiny = ZERO * scale;
    let met_before: HashSet<u32> = watched
        .iter()
        .filter(|&&(s, _)| sign(s) * value[s as usize] >= -tiny)
        .map(|w| w.0)
        .collect();
    let hole_slots: HashSet<u32> = face_slots(t, opp).into_iter().collect();
    let mut pins: Vec<(usize, f64)> = Vec::new();
    let mut pinned: HashSet<u32> = HashSet::new();
    let mut x = x0.clone();
    let mut soft = false;
    for _ in 0..ROUNDS {
        let miss: Vec<(u32, f64)> = watched
            .iter()
            .copied()
            .filter(|&(s, _)| !pinned.contains(&s))
            .filter(|&(s, m)| {
                // The crossed face's weights are lifted to the margin; the others only kept
                // from turning.
                let v = sign(s) * x[col[&s]];
                (hole_slots.contains(&s) && v < m) || (met_before.contains(&s) && v < -tiny)
            })
            .collect();
        if miss.is_empty() {
            break;
        }
        for (s, m) in miss {
            pinned.insert(s);
            pins.push((col[&s], sign(s) * m));
        }
        let ok = |sol: &dense::Solution| {
            // NaN-safe: a NaN residual or weight refuses the repair too.
            sol.residual <= CONSISTENT * scale && sol.x.iter().all(|v| v.abs() <= bound)
        };
        let mut sol = solve(&rows, &c, &pins, n, &x0);
        if !ok(&sol) {
            let hard = sol.residual;
            sol = solve_soft(&rows, &c, &pins, n, &x0);
            if !ok(&sol) {
                trace(|| {
                    format!(
                        "face {t}/{opp}: {n} unknowns, {} equations, {} pins: residual {hard:.2e} of {scale:.2e} (soft {:.2e}), largest {:.2e}",
                        rows.len(),
                        pins.len(),
                        sol.residual,
                        sol.x.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
                    )
                });
                return None;
            }
            soft = true;
        }
        x = sol.x;
    }
    if pins.is_empty() {
        trace(|| format!("face {t}/{opp}: nothing to pin among {n} unknowns"));
        return None;
    }
    let mut trial = value.to_vec();
    for (j, &s) in unk.iter().enumerate() {
        trial[s as usize] = x[j];
    }
    // The checker measures jumps relative to the local size of F: each re-solved equation's
    // residual relative to its own terms may not grow past what it was and the staged solve's
    // standard (on the nut, residuals small against the group's largest datum still gave
    // Hessian jumps of 6.5e-7 where F is small).
    let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
    let worst = |value: &[f64]| {
        eqs.iter()
            .map(|&e| sys.relative_residual(e as usize, value, wmax))
            .fold(0.0, f64::max)
    };
    let limit = worst(value).max(super::system::NEAR_NULL_RESIDUAL);
    let grown = worst(&trial);
    if grown.is_nan() || grown > limit {
        trace(|| format!("face {t}/{opp}: relative residual {grown:.2e} > {limit:.2e}"));
        return None;
    }
    let after = crossed_now(&trial);
    if after.contains(&(t, opp)) || after.iter().any(|f| !before.contains(f)) {
        trace(|| {
            format!(
                "face {t}/{opp}: {} pins; still crossed {}, newly crossed {}",
                pins.len(),
                after.contains(&(t, opp)),
                after.iter().filter(|f| !before.contains(f)).count()
            )
        });
        return None;
    }
    for (j, &s) in unk.iter().enumerate() {
        value[s as usize] = x[j];
    }
    Some((pins.len(), soft))
}

/// The weights closest to `x0` that meet `rows`·x = `c` and the pins x_j = v.
fn solve(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    pins: &[(usize, f64)],
    n: usize,
    x0: &[f64],
) -> dense::Solution {
    let m = rows.len() + pins.len();
    if n > super::system::DENSE_LIMIT {
        let mut all: Vec<super::sparse::Row> = rows.to_vec();
        let mut rhs = c.to_vec();
        for &(j, v) in pins {
            all.push(vec![(j, 1.0)]);
            rhs.push(v);
        }
        let scale = rhs.iter().chain(x0).fold(1e-300_f64, |a, x| a.max(x.abs()));
        return super::cholesky::solve_near(&all, n, &rhs, x0, 1e-13 * scale);
    }
    let mut a = vec![0.0; m * n];
    let mut rhs = Vec::with_capacity(m);
    for (i, row) in rows.iter().enumerate() {
        for &(j, k) in row {
            a[i * n + j] += k;
        }
        rhs.push(c[i]);
    }
    for (i, &(j, v)) in pins.iter().enumerate() {
        a[(rows.len() + i) * n + j] = 1.0;
        rhs.push(v);
    }
    dense::solve_near(&a, m, n, &rhs, x0, 1e-11)
}

/// [`solve`] with the pins as targets weighted by [`SOFT`] instead of equations: the weights
/// closest to `x0` (pinned ones: to their pins) in the norm that counts a pinned weight's
/// change `SOFT` times, meeting `rows`·x = `c`. Solved as the unweighted problem in y = W x.
fn solve_soft(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    pins: &[(usize, f64)],
    n: usize,
    x0: &[f64],
) -> dense::Solution {
    let mut w = vec![1.0; n];
    let mut y0 = x0.to_vec();
    for &(j, v) in pins {
        w[j] = SOFT;
        y0[j] = SOFT * v;
    }
    let scaled: Vec<Vec<(usize, f64)>> = rows
        .iter()
        .map(|r| r.iter().map(|&(j, k)| (j, k / w[j])).collect())
        .collect();
    let mut sol = solve(&scaled, c, &[], n, &y0);
    for (x, wj) in sol.x.iter_mut().zip(&w) {
        *x /= wj;
    }
    sol
}

/// Opt-in report of refused repairs on stderr (`APATCH_HOLE_TRACE`; results unaffected).
fn trace(msg: impl FnOnce() -> String) {
    if std::env::var_os("APATCH_HOLE_TRACE").is_some() {
        eprintln!("quintic-c2 hole repair: {}", msg());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One equation x0 = x1. Hard pins x0 = 1, x1 = −1 contradict it; as targets of equal
    /// weight they meet halfway, x0 = x1 = 0, and the unpinned x2 keeps its value. With x0
    /// pinned to 1 and x1 free (target 0), the weighted closest point is
    /// x0 = x1 = SOFT² / (SOFT² + 1).
    #[test]
    fn soft_pins_meet_the_equations_and_come_closest() {
        let rows = vec![vec![(0, 1.0), (1, -1.0)]];
        let x0 = [0.0, 0.0, 7.0];
        let hard = solve(&rows, &[0.0], &[(0, 1.0), (1, -1.0)], 3, &x0);
        assert!(hard.residual > 0.5, "{hard:?}");
        let s = solve_soft(&rows, &[0.0], &[(0, 1.0), (1, -1.0)], 3, &x0);
        // Rounding of a 3-unknown QR (entries O(SOFT)).
        assert!(s.residual < 1e-12, "{s:?}");
        assert!(s.x[0].abs() < 1e-12 && s.x[1].abs() < 1e-12, "{s:?}");
        assert!((s.x[2] - 7.0).abs() < 1e-12, "{s:?}");
        let s = solve_soft(&rows, &[0.0], &[(0, 1.0)], 3, &x0);
        let want = SOFT * SOFT / (SOFT * SOFT + 1.0);
        assert!(
            (s.x[0] - want).abs() < 1e-12 && (s.x[1] - want).abs() < 1e-12,
            "{s:?}"
        );
        // The same through the sparse path (more unknowns than the dense limit; the others
        // appear in no equation and keep their targets).
        let n = super::super::system::DENSE_LIMIT + 1;
        let mut x0 = vec![0.0; n];
        x0[2] = 7.0;
        let s = solve_soft(&rows, &[0.0], &[(0, 1.0)], n, &x0);
        assert!(
            (s.x[0] - want).abs() < 1e-12 && (s.x[1] - want).abs() < 1e-12,
            "{s:?}"
        );
        assert!((s.x[2] - 7.0).abs() < 1e-12, "{s:?}");
    }
}
