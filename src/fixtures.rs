//! Test complexes built from one global polynomial: the independent truth for the checker and
//! the tracer (every shared face is exactly continuous, hits have analytic answers).

use crate::bb::{multi_indices, num_coeffs};
use crate::complex::{Patch, PatchComplex, Role, SheetRule};
use crate::hull::simplicial::{Side, SimplicialHull};
use glam::{DMat3, DVec3};

/// One splitmix64 step: a seeded, reproducible uniform number in [0, 1) (the top 53 bits),
/// for tests and benches that need deterministic random samples without a generator crate.
pub fn splitmix(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// A uniformly distributed unit vector from [`splitmix`]: rejection sampling in the unit ball
/// (points too near the centre are rejected too, so normalising them is well conditioned).
pub fn random_unit(state: &mut u64) -> DVec3 {
    loop {
        let v = DVec3::new(splitmix(state), splitmix(state), splitmix(state)) * 2.0 - 1.0;
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// A tiny seeded generator for reproducible random test geometry: a 64-bit linear
/// congruential generator (Knuth's MMIX constants) whose top 53 bits give the sample.
#[derive(Clone, Debug)]
pub struct Lcg(pub u64);

impl Lcg {
    /// The next uniform number in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A quadric F(x) = xᵀ A x + bᵀ x + c (A symmetric).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Symmetric matrix A.
    pub a: DMat3,
    /// Linear part b.
    pub b: DVec3,
    /// Constant c.
    pub c: f64,
}

impl Quadric {
    /// The sphere |x − center|² − r² (negative inside).
    #[must_use]
    pub fn sphere(center: DVec3, r: f64) -> Self {
        Quadric {
            a: DMat3::IDENTITY,
            b: -2.0 * center,
            c: center.length_squared() - r * r,
        }
    }

    /// The axis-aligned ellipsoid Σ ((x_i − c_i)/r_i)² − 1 (negative inside).
    #[must_use]
    pub fn ellipsoid(center: DVec3, radii: DVec3) -> Self {
        let d = DVec3::ONE / (radii * radii);
        Quadric {
            a: DMat3::from_diagonal(d),
            b: -2.0 * d * center,
            c: (d * center * center).element_sum() - 1.0,
        }
    }

    /// F(x).
    #[must_use]
    pub fn value(&self, x: DVec3) -> f64 {
        x.dot(self.a * x) + self.b.dot(x) + self.c
    }

    /// ∇F(x) = 2 A x + b.
    #[must_use]
    pub fn gradient(&self, x: DVec3) -> DVec3 {
        2.0 * (self.a * x) + self.b
    }

    /// The degree-`n` blossom (n ≥ 2) of F at the points `args`: the symmetric multi-affine
    /// form whose diagonal is F. For n = 2, B(x, y) = xᵀAy + bᵀ(x+y)/2 + c; in general the
    /// quadratic part averages over all pairs and the linear part over all points.
    #[must_use]
    pub fn blossom(&self, args: &[DVec3]) -> f64 {
        let n = args.len();
        assert!(n >= 2, "a quadric needs a blossom of degree ≥ 2");
        let mut quad = 0.0;
        for i in 0..n {
            for j in i + 1..n {
                quad += args[i].dot(self.a * args[j]);
            }
        }
        let pairs = (n * (n - 1) / 2) as f64;
        let lin: f64 = args.iter().map(|x| self.b.dot(*x)).sum::<f64>() / n as f64;
        quad / pairs + lin + self.c
    }
}

/// BB weights of degree `n` (≥ 2) of the quadric on tetrahedron `tet`: w_λ = blossom at
/// (v1 λ1 times, v2 λ2 times, …).
#[must_use]
pub fn quadric_weights(q: &Quadric, tet: &[DVec3; 4], n: usize) -> Vec<f64> {
    let mut w = Vec::with_capacity(num_coeffs(n));
    let mut args = Vec::with_capacity(n);
    for l in multi_indices(n) {
        args.clear();
        for (k, &m) in l.iter().enumerate() {
            args.extend(std::iter::repeat_n(tet[k], m as usize));
        }
        w.push(q.blossom(&args));
    }
    w
}

/// The unit tetrahedron: the origin and the three unit points, the reference simplex of tests.
pub const UNIT_TET: [DVec3; 4] = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];

/// A plain polynomial patch: BB `weights` of `degree` on `tet`, no rational terms, any sheet,
/// role `Other`, element 0, no j-vertex or j-edge (the patch tests build by hand; set other
/// fields with struct update syntax).
#[must_use]
pub fn plain_patch(tet: [DVec3; 4], degree: usize, weights: Vec<f64>) -> Patch {
    Patch {
        tet: tet.map(|v| v.to_array()),
        degree: u8::try_from(degree).expect("patch degree fits in u8"),
        weights,
        rational: Vec::new(),
        sheet: SheetRule::Any,
        role: Role::Other,
        element: 0,
        jvertex: None,
        jedge: None,
    }
}

/// The quadric as a plain patch of degree `n` (≥ 2) on `tet`: exact, with
/// [`quadric_weights`].
#[must_use]
pub fn quadric_patch(q: &Quadric, tet: [DVec3; 4], n: usize) -> Patch {
    plain_patch(tet, n, quadric_weights(q, &tet, n))
}

/// The six tetrahedra of the Kuhn subdivision of the cube [lo, hi]: they share faces exactly
/// with the neighbouring cubes' tetrahedra, so a grid of cubes is a conforming complex.
#[must_use]
pub fn kuhn_tets(lo: DVec3, hi: DVec3) -> [[DVec3; 4]; 6] {
    let corner = |bits: [bool; 3]| {
        DVec3::new(
            if bits[0] { hi.x } else { lo.x },
            if bits[1] { hi.y } else { lo.y },
            if bits[2] { hi.z } else { lo.z },
        )
    };
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    PERMS.map(|p| {
        let mut bits = [false; 3];
        let v0 = corner(bits);
        bits[p[0]] = true;
        let v1 = corner(bits);
        bits[p[1]] = true;
        let v2 = corner(bits);
        bits[p[2]] = true;
        let v3 = corner(bits);
        [v0, v1, v2, v3]
    })
}

/// A complex representing the quadric `q` exactly on the box [lo, hi] split into `cells`³
/// cubes of six tetrahedra each, with degree-`degree` weights (≥ 2). Every shared face is
/// continuous to rounding, so it is the checker's and the tracer's reference.
#[must_use]
pub fn quadric_complex(
    q: &Quadric,
    lo: DVec3,
    hi: DVec3,
    cells: usize,
    degree: usize,
) -> PatchComplex {
    let mut c = PatchComplex::new("test-quadric");
    let step = (hi - lo) / cells as f64;
    let mut element = 0u32;
    for i in 0..cells {
        for j in 0..cells {
            for k in 0..cells {
                // Grid coordinates from one formula, so neighbouring cubes share corners
                // bit for bit (a.x + step.x would differ from the next cube's a.x by rounding).
                let coord = |lo: f64, hi: f64, step: f64, i: usize| {
                    if i == cells {
                        hi
                    } else {
                        lo + step * i as f64
                    }
                };
                let a = DVec3::new(
                    coord(lo.x, hi.x, step.x, i),
                    coord(lo.y, hi.y, step.y, j),
                    coord(lo.z, hi.z, step.z, k),
                );
                let bb = DVec3::new(
                    coord(lo.x, hi.x, step.x, i + 1),
                    coord(lo.y, hi.y, step.y, j + 1),
                    coord(lo.z, hi.z, step.z, k + 1),
                );
                for tet in kuhn_tets(a, bb) {
                    c.patches.push(Patch {
                        element,
                        ..quadric_patch(q, tet, degree)
                    });
                }
                element += 1;
            }
        }
    }
    c
}

/// A mesh through the 2001 rational C¹ scheme as the tests build it: triangulated, with
/// angle-weighted vertex normals of the input faces and default options. Returns the
/// triangulation, its triangles and the build.
///
/// # Panics
/// When the normals or the scheme fail (fixtures are known-good meshes).
#[must_use]
pub fn rational_angle_build(
    m: &crate::mesh::Mesh,
) -> (
    crate::mesh::Mesh,
    Vec<[u32; 3]>,
    crate::scheme::rational_c1::RationalBuild,
) {
    use crate::mesh::{triangulate, vertex_normals, NormalMethod};
    use crate::scheme::rational_c1::{build, RationalOptions};
    let tri = triangulate(m);
    let normals = vertex_normals(m, NormalMethod::Angle).expect("angle normals");
    let triangles: Vec<[u32; 3]> = tri.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    let b = build(
        &tri.positions,
        &triangles,
        &normals,
        &RationalOptions::default(),
    )
    .expect("the rational scheme builds");
    (tri, triangles, b)
}

/// The regular octahedron on the unit axes: 6 vertices (±x, ±y, ±z in that order), 8
/// triangles oriented outward. Its vertices are also its exact sphere normals.
#[must_use]
pub fn octahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let v = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let f = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (v, f)
}

/// Unit normals of a sphere-like mesh on the unit sphere, `v`, tilted away from the radial
/// direction by `tilt` along a deterministic per-vertex direction: normals the schemes must
/// interpolate without being handed the exact sphere (tilt 0 gives the normalised positions).
#[must_use]
pub fn tilted_normals(v: &[DVec3], tilt: f64) -> Vec<DVec3> {
    v.iter()
        .enumerate()
        .map(|(i, x)| {
            let i = i as f64;
            (*x + tilt * DVec3::new(i.sin(), (2.0 * i).cos(), 0.3)).normalize()
        })
        .collect()
}

/// The regular icosahedron inscribed in the unit sphere: 12 vertices, 20 triangles oriented
/// outward (counter-clockwise seen from outside). Test meshes for every scheme start here.
#[must_use]
pub fn icosahedron() -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let v: Vec<DVec3> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .iter()
    .map(|a| DVec3::from_array(*a).normalize())
    .collect();
    let f = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    (v, f)
}

