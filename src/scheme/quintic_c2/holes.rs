//! Local repair of holes, boundary faces of the hull that the solved surface crosses, and of
//! j-sheets, patches it crosses twice along a j-line (`QuinticOptions::repair_holes`).
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
//!
//! A j-sheet is repaired the same way with every signed weight of the patch lifted to its
//! sign (Theorem 2.1: then every j-line crosses once), judged by [`j_sheeted`] on the
//! checker's j-lines. A boundary face or j-patch of the re-solved tetrahedra that a solution
//! turns defective joins the defect (its weights are lifted too, and the group solved again)
//! instead of refusing the repair at once.

use super::checkpoint;
use super::pinned::PinnedSolves;
use super::system::{HullTet, System};
use super::{cholesky, dense};
use crate::bb::{multi_indices, poly};
use crate::check::sheets::{roots_beyond_one, simplex_lattice, zero_face_turns};
use crate::complex::Role;
use crate::error::Result;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::OnceLock;

/// What [`repair`] did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
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
    /// Of the repairs kept, those of the two last passes (`repair_hessians = true`), with the
    /// Hessians of the jets free ([`Reach::hessians`]); 0 when every pass frees them
    /// (`repair_hessians = "all"`).
    pub hessian: usize,
    /// Patches crossed twice along a j-line ([`j_sheeted`]) after the solve.
    pub sheets_before: usize,
    /// Of those, patches whose repair was kept.
    pub sheets_repaired: usize,
    /// Patches crossed twice along a j-line after the repairs.
    pub sheets_after: usize,
}

/// What one repair mends: a crossed boundary face (tetrahedron, local opposite vertex), or a
/// patch crossed twice along one of its j-lines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Defect {
    Face(u32, usize),
    Sheet(u32),
}

impl Defect {
    /// The defect's tetrahedron and the local vertex its face leaves out (4 for a j-sheet:
    /// the whole patch, no vertex left out).
    fn at(self) -> (u32, usize) {
        match self {
            Defect::Face(t, opp) => (t, opp),
            Defect::Sheet(t) => (t, 4),
        }
    }

    /// Whether the defect is there with `weights`, its tetrahedron's, of role `role`.
    fn open_in(self, weights: &[f64], role: Role) -> bool {
        match self {
            Defect::Face(_, opp) => crossed(weights, opp),
            Defect::Sheet(_) => j_sheeted(weights, role),
        }
    }
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
    /// Also re-solve the Hessians of those points' jets (their number 2 weights, moving as
    /// one symmetric matrix each; the values and normals held).
    pub hessians: bool,
}

/// What a [`repair`] is asked to do.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The first pass's reach.
    pub reach: Reach,
    /// Passes with one more ring each after the first ([`WIDEN`]).
    pub widen: usize,
    /// Two last passes with the Hessians free, unless `reach` frees them already.
    pub hessian_passes: bool,
    /// The pins a crossed face is tried with, in turn ([`pin_modes`]).
    pub pins: Vec<Option<(usize, f64)>>,
}

/// |F| at or below this share of the patch's largest weight is zero (the checker's threshold).
const ZERO: f64 = 1e-12;
/// Pinned weights are set to this share of the largest weight on their face, with their sign:
/// clearly signed (far above the solves' rounding), small against the face's data.
const MARGIN: f64 = 1e-3;
/// A re-solved unknown's coefficient at most this share of its equation's largest is left
/// out of the repair's rows: it is the rounding of an exact zero (a point of the hull on a
/// plane or line of others). Kept, such terms turn exact dependencies among the rows into near
/// ones, which the factor of Â Âᵀ cannot tell apart: it drops some of them and the move then
/// misses them. On spot's Face(150, 0) group (8311 rows) 5517 terms lay below 1e-13 of their
/// row's largest and none between 1e-13 and 1e-9; with them the pinned solve missed dropped
/// rows by 2.7e-4 of the data's 1.5e-2, without them by 6e-13. The held terms stay on the
/// right-hand side, and the per-equation guard judges the repair on the equations as given.
const NOISE: f64 = 1e-13;
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
/// The heaviest weight of pins met only as targets: where the weighted solve leaves the
/// defect, the weight grows tenfold up to this ([`soft_max`]).
const SOFT_MAX: f64 = 1e4;

/// Whether the last two passes free the Hessians: `asked` (the scene's
/// `repair_hessians`) unless `APATCH_HOLE_HESSIAN_PASSES=0` (exploration, to compare).
fn hessian_passes(asked: bool) -> bool {
    asked && std::env::var("APATCH_HOLE_HESSIAN_PASSES").map_or(true, |v| v != "0")
}

/// Exploration: with `APATCH_HOLE_ONLY=t1,t2,…` only the defects of those tetrahedra are
/// repaired (to study one refusal in a large model without waiting for the others).
fn only_tets() -> Option<HashSet<u32>> {
    let v = std::env::var("APATCH_HOLE_ONLY").ok()?;
    Some(v.split(',').filter_map(|x| x.trim().parse().ok()).collect())
}

/// The pins a crossed face is tried with, in turn, until one mends it
/// (`QuinticOptions::repair_elevate`, `repair_margins`): `None` the weights' own pins,
/// `Some((r, m))` the coefficients of its polynomial elevated by `r` degrees, signed with the
/// margin `m` (a share of the weights' [`MARGIN`]). Elevation 0: the weights' pins alone.
#[must_use]
pub fn pin_modes(elevate: usize, margins: &[Option<f64>]) -> Vec<Option<(usize, f64)>> {
    if elevate == 0 || margins.is_empty() {
        return vec![None];
    }
    margins.iter().map(|m| m.map(|m| (elevate, m))).collect()
}

/// Exploration overrides of the scene's pins (`asked`, [`pin_modes`]):
/// `APATCH_HOLE_ELEVATE=r` with the margins `APATCH_HOLE_ELEVATE_MARGIN` (a comma list, `w`
/// standing for the weights' own pins: `w,1,1e-2,0`; 0 alone by default), as before the scene
/// keys existed.
fn elevated_modes(asked: &[Option<(usize, f64)>]) -> Vec<Option<(usize, f64)>> {
    let Some(r) = std::env::var("APATCH_HOLE_ELEVATE")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&r| r > 0)
    else {
        return asked.to_vec();
    };
    let list = std::env::var("APATCH_HOLE_ELEVATE_MARGIN").unwrap_or_else(|_| "0".into());
    let modes: Vec<Option<f64>> = list
        .split(',')
        .filter_map(|m| match m.trim() {
            "w" => Some(None),
            m => m.parse::<f64>().ok().map(Some),
        })
        .collect();
    if modes.is_empty() {
        pin_modes(r, &[Some(0.0)])
    } else {
        pin_modes(r, &modes)
    }
}

/// One coefficient of a face's elevation: its indices of degree 5 + r and its terms (position
/// in the face's coefficients, factor).
type ElevatedRow = ([usize; 3], Vec<(usize, f64)>);

/// The degree elevation by `r` of a quintic on a triangle: for each coefficient of degree
/// 5 + r, its indices `b` and its terms over the quintic's coefficients `face` (positions in
/// `face`, factor): c_b = Σ_a C(5; a) C(r; b − a) / C(5 + r; b) w_a, a convex combination. Elevated
/// coefficients converge to the polynomial's values, so their signs are a weaker sufficient
/// condition for one sign on the face than the weights' own.
fn elevation(face: &[[u8; 3]], r: usize) -> Vec<ElevatedRow> {
    let fact = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
    let multi = |n: usize, a: [usize; 3]| fact(n) / (fact(a[0]) * fact(a[1]) * fact(a[2]));
    let d = 5 + r;
    let mut out = Vec::new();
    for b0 in 0..=d {
        for b1 in 0..=d - b0 {
            let b = [b0, b1, d - b0 - b1];
            let total = multi(d, b);
            let row: Vec<(usize, f64)> = face
                .iter()
                .enumerate()
                .filter_map(|(i, a)| {
                    let a = a.map(usize::from);
                    (0..3).all(|k| a[k] <= b[k]).then(|| {
                        let rest = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                        (i, multi(5, a) * multi(r, rest) / total)
                    })
                })
                .collect();
            out.push((b, row));
        }
    }
    out
}

/// The weights of a tetrahedron on its face opposite local vertex `opp`: (index into `mi`, the
/// multi-index over the face's three corners in local order).
fn face_indices(mi: &[[u8; 4]], opp: usize) -> impl Iterator<Item = (usize, [u8; 3])> + '_ {
    mi.iter()
        .enumerate()
        .filter(move |(_, l)| l[opp] == 0)
        .map(move |(i, l)| {
            let mut a = [0u8; 3];
            for (c, v) in (0..4).filter(|&v| v != opp).enumerate() {
                a[c] = l[v];
            }
            (i, a)
        })
}

/// Whether the elevated mode elevates the crossed face only, the other faces in reach watched
/// only by whether they turn (the default), or every boundary face in reach with its signs
/// watched (`APATCH_HOLE_ELEVATE_SCOPE=all`, session 52's first form): on letter_P_poly
/// without `hessian_signs` the first passes `check` in 3.5 user s, the second leaves 2
/// j-sheets in 51 s.
fn defect_scope() -> bool {
    std::env::var("APATCH_HOLE_ELEVATE_SCOPE").map_or(true, |v| v != "all")
}

