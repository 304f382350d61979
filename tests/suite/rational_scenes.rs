//! The paper's examples as scenes (`scenes/paper2001/*.toml`): each builds through
//! `RationalOptions::from_toml` from its OBJ (file normals) and passes the scheme's checks.

use crate::rational_support as support;

use apatch::mesh::{load, triangulate, vertex_normals, NormalMethod};
use apatch::scheme::rational_c1::{build, RationalOptions};
use std::path::Path;

/// Exact by construction; rounding only.
const TOL: f64 = 1e-9;

#[test]
fn paper_scenes_build_and_pass_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper2001");
    let mut scenes: Vec<_> = std::fs::read_dir(&dir)
        .expect("scene directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 5);
    for scene in scenes {
        let text = std::fs::read_to_string(&scene).unwrap();
        let t: toml::Table = toml::from_str(&text).unwrap();
        let model = t["model"].as_table().unwrap();
        assert_eq!(model["normals"].as_str(), Some("file"));
        let obj = dir.join(model["file"].as_str().unwrap());
        let scheme = t["scheme"].as_table().unwrap();
        assert_eq!(scheme["type"].as_str(), Some("rational-c1"));
        let opts = RationalOptions::from_toml(scheme, &scene).unwrap();
        let (mesh, _) = load(&obj).unwrap();
        let mesh = triangulate(&mesh);
        let normals = vertex_normals(&mesh, NormalMethod::File).unwrap();
        let tris: Vec<[u32; 3]> = mesh.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
        let b = build(&mesh.positions, &tris, &normals, &opts).unwrap();
        let c = &b.complex;
        let (fv, gv) = support::interpolation(c);
        let cont = support::continuity(c, 6);
        let (lines, slope) = support::min_root_slope(c, 8);
        let name = scene.file_name().unwrap().to_string_lossy();
        eprintln!(
            "{name}: faces {:?} edges {:?} patches {} interp {fv:.1e}/{gv:.1e} jumps {:.1e}/{:.1e} \
             roots {lines} min slope {slope:.2e} f {:?} B {:?}",
            b.faces_by_class,
            b.edges_by_class,
            c.patches.len(),
            cont.max_value_jump,
            cont.max_grad_jump,
            b.free_values,
            b.lower_bounds
        );
        assert!(fv < TOL && gv < TOL, "{name}");
        assert!(
            cont.max_value_jump < TOL && cont.max_grad_jump < TOL,
            "{name}"
        );
        assert!(cont.max_sharing <= 2, "{name}");
        // A simple root has a nonzero slope (relative to the coefficient scale).
        assert!(slope > 1e-9, "{name}: {slope}");
    }
}
