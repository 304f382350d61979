//! Zero-coplanar corner guard nets on large flat polygons (Appendix B, Algorithm 3).
//!
//! A large flat polygon (fandisk's merged coplanar regions: up to 112 corners, many of them
//! non-convex, with a kernel that is a small part of the face) served by one point of T (its
//! centroid or its kernel guard) gets long thin triangles of T from that point to far corners,
//! whose tetrahedra overlap their neighbours'. Appendix B gives every corner V of such a face
//! its own corner guard G_V inside a small *corner guard circle* near V (Algorithm 3 step
//! (1')), and the face's interior is triangulated among the guards: a *zero coplanar group*
//! (all its triangles of T lie in the face's plane, every guard carries the face normal, so
//! every edge between guards is zero convex and the surface there is the plane itself; the
//! cubic scheme's flat-edge equations are consistent, its number 2 weights a_1110 are 0).
//!
//! Reconstruction (the paper's figures are missing):
//! - the guard of corner V (edges V→W and U→V of the polygon, counter-clockwise) lies on the
//!   bisector of the corner's interior angle at [`GUARD_RADIUS`] × the shorter of the two
//!   edges from V (or of V's distance to the nearest other edge of the polygon, when that is
//!   less: across a narrow strip), halved until it sees both edges (the triangles G V U and G V W hold no
//!   other corner and cross no edge of the polygon) and the guard polygon G_1 … G_n stays
//!   simple and inside the face;
//! - only merged regions (several coplanar input faces, [`super::coplanar`]) whose point of T
//!   (centroid, kernel guard or net guard named in a corner's fan) lies more than
//!   [`super::decompose::GUARD_REACH`] × a corner's longer edge from that corner qualify:
//!   single convex faces with short edges (random convex solids) keep their centroid, and
//!   giving every merged region a flat net made fandisk worse (small regions' guards crowd);
//!   with the vertex normals ([`spread_guards_folded`]) so do merged regions whose point of T
//!   folds a corner's fan (a gap wider than [`FOLD_GAP`] between consecutive fan points round
//!   n_V: fandisk's strips of coplanar triangles with straight corners, whose vertex mean lies
//!   a few degrees from a straight corner's edge), and merged regions where, at a nearly flat
//!   corner V, the diagonal of T from the region's point to the point of the face across one
//!   of V's edges passes beside that edge ([`diagonal_misses`]: Algorithm 1's two triangles
//!   over the edge fold over each other; fandisk's polygons along its 3° folds, whose straight
//!   corners on the fold see a far point of T at a grazing angle), in passes while new ones
//!   appear;
//! - the polygon's points of T (its pieces) become the guards of its first corners, the other
//!   guards are new points of T (same face, same normal);
//! - every corner V's fan names V's own guard for the face, so Algorithm 1 / 2 builds V's
//!   triangles (3), (3'), (4), (5) with guards near V, and the edges V_1V_2 of the face get
//!   step (5') cells between G_{V_1} and G_{V_2} ([`super::guardnet::EdgeCell`]);
//! - the guard polygon is ear-clipped and made Delaunay by edge flips (no slivers where a
//!   better triangle exists) — the zero coplanar group;
//! - each of its triangles gets an L-U pair of face tetrahedra, apexes over its centroid
//!   (drawn towards its edges on the guard polygon, [`BOUNDARY_PULL`]) on both sides of the plane at [`FLAT_HEIGHT`] × its width (every apex off the plane
//!   is tangent containing: the three tangent planes are the face plane), so it shares a side
//!   with every neighbour (cells on convex edges are outer, on concave edges inner).

use super::decompose::polygon_area;
use super::guardnet::{EdgeCell, GuardNet};
use crate::hull::simplicial::{PointOrigin, SimplicialHull};
use crate::mesh::{ear_clip, Fan, Mesh};
use glam::{DVec2, DVec3};
use std::collections::{BTreeSet, HashMap};

/// Distance of a corner's guard from the corner on the bisector of its interior angle, as a
/// share of the corner's shorter edge (halved until the guard sees both edges).
pub const GUARD_RADIUS: f64 = 0.25;

/// Height of the apexes over a zero coplanar triangle, as a share of its width (twice its area
/// over its longest edge): any height is tangent containing (the tangent planes are the face
/// plane), and a long thin triangle's tetrahedra stay as thin as it (relative volume
/// 6V / L³ = FLAT_HEIGHT · (width / L)², above `verify`'s 1e-8 down to width / L ≈ 4e-4).
pub const FLAT_HEIGHT: f64 = super::sides::MIN_HEIGHT;

/// Extra barycentric weight (against 1) of each end of a zero coplanar triangle's edge on the
/// guard polygon for the point its apexes rise over. The step (5') cell across that edge has
/// its apex H beyond the polyhedron edge; the edge tetrahedra between the two take the midpoint
/// s of H and the flat apex q, and the cubic scheme can make them single sheeted only when s
/// lies on the apex side of the cell's triangle (`guardnet`'s slid cells). With q over the
/// centroid of a long flat triangle, s fell far inside the flat region, behind the cell
/// (the quarter annulus prism's holes); drawn to the edge, s lies near it.
pub const BOUNDARY_PULL: f64 = 4.0;