/// The heaviest weight the escalation reaches: [`SOFT_MAX`], or `APATCH_HOLE_SOFT_MAX`
/// (exploration; 0 turns the escalation off, to compare).
fn soft_max() -> f64 {
    std::env::var("APATCH_HOLE_SOFT_MAX")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(SOFT_MAX)
}
/// The least time between two checkpoints within a pass ([`checkpoint`]): writing fandisk's
/// 40 MB of values takes under a second, a wave of its repairs minutes.
const CHECKPOINT_EVERY: std::time::Duration = std::time::Duration::from_secs(120);
/// Lattice steps per edge at which [`j_sheeted`] draws j-lines: twice the checker's 5
/// (`CheckOptions::sheet_resolution`), so its lines are among them.
const SHEET_RES: usize = 10;
/// Samples per j-line where Descartes' rule does not decide (the checker's `line_samples`).
const LINE_SAMPLES: usize = 48;
/// Solves per defect (each pins the conditions the previous solution newly misses, or lifts
/// the weights of faces and j-patches it turned defective): on the nut 8 left 47 defects at
/// the bound, 24 none (holes 57 → 45, j-sheets 23 → 16).
const ROUNDS: usize = 24;
/// A repair may not grow any re-solved weight beyond this multiple of the largest before.
const GROWTH: f64 = 2.0;
/// A re-solved group is consistent when its residual is at most this share of its data (the
/// staged solve's standard, `system::consistent`).
pub(super) const CONSISTENT: f64 = 1e-9;
/// The same for a solve with weighted pins ([`solve_soft`]), whose group is consistent by
/// construction: looser, as the per-equation residual guard after the solve still holds every
/// re-solved equation to the staged solve's standard (on the bunny a weighted group missed
/// 1e-9 of its data by rounding: 2.9e-9 of 0.42).
pub(super) const SOFT_CONSISTENT: f64 = 1e-7;

/// The boundary faces of the hull: (tetrahedron, local opposite vertex) of every face that
/// belongs to one tetrahedron only, in tetrahedron order.
#[must_use]
pub fn boundary_faces(tets: &[HullTet]) -> Vec<(u32, usize)> {
    boundary_in(tets, &face_users(tets))
}

/// The face of `t` opposite its local vertex `opp`, as its sorted global vertex ids.
fn tet_face(t: &HullTet, opp: usize) -> [u32; 3] {
    let mut f = [0u32; 3];
    for (c, k) in (0..4).filter(|&k| k != opp).enumerate() {
        f[c] = t.gid[k];
    }
    f.sort_unstable();
    f
}

/// The tetrahedra of `tets` that have each face.
fn face_users(tets: &[HullTet]) -> HashMap<[u32; 3], Vec<u32>> {
    let mut users: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for (k, t) in tets.iter().enumerate() {
        for opp in 0..4 {
            users.entry(tet_face(t, opp)).or_default().push(k as u32);
        }
    }
    users
}

/// [`boundary_faces`] with the faces' `users` ([`face_users`]) at hand.
fn boundary_in(tets: &[HullTet], users: &HashMap<[u32; 3], Vec<u32>>) -> Vec<(u32, usize)> {
    let mut out = Vec::new();
    for (k, t) in tets.iter().enumerate() {
        for opp in 0..4 {
            if users[&tet_face(t, opp)].len() == 1 {
                out.push((k as u32, opp));
            }
        }
    }
    out
}

/// Whether F with the 56 `weights` takes both strict signs on the face opposite local vertex
/// `opp`, judged as `apatch check` judges its "holes" (coefficients, lattice, subdivision:
/// [`crate::check::holes::polynomial_face_crossed`]). A 30-step lattice, used before, missed the
/// bunny's last crossed face (a pocket 2.4e-6 deep between its points).
#[must_use]
pub fn crossed(weights: &[f64], opp: usize) -> bool {
    crate::check::holes::polynomial_face_crossed(5, weights, opp)
}

/// Whether F with the 56 `weights` of a tetrahedron of `role` meets zero more than once along
/// a j-line: from the apex (local vertex 3) of a face tetrahedron through its base, or from
/// the edge of T (local 0–1) of an edge tetrahedron to the opposite edge, judged as
/// `apatch check` judges them ([`SHEET_RES`] lattice). Other roles promise no j-lines.
#[must_use]
pub fn j_sheeted(weights: &[f64], role: Role) -> bool {
    let (from, to) = match role {
        Role::Face => (
            simplex_lattice(&[3], SHEET_RES),
            simplex_lattice(&[0, 1, 2], SHEET_RES),
        ),
        Role::Edge => (
            simplex_lattice(&[0, 1], SHEET_RES),
            simplex_lattice(&[2, 3], SHEET_RES),
        ),
        _ => return false,
    };
    if weights.iter().all(|&w| w >= 0.0) || weights.iter().all(|&w| w <= 0.0) {
        return false;
    }
    if role == Role::Face && zero_face_turns(5, weights, 3) {
        return true;
    }
    from.iter().any(|a| {
        to.iter().any(|b| {
            let mut c = [0.0; 16];
            let len = poly::restrict(5, weights, *a, *b, &mut c);
            roots_beyond_one(c, len, LINE_SAMPLES).is_some()
        })
    })
}

/// Repairs the crossed boundary faces of the solved `value` (slots of `sys`) in place, one at
/// a time in tetrahedron order (see the module documentation). With `checkpoint`, the
/// progress is saved there as it goes and taken up again from there ([`checkpoint`]).
///
/// # Errors
/// The checkpoint's: it cannot be read or written, or it is another repair's.
pub fn repair(
    sys: &System,
    tets: &[HullTet],
    value: &mut [f64],
    plan: &Plan,
    checkpoint: Option<&Path>,
) -> Result<HoleRepair> {
    let Plan {
        reach,
        widen,
        hessian_passes: hessian_passes_asked,
        ref pins,
    } = *plan;
    let np = sys.np;
    let users = face_users(tets);
    let boundary = boundary_in(tets, &users);
    let weights = |t: u32, value: &[f64]| -> Vec<f64> { sys.weights(t as usize, value) };
    let is_crossed = |&(t, opp): &(u32, usize), value: &[f64]| crossed(&weights(t, value), opp);
    let holes: Vec<(u32, usize)> = boundary
        .iter()
        .copied()
        .filter(|f| is_crossed(f, value))
        .collect();
    let is_sheet = |t: u32, value: &[f64]| j_sheeted(&weights(t, value), tets[t as usize].role);
    let sheets: Vec<u32> = (0..tets.len() as u32)
        .filter(|&t| is_sheet(t, value))
        .collect();
    let mut out = HoleRepair {
        crossed_before: holes.len(),
        sheets_before: sheets.len(),
        ..HoleRepair::default()
    };
    if holes.is_empty() && sheets.is_empty() {
        return Ok(out);
    }
    let is_open = |d: Defect, value: &[f64]| {
        let t = d.at().0;
        d.open_in(&weights(t, value), tets[t as usize].role)
    };
    let defects: Vec<Defect> = holes
        .iter()
        .map(|&(t, opp)| Defect::Face(t, opp))
        .chain(sheets.iter().map(|&t| Defect::Sheet(t)))
        .collect();
    // Equations are judged relative to the size of F, as the checker does: the largest weight
    // of the solve (the repairs are small against it).
    let wmax = value.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
    // Taken up again from a checkpoint: its values, its pass and the defects it decided.
    // Passes: the asked reach, `widen` wider ones ([`WIDEN`] by default), then (the scene's
    // `repair_hessians`, [`hessian_passes`]) the asked reach and one ring more with the
    // Hessians free for what is left (a base face of a face tetrahedron holds no late weight:
    // its weights are jets and stars), unless the asked reach frees them already
    // (`repair_hessians = "all"`).
    let asked = reach;
    let passes: Vec<Reach> = (0..=widen)
        .map(|extra| Reach {
            rings: asked.rings + extra,
            ..asked
        })
        .chain(
            (0..2)
                .filter(|_| hessian_passes(hessian_passes_asked) && !asked.hessians)
                .map(|extra| Reach {
                    rings: asked.rings + extra,
                    hessians: true,
                    ..asked
                }),
        )
        .collect();
    let plan: Vec<(usize, bool)> = passes.iter().map(|r| (r.rings, r.hessians)).collect();
    let fingerprint = checkpoint::fingerprint(defects.iter().map(|d| d.at()));
    let mut start_pass = 0;
    let mut decided: Vec<u32> = Vec::new();
    if let Some(path) = checkpoint {
        if let Some(p) = checkpoint::load(path, value.len(), fingerprint)? {
            checkpoint::check_plan(path, &p, &plan)?;
            value.copy_from_slice(&p.value);
            start_pass = p.pass;
            decided = p.decided;
            out = HoleRepair {
                crossed_before: out.crossed_before,
                sheets_before: out.sheets_before,
                ..p.counts
            };
            trace(|| {
                format!(
                    "taken up from {} at pass {} ({} defects decided)",
                    path.display(),
                    start_pass + 1,
                    decided.len()
                )
            });
        }
    }
    let mut saved_at = std::time::Instant::now();
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
    let across = neighbours(tets, &users);
    drop(users);
    let mi = multi_indices(5);
    let only = only_tets();
    let modes = elevated_modes(pins);
    let stop_after = checkpoint::stop_after();
    let (every, exit_after) = checkpoint::midway_hooks(CHECKPOINT_EVERY);
    let mut waves_run = 0usize;
    'passes: for (pass_no, &reach) in passes.iter().enumerate() {
        if stop_after == Some(0) {
            trace(|| "stopped before the first wave".to_string());
            break;
        }
        if pass_no < start_pass {
            continue;
        }
        if pass_no > start_pass {
            decided.clear();
        }
        let skip: HashSet<u32> = decided.iter().copied().collect();
        // A decided repair into the values and the counts (nothing if it was refused).
        let apply = |l: &Local, k: Option<&Repaired>, value: &mut [f64], out: &mut HoleRepair| {
            let Some((x, pinned, soft)) = k else {
                return;
            };
            for (&s, &v) in l.unk.iter().zip(x) {
                value[s as usize] = v;
            }
            match l.defect {
                Defect::Face(..) => out.repaired += 1,
                Defect::Sheet(_) => out.sheets_repaired += 1,
            }
            out.pinned += pinned;
            out.widened += usize::from(reach.rings > asked.rings);
            out.hessian += usize::from(reach.hessians && !asked.hessians);
            out.soft += usize::from(*soft);
        };
        let progress = |pass, decided, counts, value| checkpoint::Progress {
            defects: fingerprint,
            pass,
            plan: plan.clone(),
            decided,
            counts,
            value,
        };
        let index = Index {
            tets_of: &tets_of,
            faces_of: &faces_of,
            eqs_of: &eqs_of,
            mi: &mi,
            wmax,
            across: &across,
        };
        // The defects still open (earlier passes repaired some), with their neighbourhoods.
        let (ids, open): (Vec<u32>, Vec<Local>) = defects
            .par_iter()
            .enumerate()
            .filter(|&(k, _)| !skip.contains(&(k as u32)))
            .filter(|&(_, &d)| only.as_ref().is_none_or(|o| o.contains(&d.at().0)))
            .filter(|&(_, &d)| is_open(d, value))
            .filter_map(|(k, &d)| Some((k as u32, neighbourhood(sys, tets, d, &index, reach)?)))
            .unzip();
        let pass = || {
            format!(
                "{} defects open ({} rings{})",
                open.len(),
                reach.rings,
                if reach.hessians {
                    ", Hessians free"
                } else {
                    ""
                }
            )
        };
        crate::progress::report(|| format!("quintic-c2 hole repair: {}", pass()));
        trace(pass);
        let reads: Vec<Vec<u32>> = open.par_iter().map(|l| l.reads(sys)).collect();
        // Waves: in defect order, a defect joins the wave unless it writes what a defect
        // before it (in the wave, or left for a later wave) reads, or reads what one writes.
        // Members of a wave touch nothing of each other's, and every defect still comes after
        // each earlier one it touches, so the waves give the one-by-one result, bit for bit,
        // on any number of threads.
        let mut left: Vec<usize> = (0..open.len()).collect();
        let mut read_mark = vec![false; sys.keys.len()];
        let mut write_mark = vec![false; sys.keys.len()];
        while !left.is_empty() {
            let mut wave = Vec::new();
            let mut later = Vec::new();
            for &i in &left {
                let l = &open[i];
                let clash = l.unk.iter().any(|&s| read_mark[s as usize])
                    || reads[i].iter().any(|&s| write_mark[s as usize]);
                if !clash {
                    wave.push(i);
                } else {
                    later.push(i);
                }
                for &s in &reads[i] {
                    read_mark[s as usize] = true;
                }
                for &s in &l.unk {
                    write_mark[s as usize] = true;
                }
            }
            for &i in &left {
                reads[i].iter().for_each(|&s| read_mark[s as usize] = false);
                open[i]
                    .unk
                    .iter()
                    .for_each(|&s| write_mark[s as usize] = false);
            }
            let snapshot: &[f64] = value;
            // A wave can take an hour on fandisk: its finished repairs are saved as they come
            // (they touch nothing of each other's, so any of them applied to the snapshot is
            // what the wave's end gives for them).
            let midway = std::sync::Mutex::new(Midway {
                done: Vec::new(),
                saved_at,
                error: None,
            });
            let kept: Vec<Option<Repaired>> = wave
                .par_iter()
                .map(|&i| {
                    // Repaired with an earlier defect.
                    let k = is_open(open[i].defect, snapshot)
                        .then(|| {
                            // A j-sheet's pins are the weights' in every mode: one try.
                            let tries = match open[i].defect {
                                Defect::Face(..) => modes.len(),
                                Defect::Sheet(_) => 1,
                            };
                            // The elevated modes (one elevation, only their margins differ)
                            // build the same group, so they share its factor: fandisk's take
                            // 70 s in double-double. The weights' pins have their own group.
                            let (weights_factor, elevated_factor) = (Factor::new(), Factor::new());
                            modes[..tries].iter().find_map(|&mode| {
                                let attempt = Attempt {
                                    mode,
                                    sparse: if mode.is_some() {
                                        &elevated_factor
                                    } else {
                                        &weights_factor
                                    },
                                };
                                repair_defect(sys, tets, snapshot, &open[i], &index, reach, attempt)
                            })
                        })
                        .flatten();
                    if let Some(path) = checkpoint {
                        let mut m = midway
                            .lock()
                            .unwrap_or_else(std::sync::PoisonError::into_inner);
                        m.done.push((i, k.clone()));
                        if m.error.is_none() && m.saved_at.elapsed() >= every {
                            let mut v = snapshot.to_vec();
                            let mut counts = out.clone();
                            for (j, k) in &m.done {
                                apply(&open[*j], k.as_ref(), &mut v, &mut counts);
                            }
                            let mut d = decided.clone();
                            d.extend(m.done.iter().map(|(j, _)| ids[*j]));
                            match checkpoint::save(path, &progress(pass_no, d, counts, v)) {
                                Ok(()) => m.saved_at = std::time::Instant::now(),
                                Err(e) => m.error = Some(e),
                            }
                            if exit_after.is_some_and(|n| m.done.len() >= n) {
                                // Test hook: the process killed midway through a wave.
                                std::process::exit(3);
                            }
                        }
                    }
                    k
                })
                .collect();
            let midway = midway
                .into_inner()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            if let Some(e) = midway.error {
                return Err(e);
            }
            saved_at = midway.saved_at;
            for (&i, k) in wave.iter().zip(kept) {
                apply(&open[i], k.as_ref(), value, &mut out);
            }
            decided.extend(wave.iter().map(|&i| ids[i]));
            left = later;
            waves_run += 1;
            let stop = stop_after.is_some_and(|n| waves_run >= n);
            if let Some(path) = checkpoint {
                // Every few minutes, and at a pass's end (then as the next pass, none decided).
                let pass_done = left.is_empty();
                if pass_done || stop || saved_at.elapsed() >= every {
                    let d = if pass_done {
                        Vec::new()
                    } else {
                        decided.clone()
                    };
                    let next = pass_no + usize::from(pass_done);
                    checkpoint::save(path, &progress(next, d, out.clone(), value.to_vec()))?;
                    saved_at = std::time::Instant::now();
                }
            }
            if stop {
                trace(|| format!("stopped after {waves_run} waves"));
                break 'passes;
            }
        }
    }
    out.crossed_after = boundary.iter().filter(|f| is_crossed(f, value)).count();
    out.sheets_after = (0..tets.len() as u32)
        .filter(|&t| is_sheet(t, value))
        .count();
    Ok(out)
}

