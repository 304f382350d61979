//! Corner guard nets (Algorithm 2 step (1)) and the face tetrahedra between them (step (5')).
//!
//! A *region* is one face of the polyhedron as Algorithm 2 sees it: a non-convex polygon that is
//! not star shaped, or a group of edge-adjacent coplanar faces that [`super::coplanar`] could
//! not merge into one polygon (letter_P's caps are annuli: a P with a hole). Its convex pieces
//! (Hertel–Mehlhorn, [`super::decompose`]) carry the candidate corner guards. Every boundary
//! corner of the region (a vertex V with the two region edges at V) is given ONE guard that
//! sees the whole corner (Definition 2.5: both region edges at V visible), even where the
//! corner is split between pieces; the diagonals between pieces are then no edges of the
//! polyhedron at all, so V keeps one face entry per region in its fan (a reflex corner of the
//! region stays one reflex corner: trihedral V becomes Algorithm 2's hallway corner (3')).
//!
//! Reconstruction of Figure 5.6 (step (5')): for a region edge V_1V_2 between faces f_1, f_2,
//! with guards G_1 = g(V_1, f_1), G_2 = g(V_2, f_1), G_3 = g(V_1, f_2), G_4 = g(V_2, f_2), the
//! cell between V_1's triangle (which holds the edge G_1G_3) and V_2's (G_2G_4) is the
//! quadrilateral G_1G_3G_4G_2, cut by the diagonal G_2G_3 into [G_1G_3G_2] and [G_3G_4G_2];
//! their apexes H_0, H_1 lie halfway between the midpoint M of V_1V_2 and the apexes of the
//! face tetrahedra sharing G_1G_3 (V_1's) and G_2G_4 (V_2's). When G_1 = G_2 (or G_3 = G_4) the
//! cell is one triangle with apex M. Beyond the paper: that apex is moved out of the
//! polyhedron ([`CELL_LIFT`]; with M itself the edge tetrahedra over a net edge, between two
//! such cells, are flat; over a concave edge into it, and the two-triangle cell's apexes with
//! it, so that no apex lies on both faces' planes) and slid along V_1V_2 so that the midpoint
//! s of the two apexes over a net edge lies over that edge (else the cubic scheme cannot make
//! those edge tetrahedra single sheeted: letter_P showed a spurious sheet). The guard net of a
//! region is the set of guard pairs these cells use; T is a closed manifold when every pair is
//! walked once in each direction round the region's boundary loops, which the guard
//! assignment ([`GuardNet::build`]) searches for.
//!
//! Guards are placed (Appendix B's corner guard circles: any point of a region works) at the
//! centroid of their piece's kernel clipped by the inner half-planes of both region edges of
//! every corner they guard; each corner's two triangles to its guard and each net segment are
//! checked to stay inside the region. Where no assignment is found (search budget, a pinched
//! region), the region falls back to its convex pieces as separate faces (Algorithm 1 on them).

use super::coplanar;
use super::decompose::{kernel_region, merge_convex, polygon_area, Pieces, MIN_KERNEL_AREA};
use crate::hull::simplicial::{Side, SimplicialHull};
use crate::mesh::{Fan, Mesh, Topology};
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// Largest number of complete guard assignments visited per region (the backtracking prunes
/// by the pair counts); the best valid one found by then is used.
pub const SEARCH_BUDGET: usize = 200_000;

/// How far the apex of a one-triangle cell moves out of the polyhedron, as a fraction of the
/// single guard's distance from the edge line (see [`GuardNet::add_edge_cells`]). On letter_P,
/// 0.05 left six edge tetrahedra over net edges with weights of both signs even with the apexes
/// slid; 0.2 leaves none (`tests/suite/inner_guardnet.rs`).
pub const CELL_LIFT: f64 = 0.2;

/// A step (5') cell: region edge V_1V_2 and its four guards (points of T).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeCell {
    /// V_1, V_2 (input vertices), V_1 → V_2 running counter-clockwise in face f_1.
    pub v: [u32; 2],
    /// G_1 = g(V_1, f_1), G_2 = g(V_2, f_1), G_3 = g(V_1, f_2), G_4 = g(V_2, f_2).
    pub g: [u32; 4],
}

/// The faces Algorithm 2 runs on: pieces (one point of T each), their regions, the vertex fans
/// over regions and the step (5') cells.
pub struct GuardNet {
    /// Convex (or star-shaped) pieces; piece i is point i of T.
    pub pieces: Pieces,
    /// Topology of the pieces.
    pub topo: Topology,
    /// Region of every piece.
    pub region: Vec<u32>,
    /// Vertex fans over regions where they differ from the pieces' fans.
    fans: HashMap<u32, Fan>,
    /// Vertices inside a region (all their pieces in one region): no corner, no triangles.
    inside: Vec<bool>,
    /// Step (5') cells.
    pub cells: Vec<EdgeCell>,
    /// Regions with a corner guard net: (input polygon of their first piece, pieces, guards used).
    pub nets: Vec<(u32, usize, usize)>,
    /// Regions where no guard assignment was found and the pieces stay separate faces.
    pub fallback: Vec<u32>,
    /// Those regions' groups (first original piece), for the second pass of [`GuardNet::build`].
    failed: Vec<usize>,
    /// Corners on a straight edge between two flat nets (`InnerOptions::straight_corners`):
    /// no corner triangles; the step (5') cells on their edges stand in for them.
    pub straight: std::collections::BTreeSet<u32>,
}

/// One boundary corner of a region.
#[derive(Clone, Debug)]
struct RegionCorner {
    v: u32,
    /// Incoming region edge U → V and outgoing V → W.
    u: u32,
    w: u32,
    /// Pieces of the region at V (candidate guards).
    cands: Vec<u32>,
}

