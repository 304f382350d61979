//! `apatch check`: measure a patch complex; exit 0 when it keeps its scheme's promise, 1 when
//! it does not, 2 on bad input.

use apatch::check::{self, CheckOptions};
use apatch::complex::PatchComplex;
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `apatch check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// A patch complex (.json, from `apatch export patches`), a scene (.toml) or a model file.
    pub input: PathBuf,
    /// Print the report as JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Hold the complex to this continuity (1 or 2) instead of its scheme's promise.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub continuity: Option<u8>,
    /// Largest relative jump of F and ∇F across shared faces.
    #[arg(long, default_value = "1e-9", value_parser = tolerance)]
    pub jump_tolerance: f64,
    /// Largest relative Hessian jump across shared faces (C2 promises).
    #[arg(long, default_value = "1e-7", value_parser = tolerance)]
    pub hessian_tolerance: f64,
    /// Largest relative |F| at an interpolated vertex.
    #[arg(long, default_value = "1e-9", value_parser = tolerance)]
    pub value_tolerance: f64,
    /// Largest angle (radians) between ∇F and a vertex normal.
    #[arg(long, default_value = "1e-7", value_parser = tolerance)]
    pub angle_tolerance: f64,
    /// Relative slope at or below which a shooting root counts as not simple.
    #[arg(long, default_value = "1e-8", value_parser = tolerance)]
    pub simple_root_tolerance: f64,
    /// Fail (rather than warn) when a single-sheet patch is crossed twice by a line.
    #[arg(long)]
    pub single_sheet: bool,
    /// Also write every boundary face the surface crosses (the holes: patch, element, corners,
    /// depth, a point of the minority sign) and every patch a j-line crosses twice (the
    /// j-sheets: patch, element, lines, the first root) to this JSON file (format
    /// `apatch-holes`).
    #[arg(long, value_name = "FILE")]
    pub holes: Option<PathBuf>,
}

/// Format name of the file `--holes` writes.
pub const HOLES_FORMAT: &str = "apatch-holes";

/// Writes the crossed faces of `report` to `path` (atomically: a failed write leaves no file).
fn write_holes(path: &Path, input: &Path, report: &check::CheckReport) -> anyhow::Result<()> {
    let doc = serde_json::json!({
        "format": HOLES_FORMAT,
        "version": 1,
        "input": input.display().to_string(),
        "boundary_faces": report.holes.boundary_faces,
        "crossing": report.holes.crossing,
        "faces": report.holes.faces,
        "j_sheet_patches": report.sheets.j_multi_patches,
        "j_sheets": report.sheets.j_sheets,
    });
    apatch::export::write_atomically(path, |out| {
        serde_json::to_writer(&mut *out, &doc).map_err(std::io::Error::other)?;
        writeln!(out)
    })
}

fn tolerance(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{s}` is not a finite non-negative number")),
    }
}

/// Loads the patch complex `path` names: a patch JSON file, or a scene (`scene::load` +
/// `scene::build_complex`, then validated); model files wait for a default scheme.
///
/// # Errors
/// A missing or unreadable file, invalid data, or an input kind not supported yet.
pub fn load_complex(path: &Path) -> anyhow::Result<PatchComplex> {
    Ok(load_complex_with_info(path)?.0)
}

/// [`load_complex`], plus what the 2001 scheme's mesh pipeline did (weld, subdivision,
/// refined edges) when `path` is a `rational-c1` mesh scene.
///
/// # Errors
/// As [`load_complex`].
pub fn load_complex_with_info(
    path: &Path,
) -> anyhow::Result<(PatchComplex, Option<apatch::scene::MeshBuildInfo>)> {
    let (built, _) = load_built(path)?;
    Ok((built.complex, built.info))
}

