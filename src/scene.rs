//! Scene files (TOML): what to build, how to look at it, what to write. Paths inside a scene are
//! relative to the scene file. Unknown keys and bad values are errors naming the key and file.
//!
//! ```toml
//! [model]
//! file = "models/teapot.obj"      # a mesh, built with [scheme] …
//! normals = "loop"                # angle | area | loop | file (rational-c1: loop on a polygon
//!                                 # mesh uses its triangulation)
//! # subdivide = { rule = "loop", levels = 2 }   # opt-in pre-subdivision (rational-c1 only):
//! #                               # the surface then interpolates the subdivided mesh, not the file
//! # weld = 1e-3                   # opt-in (rational-c1 only): weld vertices closer than this ×
//! #                               # the bounding-box diagonal (modelling slop, see mesh::weld)
//! # clean = 1e-3                  # opt-in (cubic-c1, quintic-c2): weld at this × the diagonal,
//! #                               # split T-junctions, merge needle tips, planarise (mesh::clean)
//! # clean_coplanar = 0.5          # with `clean`: neighbouring faces meeting at less than this
//! #                               # many degrees become one face (modelling slop)
//! # flatten = 1e-4                # opt-in (cubic-c1, quintic-c2): snap regions of faces within
//! #                               # this × the diagonal of one plane onto it (rounded files,
//! #                               # mesh::flatten); set it to the file's rounding, no more
//! # flatten_min_faces = 100       # with `flatten`: only regions of at least this many faces
//! #                               # (the model's flat faces, not flat-ish strips; default 2)
//! # patches = "teapot.json"       # … or a patch complex from `apatch export patches`
//!
//! [scheme]
//! type = "rational-c1"            # + the scheme's own options (validated by the scheme)
//!
//! [camera]                        # Mitsuba `perspective`, to_world = look_at
//! origin = [0, 2, 6]
//! target = [0, 0.5, 0]
//! up = [0, 1, 0]
//! fov = 30                        # degrees
//! fov_axis = "x"                  # x | y | diagonal | smaller | larger
//! width = 800
//! height = 600
//! near_clip = 0.01
//!
//! [film]
//! spp = 16
//! filter = "box"
//!
//! [material]
//! albedo = [0.8, 0.8, 0.8]        # or one number
//!
//! [[lights]]
//! type = "directional"            # direction (travel), irradiance
//! direction = [-1, -1, -1]
//! irradiance = 3.0
//! [[lights]]
//! type = "point"                  # position, intensity
//! position = [2, 4, 2]
//! intensity = 20.0
//! [[lights]]
//! type = "constant"               # radiance
//! radiance = 0.1
//!
//! [render]
//! mode = "shaded"                 # shaded | normal | depth | patch | isophote | zebra | curvature
//! output = "../renders/teapot.png"   # the EXR is written beside it (same stem, .exr)
//! threads = 0                     # 0 = all cores
//! lines = 16                      # isophote lines / zebra stripes
//! line_width = 1.5                # pixels
//! isophote = "light"              # light | view
//! over = "shaded"                 # shaded | none (isophotes alone)
//! curvature = "mean"              # mean | gaussian
//! curvature_range = 20.0          # fixed colour span ±range (default: the image's 99th percentile)
//! patch_boundaries = true
//! ```

use crate::complex::PatchComplex;
use crate::mesh::{self, NormalMethod};
use crate::scheme::rational_c1;
use crate::trace::{Camera, FovAxis, Light, Lighting, Mode, ModeOptions, RenderSettings};
use anyhow::{anyhow, bail, Context};
use glam::DVec3;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Where the surface comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Model {
    /// A mesh file, its vertex-normal method, and the `[scheme]` table.
    Mesh {
        /// The mesh file (resolved).
        file: PathBuf,
        /// Vertex normal method name (angle | area | loop | file).
        normals: String,
        /// The `[scheme]` table, validated by the scheme.
        scheme: toml::Table,
        /// Optional approximating pre-subdivision of the triangulated mesh (`model.subdivide`,
        /// rational-c1 only, see [`mod@crate::mesh::subdivide`]): the surface then interpolates
        /// the subdivided mesh, not the file's.
        subdivide: Option<mesh::Subdivision>,
        /// Optional weld tolerance relative to the bounding-box diagonal (`model.weld`,
        /// rational-c1 only, see [`mod@crate::mesh::weld`]), applied before triangulation.
        weld: Option<f64>,
        /// Optional cleaning (`model.clean`: the tolerance relative to the bounding-box
        /// diagonal; `model.clean_coplanar`: the angle below which neighbouring faces are one
        /// plane), cubic-c1 and quintic-c2 only, see [`mod@crate::mesh::clean`]: the hull is
        /// built on the cleaned polyhedron.
        clean: Option<mesh::CleanOptions>,
        /// Optional flattening (`model.flatten`: the tolerance relative to the bounding-box
        /// diagonal), cubic-c1 and quintic-c2 only, see [`mod@crate::mesh::flatten`]: nearly
        /// flat regions of a rounded file snapped onto their planes before the hull
        /// (`model.flatten_min_faces`: only regions of that many faces).
        flatten: Option<mesh::flatten::FlattenOptions>,
    },
    /// A patch complex JSON file (resolved).
    Patches(PathBuf),
}

/// A loaded, validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The scene file.
    pub path: PathBuf,
    /// The surface source.
    pub model: Model,
    /// Camera, film, lights and mode.
    pub settings: RenderSettings,
    /// Output file (resolved); PNG or EXR by extension, the other format written beside it.
    pub output: PathBuf,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    model: ModelSection,
    scheme: Option<toml::Table>,
    camera: CameraSection,
    #[serde(default)]
    film: FilmSection,
    #[serde(default)]
    material: MaterialSection,
    #[serde(default)]
    lights: Vec<LightSection>,
    #[serde(default)]
    render: RenderSection,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelSection {
    file: Option<String>,
    normals: Option<String>,
    patches: Option<String>,
    subdivide: Option<SubdivideSection>,
    weld: Option<f64>,
    clean: Option<f64>,
    clean_coplanar: Option<f64>,
    flatten: Option<f64>,
    flatten_min_faces: Option<usize>,
}

/// `model.subdivide = { rule = "loop", levels = N }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SubdivideSection {
    #[serde(default = "default_subdivision_rule")]
    rule: String,
    levels: u32,
}

