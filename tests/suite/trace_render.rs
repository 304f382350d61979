//! Whole renders: bit-identical for any thread count, no NaN/inf in any EXR channel, every mode
//! runs, the EXR carries the documented channels, and a scene file renders end to end.

use crate::sphere_scene;

use apatch::fixtures::{quadric_complex, Quadric};
use apatch::scene;
use apatch::trace::{
    self, output, Camera, FovAxis, Frame, Geometry, Light, Lighting, Mode, ModeOptions,
    RenderSettings,
};
use glam::DVec3;
use sphere_scene::{sphere_scene, write_unit_sphere};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("apatch-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn setup(mode: Mode, threads: usize) -> (Geometry, RenderSettings) {
    let q = Quadric::ellipsoid(DVec3::new(0.05, 0.0, 0.0), DVec3::new(1.0, 0.7, 0.85));
    let complex = quadric_complex(&q, DVec3::splat(-1.2), DVec3::splat(1.2), 3, 3);
    let geo = Geometry::new(&complex).unwrap();
    let camera = Camera::look_at(
        DVec3::new(1.0, 1.5, 4.0),
        DVec3::ZERO,
        DVec3::Y,
        40.0,
        FovAxis::X,
        48,
        36,
        0.01,
    )
    .unwrap();
    let settings = RenderSettings {
        camera,
        spp: 4,
        mode,
        options: ModeOptions::default(),
        lighting: Lighting {
            albedo: DVec3::new(0.8, 0.7, 0.6),
            lights: vec![
                Light::Directional {
                    direction: DVec3::new(-1.0, -1.0, -1.0).normalize(),
                    irradiance: DVec3::splat(3.0),
                },
                Light::Point {
                    position: DVec3::new(2.0, 3.0, 1.0),
                    intensity: DVec3::splat(5.0),
                },
                Light::Constant {
                    radiance: DVec3::splat(0.2),
                },
            ],
        },
        threads,
    };
    (geo, settings)
}

fn render(mode: Mode, threads: usize) -> Frame {
    let (geo, s) = setup(mode, threads);
    trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap()
}

#[test]
fn one_thread_and_all_threads_agree_bit_for_bit() {
    for mode in [Mode::Shaded, Mode::Isophote] {
        let a = render(mode, 1);
        let b = render(mode, 0);
        let c = render(mode, 3);
        let bits = |f: &Frame| -> Vec<u32> {
            output::channels(f)
                .into_iter()
                .flat_map(|(_, v)| v.into_iter().map(f32::to_bits))
                .collect()
        };
        assert_eq!(bits(&a), bits(&b), "{mode:?}");
        assert_eq!(bits(&a), bits(&c), "{mode:?}");
    }
}

#[test]
fn every_mode_is_finite_and_covers_the_surface() {
    for mode in [
        Mode::Shaded,
        Mode::Normal,
        Mode::Depth,
        Mode::Patch,
        Mode::Isophote,
        Mode::Zebra,
        Mode::Curvature,
    ] {
        let f = render(mode, 0);
        for (name, data) in output::channels(&f) {
            assert!(
                data.iter().all(|x| x.is_finite()),
                "{mode:?}: {name} not finite"
            );
        }
        let covered = f.pixels.iter().filter(|p| p.alpha > 0.0).count();
        assert!(
            covered > f.pixels.len() / 10,
            "{mode:?}: {covered} pixels hit"
        );
        assert!(
            f.pixels.iter().any(|p| p.rgb.iter().any(|&c| c > 0.0)),
            "{mode:?}: black"
        );
        for p in &f.pixels {
            if p.alpha == 0.0 {
                assert_eq!(p.patch, -1.0);
                assert_eq!(p.depth, 0.0);
            } else {
                assert!(p.patch >= 0.0);
                // Normals are means of unit vectors over a pixel: nearly unit.
                let n = p.normal.iter().map(|c| c * c).sum::<f32>().sqrt();
                assert!(n > 0.9 && n < 1.0001, "{n}");
            }
        }
    }
}

