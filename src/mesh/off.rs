//! Object File Format (OFF) reader: ASCII `OFF`, `COFF`, `NOFF`, `CNOFF` (colours ignored,
//! NOFF normals kept as file normals). One vertex per line and one face per line, `#` comments;
//! 0-based indices. Errors name the 1-based line.

use super::raw::{content, lines, parse_float, shorten, RawMesh, MAX_FACE_VERTICES};
use glam::DVec3;

/// Parses OFF bytes. Errors are "line N: what".
pub fn parse(bytes: &[u8]) -> Result<RawMesh, String> {
    let mut raw = RawMesh::default();
    let mut with_normals = false;
    let mut header_seen = false;
    let mut counts: Option<(u64, u64)> = None;
    let mut normals = Vec::new();
    let mut last_line = 0;
    for (line_no, line) in lines(bytes) {
        last_line = line_no;
        let Some(text) = content(line_no, line)? else {
            continue;
        };
        let at = |m: String| format!("line {line_no}: {m}");
        let mut tokens: Vec<&str> = text.split_ascii_whitespace().collect();
        if !header_seen {
            header_seen = true;
            if tokens[0].ends_with("OFF") {
                let kw = tokens[0];
                let prefix = &kw[..kw.len() - 3];
                if prefix.contains('4') || prefix.contains('n') {
                    return Err(at(format!("`{kw}`: only 3D OFF is supported")));
                }
                if let Some(bad) = prefix.chars().find(|c| !"STCN".contains(*c)) {
                    return Err(at(format!(
                        "`{}`: unknown OFF header (`{bad}`)",
                        shorten(kw)
                    )));
                }
                with_normals = prefix.contains('N');
                tokens.remove(0);
                if tokens.first() == Some(&"BINARY") {
                    return Err(at("binary OFF is not supported".into()));
                }
                if tokens.is_empty() {
                    continue;
                }
            }
        }
        let Some((nv, nf)) = counts else {
            if tokens.len() < 2 || tokens.len() > 3 {
                return Err(at(
                    "expected the counts `vertices faces [edges]` after the OFF header".into(),
                ));
            }
            let mut c = [0u64; 3];
            for (k, t) in tokens.iter().enumerate() {
                c[k] = t.parse().map_err(|_| {
                    at(format!(
                        "count `{}` is not a non-negative integer",
                        shorten(t)
                    ))
                })?;
            }
            if c[0] >= u64::from(u32::MAX) || c[1] >= u64::from(u32::MAX) {
                return Err(at(format!("counts {} {} are too large", c[0], c[1])));
            }
            counts = Some((c[0], c[1]));
            continue;
        };
        if (raw.positions.len() as u64) < nv {
            let need = if with_normals { 6 } else { 3 };
            if tokens.len() < need {
                return Err(at(format!(
                    "vertex {} needs {need} values, found {}",
                    raw.positions.len(),
                    tokens.len()
                )));
            }
            let mut v = [0.0; 6];
            for k in 0..need {
                v[k] = parse_float(tokens[k])
                    .map_err(|m| at(format!("vertex {}: {m}", raw.positions.len())))?;
            }
            raw.positions.push(DVec3::new(v[0], v[1], v[2]));
            raw.position_lines.push(line_no);
            if with_normals {
                normals.push(DVec3::new(v[3], v[4], v[5]));
            }
        } else if (raw.faces.len() as u64) < nf {
            let k: usize = tokens[0].parse().map_err(|_| {
                at(format!(
                    "face {}: vertex count `{}` is not a non-negative integer",
                    raw.faces.len(),
                    shorten(tokens[0])
                ))
            })?;
            if k < 3 {
                return Err(at(format!(
                    "face {} has {k} vertices; a face needs at least 3",
                    raw.faces.len()
                )));
            }
            if k > MAX_FACE_VERTICES {
                return Err(at(format!(
                    "face {} has {k} vertices; at most {MAX_FACE_VERTICES} are supported",
                    raw.faces.len()
                )));
            }
            if tokens.len() < k + 1 {
                return Err(at(format!(
                    "face {} announces {k} vertices but lists {}",
                    raw.faces.len(),
                    tokens.len() - 1
                )));
            }
            let mut face = Vec::with_capacity(k);
            for t in &tokens[1..=k] {
                let i: u64 = t.parse().map_err(|_| {
                    at(format!(
                        "face {}: `{}` is not a valid vertex index",
                        raw.faces.len(),
                        shorten(t)
                    ))
                })?;
                if i >= nv {
                    return Err(at(format!(
                        "face {} refers to vertex {i} but the file defines {nv} vertices (0-based)",
                        raw.faces.len()
                    )));
                }
                face.push(i as u32);
            }
            raw.faces.push(face);
            raw.face_lines.push(line_no);
        } else {
            return Err(at("unexpected data after the last face".into()));
        }
    }
    let Some((nv, nf)) = counts else {
        return Err("no OFF header and counts found (empty file?)".into());
    };
    if (raw.positions.len() as u64) < nv || (raw.faces.len() as u64) < nf {
        return Err(format!(
            "line {last_line}: file ends early: {} of {nv} vertices and {} of {nf} faces read",
            raw.positions.len(),
            raw.faces.len()
        ));
    }
    if with_normals {
        raw.vertex_normals = Some(normals);
    }
    Ok(raw)
}
