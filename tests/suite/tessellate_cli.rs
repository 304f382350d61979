//! `apatch tessellate` from the command line: PLY and OBJ output of a scene, exit 2 with one
//! line and no output file on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("tessellate_cli_{name}"))
}

fn apatch(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(args)
        .output()
        .expect("run apatch")
}

fn scene() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/cube.toml")
        .to_string_lossy()
        .into_owned()
}

/// `apatch tessellate` of the cube scene to `out` at `resolution`.
fn tessellate_cube(out: &Path, resolution: usize) -> Output {
    apatch(&[
        "tessellate",
        &scene(),
        "-o",
        out.to_str().unwrap(),
        "--resolution",
        &resolution.to_string(),
    ])
}

#[test]
fn ply_and_obj_describe_the_same_closed_mesh() {
    let ply = tmp("cube.ply");
    let obj = tmp("cube.obj");
    for out in [&ply, &obj] {
        let o = tessellate_cube(out, 3);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    // OBJ: count v / vn / f and check every edge is shared by exactly two faces.
    let text = std::fs::read_to_string(&obj).unwrap();
    let nv = text.lines().filter(|l| l.starts_with("v ")).count();
    let nn = text.lines().filter(|l| l.starts_with("vn ")).count();
    let faces: Vec<Vec<usize>> = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| {
            l.split_whitespace()
                .skip(1)
                .map(|t| {
                    let (a, b) = t.split_once("//").expect("a//a");
                    assert_eq!(a, b);
                    a.parse().unwrap()
                })
                .collect()
        })
        .collect();
    assert_eq!(nv, nn);
    assert!(nv > 0 && !faces.is_empty());
    let mut edges = std::collections::HashMap::new();
    for f in &faces {
        assert_eq!(f.len(), 3);
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            assert!((1..=nv).contains(&a));
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    assert!(edges.values().all(|&c| c == 2), "not closed");
    // Sphere topology: V − E + F = 2.
    assert_eq!(nv as i64 - edges.len() as i64 + faces.len() as i64, 2);
    // PLY: binary little-endian with the same counts and the exact byte size they imply.
    let bytes = std::fs::read(&ply).unwrap();
    let end = b"end_header\n";
    let h = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    let header = String::from_utf8_lossy(&bytes[..h]);
    assert!(header.starts_with("ply\nformat binary_little_endian 1.0\n"));
    assert!(header.contains(&format!("element vertex {nv}\n")));
    assert!(header.contains(&format!("element face {}\n", faces.len())));
    assert!(header.contains("property list uchar int vertex_indices"));
    assert_eq!(bytes.len() - h, nv * 6 * 4 + faces.len() * (1 + 3 * 4));
}

#[test]
fn bad_input_exits_2_and_leaves_no_file() {
    let out = tmp("bad.obj");
    let _ = std::fs::remove_file(&out);
    let o = apatch(&[
        "tessellate",
        "no/such/scene.toml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&o.stderr).lines().count(), 1);
    assert!(!out.exists());
    let stl = tmp("bad.stl");
    let o = apatch(&["tessellate", &scene(), "-o", stl.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("expected .ply or .obj"));
    assert!(!stl.exists());
    let o = tessellate_cube(&out, 0);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    // No temporary sibling left behind either.
    let dir = std::fs::read_dir(env!("CARGO_TARGET_TMPDIR")).unwrap();
    assert!(!dir
        .filter_map(Result::ok)
        .any(|e| e.file_name().to_string_lossy().contains("bad.obj.partial")));
}