/// [`load_complex`], returning everything the build loaded and made
/// ([`apatch::scene::BuiltScene`]: the mesh, the 1994 hull the patches fill) and the scene when
/// `path` is one, so that reports reuse them rather than loading and building them again.
///
/// # Errors
/// As [`load_complex`].
pub fn load_built(
    path: &Path,
) -> anyhow::Result<(apatch::scene::BuiltScene, Option<apatch::scene::Scene>)> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let only = |complex| apatch::scene::BuiltScene {
        complex,
        info: None,
        mesh: None,
        hull: None,
        solve: None,
        hull_report: None,
        cubic_steps: None,
        clean: None,
        flatten: None,
    };
    match ext.as_str() {
        "json" => Ok((only(apatch::complex_io::read_json_file(path)?), None)),
        "toml" => {
            let scene = apatch::scene::load(path)?;
            if let apatch::scene::Model::Patches(json) = &scene.model {
                return Ok((only(apatch::complex_io::read_json_file(json)?), Some(scene)));
            }
            let built = super::with_progress(|| apatch::scene::build_scene(&scene))?;
            apatch::complex_io::validate(&built.complex)
                .map_err(|m| anyhow::anyhow!("{}: {m}", path.display()))?;
            Ok((built, Some(scene)))
        }
        "obj" | "off" => {
            if !path.exists() {
                anyhow::bail!("{}: no such file", path.display());
            }
            anyhow::bail!(
                "{}: model input needs a scheme; not available yet (give a scene .toml with \
                 [scheme] or a patches .json)",
                path.display()
            )
        }
        _ => anyhow::bail!(
            "{}: unknown input type (expected .json patches, a .toml scene or an .obj/.off model)",
            path.display()
        ),
    }
}

/// Whether `complex` comes from a 1994 scheme (`cubic-c1`, `quintic-c2`: the surface
/// approximates the polyhedron and lives on an inner hull).
fn is_1994(complex: &PatchComplex) -> bool {
    matches!(complex.scheme.as_str(), "cubic-c1" | "quintic-c2")
}

/// The scene's opt-in pre-subdivision (`model.subdivide`) when `input` is such a scene: the
/// surface then interpolates the subdivided mesh, not the input, and the report says so.
/// Also the scene's weld tolerance (`model.weld`), which changes the mesh the same way.
fn mesh_repairs(
    scene: Option<&apatch::scene::Scene>,
) -> (Option<apatch::mesh::Subdivision>, Option<f64>) {
    match scene.map(|s| &s.model) {
        Some(apatch::scene::Model::Mesh {
            subdivide, weld, ..
        }) => (
            subdivide.filter(|s| s.levels > 0),
            weld.filter(|w| *w > 0.0),
        ),
        _ => (None, None),
    }
}

/// The distance of the surface to the polyhedron `mesh` (1994 scenes: the mesh the build
/// loaded).
fn polyhedron_distance(
    mesh: &apatch::mesh::Mesh,
    complex: &PatchComplex,
) -> check::distance::DistanceStats {
    let tri = apatch::mesh::triangulate(mesh);
    let faces: Vec<[u32; 3]> = tri.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
    check::distance::distance_to_polyhedron(complex, &tri.positions, &faces, 6)
}

/// The 1994 schemes' mesh repairs before the hull.
type HullRepairs = (
    Option<(f64, apatch::hull::inner::close::CloseMerge)>,
    Option<(f64, apatch::hull::inner::planar::PlanarSplit)>,
);

/// What the 1994 schemes' close-vertex merge (`hull::inner::close`, opt-in) and planar split
/// (`hull::inner::planar`) do to the scene's mesh: each with its threshold, `None` when it
/// changes nothing (or the scene is no mesh scene). The split's faces are the input's.
/// `built` is the polyhedron the build used (1994 scenes: after `model.clean`); without it the
/// scene's file is loaded.
fn hull_repairs(
    scene: &apatch::scene::Scene,
    built: Option<&apatch::mesh::Mesh>,
) -> anyhow::Result<HullRepairs> {
    let apatch::scene::Model::Mesh {
        file,
        scheme,
        normals,
        ..
    } = &scene.model
    else {
        return Ok((None, None));
    };
    let options = apatch::hull::inner::InnerOptions::from_toml(scheme, &scene.path)?;
    let loaded;
    let m = match built {
        Some(m) => m,
        None => {
            loaded = apatch::mesh::load(file)?.0;
            &loaded
        }
    };
    // The hull's normals, for the split's steep and folded corners (as `hull::inner` has them).
    let vn = normals
        .parse()
        .ok()
        .and_then(|method| apatch::mesh::vertex_normals(m, method).ok());
    let merged = apatch::hull::inner::close::merge_close_vertices(
        m,
        vn.as_deref().unwrap_or(&[]),
        options.merge_close,
    )?;
    let mesh = merged.as_ref().map_or(m, |c| &c.mesh);
    let vn = merged.as_ref().map_or(vn.as_deref(), |c| {
        (c.normals.len() == mesh.positions.len()).then_some(&c.normals[..])
    });
    let split =
        apatch::hull::inner::planar::split_nonplanar_steep(mesh, options.planar_tolerance, vn).map(
            |mut s| {
                if merged.is_some() {
                    for f in &mut s.faces {
                        f.face = mesh.face_parent[f.face as usize];
                    }
                    for f in &mut s.kept {
                        *f = mesh.face_parent[*f as usize];
                    }
                }
                (options.planar_tolerance, s)
            },
        );
    Ok((merged.map(|c| (options.merge_close, c)), split))
}