/// Fewest corners for which a polygon whose point of T is far from a corner gets a flat net.
pub const MIN_CORNERS: usize = 4;

/// The zero coplanar groups added to a [`GuardNet`]: one per flat polygon.
#[derive(Clone, Debug, Default)]
pub struct FlatNets {
    /// Per polygon: (piece index of the polygon, guard points of its corners in order,
    /// interior triangles as guard point indices, counter-clockwise from outside).
    pub groups: Vec<FlatGroup>,
    /// Input faces (`face_parent`) of the merged polygons that have what a net needs (several
    /// input faces, at least [`MIN_CORNERS`] corners, one region, every corner's fan holding
    /// it once) but did not qualify for one: the candidates [`super::overlapnet`] may force.
    pub eligible: Vec<u32>,
}

/// One flat polygon's zero coplanar group.
#[derive(Clone, Debug)]
pub struct FlatGroup {
    /// The polygon's piece (its point of T is the first corner's guard).
    pub piece: u32,
    /// Input polygon (merged face) index.
    pub face: u32,
    /// Corners of the polygon (input vertices), counter-clockwise from outside.
    pub corners: Vec<u32>,
    /// Guard of each corner (points of T = piece indices).
    pub guards: Vec<u32>,
    /// Points of T inside the guard polygon ([`super::netmesh`]; empty unless asked for).
    pub inner: Vec<u32>,
    /// Triangles of T inside the guard polygon.
    pub triangles: Vec<[u32; 3]>,
}

/// 2D frame of a polygon's plane.
struct Frame {
    o: DVec3,
    u: DVec3,
    v: DVec3,
    n: DVec3,
}

impl Frame {
    fn flat(&self, p: DVec3) -> DVec2 {
        DVec2::new((p - self.o).dot(self.u), (p - self.o).dot(self.v))
    }
    fn lift(&self, q: DVec2) -> DVec3 {
        self.o + q.x * self.u + q.y * self.v
    }
}

/// Gives every large flat region of `mesh` (a polygon merged from several coplanar input
/// faces, `merged[f]` ≥ 2, [`super::coplanar::merge_coplanar_counted`]; Appendix B's
/// coplanarity) whose points of T lie far from a corner (a corner
/// V farther than [`super::decompose::GUARD_REACH`] × its longer edge from the point its fan
/// names for the polygon; at least [`MIN_CORNERS`] corners; the polygon one region of `net`,
/// or pieces that are regions alone (a polygon whose guard assignment failed, which
/// [`GuardNet::build`] serves by its convex pieces: flattened fandisk's large faces, whose far
/// pieces' fan triangles overlapped everywhere); the polygon's pieces one run in every
/// corner's fan, made one entry) a zero coplanar guard net (module docs): guard pieces
/// (the polygon's own pieces reused first), fans naming them, step (5') cells on its edges.
/// The interior triangles are added to the hull by [`FlatNets::add_triangles`].
pub fn spread_guards(net: &mut GuardNet, mesh: &Mesh, merged: &[usize]) -> FlatNets {
    spread_guards_folded(net, mesh, merged, None)
}

/// Widest fan gap (radians, counter-clockwise round n_V between consecutive points of a
/// corner's fan, projected along n_V) next to a merged polygon's point beyond which the
/// polygon gets a flat net too ([`spread_guards_folded`]): π, where the fan triangle
/// [C_0, C_i, C_{i+1}] turns over (fandisk's 6-corner strip [550, 640, 847, 1384, 1385, 641],
/// whose corner 641 is straight and whose vertex mean lies 4° from the edge to 1385: gap 211°,
/// the inverted triangle 3735).
pub const FOLD_GAP: f64 = std::f64::consts::PI;

/// Sine of the turn below which a polygon's corner of about π counts as straight (0.1°).
pub const STRAIGHT_SIN: f64 = 1.75e-3;

/// Width (twice the area over the diameter) below which a convex polygon counts as a strip, as
/// a share of its diameter: fandisk's strips are 0.13 long and 0.017 wide.
pub const STRIP_WIDTH: f64 = 0.25;

/// Least cosine between a vertex normal and every face normal round it for the fold test
/// (cos 10°).
pub const FLAT_VERTEX_COS: f64 = 0.985;

/// Most passes over the polygons when fold qualifies them ([`spread_guards_folded`]).
pub const FOLD_PASSES: usize = 4;

/// Counter-clockwise angle round `n` from `a` to `b`, in [0, 2π).
fn ccw(n: DVec3, a: DVec3, b: DVec3) -> f64 {
    let t = n.dot(a.cross(b)).atan2(a.dot(b));
    if t < 0.0 {
        t + 2.0 * std::f64::consts::PI
    } else {
        t
    }
}

