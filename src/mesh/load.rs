//! `load`: read a file, weld, clean, orient and validate.

use super::raw::{RawMesh, NO_NORMAL};
use super::report::{Element, FindingKind, Report};
use super::{obj, off, orient, validate, Mesh};
use crate::error::{Error, Result};
use glam::DVec3;
use std::collections::HashMap;
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
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.into(),
        source,
    })?;
    let format = Format::detect(path, &bytes)?;
    load_bytes(&bytes, format, path)
}

/// [`load`] from bytes already in memory; `path` only names the source in messages.
pub fn load_bytes(bytes: &[u8], format: Format, path: &Path) -> Result<(Mesh, Report)> {
    let parsed = match format {
        Format::Obj => obj::parse(bytes),
        Format::Off => off::parse(bytes),
    };
    let raw = parsed.map_err(|message| Error::Input {
        path: path.into(),
        message,
    })?;
    let mut report = Report {
        path: path.display().to_string(),
        findings: Vec::new(),
    };
    let mut mesh = from_raw(raw, &mut report).map_err(|message| Error::Input {
        path: path.into(),
        message,
    })?;
    orient::orient(&mut mesh, &mut report);
    validate::validate(&mesh, &mut report);
    Ok((mesh, report))
}

/// Welds exactly coincident vertices, removes repeated corners and degenerate faces, drops
/// unreferenced vertices and gathers file normals.
fn from_raw(raw: RawMesh, report: &mut Report) -> std::result::Result<Mesh, String> {
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
    let mut canon: Vec<u32> = Vec::with_capacity(n_file);
    let mut seen: HashMap<[u64; 3], u32> = HashMap::with_capacity(n_file);
    for (i, p) in raw.positions.iter().enumerate() {
        let key = [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ];
        canon.push(*seen.entry(key).or_insert(i as u32));
    }
    drop(seen);
    let mut referenced = vec![false; n_file];
    for face in &raw.faces {
        for &v in face {
            referenced[v as usize] = true;
        }
    }

    // Clean faces: canonical ids, consecutive repeats removed, degenerate faces dropped.
    let mut faces = Vec::with_capacity(raw.faces.len());
    let mut face_lines = Vec::with_capacity(raw.faces.len());
    let mut kept_from = Vec::with_capacity(raw.faces.len());
    let mut repeated = Vec::new();
    let mut dropped = Vec::new();
    for (f, face) in raw.faces.iter().enumerate() {
        let mut out: Vec<u32> = Vec::with_capacity(face.len());
        for &v in face {
            let c = canon[v as usize];
            if out.last() != Some(&c) {
                out.push(c);
            }
        }
        while out.len() > 1 && out.first() == out.last() {
            out.pop();
        }
        let line = raw.face_lines[f];
        let mut sorted = out.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() < 3 || sorted.len() != out.len() {
            dropped.push(Element::Face {
                index: f as u32,
                line,
            });
            continue;
        }
        if out.len() != face.len() {
            repeated.push(Element::Face {
                index: faces.len() as u32,
                line,
            });
        }
        faces.push(out);
        face_lines.push(line);
        kept_from.push(f);
    }
    if faces.is_empty() {
        return Err(format!(
            "all {} faces are degenerate (fewer than 3 distinct vertices)",
            raw.faces.len()
        ));
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

    let file_normals = gather_normals(
        &raw,
        &kept_from,
        &canon,
        &new_id,
        &positions,
        &vertex_lines,
        report,
    );
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

/// Per-vertex file normals: the normalised mean of the unit normals given for the vertex
/// (OBJ corners, or NOFF vertices welded into it). `None` when the file has none or some vertex
/// lacks one (reported).
fn gather_normals(
    raw: &RawMesh,
    kept_from: &[usize],
    canon: &[u32],
    new_id: &[u32],
    positions: &[DVec3],
    vertex_lines: &[u32],
    report: &mut Report,
) -> Option<Vec<DVec3>> {
    let n = positions.len();
    let mut sum = vec![DVec3::ZERO; n];
    let mut first = vec![None::<DVec3>; n];
    let mut differs = vec![false; n];
    let mut add = |v: u32, normal: DVec3| {
        let u = normal.normalize_or_zero();
        let v = v as usize;
        match first[v] {
            None => first[v] = Some(u),
            Some(f) if (f - u).length() > 1e-6 => differs[v] = true,
            Some(_) => {}
        }
        sum[v] += u;
    };
    if let Some(vn) = &raw.vertex_normals {
        for (i, &nrm) in vn.iter().enumerate() {
            let m = new_id[canon[i] as usize];
            if m != u32::MAX {
                add(m, nrm);
            }
        }
    } else if !raw.corner_normals.is_empty() {
        let mut offsets = Vec::with_capacity(raw.faces.len() + 1);
        let mut o = 0usize;
        for face in &raw.faces {
            offsets.push(o);
            o += face.len();
        }
        for &f in kept_from {
            for (k, &v) in raw.faces[f].iter().enumerate() {
                let ni = raw.corner_normals[offsets[f] + k];
                if ni != NO_NORMAL {
                    add(new_id[canon[v as usize] as usize], raw.normals[ni as usize]);
                }
            }
        }
    } else {
        return None;
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
