//! Rows that hold the normal part of a relaxed point's Hessian (`[scheme] hessian_normal`).
//!
//! The jets the scheme starts from make F a signed distance to second order at every point p
//! of T: ∇F = n, ∇²F n = 0. A point whose Hessian is relaxed (the joint stars) has its number 2
//! weights solved closest to the estimate weight by weight, and in a face tetrahedron of height
//! h a change of the normal bend nᵀ∇²F n moves them by only ~h²/20 of it: the solve and the
//! sign fit use that freedom where the tetrahedra are thin. On fandisk it put a normal bend 50×
//! the model's median at two points of T, where the hole repair then found crossed faces it
//! could not mend (docs/quintic.md, session 65). These rows keep that part of the Hessian at
//! the signed distance's zero while its tangent part stays free.
//!
//! At a corner a of a tetrahedron with barycentric gradients ∇λ_i, uᵀ∇²F v = 20 Σ_{i,j≠a}
//! (u·∇λ_i)(v·∇λ_j)(w_{3a+i+j} − w_{4a+i} − w_{4a+j} + w_{5a}): linear in the weights, so a
//! row of the system over the slots of one tetrahedron at p (C2 gives every other tetrahedron
//! at p the same Hessian).

use super::jets::Jet;
use super::system::{Equation, HullTet, System};
use crate::bb::index_of;
use glam::{DMat4, DVec3};

/// Which part of a relaxed point's Hessian H is held (`[scheme] hessian_normal`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HessianNormal {
    /// Nothing held: every relaxed Hessian weight free, closest to its estimate (`"free"`, the
    /// default; the solve before session 66, bit for bit).
    #[default]
    Free,
    /// nᵀH n = 0 (`"bend"`): one row per point.
    Bend,
    /// H n = 0 (`"column"`): three rows per point, the tangent part of H alone free.
    Column,
}