/// [`spread_guards`], with the vertex normals `normals` (when given) also qualifying merged
/// polygons whose point of T folds a corner's fan (a gap next to it wider than [`FOLD_GAP`])
/// or whose diagonals of T pass beside an edge at a nearly flat corner ([`diagonal_misses`]).
pub fn spread_guards_folded(
    net: &mut GuardNet,
    mesh: &Mesh,
    merged: &[usize],
    normals: Option<&[DVec3]>,
) -> FlatNets {
    spread_guards_forced(net, mesh, merged, normals, &BTreeSet::new(), false, 0.0)
}

/// [`spread_guards_folded`], also giving a flat net to every merged polygon whose input face
/// (`mesh.face_parent`) is in `forced` (the polygons whose triangles of T overlapped in an
/// earlier build, [`super::overlapnet`]), when it has the structure a net needs (several
/// input faces, at least [`MIN_CORNERS`] corners, one region, a guard polygon). With
/// `everywhere` (`InnerOptions::all_flat_nets`) every polygon with that structure qualifies,
/// merged or not, near or far. With `min_angle` > 0 (degrees, `InnerOptions::flat_net_angle`)
/// each net gets points inside its guard polygon until its triangles' angles reach it where
/// they can ([`super::netmesh`]).
pub fn spread_guards_forced(
    net: &mut GuardNet,
    mesh: &Mesh,
    merged: &[usize],
    normals: Option<&[DVec3]>,
    forced: &BTreeSet<u32>,
    everywhere: bool,
    min_angle: f64,
) -> FlatNets {
    let pos = &mesh.positions;
    let mut out = FlatNets::default();
    let np = net.pieces.faces.len();
    let mut of_face: HashMap<u32, Vec<u32>> = HashMap::new();
    for p in 0..np {
        of_face
            .entry(net.pieces.parent[p])
            .or_default()
            .push(p as u32);
    }
    let mut faces: Vec<u32> = of_face.keys().copied().collect();
    faces.sort_unstable();
    // Passes: a polygon's fans change when a neighbour gets its net, which can fold them.
    let mut done = std::collections::HashSet::new();
    for _ in 0..FOLD_PASSES {
        let found = out.groups.len();
        for &f in &faces {
            if done.contains(&f) {
                continue;
            }
            let own = of_face[&f].clone();
            let face = mesh.faces[f as usize].clone();
            let merged_region = merged.get(f as usize).copied().unwrap_or(1) >= 2;
            if face.len() < MIN_CORNERS || !(merged_region || everywhere) {
                continue;
            }
            let mut sorted = face.clone();
            sorted.sort_unstable();
            sorted.dedup();
            // One region holding exactly this polygon's pieces, or (a polygon whose guard
            // assignment failed, [`GuardNet::build`]'s fallback) regions of its pieces alone.
            let r = net.region[own[0] as usize];
            let own_regions: BTreeSet<u32> = own.iter().map(|&q| net.region[q as usize]).collect();
            let region_ok = (0..np)
                .all(|q| own_regions.contains(&net.region[q]) == (net.pieces.parent[q] == f));
            if sorted.len() != face.len() || !region_ok || face.iter().any(|&v| net.inside(v)) {
                continue;
            }
            // Every corner's fan holds the pieces in one run, which becomes one entry.
            let fans: Option<Vec<(Fan, usize)>> = face
                .iter()
                .map(|&v| {
                    let fan = net.fan(v).filter(|x| x.closed)?;
                    one_run(&fan, |q| own.contains(&q))
                })
                .collect();
            let Some(fans) = fans else { continue };
            let k = face.len();
            let far = everywhere
                || (0..k).any(|i| {
                    let p = |j: usize| pos[face[j % k] as usize];
                    let v = p(i);
                    let e = (p(i + 1) - v).length().max((p(i + k - 1) - v).length());
                    let g = net.pieces.center[fans[i].0.faces[fans[i].1] as usize];
                    (g - v).length() > super::decompose::GUARD_REACH * e
                });
            // Only strips: convex polygons with a straight corner (a vertex of the old
            // triangulation on an edge; fandisk's folds), so no other model's hull changes.
            let corner_turn = |i: usize| {
                let v = pos[face[i] as usize];
                let a = pos[face[(i + 1) % k] as usize] - v;
                let b = pos[face[(i + k - 1) % k] as usize] - v;
                (
                    a.cross(b).length() / (a.length() * b.length()),
                    a.dot(b) < 0.0,
                )
            };
            let diameter = face
                .iter()
                .flat_map(|&a| {
                    face.iter()
                        .map(move |&b| (pos[a as usize] - pos[b as usize]).length())
                })
                .fold(0.0, f64::max);
            let area = 0.5 * crate::mesh::geometry::area_vector(pos, &face).length();
            let strip = 2.0 * area < STRIP_WIDTH * diameter * diameter
                && crate::mesh::convexity::polygon_is_convex(pos, &face)
                && (0..k).any(|i| {
                    let (sin, opposite) = corner_turn(i);
                    opposite && sin < STRAIGHT_SIN
                });
            let folds = strip
                && normals.is_some_and(|normals| {
                    (0..k).any(|i| {
                        let v = pos[face[i] as usize];
                        let (fan, _) = &fans[i];
                        let m = fan.ring.len();
                        // A vertex with a reflex face corner (beyond rounding: straight ones count)
                        // has a fan gap beyond π by itself (Algorithm 2's hallway corners): no fold.
                        let reflex = (0..fan.faces.len()).any(|j| {
                            let a = pos[fan.ring[j] as usize] - v;
                            let b = pos[fan.ring[(j + 1) % m] as usize] - v;
                            let nf = net.pieces.normal[fan.faces[j] as usize];
                            a.cross(b).dot(nf) < -1e-9 * a.length() * b.length()
                        });
                        if reflex {
                            return false;
                        }
                        // Only nearly flat vertices (fandisk's strips lie within 4° of their
                        // neighbours); sharp vertices keep their fans (the nut's).
                        if !flat_vertex(net, fan, normals.get(face[i] as usize)) {
                            return false;
                        }
                        let Some(n) = normals
                            .get(face[i] as usize)
                            .and_then(|n| n.try_normalize())
                        else {
                            return false;
                        };
                        let (fan, at) = &fans[i];
                        let m = fan.faces.len();
                        let c = |j: usize| net.pieces.center[fan.faces[j % m] as usize] - v;
                        let g = c(*at);
                        ccw(n, c(at + m - 1), g).max(ccw(n, g, c(at + 1))) > FOLD_GAP
                    })
                });
            let misses = normals.is_some_and(|n| diagonal_misses(net, pos, n, &face, &fans));
            let overlapped = mesh
                .face_parent
                .get(f as usize)
                .is_some_and(|p| forced.contains(p));
            if !far && !folds && !misses && !overlapped {
                if let Some(&p) = mesh.face_parent.get(f as usize) {
                    out.eligible.push(p);
                }
                continue;
            }
            let n = net.pieces.normal[own[0] as usize];
            let mean = face.iter().map(|&v| pos[v as usize]).sum::<DVec3>() / k as f64;
            let u = n.any_orthonormal_vector();
            let frame = Frame {
                o: mean,
                u,
                v: n.cross(u),
                n,
            };
            let Some((mut gpos, mut tris)) = place_guards(&frame, pos, &face) else {
                continue;
            };
            if min_angle > 0.0 {
                let flat: Vec<DVec2> = gpos.iter().map(|&g| frame.flat(g)).collect();
                let refined = super::netmesh::refine(&flat, &tris, min_angle);
                gpos.extend(refined.points[k..].iter().map(|&q| frame.lift(q)));
                tris = refined.triangles;
            }
            // Guard pieces: the polygon's own first (every point of T stays used), new ones
            // after; then the net's inner points (pieces of the face too, in no corner's fan).
            let mut guards = Vec::with_capacity(gpos.len());
            for (i, &g) in gpos.iter().enumerate() {
                let g = g - frame.n.dot(g - mean) * frame.n;
                if let Some(&q) = own.get(i) {
                    net.pieces.center[q as usize] = g;
                    net.pieces.guard[q as usize] = true;
                    guards.push(q);
                } else {
                    let q = net.pieces.faces.len() as u32;
                    net.pieces.faces.push(face.clone());
                    net.pieces.parent.push(f);
                    net.pieces.normal.push(n);
                    net.pieces.guard.push(true);
                    net.pieces.center.push(g);
                    net.region.push(r);
                    guards.push(q);
                }
            }
            for &q in &own {
                net.region[q as usize] = r;
            }
            for (i, (&v, (fan, at))) in face.iter().zip(fans).enumerate() {
                let mut fan = fan;
                fan.faces[at] = guards[i];
                net.set_fan(v, fan);
            }
            out.groups.push(FlatGroup {
                piece: own[0],
                face: f,
                corners: face.clone(),
                guards: guards[..k].to_vec(),
                inner: guards[k..].to_vec(),
                triangles: tris.iter().map(|t| t.map(|i| guards[i as usize])).collect(),
            });
            done.insert(f);
        }
        if out.groups.len() == found || normals.is_none() {
            break;
        }
    }
    let netted: BTreeSet<u32> = out
        .groups
        .iter()
        .filter_map(|g| mesh.face_parent.get(g.face as usize).copied())
        .collect();
    out.eligible.sort_unstable();
    out.eligible.dedup();
    out.eligible.retain(|p| !netted.contains(p));
    if out.groups.is_empty() {
        return out;
    }
    // Step (5') cells on the edges of the flat polygons, from the (new) fans.
    let mut edges: Vec<(u32, u32)> = Vec::new();
    for g in &out.groups {
        let k = g.corners.len();
        for i in 0..k {
            let (a, b) = (g.corners[i], g.corners[(i + 1) % k]);
            edges.push((a.min(b), a.max(b)));
        }
    }
    edges.sort_unstable();
    edges.dedup();
    net.cells.retain(|c| {
        let key = (c.v[0].min(c.v[1]), c.v[0].max(c.v[1]));
        edges.binary_search(&key).is_err()
    });
    for (a, b) in edges {
        if let Some(cell) = edge_cell(net, a, b) {
            net.cells.push(cell);
        }
    }
    out
}

