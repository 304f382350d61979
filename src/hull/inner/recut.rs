//! Corners re-cut by the hull's own verification (beyond the paper; spot_control_cage's folded
//! corners).
//!
//! Two choices of Algorithm 1 at a non-trihedral corner V are free: the normal n_V, as long as
//! it is "above face" (§4 (ii), Appendix C: any direction with n_V · n_f > 0 for every face
//! round V will do), and how deep the corner is cut, α of C_0 = αV + (1 − α)V̄ (§7.1's shape
//! control). The hull takes the given normal (turned by [`super::above::make_above`] only as far
//! as it must) and one α for all corners. At a folded corner of a coarse control cage
//! (spot_control_cage's 52/161 and 50/159: face 38 folds under both, their input normals −0.95 and
//! −0.34 against it) the least turn leaves n_V nearly in a face's plane, and the face tetrahedra
//! of the fan lean across each other whichever split the bent polygons take
//! ([`super::retriangulate`]).
//!
//! So where the hull still fails [`super::verify`], the corners its violations name are tried,
//! one at a time and most named first, with the other cuts of [`CUTS`] (n_V turned further
//! towards the direction most above its faces, [`super::above::most_above`], and shallower or
//! deeper α); a cut is kept when the rebuilt hull has fewer violations and no more of other
//! kinds than overlaps ([`improve`]; greedy, at most [`MAX_ROUNDS`] passes and [`MAX_TRIALS`]
//! rebuilds). Nothing changes for a hull that verifies: every scene of `scenes/paper1994/` keeps
//! its hull. The conditions are verify's own; no check is loosened, the search only picks among
//! choices the paper leaves free (every tried normal stays above face; no vertex moves).

use super::retriangulate::named_elements;
use super::verify::{HullViolation, ViolationKind};

/// Passes over the named corners.
pub const MAX_ROUNDS: usize = 3;

/// Rebuilds of the hull the search may make in all (each costs one hull build and verification:
/// 30–60 ms on spot_control_cage in release).
pub const MAX_TRIALS: usize = 600;

/// One corner's cut: how far n_V turns from the normal the hull would take (the given normal,
/// or Appendix C's least turn of it) towards the direction most above the corner's faces, and
/// the corner's α (`None`: the hull's [`super::InnerOptions::alpha`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    /// Blend weight in [0, 1] towards [`super::above::most_above`] of the corner's faces (the
    /// blend of two above-face directions is above face: the set is convex).
    pub turn: f64,
    /// The corner's α, in (0, 1).
    pub alpha: Option<f64>,
}

/// The cuts tried at a named corner besides the hull's own (turn 0, the global α).
pub const CUTS: [Cut; 8] = [
    Cut {
        turn: 0.5,
        alpha: None,
    },
    Cut {
        turn: 1.0,
        alpha: None,
    },
    Cut {
        turn: 0.0,
        alpha: Some(0.2),
    },
    Cut {
        turn: 0.0,
        alpha: Some(0.3),
    },
    Cut {
        turn: 0.0,
        alpha: Some(0.75),
    },
    Cut {
        turn: 0.5,
        alpha: Some(0.3),
    },
    Cut {
        turn: 1.0,
        alpha: Some(0.65),
    },
    Cut {
        turn: 1.0,
        alpha: Some(0.75),
    },
];

/// What the search minimises: first the violations of other kinds than overlaps, then all.
fn score(violations: &[HullViolation]) -> (usize, usize) {
    let other = violations
        .iter()
        .filter(|v| v.kind != ViolationKind::Intersecting)
        .count();
    (other, violations.len())
}

/// What [`improve`] found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Search {
    /// The cuts kept, by corner (vertex), sorted.
    pub cuts: Vec<(u32, Cut)>,
    /// Violations of the hull the search started from.
    pub before: usize,
    /// Violations with the kept cuts.
    pub after: usize,
    /// Hull rebuilds made.
    pub trials: usize,
}

/// The greedy search of the module documentation. `violations` are the starting hull's;
/// `build` rebuilds the hull with the given cuts and returns its violations (`None` when that
/// hull cannot be built, which rejects the trial).
pub fn improve<F>(violations: &[HullViolation], build: F) -> Search
where
    F: FnMut(&[(u32, Cut)]) -> Option<Vec<HullViolation>>,
{
    improve_from(&[], &CUTS, violations, build)
}

