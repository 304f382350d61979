//! `apatch render` end to end: overrides, outputs (PNG + EXR, no temporary files left), and
//! one-line errors with exit code 2 that name the scene file and key.

use crate::sphere_scene;

use sphere_scene::{sphere_scene, write_unit_sphere};
use std::path::PathBuf;
use std::process::Command;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("apatch-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The unit sphere, 320 × 240.
fn scene() -> String {
    sphere_scene("sphere.json", 320, 240, SCENE_REST)
}

const SCENE_REST: &str = r#"
[film]
spp = 8
[[lights]]
type = "directional"
direction = [-1, -1, -1]
irradiance = 3.0
[render]
output = "out/sphere.png"
"#;

fn setup(name: &str, scene: &str) -> PathBuf {
    let dir = scratch(name);
    write_unit_sphere(&dir, "sphere.json");
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    dir
}

#[test]
fn render_writes_png_and_exr_with_overrides() {
    let dir = setup("ok", &scene());
    let out = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args([
            "render", "s.toml", "--width", "24", "--height", "16", "--spp", "1",
        ])
        .args(["--mode", "normal", "--threads", "1", "--output", "o/x.exr"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = image::open(dir.join("o/x.png")).unwrap();
    assert_eq!((png.width(), png.height()), (24, 16));
    assert!(dir.join("o/x.exr").exists());
    let files: Vec<_> = std::fs::read_dir(dir.join("o")).unwrap().collect();
    assert_eq!(files.len(), 2, "temporary files left behind");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_scene_exits_2_naming_file_and_key() {
    let dir = setup("bad", &scene().replace("fov = 40", "fov = 40\nfocal = 3"));
    let out = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(["render", "s.toml"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("s.toml") && err.contains("focal"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    std::fs::write(dir.join("s.toml"), scene()).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(["render", "s.toml", "--mode", "fancy"])
        .current_dir(&dir)
        .output()
        .unwrap();
    // This scene is fine; the override is not.
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--mode"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn ctrl_c_stops_the_render_and_leaves_no_file() {
    use std::io::{BufRead, BufReader};
    // A render that takes minutes on one thread (4096² pixels × 64 spp): SIGINT arrives long
    // before it could finish, and it stops at the next row (4096 × 64 samples, well under a
    // second), so the outcome does not depend on timing.
    let dir = setup("sigint", &scene());
    let mut child = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(["render", "s.toml", "--width", "4096", "--height", "4096"])
        .args(["--spp", "64", "--threads", "1"])
        .current_dir(&dir)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut first = String::new();
    err.read_line(&mut first).unwrap();
    assert!(first.contains("rendering"), "{first}");
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let mut rest = String::new();
    for line in err.lines() {
        rest.push_str(&line.unwrap());
        rest.push('\n');
    }
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{rest}");
    assert!(rest.contains("interrupted"), "{rest}");
    // Neither the outputs nor their temporary siblings exist (nor their directory's content).
    let out = dir.join("out");
    let left: Vec<_> = std::fs::read_dir(&out)
        .map(|d| d.map(|e| e.unwrap().file_name()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