/// `fan` with its faces for which `own` holds, when they form one cyclic run, merged into
/// one entry (the ring's vertices inside the run, ends of the diagonals between the pieces of
/// one polygon, dropped), and that entry's index; `None` for no run or several.
fn one_run(fan: &Fan, own: impl Fn(u32) -> bool) -> Option<(Fan, usize)> {
    let k = fan.faces.len();
    let is = |i: usize| own(fan.faces[i % k]);
    let count = (0..k).filter(|&i| is(i)).count();
    if count == 0 || count == k {
        return None;
    }
    if count == 1 {
        return Some((fan.clone(), (0..k).find(|&i| is(i))?));
    }
    // The run's first entry: own, after one that is not; a single run when all `count`
    // entries from there are own.
    let first = (0..k).find(|&i| is(i) && !is(i + k - 1))?;
    if !(first..first + count).all(is) {
        return None;
    }
    // Rotate so the run starts at 0: faces[i] lies between ring[i] and ring[i + 1].
    let faces: Vec<u32> = (0..k).map(|i| fan.faces[(first + i) % k]).collect();
    let ring: Vec<u32> = (0..k).map(|i| fan.ring[(first + i) % k]).collect();
    let mut out_faces = vec![faces[0]];
    out_faces.extend_from_slice(&faces[count..]);
    let mut out_ring = vec![ring[0]];
    out_ring.extend_from_slice(&ring[count..]);
    Some((
        Fan {
            ring: out_ring,
            faces: out_faces,
            closed: true,
        },
        0,
    ))
}

