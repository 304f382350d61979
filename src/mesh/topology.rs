//! Adjacency of a polygon mesh: corners (half-edges), undirected edges with their faces, and each
//! vertex's ordered fan.
//!
//! A *corner* `c` is one vertex slot of one face; it stands for the half-edge from its vertex to
//! the next vertex of the face. Corners are numbered face by face: face `f` owns corners
//! `face_start[f] .. face_start[f + 1]`.

/// Adjacency tables of a polygon mesh. Built in O(C log C) time and O(C) memory (C = corners).
#[derive(Clone, Debug)]
pub struct Topology {
    /// #F + 1 offsets: face `f` owns corners `face_start[f]..face_start[f+1]`.
    pub face_start: Vec<u32>,
    /// #C vertex of each corner.
    pub corner_vertex: Vec<u32>,
    /// #C face of each corner.
    pub corner_face: Vec<u32>,
    /// #C undirected edge of the half-edge starting at each corner.
    pub corner_edge: Vec<u32>,
    /// #C the other corner of the same edge when the edge has exactly two corners, else
    /// `u32::MAX` (boundary or non-manifold edge).
    pub corner_mate: Vec<u32>,
    /// #E undirected edges, smaller vertex first, sorted.
    pub edges: Vec<[u32; 2]>,
    /// #E + 1 offsets into `edge_corner_list`.
    edge_start: Vec<u32>,
    /// Corners of each edge, grouped by edge.
    edge_corner_list: Vec<u32>,
    /// #V + 1 offsets into `vertex_corner_list`.
    vertex_start: Vec<u32>,
    /// Corners at each vertex (half-edges leaving it), grouped by vertex.
    vertex_corner_list: Vec<u32>,
}

/// The faces around one manifold vertex in counter-clockwise order (seen from outside).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fan {
    /// Edge neighbours p_0, p_1, … in CCW order. Interior vertex: k neighbours for k faces;
    /// boundary vertex: k + 1 (p_0 and p_k are the boundary neighbours).
    pub ring: Vec<u32>,
    /// The k faces; face `faces[i]` lies between `ring[i]` and `ring[i + 1]` (cyclically if closed).
    pub faces: Vec<u32>,
    /// True for an interior vertex (the fan closes), false on the boundary.
    pub closed: bool,
}

impl Topology {
    /// Builds the tables for `faces` (each a polygon of ≥ 3 indices < `n_vertices`).
    #[must_use]
    pub fn new(n_vertices: usize, faces: &[Vec<u32>]) -> Topology {
        let n_corners: usize = faces.iter().map(Vec::len).sum();
        let mut face_start = Vec::with_capacity(faces.len() + 1);
        let mut corner_vertex = Vec::with_capacity(n_corners);
        let mut corner_face = Vec::with_capacity(n_corners);
        face_start.push(0u32);
        for (f, face) in faces.iter().enumerate() {
            corner_vertex.extend_from_slice(face);
            corner_face.extend(std::iter::repeat_n(f as u32, face.len()));
            face_start.push(corner_vertex.len() as u32);
        }
        // Undirected edges: sort (key, corner) pairs.
        let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(n_corners);
        for (f, face) in faces.iter().enumerate() {
            let s = face_start[f];
            for k in 0..face.len() {
                let a = face[k];
                let b = face[(k + 1) % face.len()];
                let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                keyed.push(((u64::from(lo) << 32) | u64::from(hi), s + k as u32));
            }
        }
        keyed.sort_unstable();
        let mut edges = Vec::with_capacity(n_corners / 2 + 1);
        let mut edge_start = Vec::with_capacity(n_corners / 2 + 2);
        let mut edge_corner_list = Vec::with_capacity(n_corners);
        let mut corner_edge = vec![0u32; n_corners];
        let mut last = u64::MAX;
        for &(key, c) in &keyed {
            if key != last {
                edge_start.push(edge_corner_list.len() as u32);
                edges.push([(key >> 32) as u32, key as u32]);
                last = key;
            }
            corner_edge[c as usize] = (edges.len() - 1) as u32;
            edge_corner_list.push(c);
        }
        edge_start.push(edge_corner_list.len() as u32);
        drop(keyed);
        let mut corner_mate = vec![u32::MAX; n_corners];
        for w in edge_start.windows(2) {
            if w[1] - w[0] == 2 {
                let (a, b) = (
                    edge_corner_list[w[0] as usize],
                    edge_corner_list[w[0] as usize + 1],
                );
                corner_mate[a as usize] = b;
                corner_mate[b as usize] = a;
            }
        }
        // Corners per vertex (counting sort).
        let mut vertex_start = vec![0u32; n_vertices + 1];
        for &v in &corner_vertex {
            vertex_start[v as usize + 1] += 1;
        }
        for i in 0..n_vertices {
            vertex_start[i + 1] += vertex_start[i];
        }
        let mut fill = vertex_start.clone();
        let mut vertex_corner_list = vec![0u32; n_corners];
        for (c, &v) in corner_vertex.iter().enumerate() {
            vertex_corner_list[fill[v as usize] as usize] = c as u32;
            fill[v as usize] += 1;
        }
        Topology {
            face_start,
            corner_vertex,
            corner_face,
            corner_edge,
            corner_mate,
            edges,
            edge_start,
            edge_corner_list,
            vertex_start,
            vertex_corner_list,
        }
    }