/// 1→4 subdivision of a unit-sphere triangulation `levels` times, new (edge-midpoint) vertices
/// projected to the sphere.
#[must_use]
pub fn subdivide_sphere(v: &[DVec3], f: &[[u32; 3]], levels: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut v = v.to_vec();
    let mut f = f.to_vec();
    for _ in 0..levels {
        let mut mid: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        let mut nf = Vec::with_capacity(f.len() * 4);
        let mut m = |a: u32, b: u32, v: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((v[a as usize] + v[b as usize]).normalize());
                (v.len() - 1) as u32
            })
        };
        for t in &f {
            let ab = m(t[0], t[1], &mut v);
            let bc = m(t[1], t[2], &mut v);
            let ca = m(t[2], t[0], &mut v);
            nf.push([t[0], ab, ca]);
            nf.push([t[1], bc, ab]);
            nf.push([t[2], ca, bc]);
            nf.push([ab, bc, ca]);
        }
        f = nf;
    }
    (v, f)
}

/// The torus of radii (`big`, `small`) about the z axis, sampled on an m × k grid of quads split
/// into outward-oriented triangles: (positions, triangles, exact unit normals).
#[must_use]
pub fn torus(big: f64, small: f64, m: usize, k: usize) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<DVec3>) {
    let mut v = Vec::new();
    let mut n = Vec::new();
    for i in 0..m {
        let u = i as f64 / m as f64 * std::f64::consts::TAU;
        for j in 0..k {
            let w = j as f64 / k as f64 * std::f64::consts::TAU;
            let dir = DVec3::new(u.cos(), u.sin(), 0.0);
            let nn = dir * w.cos() + DVec3::Z * w.sin();
            v.push(dir * big + nn * small);
            n.push(nn);
        }
    }
    let id = |i: usize, j: usize| ((i % m) * k + (j % k)) as u32;
    let mut f = Vec::new();
    for i in 0..m {
        for j in 0..k {
            f.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, f, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blossom_diagonal_is_value() {
        let q = Quadric::ellipsoid(DVec3::new(0.1, -0.2, 0.3), DVec3::new(1.0, 2.0, 0.5));
        let x = DVec3::new(0.7, -1.1, 0.25);
        for n in 2..=7 {
            let v = q.blossom(&vec![x; n]);
            // Rounding only: a handful of products of O(1) numbers.
            assert!(
                (v - q.value(x)).abs() < 1e-13,
                "n={n}: {v} vs {}",
                q.value(x)
            );
        }
    }

    #[test]
    fn kuhn_tets_fill_the_cube() {
        let tets = kuhn_tets(DVec3::ZERO, DVec3::ONE);
        let vol: f64 = tets
            .iter()
            .map(|t| ((t[1] - t[0]).cross(t[2] - t[0]).dot(t[3] - t[0]) / 6.0).abs())
            .sum();
        // Six tets of volume 1/6 each; 1/6 is inexact in binary, so allow a few ulps.
        assert!((vol - 1.0).abs() < 1e-15, "{vol}");
    }
}

/// The inner simplicial hull of a convex polyhedron whose vertices are all trihedral (cube,
/// tetrahedron, dodecahedron), by Algorithm 1 step (3) of the 1994 paper alone: T has one
/// vertex per face (its centroid, with the face normal) and one triangle per polyhedron vertex
/// (the centroids of its three faces), whose face tetrahedron has the polyhedron vertex as its
/// outer apex. A test hull for the schemes, independent of `hull::inner`.
///
/// # Panics
/// If a vertex is not trihedral or a face is degenerate (test input only).
#[must_use]
pub fn trihedral_hull(mesh: &crate::mesh::Mesh) -> crate::hull::simplicial::SimplicialHull {
    use crate::hull::simplicial::{PointOrigin, SimplicialHull};
    let mut hull = SimplicialHull::default();
    for (f, face) in mesh.faces.iter().enumerate() {
        let p: Vec<DVec3> = face.iter().map(|&v| mesh.positions[v as usize]).collect();
        let c = p.iter().copied().sum::<DVec3>() / p.len() as f64;
        let n = (1..p.len() - 1)
            .map(|k| (p[k] - p[0]).cross(p[k + 1] - p[0]))
            .sum::<DVec3>()
            .normalize();
        assert!(n.is_finite(), "degenerate face {f}");
        hull.points.push(c);
        hull.normals.push(n);
        hull.origins.push(PointOrigin::Centroid { face: f as u32 });
    }
    for (v, &pv) in mesh.positions.iter().enumerate() {
        let around: Vec<u32> = (0..mesh.faces.len() as u32)
            .filter(|&f| mesh.faces[f as usize].contains(&(v as u32)))
            .collect();
        assert_eq!(around.len(), 3, "vertex {v} is not trihedral");
        let [a, b, c] = [around[0], around[1], around[2]];
        let [pa, pb, pc] = [a, b, c].map(|i| hull.points[i as usize]);
        let outward = (pb - pa).cross(pc - pa).dot(pv - (pa + pb + pc) / 3.0) > 0.0;
        hull.triangles
            .push(if outward { [a, b, c] } else { [a, c, b] });
        hull.apexes.push([Some(pv), None]);
        hull.element.push(v as u32);
    }
    hull
}

#[cfg(test)]
mod hull_tests {
    use super::*;

    /// The cube's trihedral hull: T is an octahedron (6 centroids, 8 triangles, 12 edges), closed,
    /// with 24 edge tetrahedra (a pair per cube edge) on the outer side.
    #[test]
    fn cube_trihedral_hull_is_an_octahedron() {
        let (m, _) = crate::mesh::load(std::path::Path::new("scenes/models/cube.obj")).unwrap();
        let hull = trihedral_hull(&m);
        assert_eq!((hull.points.len(), hull.triangles.len()), (6, 8));
        let edges = hull.edges().unwrap();
        assert_eq!(edges.len(), 12);
        assert!(edges.iter().all(|e| e.faces[1] != u32::MAX));
        assert_eq!(hull.edge_tets().unwrap().len(), 24);
        // Every face tetrahedron has positive orientation: the apex lies on the outer side.
        for t in 0..8 {
            let [a, b, c, q] = hull
                .face_tet(t, crate::hull::simplicial::Side::Outer)
                .unwrap();
            assert!((b - a).cross(c - a).dot(q - a) > 0.0);
        }
    }
}

/// A torus of `nu` × `nv` planar quads (isosceles trapezoids between meridians and parallels;
/// radii 1 and 0.4), loaded through the validating pipeline so it is oriented outward: both
/// convex and saddle-shaped valence-4 corners, genus 1. A polygon model for the 1994 schemes.
///
/// # Panics
/// Never for `nu, nv ≥ 3` (the mesh is valid by construction).
#[must_use]
pub fn quad_torus(nu: usize, nv: usize) -> crate::mesh::Mesh {
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let a = std::f64::consts::TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let b = std::f64::consts::TAU * j as f64 / nv as f64;
            let r = 1.0 + 0.4 * b.cos();
            positions.push(DVec3::new(r * a.cos(), r * a.sin(), 0.4 * b.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let faces: Vec<Vec<u32>> = (0..nu)
        .flat_map(|i| {
            (0..nv).map(move |j| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    crate::mesh::from_polygons(positions, faces)
        .expect("a valid torus")
        .0
}

/// Writes `mesh` as an OBJ and a small `cubic-c1` scene (8×8 camera looking at `target`) with the
/// extra `[scheme]` lines `scheme` into a fresh directory `prefix_<pid>_<name>` under the system's
/// temporary directory; returns the scene's path. For tests that run the CLI or the scene loader
/// on a generated polyhedron.
pub fn write_cubic_scene(
    prefix: &str,
    name: &str,
    mesh: &crate::mesh::Mesh,
    scheme: &str,
    target: [f64; 3],
) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("{prefix}_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut obj = String::new();
    for p in &mesh.positions {
        obj.push_str(&format!("v {:.17} {:.17} {:.17}\n", p.x, p.y, p.z));
    }
    for f in &mesh.faces {
        let idx: Vec<String> = f.iter().map(|v| (v + 1).to_string()).collect();
        obj.push_str(&format!("f {}\n", idx.join(" ")));
    }
    std::fs::write(dir.join("m.obj"), obj).unwrap();
    let [tx, ty, tz] = target;
    let scene = format!(
        "[model]\nfile = \"m.obj\"\nnormals = \"angle\"\n[scheme]\ntype = \"cubic-c1\"\n{scheme}\n\
         [camera]\norigin = [4, 3, 5]\ntarget = [{tx}, {ty}, {tz}]\nfov = 30\nwidth = 8\nheight = 8\n\
         [[lights]]\ntype = \"directional\"\ndirection = [-1, -1, -1]\nirradiance = 2.0\n"
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    path
}

/// What the sign threshold of [`crossed_boundary_faces`] is a share of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SignScale {
    /// The largest |weight| of the patch itself.
    Patch,
    /// The largest |weight| of the whole complex.
    Complex,
}

/// Boundary faces of `c` (faces of one patch only, matched by the bits of their corners) on
/// which F takes both signs at the points of a lattice of `steps` steps per edge (barycentric
/// i/steps): values above `share` × the largest |weight| (of the patch or of the complex,
/// `scale`) count as positive, below its negative as negative. A sampling test (the checker's
/// hole certificate is `check`'s); returns the crossed faces as (patch, opposite corner) and
/// the complex's largest |weight|.
pub fn crossed_boundary_faces(
    c: &PatchComplex,
    steps: usize,
    share: f64,
    scale: SignScale,
) -> (Vec<(usize, usize)>, f64) {
    let face_key = |p: &Patch, opp: usize| {
        let mut f: Vec<[u64; 3]> = (0..4)
            .filter(|&k| k != opp)
            .map(|k| p.tet[k].map(f64::to_bits))
            .collect();
        f.sort_unstable();
        [f[0], f[1], f[2]]
    };
    let mut users: std::collections::HashMap<[[u64; 3]; 3], usize> =
        std::collections::HashMap::new();
    for p in &c.patches {
        for opp in 0..4 {
            *users.entry(face_key(p, opp)).or_insert(0) += 1;
        }
    }
    let largest = |p: &Patch| p.weights.iter().fold(0.0_f64, |a, w| a.max(w.abs()));
    let wmax = c.patches.iter().map(largest).fold(0.0_f64, f64::max);
    let mut crossed = Vec::new();
    for (k, p) in c.patches.iter().enumerate() {
        let tol = share
            * match scale {
                SignScale::Patch => largest(p),
                SignScale::Complex => wmax,
            };
        for opp in 0..4 {
            if users[&face_key(p, opp)] != 1 {
                continue;
            }
            if face_takes_both_signs(p, opp, steps, tol) {
                crossed.push((k, opp));
            }
        }
    }
    (crossed, wmax)
}

/// Whether F of `p` takes both strict signs (beyond ±`tol`) at the points of a lattice of
/// `steps` steps per edge (barycentric i/steps) on the face opposite its corner `opp`.
#[must_use]
pub fn face_takes_both_signs(p: &Patch, opp: usize, steps: usize, tol: f64) -> bool {
    let others: Vec<usize> = (0..4).filter(|&x| x != opp).collect();
    let (mut pos, mut neg) = (false, false);
    for i in 0..=steps {
        for j in 0..=steps - i {
            let mut b = [0.0; 4];
            b[others[0]] = i as f64 / steps as f64;
            b[others[1]] = j as f64 / steps as f64;
            b[others[2]] = (steps - i - j) as f64 / steps as f64;
            let f = p.value_bary(b);
            pos |= f > tol;
            neg |= f < -tol;
        }
    }
    pos && neg
}

#[cfg(test)]
mod crossed_tests {
    use super::*;

    /// Two linear patches sharing the face opposite corner 3 of the first: the shared face
    /// is no boundary face; the other faces are crossed exactly where they hold corners of
    /// both signs. The weight 1e-3 on the second patch is a sign at the patch's own scale but
    /// below 1e-2 of the complex's largest weight.
    #[test]
    fn crossed_boundary_faces_by_hand() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let mut c = PatchComplex::new("test-crossed");
        c.patches.push(plain_patch(t, 1, vec![1.0, -1.0, 1.0, 1.0]));
        // Mirror of the first through the plane z = 0: shares corners 0, 1, 2.
        let u = [DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::Z];
        c.patches
            .push(plain_patch(u, 1, vec![1e-3, 1e-3, 1e-3, -1e-3]));
        let (mut got, wmax) = crossed_boundary_faces(&c, 4, 1e-2, SignScale::Patch);
        got.sort_unstable();
        assert_eq!(wmax, 1.0);
        // Patch 0: faces opposite 0 and 2 hold corner 1 (negative) and a positive corner; the
        // face opposite 3 is shared; the face opposite 1 is all positive. Patch 1: every
        // boundary face holds corner 3 (negative) and a positive corner.
        assert_eq!(got, vec![(0, 0), (0, 2), (1, 0), (1, 1), (1, 2)]);
        let (mut got, _) = crossed_boundary_faces(&c, 4, 1e-2, SignScale::Complex);
        got.sort_unstable();
        assert_eq!(got, vec![(0, 0), (0, 2)]);
    }
}

/// The smallest relative volume 6V / L³ (L the longest edge) of any face tetrahedron of
/// `hull`, recomputed from the points (independent of `verify` and `degenerate`, which tests
/// hold to it).
#[must_use]
pub fn flattest_face_tet(hull: &SimplicialHull) -> f64 {
    let mut worst = f64::INFINITY;
    for t in 0..hull.triangles.len() {
        for side in Side::BOTH {
            let Some(tet) = hull.face_tet(t, side) else {
                continue;
            };
            let mut l: f64 = 0.0;
            for i in 0..4 {
                for j in i + 1..4 {
                    l = l.max(tet[i].distance(tet[j]));
                }
            }
            let v6 = (tet[1] - tet[0])
                .cross(tet[2] - tet[0])
                .dot(tet[3] - tet[0]);
            worst = worst.min(v6.abs() / (l * l * l));
        }
    }
    worst
}

/// Primary rays (160×160, 1 spp, one thread) of `settings`' camera whose first hit on
/// `complex` faces away from the camera. On a closed surface seen from outside every first hit
/// faces the camera; one that faces away went through a crack or a hole (`apatch check`
/// samples lines from the patches' vertices and does not see such cracks).
pub fn back_facing_hits(
    settings: &crate::trace::RenderSettings,
    complex: &PatchComplex,
) -> Result<usize, String> {
    use crate::trace::{self, Geometry, Mode};
    let geo = Geometry::new(complex).map_err(|e| e.to_string())?;
    let mut s = settings.clone();
    s.camera = s.camera.resized(160, 160)?;
    s.spp = 1;
    s.threads = 1;
    s.mode = Mode::Normal;
    let origin = s.camera.origin;
    let frame = trace::render(&geo, &s, &|| {}, &std::sync::atomic::AtomicBool::new(false))
        .map_err(|_| "render interrupted".to_string())?;
    Ok(frame
        .pixels
        .iter()
        .filter(|p| p.alpha > 0.0)
        .filter(|p| {
            let n = DVec3::from(p.normal.map(f64::from));
            let d = (DVec3::from(p.position.map(f64::from)) - origin).normalize();
            // Through a crack the first hit faces away clearly (0.7 on cube_poly before its
            // scene chose planar jets); grazing silhouette hits are within a few degrees of 0
            // (f32 normals).
            n.dot(d) > 0.1
        })
        .count())
}