/// What the inner hull's builder changed, by step (counts; the `hull_steps` of `--json`, the
/// nonzero ones in the text line): its order is the builder's.
fn hull_steps(r: &apatch::hull::inner::InnerReport) -> Vec<(&'static str, usize)> {
    vec![
        ("normals_above_face", r.adjusted_normals.len()),
        ("corners_remeshed", r.remeshed.len()),
        ("polygons_split_convex", r.split_faces.len()),
        ("star_polygons", r.star_faces.len()),
        ("flat_nets", r.flat_nets),
        ("straight_corners", r.straight_corners),
        ("unseparable_corners", r.unseparable.len()),
        ("degenerate_apexes_rebuilt", r.degenerate_repaired),
        ("ring_normals_turned", r.ring_normals),
        ("umbrella_normals", r.umbrella_normals.len()),
        ("folds_flipped", r.flipped_folds),
        ("slits_flipped", r.flipped_slits),
        ("apexes_wedged", r.wedged),
        ("apexes_lifted", r.lifted_apexes),
        ("apex_search_moves", r.reapex.moved.len()),
        ("apex_search_overlaps_before", r.reapex.before),
        ("apex_search_overlaps_after", r.reapex.after),
    ]
}

/// An apex search's moves and overlapping pairs before → after, for the steps lines; `None`
/// when it did not run or found nothing to do.
fn apex_search_text(s: &apatch::hull::inner::reapex::Search) -> Option<String> {
    (s.before > 0 || !s.moved.is_empty()).then(|| {
        format!(
            "apex search {} moves (overlapping pairs {} -> {})",
            s.moved.len(),
            s.before,
            s.after
        )
    })
}

/// What the cubic scheme changed on the hull before filling it
/// (`scheme::cubic_c1::prepare_hull`), the nonzero counts in one `info` line; `None` when it
/// changed nothing.
fn cubic_steps_line(c: &apatch::scheme::cubic_c1::PrepareSteps) -> Option<String> {
    let mut done: Vec<String> = [
        ("L-U partners added", c.lu_completed),
        ("apexes moved over tangent planes", c.tangent_moved),
        ("apexes stuck beyond one", c.tangent_stuck),
    ]
    .iter()
    .filter(|(_, n)| *n > 0)
    .map(|(k, n)| format!("{k} {n}"))
    .collect();
    done.extend(apex_search_text(&c.reapex));
    (!done.is_empty()).then(|| {
        format!(
            "cubic steps      {} (the cubic scheme's apex changes, `cubic_c1::prepare_hull`)  info",
            done.join(", ")
        )
    })
}