impl GuardNet {
    /// Regions of `pieces` (pieces of one split polygon, or coplanar edge-adjacent pieces),
    /// coplanar regions re-merged into convex pieces, and a guard per region corner.
    /// A region without a guard assignment keeps its original pieces (not re-merged) as
    /// separate faces, as before guard nets.
    #[must_use]
    pub fn build(mesh: &Mesh, pieces: Pieces) -> GuardNet {
        let mut first = GuardNet::build_skipping(mesh, pieces.clone(), &[]);
        if first.failed.is_empty() {
            return first;
        }
        // Star faces split only because their kernel guard was far keep that guard when no net
        // is found: separate coplanar pieces are worse (fandisk's face 1912: flat T, C1 broke).
        let restore: Vec<u32> = first
            .fallback
            .iter()
            .copied()
            .filter(|f| pieces.far_star.iter().any(|&(g, _)| g == *f))
            .collect();
        let pieces = if restore.is_empty() {
            pieces
        } else {
            let restored = pieces.restore_stars(mesh, &restore);
            first = GuardNet::build_skipping(mesh, restored.clone(), &[]);
            if first.failed.is_empty() {
                return first;
            }
            restored
        };
        let failed = first.failed.clone();
        let mut second = GuardNet::build_skipping(mesh, pieces, &failed);
        second.fallback = first.fallback;
        second
    }

