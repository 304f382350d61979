//! apatch against Mitsuba 3 on spheres, through `scripts/mitsuba_render.py` and
//! `apatch compare`:
//! - a quadric fixture complex (degree-2 A-patches of the unit sphere) against Mitsuba's
//!   analytic sphere, in a hand-written Mitsuba scene;
//! - the icosahedron with exact sphere normals under the 2001 rational scheme with
//!   `free = "quadric"` (quadratic precision: the exact unit sphere), through a scene file, the
//!   scene loader and `export::mitsuba` emitting Mitsuba's analytic `sphere` in place of the
//!   mesh. This pins the camera (off-axis, non-square, vertical fov) and light conventions.
//!
//! Mitsuba comes from `MITSUBA_PYTHON` (a Python with `mitsuba` and `numpy`; a broken one fails
//! the tests) or else from the venv `.ci/run` creates in `target/mitsuba-venv`. Without either
//! the tests print `skipped: <reason>` to stderr (uncaptured, so `cargo test` shows it) and pass.

use crate::sphere_scene;
use apatch::compare::{self, Image};
use apatch::export::mitsuba::{scene_xml_with, LookAt, Surface};

use apatch::fixtures::icosahedron;
use glam::DVec3;
use sphere_scene::{sphere_scene, write_unit_sphere};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Prints `skipped: <why>` where `cargo test` shows it (test output capture only intercepts
/// the print macros, not direct writes to the stderr handle).
fn skip(test: &str, why: &str) {
    let _ = writeln!(std::io::stderr(), "{test}: skipped: {why}");
}

/// The Python to render with, or why there is none.
fn mitsuba_python() -> Result<PathBuf, String> {
    if let Some(p) = std::env::var_os("MITSUBA_PYTHON").filter(|p| !p.is_empty()) {
        // An explicit choice must work: a broken one is a failure, not a skip.
        let p = PathBuf::from(p);
        assert!(
            imports_mitsuba(&p),
            "MITSUBA_PYTHON={} cannot import mitsuba",
            p.display()
        );
        return Ok(p);
    }
    // The venv of `.ci/run`, in the target directory this test binary was built into
    // (target/<profile>/deps/<test>), or in the manifest's target/.
    let mut candidates = Vec::new();
    if let Ok(exe) = std::env::current_exe() {
        if let Some(target) = exe.ancestors().nth(3) {
            candidates.push(target.join("mitsuba-venv/bin/python"));
        }
    }
    candidates.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("target/mitsuba-venv/bin/python"));
    let Some(p) = candidates.iter().find(|p| p.is_file()) else {
        return Err(format!(
            "no Mitsuba: MITSUBA_PYTHON is unset and {} does not exist (bash .ci/run creates it)",
            candidates[candidates.len() - 1].display()
        ));
    };
    if imports_mitsuba(p) {
        Ok(p.clone())
    } else {
        Err(format!("{} cannot import mitsuba", p.display()))
    }
}

