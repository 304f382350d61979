//! Tracer throughput: `cargo bench --bench trace` (plain harness; prints a table).
//!
//! For each model scene (bunny, spot, teapot) and a fixture sphere complex: BVH build time, memory
//! per patch, and primary rays per second at 1024×1024, 1 spp, with 1 and 2 threads, in
//! `shaded` mode (with its shadow rays) and `normal` mode (primary rays only).
//!
//! For the models, in the same run: the tessellation of the same complex (resolution 8 per
//! patch) traced as obvhs triangles with the same camera samples, lights and shadow rays
//! (normals interpolated from ∇F at the vertices), and the ratios patch / triangle of
//! throughput, build time and memory. Set `APATCH_BENCH_MODELS=bunny,spot` to pick models.

use apatch::export::{tessellate, TriMesh};
use apatch::fixtures::{quadric_complex, Quadric};
use apatch::scene;
use apatch::trace::shade::{self, hash01};
use apatch::trace::{self, Geometry, Mode};
use glam::{DVec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use rayon::prelude::*;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

#[path = "support/cpu.rs"]
mod cpu;
use cpu::{cpu_seconds, load_average};

/// The comparison tracer: the tessellation of the same complex (`export::tessellate`) as f32
/// triangles in an obvhs CwBvh (its fastest traversal layout), Möller–Trumbore hits, vertex
/// normals (∇F at the tessellation's vertices) interpolated, the same camera samples and the
/// same lights, material and shadow rays as the patch tracer's `shaded` mode.
struct Triangles {
    /// Corner positions per triangle (what the intersection reads).
    tris: Vec<[Vec3A; 3]>,
    /// Vertex indices per triangle (for normal interpolation).
    index: Vec<[u32; 3]>,
    normals: Vec<Vec3A>,
    bvh: CwBvh,
    build: Duration,
    extent: f32,
}

impl Triangles {
    fn new(mesh: &TriMesh) -> Self {
        let v = |p: [f64; 3]| Vec3A::new(p[0] as f32, p[1] as f32, p[2] as f32);
        let tris: Vec<[Vec3A; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|i| v(mesh.positions[i as usize])))
            .collect();
        let start = Instant::now();
        let prims: Vec<Triangle> = tris
            .iter()
            .map(|t| Triangle {
                v0: t[0],
                v1: t[1],
                v2: t[2],
            })
            .collect();
        let mut core = Duration::ZERO;
        let bvh = build_cwbvh_from_tris(&prims, BvhBuildParams::medium_build(), &mut core);
        let build = start.elapsed();
        let ext = bvh.total_aabb.diagonal();
        Triangles {
            tris,
            index: mesh.triangles.clone(),
            normals: mesh.normals.iter().map(|&n| v(n)).collect(),
            bvh,
            build,
            extent: ext.max_element(),
        }
    }

    /// Bytes of everything the tracer reads: triangle corners, BVH nodes and indices, vertex
    /// indices and normals for shading.
    fn memory_bytes(&self) -> usize {
        self.tris.len() * std::mem::size_of::<[Vec3A; 3]>()
            + self.bvh.nodes.len() * std::mem::size_of::<CwBvhNode>()
            + self.bvh.primitive_indices.len() * 4
            + self.index.len() * 12
            + self.normals.len() * std::mem::size_of::<Vec3A>()
    }

    /// Möller–Trumbore: (t, u, v) with tmin ≤ t < tmax.
    #[inline]
    fn hit(t: &[Vec3A; 3], o: Vec3A, d: Vec3A, tmin: f32, tmax: f32) -> Option<(f32, f32, f32)> {
        let e1 = t[1] - t[0];
        let e2 = t[2] - t[0];
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-20 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - t[0];
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(q) * inv;
        (t >= tmin && t < tmax).then_some((t, u, v))
    }

    fn ray(o: Vec3A, d: Vec3A, tmax: f32) -> Ray {
        Ray::new(o, d, 0.0, tmax)
    }

    /// Closest hit: (t, triangle, u, v).
    fn intersect(&self, o: Vec3A, d: Vec3A) -> Option<(f32, usize, f32, f32)> {
        let mut best: Option<(f32, usize, f32, f32)> = None;
        let mut rh = RayHit::none();
        self.bvh
            .ray_traverse(Self::ray(o, d, f32::INFINITY), &mut rh, |ray, slot| {
                let i = self.bvh.primitive_indices[slot] as usize;
                match Self::hit(&self.tris[i], o, d, 0.0, ray.tmax) {
                    Some((t, u, v)) => {
                        best = Some((t, i, u, v));
                        t
                    }
                    None => f32::INFINITY,
                }
            });
        best
    }

    fn occluded(&self, o: Vec3A, d: Vec3A, tmin: f32, tmax: f32) -> bool {
        !self
            .bvh
            .ray_traverse_miss(Self::ray(o, d, tmax), |_ray, slot| {
                let i = self.bvh.primitive_indices[slot] as usize;
                if Self::hit(&self.tris[i], o, d, tmin, tmax).is_some() {
                    0.0
                } else {
                    f32::INFINITY
                }
            })
    }

    /// Pixel (x, y) at 1 spp in `shaded` mode: the patch tracer's sample position, lights,
    /// one-sided diffuse BSDF and shadow rays. Returns (radiance, hit).
    fn shade(&self, s: &trace::RenderSettings, x: u32, y: u32) -> (DVec3, bool) {
        let (u, v) = (hash01(x, y, 0, 0), hash01(x, y, 0, 1));
        let (o, d) = s.camera.ray(f64::from(x) + u, f64::from(y) + v);
        let f = |p: DVec3| Vec3A::new(p.x as f32, p.y as f32, p.z as f32);
        let (of, df) = (f(o), f(d));
        let Some((t, i, bu, bv)) = self.intersect(of, df) else {
            return (DVec3::ZERO, false);
        };
        let [a, b, c] = self.index[i].map(|k| self.normals[k as usize]);
        let n = (a * (1.0 - bu - bv) + b * bu + c * bv).normalize_or_zero();
        let nd = DVec3::new(f64::from(n.x), f64::from(n.y), f64::from(n.z));
        if nd.dot(-d) <= 0.0 {
            return (DVec3::ZERO, true);
        }
        // f32 geometry: the shadow-ray offset must exceed f32 rounding of the scene (1e-7
        // relative) by a wide margin.
        let eps = 1e-4 * self.extent;
        let origin = of + df * t + n * eps;
        let o64 = DVec3::new(
            f64::from(origin.x),
            f64::from(origin.y),
            f64::from(origin.z),
        );
        let rnd = [hash01(x, y, 0, 2), hash01(x, y, 0, 3)];
        // The patch tracer's light loop with f32 triangle occlusion.
        let out = shade::direct_light(&s.lighting, nd, o64, rnd, |l, tmax| {
            let tmax = if tmax.is_finite() {
                tmax as f32
            } else {
                f32::INFINITY
            };
            self.occluded(origin, f(l), eps, tmax)
        });
        (out, true)
    }

    /// Renders the whole image in parallel rows (like `trace::render`); returns hits and the
    /// radiance per pixel.
    fn render(&self, s: &trace::RenderSettings) -> (usize, Vec<DVec3>) {
        let (w, h) = (s.camera.width as usize, s.camera.height as usize);
        let mut px = vec![(DVec3::ZERO, false); w * h];
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(s.threads)
            .build()
            .unwrap();
        pool.install(|| {
            px.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                for (x, p) in row.iter_mut().enumerate() {
                    *p = self.shade(s, x as u32, y as u32);
                }
            });
        });
        (
            px.iter().filter(|p| p.1).count(),
            px.into_iter().map(|p| p.0).collect(),
        )
    }
}