    /// [`GuardNet::build`] with the groups whose first original piece is in `skip` left as
    /// separate faces.
    fn build_skipping(mesh: &Mesh, mut pieces: Pieces, skip: &[usize]) -> GuardNet {
        let nv = mesh.positions.len();
        let pos = &mesh.positions;
        // 1. Regions by union-find.
        let np = pieces.faces.len();
        let mut parent: Vec<usize> = (0..np).collect();
        fn root(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        let directed = directed_edges(&pieces.faces);
        let mut keys: Vec<_> = directed.keys().copied().collect();
        keys.sort_unstable();
        for (a, b) in keys {
            let (p, Some(&q)) = (directed[&(a, b)], directed.get(&(b, a))) else {
                continue;
            };
            let (p, q) = (p as usize, q as usize);
            let same = pieces.parent[p] == pieces.parent[q]
                || coplanar::same_plane(
                    pos,
                    &pieces.faces[p],
                    pieces.normal[p],
                    &pieces.faces[q],
                    pieces.normal[q],
                );
            if same {
                let (rp, rq) = (root(&mut parent, p), root(&mut parent, q));
                if rp != rq {
                    parent[rp.max(rq)] = rp.min(rq);
                }
            }
        }
        // 2. Re-merge coplanar groups into convex pieces; new piece order by region.
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut group_of: HashMap<usize, usize> = HashMap::new();
        for p in 0..np {
            let r = root(&mut parent, p);
            let g = *group_of.entry(r).or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
            groups[g].push(p);
        }
        let mut out = Pieces {
            split: pieces.split.clone(),
            star: pieces.star.clone(),
            ..Pieces::default()
        };
        let mut region = Vec::new();
        for (g, members) in groups.iter().enumerate() {
            let first = members[0];
            let multi_parent = members
                .iter()
                .any(|&p| pieces.parent[p] != pieces.parent[first]);
            let polys: Vec<Vec<u32>> = if multi_parent
                && !skip.contains(&first)
                && members.iter().all(|&p| !is_star_only(&pieces, p))
            {
                merge_convex(
                    pos,
                    pieces.normal[first],
                    members.iter().map(|&p| pieces.faces[p].clone()).collect(),
                )
            } else {
                members.iter().map(|&p| pieces.faces[p].clone()).collect()
            };
            let merged = polys.len() != members.len();
            for (k, poly) in polys.into_iter().enumerate() {
                let src = if merged { first } else { members[k] };
                let c = poly.iter().map(|&v| pos[v as usize]).sum::<DVec3>() / poly.len() as f64;
                let n = pieces.normal[first];
                let center = if merged {
                    c - n.dot(c - pieces.center[first]) * n
                } else {
                    pieces.center[src]
                };
                out.faces.push(poly);
                out.parent.push(pieces.parent[src]);
                out.normal.push(pieces.normal[first]);
                out.guard.push(pieces.guard[src] || members.len() > 1);
                out.center.push(center);
                region.push(g as u32);
            }
        }
        pieces = out;
        let topo = Topology::new(nv, &pieces.faces);
        let nr = groups.len();
        let mut region_pieces: Vec<Vec<u32>> = vec![Vec::new(); nr];
        for (p, &r) in region.iter().enumerate() {
            region_pieces[r as usize].push(p as u32);
        }

        // 3. Corners of multi-piece regions, from the pieces' vertex fans.
        let mut corners: Vec<Vec<RegionCorner>> = vec![Vec::new(); nr];
        let mut pinched = vec![false; nr];
        let mut fans: Vec<Option<Fan>> = Vec::with_capacity(nv);
        for v in 0..nv as u32 {
            let fan = topo.vertex_fan(v).filter(|f| f.closed);
            if let Some(f) = &fan {
                for (r, i, j) in runs(&f.faces, &region) {
                    if region_pieces[r as usize].len() < 2 || i == usize::MAX {
                        continue;
                    }
                    let k = f.faces.len();
                    let mut cands: Vec<u32> = (i..=j).map(|x| f.faces[x % k]).collect();
                    cands.sort_unstable();
                    cands.dedup();
                    if corners[r as usize].iter().any(|c| c.v == v) {
                        pinched[r as usize] = true;
                    }
                    corners[r as usize].push(RegionCorner {
                        v,
                        u: f.ring[(j + 1) % k],
                        w: f.ring[i % k],
                        cands,
                    });
                }
            }
            fans.push(fan);
        }

        // 4. Guard assignment per multi-piece region.
        let mut guard_of: HashMap<(u32, u32), u32> = HashMap::new();
        let mut nets = Vec::new();
        let mut fallback = Vec::new();
        let mut failed = Vec::new();
        let mut next_region = nr as u32;
        for r in 0..nr {
            if region_pieces[r].len() < 2 {
                continue;
            }
            let found = if pinched[r] || corners[r].is_empty() || skip.contains(&groups[r][0]) {
                None
            } else {
                assign(pos, &pieces, &region_pieces[r], &corners[r])
            };
            match found {
                Some((assignment, centers)) => {
                    for (c, &g) in corners[r].iter().zip(&assignment) {
                        guard_of.insert((c.v, r as u32), g);
                    }
                    for (p, g) in centers {
                        // Exactly in the plane of the piece's own polygon (a coplanar group's
                        // polygons agree only within the coplanarity tolerance).
                        let p = p as usize;
                        let face = &mesh.faces[pieces.parent[p] as usize];
                        let mean = face.iter().map(|&v| pos[v as usize]).sum::<DVec3>()
                            / face.len() as f64;
                        let n = pieces.normal[p];
                        pieces.center[p] = g - n.dot(g - mean) * n;
                    }
                    let mut used = assignment.clone();
                    used.sort_unstable();
                    used.dedup();
                    nets.push((
                        pieces.parent[region_pieces[r][0] as usize],
                        region_pieces[r].len(),
                        used.len(),
                    ));
                }
                None => {
                    if !skip.contains(&groups[r][0]) {
                        failed.push(groups[r][0]);
                    }
                    fallback.push(pieces.parent[region_pieces[r][0] as usize]);
                    for &p in &region_pieces[r] {
                        region[p as usize] = next_region;
                        next_region += 1;
                    }
                }
            }
        }

        // 5. Fans over regions.
        let mut collapsed = HashMap::new();
        let mut inside = vec![false; nv];
        for (v, fan) in fans.iter().enumerate() {
            let Some(f) = fan else { continue };
            let rs = runs(&f.faces, &region);
            if rs.len() == f.faces.len() {
                continue; // every piece its own region
            }
            if rs.len() == 1 && rs[0].1 == usize::MAX {
                inside[v] = true;
                continue;
            }
            let k = f.faces.len();
            let mut faces = Vec::with_capacity(rs.len());
            let mut ring = Vec::with_capacity(rs.len());
            for &(r, i, _) in &rs {
                let g = guard_of
                    .get(&(v as u32, r))
                    .copied()
                    .unwrap_or(f.faces[i % k]);
                faces.push(g);
                ring.push(f.ring[i % k]);
            }
            collapsed.insert(
                v as u32,
                Fan {
                    ring,
                    faces,
                    closed: true,
                },
            );
        }

        // 6. Step (5') cells on region edges with a guard change on either side.
        let mut cells = Vec::new();
        let g = |v: u32, piece: u32| -> u32 {
            guard_of
                .get(&(v, region[piece as usize]))
                .copied()
                .unwrap_or(piece)
        };
        let directed = directed_edges(&pieces.faces);
        let mut edges: Vec<_> = directed.keys().copied().collect();
        edges.sort_unstable();
        for (a, b) in edges {
            if a > b {
                continue;
            }
            let (p1, Some(&p2)) = (directed[&(a, b)], directed.get(&(b, a))) else {
                continue;
            };
            if region[p1 as usize] == region[p2 as usize] {
                continue;
            }
            let gs = [g(a, p1), g(b, p1), g(a, p2), g(b, p2)];
            if gs[0] != gs[1] || gs[2] != gs[3] {
                cells.push(EdgeCell { v: [a, b], g: gs });
            }
        }
        GuardNet {
            pieces,
            topo,
            region,
            fans: collapsed,
            inside,
            cells,
            nets,
            fallback,
            failed,
            straight: std::collections::BTreeSet::new(),
        }
    }

    /// The fan of `v` over regions (faces = points of T), or the pieces' fan.
    #[must_use]
    pub fn fan(&self, v: u32) -> Option<Fan> {
        self.fans
            .get(&v)
            .cloned()
            .or_else(|| self.topo.vertex_fan(v))
    }

    /// Replaces the fan of `v` over regions ([`super::flatnet`]: a flat polygon's corner
    /// names its own guard).
    pub fn set_fan(&mut self, v: u32, fan: Fan) {
        self.fans.insert(v, fan);
    }

    /// True when `v` lies inside one region (no corner there).
    #[must_use]
    pub fn inside(&self, v: u32) -> bool {
        self.inside.get(v as usize).copied().unwrap_or(false)
    }

    /// Step (5'): appends the cells' triangles of T and their face tetrahedra to `hull`, whose
    /// vertex triangles (steps (3), (3'), (4), (5)) are already built.
    pub fn add_edge_cells(&self, hull: &mut SimplicialHull, positions: &[DVec3]) {
        let mut owner: HashMap<(u32, u32), usize> = HashMap::new();
        for (t, tri) in hull.triangles.iter().enumerate() {
            for k in 0..3 {
                owner.insert((tri[k], tri[(k + 1) % 3]), t);
            }
        }
        let slide = self.cell_slides(hull, positions);
        for (ci, cell) in self.cells.iter().enumerate() {
            let [g1, g2, g3, g4] = cell.g;
            let m = 0.5 * (positions[cell.v[0] as usize] + positions[cell.v[1] as usize]);
            let apexes_of = |key: (u32, u32)| -> Vec<DVec3> {
                owner
                    .get(&key)
                    .map(|&t| hull.apexes[t].iter().flatten().copied().collect())
                    .unwrap_or_default()
            };
            // V_1's triangle holds G_3 → G_1, V_2's holds G_2 → G_4. A straight corner has no
            // triangle: its apex is the corner itself, as a trihedral corner's (Algorithm 1
            // step (3)), so the cells on either side of it share their edge tetrahedra's
            // point s on the edge.
            let corner_apexes = |key: (u32, u32), v: u32| -> Vec<DVec3> {
                if self.straight.contains(&v) {
                    vec![positions[v as usize]]
                } else {
                    apexes_of(key)
                }
            };
            let q1 = corner_apexes((g3, g1), cell.v[0]);
            let q2 = corner_apexes((g2, g4), cell.v[1]);
            let lifted = |g: u32| -> DVec3 {
                let v1 = positions[cell.v[0] as usize];
                v1 + slide[ci] * (positions[cell.v[1] as usize] - v1)
                    + cell_lift(hull, positions, cell, g)
            };
            let single = if g1 == g2 {
                Some(lifted(g1))
            } else if g3 == g4 {
                Some(lifted(g3))
            } else {
                None
            };
            // Over a concave edge the two-triangle cell's apexes go into the polyhedron as a
            // one-triangle cell's do (`cell_lift`): the corner triangles' apexes can lie on the
            // edge itself (a trihedral corner's apex at V), and their midpoints with M then lie
            // in both tangent planes.
            let inward = if cell_concave(hull, positions, cell) {
                cell_lift(hull, positions, cell, g2)
            } else {
                DVec3::ZERO
            };
            let mut push = |tri: [u32; 3], apexes: Vec<DVec3>| {
                let [a, b, c] = tri.map(|i| hull.points[i as usize]);
                let mut slot = [None, None];
                for q in apexes {
                    let o = (b - a).cross(c - a).dot(q - a);
                    let side = if o > 0.0 { Side::Outer } else { Side::Inner };
                    slot[side as usize] = Some(q);
                }
                hull.triangles.push(tri);
                hull.apexes.push(slot);
                hull.element.push(cell.v[0]);
            };
            let half = |qs: &[DVec3]| -> Vec<DVec3> {
                qs.iter().map(|&q| 0.5 * (q + m) + inward).collect()
            };
            // One triangle: apex on V_1V_2 (M, or where `cell_slides` puts it), moved out of
            // (over a concave edge: into) the polyhedron along the bisector of the two faces'
            // normals by CELL_LIFT of the single guard's distance from the edge (at most
            // CELL_LIFT_REACH edge lengths).
            // The edge lies in both face planes (the guards' tangent planes); moved outwards
            // the apex stays tangent-containing (the triangle's points are on the planes'
            // inner sides or on them). With M itself, the edge tetrahedra between two such cells over one net
            // edge are flat (all in the face plane); moved inwards, they fold over the cells.
            if g1 == g2 {
                push([g1, g3, g4], single.into_iter().collect());
            } else if g3 == g4 {
                push([g1, g3, g2], single.into_iter().collect());
            } else {
                push([g1, g3, g2], half(&q1));
                push([g3, g4, g2], half(&q2));
            }
        }
    }
}

impl GuardNet {
    /// Where along its edge V_1V_2 (parameter from V_1) each one-triangle cell's apex sits.
    /// The two one-triangle cells on either side of a net edge G_aG_b give the edge tetrahedra
    /// over it their midpoint s. The cubic scheme can make those tetrahedra single sheeted only
    /// when s lies on the apex's side of each cell's triangle (its barycentric β_q > 0), which
    /// holds when s lies over the net edge itself; with both apexes over their edges' midpoints
    /// s can fall far beside it (letter_P: beside the hole's right corner). So the pair is slid
    /// along its edges (within [¼, ¾]) to bring s over the line G_aG_b, as near its middle as
    /// the edges allow (least squares, then clamped). Other cells keep ½.
    fn cell_slides(&self, hull: &SimplicialHull, positions: &[DVec3]) -> Vec<f64> {
        let mut slide = vec![0.5; self.cells.len()];
        let mut owner: HashMap<(u32, u32), usize> = HashMap::new();
        for (t, tri) in hull.triangles.iter().enumerate() {
            for k in 0..3 {
                owner.insert((tri[k], tri[(k + 1) % 3]), t);
            }
        }
        let mut by_pair: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (ci, c) in self.cells.iter().enumerate() {
            let [g1, g2, g3, g4] = c.g;
            let pair = if g1 == g2 {
                (g3, g4)
            } else if g3 == g4 {
                (g1, g2)
            } else {
                continue;
            };
            by_pair
                .entry((pair.0.min(pair.1), pair.0.max(pair.1)))
                .or_default()
                .push(ci);
        }
        for (&(ga, gb), cs) in &by_pair {
            let [c1, c2] = cs[..] else { continue };
            let start = |ci: usize| {
                let c = &self.cells[ci];
                let single = if c.g[0] == c.g[1] { c.g[0] } else { c.g[2] };
                let v1 = positions[c.v[0] as usize];
                (
                    v1 + cell_lift(hull, positions, c, single),
                    positions[c.v[1] as usize] - v1,
                )
            };
            let ((a1, d1), (a2, d2)) = (start(c1), start(c2));
            let (pa, pb) = (hull.points[ga as usize], hull.points[gb as usize]);
            // Weighted least squares: the component of 2s − (G_a + G_b) across the net edge
            // (in its face's plane) counts WEIGHT times more than the one along it.
            let along = (pb - pa).normalize_or_zero();
            let n = hull.normals[ga as usize];
            let across = n.cross(along);
            let r = pa + pb - a1 - a2;
            let proj = |x: DVec3| DVec2::new(SLIDE_ACROSS_WEIGHT * x.dot(across), x.dot(along));
            let (e1, e2, rr) = (proj(d1), proj(d2), proj(r));
            let (m11, m12, m22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
            let det = m11 * m22 - m12 * m12;
            let u0 = if det > 1e-12 * m11 * m22 {
                (m11 * e2.dot(rr) - m12 * e1.dot(rr)) / det
            } else {
                0.5
            };
            let solve = |r1: (f64, f64), r2: (f64, f64)| {
                let t =
                    ((e1.dot(rr) - m12 * u0.clamp(r2.0, r2.1)) / m11.max(1e-300)).clamp(r1.0, r1.1);
                let u = ((e2.dot(rr) - m12 * t) / m22.max(1e-300)).clamp(r2.0, r2.1);
                (t, u)
            };
            let (mut t, mut u) = solve((0.25, 0.75), (0.25, 0.75));
            // A slide past a corner's own apex overlaps that corner's tetrahedron: slide
            // again, keeping clear of the corner apexes (mpi_poly's edge 19–70).
            if self.cell_overlaps_corner(hull, positions, &owner, c1, t)
                || self.cell_overlaps_corner(hull, positions, &owner, c2, u)
            {
                (t, u) = solve(
                    self.slide_range(hull, positions, &owner, c1),
                    self.slide_range(hull, positions, &owner, c2),
                );
            }
            slide[c1] = t;
            slide[c2] = u;
        }
        slide
    }
}

/// Least distance, in units of the edge V_1V_2, between a paired cell's apex and the apexes of
/// the corner triangles beside it (built for V_1 and V_2 in steps (3)–(5)) along the edge, when
/// the least-squares slide made the cell's tetrahedron overlap a corner's
/// ([`GuardNet::add_edge_cells`]). mpi_poly's cell over edge 19–70 was slid to 0.27 of the
/// edge, behind vertex 19's step (5) apex at 0.30 (15 overlaps). Applied to every cell it
/// broke letter_P_poly's sign conditions (its slides bring s over the net edges), so only
/// overlapping cells are slid again. Where no slide keeps the gap at both ends the cell takes
/// the middle of the two bounds.
pub const SLIDE_GAP: f64 = 0.05;

impl GuardNet {
    /// The range of a paired cell's slide along its edge V_1V_2: within [¼, ¾], and beyond the
    /// apexes of the corner triangles beside it along the edge by [`SLIDE_GAP`].
    fn slide_range(
        &self,
        hull: &SimplicialHull,
        positions: &[DVec3],
        owner: &HashMap<(u32, u32), usize>,
        ci: usize,
    ) -> (f64, f64) {
        let c = &self.cells[ci];
        let [g1, g2, g3, g4] = c.g;
        let v1 = positions[c.v[0] as usize];
        let d = positions[c.v[1] as usize] - v1;
        let u_of = |q: DVec3| (q - v1).dot(d) / d.length_squared();
        let apexes = |key: (u32, u32)| -> Vec<f64> {
            owner
                .get(&key)
                .map(|&t| hull.apexes[t].iter().flatten().map(|&q| u_of(q)).collect())
                .unwrap_or_default()
        };
        let lo = apexes((g3, g1))
            .into_iter()
            .fold(0.25f64, |m, u| m.max(u + SLIDE_GAP));
        let hi = apexes((g2, g4))
            .into_iter()
            .fold(0.75f64, |m, u| m.min(u - SLIDE_GAP));
        if lo <= hi {
            (lo, hi)
        } else {
            let mid = (0.5 * (lo + hi)).clamp(0.25, 0.75);
            (mid, mid)
        }
    }

