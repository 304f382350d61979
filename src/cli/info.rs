//! `apatch info`: describe a mesh — counts, topology, convexity classes, validation findings.
//!
//! Exit code: 0 when the mesh loads with notes only, 1 when it has warnings, 2 on errors.

use apatch::mesh::{self, NormalMethod, Summary};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `apatch info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Input mesh (.obj or .off).
    pub input: PathBuf,
    /// Vertex normals for the convexity classes: angle, area, loop or file
    /// (default: loop for triangle meshes, angle otherwise).
    #[arg(long, value_parser = parse_normals)]
    pub normals: Option<NormalMethod>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

fn parse_normals(s: &str) -> Result<NormalMethod, String> {
    s.parse()
}

/// Runs `apatch info`.
pub fn run(args: InfoArgs) -> anyhow::Result<ExitCode> {
    let (m, report) = mesh::load(&args.input)?;
    let method = args
        .normals
        .unwrap_or_else(|| NormalMethod::default_for(&m));
    let s = mesh::summary(&m, &report, method);
    let tolerance = apatch::hull::inner::planar::DEFAULT_TOLERANCE;
    let split = apatch::hull::inner::planar::split_nonplanar(&m, tolerance);
    let (split_faces, split_triangles) = split.as_ref().map_or((0, 0), |sp| {
        (
            sp.faces.len(),
            sp.faces.iter().map(|f| f.triangles).sum::<usize>(),
        )
    });
    if args.json {
        let mut v = serde_json::to_value(&s)?;
        if let serde_json::Value::Object(fields) = &mut v {
            fields.insert(
                "planar_split_1994".into(),
                serde_json::json!({
                    "tolerance": tolerance,
                    "faces": split_faces,
                    "triangles": split_triangles,
                    "kept": split.as_ref().map_or(Vec::new(), |sp| sp.kept.clone()),
                }),
            );
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print_text(&args.input, &s);
        if split_faces > 0 {
            println!(
                "  1994 planar split {split_faces} polygons non-planar beyond {tolerance:e} of \
                 their size, split into {split_triangles} triangles for the 1994 schemes \
                 (`scheme.planar_tolerance`)"
            );
        }
    }
    Ok(if report.has_warnings() || s.normals_error.is_some() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn print_text(path: &std::path::Path, s: &Summary) {
    let valence: Vec<String> = s
        .faces_by_valence
        .iter()
        .map(|(k, n)| format!("{n}×{k}-gon"))
        .collect();
    println!("{}", path.display());
    println!("  vertices          {}", s.vertices);
    println!("  faces             {} ({})", s.faces, valence.join(", "));
    println!(
        "  edges             {} ({} boundary, {} non-manifold)",
        s.edges, s.boundary_edges, s.non_manifold_edges
    );
    println!("  boundary loops    {}", s.boundary_loops);
    println!("  components        {}", s.components);
    println!(
        "  genus             {} (Euler characteristic {})",
        s.genus
            .map_or("undefined (non-manifold or non-orientable)".into(), |g| g
                .to_string()),
        s.euler_characteristic
    );
    println!(
        "  bounding box      [{:.6}, {:.6}, {:.6}] – [{:.6}, {:.6}, {:.6}]",
        s.bbox_min[0], s.bbox_min[1], s.bbox_min[2], s.bbox_max[0], s.bbox_max[1], s.bbox_max[2]
    );
    println!(
        "  vertices          {} trihedral, {} non-trihedral, {} boundary, {} non-manifold",
        s.trihedral_vertices,
        s.non_trihedral_vertices,
        s.boundary_vertices,
        s.non_manifold_vertices
    );
    println!("  normals           {}", s.normals);
    let tri = if s.triangulated_for_2001 {
        " (on the ear-clipped triangulation)"
    } else {
        ""
    };
    let c = |c: &Option<mesh::ClassCounts>| match c {
        Some(c) => format!(
            "{} positive, {} zero, {} negative convex, {} nonconvex",
            c.positive, c.zero, c.negative, c.nonconvex
        ),
        None => "unknown (no normals)".into(),
    };
    if let Some(e) = &s.normals_error {
        println!("  warning: normals: {e}");
    }
    println!("  2001 edges{tri}: {}", c(&s.edges_2001));
    println!("  2001 triangles{tri}: {}", c(&s.triangles_2001));
    println!("  1994 edges: {}", c(&s.edges_1994));
    println!("  1994 triangles{tri}: {}", c(&s.triangles_1994));
    println!(
        "  1994 faces        {} convex, {} non-convex polygons",
        s.convex_faces_1994, s.nonconvex_faces_1994
    );
    if let Some(fails) = &s.above_face_failures {
        let list: Vec<String> = fails
            .iter()
            .take(mesh::LISTED_ELEMENTS)
            .map(u32::to_string)
            .collect();
        println!(
            "  1994 above-face   {} vertices fail{}{}{}",
            fails.len(),
            if list.is_empty() { "" } else { ": " },
            list.join(", "),
            if fails.len() > list.len() {
                ", …"
            } else {
                ""
            }
        );
    }
    if s.report.findings.is_empty() {
        println!("  findings          none");
    }
    for f in &s.report.findings {
        println!("  {f}");
    }
}
