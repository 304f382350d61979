//! Wavefront OBJ reader: `v`, `vn` and polygon `f` statements, with 1-based line numbers in every
//! error.
//!
//! The crate's own reader rather than tobj: tobj reads f32 unless a feature is enabled, splits
//! vertices per `o`/`g` group (breaking adjacency between groups), drops unused vertices, and its
//! errors carry no line number; this one keeps f64 coordinates, global vertex numbering and the
//! line of every element.
//!
//! Accepted: `v x y z [w]` and `v x y z r g b` (extra values ignored), `vn`, `f` with `v`, `v/vt`,
//! `v//vn`, `v/vt/vn` corners, positive (1-based) and negative (relative) indices. Ignored, and
//! counted in a note: `l`, `p`, free-form geometry statements. Skipped silently: comments, `vt`,
//! `vp`, groups, smoothing, materials. Anything else is an error naming the line.
//! Normals: per face corner (`v//vn`); when no face refers to a normal and there are as many
//! `vn` as `v`, the i-th `vn` is the i-th vertex's normal.

use super::raw::{content, lines, parse_float, shorten, RawMesh, MAX_FACE_VERTICES, NO_NORMAL};
use glam::DVec3;

/// Statements that carry no polygon data for us.
const SKIPPED: &[&str] = &[
    "vt",
    "vp",
    "o",
    "g",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "usemap",
    "maplib",
    "lod",
    "shadow_obj",
    "trace_obj",
    "bevel",
    "c_interp",
    "d_interp",
    "ctech",
    "stech",
];

/// Statements with geometry we do not use (reported as ignored).
const IGNORED: &[&str] = &[
    "l", "p", "curv", "curv2", "surf", "cstype", "deg", "bmat", "step", "parm", "trim", "hole",
    "scrv", "sp", "end", "con", "call", "csh",
];