/// The quintic scheme's solve in one `info` line: its size, what it relaxed or conditioned,
/// whether it fell back to solving every weight at once, the weights off Theorem 2.1's signs
/// (sufficient for one sheet, not necessary: the `sheets`, `j-sheets` and `holes` lines test
/// the surface itself), and the hole repair when it ran.
fn solve_line(s: &apatch::scheme::quintic_c2::BuildStats) -> String {
    let r = &s.hole_repair;
    let repair = if r == &Default::default() {
        String::new()
    } else {
        format!(
            "; hole repair: crossed faces {} -> {}, j-sheets {} -> {}",
            r.crossed_before, r.crossed_after, r.sheets_before, r.sheets_after
        )
    };
    let slivers = if s.slivers_found == 0 {
        String::new()
    } else {
        format!(
            "; sliver edge tetrahedra {} ({} thickened)",
            s.slivers_found, s.slivers_thickened
        )
    };
    let p = &s.sign_projection;
    let held = if s.normal_rows > 0 {
        format!(", {} rows holding the Hessians' normal part", s.normal_rows)
    } else {
        String::new()
    };
    let projection = if p.too_large {
        "; sign projection skipped: too large to factor".to_string()
    } else if p.rounds == 0 && !p.program {
        match &p.program_error {
            Some(e) => format!("; sign program not solved: {e}"),
            None => String::new(),
        }
    } else {
        format!(
            "; sign projection: {} -> {} weights off their signs {}{}{}",
            p.off_before,
            p.off_after,
            if p.program {
                format!(
                    "by the linear program ({})",
                    apatch::scheme::quintic_c2::signfit::SOLVER
                )
            } else {
                let failed = p
                    .program_error
                    .as_ref()
                    .map(|e| format!(" (sign program not solved: {e})"))
                    .unwrap_or_default();
                format!("in {} rounds{failed}", p.rounds)
            },
            if p.precise {
                ", last move in double-double"
            } else {
                ""
            },
            if p.kept {
                String::new()
            } else {
                format!(" (not kept: equations met to {:.1e})", p.residual)
            }
        )
    };
    format!(
        "solve            {} unknowns, {} equations, largest group {} ({} sparse), residual \
         {:.1e}; {} points of T relaxed, {} consistency conditions{}{held}; {} weights off \
         Theorem 2.1's sufficient signs, in {} patches{slivers}{projection}{repair}  info",
        s.unknowns,
        s.equations,
        s.largest_group,
        s.sparse_groups,
        s.max_residual,
        s.relaxed_points,
        s.consistency_conditions,
        if s.global {
            "; the staged solve failed: every weight solved at once"
        } else {
            ""
        },
        s.signs.violated(),
        s.signs.violating_patches
    )
}

/// One line per hull violation: the condition, the triangle of T, the detail.
fn violation_line(v: &apatch::hull::inner::HullViolation) -> String {
    match v.triangle {
        Some(t) => format!("{:?} at hull triangle {t}: {}", v.kind, v.message),
        None => format!("{:?}: {}", v.kind, v.message),
    }
}

