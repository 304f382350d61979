//! `apatch export mitsuba` from the command line: the XML read back (plain string parsing) carries
//! the scene's sensor, film, sampler and emitters, and the PLY beside it has the vertex count of
//! `tessellate`; a bad scene is one line, exit 2, and no output.

use apatch::trace::Light;
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("export_mitsuba_{name}"))
}

fn apatch(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(args)
        .output()
        .expect("run apatch")
}

fn cube() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cube.toml")
}

/// `apatch export mitsuba <scene> -o <out>` with `extra` arguments.
fn export_mitsuba(scene: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "export",
        "mitsuba",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    apatch(&args)
}

/// A fresh scratch directory `tmp(name)` holding `file`, the cube scene's text after `edit`;
/// returns the directory and the file's path.
fn edited_cube(name: &str, file: &str, edit: impl FnOnce(String) -> String) -> (PathBuf, PathBuf) {
    let dir = tmp(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let toml = dir.join(file);
    std::fs::write(&toml, edit(std::fs::read_to_string(cube()).unwrap())).unwrap();
    (dir, toml)
}

/// The value of attribute `name` in the first element of `xml` that starts with `head`.
fn attr(xml: &str, head: &str, name: &str) -> String {
    let start = xml
        .find(head)
        .unwrap_or_else(|| panic!("no `{head}` in\n{xml}"));
    let element = &xml[start..start + xml[start..].find('>').expect("element closes")];
    let key = format!(" {name}=\"");
    let a = element
        .find(&key)
        .unwrap_or_else(|| panic!("no {name} in {element}"))
        + key.len();
    element[a..a + element[a..].find('"').unwrap()].to_string()
}

fn triple(s: &str) -> DVec3 {
    let v: Vec<f64> = s.split(',').map(|t| t.trim().parse().unwrap()).collect();
    assert_eq!(v.len(), 3, "{s}");
    DVec3::new(v[0], v[1], v[2])
}

fn num<T: std::str::FromStr>(s: &str) -> T
where
    T::Err: std::fmt::Debug,
{
    s.parse().unwrap()
}

/// Checks one `<emitter>` element: its `kind`, the `x`/`y`/`z` attributes of its first element
/// starting with `at.0` (a direction or a position) against `at.1`, and its `<rgb>` named
/// `rgb.0` against `rgb.1`.
fn assert_emitter(e: &str, kind: &str, at: (&str, DVec3), rgb: (&str, DVec3)) {
    assert_eq!(attr(e, "<emitter", "type"), kind);
    let v = DVec3::new(
        num(&attr(e, at.0, "x")),
        num(&attr(e, at.0, "y")),
        num(&attr(e, at.0, "z")),
    );
    assert_eq!(v, at.1);
    let head = format!("<rgb name=\"{}\"", rgb.0);
    assert_eq!(triple(&attr(e, &head, "value")), rgb.1);
}

/// The number in the `value` attribute of the first `<kind name="name" …>` element.
fn value<T: std::str::FromStr>(xml: &str, kind: &str, name: &str) -> T
where
    T::Err: std::fmt::Debug,
{
    num(&attr(xml, &format!("<{kind} name=\"{name}\""), "value"))
}

/// The `element vertex N` count of a PLY header.
fn ply_vertices(path: &Path) -> usize {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("PLY header");
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    assert!(header.contains("property float nx"), "normals: {header}");
    header
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .expect("vertex element")
        .trim()
        .parse()
        .unwrap()
}

#[test]
fn cube_xml_matches_the_scene_and_the_ply_matches_tessellate() {
    let dir = tmp("cube");
    let _ = std::fs::remove_dir_all(&dir);
    let o = export_mitsuba(&cube(), &dir, &["--resolution", "3"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let xml = std::fs::read_to_string(dir.join("cube.xml")).unwrap();
    let scene = apatch::scene::load(&cube()).unwrap();
    let s = &scene.settings;
    let c = &s.camera;

    assert_eq!(attr(&xml, "<scene", "version"), "3.0.0");
    // Sensor: the file's own look-at (cube.toml: origin, target [0,0,0], up [0,1,0]) and fov.
    assert_eq!(attr(&xml, "<sensor", "type"), "perspective");
    assert_eq!(triple(&attr(&xml, "<lookat", "origin")), c.origin);
    assert_eq!(triple(&attr(&xml, "<lookat", "target")), DVec3::ZERO);
    assert_eq!(triple(&attr(&xml, "<lookat", "up")), DVec3::Y);
    assert_eq!(value::<f64>(&xml, "float", "fov"), c.fov);
    assert_eq!(attr(&xml, "<string name=\"fov_axis\"", "value"), "x");
    assert_eq!(value::<f64>(&xml, "float", "near_clip"), c.near_clip);
    // Film, sampler, integrator, material.
    assert_eq!(attr(&xml, "<film", "type"), "hdrfilm");
    assert_eq!(value::<u32>(&xml, "integer", "width"), c.width);
    assert_eq!(value::<u32>(&xml, "integer", "height"), c.height);
    assert_eq!(attr(&xml, "<string name=\"pixel_format\"", "value"), "rgba");
    assert_eq!(attr(&xml, "<rfilter", "type"), "box");
    assert_eq!(attr(&xml, "<sampler", "type"), "independent");
    assert_eq!(value::<u32>(&xml, "integer", "sample_count"), s.spp);
    assert_eq!(attr(&xml, "<integrator", "type"), "direct");
    assert_eq!(
        triple(&attr(&xml, "<rgb name=\"reflectance\"", "value")),
        s.lighting.albedo
    );
    // Emitters, in scene order (cube.toml: directional, constant).
    let emitters: Vec<&str> = xml.split("<emitter ").skip(1).collect();
    assert_eq!(emitters.len(), s.lighting.lights.len());
    for (e, light) in emitters.iter().zip(&s.lighting.lights) {
        let e = format!("<emitter {e}");
        match *light {
            Light::Directional {
                direction,
                irradiance,
            } => assert_emitter(
                &e,
                "directional",
                ("<vector", direction),
                ("irradiance", irradiance),
            ),
            Light::Point {
                position,
                intensity,
            } => assert_emitter(&e, "point", ("<point", position), ("intensity", intensity)),
            Light::Constant { radiance } => {
                assert_eq!(attr(&e, "<emitter", "type"), "constant");
                assert_eq!(
                    triple(&attr(&e, "<rgb name=\"radiance\"", "value")),
                    radiance
                );
            }
        }
    }
    // The mesh: a path relative to the XML, there, with tessellate's vertex count.
    let ply = attr(&xml, "<string name=\"filename\"", "value");
    assert_eq!(ply, "cube.ply");
    let complex = apatch::scene::build_complex(&scene).unwrap();
    let mesh = apatch::export::tessellate(&complex, 3).unwrap();
    assert_eq!(ply_vertices(&dir.join(&ply)), mesh.positions.len());
}

#[test]
fn depth_mode_exports_the_aov_integrator() {
    let (dir, toml) = edited_cube("depth", "d.toml", |text| {
        text.replace("mode = \"shaded\"", "mode = \"depth\"")
            .replace(
                "models/",
                &format!("{}/scenes/models/", env!("CARGO_MANIFEST_DIR")),
            )
    });
    let out = dir.join("out");
    let o = export_mitsuba(&toml, &out, &["--resolution", "2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let xml = std::fs::read_to_string(out.join("d.xml")).unwrap();
    assert_eq!(attr(&xml, "<integrator", "type"), "aov");
    assert_eq!(
        attr(&xml, "<string name=\"aovs\"", "value"),
        "nn:sh_normal,dd:depth"
    );
    assert!(out.join("d.ply").exists());
}

#[test]
fn bad_scene_is_one_line_exit_2_and_writes_nothing() {
    let (dir, toml) = edited_cube("bad", "bad.toml", |text| {
        text.replace("fov = 30", "fov = 300")
    });
    let out = dir.join("out");
    let o = export_mitsuba(&toml, &out, &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("bad.toml") && err.contains("camera.fov"),
        "{err}"
    );
    assert!(!out.exists());
}