/// A kept repair: the re-solved values, the pins it took and whether they were weighted.
type Repaired = (Vec<f64>, usize, bool);

/// What a wave's repairs finished so far, for a checkpoint midway.
struct Midway {
    /// (index into the pass's open defects, what its repair gave).
    done: Vec<(usize, Option<Repaired>)>,
    saved_at: std::time::Instant,
    error: Option<crate::error::Error>,
}

/// The lookups [`repair_defect`] shares across defects.
struct Index<'a> {
    /// Tetrahedra at each point of T.
    tets_of: &'a HashMap<u32, Vec<u32>>,
    /// Local opposite vertices of each tetrahedron's boundary faces.
    faces_of: &'a HashMap<u32, Vec<usize>>,
    /// Equations each slot appears in.
    eqs_of: &'a [Vec<u32>],
    /// Multi-indices of degree 5.
    mi: &'a [[u8; 4]],
    /// Largest weight of the solve.
    wmax: f64,
    /// The tetrahedron across each face (by local opposite vertex), [`NONE`] on the boundary.
    across: &'a [[u32; 4]],
}

/// No tetrahedron across a face: a boundary face of the hull.
const NONE: u32 = u32::MAX;

/// The tetrahedron across each face of each of `tets` (by local opposite vertex), [`NONE`]
/// where no single other tetrahedron has the face (the hull's boundary); `users` from
/// [`face_users`].
fn neighbours(tets: &[HullTet], users: &HashMap<[u32; 3], Vec<u32>>) -> Vec<[u32; 4]> {
    tets.iter()
        .enumerate()
        .map(|(k, t)| {
            std::array::from_fn(|opp| match users[&tet_face(t, opp)].as_slice() {
                [a, b] => {
                    if *a == k as u32 {
                        *b
                    } else {
                        *a
                    }
                }
                _ => NONE,
            })
        })
        .collect()
}

/// A face whose C1/C2 a re-solve broke ([`continuity_broken`]).
#[derive(Debug, PartialEq)]
struct Broken {
    /// The two tetrahedra that share it.
    face: (u32, u32),
    /// Its gradient and Hessian jumps after the re-solve, and before.
    now: [f64; 2],
    was: [f64; 2],
}

/// The first face of the `near` tetrahedra (with the tetrahedron across it) whose gradient or
/// Hessian jump, as `apatch check` measures it ([`crate::check::pair_jumps`]), is over the
/// checker's bound in `after` and larger than it was in `before`: the jump and the bound.
///
/// The repair's residual guard bounds each C1/C2 equation relative to its terms, which does
/// not bound the checker's jumps in thin tetrahedra: a residual r in a row of number 2 weights
/// of a tetrahedron of height h under a face of size l is a Hessian jump of ~4 r l/h (fandisk,
/// session 68: a Sheet repair with residual 3.4e-12 of the data's 1.9e-2 left a Hessian jump of
/// 2.78e-7, over C2's 1e-7). A face neither side of which changed is skipped.
fn continuity_broken(
    tets: &[HullTet],
    near: &[u32],
    across: &[[u32; 4]],
    weights: impl Fn(u32, &[f64]) -> Vec<f64>,
    before: &[f64],
    after: &[f64],
) -> Option<Broken> {
    let opts = crate::check::CheckOptions::default();
    let bound = [opts.jump_tolerance, opts.hessian_tolerance];
    let in_near: HashSet<u32> = near.iter().copied().collect();
    // The gradient and Hessian jumps across the face of `k` and `j` with these weights.
    let jumps = |k: u32, wk: Vec<f64>, j: u32, wj: Vec<f64>| {
        let a = super::patch_of(&tets[k as usize], wk);
        let b = super::patch_of(&tets[j as usize], wj);
        crate::check::pair_jumps(&a, &b, &opts).map(|d| [d[1], d[2]])
    };
    near.iter()
        .flat_map(|&k| across[k as usize].iter().map(move |&j| (k, j)))
        .filter(|&(k, j)| j != NONE && (k < j || !in_near.contains(&j)))
        .find_map(|(k, j)| {
            let (k_now, j_now) = (weights(k, after), weights(j, after));
            let (k_was, j_was) = (weights(k, before), weights(j, before));
            if k_now == k_was && j_now == j_was {
                return None;
            }
            let now = jumps(k, k_now, j, j_now)?;
            if now.iter().zip(&bound).all(|(d, b)| d <= b) {
                return None;
            }
            let was = jumps(k, k_was, j, j_was)?;
            let grew = (0..2).any(|i| now[i].is_nan() || now[i] > bound[i].max(was[i]));
            grew.then_some(Broken {
                face: (k, j),
                now,
                was,
            })
        })
}

