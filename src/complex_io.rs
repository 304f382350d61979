//! Reading and writing a [`PatchComplex`] as JSON (format `apatch-patches`, version 1; the
//! layout is documented in [`crate::complex`]).
//!
//! Numbers are written by `serde_json` in shortest round-trip form and read with its
//! `float_roundtrip` parser, so every `f64` (subnormals, `-0.0`, `1e300`, `0.1 + 0.2`) reads back
//! bit for bit. JSON has no NaN or infinity: writing refuses non-finite numbers, and reading
//! rejects `null`, strings and overflowing exponents with an error naming the file, the patch
//! index and the line/column.
//!
//! Reading validates ([`validate`]): format and version, degree 1..=7, C(n+3,3) weights, finite
//! numbers, non-degenerate tetrahedra, rational index sums (and a cleared segment degree ≤ 15),
//! shooting rules that split the vertices, and that `normals` is empty or as long as
//! `vertices`.
//!
//! ```
//! use apatch::complex_io::{from_json_str, to_json_string};
//! use apatch::fixtures::{quadric_complex, Quadric};
//! use glam::DVec3;
//! use std::path::Path;
//!
//! let q = Quadric::sphere(DVec3::ZERO, 0.5);
//! let complex = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 1, 2);
//! let text = to_json_string(&complex)?;
//! assert_eq!(from_json_str(&text, Path::new("memory.json"))?, complex);
//!
//! let err = from_json_str(&text.replace("\"degree\":2", "\"degree\":9"), Path::new("bad.json"));
//! assert!(err.unwrap_err().to_string().starts_with("bad.json: patch 0: degree 9"));
//! # Ok::<(), apatch::error::Error>(())
//! ```

use crate::bb::num_coeffs;
use crate::complex::{Patch, PatchComplex, FORMAT, VERSION};
use crate::error::{Error, Result};
use glam::DVec3;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;

/// Highest polynomial degree a patch may have.
pub const MAX_DEGREE: u8 = 7;

/// Highest degree of a patch restricted to a segment with its rational denominators cleared
/// ([`crate::bb::rational::segment_degree`]), as the tracer and checker need.
pub const MAX_SEGMENT_DEGREE: usize = 15;

/// A tetrahedron is degenerate when |det[v2−v1, v3−v1, v4−v1]| ≤ this × (longest edge)³
/// (a regular tetrahedron has ≈ 0.71; 1e-12 only rejects flat or repeated-vertex ones).
pub const DEGENERATE_TET_RATIO: f64 = 1e-12;

/// Reads and validates a patch complex from a JSON file.
///
/// # Errors
/// [`Error::Input`] naming the file (and the patch index where one is at fault) when it cannot
/// be opened, is malformed JSON or holds invalid data.
pub fn read_json_file(path: &Path) -> Result<PatchComplex> {
    // `Input` rather than `Io`: the latter's message repeats its cause in `{:#}` chains.
    let file = std::fs::File::open(path).map_err(|e| Error::Input {
        path: path.to_path_buf(),
        message: format!("cannot open: {e}"),
    })?;
    read_json(BufReader::new(file), path)
}

/// Reads and validates a patch complex from JSON text; `path` is only used in messages.
///
/// # Errors
/// [`Error::Input`] naming `path` (and the patch index where one is at fault).
pub fn read_json<R: Read>(reader: R, path: &Path) -> Result<PatchComplex> {
    let input = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let file: ComplexFile = serde_json::from_reader(reader).map_err(|e| input(e.to_string()))?;
    let complex = PatchComplex {
        format: file.format,
        version: file.version,
        scheme: file.scheme,
        continuity: file.continuity,
        vertices: file.vertices,
        normals: file.normals,
        patches: file.patches.0,
    };
    validate(&complex).map_err(input)?;
    Ok(complex)
}

/// Parses and validates a patch complex from a JSON string; `path` is only used in messages.
///
/// # Errors
/// As [`read_json`].
pub fn from_json_str(text: &str, path: &Path) -> Result<PatchComplex> {
    read_json(text.as_bytes(), path)
}

