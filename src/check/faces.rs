//! Shared faces: matching tetrahedron faces by their exact vertex coordinates and measuring the
//! jumps of F, ∇F and the Hessian across them; conformity counts.

use super::eval::PatchEval;
use super::{CheckOptions, FaceStats, Location, Measure};
use crate::complex::Patch;
use glam::DVec3;
use rayon::prelude::*;

/// A point's exact identity: the bits of its coordinates (−0 folded into +0).
pub(super) type PointKey = [u64; 3];

/// The key of a point.
pub(super) fn point_key(p: [f64; 3]) -> PointKey {
    p.map(|x| if x == 0.0 { 0.0f64 } else { x }.to_bits())
}

/// One face of one patch, its vertices sorted by key.
struct FaceEntry {
    key: [PointKey; 3],
    patch: u32,
    /// Tetrahedron-local vertex index of each key vertex.
    local: [u8; 3],
}

impl FaceEntry {
    /// The face of patch number `patch` (vertex keys `keys`) opposite its local vertex
    /// `opposite`.
    fn new(keys: &[PointKey; 4], opposite: u8, patch: u32) -> FaceEntry {
        let mut local: Vec<u8> = (0..4u8).filter(|&k| k != opposite).collect();
        local.sort_by_key(|&k| keys[usize::from(k)]);
        let local = [local[0], local[1], local[2]];
        FaceEntry {
            key: local.map(|k| keys[usize::from(k)]),
            patch,
            local,
        }
    }
}

/// The results of [`measure`].
pub(super) struct FaceMeasures {
    pub stats: FaceStats,
    pub value: Measure,
    pub gradient: Measure,
    pub hessian: Measure,
    /// The faces of one patch only: (position in `evals`, the opposite local vertex).
    pub boundary: Vec<(u32, u8)>,
}

/// The worst jumps on one shared face.
#[derive(Default)]
struct Jumps {
    value: Measure,
    gradient: Measure,
    hessian: Measure,
}

impl Jumps {
    fn max(self, o: Jumps) -> Jumps {
        Jumps {
            value: self.value.max(o.value),
            gradient: self.gradient.max(o.gradient),
            hessian: self.hessian.max(o.hessian),
        }
    }
}

