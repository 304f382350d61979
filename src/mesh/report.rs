//! Validation findings of a loaded mesh: what is wrong (or merely notable), where, and how bad.
//!
//! Policy (what is an error, what is a warning) is documented in [`crate::mesh`]; hard errors never
//! reach a [`Report`]: `load` returns them as `Err`.

use serde::Serialize;
use std::fmt;

/// How serious a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// A property of the input worth knowing, not a defect (boundary edges, welded duplicates).
    Note,
    /// A defect that was repaired or that some schemes cannot handle.
    Warning,
}

/// The kind of a finding; one [`Finding`] per kind lists every offending element.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// Exactly coincident vertices were merged into one (Note).
    WeldedVertices,
    /// Vertices no face uses; they were dropped (Warning).
    UnreferencedVertices,
    /// A face repeated a vertex (after welding); consecutive repeats were removed (Warning).
    RepeatedVertex,
    /// A face had fewer than 3 distinct vertices or a non-consecutive repeat; it was dropped (Warning).
    DroppedFace,
    /// A face with the same vertices as an earlier face (either orientation); dropped (Warning).
    DuplicateFace,
    /// A face with (relative) zero area; kept (Warning).
    ZeroAreaFace,
    /// A polygon whose vertices leave its best-fit plane beyond the tolerance; kept (Warning).
    NonPlanarFace,
    /// An edge with more than two faces (Warning; no scheme accepts it).
    NonManifoldEdge,
    /// A vertex whose faces do not form one fan (Warning; no scheme accepts it).
    NonManifoldVertex,
    /// A vertex whose faces formed several edge-connected fans (surfaces touching at a point);
    /// split into one vertex per fan at the same position (Warning, repaired).
    SplitVertex,
    /// An edge with only one face (Note; the 1994 inner-hull schemes need closed meshes).
    BoundaryEdge,
    /// Faces flipped to make the orientation consistent with their neighbours (Warning, repaired).
    InconsistentOrientation,
    /// A component cannot be oriented consistently (Möbius-like) (Warning).
    NonOrientable,
    /// A closed component was oriented inwards; all its faces were flipped (Warning, repaired).
    InwardOrientation,
    /// The file's per-corner normals of a vertex disagree; they were averaged (Note).
    FileNormalsAveraged,
    /// Some vertices have no file normal, so the file's normals are not used (Warning).
    FileNormalsIncomplete,
    /// A statement of the file format that is understood but ignored (lines, points, free-form) (Note).
    IgnoredStatements,
}

impl FindingKind {
    /// The severity this kind always has.
    #[must_use]
    pub fn severity(self) -> Severity {
        use FindingKind::*;
        match self {
            WeldedVertices | BoundaryEdge | FileNormalsAveraged | IgnoredStatements => {
                Severity::Note
            }
            _ => Severity::Warning,
        }
    }
}

/// One element of the mesh a finding points at. Indices are the loaded mesh's (0-based, after
/// welding); `line` is the 1-based line of the file that defined it (or the face using it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "element", rename_all = "snake_case")]
pub enum Element {
    /// A vertex of the loaded mesh.
    Vertex {
        /// Index into `Mesh::positions`.
        index: u32,
        /// Line of the file defining it.
        line: u32,
    },
    /// A face of the loaded mesh (or, for dropped faces, the file's face number, 0-based).
    Face {
        /// Index into `Mesh::faces` (file face number for dropped faces).
        index: u32,
        /// Line of the file defining it.
        line: u32,
    },
    /// An edge between two vertices of the loaded mesh.
    Edge {
        /// Its two vertices, smaller index first.
        vertices: [u32; 2],
        /// Line of a face using it.
        line: u32,
    },
}

impl fmt::Display for Element {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Element::Vertex { index, line } => write!(f, "vertex {index} (line {line})"),
            Element::Face { index, line } => write!(f, "face {index} (line {line})"),
            Element::Edge { vertices, line } => {
                write!(f, "edge {}-{} (line {line})", vertices[0], vertices[1])
            }
        }
    }
}

/// Every element of one kind of problem.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    /// What is wrong.
    pub kind: FindingKind,
    /// How serious it is (fixed per kind).
    pub severity: Severity,
    /// One-line summary, e.g. "3 boundary edges in 1 loop".
    pub message: String,
    /// Every offending element, in index order.
    pub elements: Vec<Element>,
}

/// How many elements [`Finding`]'s `Display` lists before "…".
pub const LISTED_ELEMENTS: usize = 8;

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sev = match self.severity {
            Severity::Note => "note",
            Severity::Warning => "warning",
        };
        write!(f, "{sev}: {}", self.message)?;
        for (i, e) in self.elements.iter().take(LISTED_ELEMENTS).enumerate() {
            write!(f, "{}{e}", if i == 0 { ": " } else { ", " })?;
        }
        if self.elements.len() > LISTED_ELEMENTS {
            write!(f, ", … ({} more)", self.elements.len() - LISTED_ELEMENTS)?;
        }
        Ok(())
    }
}

/// The findings of loading and validating one file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Report {
    /// The file's path as given.
    pub path: String,
    /// Findings, at most one per kind, in the order the checks ran.
    pub findings: Vec<Finding>,
}

impl Report {
    /// Adds a finding of `kind` (skipped when `elements` is empty and the message is not needed).
    pub fn add(&mut self, kind: FindingKind, message: String, elements: Vec<Element>) {
        self.findings.push(Finding {
            kind,
            severity: kind.severity(),
            message,
            elements,
        });
    }

    /// The finding of `kind`, if any.
    #[must_use]
    pub fn get(&self, kind: FindingKind) -> Option<&Finding> {
        self.findings.iter().find(|f| f.kind == kind)
    }

    /// True when some finding is a [`Severity::Warning`].
    #[must_use]
    pub fn has_warnings(&self) -> bool {
        self.findings
            .iter()
            .any(|f| f.severity == Severity::Warning)
    }

    /// True when no edge or vertex is non-manifold.
    #[must_use]
    pub fn is_manifold(&self) -> bool {
        self.get(FindingKind::NonManifoldEdge).is_none()
            && self.get(FindingKind::NonManifoldVertex).is_none()
    }

    /// True when the mesh is manifold, orientable and has no boundary edge.
    #[must_use]
    pub fn is_closed_manifold(&self) -> bool {
        self.is_manifold()
            && self.get(FindingKind::BoundaryEdge).is_none()
            && self.get(FindingKind::NonOrientable).is_none()
    }

    /// Checks what a construction scheme needs: every scheme needs a manifold, orientable mesh;
    /// the 1994 inner-hull schemes (`closed = true`) also need it closed. The 2001 rational scheme
    /// accepts boundary edges (`closed = false`).
    pub fn require(&self, closed: bool) -> crate::error::Result<()> {
        let blocking = [
            FindingKind::NonManifoldEdge,
            FindingKind::NonManifoldVertex,
            FindingKind::NonOrientable,
        ];
        for f in &self.findings {
            if blocking.contains(&f.kind) || (closed && f.kind == FindingKind::BoundaryEdge) {
                return Err(crate::error::Error::Input {
                    path: self.path.clone().into(),
                    message: format!("{f}"),
                });
            }
        }
        Ok(())
    }
}