fn default_subdivision_rule() -> String {
    "loop".into()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSection {
    origin: [f64; 3],
    target: [f64; 3],
    #[serde(default = "default_up")]
    up: [f64; 3],
    fov: f64,
    #[serde(default = "default_fov_axis")]
    fov_axis: String,
    width: u32,
    height: u32,
    #[serde(default = "default_near")]
    near_clip: f64,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov_axis() -> String {
    "x".into()
}
fn default_near() -> f64 {
    0.01
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FilmSection {
    #[serde(default = "default_spp")]
    spp: u32,
    #[serde(default = "default_filter")]
    filter: String,
}

impl Default for FilmSection {
    fn default() -> Self {
        FilmSection {
            spp: default_spp(),
            filter: default_filter(),
        }
    }
}
fn default_spp() -> u32 {
    16
}
fn default_filter() -> String {
    "box".into()
}

/// A number (grey) or an RGB triple.
#[derive(Deserialize, Clone, Copy)]
#[serde(untagged)]
enum Spectrum {
    Grey(f64),
    Rgb([f64; 3]),
}

impl Spectrum {
    fn rgb(self) -> DVec3 {
        match self {
            Spectrum::Grey(g) => DVec3::splat(g),
            Spectrum::Rgb(c) => DVec3::from_array(c),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialSection {
    #[serde(default = "default_albedo")]
    albedo: Spectrum,
}

impl Default for MaterialSection {
    fn default() -> Self {
        MaterialSection {
            albedo: default_albedo(),
        }
    }
}
fn default_albedo() -> Spectrum {
    Spectrum::Grey(0.5)
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum LightSection {
    Directional {
        direction: [f64; 3],
        irradiance: Spectrum,
    },
    Point {
        position: [f64; 3],
        intensity: Spectrum,
    },
    Constant {
        radiance: Spectrum,
    },
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RenderSection {
    mode: Option<String>,
    output: Option<String>,
    threads: Option<usize>,
    lines: Option<u32>,
    line_width: Option<f64>,
    isophote: Option<String>,
    over: Option<String>,
    curvature: Option<String>,
    curvature_range: Option<f64>,
    patch_boundaries: Option<bool>,
}

/// A curvature colour range (`render.curvature_range`, `--curvature-range`): positive and
/// finite, and representable in the frame's f32 values.
///
/// # Errors
/// What is wrong with `v`.
pub fn curvature_range(v: f64) -> Result<f64, String> {
    let (lo, hi) = (f64::from(f32::MIN_POSITIVE), f64::from(f32::MAX));
    if !(v.is_finite() && v > 0.0) {
        Err(format!("`{v}` is not a positive finite number"))
    } else if !(lo..=hi).contains(&v) {
        Err(format!(
            "`{v}` is outside the range the frame's f32 curvature can hold ({lo:e} to {hi:e})"
        ))
    } else {
        Ok(v)
    }
}

/// "file:line: message (key `k`)" from a TOML error.
fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> anyhow::Error {
    let mut msg = e.message().trim().replace('\n', " ");
    let mut loc = String::new();
    if let Some(span) = e.span() {
        let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
        loc = format!(":{line}");
        let line_text = text.lines().nth(line - 1).unwrap_or("");
        if let Some((key, _)) = line_text.split_once('=') {
            let key = key.trim();
            if !key.is_empty() && !msg.contains(&format!("`{key}`")) {
                msg = format!("key `{key}`: {msg}");
            }
        }
    }
    anyhow!("{}{loc}: {msg}", path.display())
}

/// Reads and validates the scene file at `path`.
///
/// # Errors
/// Unreadable files, TOML syntax, unknown keys and bad values, each naming the file and key.
pub fn load(path: &Path) -> anyhow::Result<Scene> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    parse(&text, path)
}

/// Parses scene `text` as if read from `path` (paths resolve against its directory).
///
/// # Errors
/// As [`load`].
pub fn parse(text: &str, path: &Path) -> anyhow::Result<Scene> {
    let file: SceneFile = toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let bad = |key: &str, what: String| anyhow!("{}: `{key}`: {what}", path.display());
    let vec3 = |key: &str, v: [f64; 3]| -> anyhow::Result<DVec3> {
        let d = DVec3::from_array(v);
        if d.is_finite() {
            Ok(d)
        } else {
            Err(bad(key, "components must be finite".into()))
        }
    };

    // Model.
    let m = &file.model;
    let model = match (&m.file, &m.patches) {
        (Some(_), Some(_)) => bail!(
            "{}: `model`: give either `file` or `patches`, not both",
            path.display()
        ),
        (None, None) => bail!(
            "{}: `model`: `file` or `patches` is required",
            path.display()
        ),
        (None, Some(p)) => {
            if m.normals.is_some() {
                return Err(bad(
                    "model.normals",
                    "only applies with `model.file`".into(),
                ));
            }
            if file.scheme.is_some() {
                return Err(bad("scheme", "only applies with `model.file`".into()));
            }
            if m.subdivide.is_some()
                || m.weld.is_some()
                || m.clean.is_some()
                || m.clean_coplanar.is_some()
                || m.flatten.is_some()
            {
                return Err(bad(
                    "model.subdivide/weld/clean/flatten",
                    "only applies with `model.file`".into(),
                ));
            }
            Model::Patches(dir.join(p))
        }
        (Some(f), None) => {
            let normals = m.normals.clone().unwrap_or_else(|| "angle".into());
            if !["angle", "area", "loop", "file"].contains(&normals.as_str()) {
                return Err(bad(
                    "model.normals",
                    format!("`{normals}` is not one of angle, area, loop, file"),
                ));
            }
            let scheme = file.scheme.clone().ok_or_else(|| {
                bad(
                    "scheme",
                    "a [scheme] table is required with `model.file`".into(),
                )
            })?;
            let subdivide = match &m.subdivide {
                None => None,
                Some(sd) => {
                    if sd.rule != "loop" {
                        return Err(bad(
                            "model.subdivide.rule",
                            format!("`{}` is not supported (only `loop`)", sd.rule),
                        ));
                    }
                    if sd.levels > mesh::Subdivision::MAX_LEVELS {
                        return Err(bad(
                            "model.subdivide.levels",
                            format!(
                                "{} is more than {}",
                                sd.levels,
                                mesh::Subdivision::MAX_LEVELS
                            ),
                        ));
                    }
                    let ty = scheme.get("type").and_then(|v| v.as_str());
                    if ty != Some("rational-c1") {
                        return Err(bad(
                            "model.subdivide",
                            "only applies to `scheme.type = \"rational-c1\"` (the 1994 \
                             schemes are measured against the input polyhedron)"
                                .into(),
                        ));
                    }
                    Some(mesh::Subdivision {
                        rule: mesh::SubdivisionRule::Loop,
                        levels: sd.levels,
                    })
                }
            };
            // `model.weld` and `model.clean` share the weld's range.
            let in_weld_range = |key: &str, t: f64| {
                if (0.0..=mesh::weld::MAX_WELD_TOLERANCE).contains(&t) {
                    Ok(())
                } else {
                    Err(bad(
                        key,
                        format!(
                            "{t} is not in [0, {}] (relative to the bounding-box diagonal)",
                            mesh::weld::MAX_WELD_TOLERANCE
                        ),
                    ))
                }
            };
            if let Some(w) = m.weld {
                in_weld_range("model.weld", w)?;
                if scheme.get("type").and_then(|v| v.as_str()) != Some("rational-c1") {
                    return Err(bad(
                        "model.weld",
                        "only applies to `scheme.type = \"rational-c1\"`".into(),
                    ));
                }
            }
            // The 1994 schemes' own repairs of the polyhedron (`model.clean`, `model.flatten`).
            let is_1994 = matches!(
                scheme.get("type").and_then(|v| v.as_str()),
                Some("cubic-c1" | "quintic-c2")
            );
            if let Some(c) = m.clean {
                in_weld_range("model.clean", c)?;
                if !is_1994 {
                    return Err(bad(
                        "model.clean",
                        "only applies to `scheme.type = \"cubic-c1\"` or `\"quintic-c2\"` \
                         (`rational-c1` has `model.weld`)"
                            .into(),
                    ));
                }
            }
            if let Some(a) = m.clean_coplanar {
                if m.clean.is_none() {
                    return Err(bad(
                        "model.clean_coplanar",
                        "only applies with `model.clean`".into(),
                    ));
                }
                if !(a > 0.0 && a <= mesh::clean::MAX_COPLANAR_ANGLE) {
                    return Err(bad(
                        "model.clean_coplanar",
                        format!(
                            "{a} is not in (0, {}] (degrees)",
                            mesh::clean::MAX_COPLANAR_ANGLE
                        ),
                    ));
                }
            }
            if let Some(t) = m.flatten {
                if !is_1994 {
                    return Err(bad(
                        "model.flatten",
                        "only applies to `scheme.type = \"cubic-c1\"` or `\"quintic-c2\"`".into(),
                    ));
                }
                // Beyond 1e-3 of the diagonal modelled shallow features would be flattened.
                if !(t > 0.0 && t <= mesh::flatten::MAX_RELATIVE) {
                    return Err(bad(
                        "model.flatten",
                        format!(
                            "{t} is not in (0, {:e}] (a share of the bounding-box diagonal)",
                            mesh::flatten::MAX_RELATIVE
                        ),
                    ));
                }
            }
            if let Some(n) = m.flatten_min_faces {
                if m.flatten.is_none() {
                    return Err(bad(
                        "model.flatten_min_faces",
                        "only applies with `model.flatten`".into(),
                    ));
                }
                if n < mesh::flatten::MIN_FACES {
                    return Err(bad(
                        "model.flatten_min_faces",
                        format!(
                            "{n} is below {} (a region is at least two faces)",
                            mesh::flatten::MIN_FACES
                        ),
                    ));
                }
            }
            Model::Mesh {
                file: dir.join(f),
                normals,
                scheme,
                subdivide,
                weld: m.weld,
                clean: m.clean.map(|relative| mesh::CleanOptions {
                    relative,
                    coplanar_angle: m.clean_coplanar.unwrap_or(0.0),
                }),
                flatten: m.flatten.map(|relative| mesh::flatten::FlattenOptions {
                    relative,
                    min_faces: m.flatten_min_faces.unwrap_or(mesh::flatten::MIN_FACES),
                }),
            }
        }
    };

    // Camera.
    let c = &file.camera;
    let axis: FovAxis = c
        .fov_axis
        .parse()
        .map_err(|e: String| bad("camera.fov_axis", e))?;
    if !(c.fov > 0.0 && c.fov < 180.0) {
        return Err(bad(
            "camera.fov",
            format!("{} is outside (0, 180) degrees", c.fov),
        ));
    }
    if c.width == 0 || c.height == 0 {
        return Err(bad("camera.width/height", "must be positive".into()));
    }
    let camera = Camera::look_at(
        vec3("camera.origin", c.origin)?,
        vec3("camera.target", c.target)?,
        vec3("camera.up", c.up)?,
        c.fov,
        axis,
        c.width,
        c.height,
        c.near_clip,
    )
    .map_err(|e| bad("camera", e))?;

    // Film.
    if file.film.spp == 0 {
        return Err(bad("film.spp", "must be ≥ 1".into()));
    }
    if file.film.filter != "box" {
        return Err(bad(
            "film.filter",
            format!("`{}` is not supported (only `box`)", file.film.filter),
        ));
    }

    // Material and lights.
    let albedo = file.material.albedo.rgb();
    if !(albedo.is_finite() && albedo.min_element() >= 0.0 && albedo.max_element() <= 1.0) {
        return Err(bad(
            "material.albedo",
            "components must lie in [0, 1]".into(),
        ));
    }
    let mut lights = Vec::new();
    for (i, l) in file.lights.iter().enumerate() {
        let key = |k: &str| format!("lights[{i}].{k}");
        let nonneg = |k: &str, s: Spectrum| -> anyhow::Result<DVec3> {
            let v = s.rgb();
            if v.is_finite() && v.min_element() >= 0.0 {
                Ok(v)
            } else {
                Err(bad(&key(k), "must be finite and ≥ 0".into()))
            }
        };
        lights.push(match *l {
            LightSection::Directional {
                direction,
                irradiance,
            } => Light::Directional {
                direction: vec3(&key("direction"), direction)?
                    .try_normalize()
                    .ok_or_else(|| bad(&key("direction"), "must be non-zero".into()))?,
                irradiance: nonneg("irradiance", irradiance)?,
            },
            LightSection::Point {
                position,
                intensity,
            } => Light::Point {
                position: vec3(&key("position"), position)?,
                intensity: nonneg("intensity", intensity)?,
            },
            LightSection::Constant { radiance } => Light::Constant {
                radiance: nonneg("radiance", radiance)?,
            },
        });
    }

    // Render.
    let r = &file.render;
    let mode: Mode = r
        .mode
        .as_deref()
        .unwrap_or("shaded")
        .parse()
        .map_err(|e: String| bad("render.mode", e))?;
    let mut options = ModeOptions::default();
    if let Some(n) = r.lines {
        if n == 0 {
            return Err(bad("render.lines", "must be ≥ 1".into()));
        }
        options.lines = n;
    }
    if let Some(w) = r.line_width {
        if !(w > 0.0 && w.is_finite()) {
            return Err(bad("render.line_width", "must be > 0".into()));
        }
        options.line_width = w;
    }
    if let Some(s) = &r.isophote {
        options.isophote_light = match s.as_str() {
            "light" => true,
            "view" => false,
            _ => {
                return Err(bad(
                    "render.isophote",
                    format!("`{s}` is not light or view"),
                ))
            }
        };
    }
    if let Some(s) = &r.over {
        options.over_shaded = match s.as_str() {
            "shaded" => true,
            "none" => false,
            _ => return Err(bad("render.over", format!("`{s}` is not shaded or none"))),
        };
    }
    if let Some(s) = &r.curvature {
        options.gaussian = match s.as_str() {
            "mean" => false,
            "gaussian" => true,
            _ => {
                return Err(bad(
                    "render.curvature",
                    format!("`{s}` is not mean or gaussian"),
                ))
            }
        };
    }
    if let Some(v) = r.curvature_range {
        options.curvature_range =
            Some(curvature_range(v).map_err(|e| bad("render.curvature_range", e))?);
    }
    if let Some(b) = r.patch_boundaries {
        options.patch_boundaries = b;
    }
    let output = match &r.output {
        Some(o) => dir.join(o),
        None => path.with_extension("png"),
    };
    check_output(&output).map_err(|e| bad("render.output", e))?;

    Ok(Scene {
        path: path.to_path_buf(),
        model,
        settings: RenderSettings {
            camera,
            spp: file.film.spp,
            mode,
            options,
            lighting: Lighting { albedo, lights },
            threads: r.threads.unwrap_or(0),
        },
        output,
    })
}

/// Accepts output paths ending in `.png` or `.exr`.
///
/// # Errors
/// Any other extension.
pub fn check_output(path: &Path) -> Result<(), String> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("png" | "exr") => Ok(()),
        _ => Err(format!(
            "{}: the output must end in .png or .exr",
            path.display()
        )),
    }
}

/// Builds the scene's patch complex: reads the patch JSON, or loads the mesh and runs the
/// `[scheme]` (dispatch on `type`).
///
/// # Errors
/// Unreadable or invalid inputs, unknown or unavailable schemes, each naming the file.
pub fn build_complex(scene: &Scene) -> anyhow::Result<PatchComplex> {
    Ok(build_complex_with_info(scene)?.0)
}

/// What the 2001 scheme's mesh pipeline did to the input before and during the build, for
/// reports (`apatch check`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct MeshBuildInfo {
    /// Triangles of the input after triangulation (and the weld, if any).
    pub input_triangles: usize,
    /// Vertices moved onto another by `model.weld` (0 without it).
    pub welded_vertices: usize,
    /// Triangles after `model.subdivide` (= `input_triangles` without it).
    pub subdivided_triangles: usize,
    /// Edges split by the hull's local refinement (§3.1) because adjacent face tetrahedra
    /// intersected.
    pub refined_edges: usize,
}

/// [`build_complex`], plus [`MeshBuildInfo`] for `rational-c1` mesh scenes (`None` otherwise).
///
/// # Errors
/// As [`build_complex`].
pub fn build_complex_with_info(
    scene: &Scene,
) -> anyhow::Result<(PatchComplex, Option<MeshBuildInfo>)> {
    let built = build_scene(scene)?;
    Ok((built.complex, built.info))
}

/// A scene's patch complex with what its build loaded and made on the way, so that reports
/// (`apatch check`) reuse them instead of loading the mesh and building the hull again.
#[derive(Clone, Debug)]
pub struct BuiltScene {
    /// The patches.
    pub complex: PatchComplex,
    /// What the 2001 scheme's mesh pipeline did (`rational-c1` mesh scenes; `None` otherwise).
    pub info: Option<MeshBuildInfo>,
    /// The mesh as loaded (after `model.weld`, before triangulation and subdivision); `None`
    /// for patch files.
    pub mesh: Option<mesh::Mesh>,
    /// The inner simplicial hull (1994) the patches fill (`cubic-c1`, `quintic-c2`), the same
    /// value [`inner_hull`] rebuilds: after the scheme's own changes
    /// ([`crate::scheme::cubic_c1::prepare_hull`], [`crate::scheme::quintic_c2::prepare_hull`]:
    /// L-U partners, apexes moved, for the quintic also opened slivers and zero coplanar
    /// groups). `None` for other scenes.
    pub hull: Option<crate::hull::simplicial::SimplicialHull>,
    /// What the quintic scheme's solve did (`quintic-c2` scenes; `None` otherwise): its size,
    /// relaxed stars, consistency conditions, whether it fell back to solving every weight at
    /// once, the weights' signs and the hole repair.
    pub solve: Option<crate::scheme::quintic_c2::BuildStats>,
    /// What the inner hull's builder changed on the way (`cubic-c1`, `quintic-c2`; `None`
    /// otherwise): normals made above face, folds flipped, apexes lifted or moved by the search.
    pub hull_report: Option<crate::hull::inner::InnerReport>,
    /// What the cubic scheme changed on the hull before filling it (`cubic-c1` scenes; `None`
    /// otherwise): L-U partners, apexes moved over tangent planes, its own apex search.
    pub cubic_steps: Option<crate::scheme::cubic_c1::PrepareSteps>,
    /// What `model.clean` changed (1994 scenes that set it; `None` otherwise).
    pub clean: Option<mesh::CleanReport>,
    /// What `model.flatten` changed (1994 scenes that set it; `None` otherwise).
    pub flatten: Option<mesh::flatten::FlattenReport>,
}

/// [`build_complex`], returning the loaded mesh and the hull beside the complex
/// ([`BuiltScene`]): the mesh is loaded once and the 1994 hull built once.
///
/// # Errors
/// As [`build_complex`].
pub fn build_scene(scene: &Scene) -> anyhow::Result<BuiltScene> {
    match &scene.model {
        Model::Patches(p) => Ok(BuiltScene {
            complex: read_patches(p)?,
            info: None,
            mesh: None,
            hull: None,
            solve: None,
            hull_report: None,
            cubic_steps: None,
            clean: None,
            flatten: None,
        }),
        Model::Mesh {
            file,
            normals,
            scheme,
            subdivide,
            weld,
            clean,
            flatten,
        } => {
            let ty = scheme.get("type").and_then(|v| v.as_str()).ok_or_else(|| {
                anyhow!(
                    "{}: `scheme.type` is required (a string)",
                    scene.path.display()
                )
            })?;
            match ty {
                "rational-c1" => {
                    let opts = rational_c1::RationalOptions::from_toml(scheme, &scene.path)?;
                    let method: NormalMethod = normals.parse().map_err(|e: String| {
                        anyhow!("{}: `model.normals`: {e}", scene.path.display())
                    })?;
                    let (mut m, report) = mesh::load(file)?;
                    report.require(false)?;
                    let mut welded_vertices = 0;
                    if let Some(w) = weld {
                        let (welded, report, moved) = mesh::weld(&m, *w)
                            .with_context(|| format!("{}: `model.weld`", file.display()))?;
                        report
                            .require(false)
                            .with_context(|| format!("{}: after `model.weld`", file.display()))?;
                        m = welded;
                        welded_vertices = moved;
                    }
                    let mut tri = mesh::triangulate(&m);
                    let input_triangles = tri.faces.len();
                    let vn = match subdivide {
                        Some(sd) => {
                            tri = mesh::subdivide(&tri, *sd)
                                .with_context(|| format!("{}", file.display()))?;
                            mesh::vertex_normals(&tri, method)?
                        }
                        // Loop-limit normals need triangles: on a polygon mesh they are
                        // taken on its triangulation (the triangles the hull is built on).
                        None if method == NormalMethod::Loop && !m.is_triangle_mesh() => {
                            mesh::vertex_normals(&tri, method)?
                        }
                        None => mesh::vertex_normals(&m, method)?,
                    };
                    let triangles: Vec<[u32; 3]> =
                        tri.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
                    let built = rational_c1::build(&tri.positions, &triangles, &vn, &opts)
                        .with_context(|| format!("{}", file.display()))?;
                    let info = MeshBuildInfo {
                        input_triangles,
                        welded_vertices,
                        subdivided_triangles: triangles.len(),
                        refined_edges: built.refined_edges,
                    };
                    Ok(BuiltScene {
                        complex: built.complex,
                        info: Some(info),
                        mesh: Some(m),
                        hull: None,
                        solve: None,
                        hull_report: None,
                        cubic_steps: None,
                        clean: None,
                        flatten: None,
                    })
                }
                "cubic-c1" | "quintic-c2" => {
                    let method: NormalMethod = normals.parse().map_err(|e: String| {
                        anyhow!("{}: `model.normals`: {e}", scene.path.display())
                    })?;
                    let (m, report, cleaned, flattened) =
                        polyhedron_1994_with(file, *clean, *flatten)?;
                    crate::hull::inner::closed::require_closed(&m, &report)?;
                    let vn = mesh::vertex_normals(&m, method)?;
                    let built = build_1994(ty, &m, &vn, scheme, &scene.path)
                        .with_context(|| format!("{}", file.display()))?;
                    Ok(BuiltScene {
                        complex: built.complex,
                        info: None,
                        mesh: Some(m),
                        hull: Some(built.hull),
                        solve: built.solve,
                        hull_report: Some(built.report),
                        cubic_steps: built.cubic_steps,
                        clean: cleaned,
                        flatten: flattened,
                    })
                }
                _ => bail!(
                    "{}: `scheme.type`: `{ty}` is not one of rational-c1, cubic-c1, quintic-c2",
                    scene.path.display()
                ),
            }
        }
    }
}

/// The polyhedron a 1994 scene's hull is built on: the mesh `file`, cleaned when the scene sets
/// `model.clean` ([`mod@crate::mesh::clean`]), with its validation report and what the clean
/// changed.
///
/// # Errors
/// Unreadable meshes and cleans that fail, naming the file.
pub fn polyhedron_1994(
    file: &Path,
    clean: Option<mesh::CleanOptions>,
) -> anyhow::Result<(mesh::Mesh, mesh::Report, Option<mesh::CleanReport>)> {
    let (m, report, cleaned, _) = polyhedron_1994_with(file, clean, None)?;
    Ok((m, report, cleaned))
}

/// [`polyhedron_1994`] with the scene's `model.flatten` too (applied first,
/// [`mod@crate::mesh::flatten`]), and what it changed.
///
/// # Errors
/// As [`polyhedron_1994`].
pub fn polyhedron_1994_with(
    file: &Path,
    clean: Option<mesh::CleanOptions>,
    flatten: Option<mesh::flatten::FlattenOptions>,
) -> anyhow::Result<(
    mesh::Mesh,
    mesh::Report,
    Option<mesh::CleanReport>,
    Option<mesh::flatten::FlattenReport>,
)> {
    let (mut m, report) = mesh::load(file)?;
    let flattened = flatten.map(|options| {
        let (f, changes) = mesh::flatten::flatten_with(&m, options);
        m = f;
        changes
    });
    let Some(options) = clean else {
        return Ok((m, report, None, flattened));
    };
    let (c, report, changes) = mesh::clean_with(&m, options)
        .with_context(|| format!("{}: `model.clean`", file.display()))?;
    Ok((c, report, Some(changes), flattened))
}

/// The inner simplicial hull (1994) a `cubic-c1` or `quintic-c2` scene is built on, with the
/// scene's normals and hull options; `None` for other scenes: the hull (Definition 3.6) without
/// the patches. It is the hull after the scheme's own changes to the apexes
/// ([`crate::scheme::cubic_c1::prepare_hull`], [`crate::scheme::quintic_c2::prepare_hull`]),
/// the one its patches fill. Loads the mesh and
/// builds the hull anew: after a build, [`BuiltScene::hull`] is this value (`apatch check`
/// reads that).
///
/// # Errors
/// Unreadable meshes, bad options, and hulls that cannot be built, naming the file.
pub fn inner_hull(
    scene: &Scene,
) -> anyhow::Result<Option<crate::hull::simplicial::SimplicialHull>> {
    let Some(hull) = builder_hull(scene)? else {
        return Ok(None);
    };
    let Model::Mesh { file, scheme, .. } = &scene.model else {
        return Ok(None);
    };
    if scheme.get("type").and_then(|v| v.as_str()) == Some("cubic-c1") {
        let (cubic, _) = crate::scheme::cubic_c1::options_from_toml(scheme, &scene.path)?;
        return Ok(Some(
            crate::scheme::cubic_c1::prepare_hull(&hull, &cubic).hull,
        ));
    }
    let quintic = crate::scheme::quintic_c2::QuinticOptions::from_toml(scheme, &scene.path)?;
    let prepared = crate::scheme::quintic_c2::prepare_hull(&hull, &quintic)
        .with_context(|| format!("{}", file.display()))?;
    Ok(Some(prepared.hull))
}

/// The inner hull builder's hull of a `cubic-c1` or `quintic-c2` scene, before the scheme's
/// own changes ([`inner_hull`] returns it after them); `None` for other scenes. For surveys of
/// what the builder gives and what the schemes change.
///
/// # Errors
/// As [`inner_hull`].
pub fn builder_hull(
    scene: &Scene,
) -> anyhow::Result<Option<crate::hull::simplicial::SimplicialHull>> {
    let Model::Mesh {
        file,
        normals,
        scheme,
        clean,
        flatten,
        ..
    } = &scene.model
    else {
        return Ok(None);
    };
    if !matches!(
        scheme.get("type").and_then(|v| v.as_str()),
        Some("cubic-c1" | "quintic-c2")
    ) {
        return Ok(None);
    }
    let method: NormalMethod = normals
        .parse()
        .map_err(|e: String| anyhow!("{}: `model.normals`: {e}", scene.path.display()))?;
    let (m, _, _, _) = polyhedron_1994_with(file, *clean, *flatten)?;
    let vn = mesh::vertex_normals(&m, method)?;
    let options = crate::hull::inner::InnerOptions::from_toml(scheme, &scene.path)?;
    let hull = crate::hull::inner::build(&m, &vn, &options)
        .with_context(|| format!("{}", file.display()))?;
    Ok(Some(hull))
}

/// Builds a `cubic-c1` or `quintic-c2` complex as the schemes' `build_from_scene` do (same
/// options, hull, patches and errors), returning beside it the hull the patches fill, what the
/// hull's builder changed and (quintic) what its solve did.
fn build_1994(
    ty: &str,
    m: &mesh::Mesh,
    vn: &[DVec3],
    scheme: &toml::Table,
    scene: &Path,
) -> anyhow::Result<Built1994> {
    use crate::scheme::{cubic_c1, quintic_c2};
    let at = || format!("{}", scene.display());
    crate::progress::report(|| "building the inner hull".into());
    if ty == "cubic-c1" {
        let (options, inner) = cubic_c1::options_from_toml(scheme, scene)?;
        let (hull, report) =
            crate::hull::inner::build_with_report(m, vn, &inner).with_context(at)?;
        crate::progress::report(|| format!("cubic-c1: {} triangles of T", hull.triangles.len()));
        let (complex, prepared) = cubic_on_prepared(&hull, &options).with_context(at)?;
        let cubic_steps = Some(prepared.steps());
        Ok(Built1994 {
            complex,
            hull: prepared.hull,
            solve: None,
            report,
            cubic_steps,
        })
    } else {
        let options = quintic_c2::QuinticOptions::from_toml(scheme, scene)?;
        let inner = crate::hull::inner::InnerOptions::from_toml(scheme, scene)?;
        let (hull, report) = crate::hull::inner::build_with_report(m, vn, &inner)?;
        // The scheme's own changes to the hull, made once: the hull returned is the one the
        // patches fill (as for the cubic).
        let prepared = quintic_c2::prepare_hull(&hull, &options).with_context(at)?;
        let (complex, stats) = quintic_c2::build_prepared(&prepared, &options)?;
        Ok(Built1994 {
            complex,
            hull: prepared.hull,
            solve: Some(stats),
            report,
            cubic_steps: None,
        })
    }
}

/// A 1994 scene's patches, the hull they fill and what each step changed ([`BuiltScene`]).
struct Built1994 {
    complex: PatchComplex,
    hull: crate::hull::simplicial::SimplicialHull,
    solve: Option<crate::scheme::quintic_c2::BuildStats>,
    report: crate::hull::inner::InnerReport,
    cubic_steps: Option<crate::scheme::cubic_c1::PrepareSteps>,
}

/// [`crate::scheme::cubic_c1::build`] on `hull`, returning the hull its patches fill: the
/// scheme's apex changes ([`crate::scheme::cubic_c1::prepare_hull`]) are made here, once, and
/// the build is told not to make them again (the same patches as `build(hull, options)`).
fn cubic_on_prepared(
    hull: &crate::hull::simplicial::SimplicialHull,
    options: &crate::scheme::cubic_c1::CubicOptions,
) -> crate::error::Result<(PatchComplex, crate::scheme::cubic_c1::PreparedHull)> {
    use crate::scheme::cubic_c1;
    let prepared = cubic_c1::prepare_hull(hull, options);
    let once = cubic_c1::CubicOptions {
        complete_lu_pairs: false,
        contain_tangents: false,
        search_apexes: false,
        ..options.clone()
    };
    Ok((cubic_c1::build(&prepared.hull, &once)?, prepared))
}

/// Reads a patch complex JSON file (as written by `apatch export patches`) with the validating
/// reader [`crate::complex_io::read_json_file`].
///
/// # Errors
/// Unreadable files, JSON errors, a wrong `format`, and invalid data (wrong weight counts,
/// non-finite values, degenerate tetrahedra, rational terms of too high a degree), each message
/// naming the file and, where one is at fault, the patch.
pub fn read_patches(path: &Path) -> anyhow::Result<PatchComplex> {
    Ok(crate::complex_io::read_json_file(path)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINIMAL: &str = r#"
[model]
patches = "sphere.json"
[camera]
origin = [0, 0, 5]
target = [0, 0, 0]
fov = 40
width = 64
height = 48
[[lights]]
type = "directional"
direction = [0, 0, -1]
irradiance = 2.0
"#;

    #[test]
    fn minimal_scene_resolves_paths_and_defaults() {
        let s = parse(MINIMAL, Path::new("scenes/x.toml")).unwrap();
        assert_eq!(s.model, Model::Patches(PathBuf::from("scenes/sphere.json")));
        assert_eq!(s.output, PathBuf::from("scenes/x.png"));
        assert_eq!(s.settings.spp, 16);
        assert_eq!(s.settings.mode, Mode::Shaded);
        assert_eq!(s.settings.lighting.lights.len(), 1);
    }

    #[test]
    fn unknown_keys_and_bad_values_name_key_and_file() {
        let text = MINIMAL.replace("fov = 40", "fov = 40\nzoom = 2");
        let e = format!("{:#}", parse(&text, Path::new("a/b.toml")).unwrap_err());
        assert!(e.contains("a/b.toml") && e.contains("zoom"), "{e}");
        let text = MINIMAL.replace("fov = 40", "fov = \"wide\"");
        let e = format!("{:#}", parse(&text, Path::new("a/b.toml")).unwrap_err());
        assert!(e.contains("a/b.toml") && e.contains("fov"), "{e}");
        let text = MINIMAL.replace("fov = 40", "fov = 200");
        let e = format!("{:#}", parse(&text, Path::new("a/b.toml")).unwrap_err());
        assert!(e.contains("camera.fov"), "{e}");
        let text = MINIMAL.replace("irradiance = 2.0", "irradiance = 2.0\nangle = 3");
        let e = format!("{:#}", parse(&text, Path::new("a/b.toml")).unwrap_err());
        assert!(e.contains("angle"), "{e}");
        let text = MINIMAL.replace("type = \"directional\"", "type = \"spot\"");
        let e = format!("{:#}", parse(&text, Path::new("a/b.toml")).unwrap_err());
        assert!(e.contains("spot"), "{e}");
    }

    #[test]
    fn subdivide_key_is_parsed_and_checked() {
        let with = |model: &str, scheme: &str| {
            MINIMAL.replace(
                "patches = \"sphere.json\"",
                &format!("file = \"m.obj\"\n{model}\n[scheme]\ntype = \"{scheme}\""),
            )
        };
        let ok = with("subdivide = { rule = \"loop\", levels = 2 }", "rational-c1");
        let s = parse(&ok, Path::new("s.toml")).unwrap();
        let Model::Mesh { subdivide, .. } = s.model else {
            panic!("mesh scene expected");
        };
        assert_eq!(
            subdivide,
            Some(mesh::Subdivision {
                rule: mesh::SubdivisionRule::Loop,
                levels: 2
            })
        );
        // `rule` defaults to loop.
        let s = parse(
            &with("subdivide = { levels = 1 }", "rational-c1"),
            Path::new("s.toml"),
        );
        assert!(s.is_ok());
        for (model, scheme, key) in [
            (
                "subdivide = { rule = \"catmull\", levels = 1 }",
                "rational-c1",
                "model.subdivide.rule",
            ),
            (
                "subdivide = { levels = 9 }",
                "rational-c1",
                "model.subdivide.levels",
            ),
            (
                "subdivide = { levels = 1, sharp = true }",
                "rational-c1",
                "sharp",
            ),
            ("subdivide = { levels = 1 }", "cubic-c1", "model.subdivide"),
            ("subdivide = 2", "rational-c1", "subdivide"),
        ] {
            let e = format!(
                "{:#}",
                parse(&with(model, scheme), Path::new("a/b.toml")).unwrap_err()
            );
            assert!(e.contains("a/b.toml") && e.contains(key), "{model}: {e}");
        }
        let s = parse(&with("weld = 1e-3", "rational-c1"), Path::new("s.toml")).unwrap();
        assert!(matches!(s.model, Model::Mesh { weld: Some(w), .. } if w == 1e-3));
        // `model.clean`: the 1994 schemes only, within the weld's range.
        let s = parse(&with("clean = 1e-3", "cubic-c1"), Path::new("s.toml")).unwrap();
        assert!(
            matches!(s.model, Model::Mesh { clean: Some(c), .. } if c.relative == 1e-3 && c.coplanar_angle == 0.0)
        );
        // `model.clean_coplanar`: with `model.clean` only, an angle in (0, 5] degrees.
        let both = "clean = 1e-3\nclean_coplanar = 0.5";
        let s = parse(&with(both, "quintic-c2"), Path::new("s.toml")).unwrap();
        assert!(matches!(s.model, Model::Mesh { clean: Some(c), .. } if c.coplanar_angle == 0.5));
        // `model.flatten`: the 1994 schemes only, in (0, 1e-3] of the diagonal.
        let s = parse(&with("flatten = 1e-4", "quintic-c2"), Path::new("s.toml")).unwrap();
        assert!(matches!(s.model, Model::Mesh { flatten: Some(o), .. }
            if o.relative == 1e-4 && o.min_faces == mesh::flatten::MIN_FACES));
        // `model.flatten_min_faces`: with `model.flatten` only, at least 2.
        let s = parse(
            &with("flatten = 1e-4\nflatten_min_faces = 100", "cubic-c1"),
            Path::new("s.toml"),
        )
        .unwrap();
        assert!(matches!(s.model, Model::Mesh { flatten: Some(o), .. } if o.min_faces == 100));
        for (model, scheme, key) in [
            (
                "flatten_min_faces = 100",
                "cubic-c1",
                "model.flatten_min_faces",
            ),
            (
                "flatten = 1e-4\nflatten_min_faces = 1",
                "quintic-c2",
                "model.flatten_min_faces",
            ),
            ("flatten = 1e-4", "rational-c1", "model.flatten"),
            ("flatten = 0", "cubic-c1", "model.flatten"),
            ("flatten = 0.01", "quintic-c2", "model.flatten"),
            ("weld = 0.5", "rational-c1", "model.weld"),
            ("weld = 1e-3", "quintic-c2", "model.weld"),
            ("clean = 0.5", "cubic-c1", "model.clean"),
            ("clean = 1e-3", "rational-c1", "model.clean"),
            ("clean_coplanar = 0.5", "cubic-c1", "model.clean_coplanar"),
            (
                "clean = 1e-3\nclean_coplanar = 0",
                "cubic-c1",
                "model.clean_coplanar",
            ),
            (
                "clean = 1e-3\nclean_coplanar = 9",
                "cubic-c1",
                "model.clean_coplanar",
            ),
        ] {
            let e = format!(
                "{:#}",
                parse(&with(model, scheme), Path::new("a/b.toml")).unwrap_err()
            );
            assert!(e.contains("a/b.toml") && e.contains(key), "{model}: {e}");
        }
        let patches = MINIMAL.replace(
            "patches = \"sphere.json\"",
            "patches = \"p.json\"\nsubdivide = { levels = 1 }",
        );
        let e = format!("{:#}", parse(&patches, Path::new("s.toml")).unwrap_err());
        assert!(e.contains("model.subdivide"), "{e}");
    }

    #[test]
    fn schemes_dispatch_with_clear_errors() {
        let text = MINIMAL.replace(
            "patches = \"sphere.json\"",
            "file = \"m.obj\"\n[scheme]\ntype = \"bezier-c9\"",
        );
        let s = parse(&text, Path::new("s.toml")).unwrap();
        let e = format!("{:#}", build_complex(&s).unwrap_err());
        assert!(e.contains("s.toml") && e.contains("bezier-c9"), "{e}");
    }

    use crate::hull::simplicial::{Side, SimplicialHull};
    use crate::scheme::{cubic_c1, quintic_c2};

    /// Each tetrahedron as its corners' bits, sorted, and the list sorted: two lists are equal
    /// exactly when they hold the same tetrahedra (in any order, with any corner order).
    fn tet_keys(tets: impl Iterator<Item = [[f64; 3]; 4]>) -> Vec<[[u64; 3]; 4]> {
        let mut keys: Vec<[[u64; 3]; 4]> = tets
            .map(|t| {
                let mut k = t.map(|p| p.map(f64::to_bits));
                k.sort_unstable();
                k
            })
            .collect();
        keys.sort_unstable();
        keys
    }

    /// The face and edge tetrahedra of `hull`: the cells a 1994 scheme puts one patch in each.
    fn hull_tets(hull: &SimplicialHull) -> Vec<[[u64; 3]; 4]> {
        let faces = (0..hull.triangles.len())
            .flat_map(|t| Side::BOTH.map(|side| hull.face_tet(t, side)))
            .flatten();
        let edges = hull.edge_tets().unwrap().into_iter().map(|e| e.tet);
        tet_keys(faces.chain(edges).map(|t| t.map(|p| p.to_array())))
    }

    fn patch_tets(c: &PatchComplex) -> Vec<[[u64; 3]; 4]> {
        tet_keys(c.patches.iter().map(|p| p.tet))
    }

    /// Every field of two hulls equal (`SimplicialHull` has no `PartialEq`).
    fn same_hull(a: &SimplicialHull, b: &SimplicialHull) -> bool {
        a.points == b.points
            && a.normals == b.normals
            && a.origins == b.origins
            && a.triangles == b.triangles
            && a.apexes == b.apexes
            && a.element == b.element
    }

    fn paper1994(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/paper1994/{name}.toml"))
    }

    /// A mesh scene's mesh (loaded anew), its normals and its `[scheme]` table.
    fn mesh_of(sc: &Scene) -> (mesh::Mesh, Vec<DVec3>, &toml::Table) {
        let Model::Mesh {
            file,
            normals,
            scheme,
            clean,
            ..
        } = &sc.model
        else {
            panic!("{}: a mesh scene", sc.path.display());
        };
        // The polyhedron the build uses (mpi_poly's scene cleans its model).
        let (m, _, _) = polyhedron_1994(file, *clean).unwrap();
        let vn = mesh::vertex_normals(&m, normals.parse().unwrap()).unwrap();
        (m, vn, scheme)
    }

    /// `build_scene` returns the mesh it loaded and the very hull its patches fill (what
    /// `apatch check` verifies and measures the distance to): the patches are exactly that
    /// hull's face and edge tetrahedra, the hull is the one `inner_hull` builds anew, and the
    /// patches are the schemes' own `build_from_scene`'s, bit for bit. Scenes with shape options
    /// (an icosahedron with `alpha`, whose hull the option changes; the hallway corner's
    /// `levels`; mpi_poly's `apex_search`), both schemes.
    #[test]
    fn built_scene_returns_the_mesh_and_the_hull_its_patches_fill() {
        let ico = std::fs::read_to_string(paper1994("icosahedron")).unwrap();
        let shaped = ico.replace(
            "type = \"cubic-c1\"",
            "type = \"cubic-c1\"\nalpha = 0.3\ntrihedral_level = 0.7",
        );
        assert_ne!(shaped, ico);
        let shaped = parse(&shaped, &paper1994("icosahedron")).unwrap();
        let default_hull = inner_hull(&load(&paper1994("icosahedron")).unwrap())
            .unwrap()
            .unwrap();
        let mut scenes = vec![shaped];
        // mpi_poly: the apex search moves apexes again after the cubic's own changes, and its
        // model is cleaned (`model.clean`): every path to the cubic's patches must do both.
        for name in [
            "cube",
            "hallway_corner",
            "cube_quintic",
            "l_prism_quintic",
            "mpi_poly",
        ] {
            scenes.push(load(&paper1994(name)).unwrap());
        }
        for (k, sc) in scenes.iter().enumerate() {
            let name = sc.path.display();
            let built = build_scene(sc).unwrap();
            let hull = built.hull.as_ref().expect("1994 scenes return their hull");
            if k == 0 {
                // The premise: `alpha` changes the hull, so a hull built with the wrong
                // options would not match the patches below.
                assert!(!same_hull(hull, &default_hull));
            }
            let quintic = built.complex.scheme == "quintic-c2";
            let filled = hull.clone();
            assert_eq!(
                built.complex.patches.len(),
                hull_tets(&filled).len(),
                "{name}"
            );
            assert_eq!(patch_tets(&built.complex), hull_tets(&filled), "{name}");
            assert!(same_hull(hull, &inner_hull(sc).unwrap().unwrap()), "{name}");
            let (m, vn, scheme) = mesh_of(sc);
            assert_eq!(built.mesh.as_ref(), Some(&m), "{name}");
            assert!(built.info.is_none(), "{name}");
            let own = if quintic {
                quintic_c2::build_from_scene(&m, &vn, scheme, &sc.path)
            } else {
                cubic_c1::build_from_scene(&m, &vn, scheme, &sc.path)
            };
            assert_eq!(built.complex, own.unwrap(), "{name}");
        }
    }

    /// Where the cubic scheme's own apex changes do change the hull (the 12×8 torus with the
    /// inner apexes of its non-convex triangles taken away again: `complete_lu_pairs` gives
    /// them back), the hull returned is the changed one, its tetrahedra are the patches', and
    /// the patches are those of `cubic_c1::build` on the unchanged hull (the changes made once,
    /// not twice).
    #[test]
    fn cubic_apex_changes_are_made_once_on_the_hull_returned() {
        let sc = load(&paper1994("torus_quad12x8")).unwrap();
        let (m, vn, scheme) = mesh_of(&sc);
        let (options, inner) = cubic_c1::options_from_toml(scheme, &sc.path).unwrap();
        let mut hull = crate::hull::inner::build(&m, &vn, &inner).unwrap();
        for t in 0..hull.triangles.len() {
            if hull.apexes[t].iter().all(Option::is_some)
                && !cubic_c1::sided::convex_for(&hull, t, Side::Outer)
            {
                hull.apexes[t][Side::Inner as usize] = None;
            }
        }
        let prepared = cubic_c1::prepare_hull(&hull, &options);
        // The premise: the changes add tetrahedra.
        assert!(!prepared.lu_completed.is_empty());
        let (complex, filled) = cubic_on_prepared(&hull, &options).unwrap();
        assert_eq!(filled.steps(), prepared.steps());
        let filled = filled.hull;
        assert!(same_hull(&filled, &prepared.hull));
        assert_eq!(patch_tets(&complex), hull_tets(&filled));
        assert_ne!(patch_tets(&complex), hull_tets(&hull));
        assert_eq!(complex, cubic_c1::build(&hull, &options).unwrap());
    }

    #[test]
    fn bad_patch_files_are_rejected_with_file_and_patch() {
        let dir = std::env::temp_dir().join(format!("apatch-scene-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.json");
        let mut c = crate::fixtures::quadric_complex(
            &crate::fixtures::Quadric::sphere(DVec3::ZERO, 0.5),
            DVec3::splat(-1.0),
            DVec3::splat(1.0),
            1,
            2,
        );
        let good = crate::complex_io::to_json_string(&c).unwrap();
        std::fs::write(&path, &good).unwrap();
        assert_eq!(read_patches(&path).unwrap().patches.len(), c.patches.len());
        // One weight too few in patch 3: plain serde accepted this and the tracer failed later.
        c.patches[3].weights.pop();
        let bad = serde_json::to_string(&c).unwrap();
        std::fs::write(&path, bad).unwrap();
        let e = format!("{:#}", read_patches(&path).unwrap_err());
        assert!(e.contains("bad.json") && e.contains("patch 3"), "{e}");
        std::fs::write(&path, "{").unwrap();
        let e = format!("{:#}", read_patches(&path).unwrap_err());
        assert!(e.contains("bad.json"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