/// The neighbourhood a defect's repair re-solves: which weights it may write and which it
/// reads, fixed by the hull alone (not by the values), so that repairs whose neighbourhoods
/// do not touch can run at once and give what they give one after the other.
struct Local {
    defect: Defect,
    /// Points of T one ring less than the reach (their stars, with `Reach::hessians` their
    /// jets' Hessians, are re-solved).
    inner: HashSet<u32>,
    /// The tetrahedra around the points within reach, sorted.
    near: Vec<u32>,
    /// The re-solved slots, sorted.
    unk: Vec<u32>,
    /// Every equation a re-solved slot appears in, sorted.
    eqs: Vec<u32>,
}

impl Local {
    /// Slots the repair reads: the near tetrahedra's (their faces and j-lines are judged) and
    /// every term of its equations.
    fn reads(&self, sys: &System) -> Vec<u32> {
        let mut r: Vec<u32> = self
            .near
            .iter()
            .flat_map(|&k| sys.slot_of[k as usize].iter().copied())
            .chain(
                self.eqs
                    .iter()
                    .flat_map(|&e| sys.equations[e as usize].terms.iter().map(|t| t.0)),
            )
            .collect();
        r.sort_unstable();
        r.dedup();
        r
    }
}

/// The neighbourhood of `defect` at `reach`; `None` when it has no slot to re-solve.
fn neighbourhood(
    sys: &System,
    tets: &[HullTet],
    defect: Defect,
    index: &Index<'_>,
    reach: Reach,
) -> Option<Local> {
    let Index {
        tets_of, eqs_of, ..
    } = *index;
    let np = sys.np;
    let (t, opp) = defect.at();
    let tet = &tets[t as usize];
    // Points of T within `reach` edges of the defect's points.
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
            if reach.hessians && hessian_point(&parts, np, &inner).is_some() {
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
    let mut eqs: Vec<u32> = unk
        .iter()
        .flat_map(|&s| eqs_of[s as usize].iter().copied())
        .collect();
    eqs.sort_unstable();
    eqs.dedup();
    Some(Local {
        defect,
        inner,
        near,
        unk,
        eqs,
    })
}

/// One try at a defect: its pins' mode ([`elevated_modes`]) and its group's factor, shared by
/// the tries whose groups are the same.
#[derive(Clone, Copy)]
struct Attempt<'a> {
    mode: Option<(usize, f64)>,
    sparse: &'a Factor,
}