    /// Whether one-triangle cell `ci`, its apex slid to `u`, overlaps the face tetrahedra of
    /// the corner triangles beside it (the verifier's test and depth).
    fn cell_overlaps_corner(
        &self,
        hull: &SimplicialHull,
        positions: &[DVec3],
        owner: &HashMap<(u32, u32), usize>,
        ci: usize,
        u: f64,
    ) -> bool {
        let c = &self.cells[ci];
        let [g1, g2, g3, g4] = c.g;
        let (single, tri) = if g1 == g2 {
            (g1, [g1, g3, g4])
        } else {
            (g3, [g1, g3, g2])
        };
        let v1 = positions[c.v[0] as usize];
        let apex =
            v1 + u * (positions[c.v[1] as usize] - v1) + cell_lift(hull, positions, c, single);
        let [a, b, cc] = tri.map(|i| hull.points[i as usize]);
        let cell = [a, b, cc, apex];
        [(g3, g1), (g2, g4)].iter().any(|key| {
            owner.get(key).is_some_and(|&t| {
                let [p, q, r] = hull.triangles[t].map(|i| hull.points[i as usize]);
                hull.apexes[t].iter().flatten().any(|&x| {
                    let corner = [p, q, r, x];
                    let scale = longest(&cell).min(longest(&corner));
                    let limit = super::verify::OVERLAP_DEPTH * scale;
                    super::verify::sat_depth_above(&cell, &corner, limit).is_some()
                })
            })
        })
    }
}

/// Longest edge of a tetrahedron.
fn longest(t: &[DVec3; 4]) -> f64 {
    let mut l: f64 = 0.0;
    for i in 0..4 {
        for j in i + 1..4 {
            l = l.max((t[i] - t[j]).length());
        }
    }
    l
}

/// How much more the offset of s across a net edge counts than along it when the cells' apexes
/// are slid ([`GuardNet::add_edge_cells`]).
const SLIDE_ACROSS_WEIGHT: f64 = 10.0;

/// The outward move of a one-triangle cell's apex off its edge: along the bisector of the two
/// faces' normals, [`CELL_LIFT`] of the single guard `g`'s distance from the edge line, that
/// distance capped at [`CELL_LIFT_REACH`] edge lengths.
fn cell_lift(hull: &SimplicialHull, positions: &[DVec3], cell: &EdgeCell, g: u32) -> DVec3 {
    let (v1, v2) = (positions[cell.v[0] as usize], positions[cell.v[1] as usize]);
    let e = (v2 - v1).normalize_or_zero();
    let out =
        (hull.normals[cell.g[0] as usize] + hull.normals[cell.g[2] as usize]).normalize_or_zero();
    let d = hull.points[g as usize] - v1;
    let reach = (d - d.dot(e) * e).length();
    // Over a concave edge (f_2's guard above f_1's plane) out of the polyhedron is above both
    // tangent planes, where the cell's apex, on the inner side of its triangle, is not tangent
    // containing, and `clearance` then pulls it back onto the edge itself (mpi_poly cleaned: a
    // cell beside a flat net, whose edge tetrahedron's face was crossed); such an apex goes
    // into the polyhedron, below both planes.
    let sign = if cell_concave(hull, positions, cell) {
        -1.0
    } else {
        1.0
    };
    sign * CELL_LIFT * reach.min(CELL_LIFT_REACH * (v2 - v1).length()) * out
}

/// True when the cell's edge V_1V_2 is concave: f_2's guard G_3 lies above f_1's plane.
fn cell_concave(hull: &SimplicialHull, positions: &[DVec3], cell: &EdgeCell) -> bool {
    let v1 = positions[cell.v[0] as usize];
    hull.normals[cell.g[0] as usize].dot(hull.points[cell.g[2] as usize] - v1) > 0.0
}

/// Cap on the guard distance [`cell_lift`] scales by, in units of the cell's edge V_1V_2: the
/// lift comes from the local scale. mpi_poly's edge 74–77 (1.5 long) has its single guard (face
/// 8's kernel guard) 10 away: uncapped, the apex rose 1.7 out of the polyhedron and its
/// tetrahedron, over a nearly flat stretch of T (a 0.1° fold), covered its neighbours' (58
/// overlaps); capped, 470 → 351 hull violations on the raw hull. A U prism 20 high over a U of
/// unit edges (side-face centroids 10 from the caps' edges) had 44 overlaps and now verifies
/// (`tests/suite/inner_mpi.rs`). letter_P's guards lie within their edges' lengths, so its cells do
/// not change.
pub const CELL_LIFT_REACH: f64 = 1.0;

/// True for a star-shaped non-convex piece (kept whole with its kernel guard).
fn is_star_only(pieces: &Pieces, p: usize) -> bool {
    pieces
        .star
        .iter()
        .any(|&(_, g)| (g - pieces.center[p]).length() == 0.0)
}

/// Directed edge → piece.
fn directed_edges(faces: &[Vec<u32>]) -> HashMap<(u32, u32), u32> {
    let mut m = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            m.insert((face[k], face[(k + 1) % face.len()]), f as u32);
        }
    }
    m
}

