//! Bent polygons' splits chosen by the hull's own verification.
//!
//! [`super::planar`] ranks the triangulations of every non-planar polygon by local rules (no
//! diagonal ending at a steep corner, diagonals folding like the polygon's own edges, nearly
//! coplanar pieces joined back at folded corners). On a coarse, strongly bent control cage
//! (spot_control_cage) those rules still leave corners whose fans overlap, and which split is
//! better there depends on the whole corner: its turned normal (Appendix C), the other
//! polygons' pieces, the apexes. So where the hull built from the ranked splits fails
//! [`super::verify`], the splits of the bent polygons at the corners its violations name are
//! changed one polygon at a time, every other triangulation and join tried, and a change is kept
//! when the rebuilt hull has strictly fewer violations and no more of other kinds than overlaps ([`improve`]; greedy, at most
//! [`MAX_ROUNDS`] passes, at most [`MAX_TRIALS`] rebuilds). Nothing changes for a hull that
//! verifies or has no bent polygon: every scene of `scenes/paper1994/` keeps its hull. The
//! conditions are verify's own; no check is loosened, the search only picks among proper
//! triangulations of the same polygons (no vertex moves).

use super::planar::Forced;
use super::verify::{HullViolation, ViolationKind};

/// Passes over the bent polygons at named corners.
pub const MAX_ROUNDS: usize = 4;

/// Rebuilds of the hull the search may make in all (each costs one hull build and
/// verification: 30–60 ms on spot_control_cage in release).
pub const MAX_TRIALS: usize = 600;

/// One split polygon the search may change.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bent {
    /// The face (index in the mesh handed to [`super::planar`]).
    pub face: u32,
    /// Its corners (vertex indices).
    pub corners: Vec<u32>,
    /// How many ranked triangulations it has.
    pub candidates: usize,
    /// The split the ranked choice took.
    pub ranked: Forced,
    /// For each triangulation, whether joining changes it (else only `join: true` is tried).
    pub joinable: Vec<bool>,
}

/// The input vertices ("element N") a violation's message names.
#[must_use]
pub fn named_elements(message: &str) -> Vec<u32> {
    message
        .split("element ")
        .skip(1)
        .filter_map(|s| {
            s.split(|c: char| !c.is_ascii_digit())
                .next()
                .and_then(|d| d.parse().ok())
        })
        .collect()
}

/// What the search minimises: first the violations of other kinds than overlaps (a split
/// must not trade overlaps for a nonconvex edge of T or a tangent plane missing its
/// tetrahedra), then all of them.
fn score(violations: &[HullViolation]) -> (usize, usize) {
    let other = violations
        .iter()
        .filter(|v| v.kind != ViolationKind::Intersecting)
        .count();
    (other, violations.len())
}

/// What [`improve`] found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Search {
    /// The forced splits kept, by face.
    pub forced: Vec<(u32, Forced)>,
    /// Violations of the ranked splits' hull.
    pub before: usize,
    /// Violations with the forced splits.
    pub after: usize,
    /// Hull rebuilds made.
    pub trials: usize,
}

/// The greedy search of the module documentation. `violations` are the ranked splits' hull's;
/// `build` rebuilds the hull with the given forced splits and returns its violations (`None`
/// when that hull cannot be built, which rejects the trial).
pub fn improve<F>(bent: &[Bent], violations: &[HullViolation], build: F) -> Search
where
    F: FnMut(&[(u32, Forced)]) -> Option<Vec<HullViolation>>,
{
    improve_from(bent, &[], violations, build)
}