/// One defect's repair on `value` within `local`: the re-solved values of `local.unk`, the
/// pins and whether they were weighted, when kept.
fn repair_defect(
    sys: &System,
    tets: &[HullTet],
    value: &[f64],
    local: &Local,
    index: &Index<'_>,
    reach: Reach,
    attempt: Attempt<'_>,
) -> Option<Repaired> {
    let Attempt { mode, sparse } = attempt;
    let Index {
        faces_of,
        mi,
        wmax,
        across,
        ..
    } = *index;
    let np = sys.np;
    let Local {
        defect,
        ref inner,
        ref near,
        ref unk,
        ref eqs,
    } = *local;
    let t = defect.at().0;
    let tet = &tets[t as usize];
    let mut col: HashMap<u32, usize> = unk.iter().enumerate().map(|(i, &s)| (s, i)).collect();
    // With `hessians`, the number 2 weights of each inner point p move together as its jet's
    // Hessian does: one more unknown per entry of the change δH (target 0), and for each
    // such weight b at p, a, b' the equation b − (a − p)ᵀ δH (b' − p)/20 = its value now.
    let mut hess_rows: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
    let mut hess_col: HashMap<u32, usize> = HashMap::new();
    let mut hess_unit: Vec<f64> = Vec::new();
    if reach.hessians {
        let mut pos: HashMap<u32, glam::DVec3> = HashMap::new();
        for &k in near {
            for (g, p) in tets[k as usize].gid.iter().zip(tets[k as usize].pts) {
                pos.insert(*g, p);
            }
        }
        for (j, &s) in unk.iter().enumerate() {
            let parts = super::system::unkey(sys.keys[s as usize]);
            let Some(p) = hessian_point(&parts, np, inner) else {
                continue;
            };
            let next = unk.len() + 6 * hess_col.len();
            let base = *hess_col.entry(p).or_insert(next);
            let at = pos[&p];
            let others: Vec<glam::DVec3> = parts
                .iter()
                .filter(|q| q.0 != p)
                .flat_map(|q| std::iter::repeat_n(pos[&q.0] - at, usize::from(q.1)))
                .collect();
            let coef = symmetric_pair(others[0], others[1]);
            let mut row = vec![(j, 1.0)];
            row.extend(coef.iter().enumerate().map(|(e, c)| (base + e, -c / 20.0)));
            hess_rows.push((row, value[s as usize]));
        }
        // Each point's δH is solved for in units that make its largest coefficient 1 (the
        // unknown is s_p·δH): as given, the coefficients are |a − p||b′ − p|/20, about 1e-3 on
        // the bunny, and the C2 rows among a point's number 2 weights are then nearly
        // combinations of its Hessian rows (Â Âᵀ nearly singular), which stalled the solves of
        // its last holes.
        let point = |j: usize| (j - unk.len()) / 6;
        let mut unit = vec![0.0_f64; hess_col.len()];
        for (row, _) in &hess_rows {
            for &(j, k) in &row[1..] {
                unit[point(j)] = unit[point(j)].max(k.abs());
            }
        }
        for (row, _) in &mut hess_rows {
            for (j, k) in &mut row[1..] {
                let u = unit[point(*j)];
                if u > 0.0 {
                    *k /= u;
                }
            }
        }
        hess_unit = unit;
    }
    let n = unk.len() + 6 * hess_col.len();
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::with_capacity(eqs.len());
    let mut c: Vec<f64> = Vec::with_capacity(eqs.len());
    for &e in eqs {
        let mut row = Vec::new();
        let mut rhs = 0.0;
        let terms = &sys.equations[e as usize].terms;
        let noise = NOISE * terms.iter().fold(0.0_f64, |a, t| a.max(t.1.abs()));
        for &(s, k) in terms {
            match col.get(&s) {
                Some(_) if k.abs() <= noise => {}
                Some(&j) => row.push((j, k)),
                None => rhs -= k * value[s as usize],
            }
        }
        rows.push(row);
        c.push(rhs);
    }
    for (row, rhs) in hess_rows {
        rows.push(row);
        c.push(rhs);
    }
    // The scene's held normal part of the Hessians (`hessian_normal`, [`super::normalpart`]):
    // each freed Hessian's change keeps it, so the repair cannot put back the normal bend the
    // solve was kept from.
    for (&p, &base) in &hess_col {
        for row in held_hessian_rows(sys, tets, near, value, p, base) {
            rows.push(row);
            c.push(0.0);
        }
    }
    let mut x0: Vec<f64> = unk.iter().map(|&s| value[s as usize]).collect();
    x0.resize(n, 0.0);
    if let Some(column) = normal_bend_target() {
        // Exploration (`APATCH_HOLE_NORMAL_BEND`): each freed Hessian's change aims at
        // taking its normal part back to the jets' 0 (`scripts/normal_curvature.py`).
        for (&p, &base) in &hess_col {
            let Some(k) = near
                .iter()
                .copied()
                .find(|&k| tets[k as usize].gid.contains(&p))
            else {
                continue;
            };
            let tet = &tets[k as usize];
            let at = tet.gid.iter().position(|&g| g == p).unwrap_or(0);
            let Some((g, h)) = jet_at(&sys.weights(k as usize, value), &tet.pts, at) else {
                continue;
            };
            let nn = g.normalize_or_zero();
            let u = hess_unit[(base - unk.len()) / 6];
            // The part taken out, as the entries xx, xy, xz, yy, yz, zz.
            let nnt = glam::DMat3::from_cols(nn * nn.x, nn * nn.y, nn * nn.z);
            let out = if column {
                let p = glam::DMat3::IDENTITY - nnt;
                h - p * h * p
            } else {
                nn.dot(h * nn) * nnt
            };
            let d = [
                out.x_axis.x,
                out.y_axis.x,
                out.z_axis.x,
                out.y_axis.y,
                out.z_axis.y,
                out.z_axis.z,
            ];
            for (e, v) in d.iter().enumerate() {
                x0[base + e] = -u * v;
            }
        }
    }
    // Exploration (`APATCH_HOLE_ELEVATE`): the crossed face (or every boundary face of the
    // re-solved tetrahedra) gets one more unknown per elevated coefficient that a re-solved
    // weight enters, tied to the weights by a row; those carry the face's sign conditions
    // instead of its weights (ids past the slots: `nslots + k`).
    let nslots = sys.keys.len() as u32;
    let mut aux_sign: Vec<f64> = Vec::new();
    let mut aux_of: HashMap<(u32, usize), Vec<u32>> = HashMap::new();
    let elevate = mode
        .map(|m| m.0)
        .filter(|_| matches!(defect, Defect::Face(..)));
    // Only the crossed face itself is elevated unless `APATCH_HOLE_ELEVATE_SCOPE=all`
    // ([`defect_scope`]).
    let one_face = defect_scope();
    let elevated_face = |k: u32, o: usize| {
        elevate.is_some() && (!one_face || matches!(defect, Defect::Face(f, p) if (f, p) == (k, o)))
    };
    if let Some(r) = elevate {
        let face_list: Vec<(u32, usize)> = near
            .iter()
            .flat_map(|&k| faces_of.get(&k).into_iter().flatten().map(move |&o| (k, o)))
            .filter(|&(k, o)| elevated_face(k, o))
            .collect();
        for (k, o) in face_list {
            let (slots, idx): (Vec<u32>, Vec<[u8; 3]>) = face_indices(mi, o)
                .map(|(i, a)| (sys.slot_of[k as usize][i], a))
                .unzip();
            // The face's sign: Theorem 2.1's for its signed weights (their majority), else its
            // largest weight's.
            let votes: i32 = slots
                .iter()
                .map(|&q| i32::from(sys.req[q as usize]))
                .filter(|v| v.abs() == 1)
                .sum();
            let big = slots
                .iter()
                .map(|&q| value[q as usize])
                .fold(0.0_f64, |a, v| if v.abs() > a.abs() { v } else { a });
            let sigma = if votes != 0 {
                f64::from(votes.signum())
            } else {
                big.signum()
            };
            if sigma == 0.0 {
                continue;
            }
            let mut ids = Vec::new();
            for (_, erow) in elevation(&idx, r) {
                if !erow.iter().any(|&(i, _)| col.contains_key(&slots[i])) {
                    continue;
                }
                let j = x0.len();
                let id = nslots + aux_sign.len() as u32;
                let mut row = vec![(j, 1.0)];
                let mut rhs = 0.0;
                let mut now = 0.0;
                for &(i, f) in &erow {
                    let q = slots[i];
                    now += f * value[q as usize];
                    match col.get(&q) {
                        Some(&jj) => row.push((jj, -f)),
                        None => rhs += f * value[q as usize],
                    }
                }
                rows.push(row);
                c.push(rhs);
                x0.push(now);
                col.insert(id, j);
                aux_sign.push(sigma);
                ids.push(id);
            }
            aux_of.insert((k, o), ids);
        }
    }
    let n = x0.len();
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
    // The j-patches among them crossed twice along a j-line now.
    let sheets_now = |value: &[f64]| -> HashSet<u32> {
        near.iter()
            .copied()
            .filter(|&k| j_sheeted(&sys.weights(k as usize, value), tets[k as usize].role))
            .collect()
    };
    let sheets_before = sheets_now(value);
    // Sign conditions: every late slot on a boundary face of the re-solved tetrahedra with a
    // sign from Theorem 2.1 (its face's weights), the crossed face's misses pinned first, then
    // whatever a solution newly misses among the ones met before.
    let sign = |s: u32| match s.checked_sub(nslots) {
        Some(a) => aux_sign[a as usize],
        None => f64::from(sys.req[s as usize]),
    };
    let has_sign = |s: u32| s >= nslots || matches!(sys.req[s as usize], 1 | -1);
    // A weight's value before the repair, or an elevated coefficient's.
    let cur = |s: u32| {
        if s >= nslots {
            x0[col[&s]]
        } else {
            value[s as usize]
        }
    };
    let face_slots = |k: u32, o: usize| -> Vec<u32> {
        face_indices(mi, o)
            .map(|(i, _)| sys.slot_of[k as usize][i])
            .collect()
    };
    // What carries a face's sign conditions: its weights, or its elevated coefficients.
    let face_cond = |k: u32, o: usize| -> Vec<u32> {
        if elevated_face(k, o) {
            aux_of.get(&(k, o)).cloned().unwrap_or_default()
        } else {
            face_slots(k, o)
        }
    };
    // The elevated coefficients' margin as a share of the weights' ([`elevated_modes`]): at a
    // crease point of letter_P the sides ask opposite signs of the curvature along one line,
    // so its number 2 weights there must be zero and any margin is infeasible
    // (`scripts/hole_feasibility.py`); on fandisk's Face(22450, 3) 1e-2 mends what 0 and 1
    // do not.
    let aux_margin = mode.map_or(0.0, |m| m.1);
    // The largest weight among `slots` (before the repair), and: watch the signed re-solved
    // ones of `slots` with margin `m`, returning those.
    let largest = |slots: &[u32]| slots.iter().fold(0.0_f64, |a, &s| a.max(cur(s).abs()));
    let watch = |watched: &mut Vec<(u32, f64)>, slots: &[u32], m: f64| -> Vec<u32> {
        let signed: Vec<u32> = slots
            .iter()
            .copied()
            .filter(|s| col.contains_key(s) && has_sign(*s))
            .collect();
        watched.extend(
            signed
                .iter()
                .map(|&s| (s, if s >= nslots { m * aux_margin } else { m })),
        );
        signed
    };
    let mut watched: Vec<(u32, f64)> = Vec::new();
    // (In the elevated mode only the elevated faces are watched by their signs, the others
    // only by whether they turn: their weights' signs are what a crease cannot meet.)
    for &(k, o) in faces
        .iter()
        .filter(|&&(k, o)| elevate.is_none() || elevated_face(k, o))
    {
        let slots = face_slots(k, o);
        watch(&mut watched, &face_cond(k, o), MARGIN * largest(&slots));
    }
    // The defect's own weights: a crossed face's, or every signed weight of a patch crossed
    // twice along a j-line (Theorem 2.1's signs make every j-line cross once).
    let hole_slots: HashSet<u32> = match defect {
        Defect::Face(_, opp) => face_cond(t, opp).into_iter().collect(),
        Defect::Sheet(_) => {
            let own = &sys.slot_of[t as usize];
            watch(&mut watched, own, MARGIN * largest(own));
            own.iter().copied().collect()
        }
    };
    watched.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
    watched.dedup_by_key(|w| w.0);
    let tiny = ZERO * scale;
    let met_before: HashSet<u32> = watched
        .iter()
        .filter(|&&(s, _)| sign(s) * cur(s) >= -tiny)
        .map(|w| w.0)
        .collect();
    let mut pins: Vec<(usize, f64)> = Vec::new();
    let mut pinned: HashSet<u32> = HashSet::new();
    let mut x = x0.clone();
    let mut soft = false;
    // The weight of pins met only as targets, raised ([`SOFT_MAX`]) while the targets as
    // weighted leave the defect or a turned neighbour.
    let mut weight = SOFT;
    let ok = |sol: &dense::Solution| {
        // NaN-safe: a NaN residual or weight refuses the repair too.
        sol.residual <= CONSISTENT * scale && sol.x.iter().all(|v| v.abs() <= bound)
    };
    // A weighted solve is consistent by construction (the values now meet its equations), so
    // what it misses is rounding in a group the weights condition worse: it goes on to the
    // per-equation guard below, which decides.
    let ok_soft = |sol: &dense::Solution| {
        sol.residual <= SOFT_CONSISTENT * scale && sol.x.iter().all(|v| v.abs() <= bound)
    };
    // One more solve with the pins weighted ten times more, when they are targets and the
    // solves and the weight allow: the new values if that solve meets the equations.
    let heavier = |weight: &mut f64, solves: &mut usize, pins: &[(usize, f64)]| {
        if *weight >= soft_max() || *solves >= ROUNDS {
            return None;
        }
        *weight *= 10.0;
        *solves += 1;
        let sol = solve_soft(&rows, &c, pins, n, &x0, *weight, sparse);
        ok_soft(&sol).then_some(sol.x)
    };
    // The weights lifted to the margin: the defect's, then those of any boundary face or
    // j-patch a solution turns defective (they join the defect instead of refusing it).
    let mut lifted = hole_slots;
    let mut trial = value.to_vec();
    let mut solves = 0;
    // Exploration, with `APATCH_HOLE_ELEVATE`: moves at the solves' rounding are dropped, so
    // that weights exactly zero (flat regions) stay so and their equations stay exact.
    let snap = |mut y: Vec<f64>| {
        if elevate.is_some() {
            for (v, v0) in y.iter_mut().zip(&x0) {
                if (*v - v0).abs() <= tiny {
                    *v = *v0;
                }
            }
        }
        y
    };
    loop {
        let miss: Vec<(u32, f64)> = watched
            .iter()
            .copied()
            .filter(|&(s, _)| !pinned.contains(&s))
            .filter(|&(s, m)| {
                // The lifted weights go to the margin; the others are only kept from turning.
                let v = sign(s) * x[col[&s]];
                (lifted.contains(&s) && v < m) || (met_before.contains(&s) && v < -tiny)
            })
            .collect();
        if miss.is_empty() {
            if pins.is_empty() {
                trace(|| format!("{defect:?}: nothing to pin among {n} unknowns"));
                return None;
            }
            // Kept only when the defect is gone and no other boundary face or j-patch of the
            // re-solved tetrahedra turned defective; those that did join the defect.
            for (j, &s) in unk.iter().enumerate() {
                trial[s as usize] = x[j];
            }
            let still = defect.open_in(&sys.weights(t as usize, &trial), tet.role);
            if still {
                if soft {
                    if let Some(y) = heavier(&mut weight, &mut solves, &pins) {
                        x = snap(y);
                        continue;
                    }
                }
                trace(|| {
                    // What the re-solve cannot reach: the defect's weights held (data, or
                    // beyond the reach) with the wrong sign, and those without a sign (its
                    // elevated coefficients left out).
                    let real: Vec<u32> = lifted.iter().copied().filter(|&s| s < nslots).collect();
                    let held_wrong = real
                        .iter()
                        .filter(|s| !col.contains_key(s))
                        .filter(|&&s| has_sign(s) && sign(s) * trial[s as usize] < -tiny)
                        .count();
                    let big = real
                        .iter()
                        .fold(0.0_f64, |a, &s| a.max(trial[s as usize].abs()));
                    // A weight as the trace names it: its key and required sign.
                    let name = |s: u32| {
                        format!(
                            "{:?} req {}",
                            super::system::unkey(sys.keys[s as usize]),
                            sys.req[s as usize]
                        )
                    };
                    let unsigned: Vec<String> = real
                        .iter()
                        .filter(|&&s| !has_sign(s))
                        .map(|&s| format!("{} {:.1e}", name(s), trial[s as usize] / big))
                        .collect();
                    // The face's weights whose sign differs from its largest's: where it
                    // crosses (exploration detail, with which are re-solved).
                    let lead = real
                        .iter()
                        .map(|&s| trial[s as usize])
                        .fold(0.0_f64, |a, v| if v.abs() > a.abs() { v } else { a });
                    let against: Vec<String> = real
                        .iter()
                        .filter(|&&s| trial[s as usize] * lead < 0.0)
                        .map(|&s| {
                            let how = if col.contains_key(&s) {
                                "solved"
                            } else {
                                "held"
                            };
                            format!("{} {:.2e} {how}", name(s), trial[s as usize])
                        })
                        .collect();
                    // In the elevated mode: the crossed face's elevated coefficients at the
                    // trial that are negative (against its sign), in the group (a re-solved
                    // weight enters them) and held, each group's least as a share of the
                    // face's largest weight, and where the negative ones are (degree 5 + r
                    // indices over the face's corners).
                    let elevated = match (elevate, defect) {
                        (Some(r), Defect::Face(_, opp)) => {
                            let w = sys.weights(t as usize, &trial);
                            let (fw, idx): (Vec<(u32, f64)>, Vec<[u8; 3]>) = face_indices(mi, opp)
                                .map(|(i, a)| ((sys.slot_of[t as usize][i], w[i]), a))
                                .unzip();
                            let big = fw.iter().fold(1e-300_f64, |a, p| a.max(p.1.abs()));
                            let sigma = aux_of
                                .get(&(t, opp))
                                .and_then(|ids| ids.first())
                                .map_or(0.0, |&id| aux_sign[(id - nslots) as usize]);
                            let (mut held, mut solved) = ((0, 0.0_f64), (0, 0.0_f64));
                            let mut negative = Vec::new();
                            for (b, erow) in elevation(&idx, r) {
                                let v: f64 = erow.iter().map(|&(i, f)| f * fw[i].1).sum();
                                let share = sigma * v / big;
                                if share < 0.0 {
                                    let in_group =
                                        erow.iter().any(|&(i, _)| col.contains_key(&fw[i].0));
                                    let tally = if in_group { &mut solved } else { &mut held };
                                    tally.0 += 1;
                                    tally.1 = tally.1.min(share);
                                    negative.push(format!("{b:?} {share:.2e}"));
                                }
                            }
                            let corners: Vec<(u32, bool)> = (0..4)
                                .filter(|&v| v != opp)
                                .map(|v| (tet.gid[v], tet.gid[v] < np))
                                .collect();
                            format!(
                                "; elevated sign {sigma}: negative in the group {} (least {:.2e}), held {} (least {:.2e}); soft {soft} weight {weight:.0e} solves {solves}; corners (id, of T) {corners:?}; negative at {negative:?}",
                                solved.0, solved.1, held.0, held.1
                            )
                        }
                        _ => String::new(),
                    };
                    format!(
                        "{defect:?}: {} pins; still there ({held_wrong} held weights with the wrong sign; without a sign: {unsigned:?}; against the largest {lead:.2e}: {against:?}), side {:?} role {:?}{elevated}",
                        pins.len(),
                        tet.side,
                        tet.role
                    )
                });
                return None;
            }
            let new_faces: Vec<(u32, usize)> = crossed_now(&trial)
                .into_iter()
                .filter(|f| !before.contains(f))
                .collect();
            let new_sheets: Vec<u32> = sheets_now(&trial)
                .into_iter()
                .filter(|k| !sheets_before.contains(k))
                .collect();
            if new_faces.is_empty() && new_sheets.is_empty() {
                break;
            }
            let mut grew = false;
            let turned = new_faces
                .iter()
                .map(|&(k, o)| face_cond(k, o))
                .chain(new_sheets.iter().map(|&k| sys.slot_of[k as usize].to_vec()));
            for slots in turned {
                for s in watch(&mut watched, &slots, MARGIN * largest(&slots)) {
                    grew |= lifted.insert(s);
                }
            }
            watched.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
            watched.dedup_by_key(|w| w.0);
            if !grew && soft {
                if let Some(y) = heavier(&mut weight, &mut solves, &pins) {
                    x = snap(y);
                    continue;
                }
            }
            if !grew || solves == ROUNDS {
                trace(|| {
                    format!(
                        "{defect:?}: {} pins; newly crossed faces {}, new j-sheets {}",
                        pins.len(),
                        new_faces.len(),
                        new_sheets.len()
                    )
                });
                return None;
            }
            continue;
        }
        if solves == ROUNDS {
            trace(|| format!("{defect:?}: {} pins; rounds used up", pins.len()));
            return None;
        }
        solves += 1;
        for (s, m) in miss {
            pinned.insert(s);
            pins.push((col[&s], sign(s) * m));
        }
        dump(defect, n, &rows, &c, &x0, &pins, || {
            unk.iter()
                .map(|&s| {
                    format!(
                        "{:?} req {}",
                        super::system::unkey(sys.keys[s as usize]),
                        sys.req[s as usize]
                    )
                })
                .collect()
        });
        let mut sol = solve(&rows, &c, &pins, n, &x0, sparse);
        if !ok(&sol) {
            let (hard, hard_rank) = (sol.residual, sol.rank);
            sol = solve_soft(&rows, &c, &pins, n, &x0, weight, sparse);
            if !ok_soft(&sol) {
                trace(|| {
                    format!(
                        "{defect:?}: {n} unknowns, {} equations, {} pins: residual {hard:.2e} of {scale:.2e} at rank {hard_rank} (soft {:.2e} at rank {}; the values before: {:.2e}), largest {:.2e}",
                        rows.len(),
                        pins.len(),
                        sol.residual,
                        sol.rank,
                        rows.iter()
                            .zip(&c)
                            .map(|(r, &ci)| (r.iter().map(|&(j, k)| k * x0[j]).sum::<f64>() - ci).abs())
                            .fold(0.0_f64, f64::max),
                        sol.x.iter().fold(0.0_f64, |a, v| a.max(v.abs()))
                    )
                });
                return None;
            }
            soft = true;
        }
        x = snap(sol.x);
    }
    // The checker measures jumps relative to the local size of F: each re-solved equation's
    // residual relative to its own terms may not grow past what it was and the staged solve's
    // standard (on the nut, residuals small against the group's largest datum still gave
    // Hessian jumps of 6.5e-7 where F is small).
    // In the elevated mode each term is sized by the larger of its values before and after
    // the move ([`System::relative_residual_moved`]): the elevated pins can take a point's
    // number 2 weights from 4e-2 to zero (a flat direction at letter_P's creases, where the
    // sides ask opposite signs), and their equations are then met to the rounding of the
    // move (1e-16), which a bound relative to the new terms alone refuses while the checker
    // (jumps relative to the face's gradient) does not see it.
    let sized_by: &[f64] = if elevate.is_some() { value } else { &trial };
    let measure = |e: u32| sys.relative_residual_moved(e as usize, &trial, sized_by, wmax);
    let limit = eqs
        .iter()
        .map(|&e| sys.relative_residual(e as usize, value, wmax))
        .fold(0.0, f64::max)
        .max(super::system::NEAR_NULL_RESIDUAL);
    let grown = eqs.iter().map(|&e| measure(e)).fold(0.0, f64::max);
    if grown.is_nan() || grown > limit {
        trace(|| {
            // The worst equation: its terms before and after (exploration detail).
            let e = eqs
                .iter()
                .copied()
                .max_by(|&a, &b| measure(a).total_cmp(&measure(b)))
                .unwrap_or(0);
            let terms: Vec<String> = sys.equations[e as usize]
                .terms
                .iter()
                .map(|&(q, k)| {
                    format!(
                        "{k:.3e}×{:?} {:.3e}→{:.3e}{}",
                        super::system::unkey(sys.keys[q as usize]),
                        value[q as usize],
                        trial[q as usize],
                        if col.contains_key(&q) { "" } else { " held" }
                    )
                })
                .collect();
            format!("{defect:?}: relative residual {grown:.2e} > {limit:.2e}: {terms:?}")
        });
        return None;
    }
    // And C1/C2 as `apatch check` measures them, on every face the re-solve touched.
    let weights_in = |k: u32, v: &[f64]| sys.weights(k as usize, v);
    if let Some(Broken {
        face: (k, j),
        now,
        was,
    }) = continuity_broken(tets, near, across, weights_in, value, &trial)
    {
        trace(|| {
            format!(
                "{defect:?}: jumps across the face of {k} and {j} (gradient, Hessian) {:.2e}, {:.2e} over the bound (were {:.2e}, {:.2e})",
                now[0], now[1], was[0], was[1]
            )
        });
        return None;
    }
    x.truncate(unk.len());
    trace(|| {
        format!(
            "{defect:?}: repaired, {} pins{}, residual {grown:.2e}",
            pins.len(),
            if soft { " (weighted)" } else { "" }
        )
    });
    Some((x, pins.len(), soft))
}