/// Maximal cyclic runs of one region in a closed fan: (region, first, last) with indices into
/// `faces` (last may exceed the length: it wraps). A fan that is all one region gives one run
/// with first = `usize::MAX`.
fn runs(faces: &[u32], region: &[u32]) -> Vec<(u32, usize, usize)> {
    let k = faces.len();
    let reg = |i: usize| region[faces[i % k] as usize];
    let Some(start) = (0..k).find(|&i| reg(i + k - 1) != reg(i)) else {
        return vec![(reg(0), usize::MAX, usize::MAX)];
    };
    let mut out = Vec::new();
    let mut i = start;
    while i < start + k {
        let mut j = i;
        while j + 1 < start + k && reg(j + 1) == reg(i) {
            j += 1;
        }
        out.push((reg(i), i % k, i % k + (j - i)));
        i = j + 1;
    }
    out
}

/// 2D frame of a region's plane.
struct Plane {
    o: DVec3,
    u: DVec3,
    v: DVec3,
}

impl Plane {
    fn flat(&self, p: DVec3) -> DVec2 {
        DVec2::new((p - self.o).dot(self.u), (p - self.o).dot(self.v))
    }
    fn lift(&self, q: DVec2) -> DVec3 {
        self.o + q.x * self.u + q.y * self.v
    }
}

