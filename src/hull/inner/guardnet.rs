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
//! cell is one triangle with apex M. The guard net of a region is the set of guard pairs these
//! cells use; T is a closed manifold when every pair is walked once in each direction round
//! the region's boundary loops, which the guard assignment ([`GuardNet::build`]) searches for.
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

/// Largest number of complete guard assignments tried per region before giving up (the
/// backtracking prunes by the pair counts; letter_P's caps need a few hundred).
pub const SEARCH_BUDGET: usize = 200_000;

/// How far the apex of a one-triangle cell moves from the edge midpoint M away from the single
/// guard (fraction of the guard's distance from the edge line); see
/// [`GuardNet::add_edge_cells`].
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
    #[must_use]
    pub fn build(mesh: &Mesh, mut pieces: Pieces) -> GuardNet {
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
            let polys: Vec<Vec<u32>> =
                if multi_parent && members.iter().all(|&p| !is_star_only(&pieces, p)) {
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
        let mut next_region = nr as u32;
        for r in 0..nr {
            if region_pieces[r].len() < 2 {
                continue;
            }
            let found = if pinched[r] || corners[r].is_empty() {
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
        for cell in &self.cells {
            let [g1, g2, g3, g4] = cell.g;
            let m = 0.5 * (positions[cell.v[0] as usize] + positions[cell.v[1] as usize]);
            let apexes_of = |key: (u32, u32)| -> Vec<DVec3> {
                owner
                    .get(&key)
                    .map(|&t| hull.apexes[t].iter().flatten().copied().collect())
                    .unwrap_or_default()
            };
            // V_1's triangle holds G_3 → G_1, V_2's holds G_2 → G_4.
            let q1 = apexes_of((g3, g1));
            let q2 = apexes_of((g2, g4));
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
            let half = |qs: &[DVec3]| -> Vec<DVec3> { qs.iter().map(|&q| 0.5 * (q + m)).collect() };
            // One triangle: apex M, moved in the single-guard face's plane away from its guard
            // (out of the polyhedron, beyond the edge) by CELL_LIFT of the guard's distance
            // from the edge. That plane is the guard's tangent plane, and the other two
            // vertices' tangent plane holds two of the tetrahedron's points, so it stays
            // tangent-containing; with M itself the edge tetrahedra between two such cells
            // over one net edge are flat, and moved inwards they fold over the cells.
            let e = (positions[cell.v[1] as usize] - m).normalize_or_zero();
            let lifted = |g: u32| -> DVec3 {
                let d = hull.points[g as usize] - m;
                m - CELL_LIFT * (d - d.dot(e) * e)
            };
            if g1 == g2 {
                push([g1, g3, g4], vec![lifted(g1)]);
            } else if g3 == g4 {
                push([g1, g3, g2], vec![lifted(g3)]);
            } else {
                push([g1, g3, g2], half(&q1));
                push([g3, g4, g2], half(&q2));
            }
        }
    }
}

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
        result: None,
    };
    let mut check = |pick: &[u32]| -> Option<Vec<(u32, DVec3)>> {
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
            let gp = centroid(&k);
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
        for (i, &g) in pick.iter().enumerate() {
            let h = pick[next[i]];
            if g != h && crosses_boundary(guard[&g], guard[&h], &boundary) {
                return None;
            }
        }
        Some(out)
    };
    st.run(0, &mut check);
    let pick = st.pick_final();
    st.result.map(|centers| (pick, centers))
}

/// The geometric test of a complete assignment: guard positions of the pieces used, or `None`.
type GuardCheck<'c> = dyn FnMut(&[u32]) -> Option<Vec<(u32, DVec3)>> + 'c;

/// Backtracking state of [`assign`].
struct Search<'a> {
    cands: &'a [Vec<u32>],
    order: &'a [usize],
    next: &'a [usize],
    prev: &'a [usize],
    pick: Vec<u32>,
    pairs: HashMap<(u32, u32), u32>,
    leaves: usize,
    result: Option<Vec<(u32, DVec3)>>,
}

impl Search<'_> {
    fn pick_final(&self) -> Vec<u32> {
        self.pick.clone()
    }

    fn run(&mut self, depth: usize, check: &mut GuardCheck) {
        if self.result.is_some() || self.leaves >= SEARCH_BUDGET {
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
                if let Some(r) = check(&self.pick) {
                    self.result = Some(r);
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
            if self.result.is_some() {
                return;
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