/// Writes `complex` as JSON to `path` (validated first, so the file always reads back).
///
/// # Errors
/// [`Error::Invalid`] when the complex fails [`validate`], [`Error::Input`] naming the file on
/// write failure.
pub fn write_json_file(complex: &PatchComplex, path: &Path) -> Result<()> {
    let io = |e: std::io::Error| Error::Input {
        path: path.to_path_buf(),
        message: format!("cannot write: {e}"),
    };
    validate(complex).map_err(Error::Invalid)?;
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = BufWriter::new(file);
    write_json_unchecked(complex, &mut w).map_err(io)?;
    w.flush().map_err(io)
}

/// Writes `complex` as JSON to `writer` (validated first).
///
/// # Errors
/// [`Error::Invalid`] when the complex fails [`validate`]; write failures as [`Error::Invalid`]
/// with the cause (there is no file name to attach).
pub fn write_json<W: Write>(complex: &PatchComplex, writer: W) -> Result<()> {
    validate(complex).map_err(Error::Invalid)?;
    write_json_unchecked(complex, writer).map_err(|e| Error::Invalid(e.to_string()))
}

/// The JSON text of `complex` (validated first).
///
/// # Errors
/// [`Error::Invalid`] when the complex fails [`validate`].
pub fn to_json_string(complex: &PatchComplex) -> Result<String> {
    let mut out = Vec::new();
    write_json(complex, &mut out)?;
    String::from_utf8(out).map_err(|e| Error::Invalid(e.to_string()))
}

fn write_json_unchecked<W: Write>(complex: &PatchComplex, writer: W) -> std::io::Result<()> {
    serde_json::to_writer(writer, complex).map_err(std::io::Error::other)
}

/// Checks everything the JSON reader promises about a complex; the message names the patch
/// index (and vertex index) at fault.
///
/// # Errors
/// A one-line description of the first problem found.
pub fn validate(c: &PatchComplex) -> std::result::Result<(), String> {
    if c.format != FORMAT {
        return Err(format!("format is \"{}\", expected \"{FORMAT}\"", c.format));
    }
    if c.version != VERSION {
        return Err(format!(
            "unsupported version {} (this build reads version {VERSION})",
            c.version
        ));
    }
    if let Some(k) = c.continuity {
        if !(1..=2).contains(&k) {
            return Err(format!("continuity {k} is not 1 or 2"));
        }
    }
    if !c.normals.is_empty() && c.normals.len() != c.vertices.len() {
        return Err(format!(
            "{} normals for {} vertices (give one per vertex, or none)",
            c.normals.len(),
            c.vertices.len()
        ));
    }
    for (i, v) in c.vertices.iter().enumerate() {
        if !v.iter().all(|x| x.is_finite()) {
            return Err(format!("vertex {i}: non-finite coordinate {v:?}"));
        }
    }
    for (i, n) in c.normals.iter().enumerate() {
        if !n.iter().all(|x| x.is_finite()) {
            return Err(format!("normal {i}: non-finite component {n:?}"));
        }
    }
    for (i, p) in c.patches.iter().enumerate() {
        validate_patch(p).map_err(|m| format!("patch {i}: {m}"))?;
    }
    Ok(())
}