/// Patch-tracer figures of one run: (M rays/s wall, M rays per CPU-second) per thread count.
type Rates = Vec<(usize, f64, f64)>;

fn bench(
    name: &str,
    complex: &apatch::complex::PatchComplex,
    settings: &trace::RenderSettings,
) -> Option<(Rates, usize, Duration, f64)> {
    let geo = match Geometry::new(complex) {
        Ok(g) => g,
        Err(e) => {
            println!("{name}: cannot compile: {e}");
            return None;
        }
    };
    let mut shaded = Vec::new();
    let mut hits = 0;
    let n = complex.patches.len();
    println!(
        "{name}: {n} patches, BVH build {:.1} ms, {:.0} bytes/patch (compiled patches + BVH)",
        geo.bvh_build_time().as_secs_f64() * 1e3,
        geo.memory_bytes() as f64 / n as f64
    );
    let mut s = settings.clone();
    s.camera = s.camera.resized(1024, 1024).unwrap();
    s.spp = 1;
    for mode in [Mode::Shaded, Mode::Normal] {
        for threads in [1, 2] {
            s.mode = mode;
            s.threads = threads;
            let t = Instant::now();
            let cpu = cpu_seconds();
            let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
            let secs = t.elapsed().as_secs_f64();
            let cpu = cpu_seconds() - cpu;
            let hit = f.pixels.iter().filter(|p| p.alpha > 0.0).count();
            hits = hit;
            if mode == Mode::Shaded {
                shaded.push((threads, 1.048_576 / secs, 1.048_576 / cpu));
            }
            println!(
                "  {mode:?}, {threads} thread(s): {:.3} s, {:.2} M primary rays/s, {:.2} M rays per CPU-second ({:.0} % of pixels hit)",
                secs,
                1024.0 * 1024.0 / secs / 1e6,
                1024.0 * 1024.0 / cpu / 1e6,
                100.0 * hit as f64 / (1024.0 * 1024.0)
            );
        }
    }
    Some((
        shaded,
        geo.memory_bytes(),
        geo.bvh_build_time(),
        hits as f64,
    ))
}

