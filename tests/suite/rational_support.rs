//! Shared test support for the rational C¹ scheme: generated meshes and measurements
//! (used by the `rational_*` modules as `support`; has no tests of its own).
#![allow(dead_code)]

use apatch::complex::{Patch, PatchComplex, Role, SheetRule};
use apatch::scheme::rational_c1::eval::value_gradient;
use apatch::scheme::rational_c1::RationalBuild;
use glam::DVec3;
use std::collections::HashMap;

/// A mesh with normals.
pub struct Model {
    pub name: &'static str,
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Vec<DVec3>,
}

pub use apatch::fixtures::{icosahedron, subdivide_sphere};

pub fn sphere_model(name: &'static str, levels: usize) -> Model {
    let (v, f) = icosahedron();
    let (v, f) = subdivide_sphere(&v, &f, levels);
    Model {
        name,
        normals: v.clone(),
        positions: v,
        triangles: f,
    }
}

pub fn octahedron() -> Model {
    let (v, f) = apatch::fixtures::octahedron();
    Model {
        name: "octahedron",
        normals: v.clone(),
        positions: v,
        triangles: f,
    }
}

/// Angle-weighted vertex normals.
pub fn angle_normals(v: &[DVec3], f: &[[u32; 3]]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; v.len()];
    for t in f {
        let fnrm = (v[t[1] as usize] - v[t[0] as usize])
            .cross(v[t[2] as usize] - v[t[0] as usize])
            .normalize();
        for c in 0..3 {
            let p = v[t[c] as usize];
            let a = (v[t[(c + 1) % 3] as usize] - p).normalize();
            let b = (v[t[(c + 2) % 3] as usize] - p).normalize();
            n[t[c] as usize] += fnrm * a.dot(b).clamp(-1.0, 1.0).acos();
        }
    }
    n.iter().map(|x| x.normalize()).collect()
}

/// A seeded noisy sphere (subdivided icosahedron with radial noise), angle-weighted normals.
pub fn noisy_sphere(levels: usize, amp: f64, seed: u64) -> Model {
    let (v, f) = icosahedron();
    let (mut v, f) = subdivide_sphere(&v, &f, levels);
    let mut s = seed;
    for p in &mut v {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let r = ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
        *p *= 1.0 + amp * r;
    }
    let n = angle_normals(&v, &f);
    Model {
        name: "noisy sphere",
        positions: v,
        triangles: f,
        normals: n,
    }
}

/// Torus (R, r) with m × k quads split into triangles, exact normals.
pub fn torus(big: f64, small: f64, m: usize, k: usize) -> Model {
    let (v, f, n) = apatch::fixtures::torus(big, small, m, k);
    Model {
        name: "torus",
        positions: v,
        triangles: f,
        normals: n,
    }
}

/// The two-triangle examples of §6 (Figs. 6, 7, 9, 10).
pub fn paper_example(fig: u32) -> Model {
    let p1 = DVec3::new(-2.0, 0.0, 0.0);
    let p2 = DVec3::new(2.0, 0.0, 0.0);
    let p3 = DVec3::new(0.0, 4.0, -1.0);
    let (p4, n): (DVec3, [[f64; 3]; 4]) = match fig {
        6 => (
            DVec3::new(0.0, -4.0, -1.0),
            [
                [-1.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [0.0, 1.0, 1.0],
                [0.0, -1.0, 1.0],
            ],
        ),
        7 => (
            DVec3::new(0.0, -4.0, -1.0),
            [
                [-1.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [0.0, 1.0, 1.5],
                [0.0, 1.0, 1.5],
            ],
        ),
        9 => (
            DVec3::new(0.0, -4.0, -1.0),
            [
                [1.0, 0.0, 1.0],
                [1.0, 0.0, 1.0],
                [0.0, -1.0, 1.5],
                [0.0, 1.0, 1.5],
            ],
        ),
        _ => (
            DVec3::new(0.0, -4.0, 0.0),
            [
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0],
                [0.0, -1.0, 1.5],
                [0.0, 0.0, 1.0],
            ],
        ),
    };
    Model {
        name: "paper",
        positions: vec![p1, p2, p3, p4],
        triangles: vec![[0, 1, 2], [1, 0, 3]],
        normals: n
            .iter()
            .map(|a| DVec3::from_array(*a).normalize())
            .collect(),
    }
}

/// Largest relative jumps of F and ∇F across shared tetrahedron faces, and the largest number
/// of patches sharing one face.
pub struct Continuity {
    pub shared_faces: usize,
    pub max_value_jump: f64,
    pub max_grad_jump: f64,
    pub max_sharing: usize,
}

/// The one-line summary the rational tests print for a build: sizes, face and edge classes,
/// refinements, interpolation errors `(value, gradient)`, continuity, and the number of
/// shooting lines with the smallest root slope `(lines, slope)` found on them.
pub fn build_summary(
    name: &str,
    b: &RationalBuild,
    interp: (f64, f64),
    cont: &Continuity,
    roots: (usize, f64),
) -> String {
    let ((fv, gv), (lines, slope)) = (interp, roots);
    format!(
        "{name}: {} tris, {} patches, classes {:?}, edges {:?}, refined {}, promoted {}, raised {}, \
         interp {fv:.1e}/{gv:.1e}, shared {} jumps {:.1e}/{:.1e}, sharing {}, roots {lines} min slope {slope:.2e}",
        b.triangles.len(),
        b.complex.patches.len(),
        b.faces_by_class,
        b.edges_by_class,
        b.refined_edges,
        b.promoted_faces,
        b.raised_faces,
        cont.shared_faces,
        cont.max_value_jump,
        cont.max_grad_jump,
        cont.max_sharing
    )
}

fn key(p: [f64; 3]) -> [u64; 3] {
    p.map(f64::to_bits)
}

pub fn continuity(c: &PatchComplex, samples: usize) -> Continuity {
    let mut map: HashMap<[[u64; 3]; 3], Vec<usize>> = HashMap::new();
    for (k, p) in c.patches.iter().enumerate() {
        for skip in 0..4 {
            let mut f: Vec<[u64; 3]> = (0..4)
                .filter(|&i| i != skip)
                .map(|i| key(p.tet[i]))
                .collect();
            f.sort();
            map.entry([f[0], f[1], f[2]]).or_default().push(k);
        }
    }
    let mut out = Continuity {
        shared_faces: 0,
        max_value_jump: 0.0,
        max_grad_jump: 0.0,
        max_sharing: 0,
    };
    for (face, ps) in &map {
        out.max_sharing = out.max_sharing.max(ps.len());
        if ps.len() != 2 {
            continue;
        }
        out.shared_faces += 1;
        let v = face.map(|k| {
            DVec3::new(
                f64::from_bits(k[0]),
                f64::from_bits(k[1]),
                f64::from_bits(k[2]),
            )
        });
        let (a, b) = (&c.patches[ps[0]], &c.patches[ps[1]]);
        let scale = (v[1] - v[0]).length().max((v[2] - v[0]).length());
        for i in 1..samples {
            for j in 1..samples - i {
                let (x, y) = (i as f64 / samples as f64, j as f64 / samples as f64);
                let p = v[0] * (1.0 - x - y) + v[1] * x + v[2] * y;
                let (fa, ga) = value_gradient(a, p);
                let (fb, gb) = value_gradient(b, p);
                let gs = ga.length().max(gb.length()).max(1e-300);
                out.max_value_jump = out.max_value_jump.max((fa - fb).abs() / (gs * scale));
                out.max_grad_jump = out.max_grad_jump.max((ga - gb).length() / gs);
            }
        }
    }
    out
}

/// Largest |F(p_v)|/|∇F| and |∇F/|∇F| − n_v| over every patch having a mesh vertex as a corner.
pub fn interpolation(c: &PatchComplex) -> (f64, f64) {
    let verts: HashMap<[u64; 3], usize> = c
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| (key(*v), i))
        .collect();
    let (mut fv, mut gv) = (0.0f64, 0.0f64);
    for p in &c.patches {
        if p.role == Role::Planar {
            continue;
        }
        for corner in p.tet {
            if let Some(&i) = verts.get(&key(corner)) {
                let x = DVec3::from_array(corner);
                let (f, g) = value_gradient(p, x);
                let n = DVec3::from_array(c.normals[i]);
                fv = fv.max(f.abs() / g.length());
                gv = gv.max((g.normalize() - n).length());
            }
        }
    }
    (fv, gv)
}

