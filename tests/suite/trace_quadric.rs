//! The tracer against analytic ray–quadric solutions: one global quadric represented exactly
//! by a patch complex (fixtures) must give, per camera ray, the analytic hit distance and normal
//! to 1e-9 relative; rays from inside the closed surface never miss (no cracks).

use apatch::fixtures::{quadric_complex, random_unit as unit, splitmix as rng, Quadric};
use apatch::trace::shade::surface;
use apatch::trace::{Camera, FovAxis, Geometry};
use glam::DVec3;

/// Relative accuracy demanded of hit distances and normals. Roots are polished by Newton in
/// f64 on O(1) Bernstein coefficients: errors are ~1e-14, so 1e-9 leaves room only for rounding.
const REL: f64 = 1e-9;

/// The analytic first root t ≥ tmin of q along o + t·d, with the discriminant relative to b²
/// (to skip grazing rays, where hit or miss is decided by rounding).
fn analytic(q: &Quadric, o: DVec3, d: DVec3, tmin: f64) -> (Option<f64>, f64) {
    let a = d.dot(q.a * d);
    let b = 2.0 * o.dot(q.a * d) + q.b.dot(d);
    let c = q.value(o);
    let disc = b * b - 4.0 * a * c;
    let rel = disc / (b * b).max(1e-300);
    if disc < 0.0 {
        return (None, rel);
    }
    // Stable quadratic formula.
    let s = disc.sqrt();
    let qq = -0.5 * (b + b.signum() * s);
    let (mut t0, mut t1) = (qq / a, c / qq);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let t = if t0 >= tmin {
        Some(t0)
    } else if t1 >= tmin {
        Some(t1)
    } else {
        None
    };
    (t, rel)
}

fn check_image(q: &Quadric, degree: usize, cells: usize, cam: &Camera) {
    let complex = quadric_complex(q, DVec3::splat(-1.3), DVec3::splat(1.3), cells, degree);
    let geo = Geometry::new(&complex).unwrap();
    let (mut hits, mut checked) = (0, 0);
    for y in 0..cam.height {
        for x in 0..cam.width {
            let (o, d) = cam.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let (want, disc) = analytic(q, o, d, 0.0);
            let got = geo.intersect(o, d, 0.0, f64::INFINITY);
            if disc.abs() < 1e-6 {
                continue; // grazing: hit or miss is a matter of rounding
            }
            checked += 1;
            match (want, got) {
                (None, None) => {}
                (Some(t), Some(h)) => {
                    hits += 1;
                    assert!(
                        (h.t - t).abs() <= REL * t,
                        "pixel ({x},{y}): t {} vs analytic {t} (rel {:e})",
                        h.t,
                        (h.t - t).abs() / t
                    );
                    let s = surface(&geo, &h, o, d, false);
                    let n = q.gradient(o + t * d).normalize();
                    assert!(
                        (s.n - n).length() <= REL,
                        "pixel ({x},{y}): normal {} vs {n}",
                        s.n
                    );
                }
                (w, g) => panic!("pixel ({x},{y}): analytic {w:?}, traced {g:?}"),
            }
        }
    }
    assert!(
        hits > checked / 5,
        "too few hits to mean anything: {hits}/{checked}"
    );
}

fn camera(origin: DVec3, w: u32, h: u32) -> Camera {
    Camera::look_at(origin, DVec3::ZERO, DVec3::Y, 45.0, FovAxis::X, w, h, 0.01).unwrap()
}

#[test]
fn sphere_renders_to_the_analytic_image() {
    let q = Quadric::sphere(DVec3::new(0.1, -0.05, 0.02), 1.0);
    for degree in [2, 3] {
        check_image(&q, degree, 3, &camera(DVec3::new(0.3, 0.8, 4.0), 64, 48));
    }
}

#[test]
fn ellipsoid_renders_to_the_analytic_image() {
    let q = Quadric::ellipsoid(DVec3::new(0.05, 0.1, -0.1), DVec3::new(1.1, 0.7, 0.9));
    check_image(&q, 2, 4, &camera(DVec3::new(-2.5, 1.5, 3.0), 64, 48));
    check_image(&q, 4, 2, &camera(DVec3::new(3.0, -1.0, 2.0), 48, 48));
}