/// Exploration (`APATCH_HOLE_NORMAL_BEND`): what the freed Hessians' changes aim to take out
/// of the point's Hessian H. `1`: the normal bend n·H·n (`Some(false)`); `column`: the whole
/// H − P H P (P = I − n nᵀ), the bend and the mixed part P H n, which the joint stars put at
/// fandisk's deepest crossed faces (session 67) (`Some(true)`).
fn normal_bend_target() -> Option<bool> {
    match std::env::var("APATCH_HOLE_NORMAL_BEND").ok()?.as_str() {
        "0" => None,
        "column" => Some(true),
        _ => Some(false),
    }
}

/// ∇F and ∇²F of the quintic with `weights` (in [`multi_indices`] order) over the
/// tetrahedron `pts` at its corner `at`: 5 Σ (w_{4a+i} − w_{5a}) ∇λ_i and 20 Σ (w_{3a+i+j} −
/// w_{4a+i} − w_{4a+j} + w_{5a}) ∇λ_i ∇λ_jᵀ over the other corners i, j. `None` for a flat
/// tetrahedron.
fn jet_at(
    weights: &[f64],
    pts: &[glam::DVec3; 4],
    at: usize,
) -> Option<(glam::DVec3, glam::DMat3)> {
    let grads = super::normalpart::barycentric_gradients(pts)?;
    let grad = |i: usize| grads[i];
    let w = |extra: &[usize]| {
        let mut l = [0u8; 4];
        l[at] = 5 - extra.len() as u8;
        for &i in extra {
            l[i] += 1;
        }
        weights[crate::bb::index_of(l)]
    };
    let others: Vec<usize> = (0..4).filter(|&i| i != at).collect();
    let mut g = glam::DVec3::ZERO;
    let mut h = glam::DMat3::ZERO;
    for &i in &others {
        g += 5.0 * (w(&[i]) - w(&[])) * grad(i);
        for &j in &others {
            let d2 = w(&[i, j]) - w(&[i]) - w(&[j]) + w(&[]);
            let (a, b) = (grad(i), grad(j));
            h += 20.0 * d2 * glam::DMat3::from_cols(a * b.x, a * b.y, a * b.z);
        }
    }
    Some((g, h))
}

