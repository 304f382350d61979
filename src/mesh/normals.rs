//! Vertex normals: the schemes interpolate them, so they shape the surface.

use super::geometry::{area_vector, corner_angle};
use super::topology::{Fan, Topology};
use super::Mesh;
use crate::error::{Error, Result};
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use std::fmt;
use std::str::FromStr;

/// How vertex normals are estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum NormalMethod {
    /// Face normals weighted by the face's interior angle at the vertex.
    Angle,
    /// Face area vectors summed (area-weighted face normals).
    Area,
    /// The normal of the Loop subdivision limit surface at the vertex (triangle meshes only), as
    /// the 2001 paper uses. Boundary vertices use the boundary limit tangents; non-manifold
    /// vertices fall back to `Angle`.
    Loop,
    /// The file's normals (OBJ `vn`, NOFF); an error when the file has none.
    File,
}

impl FromStr for NormalMethod {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "angle" => Ok(NormalMethod::Angle),
            "area" => Ok(NormalMethod::Area),
            "loop" => Ok(NormalMethod::Loop),
            "file" => Ok(NormalMethod::File),
            _ => Err(format!(
                "unknown normal method `{s}` (expected angle, area, loop or file)"
            )),
        }
    }
}

impl fmt::Display for NormalMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NormalMethod::Angle => "angle",
            NormalMethod::Area => "area",
            NormalMethod::Loop => "loop",
            NormalMethod::File => "file",
        })
    }
}

impl NormalMethod {
    /// The default for a mesh: `Loop` for triangle meshes, `Angle` otherwise.
    #[must_use]
    pub fn default_for(mesh: &Mesh) -> NormalMethod {
        if mesh.faces.iter().all(|f| f.len() == 3) {
            NormalMethod::Loop
        } else {
            NormalMethod::Angle
        }
    }
}

/// #V unit vertex normals of `mesh` by `method`. Errors: `File` without file normals, `Loop` on
/// a mesh with polygon faces, or a vertex whose normal vanishes (its face normals cancel).
pub fn vertex_normals(mesh: &Mesh, method: NormalMethod) -> Result<Vec<DVec3>> {
    let raw = match method {
        NormalMethod::Angle => weighted(mesh, true),
        NormalMethod::Area => weighted(mesh, false),
        NormalMethod::Loop => loop_normals(mesh)?,
        NormalMethod::File => mesh.file_normals.clone().ok_or_else(|| {
            Error::Invalid(
                "normals `file` requested but the file has no vertex normals (OBJ `vn` / NOFF)"
                    .into(),
            )
        })?,
    };
    raw.into_iter()
        .enumerate()
        .map(|(v, n)| {
            n.try_normalize().ok_or_else(|| {
                Error::Invalid(format!(
                    "vertex {v} (line {}): its {method} normal is zero (faces around it cancel)",
                    mesh.vertex_lines.get(v).copied().unwrap_or(0)
                ))
            })
        })
        .collect()
}

/// Unnormalised sums of face normals weighted by corner angle (`angle`) or area.
fn weighted(mesh: &Mesh, angle: bool) -> Vec<DVec3> {
    let mut sum = vec![DVec3::ZERO; mesh.positions.len()];
    for face in &mesh.faces {
        let a = area_vector(&mesh.positions, face);
        if angle {
            let Some(n) = a.try_normalize() else { continue };
            for k in 0..face.len() {
                sum[face[k] as usize] += corner_angle(&mesh.positions, face, k, n) * n;
            }
        } else {
            for &v in face {
                sum[v as usize] += a;
            }
        }
    }
    sum
}

/// Loop limit-surface normals (unnormalised), oriented like the area-weighted normal.
fn loop_normals(mesh: &Mesh) -> Result<Vec<DVec3>> {
    if let Some((f, face)) = mesh.faces.iter().enumerate().find(|(_, f)| f.len() != 3) {
        return Err(Error::Invalid(format!(
            "normals `loop` need a triangle mesh, but face {f} (line {}) has {} vertices; \
             triangulate first or use `angle`",
            mesh.face_lines[f],
            face.len()
        )));
    }
    let topo = Topology::new(mesh.positions.len(), &mesh.faces);
    let area = weighted(mesh, false);
    let angle = weighted(mesh, true);
    Ok((0..mesh.positions.len())
        .map(|v| {
            let n = topo
                .vertex_fan(v as u32)
                .map(|fan| loop_limit_normal(&mesh.positions, mesh.positions[v], &fan))
                .filter(|n| n.length_squared() > 0.0)
                .unwrap_or(angle[v]);
            if n.dot(area[v]) < 0.0 {
                -n
            } else {
                n
            }
        })
        .collect())
}

/// The (unnormalised) normal of the Loop limit surface at a vertex `p` with one-ring `fan`.
///
/// Interior vertex of valence n with CCW ring p_0..p_{n−1}: tangents
/// t1 = Σ cos(2πk/n) p_k, t2 = Σ sin(2πk/n) p_k, normal t1 × t2 (Loop 1987; Hoppe et al. 1994).
/// Boundary vertex with ring p_0..p_k (p_0, p_k on the boundary): t_along = p_0 − p_k and
/// t_across = p_0 + p_1 − 2p (k = 1), p_0 + p_2 − 2p_1 (k = 2), and
/// sin θ (p_0 + p_k) + (2 cos θ − 2) Σ_{i=1}^{k−1} sin(iθ) p_i with θ = π/k (k ≥ 3);
/// the caller orients the result.
#[must_use]
pub fn loop_limit_normal(positions: &[DVec3], p: DVec3, fan: &Fan) -> DVec3 {
    let ring: Vec<DVec3> = fan
        .ring
        .iter()
        .map(|&i| positions[i as usize] - p)
        .collect();
    if fan.closed {
        let n = ring.len() as f64;
        let mut t1 = DVec3::ZERO;
        let mut t2 = DVec3::ZERO;
        for (k, q) in ring.iter().enumerate() {
            let a = TAU * k as f64 / n;
            t1 += a.cos() * *q;
            t2 += a.sin() * *q;
        }
        t1.cross(t2)
    } else {
        let k = ring.len() - 1;
        let along = ring[0] - ring[k];
        let across = match k {
            1 => ring[0] + ring[1],
            2 => ring[0] + ring[2] - 2.0 * ring[1],
            _ => {
                let th = PI / k as f64;
                let mut s = th.sin() * (ring[0] + ring[k]);
                for (i, q) in ring.iter().enumerate().take(k).skip(1) {
                    s += (2.0 * th.cos() - 2.0) * (i as f64 * th).sin() * *q;
                }
                s
            }
        };
        along.cross(across)
    }
}

/// Vertices whose normal fails the 1994 paper's above-face condition: n · n_f ≤ 0 for some
/// incident face f (n_f its area vector). Sorted, each listed once. `normals` is #V.
#[must_use]
pub fn above_face_failures(mesh: &Mesh, normals: &[DVec3]) -> Vec<u32> {
    let mut fails = vec![false; mesh.positions.len()];
    for face in &mesh.faces {
        let nf = area_vector(&mesh.positions, face);
        for &v in face {
            if normals[v as usize].dot(nf) <= 0.0 {
                fails[v as usize] = true;
            }
        }
    }
    (0..mesh.positions.len() as u32)
        .filter(|&v| fails[v as usize])
        .collect()
}