impl HessianNormal {
    /// The scene key's names, in the order the error message lists them.
    pub const NAMES: [&'static str; 3] = ["free", "bend", "column"];

    /// The mode a scene key's value names, `None` for any other string.
    #[must_use]
    pub fn named(name: &str) -> Option<HessianNormal> {
        let modes = [Self::Free, Self::Bend, Self::Column];
        Self::NAMES
            .iter()
            .position(|&n| n == name)
            .map(|at| modes[at])
    }

    /// The directions u whose uᵀH n this mode holds at 0, for the unit normal `n`: none,
    /// n alone, or n and two tangents.
    #[must_use]
    pub fn directions(self, n: DVec3) -> Vec<DVec3> {
        match self {
            Self::Free => Vec::new(),
            Self::Bend => vec![n],
            Self::Column => {
                let (t1, t2) = n.any_orthonormal_pair();
                vec![n, t1, t2]
            }
        }
    }
}

/// The points of T where the model is flat to `degrees` (`[scheme] hessian_column_flat`): the
/// normal of every point of T that shares a tetrahedron with it lies within `degrees` of its
/// own (`normals`: one per point of T, any length). Sorted.
///
/// There F should be the plane's signed distance, whose Hessian is 0: the whole column H n is
/// held at these points. fandisk's crossed faces that no repair mends sit where the joint stars
/// gave the Hessian its largest mixed part P H n (5.4e4 against a median of 113), and those
/// points are flat to under 1° (session 69); held at every point flat to 0.5° the sign fit
/// leaves 305 weights off instead of 576, and the repair starts from fewer defects.
#[must_use]
pub fn flat_points(tets: &[HullTet], normals: &[DVec3], degrees: f64) -> Vec<u32> {
    let np = normals.len();
    let unit: Vec<DVec3> = normals.iter().map(|n| n.normalize_or_zero()).collect();
    // The largest angle from each point's normal to a neighbour's.
    let mut spread = vec![0.0_f64; np];
    for tet in tets {
        for &p in tet.gid.iter().filter(|&&g| (g as usize) < np) {
            for &q in tet.gid.iter().filter(|&&g| (g as usize) < np && g != p) {
                let cos = unit[p as usize].dot(unit[q as usize]).clamp(-1.0, 1.0);
                let angle = cos.acos().to_degrees();
                let s = &mut spread[p as usize];
                if angle > *s || angle.is_nan() {
                    *s = angle;
                }
            }
        }
    }
    (0..np as u32)
        .filter(|&p| spread[p as usize] < degrees)
        .collect()
}

/// The points of T whose whole column H n is held (exploration, `APATCH_HESSIAN_COLUMN_AT`:
/// comma-separated indices of the complex's vertices, e.g. those `scripts/normal_curvature.py`
/// ranks first by the mixed part), sorted; indices past the `np` points are reported and
/// skipped.
#[must_use]
pub fn column_points_from_env(np: u32) -> Vec<u32> {
    std::env::var("APATCH_HESSIAN_COLUMN_AT").map_or_else(|_| Vec::new(), |v| column_points(&v, np))
}

/// The points of T a comma-separated list names, sorted and without repeats; an entry that
/// is not an index below `np` is reported on stderr and skipped.
fn column_points(list: &str, np: u32) -> Vec<u32> {
    let mut points: Vec<u32> = list
        .split(',')
        .map(str::trim)
        .filter(|v| !v.is_empty())
        .filter_map(|v| match v.parse::<u32>() {
            Ok(p) if p < np => Some(p),
            _ => {
                eprintln!("APATCH_HESSIAN_COLUMN_AT: `{v}` is not a point of T (0..{np}); skipped");
                None
            }
        })
        .collect();
    points.sort_unstable();
    points.dedup();
    points
}

/// ∇λ_i of the tetrahedron's barycentric coordinates; `None` for a flat tetrahedron.
#[must_use]
pub fn barycentric_gradients(pts: &[DVec3; 4]) -> Option<[DVec3; 4]> {
    let m = DMat4::from_cols(
        pts[0].extend(1.0),
        pts[1].extend(1.0),
        pts[2].extend(1.0),
        pts[3].extend(1.0),
    );
    if m.determinant().abs() <= f64::MIN_POSITIVE {
        return None;
    }
    // λ = M⁻¹ (x, 1): ∇λ_i is row i of M⁻¹ without its last entry.
    let inv = m.inverse().transpose();
    Some([0, 1, 2, 3].map(|i| inv.col(i).truncate()))
}

/// The coefficients of uᵀ∇²F v at corner `at` of the tetrahedron `pts`, by multi-index of its
/// quintic's weights; `None` for a flat tetrahedron.
#[must_use]
pub fn second_derivative_row(
    pts: &[DVec3; 4],
    at: usize,
    u: DVec3,
    v: DVec3,
) -> Option<Vec<([u8; 4], f64)>> {
    let grads = barycentric_gradients(pts)?;
    let grad = |i: usize| grads[i];
    let index = |extra: &[usize]| {
        let mut l = [0u8; 4];
        l[at] = 5 - extra.len() as u8;
        for &i in extra {
            l[i] += 1;
        }
        l
    };
    let mut terms: Vec<([u8; 4], f64)> = Vec::new();
    let mut add = |l: [u8; 4], k: f64| match terms.iter_mut().find(|t| t.0 == l) {
        Some(t) => t.1 += k,
        None => terms.push((l, k)),
    };
    for i in (0..4).filter(|&i| i != at) {
        for j in (0..4).filter(|&j| j != at) {
            let k = 20.0 * u.dot(grad(i)) * v.dot(grad(j));
            add(index(&[i, j]), k);
            add(index(&[i]), -k);
            add(index(&[j]), -k);
            add(index(&[]), k);
        }
    }
    terms.retain(|t| t.1 != 0.0);
    Some(terms)
}

/// The rows [`System::hessian_normal_at`] asks at every point of T (none where it is
/// [`HessianNormal::Free`]), each over the slots of the tetrahedron at the point that reaches
/// farthest along its normal (the smallest coefficients). A point whose Hessian is not relaxed
/// has every slot of its rows known, and the estimate meets them.
#[must_use]
pub(super) fn rows(sys: &System, tets: &[HullTet], jets: &[Jet]) -> Vec<Equation> {
    if sys.hessian_normal == HessianNormal::Free && sys.column_points.is_empty() {
        return Vec::new();
    }
    let np = sys.np as usize;
    // Per point: (largest |coefficient| of its nᵀ∇²F n row there, tetrahedron, corner).
    let mut best: Vec<Option<(f64, usize, usize)>> = vec![None; np];
    for (t, tet) in tets.iter().enumerate() {
        for at in 0..4 {
            let p = tet.gid[at] as usize;
            if p >= np {
                continue;
            }
            let Some(row) = second_derivative_row(&tet.pts, at, jets[p].g, jets[p].g) else {
                continue;
            };
            let size = row.iter().fold(0.0_f64, |a, t| a.max(t.1.abs()));
            if best[p].is_none_or(|b| size < b.0) {
                best[p] = Some((size, t, at));
            }
        }
    }
    let mut out = Vec::new();
    for (p, b) in best.iter().enumerate() {
        let Some((_, t, at)) = *b else { continue };
        let n = jets[p].g.normalize_or_zero();
        if n == DVec3::ZERO {
            continue;
        }
        let tet = &tets[t];
        for u in sys.hessian_normal_at(p as u32).directions(n) {
            let Some(row) = second_derivative_row(&tet.pts, at, u, n) else {
                continue;
            };
            // In the weights' units (largest coefficient 1): the row's right-hand side, formed
            // from the known weights, is then of their size and does not set the group's scale.
            let size = row.iter().fold(0.0_f64, |a, t| a.max(t.1.abs()));
            let terms = row
                .into_iter()
                .map(|(l, k)| (sys.slot_of[t][index_of(l)], k / size))
                .collect();
            out.push(Equation { terms });
        }
    }
    out
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::bb::multi_indices;
    use glam::DMat3;

    /// A skewed tetrahedron (edges ~1) and a 2-jet (gradient, symmetric Hessian) of no special
    /// form, for the corner formulas' tests here and in [`super::super::holes`].
    pub(in crate::scheme::quintic_c2) fn skewed_jet() -> ([DVec3; 4], DVec3, DMat3) {
        let pts = [
            DVec3::new(0.1, -0.2, 0.05),
            DVec3::new(1.3, 0.1, -0.2),
            DVec3::new(0.2, 0.9, 0.3),
            DVec3::new(0.4, 0.3, 0.02),
        ];
        let g = DVec3::new(0.3, -0.8, 0.5);
        let h = DMat3::from_cols(
            DVec3::new(2.0, -0.7, 0.4),
            DVec3::new(-0.7, -1.5, 3.0),
            DVec3::new(0.4, 3.0, 0.25),
        );
        (pts, g, h)
    }

    /// A flat point is one whose neighbours (points of T sharing a tetrahedron) all have
    /// normals within the angle of its own; apexes (ids past the normals) are not points of T.
    /// Points 0–2 with normal z (point 1's not of unit length), point 3's tilted 0.3° about x,
    /// point 4's 2°; tetrahedra [0 1 2 a], [0 1 3 a], [1 2 4 a] (apex a = 5). Largest angle to
    /// a neighbour: 0 → 0.3° (1, 2, 3), 1 → 2° (0, 2, 3, 4), 2 → 2° (0, 1, 4), 3 → 0.3°
    /// (0, 1), 4 → 2° (1, 2).
    #[test]
    fn flat_points_are_those_whose_neighbours_normals_agree() {
        use crate::complex::Role;
        use crate::hull::simplicial::Side;
        let tilt = |deg: f64| {
            let r = deg.to_radians();
            DVec3::new(0.0, -r.sin(), r.cos())
        };
        let normals = [DVec3::Z, DVec3::Z * 2.0, DVec3::Z, tilt(0.3), tilt(2.0)];
        let tet = |gid: [u32; 4]| HullTet {
            gid,
            pts: [DVec3::ZERO; 4],
            role: Role::Face,
            element: 0,
            triangle: 0,
            side: Side::Outer,
        };
        let tets = [tet([0, 1, 2, 5]), tet([0, 1, 3, 5]), tet([1, 2, 4, 5])];
        assert_eq!(flat_points(&tets, &normals, 0.5), vec![0, 3]);
        // 0.3° apart is flat at 0.31°, not at 0.29°; 2° takes in 1, 2 and 4 at 2.1°.
        assert_eq!(flat_points(&tets, &normals, 0.31), vec![0, 3]);
        assert_eq!(flat_points(&tets, &normals, 0.29), Vec::<u32>::new());
        assert_eq!(flat_points(&tets, &normals, 2.1), vec![0, 1, 2, 3, 4]);
    }

    /// The row gives uᵀ∇²F v of the quintic made from a 2-jet's Taylor polynomial
    /// ([`Jet::blossom5`]), at every corner of a skewed tetrahedron, for three pairs (u, v).
    #[test]
    fn the_row_gives_the_second_derivative_of_a_taylor_quintic() {
        let (pts, g, h) = skewed_jet();
        let pairs = [
            (DVec3::X, DVec3::X),
            (DVec3::new(0.6, 0.0, 0.8), DVec3::new(0.0, 1.0, 0.0)),
            (DVec3::new(-0.3, 0.5, 0.2), DVec3::new(0.7, 0.1, -0.4)),
        ];
        for at in 0..4 {
            let jet = Jet { p: pts[at], g, h };
            let weights: Vec<f64> = multi_indices(5)
                .iter()
                .map(|&l| jet.blossom5(&super::super::jets::domain_args(&pts, l)))
                .collect();
            for (u, v) in pairs {
                let row = second_derivative_row(&pts, at, u, v).expect("a solid tetrahedron");
                let got: f64 = row.iter().map(|(l, k)| k * weights[index_of(*l)]).sum();
                let want = u.dot(h * v);
                // The weights are O(1) and the row's coefficients O(20/height²) ~ 1e3 over 10
                // terms: f64 rounding of ~1e3 × 1e-16 × 10, with room.
                assert!(
                    (got - want).abs() <= 1e-10 * want.abs().max(1.0),
                    "corner {at}: {got} vs {want}"
                );
            }
        }
    }

    /// `APATCH_HESSIAN_COLUMN_AT`'s list: sorted, repeats and entries that are not points of T
    /// dropped.
    #[test]
    fn column_points_are_read_sorted_and_checked() {
        assert_eq!(column_points("9, 3,9,,12", 10), vec![3, 9]);
        assert_eq!(column_points("x,-1,2", 10), vec![2]);
        assert!(column_points("", 10).is_empty());
    }

    /// A flat tetrahedron has no row.
    #[test]
    fn a_flat_tetrahedron_has_no_row() {
        let pts = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        assert!(second_derivative_row(&pts, 0, DVec3::Z, DVec3::Z).is_none());
    }
}
