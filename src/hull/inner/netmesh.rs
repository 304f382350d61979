//! Well-shaped triangles for a zero coplanar group: Steiner points inside a flat net's guard
//! polygon ([`super::flatnet`]).
//!
//! A flat net triangulates only its guards, one per corner of the flat polygon. Where the
//! polygon's boundary is finely sampled along a long side (flattened fandisk: corners every
//! 0.019 along sides 0.8 long), the guards there are nearly collinear and even the Delaunay
//! triangulation of the guard polygon is a fan of needles: angles of 0.5° and 173°, triangles
//! 0.76 long and 0.019 wide. The quintic's C1/C2 conditions from such a face tetrahedron into
//! its edge tetrahedra extrapolate by up to 265 of its sizes (passing scenes stay below 17),
//! and its star equations become nearly dependent: every row fandisk's joint solve missed lay
//! next to such needles. Any point of the polygon may be a point of T of the zero coplanar
//! group (on the plane, with the face normal and a zero Hessian), so points are added inside
//! until the triangles are well shaped, as Ruppert's refinement does; the guard polygon's
//! edges are kept (each carries a step (5') cell), so a circumcentre that would encroach on one
//! is replaced by the apex of the equilateral triangle standing on that edge.

use glam::DVec2;
use std::collections::{BTreeSet, HashMap};

/// Most Steiner points per guard of the polygon (a bound, not a target: refinement stops
/// earlier when every triangle is good or cannot be improved).
pub const MAX_POINTS_PER_GUARD: usize = 12;

/// A Steiner point closer than this share of its local length (the edge or circumradius that
/// asked for it) to an existing point is refused: it would make a new needle.
const MIN_SPACING: f64 = 0.3;

/// A triangulation of a polygon with added interior points.
#[derive(Clone, Debug)]
pub struct NetMesh {
    /// The polygon's corners (first, in order) and the Steiner points after them.
    pub points: Vec<DVec2>,
    /// Counter-clockwise triangles (indices into `points`).
    pub triangles: Vec<[u32; 3]>,
}

/// Smallest angle of triangle (a, b, c), in radians.
#[must_use]
pub fn min_angle(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let ang = |p: DVec2, q: DVec2, r: DVec2| (q - p).angle_to(r - p).abs();
    ang(a, b, c).min(ang(b, c, a)).min(ang(c, a, b))
}