    /// Number of vertices the tables were built for.
    #[must_use]
    pub fn n_vertices(&self) -> usize {
        self.vertex_start.len() - 1
    }

    /// The corner after `c` in its face.
    #[must_use]
    pub fn next(&self, c: u32) -> u32 {
        let f = self.corner_face[c as usize] as usize;
        if c + 1 == self.face_start[f + 1] {
            self.face_start[f]
        } else {
            c + 1
        }
    }

    /// The corner before `c` in its face.
    #[must_use]
    pub fn prev(&self, c: u32) -> u32 {
        let f = self.corner_face[c as usize] as usize;
        if c == self.face_start[f] {
            self.face_start[f + 1] - 1
        } else {
            c - 1
        }
    }

    /// The vertex the half-edge of corner `c` points to.
    #[must_use]
    pub fn head(&self, c: u32) -> u32 {
        self.corner_vertex[self.next(c) as usize]
    }

    /// Corners (half-edges) of edge `e`: one per face using it.
    #[must_use]
    pub fn edge_corners(&self, e: u32) -> &[u32] {
        let e = e as usize;
        &self.edge_corner_list[self.edge_start[e] as usize..self.edge_start[e + 1] as usize]
    }

    /// Corners at vertex `v` (half-edges leaving it).
    #[must_use]
    pub fn vertex_corners(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.vertex_corner_list[self.vertex_start[v] as usize..self.vertex_start[v + 1] as usize]
    }

    /// The opposite half-edge of `c`: the other corner of its edge when the edge has exactly two
    /// faces that traverse it in opposite directions.
    #[must_use]
    pub fn twin(&self, c: u32) -> Option<u32> {
        let o = self.corner_mate[c as usize];
        (o != u32::MAX && self.corner_vertex[o as usize] != self.corner_vertex[c as usize])
            .then_some(o)
    }

