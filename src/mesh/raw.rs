//! The file's data as read, before welding and validation (shared by the OBJ and OFF readers).

use glam::DVec3;

/// Largest accepted coordinate magnitude: squares and cross products of larger values overflow
/// f64 (1e154² > f64::MAX), so a margin keeps every area and volume finite.
pub const MAX_COORDINATE: f64 = 1e100;

/// Most vertices one face may have. Ear clipping is quadratic in this; real polygon faces have a
/// handful of vertices, so a bound turns hostile inputs into an error instead of a hang.
pub const MAX_FACE_VERTICES: usize = 4096;

/// No corner normal.
pub const NO_NORMAL: u32 = u32::MAX;

/// A polygon soup as read from a file.
#[derive(Debug, Default)]
pub struct RawMesh {
    /// #V file vertices.
    pub positions: Vec<DVec3>,
    /// #V 1-based line of each vertex.
    pub position_lines: Vec<u32>,
    /// #F faces, 0-based indices into `positions`, all checked in range.
    pub faces: Vec<Vec<u32>>,
    /// #F 1-based line of each face.
    pub face_lines: Vec<u32>,
    /// OBJ `vn` normals.
    pub normals: Vec<DVec3>,
    /// Per face corner (flattened in face order) the index into `normals`, or [`NO_NORMAL`];
    /// empty when the file has no corner normals.
    pub corner_normals: Vec<u32>,
    /// Per-vertex normals (NOFF), #V, when the file has them.
    pub vertex_normals: Option<Vec<DVec3>>,
    /// Count of statements read but ignored (OBJ lines, points, free-form geometry).
    pub ignored: usize,
    /// 1-based line of the first ignored statement.
    pub first_ignored_line: u32,
}

/// Checks one parsed coordinate or normal component.
pub fn check_coordinate(value: f64) -> Result<f64, String> {
    if !value.is_finite() {
        Err(format!("non-finite coordinate {value}"))
    } else if value.abs() > MAX_COORDINATE {
        Err(format!(
            "coordinate {value:e} exceeds the supported magnitude {MAX_COORDINATE:e}"
        ))
    } else {
        Ok(value)
    }
}

/// Parses a float token, naming it in the error.
pub fn parse_float(token: &str) -> Result<f64, String> {
    let v: f64 = token
        .parse()
        .map_err(|_| format!("`{}` is not a number", shorten(token)))?;
    check_coordinate(v)
}

/// A token cut to a readable length for error messages.
pub fn shorten(token: &str) -> String {
    const MAX: usize = 32;
    if token.chars().count() <= MAX {
        token.to_string()
    } else {
        let s: String = token.chars().take(MAX).collect();
        format!("{s}…")
    }
}

/// The text of one line of a text mesh format, comments (`#` to the end of the line) removed;
/// `None` for a blank (or comment-only) line.
///
/// # Errors
/// A line that is not UTF-8, named by its number.
pub fn content(line_no: u32, line: &[u8]) -> Result<Option<&str>, String> {
    let line = match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    };
    if line.iter().all(u8::is_ascii_whitespace) {
        return Ok(None);
    }
    std::str::from_utf8(line)
        .map(Some)
        .map_err(|_| format!("line {line_no}: not UTF-8 text (binary data?)"))
}

/// Splits a byte buffer into lines (LF or CRLF; a leading UTF-8 byte-order mark is skipped),
/// yielding (1-based line number, bytes).
pub fn lines(bytes: &[u8]) -> impl Iterator<Item = (u32, &[u8])> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, l)| {
        let l = l.strip_suffix(b"\r").unwrap_or(l);
        (u32::try_from(i + 1).unwrap_or(u32::MAX), l)
    })
}