/// Searches a guard per corner (see the module documentation). Returns the assignment (piece
/// per corner) and the guard positions of the pieces used.
#[allow(clippy::type_complexity)]
fn assign(
    pos: &[DVec3],
    pieces: &Pieces,
    members: &[u32],
    corners: &[RegionCorner],
) -> Option<(Vec<u32>, Vec<(u32, DVec3)>)> {
    let n = pieces.normal[members[0] as usize];
    let u = n.any_orthonormal_vector();
    let plane = Plane {
        o: pos[pieces.faces[members[0] as usize][0] as usize],
        u,
        v: n.cross(u),
    };
    let f = |i: u32| plane.flat(pos[i as usize]);
    // Region boundary edges (U → V, CCW) and vertices.
    let boundary: Vec<(DVec2, DVec2)> = corners.iter().map(|c| (f(c.v), f(c.w))).collect();
    let kernels: HashMap<u32, Vec<DVec2>> = members
        .iter()
        .map(|&p| {
            let poly: Vec<DVec2> = pieces.faces[p as usize].iter().map(|&i| f(i)).collect();
            (p, kernel_region(&poly).unwrap_or_default())
        })
        .collect();
    let area: HashMap<u32, f64> = members
        .iter()
        .map(|&p| {
            let poly: Vec<DVec2> = pieces.faces[p as usize].iter().map(|&i| f(i)).collect();
            (p, polygon_area(&poly))
        })
        .collect();
    // Candidate pieces per corner: those whose kernel meets the corner's wedge.
    let wedge = |c: &RegionCorner| [(f(c.u), f(c.v)), (f(c.v), f(c.w))];
    let diameter = boundary
        .iter()
        .flat_map(|&(a, _)| boundary.iter().map(move |&(b, _)| (a - b).length()))
        .fold(0.0, f64::max);
    let mut cands: Vec<Vec<u32>> = Vec::with_capacity(corners.len());
    for c in corners {
        let mut ok = Vec::new();
        for &p in &c.cands {
            let mut k = kernels[&p].clone();
            for (a, b) in wedge(c) {
                k = clip(&k, a, b);
            }
            if k.len() >= 3 && polygon_area(&k) >= MIN_KERNEL_AREA * area[&p] {
                ok.push(p);
            }
        }
        if ok.is_empty() {
            return None;
        }
        cands.push(ok);
    }
    // Corner index by vertex; the successor corner of each (along its outgoing edge).
    let by_v: HashMap<u32, usize> = corners.iter().enumerate().map(|(i, c)| (c.v, i)).collect();
    let next: Vec<usize> = corners
        .iter()
        .map(|c| by_v.get(&c.w).copied())
        .collect::<Option<Vec<_>>>()?;
    let prev: Vec<usize> = corners
        .iter()
        .map(|c| by_v.get(&c.u).copied())
        .collect::<Option<Vec<_>>>()?;
    // Order: walk the boundary loops so pairs close early.
    let mut order = Vec::with_capacity(corners.len());
    let mut seen = vec![false; corners.len()];
    for s in 0..corners.len() {
        let mut c = s;
        while !seen[c] {
            seen[c] = true;
            order.push(c);
            c = next[c];
        }
    }
    let mut st = Search {
        cands: &cands,
        order: &order,
        next: &next,
        prev: &prev,
        pick: vec![u32::MAX; corners.len()],
        pairs: HashMap::new(),
        leaves: 0,
        best: None,
    };
    let mut check = |pick: &[u32]| -> Option<(Vec<(u32, DVec3)>, f64)> {
        let mut out = Vec::new();
        let mut guard: HashMap<u32, DVec2> = HashMap::new();
        for &p in members {
            let mut k = kernels[&p].clone();
            let mut any = false;
            for (c, &g) in corners.iter().zip(pick) {
                if g == p {
                    any = true;
                    for (a, b) in wedge(c) {
                        k = clip(&k, a, b);
                    }
                }
            }
            if !any {
                continue;
            }
            if k.len() < 3 || polygon_area(&k) < MIN_KERNEL_AREA * area[&p] {
                return None;
            }
            let served: Vec<[DVec2; 3]> = corners
                .iter()
                .zip(pick)
                .filter(|&(_, &g)| g == p)
                .map(|(c, _)| [f(c.u), f(c.v), f(c.w)])
                .collect();
            let gp = near_guard(&k, &served);
            guard.insert(p, gp);
            out.push((p, plane.lift(gp)));
        }
        // Visibility of every corner from its guard, and net segments inside the region.
        for (c, &g) in corners.iter().zip(pick) {
            let gp = guard[&g];
            let (pu, pv, pw) = (f(c.u), f(c.v), f(c.w));
            for q in [pu, pv, pw] {
                if crosses_boundary(gp, q, &boundary) {
                    return None;
                }
            }
            for t in [[gp, pu, pv], [gp, pv, pw]] {
                if boundary
                    .iter()
                    .any(|&(a, _)| a != pu && a != pv && a != pw && strictly_inside(t, a))
                {
                    return None;
                }
            }
        }
        // Corners served from too far ([`too_far`]) weigh far more than net length: guards
        // near their corners first, then the shortest net.
        let mut length2 = 0.0;
        for (c, &g) in corners.iter().zip(pick) {
            let (pu, pv, pw) = (f(c.u), f(c.v), f(c.w));
            let e = (pu - pv).length().max((pw - pv).length());
            let d = (guard[&g] - pv).length();
            let beyond = d - super::decompose::GUARD_REACH * e;
            if too_far(d, e, diameter) {
                length2 += FAR_WEIGHT * beyond * beyond;
            }
        }
        for (i, &g) in pick.iter().enumerate() {
            let h = pick[next[i]];
            if g != h {
                if crosses_boundary(guard[&g], guard[&h], &boundary) {
                    return None;
                }
                length2 += (guard[&g] - guard[&h]).length_squared();
            }
        }
        Some((out, length2))
    };
    st.run(0, &mut check);
    st.best.map(|(_, pick, centers)| (pick, centers))
}