/// Checks one patch (degree, weight count, finiteness, tetrahedron, rational terms).
///
/// # Errors
/// A one-line description of the first problem found.
pub fn validate_patch(p: &Patch) -> std::result::Result<(), String> {
    if !(1..=MAX_DEGREE).contains(&p.degree) {
        return Err(format!("degree {} is not in 1..={MAX_DEGREE}", p.degree));
    }
    let n = usize::from(p.degree);
    if p.weights.len() != num_coeffs(n) {
        return Err(format!(
            "{} weights for degree {n} (expected C({n}+3,3) = {})",
            p.weights.len(),
            num_coeffs(n)
        ));
    }
    if let Some(k) = p.weights.iter().position(|w| !w.is_finite()) {
        return Err(format!("weight {k} is not finite ({})", p.weights[k]));
    }
    if !p.tet.iter().flatten().all(|x| x.is_finite()) {
        return Err("non-finite tetrahedron coordinate".to_string());
    }
    let v = p.tet_points();
    let det = (v[1] - v[0]).cross(v[2] - v[0]).dot(v[3] - v[0]);
    let longest = longest_edge(&v);
    if det.is_nan() || det.abs() <= DEGENERATE_TET_RATIO * longest.powi(3) {
        return Err(format!(
            "degenerate tetrahedron {:?} (volume {:e})",
            p.tet,
            det.abs() / 6.0
        ));
    }
    if p.jvertex.is_some_and(|j| j > 3) {
        return Err(format!(
            "jvertex {:?} is not a tetrahedron vertex (0..=3)",
            p.jvertex
        ));
    }
    if let Some([a, b]) = p.jedge {
        if a > 3 || b > 3 || a == b {
            return Err(format!(
                "jedge [{a}, {b}] is not an edge of the tetrahedron"
            ));
        }
    }
    for (r, term) in p.rational.iter().enumerate() {
        let ksum: usize = term.index.iter().map(|&k| usize::from(k)).sum();
        if ksum != n {
            return Err(format!(
                "rational term {r}: index {:?} sums to {ksum}, not the degree {n}",
                term.index
            ));
        }
        let Some((_, mu0)) = term.terms.first() else {
            return Err(format!("rational term {r}: no terms"));
        };
        let msum = |mu: &[u8; 4]| mu.iter().map(|&k| usize::from(k)).sum::<usize>();
        for (m, (w, mu)) in term.terms.iter().enumerate() {
            if !w.is_finite() {
                return Err(format!(
                    "rational term {r}, term {m}: weight {w} is not finite"
                ));
            }
            if msum(mu) != msum(mu0) || msum(mu) == 0 || msum(mu) > usize::from(MAX_DEGREE) {
                return Err(format!(
                    "rational term {r}, term {m}: monomial {mu:?} must have the same \
                     positive degree (≤ {MAX_DEGREE}) as {mu0:?}"
                ));
            }
        }
    }
    let mut distinct = 0;
    for (r, term) in p.rational.iter().enumerate() {
        if !p.rational[..r]
            .iter()
            .any(|t| crate::bb::rational::same_denominator(t, term))
        {
            distinct += 1;
        }
    }
    if distinct > crate::bb::rational::MAX_DENOMINATORS {
        return Err(format!(
            "{distinct} distinct rational denominators (at most {})",
            crate::bb::rational::MAX_DENOMINATORS
        ));
    }
    let cleared = crate::bb::rational::segment_degree(n, &p.rational);
    if cleared > MAX_SEGMENT_DEGREE {
        return Err(format!(
            "rational terms raise the segment degree to {cleared} (at most {MAX_SEGMENT_DEGREE})"
        ));
    }
    if let crate::complex::SheetRule::Shooting { base, top } = &p.sheet {
        let ok = !base.is_empty()
            && !top.is_empty()
            && base.len() + top.len() == 4
            && base.iter().chain(top).all(|&k| k < 4)
            && (0..4u8).all(|k| base.contains(&k) || top.contains(&k));
        if !ok {
            return Err(format!(
                "sheet rule: base {base:?} and top {top:?} must split the vertices 0..4"
            ));
        }
    }
    Ok(())
}

/// The longest edge of a tetrahedron.
#[must_use]
pub fn longest_edge(v: &[DVec3; 4]) -> f64 {
    let mut l: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l = l.max(v[i].distance(v[j]));
        }
    }
    l
}

// ---------------------------------------------------------------------------------------------
// Reading: a mirror of `PatchComplex` whose format/version are checked as soon as they are read
// and whose patch list names the failing patch index in parse errors.