/// [`improve`] starting from the cuts `start` (whose hull has `violations`): a second pass
/// after other choices changed ([`super::retriangulate`]), trying the cuts `tried`. The result lists `start`'s cuts
/// too, changed or not.
pub fn improve_from<F>(
    start: &[(u32, Cut)],
    tried: &[Cut],
    violations: &[HullViolation],
    mut build: F,
) -> Search
where
    F: FnMut(&[(u32, Cut)]) -> Option<Vec<HullViolation>>,
{
    let mut search = Search {
        before: violations.len(),
        after: violations.len(),
        ..Search::default()
    };
    let mut current = violations.to_vec();
    let mut cuts: Vec<(u32, Cut)> = start.to_vec();
    for _ in 0..MAX_ROUNDS {
        if current.is_empty() {
            break;
        }
        // Corners named by violations, most named first (ties: vertex order).
        let mut named: Vec<u32> = current
            .iter()
            .flat_map(|v| named_elements(&v.message))
            .collect();
        named.sort_unstable();
        let mut order: Vec<(usize, u32)> = Vec::new();
        for &v in &named {
            match order.last_mut() {
                Some((c, w)) if *w == v => *c += 1,
                _ => order.push((1, v)),
            }
        }
        order.sort_by(|x, y| y.0.cmp(&x.0).then(x.1.cmp(&y.1)));
        let mut improved = false;
        for (_, corner) in order {
            let now = cuts.iter().find(|(v, _)| *v == corner).map(|(_, c)| *c);
            let mut best: Option<(Option<Cut>, Vec<HullViolation>)> = None;
            let options = std::iter::once(None).chain(tried.iter().copied().map(Some));
            for alt in options {
                if alt == now || search.trials >= MAX_TRIALS {
                    continue;
                }
                let mut trial = cuts.clone();
                trial.retain(|(v, _)| *v != corner);
                if let Some(c) = alt {
                    trial.push((corner, c));
                }
                search.trials += 1;
                let Some(v) = build(&trial) else { continue };
                let bound = best.as_ref().map_or(score(&current), |(_, w)| score(w));
                if score(&v) < bound {
                    best = Some((alt, v));
                }
            }
            if let Some((alt, v)) = best {
                cuts.retain(|(w, _)| *w != corner);
                if let Some(c) = alt {
                    cuts.push((corner, c));
                }
                current = v;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    cuts.sort_by_key(|(v, _)| *v);
    search.after = current.len();
    search.cuts = cuts;
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

    /// A toy cost: corner k has violations |turn − its best turn| × 4 + (α as wanted ? 0 : 1),
    /// each naming it; corner 9 is never named. The greedy search reaches the cost's minimum
    /// (0, independent truth) with the best cut of [`CUTS`] at each named corner, and leaves
    /// the unnamed corner alone.
    #[test]
    fn greedy_search_finds_each_corners_best_cut() {
        let best = [(0u32, CUTS[1]), (1, CUTS[2]), (2, CUTS[6])];
        let cost = |cuts: &[(u32, Cut)]| -> Vec<HullViolation> {
            let mut out = Vec::new();
            for &(k, want) in &best {
                let c = cuts.iter().find(|(v, _)| *v == k).map_or(
                    Cut {
                        turn: 0.0,
                        alpha: None,
                    },
                    |(_, c)| *c,
                );
                let n = ((c.turn - want.turn).abs() * 4.0).round() as usize
                    + usize::from(c.alpha != want.alpha);
                for _ in 0..n {
                    out.push(violation(&format!("triangle 1 (element {k}) overlaps")));
                }
            }
            out
        };
        let start = cost(&[]);
        assert!(!start.is_empty());
        let mut touched_9 = false;
        let s = improve(&start, |c| {
            touched_9 |= c.iter().any(|(v, _)| *v == 9);
            Some(cost(c))
        });
        assert!(!touched_9);
        assert_eq!(s.before, start.len());
        assert_eq!(s.after, 0);
        assert_eq!(s.cuts, best.to_vec());
        assert!(s.trials <= MAX_TRIALS);
        // Nothing named: nothing tried.
        let s = improve(&[], |_| panic!("no rebuild without violations"));
        assert_eq!((s.trials, s.after), (0, 0));
    }
}
