//! Mitsuba 3 export: a scene XML with the same sensor, film, sampler, integrator, diffuse BSDF and
//! emitters as an apatch [`Scene`], and the A-patch surface as a tessellated PLY mesh (vertex
//! normals from ∇F) beside it, referenced by a relative path.
//!
//! Conventions (see `/work/shared/mitsuba.md`): `perspective` sensor with
//! `to_world = look_at(origin, target, up)`, `fov` along `fov_axis`, `near_clip`; `hdrfilm` with a
//! `box` rfilter and `rgba` pixels (alpha = coverage); `independent` sampler; `direct` integrator
//! for `shaded`, `aov` (`nn:sh_normal,dd:depth`, inner `direct`) for `normal` and `depth`.
//! Modes Mitsuba cannot show (patch, isophote, zebra, curvature) export the `shaded` setup.
//!
//! Usage: `apatch export mitsuba scenes/cube.toml -o out/` writes `out/cube.xml` and
//! `out/cube.ply`; render with `mi.load_file("out/cube.xml")`.

use super::{ply, tessellate, write_atomically, TriMesh};
use crate::complex::PatchComplex;
use crate::scene::Scene;
use crate::trace::{Camera, FovAxis, Light, Mode};
use anyhow::Context;
use glam::DVec3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The sensor's `look_at` transform as written in the scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LookAt {
    /// Eye position.
    pub origin: DVec3,
    /// Point looked at.
    pub target: DVec3,
    /// Up hint.
    pub up: DVec3,
}

impl LookAt {
    /// The look-at `camera` was built from: the scene's own origin, target and up.
    #[must_use]
    pub fn from_camera(camera: &Camera) -> Self {
        LookAt {
            origin: camera.origin,
            target: camera.target,
            up: camera.up,
        }
    }

    /// The look-at of `scene`'s camera.
    #[must_use]
    pub fn of_scene(scene: &Scene) -> Self {
        LookAt::from_camera(&scene.settings.camera)
    }
}

/// The files one export wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Exported {
    /// The Mitsuba scene XML.
    pub xml: PathBuf,
    /// The PLY mesh it references (same directory).
    pub ply: PathBuf,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Triangles of the mesh.
    pub triangles: usize,
}

/// Mitsuba's name of a field-of-view axis.
#[must_use]
pub fn fov_axis_name(axis: FovAxis) -> &'static str {
    match axis {
        FovAxis::X => "x",
        FovAxis::Y => "y",
        FovAxis::Diagonal => "diagonal",
        FovAxis::Smaller => "smaller",
        FovAxis::Larger => "larger",
    }
}

