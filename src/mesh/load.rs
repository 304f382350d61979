//! `load`: read a file, weld, clean, orient and validate.

use super::raw::{RawMesh, NO_NORMAL};
use super::report::{Element, FindingKind, Report};
use super::{obj, off, orient, split, validate, Mesh};
use crate::error::{Error, Result};
use glam::DVec3;
use std::path::Path;

/// File formats `load` reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ.
    Obj,
    /// Object File Format.
    Off,
}

impl Format {
    /// The format of `path` by its extension (`.obj`, `.off`, any case); otherwise an `OFF`
    /// header in `bytes` means OFF. Anything else is an error.
    pub fn detect(path: &Path, bytes: &[u8]) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(Format::Obj),
            Some("off") => Ok(Format::Off),
            _ => {
                let head = String::from_utf8_lossy(&bytes[..bytes.len().min(16)]);
                if head
                    .split_whitespace()
                    .next()
                    .is_some_and(|t| t.ends_with("OFF"))
                {
                    Ok(Format::Off)
                } else {
                    Err(Error::Input {
                        path: path.into(),
                        message: "unknown mesh format (expected a .obj or .off file)".into(),
                    })
                }
            }
        }
    }
}

/// Reads an OBJ or OFF file into a welded, consistently and outwardly oriented [`Mesh`] with its
/// validation [`Report`]. Hard errors (unreadable file, syntax, NaN/inf or huge coordinates,
/// missing vertices, faces with fewer than 3 vertices, no usable face) are `Err` naming the file
/// and line.
pub fn load(path: &Path) -> Result<(Mesh, Report)> {
    let bytes = std::fs::read(path).map_err(|cause| Error::Io {
        path: path.into(),
        cause,
    })?;
    let format = Format::detect(path, &bytes)?;
    let raw = parse(&bytes, format, path)?;
    // The text is no longer needed: free it before building the mesh.
    drop(bytes);
    finish(raw, path)
}

/// [`load`] from bytes already in memory; `path` only names the source in messages.
pub fn load_bytes(bytes: &[u8], format: Format, path: &Path) -> Result<(Mesh, Report)> {
    finish(parse(bytes, format, path)?, path)
}