/// Rays from random interior points in random directions (and towards the complex's shared
/// vertices and edges, where neighbouring tetrahedra meet) all hit the closed surface.
#[test]
fn rays_from_inside_never_miss() {
    let rays: usize = if cfg!(debug_assertions) {
        100_000
    } else {
        1_000_000
    };
    let cases = [
        (Quadric::sphere(DVec3::new(0.02, 0.01, -0.03), 1.0), 2, 4),
        (
            Quadric::ellipsoid(DVec3::ZERO, DVec3::new(1.2, 0.8, 1.0)),
            3,
            5,
        ),
    ];
    let mut state = 12345u64;
    for (q, degree, cells) in cases {
        let complex = quadric_complex(&q, DVec3::splat(-1.3), DVec3::splat(1.3), cells, degree);
        let geo = Geometry::new(&complex).unwrap();
        let step = 2.6 / cells as f64;
        let mut misses = 0;
        for i in 0..rays / 2 {
            // An interior point (rejection sampling in the box).
            let o = loop {
                let p = (DVec3::new(rng(&mut state), rng(&mut state), rng(&mut state)) * 2.0 - 1.0)
                    * 1.2;
                if q.value(p) < -1e-3 {
                    break p;
                }
            };
            let d = if i % 4 == 0 {
                // Towards a grid vertex or edge midpoint of the Kuhn complex.
                let g = |s: &mut u64| -1.3 + step * (rng(s) * (cells as f64 + 1.0)).floor();
                let mut t = DVec3::new(g(&mut state), g(&mut state), g(&mut state));
                if i % 8 == 0 {
                    t.x += 0.5 * step;
                }
                (t - o).try_normalize().unwrap_or(DVec3::X)
            } else {
                unit(&mut state)
            };
            let hit = geo.intersect(o, d, 0.0, f64::INFINITY);
            match hit {
                Some(h) => {
                    // Exiting the solid: the hit must be on the surface.
                    let p = o + h.t * d;
                    // Value at the hit: rounding of F near the surface (O(1) coefficients).
                    assert!(q.value(p).abs() < 1e-9, "off-surface hit {p}");
                }
                None => misses += 1,
            }
        }
        assert_eq!(
            misses,
            0,
            "{misses} of {} rays escaped (degree {degree})",
            rays / 2
        );
    }
}

/// Shadow-ray queries agree with closest hits.
#[test]
fn occlusion_matches_intersection() {
    let q = Quadric::sphere(DVec3::ZERO, 0.9);
    let complex = quadric_complex(&q, DVec3::splat(-1.0), DVec3::splat(1.0), 3, 2);
    let geo = Geometry::new(&complex).unwrap();
    let mut state = 7u64;
    for _ in 0..2000 {
        let o = unit(&mut state) * 3.0;
        let d = (unit(&mut state) * 0.8 - o).normalize();
        let hit = geo.intersect(o, d, 0.0, f64::INFINITY);
        let tmax = 1.0 + 4.0 * rng(&mut state);
        let blocked = geo.occluded(o, d, 0.0, tmax);
        assert_eq!(blocked, hit.is_some_and(|h| h.t < tmax), "o={o} d={d}");
    }
}

/// The 2001 scheme reproduces quadrics (Theorem 4.2): the icosahedron with exact sphere normals
/// and `free = "quadric"` (scenes/paper2001/fig13_sphere.toml) is the unit sphere, so the
/// tracer's rational patches, shooting rules and cleared denominators must give the analytic
/// sphere's hit distance and normal.
#[test]
fn rational_fig13_sphere_renders_to_the_analytic_sphere() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper2001/fig13_sphere.toml");
    let scene = apatch::scene::load(&path).unwrap();
    let complex = apatch::scene::build_complex(&scene).unwrap();
    let geo = Geometry::new(&complex).unwrap();
    let q = Quadric::sphere(DVec3::ZERO, 1.0);
    let cam = scene.settings.camera.resized(64, 64).unwrap();
    let mut hits = 0;
    for y in 0..cam.height {
        for x in 0..cam.width {
            let (o, d) = cam.ray(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let (want, disc) = analytic(&q, o, d, 0.0);
            if disc.abs() < 1e-6 {
                continue;
            }
            match (want, geo.intersect(o, d, 0.0, f64::INFINITY)) {
                (None, None) => {}
                (Some(t), Some(h)) => {
                    hits += 1;
                    assert!(
                        (h.t - t).abs() <= REL * t,
                        "pixel ({x},{y}): t {} vs {t} (rel {:e})",
                        h.t,
                        (h.t - t).abs() / t
                    );
                    let n = surface(&geo, &h, o, d, false).n;
                    let want_n = (o + t * d).normalize();
                    assert!((n - want_n).length() <= REL, "pixel ({x},{y}): normal {n}");
                }
                (w, g) => panic!("pixel ({x},{y}): analytic {w:?}, traced {g:?}"),
            }
        }
    }
    assert!(hits > 500, "{hits}");
}