/// Weight of the squared distance by which a corner's guard lies beyond
/// [`super::decompose::GUARD_REACH`] in an assignment's cost, against the squared net length.
const FAR_WEIGHT: f64 = 1e3;

/// The geometric test of a complete assignment: guard positions of the pieces used and the
/// assignment's cost (the sum of the squared net edge lengths), or `None`.
type GuardCheck<'c> = dyn FnMut(&[u32]) -> Option<(Vec<(u32, DVec3)>, f64)> + 'c;

/// The best assignment so far: cost, guard per corner, guard positions.
type Best = (f64, Vec<u32>, Vec<(u32, DVec3)>);

/// Backtracking state of [`assign`].
struct Search<'a> {
    cands: &'a [Vec<u32>],
    order: &'a [usize],
    next: &'a [usize],
    prev: &'a [usize],
    pick: Vec<u32>,
    pairs: HashMap<(u32, u32), u32>,
    leaves: usize,
    best: Option<Best>,
}

impl Search<'_> {
    /// Visits every assignment (up to [`SEARCH_BUDGET`] complete ones) and keeps the valid one
    /// with the shortest net: short net edges keep the step (5') cells and the edge
    /// tetrahedra over net edges small and well shaped.
    fn run(&mut self, depth: usize, check: &mut GuardCheck) {
        if self.leaves >= SEARCH_BUDGET {
            return;
        }
        if depth == self.order.len() {
            self.leaves += 1;
            // Every guard pair walked once each way.
            if self
                .pairs
                .iter()
                .all(|(&(a, b), &n)| n == 1 && self.pairs.get(&(b, a)) == Some(&1))
            {
                if let Some((r, cost)) = check(&self.pick) {
                    if self.best.as_ref().is_none_or(|b| cost < b.0) {
                        self.best = Some((cost, self.pick.clone(), r));
                    }
                }
            }
            return;
        }
        let c = self.order[depth];
        for k in 0..self.cands[c].len() {
            let g = self.cands[c][k];
            self.pick[c] = g;
            let mut added = Vec::new();
            let mut ok = true;
            for (a, b) in [(self.prev[c], c), (c, self.next[c])] {
                let (ga, gb) = (self.pick[a], self.pick[b]);
                if ga == u32::MAX || gb == u32::MAX || ga == gb || (a == c && b == c) {
                    continue;
                }
                if a == b {
                    continue;
                }
                let e = self.pairs.entry((ga, gb)).or_insert(0);
                *e += 1;
                added.push((ga, gb));
                if *e > 1 {
                    ok = false;
                }
            }
            if ok {
                self.run(depth + 1, check);
            }
            for key in added {
                if let Some(e) = self.pairs.get_mut(&key) {
                    *e -= 1;
                    if *e == 0 {
                        self.pairs.remove(&key);
                    }
                }
            }
            self.pick[c] = u32::MAX;
        }
    }
}