/// True when, at some corner V of `face`, the diagonal from the polygon's point of T named in
/// V's fan to the point of the face across one of V's polygon edges V W passes the edge's line
/// outside the edge (closest points of the two lines: at a share t of V → W outside (0, 1),
/// or beyond either end of the diagonal): Algorithm 1's two triangles
/// over that edge, [C_0(V), G, C'] and [C_0(W), C', G], then fold over each other.
pub fn diagonal_misses(
    net: &GuardNet,
    pos: &[DVec3],
    normals: &[DVec3],
    face: &[u32],
    fans: &[(Fan, usize)],
) -> bool {
    face.iter().zip(fans).any(|(&v, (fan, at))| {
        // Only nearly flat corners, where T's fan lies close to one plane (sharp corners' fans
        // turn round their edges, and the lines' closest points say nothing about a fold).
        if !flat_vertex(net, fan, normals.get(v as usize)) {
            return false;
        }
        let m = fan.faces.len();
        let g = net.pieces.center[fan.faces[*at] as usize];
        let a = pos[v as usize];
        [
            (fan.ring[*at], fan.faces[(at + m - 1) % m]),
            (fan.ring[(at + 1) % m], fan.faces[(at + 1) % m]),
        ]
        .into_iter()
        .any(|(w, other)| {
            let c = net.pieces.center[other as usize];
            let (d1, d2, r) = (pos[w as usize] - a, c - g, a - g);
            let (a11, a12, a22) = (d1.dot(d1), d1.dot(d2), d2.dot(d2));
            let (b1, b2) = (d1.dot(r), d2.dot(r));
            let det = a11 * a22 - a12 * a12;
            if det <= 1e-12 * a11 * a22 {
                return false; // parallel lines: no crossing to judge
            }
            let t = (a12 * b2 - a22 * b1) / det;
            let s = (a11 * b2 - a12 * b1) / det;
            t <= 0.0 || t >= 1.0 || s <= 0.0 || s >= 1.0
        })
    })
}

/// True when every piece round a vertex (its `fan`) faces within `FLAT_VERTEX_COS` of the
/// vertex normal `n`: the vertex is nearly flat, so T's fan there lies close to one plane.
fn flat_vertex(net: &GuardNet, fan: &Fan, n: Option<&DVec3>) -> bool {
    n.is_some_and(|n| {
        let n = n.normalize_or_zero();
        fan.faces
            .iter()
            .all(|&g| net.pieces.normal[g as usize].dot(n) > FLAT_VERTEX_COS)
    })
}

/// The step (5') cell on polygon edge {a, b} from the fans of a and b: V_1 → V_2 runs
/// counter-clockwise in f_1. `None` when the guards agree on both sides (no cell needed) or a
/// fan does not hold the edge.
pub(crate) fn edge_cell(net: &GuardNet, a: u32, b: u32) -> Option<EdgeCell> {
    let fa = net.fan(a)?;
    let fb = net.fan(b)?;
    let k = fa.faces.len();
    let l = fb.faces.len();
    // In a's fan, face[i] lies between ring[i] and ring[i + 1] (counter-clockwise round a):
    // the face with ring[i] = b holds a → b counter-clockwise (it is f_1 for V_1 = a).
    let i = fa.ring.iter().position(|&w| w == b)?;
    let j = fb.ring.iter().position(|&w| w == a)?;
    // f_1 (a → b) at a: faces[i]; at b: the face before the one holding b → a, faces[j − 1].
    // f_2 (b → a) at a: faces[i − 1]; at b: faces[j].
    let g = [
        fa.faces[i],
        fb.faces[(j + l - 1) % l],
        fa.faces[(i + k - 1) % k],
        fb.faces[j],
    ];
    (g[0] != g[1] || g[2] != g[3]).then_some(EdgeCell { v: [a, b], g })
}