/// [`improve`] starting from the forced splits `start` (whose hull has `violations`): a
/// second pass after other choices changed ([`super::recut`]). The result lists `start`'s
/// splits too, changed or not.
pub fn improve_from<F>(
    bent: &[Bent],
    start: &[(u32, Forced)],
    violations: &[HullViolation],
    mut build: F,
) -> Search
where
    F: FnMut(&[(u32, Forced)]) -> Option<Vec<HullViolation>>,
{
    let mut search = Search {
        before: violations.len(),
        after: violations.len(),
        ..Search::default()
    };
    let mut current = violations.to_vec();
    let mut forced: Vec<(u32, Forced)> = start.to_vec();
    for _ in 0..MAX_ROUNDS {
        if current.is_empty() {
            break;
        }
        let mut improved = false;
        // Corners named by violations, by how often.
        let mut named: Vec<u32> = current
            .iter()
            .flat_map(|v| named_elements(&v.message))
            .collect();
        named.sort_unstable();
        let count = |v: u32| named.partition_point(|&x| x <= v) - named.partition_point(|&x| x < v);
        // Bent polygons at named corners, most named first (ties: face order).
        let mut order: Vec<(usize, &Bent)> = bent
            .iter()
            .map(|b| (b.corners.iter().map(|&v| count(v)).sum::<usize>(), b))
            .filter(|(c, b)| *c > 0 && (b.candidates > 1 || b.corners.len() > 3))
            .collect();
        order.sort_by(|x, y| y.0.cmp(&x.0).then(x.1.face.cmp(&y.1.face)));
        for (_, b) in order {
            let now = forced
                .iter()
                .find(|(f, _)| *f == b.face)
                .map_or(b.ranked, |(_, s)| *s);
            let mut best: Option<(Forced, Vec<HullViolation>)> = None;
            for triangulation in 0..b.candidates {
                for join in [true, false] {
                    let alt = Forced {
                        triangulation,
                        join,
                    };
                    // Without a pair to join, both settings are one split.
                    let joins = |t: usize| b.joinable.get(t).copied().unwrap_or(true);
                    let plain = |f: Forced| Forced {
                        join: f.join || !joins(f.triangulation),
                        ..f
                    };
                    if (!join && !joins(triangulation))
                        || plain(alt) == plain(now)
                        || search.trials >= MAX_TRIALS
                    {
                        continue;
                    }
                    let mut trial = forced.clone();
                    trial.retain(|(f, _)| *f != b.face);
                    trial.push((b.face, alt));
                    search.trials += 1;
                    let Some(v) = build(&trial) else { continue };
                    let bound = best.as_ref().map_or(score(&current), |(_, w)| score(w));
                    if score(&v) < bound {
                        best = Some((alt, v));
                    }
                }
            }
            if let Some((alt, v)) = best {
                forced.retain(|(f, _)| *f != b.face);
                forced.push((b.face, alt));
                current = v;
                improved = true;
            }
        }
        if !improved || search.trials >= MAX_TRIALS {
            break;
        }
    }
    forced.sort_by_key(|(f, _)| *f);
    search.after = current.len();
    search.forced = forced;
    search
}

#[cfg(test)]
mod tests {
    use super::*;

    fn violation(message: &str) -> HullViolation {
        HullViolation {
            kind: ViolationKind::Intersecting,
            triangle: None,
            message: message.into(),
        }
    }

    /// The elements a verify message names, in order.
    #[test]
    fn named_elements_reads_verify_messages() {
        let m = "Outer face tetrahedron of triangle 54 (element 9) overlaps Outer edge \
                 tetrahedron at edge (83, 353) beside triangle 55 (element 15) (depth 4.04e-2)";
        assert_eq!(named_elements(m), vec![9, 15]);
        assert!(named_elements("no elements").is_empty());
    }

    /// A toy cost: each polygon's violations are |triangulation − its best| + (join ? 0 : 1),
    /// naming its first corner. The greedy search finds every polygon's best (independent
    /// truth: the cost's minimum, 0), only touching polygons at named corners, and keeps the
    /// ranked split where it is best already.
    #[test]
    fn greedy_search_finds_a_separable_minimum() {
        let best = [2usize, 0, 1];
        let bent: Vec<Bent> = (0..3)
            .map(|k| Bent {
                face: 10 + k as u32,
                corners: vec![k as u32, 100 + k as u32, 200 + k as u32, 300 + k as u32],
                candidates: 3,
                ranked: Forced {
                    triangulation: 0,
                    join: true,
                },
                joinable: vec![true; 3],
            })
            .collect();
        let cost = |forced: &[(u32, Forced)]| -> Vec<HullViolation> {
            let mut out = Vec::new();
            for (k, b) in bent.iter().enumerate() {
                let s = forced
                    .iter()
                    .find(|(f, _)| *f == b.face)
                    .map_or(b.ranked, |(_, s)| *s);
                let n = s.triangulation.abs_diff(best[k]) + usize::from(!s.join);
                for _ in 0..n {
                    out.push(violation(&format!("triangle 1 (element {k}) bad")));
                }
            }
            out
        };
        let start = cost(&[]);
        assert_eq!(start.len(), 3);
        let s = improve(&bent, &start, |f| Some(cost(f)));
        assert_eq!(s.before, 3);
        assert_eq!(s.after, 0);
        let faces: Vec<u32> = s.forced.iter().map(|(f, _)| *f).collect();
        assert_eq!(faces, vec![10, 12]);
        assert!(s.forced.iter().all(|(_, x)| x.join));
        assert_eq!(s.forced[0].1.triangulation, 2);
        assert_eq!(s.forced[1].1.triangulation, 1);
        // Nothing named: nothing tried.
        let s = improve(&bent, &[], |_| panic!("no rebuild without violations"));
        assert_eq!((s.trials, s.after), (0, 0));
    }
}