/// Runs `apatch check`.
pub fn run(args: CheckArgs) -> anyhow::Result<ExitCode> {
    let (built, scene) = load_built(&args.input)?;
    let (complex, build_info) = (&built.complex, built.info);
    let opts = CheckOptions {
        continuity: args.continuity,
        jump_tolerance: args.jump_tolerance,
        hessian_tolerance: args.hessian_tolerance,
        value_tolerance: args.value_tolerance,
        angle_tolerance: args.angle_tolerance,
        simple_root_tolerance: args.simple_root_tolerance,
        single_sheet: args.single_sheet,
        ..CheckOptions::default()
    };
    let report = check::check(complex, &opts);
    if let Some(path) = &args.holes {
        write_holes(path, &args.input, &report)?;
        eprintln!(
            "apatch: wrote {} crossed boundary faces and {} j-sheet patches to {}",
            report.holes.faces.len(),
            report.sheets.j_sheets.len(),
            path.display()
        );
    }
    // 1994 scenes: the distance to the very mesh and the verdict on the very hull (Definition
    // 3.6, Lemmas 4.1-4.3: `hull::inner::verify`) the build used.
    let (distance, hull) = match &built.mesh {
        Some(m) if is_1994(complex) => (
            Some(polyhedron_distance(m, complex)),
            built.hull.as_ref().map(apatch::hull::inner::verify),
        ),
        _ => (None, None),
    };
    let (merged, split) = match &scene {
        // 1994 scenes: the mesh the build loaded (and cleaned), not loaded and cleaned again.
        Some(s) => hull_repairs(s, built.mesh.as_ref().filter(|_| is_1994(complex)))?,
        None => (None, None),
    };
    let hull_valid = hull.as_ref().is_none_or(Vec::is_empty);
    let (subdivided, welded) = mesh_repairs(scene.as_ref());
    let passed = report.passed() && hull_valid;
    if args.json {
        // The verdict first, then every measure.
        let mut out = serde_json::Map::new();
        out.insert("passed".into(), passed.into());
        out.insert("failures".into(), report.failures().into());
        if let serde_json::Value::Object(fields) = serde_json::to_value(&report)? {
            out.extend(fields);
        }
        if let Some(d) = &distance {
            out.insert("distance".into(), serde_json::to_value(d)?);
        }
        if let Some(sd) = &subdivided {
            out.insert("subdivision".into(), serde_json::to_value(sd)?);
        }
        if let Some(w) = welded {
            out.insert("weld".into(), w.into());
        }
        if let Some(c) = &built.clean {
            out.insert("clean".into(), serde_json::to_value(c)?);
        }
        if let Some(f) = &built.flatten {
            out.insert("flatten".into(), serde_json::to_value(f)?);
        }
        if let Some(c) = &built.cubic_steps {
            out.insert(
                "cubic_steps".into(),
                serde_json::json!({
                    "lu_completed": c.lu_completed,
                    "tangent_moved": c.tangent_moved,
                    "tangent_stuck": c.tangent_stuck,
                    "apex_search_moves": c.reapex.moved.len(),
                    "apex_search_overlaps_before": c.reapex.before,
                    "apex_search_overlaps_after": c.reapex.after,
                }),
            );
        }
        if let Some(info) = &build_info {
            out.insert("mesh_build".into(), serde_json::to_value(info)?);
        }
        if let Some(stats) = &built.solve {
            out.insert("solve".into(), serde_json::to_value(stats)?);
        }
        if let Some(r) = &built.hull_report {
            let steps: serde_json::Map<String, serde_json::Value> = hull_steps(r)
                .into_iter()
                .map(|(k, v)| (k.to_string(), v.into()))
                .collect();
            out.insert("hull_steps".into(), steps.into());
        }
        if let Some((t, c)) = &merged {
            out.insert(
                "merge_close".into(),
                serde_json::json!({
                    "threshold": t,
                    "clusters": c.clusters,
                    "dropped_faces": c.dropped_faces,
                }),
            );
        }
        if let Some((tolerance, sp)) = &split {
            out.insert(
                "planar_split".into(),
                serde_json::json!({
                    "tolerance": tolerance,
                    "faces": sp.faces,
                    "triangles": sp.faces.iter().map(|f| f.triangles).sum::<usize>(),
                    "kept": sp.kept,
                }),
            );
        }
        if let Some(v) = &hull {
            let list: Vec<String> = v.iter().map(violation_line).collect();
            out.insert(
                "hull".into(),
                serde_json::json!({ "valid": v.is_empty(), "violations": list }),
            );
        }
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        if let Some(f) = &built.flatten {
            println!(
                "flatten          {} nearly flat regions ({} faces) snapped onto their planes, {} \
                 vertices moved ≤ {:.3e}: the hull is built on the flattened polyhedron \
                 (`model.flatten`, `mesh::flatten`)  info",
                f.regions, f.faces, f.moved, f.max_move
            );
        }
        if let Some(c) = &built.clean {
            let nearly = if c.coplanar_merged > 0 {
                format!(
                    ", {} nearly coplanar face pairs merged (`model.clean_coplanar`)",
                    c.coplanar_merged
                )
            } else {
                String::new()
            };
            println!(
                "clean            {} vertices welded, {} T-junctions split, {} coplanar face \
                 pairs merged and {} straight vertices dropped at two-face vertices{nearly}, \
                 planar to {:.1e} of the diagonal, vertices moved ≤ {:.3e}: the surface \
                 approximates the cleaned polyhedron (`model.clean`, `mesh::clean`)  info",
                c.welded,
                c.t_junctions,
                c.merged_faces,
                c.dropped_vertices,
                c.planarity,
                c.max_move
            );
        }
        if let Some(w) = welded {
            println!(
                "weld             vertices closer than {w:e} of the bounding-box diagonal were \
                 welded before the hull: the surface interpolates the welded mesh  info"
            );
        }
        if let Some(sd) = &subdivided {
            println!(
                "subdivision      {} levels of `{}` before the hull: the surface interpolates the \
                 subdivided, locally refined mesh ({} vertices), not the input mesh  info",
                sd.levels,
                sd.rule,
                complex.vertices.len()
            );
        }
        if let Some(info) = &build_info {
            println!(
                "mesh             {} triangles{}{}; {} edges refined because adjacent face \
                 tetrahedra intersected (§3.1)  info",
                info.input_triangles,
                if info.welded_vertices > 0 {
                    format!(" ({} vertices welded)", info.welded_vertices)
                } else {
                    String::new()
                },
                if info.subdivided_triangles != info.input_triangles {
                    format!(", {} after subdivision", info.subdivided_triangles)
                } else {
                    String::new()
                },
                info.refined_edges
            );
        }
        if let Some(r) = &built.hull_report {
            let mut done: Vec<String> = hull_steps(r)
                .into_iter()
                .filter(|(k, n)| *n > 0 && !k.starts_with("apex_search"))
                .map(|(k, n)| format!("{} {n}", k.replace('_', " ")))
                .collect();
            done.extend(apex_search_text(&r.reapex));
            if !done.is_empty() {
                println!(
                    "hull steps       {} (the inner hull's repairs, `hull::inner::InnerReport`)  info",
                    done.join(", ")
                );
            }
        }
        if let Some(line) = built.cubic_steps.as_ref().and_then(cubic_steps_line) {
            println!("{line}");
        }
        if let Some(stats) = &built.solve {
            println!("{}", solve_line(stats));
        }
        if let Some((t, c)) = &merged {
            println!(
                "close merge      {} clusters of vertices closer than {t:e} of the bounding-box \
                 diagonal made one corner of T each, {} sliver faces dropped before the hull \
                 (`scheme.merge_close`)  info",
                c.clusters.len(),
                c.dropped_faces.len()
            );
        }
        if let Some((tolerance, sp)) = &split {
            println!(
                "planar split     {} non-planar polygons (beyond {tolerance:e} of their size) split \
                 into {} triangles before the hull (`scheme.planar_tolerance`){}{}  info",
                sp.faces.len(),
                sp.faces.iter().map(|f| f.triangles).sum::<usize>(),
                match sp.faces.iter().map(|f| f.joined).sum::<usize>() {
                    0 => String::new(),
                    j => format!(
                        ", {j} nearly coplanar pairs at folded corners joined back into quads (`hull::inner::planar::JOIN_ANGLE`)"
                    ),
                },
                if sp.kept.is_empty() {
                    String::new()
                } else {
                    format!(
                        "; {} kept whole (no proper triangulation: faces {:?})",
                        sp.kept.len(),
                        sp.kept
                    )
                }
            );
        }
        print!("{report}");
        if let Some(d) = &distance {
            println!(
                "distance         max {:.4e}, mean {:.4e} of the bounding-box diagonal {:.4} \
                 ({} surface samples to the polyhedron)  info",
                d.max, d.mean, d.diagonal, d.samples
            );
        }
        if let Some(v) = &hull {
            if v.is_empty() {
                println!(
                    "hull             valid: Def. 3.6 / Lemmas 4.1-4.3 hold (edge-convex T, \
                     tangent-containing and non-intersecting face tetrahedra)  ok"
                );
            } else {
                println!(
                    "hull             {} violations of Def. 3.6 / Lemmas 4.1-4.3  FAIL",
                    v.len()
                );
                for x in v.iter().take(10) {
                    println!("  {}", violation_line(x));
                }
                println!("FAILED: the simplicial hull is not smoothable");
            }
        }
    }
    Ok(if passed {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Wrap {
        #[command(flatten)]
        args: CheckArgs,
    }

    /// The CLI's literal defaults are the library's constants.
    #[test]
    fn defaults_match_library() {
        let a = Wrap::parse_from(["x", "in.json"]).args;
        assert_eq!(a.jump_tolerance, check::DEFAULT_JUMP_TOLERANCE);
        assert_eq!(a.hessian_tolerance, check::DEFAULT_HESSIAN_TOLERANCE);
        assert_eq!(a.value_tolerance, check::DEFAULT_VALUE_TOLERANCE);
        assert_eq!(a.angle_tolerance, check::DEFAULT_ANGLE_TOLERANCE);
        assert_eq!(
            a.simple_root_tolerance,
            check::DEFAULT_SIMPLE_ROOT_TOLERANCE
        );
        assert!(Wrap::try_parse_from(["x", "in.json", "--jump-tolerance", "-1"]).is_err());
        assert!(Wrap::try_parse_from(["x", "in.json", "--continuity", "3"]).is_err());
    }
}