/// Rows on point `p`'s six Hessian unknowns (columns `base..base + 6`, the change δH in the
/// entries xx, xy, xz, yy, yz, zz, each in its point's unit) that keep uᵀδH n = 0 for the
/// directions u that [`System::hessian_normal_at`] holds, n the unit gradient at `p` read from a
/// near tetrahedron's weights. A uniform scale of δH (the point's unit) leaves the rows true.
fn held_hessian_rows(
    sys: &System,
    tets: &[HullTet],
    near: &[u32],
    value: &[f64],
    p: u32,
    base: usize,
) -> Vec<Vec<(usize, f64)>> {
    use super::normalpart::HessianNormal;
    let mode = sys.hessian_normal_at(p);
    if mode == HessianNormal::Free {
        return Vec::new();
    }
    let Some(k) = near
        .iter()
        .copied()
        .find(|&k| tets[k as usize].gid.contains(&p))
    else {
        return Vec::new();
    };
    let tet = &tets[k as usize];
    let at = tet.gid.iter().position(|&g| g == p).unwrap_or(0);
    let Some((g, _)) = jet_at(&sys.weights(k as usize, value), &tet.pts, at) else {
        return Vec::new();
    };
    let n = g.normalize_or_zero();
    if n == glam::DVec3::ZERO {
        return Vec::new();
    }
    mode.directions(n)
        .into_iter()
        .map(|u| {
            symmetric_pair(u, n)
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != 0.0)
                .map(|(e, v)| (base + e, *v))
                .collect()
        })
        .collect()
}

/// uᵀH v as coefficients of the symmetric H's entries xx, xy, xz, yy, yz, zz.
fn symmetric_pair(u: glam::DVec3, v: glam::DVec3) -> [f64; 6] {
    [
        u.x * v.x,
        u.x * v.y + u.y * v.x,
        u.x * v.z + u.z * v.x,
        u.y * v.y,
        u.y * v.z + u.z * v.y,
        u.z * v.z,
    ]
}

/// The point of T whose number 2 weight the slot with key `parts` is (multiplicity 3 there,
/// the other two indices elsewhere) when that point is in `inner`: the weights whose jet a
/// repair with [`Reach::hessians`] re-solves.
fn hessian_point(parts: &[(u32, u8)], np: u32, inner: &HashSet<u32>) -> Option<u32> {
    let p = parts.iter().find(|q| q.1 == 3)?;
    (p.0 < np && inner.contains(&p.0)).then_some(p.0)
}

/// The weights closest to `x0` that meet `rows`·x = `c` and the pins x_j = v.
///
/// Large groups are solved by [`PinnedSolves`] (made at the repair's first solve and kept for
/// its rounds: one factorisation of the group's equations per repair).
fn solve(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    pins: &[(usize, f64)],
    n: usize,
    x0: &[f64],
    sparse: &Factor,
) -> dense::Solution {
    if n > super::system::DENSE_LIMIT {
        return match pinned_solves(rows, c, n, x0, sparse) {
            Some(p) => p.solve(rows, c, pins, None),
            None => dense::Solution::unsolved(x0),
        };
    }
    let m = rows.len() + pins.len();
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

/// The group's [`PinnedSolves`], made at its first sparse solve; `None` for a group too large
/// to factor ([`factored`] within the staged solve's limits).
fn pinned_solves<'a>(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    n: usize,
    x0: &[f64],
    sparse: &'a Factor,
) -> Option<&'a PinnedSolves> {
    sparse
        .get_or_init(|| {
            let limits = (cholesky::MAX_FACTOR_ROWS, cholesky::MAX_FACTOR_ENTRIES);
            let p = factored(rows, c, n, x0, limits);
            if p.is_none() {
                trace(|| {
                    format!(
                        "a group of {} equations, {n} unknowns is too large to factor",
                        rows.len()
                    )
                });
            }
            p
        })
        .as_ref()
}

/// A repair group's factor, kept for its rounds (none until its first sparse solve).
type Factor = OnceLock<Option<PinnedSolves>>;

/// The group's [`PinnedSolves`] when it has at most `max rows` equations and its factor at
/// most `max entries`, as the staged solve allows (`system::solve_sparse`): a repair of a
/// defect whose neighbourhood has grown beyond them is refused instead of filling the memory.
fn factored(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    n: usize,
    x0: &[f64],
    limits: (usize, usize),
) -> Option<PinnedSolves> {
    cholesky::Ordering::within(rows, n, limits)
        .map(|ordering| PinnedSolves::new(rows, c, n, x0, &ordering))
}

/// [`solve`] with the pins as targets weighted by `weight` ([`SOFT`] first) instead of
/// equations: the weights closest to `x0` (pinned ones: to their pins) in the norm that counts
/// a pinned weight's change `weight` times, meeting `rows`·x = `c`. Small groups are solved as
/// the unweighted problem in y = W x, large ones by [`PinnedSolves`].
fn solve_soft(
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    pins: &[(usize, f64)],
    n: usize,
    x0: &[f64],
    weight: f64,
    sparse: &Factor,
) -> dense::Solution {
    if n > super::system::DENSE_LIMIT {
        return match pinned_solves(rows, c, n, x0, sparse) {
            Some(p) => p.solve(rows, c, pins, Some(weight)),
            None => dense::Solution::unsolved(x0),
        };
    }
    let mut w = vec![1.0; n];
    let mut y0 = x0.to_vec();
    for &(j, v) in pins {
        w[j] = weight;
        y0[j] = weight * v;
    }
    let scaled: Vec<Vec<(usize, f64)>> = rows
        .iter()
        .map(|r| r.iter().map(|&(j, k)| (j, k / w[j])).collect())
        .collect();
    let mut sol = solve(&scaled, c, &[], n, &y0, sparse);
    for (x, wj) in sol.x.iter_mut().zip(&w) {
        *x /= wj;
    }
    sol
}

/// Opt-in dump of a defect's group before each of its solves (`APATCH_HOLE_DUMP` = the
/// defect as the trace prints it, e.g. `Face(4274, 3)`; results unaffected): its unknowns,
/// rows, right-hand sides, values and pins as JSON in `/tmp/dump_<defect>_<n>.json`, for
/// `pinned`'s ignored `explore_dump` test and `scripts/hole_feasibility.py`; `names` gives the
/// re-solved slots' keys and required signs (the Hessian unknowns after them are unnamed).
fn dump(
    defect: Defect,
    n: usize,
    rows: &[Vec<(usize, f64)>],
    c: &[f64],
    x0: &[f64],
    pins: &[(usize, f64)],
    names: impl FnOnce() -> Vec<String>,
) {
    if std::env::var("APATCH_HOLE_DUMP").is_ok_and(|want| want == format!("{defect:?}")) {
        let name = format!("{defect:?}").replace([' ', '(', ')', ','], "_");
        let path = std::env::temp_dir().join(format!("dump_{name}_{n}.json"));
        let j = serde_json::json!({"n": n, "rows": rows, "c": c, "x0": x0, "pins": pins, "names": names()});
        if let Err(e) = std::fs::write(&path, j.to_string()) {
            eprintln!("quintic-c2 hole repair: dump {}: {e}", path.display());
        }
    }
}