/// Guards of the polygon's corners (3D, in its plane) and the Delaunay triangulation of the
/// guard polygon (indices of corners), or `None` when no radius works.
#[allow(clippy::type_complexity)]
fn place_guards(frame: &Frame, pos: &[DVec3], face: &[u32]) -> Option<(Vec<DVec3>, Vec<[u32; 3]>)> {
    let k = face.len();
    let flat: Vec<DVec2> = face.iter().map(|&v| frame.flat(pos[v as usize])).collect();
    if polygon_area(&flat) <= 0.0 {
        return None;
    }
    let boundary: Vec<(DVec2, DVec2)> = (0..k).map(|i| (flat[i], flat[(i + 1) % k])).collect();
    let mut guards = Vec::with_capacity(k);
    for i in 0..k {
        let (u, v, w) = (flat[(i + k - 1) % k], flat[i], flat[(i + 1) % k]);
        let (du, dw) = ((u - v).normalize(), (w - v).normalize());
        // Interior bisector: the interior lies to the left of v → w, so rotate dw by half the
        // interior angle counter-clockwise.
        let angle = {
            let a = dw.angle_to(du); // counter-clockwise from dw to du, in (−π, π]
            if a <= 0.0 {
                a + std::f64::consts::TAU
            } else {
                a
            }
        };
        let half = 0.5 * angle;
        let dir = DVec2::new(
            dw.x * half.cos() - dw.y * half.sin(),
            dw.x * half.sin() + dw.y * half.cos(),
        );
        // The corner's reach: its shorter edge, and across a narrow strip the distance to the
        // nearest edge not at v (fandisk's face 1313, 0.019 wide with edges of 0.08 at its
        // straight corners: guards a quarter edge in from both sides met in the middle).
        let across = boundary
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != i && (j + 1) % k != i)
            .map(|(_, &(a, b))| point_segment_distance(v, a, b))
            .fold(f64::INFINITY, f64::min);
        let reach = (u - v).length().min((w - v).length()).min(across);
        let mut r = GUARD_RADIUS * reach;
        let mut found = None;
        for _ in 0..12 {
            let g = v + r * dir;
            if sees_corner(g, u, v, w, &flat, &boundary) {
                found = Some(g);
                break;
            }
            r *= 0.5;
        }
        guards.push(found?);
    }
    // The guard polygon: simple, its edges crossing no polygon edge.
    for i in 0..k {
        let (p, q) = (guards[i], guards[(i + 1) % k]);
        if crosses(p, q, &boundary) {
            return None;
        }
        for j in 0..k {
            if j == i || j == (i + 1) % k || (j + 1) % k == i {
                continue;
            }
            let (a, b) = (guards[j], guards[(j + 1) % k]);
            if segments_cross(p, q, a, b) {
                return None;
            }
        }
    }
    if polygon_area(&guards) <= 0.0 {
        return None;
    }
    let g3: Vec<DVec3> = guards.iter().map(|&g| frame.lift(g)).collect();
    let ids: Vec<u32> = (0..k as u32).collect();
    let mut scratch = Vec::new();
    let mut tris = Vec::new();
    ear_clip(&g3, &ids, &mut scratch, &mut tris);
    if tris.len() != k - 2 {
        return None;
    }
    let mut tris: Vec<[u32; 3]> = tris.iter().map(|t| [t[0], t[1], t[2]]).collect();
    // Same orientation as the polygon (counter-clockwise about its normal).
    for t in &mut tris {
        let [a, b, c] = t.map(|i| guards[i as usize]);
        if (b - a).perp_dot(c - a) < 0.0 {
            t.swap(1, 2);
        }
    }
    delaunay_flips(&guards, &mut tris);
    Some((g3, tris))
}

/// True when guard `g` of corner v (edges u → v → w) sees both edges: g lies strictly inside
/// the corner's wedge, and the triangles g v u, g v w hold no other corner and their sides
/// from g cross no polygon edge.
pub(crate) fn sees_corner(
    g: DVec2,
    u: DVec2,
    v: DVec2,
    w: DVec2,
    flat: &[DVec2],
    boundary: &[(DVec2, DVec2)],
) -> bool {
    // Left of v → w and left of u → v (inside both edges' half-planes near v).
    if (w - v).perp_dot(g - v) <= 0.0 || (v - u).perp_dot(g - u) <= 0.0 {
        return false;
    }
    for q in [u, v, w] {
        if crosses(g, q, boundary) {
            return false;
        }
    }
    for t in [[g, v, u], [g, v, w]] {
        if flat
            .iter()
            .any(|&a| a != u && a != v && a != w && inside_closed(t, a))
        {
            return false;
        }
    }
    true
}