/// Parses OBJ bytes. Errors are "line N: what".
pub fn parse(bytes: &[u8]) -> Result<RawMesh, String> {
    let mut raw = RawMesh::default();
    // Corner normals are collected per face while any face has them.
    let mut any_corner_normal = false;
    // Unresolved positive indices are checked once all vertices are known (forward references).
    let mut max_index: u64 = 0;
    let mut max_index_line = 0u32;
    // The same for normal indices (`vn` lines may follow the faces that use them).
    let mut max_normal: u64 = 0;
    let mut max_normal_line = 0u32;
    for (line_no, line) in lines(bytes) {
        // Comments run from `#` to the end of the line.
        let Some(text) = content(line_no, line)? else {
            continue;
        };
        let at = |m: String| format!("line {line_no}: {m}");
        let mut tokens = text.split_ascii_whitespace();
        let keyword = tokens.next().unwrap_or_default();
        match keyword {
            "v" => {
                let values: Vec<&str> = tokens.by_ref().take(8).collect();
                if values.len() < 3 || values.len() > 7 {
                    return Err(at(format!(
                        "vertex needs 3 coordinates (optionally w or r g b), found {}{}",
                        values.len(),
                        if values.len() > 7 { "+" } else { "" }
                    )));
                }
                let mut p = [0.0; 3];
                for (k, t) in values.iter().take(3).enumerate() {
                    p[k] = parse_float(t)
                        .map_err(|m| at(format!("vertex {}: {m}", raw.positions.len() + 1)))?;
                }
                if u32::try_from(raw.positions.len() + 1).is_err() {
                    return Err(at("more than 2^32 - 1 vertices".into()));
                }
                raw.positions.push(DVec3::from_array(p));
                raw.position_lines.push(line_no);
            }
            "vn" => {
                let values: Vec<&str> = tokens.collect();
                if values.len() != 3 {
                    return Err(at(format!("normal needs 3 values, found {}", values.len())));
                }
                let mut n = [0.0; 3];
                for (k, t) in values.iter().enumerate() {
                    n[k] = parse_float(t).map_err(|m| at(format!("normal: {m}")))?;
                }
                raw.normals.push(DVec3::from_array(n));
            }
            "f" | "fo" => {
                let mut face = Vec::with_capacity(4);
                let mut normals = Vec::with_capacity(4);
                for corner in tokens {
                    if face.len() == MAX_FACE_VERTICES {
                        return Err(at(format!(
                            "face has more than {MAX_FACE_VERTICES} vertices (not supported)"
                        )));
                    }
                    let mut parts = corner.split('/');
                    let v = parts.next().unwrap_or_default();
                    let _vt = parts.next();
                    let vn = parts.next().filter(|s| !s.is_empty());
                    if parts.next().is_some() {
                        return Err(at(format!("bad face corner `{}`", shorten(corner))));
                    }
                    let (vi, forward) = resolve(v, raw.positions.len())
                        .map_err(|m| at(format!("face vertex {}: {m}", face.len() + 1)))?;
                    if forward && u64::from(vi) + 1 > max_index {
                        max_index = u64::from(vi) + 1;
                        max_index_line = line_no;
                    }
                    face.push(vi);
                    let ni = match vn {
                        Some(t) => {
                            let (ni, forward) = resolve(t, raw.normals.len())
                                .map_err(|m| at(format!("face normal {}: {m}", face.len())))?;
                            if forward && u64::from(ni) + 1 > max_normal {
                                max_normal = u64::from(ni) + 1;
                                max_normal_line = line_no;
                            }
                            any_corner_normal = true;
                            ni
                        }
                        None => NO_NORMAL,
                    };
                    normals.push(ni);
                }
                if face.len() < 3 {
                    return Err(at(format!(
                        "face has {} vertices; a face needs at least 3",
                        face.len()
                    )));
                }
                if any_corner_normal && raw.corner_normals.is_empty() && !raw.faces.is_empty() {
                    // Earlier faces had no normals: back-fill.
                    let n: usize = raw.faces.iter().map(Vec::len).sum();
                    raw.corner_normals.resize(n, NO_NORMAL);
                }
                if any_corner_normal {
                    raw.corner_normals.extend_from_slice(&normals);
                }
                raw.faces.push(face);
                raw.face_lines.push(line_no);
            }
            k if SKIPPED.contains(&k) => {}
            k if IGNORED.contains(&k) => {
                if raw.ignored == 0 {
                    raw.first_ignored_line = line_no;
                }
                raw.ignored += 1;
            }
            k => {
                return Err(at(format!("unknown OBJ statement `{}`", shorten(k))));
            }
        }
    }
    if max_index > raw.positions.len() as u64 {
        return Err(format!(
            "line {max_index_line}: face refers to vertex {max_index} but the file defines {} vertices",
            raw.positions.len()
        ));
    }
    if max_normal > raw.normals.len() as u64 {
        return Err(format!(
            "line {max_normal_line}: face refers to normal {max_normal} but the file defines {} normals",
            raw.normals.len()
        ));
    }
    // No face refers to a normal but there is one per vertex: the common per-vertex convention.
    if !any_corner_normal && !raw.normals.is_empty() && raw.normals.len() == raw.positions.len() {
        raw.vertex_normals = Some(std::mem::take(&mut raw.normals));
    }
    Ok(raw)
}

/// Resolves an OBJ index token against `count` elements defined so far. Returns the 0-based index
/// and whether it is a (positive) reference that may point forward (checked at the end).
fn resolve(token: &str, count: usize) -> Result<(u32, bool), String> {
    let i: i64 = token
        .parse()
        .map_err(|_| format!("`{}` is not a valid index", shorten(token)))?;
    if i == 0 {
        return Err("index 0 (OBJ indices start at 1)".into());
    }
    if i > 0 {
        let z = u32::try_from(i - 1).map_err(|_| format!("index {i} is too large"))?;
        if z == u32::MAX {
            return Err(format!("index {i} is too large"));
        }
        return Ok((z, true));
    }
    // Negative: relative to the elements defined so far (-1 is the last one).
    let back = i.unsigned_abs();
    if back > count as u64 {
        return Err(format!(
            "relative index {i} points before the first element ({count} defined so far)"
        ));
    }
    Ok(((count as u64 - back) as u32, false))
}