/// The triangle tracer on the tessellation, and the ratios against the patch tracer's figures.
fn compare(
    name: &str,
    complex: &apatch::complex::PatchComplex,
    settings: &trace::RenderSettings,
    patch: &(Rates, usize, Duration, f64),
) {
    let t = Instant::now();
    let mesh = match tessellate(complex, 8) {
        Ok(m) => m,
        Err(e) => {
            println!("{name}: cannot tessellate: {e:#}");
            return;
        }
    };
    let tess = t.elapsed().as_secs_f64();
    let tri = Triangles::new(&mesh);
    let n = complex.patches.len() as f64;
    println!(
        "{name} triangles (resolution 8): {} triangles ({:.1} per patch), tessellated in {:.2} s, CwBvh build {:.1} ms, {:.0} bytes/patch (corners + BVH + indices + normals)",
        mesh.triangles.len(),
        mesh.triangles.len() as f64 / n,
        tess,
        tri.build.as_secs_f64() * 1e3,
        tri.memory_bytes() as f64 / n
    );
    let mut s = settings.clone();
    s.camera = s.camera.resized(1024, 1024).unwrap();
    s.spp = 1;
    s.mode = Mode::Shaded;
    for &(threads, p_wall, p_cpu) in &patch.0 {
        s.threads = threads;
        let t = Instant::now();
        let cpu = cpu_seconds();
        let (hit, _) = tri.render(&s);
        let secs = t.elapsed().as_secs_f64();
        let cpu = cpu_seconds() - cpu;
        let (wall, per_cpu) = (1.048_576 / secs, 1.048_576 / cpu);
        println!(
            "  Shaded, {threads} thread(s): {secs:.3} s, {wall:.2} M primary rays/s, {per_cpu:.2} M rays per CPU-second; patch/triangle throughput {:.2} (wall) {:.2} (CPU); pixels hit {hit} vs patches {:.0}",
            p_wall / wall,
            p_cpu / per_cpu,
            patch.3
        );
    }
    println!(
        "  ratios patch/triangle: BVH build {:.3}, memory {:.3} (triangles use {:.1}× the memory)",
        patch.2.as_secs_f64() / tri.build.as_secs_f64(),
        patch.1 as f64 / tri.memory_bytes() as f64,
        tri.memory_bytes() as f64 / patch.1 as f64
    );
}