/// Finds every face, groups equal ones, measures jumps on faces shared by two patches.
pub(super) fn measure(evals: &[PatchEval<'_>], opts: &CheckOptions) -> FaceMeasures {
    // Collect the four faces of every patch, sorted so equal faces are adjacent.
    let mut entries: Vec<FaceEntry> = evals
        .par_iter()
        .enumerate()
        .flat_map_iter(|(pi, e)| {
            let keys = e.patch.tet.map(point_key);
            (0..4u8).map(move |opposite| FaceEntry::new(&keys, opposite, pi as u32))
        })
        .collect();
    entries.par_sort_unstable_by(|a, b| a.key.cmp(&b.key).then(a.patch.cmp(&b.patch)));

    // Group runs of equal keys.
    let mut groups: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for i in 1..=entries.len() {
        if i == entries.len() || entries[i].key != entries[start].key {
            groups.push((start, i));
            start = i;
        }
    }

    let mut stats = FaceStats::default();
    let mut boundary_faces: Vec<&FaceEntry> = Vec::new();
    let mut shared: Vec<(&FaceEntry, &FaceEntry)> = Vec::new();
    for &(s, e) in &groups {
        match e - s {
            1 => {
                stats.boundary += 1;
                boundary_faces.push(&entries[s]);
            }
            2 => {
                stats.shared += 1;
                shared.push((&entries[s], &entries[s + 1]));
            }
            _ => {
                stats.overshared += 1;
                if stats.overshared_at.is_none() {
                    let f = &entries[s];
                    let group: Vec<&PatchEval<'_>> = entries[s..e]
                        .iter()
                        .map(|f| &evals[f.patch as usize])
                        .collect();
                    stats.overshared_at = Some(Location::new(
                        &group,
                        face_centroid(evals, f).to_array(),
                        None,
                    ));
                }
            }
        }
    }

    let boundary: Vec<(u32, u8)> = boundary_faces
        .iter()
        .map(|f| (f.patch, 6 - f.local.iter().sum::<u8>()))
        .collect();
    let (t_junctions, t_junction_at) = super::tjunction::overlapping_pairs(evals, &boundary);
    stats.t_junctions = t_junctions;
    stats.t_junction_at = t_junction_at;

    let jumps = shared
        .par_iter()
        .map(|(a, b)| face_jumps(evals, a, b, opts))
        .reduce(Jumps::default, Jumps::max);
    FaceMeasures {
        stats,
        value: jumps.value,
        gradient: jumps.gradient,
        hessian: jumps.hessian,
        boundary,
    }
}

/// The worst jumps across the face that patches `a` and `b` share, measured as `apatch check`
/// measures them (the same lattice points, the same scales): value over g·l, gradient over g,
/// Hessian times l over g (g the face's largest gradient, l its longest edge). `None` when the
/// two share no face. For builders that must not make what `check` refuses: the quintic's hole
/// repair asks it of every face its re-solve touches.
#[must_use]
pub fn pair_jumps(a: &Patch, b: &Patch, opts: &CheckOptions) -> Option<[f64; 3]> {
    let (ka, kb) = (a.tet.map(point_key), b.tet.map(point_key));
    let (fa, fb) = (0..4u8)
        .flat_map(|oa| (0..4u8).map(move |ob| (oa, ob)))
        .map(|(oa, ob)| (FaceEntry::new(&ka, oa, 0), FaceEntry::new(&kb, ob, 1)))
        .find(|(fa, fb)| fa.key == fb.key)?;
    let evals = [PatchEval::new(a, 0), PatchEval::new(b, 1)];
    let j = face_jumps(&evals, &fa, &fb, opts);
    Some([j.value.worst, j.gradient.worst, j.hessian.worst])
}

fn face_points(evals: &[PatchEval<'_>], f: &FaceEntry) -> [DVec3; 3] {
    let t = &evals[f.patch as usize].patch.tet;
    f.local.map(|k| DVec3::from_array(t[usize::from(k)]))
}

fn face_centroid(evals: &[PatchEval<'_>], f: &FaceEntry) -> DVec3 {
    let p = face_points(evals, f);
    (p[0] + p[1] + p[2]) / 3.0
}

/// Samples the interior lattice points of the face and measures the jumps there.
fn face_jumps(evals: &[PatchEval<'_>], a: &FaceEntry, b: &FaceEntry, opts: &CheckOptions) -> Jumps {
    let ea = &evals[a.patch as usize];
    let eb = &evals[b.patch as usize];
    let pts = face_points(evals, a);
    let l = (pts[0].distance(pts[1]))
        .max(pts[1].distance(pts[2]))
        .max(pts[2].distance(pts[0]));
    let degree = usize::from(ea.patch.degree.max(eb.patch.degree));
    let m = opts.face_resolution.max(degree + 2).max(3);

    // Evaluate both sides at each sample (exact barycentrics from the face's local indices).
    let mut samples = Vec::with_capacity((m - 1) * (m - 2) / 2);
    for i in 1..m {
        for j in 1..m - i {
            let k = m - i - j;
            let s = [i, j, k].map(|x| x as f64 / m as f64);
            let mut alpha_a = [0.0; 4];
            let mut alpha_b = [0.0; 4];
            for v in 0..3 {
                alpha_a[usize::from(a.local[v])] = s[v];
                alpha_b[usize::from(b.local[v])] = s[v];
            }
            let x = s[0] * pts[0] + s[1] * pts[1] + s[2] * pts[2];
            samples.push((x, ea.world_jet(alpha_a), eb.world_jet(alpha_b)));
        }
    }

    // The face's gradient scale.
    let mut g = samples.iter().fold(0.0f64, |g, (_, ja, jb)| {
        g.max(ja.grad.length()).max(jb.grad.length())
    });
    if g == 0.0 {
        g = ea.weight_scale().max(eb.weight_scale()) / l;
    }
    if g == 0.0 || !g.is_finite() {
        g = 1.0;
    }

    // Worst sample of each measure (first on ties; NaN counts as worst).
    let mut worst = [(0.0f64, 0usize); 3];
    for (idx, (_, ja, jb)) in samples.iter().enumerate() {
        let dv = (ja.value - jb.value).abs() / (g * l);
        let dg = (ja.grad - jb.grad).length() / g;
        let dh = (ja.hess - jb.hess)
            .to_cols_array()
            .iter()
            .map(|d| d * d)
            .sum::<f64>()
            .sqrt()
            * l
            / g;
        for (w, d) in worst.iter_mut().zip([dv, dg, dh]) {
            if d > w.0 || (d.is_nan() && !w.0.is_nan()) {
                *w = (d, idx);
            }
        }
    }
    let measure = |(d, idx): (f64, usize)| Measure {
        worst: d,
        samples: samples.len(),
        at: Some(Location::new(&[ea, eb], samples[idx].0.to_array(), None)),
    };
    Jumps {
        value: measure(worst[0]),
        gradient: measure(worst[1]),
        hessian: measure(worst[2]),
    }
}