/// Keeps the part of convex polygon `k` strictly left of the line a → b (Sutherland–Hodgman).
fn clip(k: &[DVec2], a: DVec2, b: DVec2) -> Vec<DVec2> {
    let side = |p: DVec2| (b - a).perp_dot(p - a);
    let mut out = Vec::with_capacity(k.len() + 1);
    for i in 0..k.len() {
        let (p, q) = (k[i], k[(i + 1) % k.len()]);
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            out.push(p + (q - p) * (sp / (sp - sq)));
        }
    }
    out
}

/// How far (as a share of the way to the kernel's edge) a guard moves from its clipped kernel's
/// centroid towards the corners it serves when the centroid is too far from them
/// ([`near_guard`]); the rest keeps it off the kernel's boundary.
pub const GUARD_PULL: f64 = 0.8;

/// The guard of one piece, in its kernel `k` (already clipped by the wedges of the corners it
/// serves, each given as U, V, W). The centroid of `k` when every served corner V lies within
/// [`super::decompose::GUARD_REACH`] of its longer edge's length from it; otherwise the point
/// [`GUARD_PULL`] of the way from the centroid to where the segment towards the corners' mean
/// leaves `k` (Appendix B's corner guard circles: any point of the kernel serves, so one near
/// its corners keeps T's triangles there short; a long L's arm end was served from its elbow).
fn near_guard(k: &[DVec2], served: &[[DVec2; 3]]) -> DVec2 {
    let c = centroid(k);
    let far = served.iter().any(|&[u, v, w]| {
        let e = (u - v).length().max((w - v).length());
        (v - c).length() > super::decompose::GUARD_REACH * e
    });
    if !far || served.is_empty() {
        return c;
    }
    let m = served.iter().map(|x| x[1]).sum::<DVec2>() / served.len() as f64;
    let d = m - c;
    // Largest t ≤ 1 with c + t·d inside the convex, counter-clockwise k.
    let mut t: f64 = 1.0;
    for i in 0..k.len() {
        let (a, b) = (k[i], k[(i + 1) % k.len()]);
        let side = (b - a).perp_dot(c - a);
        let rate = (b - a).perp_dot(d);
        if rate < 0.0 {
            t = t.min(side / -rate);
        }
    }
    c + GUARD_PULL * t.max(0.0) * d
}

/// Share of its region's diameter beyond which a guard counts as far from a corner (with
/// [`super::decompose::GUARD_REACH`]): corners with tiny edges (mpi_poly's slivers, 0.02 wide)
/// cannot have guards within a few edge lengths, and moving guards for them only shuffles
/// the net.
pub const FAR_SHARE: f64 = 0.5;

/// A guard at distance `d` from a corner whose longer edge is `e`, in a region of diameter
/// `diameter`, is too far when `d` exceeds both [`super::decompose::GUARD_REACH`] × `e` and
/// [`FAR_SHARE`] × `diameter`.
fn too_far(d: f64, e: f64, diameter: f64) -> bool {
    d > super::decompose::GUARD_REACH * e && d > FAR_SHARE * diameter
}

/// Area centroid of a convex polygon of positive area.
fn centroid(k: &[DVec2]) -> DVec2 {
    let a = polygon_area(k);
    let mut c = DVec2::ZERO;
    for i in 0..k.len() {
        let (p, q) = (k[i], k[(i + 1) % k.len()]);
        c += (p + q) * p.perp_dot(q);
    }
    c / (6.0 * a)
}

/// True when segment p–q properly crosses a boundary edge (endpoints shared with it do not
/// count).
fn crosses_boundary(p: DVec2, q: DVec2, boundary: &[(DVec2, DVec2)]) -> bool {
    let orient = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    boundary.iter().any(|&(a, b)| {
        if a == p || a == q || b == p || b == q {
            return false;
        }
        let (d1, d2) = (orient(p, q, a), orient(p, q, b));
        let (d3, d4) = (orient(a, b, p), orient(a, b, q));
        d1 * d2 < 0.0 && d3 * d4 < 0.0
    })
}

/// True when `x` lies strictly inside triangle `t` (either orientation).
fn strictly_inside(t: [DVec2; 3], x: DVec2) -> bool {
    let s: Vec<f64> = (0..3)
        .map(|i| (t[(i + 1) % 3] - t[i]).perp_dot(x - t[i]))
        .collect();
    s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0)
}