fn imports_mitsuba(python: &Path) -> bool {
    Command::new(python)
        .args(["-c", "import mitsuba, numpy"])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("apatch-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Renders `xml` (in `dir`) with Mitsuba's `scalar_rgb` variant (deterministic, always
/// available) to `dir/mitsuba.exr`.
fn render_mitsuba(python: &Path, dir: &Path, xml: &str) -> Image {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/mitsuba_render.py");
    let out = Command::new(python)
        .args([
            script,
            xml,
            "mitsuba.exr",
            "--quiet",
            "--variant",
            "scalar_rgb",
        ])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "mitsuba_render.py: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    compare::read_exr(&dir.join("mitsuba.exr")).unwrap()
}

/// Renders the scene file `toml` (in `dir`, output `apatch.exr`) with the apatch CLI.
fn render_apatch(dir: &Path, toml: &str) -> Image {
    let out = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(["render", toml])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "apatch render: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    compare::read_exr(&dir.join("apatch.exr")).unwrap()
}

/// `apatch compare --json` of the two renders in `dir`.
fn compare_cli(dir: &Path) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args([
            "compare",
            "apatch.exr",
            "mitsuba.exr",
            "--json",
            "--side-by-side",
            "sbs.png",
        ])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    serde_json::from_slice(&out.stdout).unwrap()
}

const SPHERE_XML: &str = r#"<scene version="3.0.0">
  <integrator type="direct"/>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="256"/></sampler>
    <film type="hdrfilm">
      <integer name="width" value="64"/><integer name="height" value="48"/>
      <string name="pixel_format" value="rgba"/>
      <rfilter type="box"/>
    </film>
  </sensor>
  <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.8, 0.8, 0.8"/></bsdf></shape>
  <emitter type="directional"><vector name="direction" value="-1, -1, -1"/><rgb name="irradiance" value="3, 3, 3"/></emitter>
</scene>
"#;

/// The scene of `SPHERE_XML` for apatch (camera, film, albedo and light alike).
fn sphere_toml() -> String {
    sphere_scene("sphere.json", 64, 48, SPHERE_REST)
}

const SPHERE_REST: &str = r#"
[film]
spp = 64
filter = "box"
[material]
albedo = 0.8
[[lights]]
type = "directional"
direction = [-1, -1, -1]
irradiance = 3.0
[render]
output = "apatch.exr"
"#;

#[test]
fn sphere_agrees_with_mitsuba() {
    let python = match mitsuba_python() {
        Ok(p) => p,
        Err(why) => return skip("sphere_agrees_with_mitsuba", &why),
    };
    let dir = scratch("compare-mts-sphere");
    write_unit_sphere(&dir, "sphere.json");
    std::fs::write(dir.join("s.toml"), sphere_toml()).unwrap();
    std::fs::write(dir.join("s.xml"), SPHERE_XML).unwrap();
    render_mitsuba(&python, &dir, "s.xml");
    render_apatch(&dir, "s.toml");
    let j = compare_cli(&dir);
    // Measured 51.9 dB on R (differences only in silhouette pixels: coverage sampling noise
    // and Mitsuba's f16 output). A 3 % radiance error on the lit part of the disc (~40 % of
    // the pixels, radiance ~0.4) alone would give ~42 dB, so 45 dB catches lighting or albedo
    // mismatches while leaving 7 dB for sampling noise.
    let psnr = j["channels"][0]["psnr"].as_f64().unwrap();
    assert!(psnr > 45.0, "R PSNR {psnr}");
    // Measured 0.9998; a shifted or mis-scaled sphere drops well below 0.99.
    assert!(j["ssim"].as_f64().unwrap() > 0.99);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The icosahedron scene: off-axis camera with a vertical fov on a non-square film, coloured
/// albedo and irradiance (channels must not mix), one directional light (Mitsuba's `direct`
/// is then noise-free away from the silhouette).
const ICO_TOML: &str = r#"
[model]
file = "ico.obj"
normals = "file"
[scheme]
type = "rational-c1"
free = "quadric"
[camera]
origin = [2.2, 1.3, 3.1]
target = [0.07, -0.11, 0.03]
up = [0.1, 1, 0]
fov = 34
fov_axis = "y"
width = 128
height = 96
[film]
spp = 256
filter = "box"
[material]
albedo = [0.8, 0.6, 0.4]
[[lights]]
type = "directional"
direction = [-0.6, -1, -0.4]
irradiance = [3.0, 2.5, 2.0]
[render]
mode = "shaded"
output = "apatch.exr"
"#;

/// The icosahedron of `fixtures` with its exact unit-sphere normals, as OBJ.
fn icosahedron_obj() -> String {
    let (v, f) = icosahedron();
    let mut s = String::new();
    for p in &v {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for p in &v {
        let n = p.normalize();
        s += &format!("vn {} {} {}\n", n.x, n.y, n.z);
    }
    for t in &f {
        let [a, b, c] = t.map(|i| i + 1);
        s += &format!("f {a}//{a} {b}//{b} {c}//{c}\n");
    }
    s
}

#[test]
fn icosahedron_quadric_matches_mitsubas_analytic_sphere() {
    let name = "icosahedron_quadric_matches_mitsubas_analytic_sphere";
    let python = match mitsuba_python() {
        Ok(p) => p,
        Err(why) => return skip(name, &why),
    };
    let dir = scratch("compare-mts-ico");
    std::fs::write(dir.join("ico.obj"), icosahedron_obj()).unwrap();
    std::fs::write(dir.join("ico.toml"), ICO_TOML).unwrap();
    let scene = apatch::scene::load(&dir.join("ico.toml")).unwrap();
    let xml = scene_xml_with(
        &scene,
        &LookAt::of_scene(&scene),
        &Surface::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        },
    );
    std::fs::write(dir.join("ico.xml"), xml).unwrap();
    let m = render_mitsuba(&python, &dir, "ico.xml");
    let a = render_apatch(&dir, "ico.toml");
    let j = compare_cli(&dir);

    // Radiance: every colour channel at ≥ 45 dB. Away from the silhouette both sides compute
    // ρ/π·E·max(0, n·l) of the same sphere without noise (one delta light), so the residual
    // is coverage noise on the boundary and Mitsuba's f16 output (relative 5e-4).
    for ch in &j["channels"].as_array().unwrap()[..3] {
        let psnr = ch["psnr"].as_f64().unwrap();
        let _ = writeln!(
            std::io::stderr(),
            "{name}: {} PSNR {psnr:.2} dB",
            ch["name"]
        );
        assert!(psnr >= 45.0, "{}: PSNR {psnr}", ch["name"]);
    }

    // Silhouette. Mitsuba's alpha is a 256-sample binomial coverage estimate (sd ≤ 0.031),
    // apatch's a low-discrepancy one (error ≲ 0.01), so:
    // (1) no pixel differs by more than 0.25 in alpha (8 sd; a silhouette displaced by a
    //     quarter pixel would exceed it along the whole boundary);
    // (2) inside/outside (alpha ≥ 0.5) agrees on every pixel whose alpha is not within the
    //     noise of 0.5 on either side (|alpha − 0.5| > 0.1 in both images, 3 sd);
    // (3) the total coverage (the disc's projected area in pixels) agrees to 0.02 pixel per
    //     boundary pixel: Mitsuba's noise on the sum is ~0.5 pixel, while a radius error of
    //     1/50 pixel changes the sum by that much.
    let (aa, ma) = (a.channel("A").unwrap(), m.channel("A").unwrap());
    let (mut worst, mut flips, mut boundary) = (0.0f64, 0usize, 0usize);
    let (mut sum_a, mut sum_m) = (0.0f64, 0.0f64);
    for (&x, &y) in aa.iter().zip(ma) {
        let (x, y) = (f64::from(x), f64::from(y));
        worst = worst.max((x - y).abs());
        if (x - 0.5).abs() > 0.1 && (y - 0.5).abs() > 0.1 && (x >= 0.5) != (y >= 0.5) {
            flips += 1;
        }
        if (0.0..1.0).contains(&x.min(y)) && x.max(y) > 0.0 {
            boundary += 1;
        }
        sum_a += x;
        sum_m += y;
    }
    let _ = writeln!(
        std::io::stderr(),
        "{name}: alpha max |d| {worst:.3}, flips {flips}, boundary pixels {boundary}, \
         coverage {sum_a:.2} vs {sum_m:.2}"
    );
    assert!(boundary > 50, "the sphere must have a silhouette in view");
    assert!(worst < 0.25, "alpha differs by {worst}");
    assert_eq!(flips, 0, "inside/outside disagree");
    assert!(
        (sum_a - sum_m).abs() < 0.02 * boundary as f64,
        "coverage {sum_a} vs {sum_m}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