/// Refines the counter-clockwise triangulation `triangles` of the simple counter-clockwise
/// polygon `polygon` (its corners are points 0..k, its edges i → i + 1 are kept) by Steiner
/// points until no triangle has an angle below `min_angle_deg` that a point inside the polygon
/// can remove (see the module docs), at most [`MAX_POINTS_PER_GUARD`] per corner. The result is
/// Delaunay within the polygon. Deterministic: the worst triangle (smallest angle, then lowest
/// sorted vertex triple) is treated first.
#[must_use]
pub fn refine(polygon: &[DVec2], triangles: &[[u32; 3]], min_angle_deg: f64) -> NetMesh {
    let mut m = Mesh::new(polygon, triangles);
    let bound = min_angle_deg.to_radians();
    let budget = MAX_POINTS_PER_GUARD * polygon.len();
    let mut refused: BTreeSet<[u32; 3]> = BTreeSet::new();
    while m.points.len() < polygon.len() + budget {
        // The worst triangle not yet refused.
        let worst = m
            .tris
            .iter()
            .filter_map(|t| {
                let t = (*t)?;
                let [a, b, c] = t.map(|i| m.points[i as usize]);
                let q = min_angle(a, b, c);
                let mut key = t;
                key.sort_unstable();
                (q < bound && !refused.contains(&key)).then_some((q, key, t))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let Some((_, key, t)) = worst else { break };
        match m.candidate(t, bound) {
            Some(p) if m.insert(p) => {}
            _ => {
                refused.insert(key);
            }
        }
    }
    NetMesh {
        points: m.points,
        triangles: m.tris.into_iter().flatten().collect(),
    }
}

/// The triangulation being refined: triangles (None once replaced) and the owner of every
/// directed edge.
struct Mesh {
    points: Vec<DVec2>,
    k: usize,
    tris: Vec<Option<[u32; 3]>>,
    owner: HashMap<(u32, u32), usize>,
}

impl Mesh {
    fn new(polygon: &[DVec2], triangles: &[[u32; 3]]) -> Mesh {
        let mut m = Mesh {
            points: polygon.to_vec(),
            k: polygon.len(),
            tris: Vec::new(),
            owner: HashMap::new(),
        };
        for &t in triangles {
            m.add(t);
        }
        let mut all: Vec<(u32, u32)> = m.owner.keys().copied().collect();
        all.sort_unstable();
        m.legalize(all);
        m
    }

    fn add(&mut self, t: [u32; 3]) {
        let i = self.tris.len();
        for e in 0..3 {
            self.owner.insert((t[e], t[(e + 1) % 3]), i);
        }
        self.tris.push(Some(t));
    }

    fn remove(&mut self, i: usize) -> [u32; 3] {
        let t = self.tris[i].take().expect("a live triangle");
        for e in 0..3 {
            if self.owner.get(&(t[e], t[(e + 1) % 3])) == Some(&i) {
                self.owner.remove(&(t[e], t[(e + 1) % 3]));
            }
        }
        t
    }

    fn p(&self, i: u32) -> DVec2 {
        self.points[i as usize]
    }

    /// Edge a → b is an edge of the guard polygon.
    fn is_boundary(&self, a: u32, b: u32) -> bool {
        let k = self.k as u32;
        a < k && b < k && (a + 1) % k == b
    }

    fn boundary(&self) -> impl Iterator<Item = (DVec2, DVec2)> + '_ {
        (0..self.k).map(|i| (self.points[i], self.points[(i + 1) % self.k]))
    }

    /// Strictly inside the polygon (even-odd crossing count).
    fn inside(&self, p: DVec2) -> bool {
        let mut inside = false;
        for (a, b) in self.boundary() {
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// A polygon edge that `p` encroaches on: one it sees under more than π − 2 `bound` (its
    /// diametral lens, Shewchuk's variant of Ruppert's circle: the triangle `p` would make with
    /// the edge has an angle below `bound` at both of the edge's ends). The polygon's edges are
    /// not split, so the circle, which grows with a long edge, would refuse the points a long
    /// thin net needs.
    fn encroached(&self, p: DVec2, bound: f64) -> Option<usize> {
        let limit = std::f64::consts::PI - 2.0 * bound;
        (0..self.k).find(|&i| {
            let (a, b) = (self.points[i], self.points[(i + 1) % self.k]);
            (a - p).angle_to(b - p).abs() > limit
        })
    }

    /// The point that would improve triangle `t`: its off-centre (Üngör: the apex of the
    /// equilateral triangle on its shortest edge, on its side, or the circumcentre when that
    /// is nearer), then its circumcentre; where one encroaches on a polygon edge, the apex of
    /// the equilateral triangle standing inside on that edge instead. A point outside the
    /// polygon, still encroaching, or within [`MIN_SPACING`] of its local length from an
    /// existing point is refused; `None` when both are.
    fn candidate(&self, t: [u32; 3], bound: f64) -> Option<DVec2> {
        let v = t.map(|i| self.p(i));
        let (cc, r) = circumcircle(v[0], v[1], v[2])?;
        let e = (0..3)
            .min_by(|&a, &b| {
                let l = |e: usize| (v[(e + 1) % 3] - v[e]).length_squared();
                l(a).total_cmp(&l(b))
            })
            .expect("three edges");
        let (p, q) = (v[e], v[(e + 1) % 3]);
        let (mid, d) = (0.5 * (p + q), q - p);
        // The triangle is counter-clockwise: its third vertex lies to the left of p → q.
        let off = mid + 0.5 * 3f64.sqrt() * d.perp();
        let first = if (cc - mid).length() < (off - mid).length() {
            (cc, r)
        } else {
            (off, d.length())
        };
        [first, (cc, r)]
            .into_iter()
            .find_map(|(point, local)| self.admit(point, local, bound))
    }

    /// `point` (asked for at length `local`), or, when it encroaches on a polygon edge, a
    /// point on that edge's inward bisector: the apex of the equilateral triangle on it, or
    /// where that lies outside (a long edge across a narrow polygon), the highest of half, a
    /// quarter … of that height that lies inside; the point must lie inside, encroach on no
    /// other edge and keep [`MIN_SPACING`] of its length from every point.
    fn admit(&self, point: DVec2, local: f64, bound: f64) -> Option<DVec2> {
        let spaced = |p: DVec2, local: f64| {
            self.points
                .iter()
                .all(|&x| (x - p).length() >= MIN_SPACING * local)
        };
        let Some(i) = self.encroached(point, bound) else {
            return (self.inside(point) && spaced(point, local)).then_some(point);
        };
        let (a, b) = (self.points[i], self.points[(i + 1) % self.k]);
        let s = b - a;
        // The polygon is counter-clockwise: its inside lies to the left of a → b.
        let (mid, up) = (0.5 * (a + b), s.perp());
        let mut h = 0.5 * 3f64.sqrt();
        for _ in 0..4 {
            let apex = mid + h * up;
            if self.inside(apex) {
                let other = (0..self.k).filter(|&j| j != i).any(|j| {
                    let (p, q) = (self.points[j], self.points[(j + 1) % self.k]);
                    (p - apex).angle_to(q - apex).abs() > std::f64::consts::PI - 2.0 * bound
                });
                return (!other && spaced(apex, h * s.length())).then_some(apex);
            }
            h *= 0.5;
        }
        None
    }

    /// Inserts `p` (inside the polygon) and restores the Delaunay property by flips; false
    /// when no triangle holds it, or it lies on a polygon edge.
    fn insert(&mut self, p: DVec2) -> bool {
        let Some((t, on)) = self.locate(p) else {
            return false;
        };
        let tri = self.tris[t].expect("located triangle is live");
        let n = self.points.len() as u32;
        let mut check = Vec::new();
        match on {
            None => {
                self.points.push(p);
                self.remove(t);
                for e in 0..3 {
                    let (a, b) = (tri[e], tri[(e + 1) % 3]);
                    self.add([a, b, n]);
                    check.push((a, b));
                }
            }
            Some(e) => {
                let (a, b, c) = (tri[e], tri[(e + 1) % 3], tri[(e + 2) % 3]);
                if self.is_boundary(a, b) {
                    return false;
                }
                let Some(&s) = self.owner.get(&(b, a)) else {
                    return false;
                };
                let other = self.tris[s].expect("owner is live");
                let f = (0..3).find(|&f| other[f] == b).expect("shared edge");
                let d = other[(f + 2) % 3];
                self.points.push(p);
                self.remove(t);
                self.remove(s);
                for (x, y) in [(b, c), (c, a), (a, d), (d, b)] {
                    self.add([x, y, n]);
                    check.push((x, y));
                }
            }
        }
        self.legalize(check);
        true
    }

    /// Lawson's flips from the edges in `check` (round a new point, or all of them) until
    /// every one reached is locally Delaunay.
    fn legalize(&mut self, mut check: Vec<(u32, u32)>) {
        while let Some((a, b)) = check.pop() {
            if self.is_boundary(a, b) {
                continue;
            }
            let (Some(&t), Some(&s)) = (self.owner.get(&(a, b)), self.owner.get(&(b, a))) else {
                continue;
            };
            let tt = self.tris[t].expect("live");
            let ts = self.tris[s].expect("live");
            let c = tt[(tt.iter().position(|&x| x == a).expect("a in t") + 2) % 3];
            let d = ts[(ts.iter().position(|&x| x == b).expect("b in s") + 2) % 3];
            if in_circle(self.p(a), self.p(b), self.p(c), self.p(d)) {
                self.remove(t);
                self.remove(s);
                self.add([c, a, d]);
                self.add([d, b, c]);
                for e in [(a, d), (d, b), (b, c), (c, a)] {
                    check.push(e);
                }
            }
        }
    }

    /// The triangle holding `p` and, when `p` lies on one of its edges (within rounding), that
    /// edge's index.
    fn locate(&self, p: DVec2) -> Option<(usize, Option<usize>)> {
        for (i, t) in self.tris.iter().enumerate() {
            let Some(t) = t else { continue };
            let v = t.map(|j| self.p(j));
            let scale = (v[1] - v[0])
                .length_squared()
                .max((v[2] - v[1]).length_squared())
                .max((v[0] - v[2]).length_squared());
            let s: Vec<f64> = (0..3)
                .map(|e| (v[(e + 1) % 3] - v[e]).perp_dot(p - v[e]))
                .collect();
            let eps = 1e-12 * scale;
            if s.iter().all(|&x| x > -eps) {
                let on = (0..3).find(|&e| s[e] <= eps);
                return Some((i, on));
            }
        }
        None
    }
}

/// Circumcentre and radius of (a, b, c); `None` when they are collinear.
fn circumcircle(a: DVec2, b: DVec2, c: DVec2) -> Option<(DVec2, f64)> {
    let (b, c) = (b - a, c - a);
    let d = 2.0 * b.perp_dot(c);
    if d.abs() <= 1e-300 {
        return None;
    }
    let u = DVec2::new(
        c.y * b.length_squared() - b.y * c.length_squared(),
        b.x * c.length_squared() - c.x * b.length_squared(),
    ) / d;
    Some((a + u, u.length()))
}

/// `d` strictly inside the circle through the counter-clockwise a, b, c (beyond rounding).
fn in_circle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let det = ad.length_squared() * bd.perp_dot(cd) - bd.length_squared() * ad.perp_dot(cd)
        + cd.length_squared() * ad.perp_dot(bd);
    let scale = ad
        .length_squared()
        .max(bd.length_squared())
        .max(cd.length_squared());
    det > 1e-12 * scale * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(p: &[DVec2], t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| p[i as usize]);
        0.5 * (b - a).perp_dot(c - a)
    }

    /// A long thin polygon, as fandisk's flat nets' guard polygons: one long side sampled
    /// every 0.02 (41 corners), the other only at its ends, triangulated as a fan from one far
    /// corner (needles of 0.1°). Refined, every triangle is counter-clockwise, they tile the
    /// polygon (areas add up), the polygon's edges are still edges, the result is Delaunay,
    /// and the smallest angle is far above the fan's.
    #[test]
    fn a_fan_of_needles_becomes_well_shaped() {
        let mut poly: Vec<DVec2> = (0..=40).map(|i| DVec2::new(0.02 * i as f64, 0.0)).collect();
        poly.push(DVec2::new(0.8, 0.3));
        poly.push(DVec2::new(0.0, 0.3));
        let k = poly.len() as u32;
        // Fan from the last corner (0, 0.3).
        let tris: Vec<[u32; 3]> = (0..k - 2).map(|i| [k - 1, i, i + 1]).collect();
        let before = tris
            .iter()
            .map(|t| {
                min_angle(
                    poly[t[0] as usize],
                    poly[t[1] as usize],
                    poly[t[2] as usize],
                )
            })
            .fold(f64::INFINITY, f64::min);
        let m = refine(&poly, &tris, 25.0);
        let total: f64 = m.triangles.iter().map(|&t| area(&m.points, t)).sum();
        // The polygon's area is 0.8 × 0.3; the sum only rounds.
        assert!((total - 0.24).abs() < 1e-12, "{total}");
        assert!(m.triangles.iter().all(|&t| area(&m.points, t) > 0.0));
        let edges: BTreeSet<(u32, u32)> = m
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |e| (t[e], t[(e + 1) % 3])))
            .collect();
        for i in 0..k {
            assert!(edges.contains(&(i, (i + 1) % k)), "polygon edge {i} kept");
        }
        // Every Steiner point lies inside.
        let mesh = Mesh::new(&poly, &[]);
        assert!(m.points[k as usize..].iter().all(|&p| mesh.inside(p)));
        // Delaunay: no interior edge's opposite vertex inside the other triangle's circle.
        for t in &m.triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                let Some(s) = m
                    .triangles
                    .iter()
                    .find(|s| (0..3).any(|f| s[f] == b && s[(f + 1) % 3] == a))
                else {
                    continue;
                };
                let d = *s.iter().find(|&&x| x != a && x != b).unwrap();
                let p = |i: u32| m.points[i as usize];
                assert!(!in_circle(p(a), p(b), p(t[(e + 2) % 3]), p(d)));
            }
        }
        let after = m
            .triangles
            .iter()
            .map(|&t| {
                min_angle(
                    m.points[t[0] as usize],
                    m.points[t[1] as usize],
                    m.points[t[2] as usize],
                )
            })
            .fold(f64::INFINITY, f64::min);
        assert!(before.to_degrees() < 1.0, "{}", before.to_degrees());
        // Ruppert's 25° would need the long sides split; they are kept, so the triangles next
        // to the 0.8-long side stay below it (7.2° here), but no needle is left: the fan's
        // 0.1° become more than 5°.
        assert!(after.to_degrees() > 5.0, "{}", after.to_degrees());
        assert!(m.points.len() < poly.len() * (1 + MAX_POINTS_PER_GUARD));
    }

    /// A triangulation already good enough is returned as it is.
    #[test]
    fn good_triangles_are_left_alone() {
        let poly = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let tris = vec![[0, 1, 2], [0, 2, 3]];
        let m = refine(&poly, &tris, 30.0);
        assert_eq!(m.points, poly);
        assert_eq!(m.triangles, tris);
    }
}