/// The shooting cubic (Bernstein coefficients) of a patch along base → top, from exact values
/// at t = 0, 1/3, 2/3, 1 (the restriction is a cubic: rational terms are constant along it).
pub fn shooting_cubic(p: &Patch, q: DVec3, top: DVec3) -> [f64; 4] {
    let f = |t: f64| value_gradient(p, q * (1.0 - t) + top * t).0;
    let (v0, v1, v2, v3) = (f(1e-300f64.max(0.0)), f(1.0 / 3.0), f(2.0 / 3.0), f(1.0));
    // Solve the Bernstein interpolation at 0, 1/3, 2/3, 1.
    let c0 = v0;
    let c3 = v3;
    // v1 = (8c0 + 12c1 + 6c2 + c3)/27, v2 = (c0 + 6c1 + 12c2 + 8c3)/27
    let r1 = 27.0 * v1 - 8.0 * c0 - c3;
    let r2 = 27.0 * v2 - c0 - 8.0 * c3;
    let c1 = (12.0 * r1 - 6.0 * r2) / 108.0;
    let c2 = (12.0 * r2 - 6.0 * r1) / 108.0;
    [c0, c1, c2, c3]
}

/// Minimum over sampled shooting lines of the face and edge patches of the slope |P'| at the
/// selected (minimal) root relative to the coefficient scale; lines whose base value has the
/// top's sign are not this patch's. Returns (lines with a root, minimum slope).
pub fn min_root_slope(c: &PatchComplex, n: usize) -> (usize, f64) {
    let mut count = 0;
    let mut slope = f64::INFINITY;
    for p in &c.patches {
        let SheetRule::Shooting { base, top } = &p.sheet else {
            continue;
        };
        let t = p.tet_points();
        let mut lines: Vec<(DVec3, DVec3)> = Vec::new();
        if base.len() == 3 {
            for i in 0..=n {
                for j in 0..=n - i {
                    let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
                    let q = t[base[0] as usize] * a
                        + t[base[1] as usize] * b
                        + t[base[2] as usize] * (1.0 - a - b);
                    lines.push((q, t[top[0] as usize]));
                }
            }
        } else {
            for i in 0..=n {
                for j in 0..=n {
                    let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                    let q = t[base[0] as usize] * x + t[base[1] as usize] * (1.0 - x);
                    let u = t[top[0] as usize] * y + t[top[1] as usize] * (1.0 - y);
                    lines.push((q, u));
                }
            }
        }
        for (q, u) in lines {
            let cf = shooting_cubic(p, q, u);
            if cf[0] * cf[3] > 0.0 {
                continue;
            }
            if let Some((_, s)) = apatch::scheme::rational_c1::bound::minimal_root_slope(cf) {
                count += 1;
                slope = slope.min(s);
            }
        }
    }
    (count, slope)
}