/// The [`load`] pipeline (weld, clean, orient, validate) for a mesh built in memory: `faces`
/// index `positions` (0-based). Errors name the offending face or vertex; lines in the result
/// and its findings are 0.
pub fn from_polygons(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Result<(Mesh, Report)> {
    let invalid = |m: String| Error::Invalid(format!("polygon mesh: {m}"));
    for (i, p) in positions.iter().enumerate() {
        for c in p.to_array() {
            super::raw::check_coordinate(c).map_err(|m| invalid(format!("vertex {i}: {m}")))?;
        }
    }
    for (f, face) in faces.iter().enumerate() {
        if face.len() < 3 {
            return Err(invalid(format!("face {f} has {} vertices", face.len())));
        }
        if let Some(v) = face.iter().find(|&&v| v as usize >= positions.len()) {
            return Err(invalid(format!(
                "face {f} refers to vertex {v} but there are {}",
                positions.len()
            )));
        }
    }
    let raw = RawMesh {
        position_lines: vec![0; positions.len()],
        face_lines: vec![0; faces.len()],
        positions,
        faces,
        ..RawMesh::default()
    };
    finish(raw, Path::new("<memory>"))
}

/// Reads the polygon soup.
fn parse(bytes: &[u8], format: Format, path: &Path) -> Result<RawMesh> {
    let parsed = match format {
        Format::Obj => obj::parse(bytes),
        Format::Off => off::parse(bytes),
    };
    parsed.map_err(|message| Error::Input {
        path: path.into(),
        message,
    })
}

/// Welds, cleans, splits non-manifold vertices, orients and validates a polygon soup.
fn finish(raw: RawMesh, path: &Path) -> Result<(Mesh, Report)> {
    let mut report = Report {
        path: path.display().to_string(),
        findings: Vec::new(),
    };
    let mut mesh = from_raw(raw, &mut report).map_err(|message| Error::Input {
        path: path.into(),
        message,
    })?;
    split::split_vertex_fans(&mut mesh, &mut report);
    let topology = orient::orient(&mut mesh, &mut report);
    validate::validate(&mesh, topology, &mut report);
    Ok((mesh, report))
}

/// Welds exactly coincident vertices, removes repeated corners and degenerate faces, drops
/// unreferenced vertices and gathers file normals.
fn from_raw(mut raw: RawMesh, report: &mut Report) -> std::result::Result<Mesh, String> {
    if raw.ignored > 0 {
        report.add(
            FindingKind::IgnoredStatements,
            format!(
                "{} point, line or free-form statements ignored (first at line {})",
                raw.ignored, raw.first_ignored_line
            ),
            Vec::new(),
        );
    }
    if raw.faces.is_empty() {
        return Err(format!(
            "no faces ({} vertices); a surface needs polygon faces",
            raw.positions.len()
        ));
    }
    let n_file = raw.positions.len();
    // Weld: canonical file vertex of each file vertex (first with the same coordinates;
    // +0.0 turns −0.0 into 0.0 so both weld).
    // Sorting by the coordinates' bits groups exact duplicates; the smallest index of each
    // group is its canonical vertex.
    let key = |p: DVec3| {
        [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ]
    };
    let mut order: Vec<u32> = (0..n_file as u32).collect();
    order.sort_unstable_by_key(|&i| (key(raw.positions[i as usize]), i));
    let mut canon: Vec<u32> = vec![0; n_file];
    let mut g = 0;
    while g < order.len() {
        let first = order[g];
        let k = key(raw.positions[first as usize]);
        let mut h = g;
        while h < order.len() && key(raw.positions[order[h] as usize]) == k {
            canon[order[h] as usize] = first;
            h += 1;
        }
        g = h;
    }
    drop(order);
    let mut referenced = vec![false; n_file];
    for face in &raw.faces {
        for &v in face {
            referenced[v as usize] = true;
        }
    }

    // File normals are gathered per canonical file vertex before the faces are rewritten.
    let normals = accumulate_normals(&raw, &canon);

    // Clean faces in place: canonical ids, consecutive repeats removed, degenerate faces dropped.
    let n_raw_faces = raw.faces.len();
    let mut faces = Vec::with_capacity(n_raw_faces);
    let mut face_lines = Vec::with_capacity(n_raw_faces);
    let mut file_face: Vec<u32> = Vec::with_capacity(n_raw_faces);
    let mut repeated = Vec::new();
    let mut dropped = Vec::new();
    for (f, mut out) in std::mem::take(&mut raw.faces).into_iter().enumerate() {
        let original_len = out.len();
        for v in out.iter_mut() {
            *v = canon[*v as usize];
        }
        out.dedup();
        while out.len() > 1 && out.first() == out.last() {
            out.pop();
        }
        let line = raw.face_lines[f];
        let repeats = (1..out.len()).any(|i| out[..i].contains(&out[i]));
        if out.len() < 3 || repeats {
            dropped.push(Element::Face {
                index: f as u32,
                line,
            });
            continue;
        }
        if out.len() != original_len {
            repeated.push(Element::Face {
                index: faces.len() as u32,
                line,
            });
        }
        faces.push(out);
        face_lines.push(line);
        file_face.push(f as u32);
    }
    if faces.is_empty() {
        return Err(format!(
            "all {n_raw_faces} faces are degenerate (fewer than 3 distinct vertices)"
        ));
    }

    // Duplicate faces (same vertex set, either orientation): keep the first.
    let dup = duplicate_faces(&faces);
    let mut duplicates = Vec::new();
    if dup.iter().any(|&d| d) {
        let mut new_index = vec![u32::MAX; faces.len()];
        let mut k = 0;
        for (f, &d) in dup.iter().enumerate() {
            if d {
                duplicates.push(Element::Face {
                    index: file_face[f],
                    line: face_lines[f],
                });
            } else {
                new_index[f] = k;
                k += 1;
            }
        }
        let mut i = 0;
        faces.retain(|_| {
            i += 1;
            !dup[i - 1]
        });
        let mut i = 0;
        face_lines.retain(|_| {
            i += 1;
            !dup[i - 1]
        });
        repeated.retain_mut(|e| match e {
            Element::Face { index, .. } if new_index[*index as usize] != u32::MAX => {
                *index = new_index[*index as usize];
                true
            }
            _ => false,
        });
    }

    // Compact: mesh ids for the canonical vertices the kept faces use, in file order.
    let mut used = vec![false; n_file];
    for face in &faces {
        for &v in face {
            used[v as usize] = true;
        }
    }
    let mut new_id = vec![u32::MAX; n_file];
    let mut positions = Vec::new();
    let mut vertex_lines = Vec::new();
    for i in 0..n_file {
        if used[i] {
            new_id[i] = positions.len() as u32;
            positions.push(raw.positions[i]);
            vertex_lines.push(raw.position_lines[i]);
        }
    }
    for face in &mut faces {
        for v in face.iter_mut() {
            *v = new_id[*v as usize];
        }
    }
    let mut welded = Vec::new();
    let mut unreferenced = Vec::new();
    for i in 0..n_file {
        let c = canon[i] as usize;
        if c != i && referenced[i] && used[c] {
            welded.push(Element::Vertex {
                index: new_id[c],
                line: raw.position_lines[i],
            });
        } else if !used[c] {
            unreferenced.push(Element::Vertex {
                index: i as u32,
                line: raw.position_lines[i],
            });
        }
    }
    if !welded.is_empty() {
        report.add(
            FindingKind::WeldedVertices,
            format!(
                "{} exactly coincident vertices welded (element: the vertex kept, line of the duplicate)",
                welded.len()
            ),
            welded,
        );
    }
    if !unreferenced.is_empty() {
        report.add(
            FindingKind::UnreferencedVertices,
            format!(
                "{} vertices are used by no face and were dropped (element: file vertex number, 0-based)",
                unreferenced.len()
            ),
            unreferenced,
        );
    }
    if !repeated.is_empty() {
        report.add(
            FindingKind::RepeatedVertex,
            format!(
                "{} faces repeated a vertex (after welding); repeats removed",
                repeated.len()
            ),
            repeated,
        );
    }
    if !dropped.is_empty() {
        report.add(
            FindingKind::DroppedFace,
            format!(
                "{} faces with fewer than 3 distinct vertices (or a vertex used twice) dropped (element: file face number, 0-based)",
                dropped.len()
            ),
            dropped,
        );
    }

    if !duplicates.is_empty() {
        report.add(
            FindingKind::DuplicateFace,
            format!(
                "{} faces repeat the vertices of an earlier face and were dropped (element: file face number, 0-based)",
                duplicates.len()
            ),
            duplicates,
        );
    }
    let file_normals = normals.and_then(|acc| finish_normals(acc, &new_id, &vertex_lines, report));
    let n_faces = faces.len() as u32;
    Ok(Mesh {
        positions,
        faces,
        file_normals,
        vertex_lines,
        face_lines,
        face_parent: (0..n_faces).collect(),
    })
}

/// Flags every face whose vertex set equals that of an earlier face. Faces are grouped by a hash
/// of their sorted vertices (sorting the hashes, O(F log F)), and equal hashes are confirmed.
fn duplicate_faces(faces: &[Vec<u32>]) -> Vec<bool> {
    let sorted = |face: &[u32]| {
        let mut s = face.to_vec();
        s.sort_unstable();
        s
    };
    let hash = |face: &[u32]| {
        let mut buf = [0u32; 8];
        let s: Vec<u32>;
        let ids: &[u32] = if face.len() <= 8 {
            buf[..face.len()].copy_from_slice(face);
            buf[..face.len()].sort_unstable();
            &buf[..face.len()]
        } else {
            s = sorted(face);
            &s
        };
        // FNV-1a over the sorted ids.
        ids.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &v| {
            (h ^ u64::from(v)).wrapping_mul(0x0000_0100_0000_01b3)
        })
    };
    let mut keyed: Vec<(u64, u32)> = faces
        .iter()
        .enumerate()
        .map(|(f, face)| (hash(face), f as u32))
        .collect();
    keyed.sort_unstable();
    let mut dup = vec![false; faces.len()];
    let mut g = 0;
    while g < keyed.len() {
        let mut h = g + 1;
        while h < keyed.len() && keyed[h].0 == keyed[g].0 {
            h += 1;
        }
        // Within a run (in face order), compare each face with the earlier kept ones.
        for i in g + 1..h {
            let fi = keyed[i].1 as usize;
            let si = sorted(&faces[fi]);
            if (g..i).any(|j| {
                let fj = keyed[j].1 as usize;
                !dup[fj] && sorted(&faces[fj]) == si
            }) {
                dup[fi] = true;
            }
        }
        g = h;
    }
    dup
}