/// A sphere of radius `r` (an exact quadric complex) and curvature-mode settings at 1 spp.
fn sphere_curvature(r: f64) -> (Geometry, RenderSettings) {
    let q = Quadric::sphere(DVec3::ZERO, r);
    let complex = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 2, 2);
    let (_, mut s) = setup(Mode::Curvature, 0);
    s.spp = 1;
    (Geometry::new(&complex).unwrap(), s)
}

#[test]
fn curvature_mode_reports_the_sphere_curvature() {
    // A sphere of radius r: mean curvature 1/r and Gaussian 1/r² at every hit.
    let r = 0.8;
    let (geo, s) = sphere_curvature(r);
    let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
    for p in f.pixels.iter().filter(|p| p.alpha > 0.0) {
        // f32 storage: relative 1e-6.
        assert!(
            (f64::from(p.value[0]) - 1.0 / r).abs() < 1e-5,
            "{}",
            p.value[0]
        );
        assert!(
            (f64::from(p.value[1]) - 1.0 / (r * r)).abs() < 1e-5,
            "{}",
            p.value[1]
        );
    }
    assert!(
        (f.range - 1.0 / r).abs() < 1e-5,
        "reported range {}",
        f.range
    );
}

/// A fixed colour range (`render.curvature_range`): the map spans ±range whatever the image
/// holds, so each sphere pixel has the diverging map's colour at H / range; the scene key
/// reaches the settings, and a range that is not positive is refused naming the key.
#[test]
fn curvature_mode_with_a_fixed_range() {
    let r = 0.8;
    let (geo, mut s) = sphere_curvature(r);
    s.options.curvature_range = Some(5.0);
    let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
    assert_eq!(f.range, 5.0);
    let want = trace::shade::diverging(1.0 / r / 5.0);
    let mut covered = 0;
    for p in f.pixels.iter().filter(|p| p.alpha == 1.0) {
        // f32 storage of the colour; the map is linear in H / range (H to 1e-5, above).
        for (got, w) in p.rgb.iter().zip(want.to_array()) {
            assert!((f64::from(*got) - w).abs() < 1e-5, "{:?} vs {want}", p.rgb);
        }
        covered += 1;
    }
    assert!(covered > 100, "{covered}");
    // The image's own range would have made the same sphere the map's full red.
    assert!(
        (want - trace::shade::diverging(1.0)).length() > 0.1,
        "{want}"
    );

    let dir = scratch("curvature-range");
    let rest = |v: &str| format!("[render]\nmode = \"curvature\"\ncurvature_range = {v}\n");
    let path = dir.join("s.toml");
    std::fs::write(&path, sphere_scene("s.json", 8, 6, &rest("2.5"))).unwrap();
    let sc = scene::load(&path).unwrap();
    assert_eq!(sc.settings.options.curvature_range, Some(2.5));
    for bad in ["0.0", "-1.0", "inf"] {
        std::fs::write(&path, sphere_scene("s.json", 8, 6, &rest(bad))).unwrap();
        let e = format!("{:#}", scene::load(&path).unwrap_err());
        assert!(
            e.contains("render.curvature_range") && e.contains("s.toml"),
            "{bad}: {e}"
        );
    }
    // Positive and finite but beyond f32 (the frame's curvature channel): the message says so.
    for far in ["1e39", "1e-39"] {
        std::fs::write(&path, sphere_scene("s.json", 8, 6, &rest(far))).unwrap();
        let e = format!("{:#}", scene::load(&path).unwrap_err());
        assert!(
            e.contains("render.curvature_range") && e.contains("f32"),
            "{far}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn shaded_matches_lambert_without_shadows() {
    // One directional light, convex surface, the pixel centre hit: L = ρ/π·E·n·l exactly.
    let (geo, mut s) = setup(Mode::Shaded, 0);
    let e = 2.5;
    let l = DVec3::new(0.3, 0.4, 1.0).normalize();
    s.lighting.lights = vec![Light::Directional {
        direction: -l,
        irradiance: DVec3::splat(e),
    }];
    s.spp = 1;
    let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
    let mut checked = 0;
    for p in f.pixels.iter().filter(|p| p.alpha == 1.0) {
        let n = DVec3::new(p.normal[0].into(), p.normal[1].into(), p.normal[2].into());
        let want = 0.8 / std::f64::consts::PI * e * n.dot(l).max(0.0);
        // f32 storage of normal and radiance.
        assert!(
            (f64::from(p.rgb[0]) - want).abs() < 1e-5,
            "{} vs {want}",
            p.rgb[0]
        );
        checked += 1;
    }
    assert!(checked > 100);
}

#[test]
fn exr_carries_the_documented_channels() {
    let f = render(Mode::Curvature, 0);
    let dir = scratch("exr");
    let path = dir.join("c.exr");
    trace::write_exr(&f, &path).unwrap();
    trace::write_png(&f, &dir.join("c.png")).unwrap();
    let img = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let layer = &img.layer_data[0];
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    for want in [
        "R",
        "G",
        "B",
        "A",
        "Z",
        "normal.X",
        "normal.Y",
        "normal.Z",
        "position.X",
        "position.Y",
        "position.Z",
        "patch.id",
        "curvature.mean",
        "curvature.gaussian",
    ] {
        assert!(
            names.iter().any(|n| n == want),
            "missing {want} in {names:?}"
        );
    }
    for c in &layer.channel_data.list {
        assert!(
            c.sample_data.values_as_f32().all(f32::is_finite),
            "{}",
            c.name
        );
    }
    // No temporary files left behind.
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "{left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cancelled_render_returns_interrupted() {
    let (geo, s) = setup(Mode::Shaded, 0);
    let r = trace::render(&geo, &s, &|| {}, &AtomicBool::new(true));
    assert!(r.is_err());
}

#[test]
fn scene_file_with_patch_json_renders() {
    let dir = scratch("scene");
    let complex = write_unit_sphere(&dir, "s.json");
    let rest = r#"
[film]
spp = 2
[[lights]]
type = "constant"
radiance = 1.0
[render]
mode = "shaded"
output = "out/s.png"
"#;
    let path = dir.join("s.toml");
    std::fs::write(&path, sphere_scene("s.json", 16, 12, rest)).unwrap();
    let sc = scene::load(&path).unwrap();
    assert_eq!(sc.output, dir.join("out/s.png"));
    let c = scene::build_complex(&sc).unwrap();
    assert_eq!(c, complex);
    let geo = Geometry::new(&c).unwrap();
    let f = trace::render(&geo, &sc.settings, &|| {}, &AtomicBool::new(false)).unwrap();
    // Constant light on a convex body: every fully covered pixel sees ρ·L = 0.5 exactly.
    for p in f.pixels.iter().filter(|p| p.alpha == 1.0) {
        assert!((p.rgb[0] - 0.5).abs() < 1e-6, "{}", p.rgb[0]);
    }
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\"format\": 3}").unwrap();
    let e = format!("{:#}", scene::read_patches(&bad).unwrap_err());
    // The validating reader names the file and passes on serde's line and column.
    assert!(e.contains("bad.json") && e.contains("line 1"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rational_complex_renders_identically_with_any_thread_count() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/icosahedron.obj");
    let (m, _) = apatch::mesh::load(&path).unwrap();
    let (_, _, b) = apatch::fixtures::rational_angle_build(&m);
    let geo = Geometry::new(&b.complex).unwrap();
    let (_, mut s) = setup(Mode::Shaded, 1);
    s.camera = Camera::look_at(
        DVec3::new(1.5, 2.0, 4.0),
        DVec3::ZERO,
        DVec3::Y,
        35.0,
        FovAxis::X,
        40,
        30,
        0.01,
    )
    .unwrap();
    let run = |threads: usize| {
        let mut s = s.clone();
        s.threads = threads;
        let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
        output::channels(&f)
            .into_iter()
            .flat_map(|(_, v)| v.into_iter().map(f32::to_bits))
            .collect::<Vec<u32>>()
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(0));
    s.threads = 0;
    let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
    assert!(f.pixels.iter().filter(|p| p.alpha > 0.0).count() > 200);
    for (name, data) in output::channels(&f) {
        assert!(data.iter().all(|x| x.is_finite()), "{name}");
    }
}