#[derive(Deserialize)]
struct ComplexFile {
    #[serde(deserialize_with = "format_tag")]
    format: String,
    #[serde(deserialize_with = "version_tag")]
    version: u32,
    scheme: String,
    #[serde(default)]
    continuity: Option<u8>,
    vertices: Vec<[f64; 3]>,
    #[serde(default)]
    normals: Vec<[f64; 3]>,
    patches: PatchList,
}

fn format_tag<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<String, D::Error> {
    let s = String::deserialize(d)?;
    if s == FORMAT {
        Ok(s)
    } else {
        Err(de::Error::custom(format!(
            "not an {FORMAT} file (format is \"{s}\")"
        )))
    }
}

fn version_tag<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<u32, D::Error> {
    let v = u32::deserialize(d)?;
    if v == VERSION {
        Ok(v)
    } else {
        Err(de::Error::custom(format!(
            "unsupported version {v} (this build reads version {VERSION})"
        )))
    }
}

struct PatchList(Vec<Patch>);

impl<'de> Deserialize<'de> for PatchList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        d.deserialize_seq(PatchListVisitor)
    }
}

struct PatchListVisitor;

impl<'de> Visitor<'de> for PatchListVisitor {
    type Value = PatchList;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a list of patches")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<PatchList, A::Error> {
        let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 20));
        loop {
            match seq.next_element::<Patch>() {
                Ok(Some(p)) => out.push(p),
                Ok(None) => return Ok(PatchList(out)),
                Err(e) => {
                    return Err(de::Error::custom(format!("patch {}: {e}", out.len())));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::complex::{Role, SheetRule};
    use crate::fixtures::{plain_patch, UNIT_TET};

    fn unit_patch() -> Patch {
        plain_patch(UNIT_TET, 1, vec![1.0, -1.0, 0.5, 0.25])
    }

    #[test]
    fn flat_tet_is_rejected() {
        let mut p = unit_patch();
        p.tet[3] = [0.5, 0.5, 0.0];
        let e = validate_patch(&p).unwrap_err();
        assert!(e.contains("degenerate"), "{e}");
    }

    #[test]
    fn shooting_rule_must_split_vertices() {
        let mut p = unit_patch();
        p.sheet = SheetRule::Shooting {
            base: [0, 1, 2].into(),
            top: [2].into(),
        };
        assert!(validate_patch(&p).is_err());
        p.sheet = SheetRule::Shooting {
            base: [0, 1, 2].into(),
            top: [3].into(),
        };
        assert!(validate_patch(&p).is_ok());
    }

    /// A complex using every optional part of the format: a face-like rational term (three
    /// pairs), edge-like terms (two pairs each), a term of four pairs (more than are stored
    /// inline), both shooting rules, the j-vertex and j-edge, and numbers that need care.
    fn format_complex() -> PatchComplex {
        use crate::complex::RationalTerm;
        let mut c = PatchComplex::new("test");
        c.continuity = Some(1);
        c.vertices = vec![[0.1, -0.0, 1e300]];
        c.normals = vec![[0.0, 0.0, 1.0]];
        let mut face = unit_patch();
        face.rational = vec![RationalTerm {
            index: [0, 0, 0, 1],
            terms: [
                (0.1, [0, 1, 1, 0]),
                (-2.5, [1, 0, 1, 0]),
                (5e-324, [1, 1, 0, 0]),
            ]
            .into(),
        }];
        face.sheet = SheetRule::Shooting {
            base: [0, 1, 2].into(),
            top: [3].into(),
        };
        face.role = Role::Face;
        face.element = 7;
        let mut edge = unit_patch();
        edge.rational = vec![
            RationalTerm {
                index: [1, 0, 0, 0],
                terms: [(1.0, [0, 0, 1, 0]), (-1.0, [0, 0, 0, 1])].into(),
            },
            RationalTerm {
                index: [0, 1, 0, 0],
                terms: vec![(0.5, [0, 0, 1, 0]), (0.25, [0, 0, 0, 1])].into(),
            },
        ];
        edge.sheet = SheetRule::Shooting {
            base: [0, 1].into(),
            top: [2, 3].into(),
        };
        edge.role = Role::Edge;
        edge.element = 4_000_000_000;
        let mut other = unit_patch();
        let mut four = crate::complex::Blend::default();
        for (k, w) in [3.0, 1.5, -0.75, 2.0].into_iter().enumerate() {
            let mut mu = [0; 4];
            mu[k] = 1;
            four.push((w, mu));
        }
        other.rational = vec![RationalTerm {
            index: [0, 0, 1, 0],
            terms: four,
        }];
        other.role = Role::Vertex;
        other.jvertex = Some(3);
        other.jedge = Some([0, 1]);
        c.patches = vec![face, edge, other];
        c
    }

    /// The JSON text of [`format_complex`], character for character: the form outside tools
    /// read (written before the inline `TetVerts` / `Blend` types replaced the `Vec`s of the
    /// sheet rule and rational terms; the real scenes' files were compared byte for byte then).
    const FORMAT_JSON: &str = concat!(
        r#"{"format":"apatch-patches","version":1,"scheme":"test","continuity":1,"#,
        r#""vertices":[[0.1,-0.0,1e+300]],"normals":[[0.0,0.0,1.0]],"patches":["#,
        r#"{"tet":[[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]],"degree":1,"#,
        r#""weights":[1.0,-1.0,0.5,0.25],"rational":[{"index":[0,0,0,1],"terms":"#,
        r#"[[0.1,[0,1,1,0]],[-2.5,[1,0,1,0]],[5e-324,[1,1,0,0]]]}],"#,
        r#""sheet":{"rule":"shooting","base":[0,1,2],"top":[3]},"role":"face","element":7},"#,
        r#"{"tet":[[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]],"degree":1,"#,
        r#""weights":[1.0,-1.0,0.5,0.25],"rational":[{"index":[1,0,0,0],"terms":"#,
        r#"[[1.0,[0,0,1,0]],[-1.0,[0,0,0,1]]]},{"index":[0,1,0,0],"terms":"#,
        r#"[[0.5,[0,0,1,0]],[0.25,[0,0,0,1]]]}],"#,
        r#""sheet":{"rule":"shooting","base":[0,1],"top":[2,3]},"role":"edge","element":4000000000},"#,
        r#"{"tet":[[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]],"degree":1,"#,
        r#""weights":[1.0,-1.0,0.5,0.25],"rational":[{"index":[0,0,1,0],"terms":"#,
        r#"[[3.0,[1,0,0,0]],[1.5,[0,1,0,0]],[-0.75,[0,0,1,0]],[2.0,[0,0,0,1]]]}],"#,
        r#""role":"vertex","element":0,"jvertex":3,"jedge":[0,1]}]}"#
    );

    /// The JSON form is the documented contract, unchanged by the inline storage of sheet
    /// vertices and rational pairs, and reads back to the same complex.
    #[test]
    fn json_text_is_the_contract() {
        let c = format_complex();
        let text = to_json_string(&c).expect("writes");
        assert_eq!(text, FORMAT_JSON);
        let back = from_json_str(&text, Path::new("format.json")).expect("reads");
        assert_eq!(back, c);
        assert_eq!(to_json_string(&back).expect("writes"), FORMAT_JSON);
    }

    /// A sheet simplex of five vertices cannot be stored: a clear error naming the file, no
    /// panic (it was rejected by validation before; now by the reader).
    #[test]
    fn five_sheet_vertices_are_an_error() {
        let text = FORMAT_JSON.replace(r#""top":[3]"#, r#""top":[3,3,3,3,3]"#);
        let e = from_json_str(&text, Path::new("five.json")).unwrap_err();
        let m = e.to_string();
        assert!(m.starts_with("five.json"), "{m}");
        assert!(m.contains("at most 4"), "{m}");
    }
}