/// Unit file normals summed per canonical file vertex, the first one seen, and whether later
/// ones differed from it.
struct NormalSums {
    sum: Vec<DVec3>,
    first: Vec<Option<DVec3>>,
    differs: Vec<bool>,
}

/// Gathers the file's normals (OBJ corners, or per-vertex OBJ/NOFF normals) onto canonical file
/// vertices; `None` when the file has none.
fn accumulate_normals(raw: &RawMesh, canon: &[u32]) -> Option<NormalSums> {
    let n = raw.positions.len();
    let mut acc = NormalSums {
        sum: vec![DVec3::ZERO; n],
        first: vec![None; n],
        differs: vec![false; n],
    };
    let mut add = |v: u32, normal: DVec3| {
        let u = normal.normalize_or_zero();
        let v = v as usize;
        match acc.first[v] {
            None => acc.first[v] = Some(u),
            Some(f) if (f - u).length() > 1e-6 => acc.differs[v] = true,
            Some(_) => {}
        }
        acc.sum[v] += u;
    };
    if let Some(vn) = &raw.vertex_normals {
        for (i, &nrm) in vn.iter().enumerate() {
            add(canon[i], nrm);
        }
    } else if !raw.corner_normals.is_empty() {
        let mut c = 0;
        for face in &raw.faces {
            for &v in face {
                let ni = raw.corner_normals[c];
                c += 1;
                if ni != NO_NORMAL {
                    add(canon[v as usize], raw.normals[ni as usize]);
                }
            }
        }
    } else {
        return None;
    }
    Some(acc)
}