/// Distance from `p` to the segment a–b.
fn point_segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + t * d - p).length()
}

/// True when segment p–q properly crosses a boundary edge (shared endpoints do not count).
pub(crate) fn crosses(p: DVec2, q: DVec2, boundary: &[(DVec2, DVec2)]) -> bool {
    boundary
        .iter()
        .any(|&(a, b)| a != p && a != q && b != p && b != q && segments_cross(p, q, a, b))
}

/// True when segments p–q and a–b cross or touch (an endpoint of one on the other counts, so
/// guard polygons keep clear of each other and of the polygon).
fn segments_cross(p: DVec2, q: DVec2, a: DVec2, b: DVec2) -> bool {
    let o = |x: DVec2, y: DVec2, z: DVec2| (y - x).perp_dot(z - x);
    let (d1, d2) = (o(p, q, a), o(p, q, b));
    let (d3, d4) = (o(a, b, p), o(a, b, q));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    let on = |x: DVec2, y: DVec2, z: DVec2, d: f64| {
        d == 0.0 && (z - x).dot(z - y) <= 0.0 // z on segment x–y
    };
    on(p, q, a, d1) || on(p, q, b, d2) || on(a, b, p, d3) || on(a, b, q, d4)
}

/// True when x lies in the closed triangle t (either orientation).
fn inside_closed(t: [DVec2; 3], x: DVec2) -> bool {
    let s: Vec<f64> = (0..3)
        .map(|i| (t[(i + 1) % 3] - t[i]).perp_dot(x - t[i]))
        .collect();
    s.iter().all(|&v| v >= 0.0) || s.iter().all(|&v| v <= 0.0)
}

/// Lawson's flips: an interior edge whose two triangles form a convex quadrilateral is flipped
/// when the opposite angles sum to more than π (the empty-circle test), until none is; the
/// triangulation of a polygon becomes its constrained Delaunay triangulation.
fn delaunay_flips(p: &[DVec2], tris: &mut [[u32; 3]]) {
    let in_circle = |a: DVec2, b: DVec2, c: DVec2, d: DVec2| -> bool {
        // d strictly inside the circle through the counter-clockwise a, b, c.
        let (ad, bd, cd) = (a - d, b - d, c - d);
        let det = (ad.length_squared()) * bd.perp_dot(cd) - (bd.length_squared()) * ad.perp_dot(cd)
            + (cd.length_squared()) * ad.perp_dot(bd);
        let scale = ad
            .length_squared()
            .max(bd.length_squared())
            .max(cd.length_squared());
        det > 1e-12 * scale * scale
    };
    for _ in 0..(4 * tris.len() * tris.len()).max(16) {
        let mut owner: HashMap<(u32, u32), (usize, usize)> = HashMap::new();
        for (t, tri) in tris.iter().enumerate() {
            for e in 0..3 {
                owner.insert((tri[e], tri[(e + 1) % 3]), (t, e));
            }
        }
        let mut flipped = false;
        for (t, e) in (0..tris.len()).flat_map(|t| (0..3).map(move |e| (t, e))) {
            let tri = tris[t];
            let (a, b, c) = (tri[e], tri[(e + 1) % 3], tri[(e + 2) % 3]);
            let Some(&(s, f)) = owner.get(&(b, a)) else {
                continue;
            };
            let d = tris[s][(f + 2) % 3];
            let (pa, pb, pc, pd) = (p[a as usize], p[b as usize], p[c as usize], p[d as usize]);
            // Convex quadrilateral a d b c: the new diagonal c–d must separate a and b.
            let convex = (pd - pc).perp_dot(pa - pc) < 0.0 && (pd - pc).perp_dot(pb - pc) > 0.0;
            if convex && in_circle(pa, pb, pc, pd) {
                tris[t] = [c, a, d];
                tris[s] = [d, b, c];
                flipped = true;
                break;
            }
        }
        if !flipped {
            return;
        }
    }
}