    /// True when edge `e` has exactly one face.
    #[must_use]
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.edge_corners(e).len() == 1
    }

    /// The ordered fan of vertex `v`, or `None` when `v` is non-manifold (its faces do not form
    /// a single fan through manifold, consistently oriented edges) or isolated.
    #[must_use]
    pub fn vertex_fan(&self, v: u32) -> Option<Fan> {
        let out = self.vertex_corners(v);
        if out.is_empty() {
            return None;
        }
        // Every edge at v must be manifold and consistently oriented (or boundary).
        let mut start = None;
        let mut boundary_out = 0;
        for &c in out {
            for h in [c, self.prev(c)] {
                let n = self.edge_corners(self.corner_edge[h as usize]).len();
                if n > 2 || (n == 2 && self.twin(h).is_none()) {
                    return None;
                }
            }
            if self.twin(c).is_none() {
                boundary_out += 1;
                start = Some(c);
            }
        }
        if boundary_out > 1 {
            return None;
        }
        let closed = start.is_none();
        let start = start.unwrap_or(out[0]);
        let mut ring = Vec::with_capacity(out.len() + 1);
        let mut faces = Vec::with_capacity(out.len());
        let mut c = start;
        loop {
            ring.push(self.head(c));
            faces.push(self.corner_face[c as usize]);
            let p = self.prev(c);
            match self.twin(p) {
                Some(t) if t == start => break,
                Some(t) => {
                    if faces.len() > out.len() {
                        return None;
                    }
                    c = t;
                }
                None => {
                    ring.push(self.corner_vertex[p as usize]);
                    break;
                }
            }
        }
        (faces.len() == out.len()).then_some(Fan {
            ring,
            faces,
            closed,
        })
    }

    /// Number of connected components of the faces (sharing a vertex connects), and the
    /// component of each vertex (`u32::MAX` for vertices no face uses).
    #[must_use]
    pub fn components(&self) -> (usize, Vec<u32>) {
        let n = self.n_vertices();
        let mut uf = UnionFind::new(n);
        for e in &self.edges {
            uf.union(e[0], e[1]);
        }
        let mut id = vec![u32::MAX; n];
        let mut root_id = vec![u32::MAX; n];
        let mut count = 0usize;
        for v in 0..n as u32 {
            if self.vertex_corners(v).is_empty() {
                continue;
            }
            let r = uf.find(v) as usize;
            if root_id[r] == u32::MAX {
                root_id[r] = count as u32;
                count += 1;
            }
            id[v as usize] = root_id[r];
        }
        (count, id)
    }

    /// Number of boundary loops: connected components of the graph of boundary edges.
    #[must_use]
    pub fn boundary_loops(&self) -> usize {
        let mut uf = UnionFind::new(self.n_vertices());
        let mut on_boundary = vec![false; self.n_vertices()];
        for (e, ends) in self.edges.iter().enumerate() {
            if self.is_boundary_edge(e as u32) {
                uf.union(ends[0], ends[1]);
                on_boundary[ends[0] as usize] = true;
                on_boundary[ends[1] as usize] = true;
            }
        }
        (0..self.n_vertices() as u32)
            .filter(|&v| on_boundary[v as usize] && uf.find(v) == v)
            .count()
    }
}

/// The face holding each directed edge (a → b) of the polygons `faces` (the last face wins
/// where an edge repeats, as in a non-manifold mesh): the face across an edge (a → b) of an
/// oriented mesh is the one holding (b → a).
#[must_use]
pub fn directed_edge_faces(faces: &[Vec<u32>]) -> std::collections::HashMap<(u32, u32), usize> {
    let mut of_edge = std::collections::HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            of_edge.insert((face[k], face[(k + 1) % face.len()]), f);
        }
    }
    of_edge
}

/// The boundary of the union of the polygons `faces[f]`, f in `group`, as one simple loop
/// (counter-clockwise from outside like its faces), or `None` when the boundary is pinched or
/// not one loop.
#[must_use]
pub fn boundary_loop(faces: &[Vec<u32>], group: &[usize]) -> Option<Vec<u32>> {
    let mut half: std::collections::HashMap<(u32, u32), ()> = std::collections::HashMap::new();
    for &f in group {
        let face = &faces[f];
        for k in 0..face.len() {
            half.insert((face[k], face[(k + 1) % face.len()]), ());
        }
    }
    let mut next: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for &(a, b) in half.keys() {
        if !half.contains_key(&(b, a)) && next.insert(a, b).is_some() {
            return None; // a pinched boundary
        }
    }
    let start = *next.keys().min()?;
    let mut poly = vec![start];
    let mut cur = next[&start];
    while cur != start {
        if poly.len() > next.len() {
            return None;
        }
        poly.push(cur);
        cur = *next.get(&cur)?;
    }
    (poly.len() == next.len()).then_some(poly)
}

/// Disjoint sets over `0..n` with path halving and union by size.
pub struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    /// `n` singletons.
    #[must_use]
    pub fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }

    /// The representative of `x`'s set.
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[x as usize];
            self.parent[x as usize] = self.parent[p as usize];
            x = p;
        }
        x
    }

    /// Merges the sets of `a` and `b`.
    pub fn union(&mut self, a: u32, b: u32) {
        let (mut a, mut b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        if self.size[a as usize] < self.size[b as usize] {
            std::mem::swap(&mut a, &mut b);
        }
        self.parent[b as usize] = a;
        self.size[a as usize] += self.size[b as usize];
    }
}