/// `APATCH_BENCH_PROFILE=N`: only the first selected model's patch tracer, shaded, 1 thread,
/// N renders (a steady loop for `perf record`); prints rays per CPU-second per render.
fn profile_shaded(
    name: &str,
    complex: &apatch::complex::PatchComplex,
    settings: &trace::RenderSettings,
    n: usize,
) {
    let geo = Geometry::new(complex).expect("compiles");
    let mut s = settings.clone();
    s.camera = s.camera.resized(1024, 1024).unwrap();
    s.spp = 1;
    s.mode = Mode::Shaded;
    s.threads = 1;
    for _ in 0..n {
        let cpu = cpu_seconds();
        let f = trace::render(&geo, &s, &|| {}, &AtomicBool::new(false)).unwrap();
        let cpu = cpu_seconds() - cpu;
        let sum: f64 = f.pixels.iter().map(|p| f64::from(p.rgb[0])).sum();
        println!(
            "{name} shaded 1 thread: {:.2} M rays per CPU-second (sum R {sum:.6})",
            1.048_576 / cpu
        );
    }
}

fn main() {
    println!(
        "trace bench: {} CPUs, load average {} (1/5/15 min) at start",
        std::thread::available_parallelism().map_or(0, std::num::NonZero::get),
        load_average()
    );
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    // scenes/teapot.toml is the Newell teapot (8×8 per patch); scenes/pending/teapot.toml (the
    // NPM teapot) is run only when the first is absent.
    let only = std::env::var("APATCH_BENCH_MODELS").ok();
    let profile: usize = std::env::var("APATCH_BENCH_PROFILE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    for (name, dir) in [
        ("teapot", "scenes"),
        ("teapot", "scenes/pending"),
        ("bunny", "scenes"),
        ("spot", "scenes"),
    ] {
        if only
            .as_ref()
            .is_some_and(|o| !o.split(',').any(|m| m == name))
        {
            continue;
        }
        let path = root.join(dir).join(format!("{name}.toml"));
        if !path.exists()
            || (dir != "scenes" && root.join("scenes").join(format!("{name}.toml")).exists())
        {
            continue;
        }
        let sc = match scene::load(&path) {
            Ok(s) => s,
            Err(e) => {
                println!("{name}: {e:#}");
                continue;
            }
        };
        let t = Instant::now();
        match scene::build_complex(&sc) {
            Ok(c) if profile > 0 => {
                profile_shaded(name, &c, &sc.settings, profile);
                return;
            }
            Ok(c) => {
                println!(
                    "{name}: complex built in {:.2} s",
                    t.elapsed().as_secs_f64()
                );
                if let Some(p) = bench(name, &c, &sc.settings) {
                    compare(name, &c, &sc.settings, &p);
                }
            }
            Err(e) => println!("{name}: {e:#}"),
        }
    }
    // A fixture: the unit sphere on 10³ Kuhn cubes (6000 cubic patches).
    let q = Quadric::sphere(DVec3::ZERO, 1.0);
    let c = quadric_complex(&q, DVec3::splat(-1.2), DVec3::splat(1.2), 10, 3);
    let mut sc = scene::parse(
        r#"
[model]
patches = "unused.json"
[camera]
origin = [0.5, 1.0, 4.0]
target = [0, 0, 0]
fov = 40
width = 64
height = 64
[[lights]]
type = "directional"
direction = [-1, -1, -1]
irradiance = 3.0
"#,
        &root.join("scenes/bench.toml"),
    )
    .unwrap();
    sc.settings.spp = 1;
    if only.is_none() {
        bench("sphere fixture (degree 3)", &c, &sc.settings);
    }
    println!("load average {} (1/5/15 min) at the end", load_average());
}