impl FlatNets {
    /// Appends the zero coplanar groups' triangles to `hull` (whose points include the guards)
    /// with an L-U pair of face tetrahedra each, apexes over the centroid (drawn towards the
    /// guard polygon, [`BOUNDARY_PULL`]) at [`FLAT_HEIGHT`]
    /// of its width on both sides; `element` is the polygon's first corner.
    pub fn add_triangles(&self, hull: &mut SimplicialHull) {
        for g in &self.groups {
            let k = g.guards.len();
            let boundary: Vec<(u32, u32)> = (0..k)
                .map(|i| (g.guards[i], g.guards[(i + 1) % k]))
                .collect();
            for &tri in &g.triangles {
                let [a, b, c] = tri.map(|i| hull.points[i as usize]);
                let Some(n) = (b - a).cross(c - a).try_normalize() else {
                    continue;
                };
                let len = (b - a).length().max((c - b).length()).max((a - c).length());
                let width = (b - a).cross(c - a).length() / len;
                // Over the base, drawn towards its edges on the guard polygon (module docs).
                let mut w = [1.0; 3];
                for e in 0..3 {
                    if boundary.contains(&(tri[e], tri[(e + 1) % 3])) {
                        w[e] += BOUNDARY_PULL;
                        w[(e + 1) % 3] += BOUNDARY_PULL;
                    }
                }
                let m = (w[0] * a + w[1] * b + w[2] * c) / (w[0] + w[1] + w[2]);
                let h = FLAT_HEIGHT * width;
                hull.triangles.push(tri);
                hull.apexes.push([Some(m + h * n), Some(m - h * n)]);
                hull.element.push(g.corners[0]);
            }
        }
        debug_assert!(self.groups.iter().all(|g| g
            .guards
            .iter()
            .chain(&g.inner)
            .all(|&q| matches!(hull.origins[q as usize], PointOrigin::CornerGuard { .. }))));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A corner whose polygon is split into pieces 10, 11, 12 (faces between ring vertices,
    /// the pieces' diagonals ending at ring vertices 3 and 4) gets one entry for the polygon
    /// between the run's outer ring vertices; the other faces keep their neighbours. One piece
    /// alone leaves the fan as it is; pieces in two runs, or none, give no fan.
    #[test]
    fn a_run_of_pieces_becomes_one_entry() {
        // faces[i] lies between ring[i] and ring[i + 1] (cyclically).
        let fan = Fan {
            ring: vec![1, 2, 3, 4, 5, 6],
            faces: vec![7, 10, 11, 12, 8, 9],
            closed: true,
        };
        let (one, at) = one_run(&fan, |q| q >= 10).unwrap();
        assert_eq!(one.faces[at], 10);
        assert_eq!(one.faces, vec![10, 8, 9, 7]);
        // 10 lies between 2 and 5, as pieces 10–12 did together.
        assert_eq!(one.ring, vec![2, 5, 6, 1]);
        assert!(one.closed);
        // The run may wrap round the fan's start.
        let wrapped = Fan {
            ring: vec![1, 2, 3, 4, 5],
            faces: vec![11, 7, 8, 9, 10],
            closed: true,
        };
        let (one, at) = one_run(&wrapped, |q| q >= 10).unwrap();
        assert_eq!(
            (one.faces.clone(), one.ring.clone(), at),
            (vec![10, 7, 8, 9], vec![5, 2, 3, 4], 0)
        );
        let (same, at) = one_run(&fan, |q| q == 11).unwrap();
        assert_eq!(
            (same.faces, same.ring, at),
            (fan.faces.clone(), fan.ring.clone(), 2)
        );
        assert!(one_run(&fan, |q| q == 10 || q == 11 || q == 7).is_some());
        assert!(one_run(&fan, |q| q == 10 || q == 12).is_none());
        assert!(one_run(&fan, |q| q > 100).is_none());
    }

    /// A strip 0.02 wide with straight corners whose edges are four times its width (fandisk's
    /// face 1313): a quarter of the shorter edge reaches across the strip, so the guards of two
    /// opposite straight corners met in the middle and the guard polygon was not simple. With
    /// the reach capped by the distance to the opposite edge, every guard lies within a quarter
    /// of the strip's width from its corner and the guard polygon is triangulated.
    #[test]
    fn thin_strip_guards_stay_on_their_side() {
        // Bottom edge 0 → 0.16 with straight corners at 0.08; top edge with straight corners at
        // 0.04 and 0.12, counter-clockwise seen from +z.
        let pts = [
            (0.0, 0.0),
            (0.08, 0.0),
            (0.16, 0.0),
            (0.16, 0.02),
            (0.12, 0.02),
            (0.04, 0.02),
            (0.0, 0.02),
        ];
        let pos: Vec<DVec3> = pts.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
        let face: Vec<u32> = (0..pos.len() as u32).collect();
        let frame = Frame {
            o: DVec3::ZERO,
            u: DVec3::X,
            v: DVec3::Y,
            n: DVec3::Z,
        };
        let (guards, tris) = place_guards(&frame, &pos, &face).expect("guards placed");
        assert_eq!(tris.len(), face.len() - 2);
        for (g, p) in guards.iter().zip(&pos) {
            // A quarter of the width 0.02 (bisector of a corner of 90° or 180°), plus rounding.
            assert!((*g - *p).length() <= 0.25 * 0.02 + 1e-12, "{g} from {p}");
            assert!(g.y > 0.0 && g.y < 0.02, "{g} inside the strip");
        }
    }

    /// `point_segment_distance` against hand values: perpendicular foot inside, ends outside.
    #[test]
    fn point_segment_distance_cases() {
        let (a, b) = (DVec2::new(0.0, 0.0), DVec2::new(2.0, 0.0));
        assert_eq!(point_segment_distance(DVec2::new(1.0, 3.0), a, b), 3.0);
        assert_eq!(point_segment_distance(DVec2::new(5.0, 4.0), a, b), 5.0);
        assert_eq!(point_segment_distance(DVec2::new(-3.0, 0.0), a, b), 3.0);
    }
}
