//! Local quadric fit for `free = "quadric"`: a quadric Q with Q(p) = 0 and ∇Q(p) = n at the
//! vertices of the face's neighbourhood (its corners and the vertices of every triangle sharing
//! a corner), solved in least squares (coordinates centred on the face and scaled by its size,
//! with a tiny ridge on the quadratic part so flat neighbourhoods give the plane). Data taken
//! from a quadric whose gradient at the vertices equals the given normals is fitted exactly.

use super::weights::solve;
use glam::DVec3;

/// Vertex → incident triangles (compressed rows).
#[derive(Clone, Debug)]
pub struct VertexFaces {
    start: Vec<u32>,
    faces: Vec<u32>,
}

impl VertexFaces {
    /// Builds the table.
    #[must_use]
    pub fn new(nverts: usize, triangles: &[[u32; 3]]) -> Self {
        let mut count = vec![0u32; nverts + 1];
        for tri in triangles {
            for &v in tri {
                count[v as usize + 1] += 1;
            }
        }
        for i in 0..nverts {
            count[i + 1] += count[i];
        }
        let mut fill = count.clone();
        let mut faces = vec![0u32; triangles.len() * 3];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                faces[fill[v as usize] as usize] = t as u32;
                fill[v as usize] += 1;
            }
        }
        VertexFaces {
            start: count,
            faces,
        }
    }

    /// Triangles incident to vertex v.
    #[must_use]
    pub fn of(&self, v: u32) -> &[u32] {
        &self.faces[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }
}

/// A fitted quadric in scaled local coordinates x' = (x − center)/scale.
#[derive(Clone, Copy, Debug)]
pub struct LocalQuadric {
    center: DVec3,
    scale: f64,
    /// a0..a5 (xx, yy, zz, xy, xz, yz with the off-diagonal doubled), b0..b2, c.
    coef: [f64; 10],
}

impl LocalQuadric {
    /// Q(x) (in the units where ∇Q = n at the data).
    #[must_use]
    pub fn value(&self, x: DVec3) -> f64 {
        let y = (x - self.center) / self.scale;
        let c = &self.coef;
        c[0] * y.x * y.x
            + c[1] * y.y * y.y
            + c[2] * y.z * y.z
            + 2.0 * (c[3] * y.x * y.y + c[4] * y.x * y.z + c[5] * y.y * y.z)
            + c[6] * y.x
            + c[7] * y.y
            + c[8] * y.z
            + c[9]
    }
}

/// Fits the quadric of triangle t's neighbourhood; None when the system is singular.
#[must_use]
pub fn fit_face(
    vf: &VertexFaces,
    positions: &[DVec3],
    normals: &[DVec3],
    triangles: &[[u32; 3]],
    t: usize,
) -> Option<LocalQuadric> {
    let tri = triangles[t];
    let mut verts: Vec<u32> = tri.to_vec();
    for &v in &tri {
        for &g in vf.of(v) {
            for &w in &triangles[g as usize] {
                if !verts.contains(&w) {
                    verts.push(w);
                }
            }
        }
    }
    let p = tri.map(|i| positions[i as usize]);
    let center = (p[0] + p[1] + p[2]) / 3.0;
    let scale = (p[1] - p[0])
        .length()
        .max((p[2] - p[1]).length())
        .max((p[0] - p[2]).length());
    let mut ata = vec![vec![0.0; 10]; 10];
    let mut atb = vec![0.0; 10];
    let mut add = |row: [f64; 10], rhs: f64| {
        for i in 0..10 {
            for j in 0..10 {
                ata[i][j] += row[i] * row[j];
            }
            atb[i] += row[i] * rhs;
        }
    };
    for &v in &verts {
        let y = (positions[v as usize] - center) / scale;
        let n = normals[v as usize] * scale;
        add(
            [
                y.x * y.x,
                y.y * y.y,
                y.z * y.z,
                2.0 * y.x * y.y,
                2.0 * y.x * y.z,
                2.0 * y.y * y.z,
                y.x,
                y.y,
                y.z,
                1.0,
            ],
            0.0,
        );
        add(
            [
                2.0 * y.x,
                0.0,
                0.0,
                2.0 * y.y,
                2.0 * y.z,
                0.0,
                1.0,
                0.0,
                0.0,
                0.0,
            ],
            n.x,
        );
        add(
            [
                0.0,
                2.0 * y.y,
                0.0,
                2.0 * y.x,
                0.0,
                2.0 * y.z,
                0.0,
                1.0,
                0.0,
                0.0,
            ],
            n.y,
        );
        add(
            [
                0.0,
                0.0,
                2.0 * y.z,
                0.0,
                2.0 * y.x,
                2.0 * y.y,
                0.0,
                0.0,
                1.0,
                0.0,
            ],
            n.z,
        );
    }
    // Ridge on the quadratic part: picks the plane when the neighbourhood is flat.
    for (i, row) in ata.iter_mut().enumerate().take(6) {
        row[i] += 1e-12;
    }
    let x = solve(ata, atb)?;
    let coef: [f64; 10] = std::array::from_fn(|i| x[i]);
    coef.iter().all(|c| c.is_finite()).then_some(LocalQuadric {
        center,
        scale,
        coef,
    })
}