/// Opt-in report of each pass and each repair, kept or refused, on stderr (`APATCH_HOLE_TRACE`;
/// results unaffected).
fn trace(msg: impl FnOnce() -> String) {
    if std::env::var_os("APATCH_HOLE_TRACE").is_some() {
        eprintln!("quintic-c2 hole repair: {}", msg());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quintic whose weights are the blossom of a 2-jet's Taylor polynomial at one corner
    /// ([`super::super::jets::Jet::blossom5`]) has that jet there: `jet_at` gives back its
    /// gradient and Hessian, at every corner of a skewed tetrahedron.
    #[test]
    fn jet_at_recovers_the_taylor_polynomial_it_was_made_from() {
        let (pts, g, h) = super::super::normalpart::tests::skewed_jet();
        for at in 0..4 {
            let jet = super::super::jets::Jet { p: pts[at], g, h };
            let weights: Vec<f64> = multi_indices(5)
                .iter()
                .map(|&l| jet.blossom5(&super::super::jets::domain_args(&pts, l)))
                .collect();
            let (g2, h2) = jet_at(&weights, &pts, at).unwrap();
            // Rounding only: the tetrahedron's edges are ~1 and its λ-gradients ~5, so the
            // differences of weights ~1 lose a few digits of 1e-16.
            assert!((g2 - g).length() < 1e-12, "{at}: {g2} vs {g}");
            for c in 0..3 {
                assert!((h2.col(c) - h.col(c)).length() < 1e-11, "{at}: {h2} vs {h}");
            }
        }
    }

    /// Two tetrahedra glued on a face, B's weights the continuation of A's quintic
    /// (`poly::blossom` at B's domain points in A's coordinates), so F is one polynomial and
    /// every jump is rounding. BB theory says which of B's weights reach across the face: with
    /// λ_opp = 1 the gradient, = 2 the Hessian, ≥ 3 neither. The guard must name the face for
    /// the first two changes, not for the third, and not when a jump only stays what it was.
    #[test]
    fn continuity_broken_sees_the_jumps_check_would_see() {
        use crate::hull::simplicial::Side;
        let a_pts = [
            glam::DVec3::new(0.0, 0.0, 0.0),
            glam::DVec3::new(1.0, 0.1, 0.0),
            glam::DVec3::new(0.2, 0.9, 0.1),
            glam::DVec3::new(0.3, 0.3, 0.8),
        ];
        let b_pts = [
            a_pts[0],
            a_pts[1],
            a_pts[2],
            glam::DVec3::new(0.4, 0.2, -0.6),
        ];
        let tet = |gid: [u32; 4], pts: [glam::DVec3; 4]| HullTet {
            gid,
            pts,
            role: Role::Face,
            element: 0,
            triangle: 0,
            side: Side::Outer,
        };
        let tets = [tet([0, 1, 2, 3], a_pts), tet([0, 1, 2, 4], b_pts)];
        let across = neighbours(&tets, &face_users(&tets));
        assert_eq!(across, vec![[NONE, NONE, NONE, 1], [NONE, NONE, NONE, 0]]);
        // A's weights: a fixed pseudo-random sequence in [-1, 1].
        let mut seed = 12345_u64;
        let wa: Vec<f64> = (0..56)
            .map(|_| {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            })
            .collect();
        let ta = crate::bb::tet::Tet::new(a_pts).unwrap();
        let in_a: Vec<[f64; 4]> = b_pts.iter().map(|&p| ta.bary(p)).collect();
        let mi = multi_indices(5);
        let wb: Vec<f64> = mi
            .iter()
            .map(|l| {
                let args: Vec<[f64; 4]> = (0..4)
                    .flat_map(|v| std::iter::repeat_n(in_a[v], usize::from(l[v])))
                    .collect();
                poly::blossom(5, &wa, &args)
            })
            .collect();
        let before: Vec<f64> = wa.iter().chain(&wb).copied().collect();
        let weights = |k: u32, v: &[f64]| v[56 * k as usize..56 * (k as usize + 1)].to_vec();
        let near = [0, 1];
        let changed = |level: u8| {
            let i = mi.iter().position(|l| l[3] == level).unwrap();
            let mut v = before.clone();
            v[56 + i] += 1e-3;
            v
        };
        let broken = |after: &[f64], before: &[f64]| {
            continuity_broken(&tets, &near, &across, weights, before, after)
        };
        assert_eq!(broken(&before, &before), None);
        let Broken { face, now, .. } = broken(&changed(1), &before).expect("a gradient jump");
        assert_eq!(face, (0, 1));
        assert!(now[0] > 1e-6, "{now:?}");
        let Broken { now, was, .. } = broken(&changed(2), &before).expect("a Hessian jump");
        // The continuation's rounding: weights ~1 through a blossom of 5 arguments.
        assert!(
            now[0] < 1e-12 && now[1] > 1e-6 && was[1] < 1e-12,
            "{now:?} {was:?}"
        );
        assert_eq!(broken(&changed(3), &before), None);
        assert_eq!(broken(&changed(2), &changed(2)), None);
    }

    /// Weights that depend only on the level (λ_3 for a face tetrahedron, λ_2 + λ_3 for an
    /// edge tetrahedron) make F a univariate Bernstein polynomial in the level with those
    /// coefficients, the same on every j-line. Levels 1, −3, 1, 1, 1, 1: F(0) = F(1) = 1 and
    /// F(0.2) ≈ −0.64, two roots on every line; 1, −3, −1, −1, −1, −1: one sign change, one
    /// root (Descartes). A tetrahedron of another role promises no j-lines.
    #[test]
    fn j_sheets_are_two_roots_along_the_j_lines() {
        let mi = multi_indices(5);
        let by_level = |g: [f64; 6], role: Role| -> Vec<f64> {
            mi.iter()
                .map(|l| match role {
                    Role::Edge => g[usize::from(l[2] + l[3])],
                    _ => g[usize::from(l[3])],
                })
                .collect()
        };
        let two = [1.0, -3.0, 1.0, 1.0, 1.0, 1.0];
        let one = [1.0, -3.0, -1.0, -1.0, -1.0, -1.0];
        for role in [Role::Face, Role::Edge] {
            assert!(j_sheeted(&by_level(two, role), role), "{role:?}");
            assert!(!j_sheeted(&by_level(one, role), role), "{role:?}");
        }
        assert!(!j_sheeted(&by_level(two, Role::Face), Role::Vertex));
        // F = g(λ_0) with the first g has roots at λ_0 ≈ 0.066 and 0.409: a j-line of the
        // face tetrahedron runs from the apex (λ_0 = 0) to a base point with λ_0 up to 0.8
        // on the lattice, so some j-lines cross twice; so do the edge tetrahedron's, from its
        // edge of T (local 0–1, λ_0 up to 0.9 on the lattice) to the opposite edge (λ_0 = 0).
        let across: Vec<f64> = mi.iter().map(|l| two[usize::from(l[0])]).collect();
        assert!(j_sheeted(&across, Role::Face));
        assert!(j_sheeted(&across, Role::Edge));
        // With the one-root levels along λ_0, F has one root in λ_0 ∈ [0, 1]: no line of
        // the tetrahedron crosses twice.
        let once: Vec<f64> = mi.iter().map(|l| one[usize::from(l[0])]).collect();
        assert!(!j_sheeted(&once, Role::Face) && !j_sheeted(&once, Role::Edge));
    }

    /// One equation x0 = x1. Hard pins x0 = 1, x1 = −1 contradict it; as targets of equal
    /// weight they meet halfway, x0 = x1 = 0, and the unpinned x2 keeps its value. With x0
    /// pinned to 1 and x1 free (target 0), the weighted closest point is
    /// x0 = x1 = SOFT² / (SOFT² + 1).
    #[test]
    fn soft_pins_meet_the_equations_and_come_closest() {
        let rows = vec![vec![(0, 1.0), (1, -1.0)]];
        let x0 = [0.0, 0.0, 7.0];
        let hard = solve(
            &rows,
            &[0.0],
            &[(0, 1.0), (1, -1.0)],
            3,
            &x0,
            &OnceLock::new(),
        );
        assert!(hard.residual > 0.5, "{hard:?}");
        let s = solve_soft(
            &rows,
            &[0.0],
            &[(0, 1.0), (1, -1.0)],
            3,
            &x0,
            SOFT,
            &OnceLock::new(),
        );
        // Rounding of a 3-unknown QR (entries O(SOFT)).
        assert!(s.residual < 1e-12, "{s:?}");
        assert!(s.x[0].abs() < 1e-12 && s.x[1].abs() < 1e-12, "{s:?}");
        assert!((s.x[2] - 7.0).abs() < 1e-12, "{s:?}");
        let s = solve_soft(&rows, &[0.0], &[(0, 1.0)], 3, &x0, SOFT, &OnceLock::new());
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
        let s = solve_soft(&rows, &[0.0], &[(0, 1.0)], n, &x0, SOFT, &OnceLock::new());
        assert!(
            (s.x[0] - want).abs() < 1e-12 && (s.x[1] - want).abs() < 1e-12,
            "{s:?}"
        );
        assert!((s.x[2] - 7.0).abs() < 1e-12, "{s:?}");
    }

    /// A repair group beyond either factor limit is not factored (the staged solve's
    /// `groups_beyond_the_factor_limits_are_left_unsolved`, for the repair), one within both
    /// is, and a solve without a factor is refused by any residual bound.
    #[test]
    fn repair_groups_beyond_the_factor_limits_are_refused() {
        // A chain x_i - x_{i+1} = 1 over more unknowns than the dense limit.
        let n = super::super::system::DENSE_LIMIT + 10;
        let rows: Vec<Vec<(usize, f64)>> =
            (0..n - 1).map(|i| vec![(i, 1.0), (i + 1, -1.0)]).collect();
        let c = vec![1.0; n - 1];
        let x0 = vec![0.0; n];
        let entries = cholesky::Ordering::of(&rows, n).entries();
        for limits in [(n - 2, entries), (n - 1, entries - 1)] {
            assert!(factored(&rows, &c, n, &x0, limits).is_none(), "{limits:?}");
        }
        let p = factored(&rows, &c, n, &x0, (n - 1, entries)).expect("within both limits");
        let s = p.solve(&rows, &c, &[], None);
        // Unit coefficients, values up to n/2: rounding of the factor's refined solve.
        assert!(s.residual < 1e-9, "{}", s.residual);
        let left = dense::Solution::unsolved(&x0);
        assert!(left.residual.is_infinite() && left.x == x0);
    }

    /// The elevated net of a quintic on a triangle is the same polynomial: evaluated at
    /// interior and edge points its Bernstein sum equals the quintic's, each elevated
    /// coefficient is a convex combination of the weights, and the corners are the corner
    /// weights themselves.
    #[test]
    fn elevated_coefficients_are_the_same_polynomial() {
        let face: Vec<[u8; 3]> = (0..=5u8)
            .flat_map(|a| (0..=5 - a).map(move |b| [a, b, 5 - a - b]))
            .collect();
        // Weights without structure (a fixed pseudo-random sequence).
        let w: Vec<f64> = (0..face.len())
            .map(|i| ((i * 7919 % 23) as f64 - 11.0) / 7.0)
            .collect();
        let fact = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
        let bern = |idx: [usize; 3], l: [f64; 3]| {
            let d = idx.iter().sum::<usize>();
            fact(d) / (fact(idx[0]) * fact(idx[1]) * fact(idx[2]))
                * l[0].powi(idx[0] as i32)
                * l[1].powi(idx[1] as i32)
                * l[2].powi(idx[2] as i32)
        };
        for r in [1, 2, 5] {
            let rows = elevation(&face, r);
            let d = 5 + r;
            assert_eq!(rows.len(), (d + 1) * (d + 2) / 2);
            for (b, row) in &rows {
                assert_eq!(b.iter().sum::<usize>(), d, "r {r}: indices {b:?}");
                let sum: f64 = row.iter().map(|t| t.1).sum();
                // Rational factors summing to one: a few roundings of numbers near 1.
                assert!((sum - 1.0).abs() < 1e-14, "r {r}: row sums to {sum}");
                assert!(row.iter().all(|t| t.1 > 0.0));
                if b.contains(&d) {
                    assert_eq!(row.len(), 1, "a corner is its own weight");
                }
            }
            for l in [
                [0.2, 0.3, 0.5],
                [0.6, 0.4, 0.0],
                [1.0 / 3.0; 3],
                [0.05, 0.9, 0.05],
            ] {
                let f5: f64 = face
                    .iter()
                    .zip(&w)
                    .map(|(a, wi)| wi * bern(a.map(usize::from), l))
                    .sum();
                let fe: f64 = rows
                    .iter()
                    .map(|(b, row)| row.iter().map(|&(i, f)| f * w[i]).sum::<f64>() * bern(*b, l))
                    .sum();
                // Sums of ~60 terms of size ≤ 1.6: rounding well below 1e-12.
                assert!((f5 - fe).abs() < 1e-12, "r {r} at {l:?}: {f5} vs {fe}");
            }
        }
    }
}