/// Per-vertex file normals of the mesh: the normalised mean of the unit normals given for the
/// vertex (its corners, or the file vertices welded into it). `None` when some vertex lacks one
/// (reported).
fn finish_normals(
    acc: NormalSums,
    new_id: &[u32],
    vertex_lines: &[u32],
    report: &mut Report,
) -> Option<Vec<DVec3>> {
    let n = vertex_lines.len();
    let mut sum = vec![DVec3::ZERO; n];
    let mut first = vec![None::<DVec3>; n];
    let mut differs = vec![false; n];
    for (i, &m) in new_id.iter().enumerate() {
        if m != u32::MAX {
            let m = m as usize;
            sum[m] = acc.sum[i];
            first[m] = acc.first[i];
            differs[m] = acc.differs[i];
        }
    }
    let missing: Vec<Element> = (0..n)
        .filter(|&v| first[v].is_none() || sum[v].length() < 1e-12)
        .map(|v| Element::Vertex {
            index: v as u32,
            line: vertex_lines[v],
        })
        .collect();
    if !missing.is_empty() {
        report.add(
            FindingKind::FileNormalsIncomplete,
            format!(
                "{} vertices have no usable file normal; the file's normals are not used",
                missing.len()
            ),
            missing,
        );
        return None;
    }
    let averaged: Vec<Element> = (0..n)
        .filter(|&v| differs[v])
        .map(|v| Element::Vertex {
            index: v as u32,
            line: vertex_lines[v],
        })
        .collect();
    if !averaged.is_empty() {
        report.add(
            FindingKind::FileNormalsAveraged,
            format!(
                "{} vertices have differing file normals at their corners; averaged",
                averaged.len()
            ),
            averaged,
        );
    }
    Some(sum.into_iter().map(DVec3::normalize).collect())
}