/// `s` with the five XML special characters escaped (for attribute values).
#[must_use]
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// "x, y, z" with shortest round-trip decimals.
fn triple(v: DVec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

/// `x="…" y="…" z="…"` attributes.
fn xyz(v: DVec3) -> String {
    format!(r#"x="{}" y="{}" z="{}""#, v.x, v.y, v.z)
}

/// The surface an exported scene shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface<'a> {
    /// A mesh file (PLY), by a path relative to the XML's directory.
    Ply(&'a str),
    /// Mitsuba's analytic `sphere` shape: the exact reference for A-patch spheres (tests pin the
    /// camera and light conventions with it).
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius (> 0).
        radius: f64,
    },
}

/// The `direct` integrator element (`name` attribute for nesting inside `aov`), with emitters
/// hidden from camera rays: apatch's background is 0 with coverage alpha, while Mitsuba would
/// otherwise show a `constant` emitter behind the object and set alpha to 1 everywhere.
fn direct_integrator(x: &mut String, indent: &str, name: Option<&str>) {
    let name = name.map_or_else(String::new, |n| format!(r#" name="{n}""#));
    let _ = writeln!(x, r#"{indent}<integrator type="direct"{name}>"#);
    let _ = writeln!(
        x,
        r#"{indent}    <boolean name="hide_emitters" value="true"/>"#
    );
    let _ = writeln!(x, "{indent}</integrator>");
}

/// The Mitsuba 3 scene XML of `scene`, viewed through `look_at`, with the surface read from
/// `ply_file` (a path relative to the XML's directory).
#[must_use]
pub fn scene_xml(scene: &Scene, look_at: &LookAt, ply_file: &str) -> String {
    scene_xml_with(scene, look_at, &Surface::Ply(ply_file))
}

/// The Mitsuba 3 scene XML of `scene`, viewed through `look_at`, showing `surface`.
///
/// Emitter sampling: Mitsuba's `direct` picks one emitter at random per emitter sample, and
/// its `constant` emitter is sampled both by emitter and by BSDF sampling (MIS). apatch casts
/// one shadow ray to every `directional`/`point` light and lights `constant` by one
/// cosine-weighted ray. When the scene has both kinds, the `constant` emitter gets
/// `sampling_weight` 0, so Mitsuba's emitter samples go to the delta lights and the
/// environment is reached by BSDF sampling alone (MIS weight 1): the same expected image with
/// the same estimator as apatch. With one delta light this removes the emitter-selection noise
/// that otherwise keeps 256-spp comparisons near 36 dB (measured on spot: 36.3 dB; 52 dB
/// with the weight at 64 spp). With several delta lights Mitsuba still selects among them.
/// (`emitter_samples` > 1 is not used: in Mitsuba 3.9.1 it scales the emitter contribution
/// by the sample count instead of averaging, measured on a lit sphere.)
#[must_use]
pub fn scene_xml_with(scene: &Scene, look_at: &LookAt, surface: &Surface) -> String {
    let s = &scene.settings;
    let c = &s.camera;
    let mut x = String::new();
    // Writing to a String cannot fail; the results are ignored below.
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="utf-8"?>"#);
    let _ = writeln!(
        x,
        "<!-- apatch export mitsuba: {} -->",
        xml_escape(&scene.path.display().to_string()).replace("--", "- -")
    );
    let _ = writeln!(x, r#"<scene version="3.0.0">"#);

    // Integrator.
    match s.mode {
        Mode::Normal | Mode::Depth => {
            let _ = writeln!(x, r#"    <integrator type="aov">"#);
            let _ = writeln!(
                x,
                r#"        <string name="aovs" value="nn:sh_normal,dd:depth"/>"#
            );
            direct_integrator(&mut x, "        ", Some("image"));
            let _ = writeln!(x, "    </integrator>");
        }
        Mode::Shaded => direct_integrator(&mut x, "    ", None),
        Mode::Patch | Mode::Isophote | Mode::Zebra | Mode::Curvature => {
            let _ = writeln!(
                x,
                "    <!-- render mode has no Mitsuba counterpart: shaded setup -->"
            );
            direct_integrator(&mut x, "    ", None);
        }
    }

    // Sensor, film, sampler.
    let _ = writeln!(x, r#"    <sensor type="perspective">"#);
    let _ = writeln!(x, r#"        <float name="fov" value="{}"/>"#, c.fov);
    let _ = writeln!(
        x,
        r#"        <string name="fov_axis" value="{}"/>"#,
        fov_axis_name(c.fov_axis)
    );
    let _ = writeln!(
        x,
        r#"        <float name="near_clip" value="{}"/>"#,
        c.near_clip
    );
    let _ = writeln!(x, r#"        <transform name="to_world">"#);
    let _ = writeln!(
        x,
        r#"            <lookat origin="{}" target="{}" up="{}"/>"#,
        triple(look_at.origin),
        triple(look_at.target),
        triple(look_at.up)
    );
    let _ = writeln!(x, "        </transform>");
    let _ = writeln!(x, r#"        <sampler type="independent">"#);
    let _ = writeln!(
        x,
        r#"            <integer name="sample_count" value="{}"/>"#,
        s.spp
    );
    let _ = writeln!(x, "        </sampler>");
    let _ = writeln!(x, r#"        <film type="hdrfilm">"#);
    let _ = writeln!(
        x,
        r#"            <integer name="width" value="{}"/>"#,
        c.width
    );
    let _ = writeln!(
        x,
        r#"            <integer name="height" value="{}"/>"#,
        c.height
    );
    let _ = writeln!(
        x,
        r#"            <string name="pixel_format" value="rgba"/>"#
    );
    let _ = writeln!(x, r#"            <rfilter type="box"/>"#);
    let _ = writeln!(x, "        </film>");
    let _ = writeln!(x, "    </sensor>");

    // Surface.
    match *surface {
        Surface::Ply(file) => {
            let _ = writeln!(x, r#"    <shape type="ply">"#);
            let _ = writeln!(
                x,
                r#"        <string name="filename" value="{}"/>"#,
                xml_escape(file)
            );
        }
        Surface::Sphere { center, radius } => {
            let _ = writeln!(x, r#"    <shape type="sphere">"#);
            let _ = writeln!(x, r#"        <point name="center" {}/>"#, xyz(center));
            let _ = writeln!(x, r#"        <float name="radius" value="{radius}"/>"#);
        }
    }
    let _ = writeln!(x, r#"        <bsdf type="diffuse">"#);
    let _ = writeln!(
        x,
        r#"            <rgb name="reflectance" value="{}"/>"#,
        triple(s.lighting.albedo)
    );
    let _ = writeln!(x, "        </bsdf>");
    let _ = writeln!(x, "    </shape>");

    // Emitters.
    let has_delta = s
        .lighting
        .lights
        .iter()
        .any(|l| matches!(l, Light::Directional { .. } | Light::Point { .. }));
    for light in &s.lighting.lights {
        match *light {
            Light::Directional {
                direction,
                irradiance,
            } => {
                let _ = writeln!(x, r#"    <emitter type="directional">"#);
                let _ = writeln!(
                    x,
                    r#"        <vector name="direction" {}/>"#,
                    xyz(direction)
                );
                let _ = writeln!(
                    x,
                    r#"        <rgb name="irradiance" value="{}"/>"#,
                    triple(irradiance)
                );
            }
            Light::Point {
                position,
                intensity,
            } => {
                let _ = writeln!(x, r#"    <emitter type="point">"#);
                let _ = writeln!(x, r#"        <point name="position" {}/>"#, xyz(position));
                let _ = writeln!(
                    x,
                    r#"        <rgb name="intensity" value="{}"/>"#,
                    triple(intensity)
                );
            }
            Light::Constant { radiance } => {
                let _ = writeln!(x, r#"    <emitter type="constant">"#);
                if has_delta {
                    let _ = writeln!(x, r#"        <float name="sampling_weight" value="0"/>"#);
                }
                let _ = writeln!(
                    x,
                    r#"        <rgb name="radiance" value="{}"/>"#,
                    triple(radiance)
                );
            }
        }
        let _ = writeln!(x, "    </emitter>");
    }
    let _ = writeln!(x, "</scene>");
    x
}

/// Writes `<dir>/<stem>.ply` (the tessellation of `complex` at `resolution`) and
/// `<dir>/<stem>.xml` (the Mitsuba scene of `scene`), `<stem>` being the scene file's stem.
/// `dir` is created when missing; each file is written atomically, the mesh first.
///
/// # Errors
/// Tessellation failures (naming the scene file) and I/O errors (naming the path).
pub fn export(
    scene: &Scene,
    complex: &PatchComplex,
    dir: &Path,
    resolution: usize,
) -> anyhow::Result<Exported> {
    let mesh: TriMesh = tessellate(complex, resolution)
        .map_err(|e| anyhow::anyhow!("{}: {e:#}", scene.path.display()))?;
    let stem = scene
        .path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .unwrap_or("scene");
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let ply_name = format!("{stem}.ply");
    let ply_path = dir.join(&ply_name);
    let xml_path = dir.join(format!("{stem}.xml"));
    write_atomically(&ply_path, |out| ply::write(&mesh, out))?;
    let xml = scene_xml(scene, &LookAt::of_scene(scene), &ply_name);
    write_atomically(&xml_path, |out| out.write_all(xml.as_bytes()))?;
    Ok(Exported {
        xml: xml_path,
        ply: ply_path,
        vertices: mesh.positions.len(),
        triangles: mesh.triangles.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
[model]
patches = "sphere.json"
[camera]
origin = [1, 2.5, 6]
target = [0, 0.25, 0]
up = [0, 0, 1]
fov = 35
fov_axis = "y"
width = 64
height = 48
near_clip = 0.001
[film]
spp = 7
[material]
albedo = [0.1, 0.2, 0.3]
[[lights]]
type = "point"
position = [2, 4, 2]
intensity = [20, 10, 5]
[render]
mode = "depth"
"#;

    #[test]
    fn look_at_is_the_scene_files_values() {
        let scene = crate::scene::parse(SCENE, Path::new("x.toml")).unwrap();
        let l = LookAt::of_scene(&scene);
        assert_eq!(l.origin, DVec3::new(1.0, 2.5, 6.0));
        assert_eq!(l.target, DVec3::new(0.0, 0.25, 0.0));
        assert_eq!(l.up, DVec3::Z);
    }

    #[test]
    fn camera_frame_look_at_rebuilds_the_same_camera() {
        let scene = crate::scene::parse(SCENE, Path::new("x.toml")).unwrap();
        let c = scene.settings.camera;
        let l = LookAt::from_camera(&c);
        let again = Camera::look_at(
            l.origin,
            l.target,
            l.up,
            c.fov,
            c.fov_axis,
            c.width,
            c.height,
            c.near_clip,
        )
        .unwrap();
        // Re-normalising an orthonormal frame moves components by a few ulps at most.
        for (a, b) in [(c.x, again.x), (c.y, again.y), (c.f, again.f)] {
            assert!((a - b).length() < 1e-14, "{a} vs {b}");
        }
    }

    #[test]
    fn xml_carries_mode_film_material_and_point_light() {
        let scene = crate::scene::parse(SCENE, Path::new("x.toml")).unwrap();
        let l = LookAt::of_scene(&scene);
        let x = scene_xml(&scene, &l, "a&b.ply");
        assert!(x.contains(r#"<integrator type="aov">"#), "{x}");
        assert!(x.contains(r#"value="nn:sh_normal,dd:depth""#), "{x}");
        assert!(x.contains(r#"<string name="fov_axis" value="y"/>"#), "{x}");
        assert!(
            x.contains(r#"<float name="near_clip" value="0.001"/>"#),
            "{x}"
        );
        assert!(
            x.contains(r#"<integer name="sample_count" value="7"/>"#),
            "{x}"
        );
        assert!(
            x.contains(r#"<rgb name="reflectance" value="0.1, 0.2, 0.3"/>"#),
            "{x}"
        );
        assert!(
            x.contains(r#"<point name="position" x="2" y="4" z="2"/>"#),
            "{x}"
        );
        assert!(
            x.contains(r#"<rgb name="intensity" value="20, 10, 5"/>"#),
            "{x}"
        );
        assert!(x.contains(r#"value="a&amp;b.ply""#), "{x}");
        assert!(x.contains(r#"up="0, 0, 1""#), "{x}");
        // Balanced elements: every opened tag is closed.
        for tag in [
            "scene", "sensor", "film", "sampler", "shape", "bsdf", "emitter",
        ] {
            let open =
                x.matches(&format!("<{tag} ")).count() + x.matches(&format!("<{tag}>")).count();
            assert_eq!(open, x.matches(&format!("</{tag}>")).count(), "{tag}");
        }
    }

    #[test]
    fn shaded_and_unmappable_modes_use_direct() {
        for mode in ["shaded", "zebra"] {
            let text = SCENE.replace("mode = \"depth\"", &format!("mode = \"{mode}\""));
            let scene = crate::scene::parse(&text, Path::new("x.toml")).unwrap();
            let x = scene_xml(
                &scene,
                &LookAt::from_camera(&scene.settings.camera),
                "s.ply",
            );
            assert!(x.contains(r#"<integrator type="direct">"#), "{x}");
            assert!(
                x.contains(r#"<boolean name="hide_emitters" value="true"/>"#),
                "{x}"
            );
            // Mitsuba's defaults are not spelled out.
            assert!(!x.contains("emitter_samples"), "{x}");
            assert!(!x.contains("aov"), "{x}");
        }
    }

    #[test]
    fn hidden_emitters_in_every_mode() {
        for mode in ["shaded", "depth", "patch"] {
            let text = SCENE.replace("mode = \"depth\"", &format!("mode = \"{mode}\""));
            let scene = crate::scene::parse(&text, Path::new("x.toml")).unwrap();
            let x = scene_xml(&scene, &LookAt::of_scene(&scene), "s.ply");
            assert_eq!(x.matches(r#"<integrator type="direct""#).count(), 1, "{x}");
            assert_eq!(
                x.matches(r#"<boolean name="hide_emitters" value="true"/>"#)
                    .count(),
                1,
                "{x}"
            );
            let open = x.matches("<integrator ").count();
            assert_eq!(open, x.matches("</integrator>").count(), "{x}");
        }
    }

    #[test]
    fn constant_emitter_is_left_to_bsdf_sampling_only_beside_a_delta_light() {
        let with_point = SCENE.replace(
            "[render]",
            "[[lights]]\ntype = \"constant\"\nradiance = 0.2\n[render]",
        );
        let only_constant = SCENE.replace(
            "type = \"point\"\nposition = [2, 4, 2]\nintensity = [20, 10, 5]",
            "type = \"constant\"\nradiance = 0.2",
        );
        for (text, weighted) in [(with_point, true), (only_constant, false)] {
            let scene = crate::scene::parse(&text, Path::new("x.toml")).unwrap();
            let x = scene_xml(&scene, &LookAt::of_scene(&scene), "s.ply");
            let c = &x[x.find(r#"<emitter type="constant">"#).unwrap()..];
            let c = &c[..c.find("</emitter>").unwrap()];
            assert!(
                c.contains(r#"<rgb name="radiance" value="0.2, 0.2, 0.2"/>"#),
                "{x}"
            );
            // The weight only where another emitter takes the emitter samples (a zero total
            // weight would leave Mitsuba nothing to sample).
            assert_eq!(
                c.contains(r#"<float name="sampling_weight" value="0"/>"#),
                weighted,
                "{x}"
            );
        }
    }

    #[test]
    fn analytic_sphere_replaces_the_mesh() {
        let scene = crate::scene::parse(SCENE, Path::new("x.toml")).unwrap();
        let x = scene_xml_with(
            &scene,
            &LookAt::of_scene(&scene),
            &Surface::Sphere {
                center: DVec3::new(0.5, -1.0, 2.0),
                radius: 1.25,
            },
        );
        assert!(x.contains(r#"<shape type="sphere">"#), "{x}");
        assert!(
            x.contains(r#"<point name="center" x="0.5" y="-1" z="2"/>"#),
            "{x}"
        );
        assert!(x.contains(r#"<float name="radius" value="1.25"/>"#), "{x}");
        assert!(!x.contains("ply"), "{x}");
        // The material still belongs to the shape.
        let shape = &x[x.find("<shape").unwrap()..x.find("</shape>").unwrap()];
        assert!(shape.contains(r#"<bsdf type="diffuse">"#), "{x}");
    }
}
