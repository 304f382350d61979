//! A second corner guard for a star face's corner that its kernel guard serves from far away
//! where the face continues nearly flat into its neighbour (Algorithm 2 step (1): any point of
//! the face that sees the corner's two edges is a corner guard for it; Definition 2.5).
//!
//! A star-shaped polygon keeps one guard, its kernel's centroid ([`super::decompose`]). When
//! the kernel is a small wedge far from a corner V, V's step (3) triangle reaches from V's other
//! guards to that far guard. Where the polygon f meets a neighbour face f' across an edge at V
//! at a nearly flat angle (mpi_poly: star face 8 and face 0 flat to 0.1° along edge 1–74), V's
//! triangle [G_{f'}, G_f, G_3] and the triangle beyond the edge G_{f'}G_f (the step (5') cell
//! over that edge) lie in almost one plane, and with G_f far along the edge the two fold over
//! each other (mpi_poly's triangle 108 folded 150° under cell 124: V_74 projected outside its
//! own guard triangle, ~100 overlaps). Splitting such faces into convex pieces of input
//! vertices gives pieces that are long too (the earlier experiments: worse).
//!
//! Here the corner gets its own guard N_V in f (only where the neighbour's guard changes along
//! the flat edge, see [`add_near_guards`]), on the bisector of its interior angle at
//! [`RADIUS`] × its shorter edge (halved until N_V sees both edges and the net segment N_V–G_f
//! stays inside f): V's fan names N_V for f, and the two edges of f at V get step (5') cells
//! between N_V and the guards of their other ends ([`super::guardnet::EdgeCell`]). The face's
//! guard net is then the segment N_V–G_f (a tree: T stays a closed manifold, the segment a zero
//! convex edge, both guards carrying f's normal).

use super::decompose::GUARD_REACH;
use super::flatnet;
use super::guardnet::GuardNet;
use crate::mesh::Mesh;
use glam::{DVec2, DVec3};

/// Distance of the new guard from its corner on the interior bisector, as a share of the
/// corner's shorter edge (halved until it sees the corner).
pub const RADIUS: f64 = 0.5;

/// Cosine of the largest dihedral angle (away from flat) between the star face and a neighbour
/// across an edge at the corner for which the corner gets a guard of its own: 2°. mpi_poly's
/// faces 0 and 8 meet at 0.1°; exact coplanar neighbours are merged before
/// ([`super::coplanar`]), so only nearly flat folds (scanned or rounded models) qualify.
pub const FLAT_COS: f64 = 0.999_39;

/// The corners given a guard of their own: (merged face, vertex, new point of T).
pub type NearGuards = Vec<(u32, u32, u32)>;

/// Gives each qualifying corner of a star face of `net` (kept whole with one kernel guard, the
/// only piece of its region) its own guard (module docs): the corner's kernel guard lies
/// farther than [`GUARD_REACH`] × the corner's *shorter* edge from it, and the face meets a
/// neighbour across one of the corner's two edges within [`FLAT_COS`] of flat whose guard
/// changes along that edge (a step (5') cell there, as face 0's net along mpi_poly's edge
/// 1–74). Without such a cell the two corners of the edge share one guard of the neighbour and
/// the fold does not arise: mpi_poly's mirror corner 57 (face 25 against star face 24) and
/// corners 33, 39, 43 qualify otherwise, and guards of their own made the raw hull worse
/// (331 → 403, 354, 359 violations).
pub fn add_near_guards(net: &mut GuardNet, mesh: &Mesh) -> NearGuards {
    let pos = &mesh.positions;
    let mut out = NearGuards::new();
    let stars: Vec<(u32, DVec3)> = net.pieces.star.clone();
    let np = net.pieces.faces.len();
    for (f, g) in stars {
        let Some(p) = (0..np)
            .find(|&p| net.pieces.parent[p] == f && (net.pieces.center[p] - g).length() == 0.0)
        else {
            continue;
        };
        let r = net.region[p];
        if (0..np).any(|q| q != p && net.region[q] == r) {
            continue; // part of a guard net already
        }
        let face = mesh.faces[f as usize].clone();
        let k = face.len();
        let n = net.pieces.normal[p];
        let mean = face.iter().map(|&v| pos[v as usize]).sum::<DVec3>() / k as f64;
        let u = n.any_orthonormal_vector();
        let frame = (mean, u, n.cross(u));
        let flat_of = |x: DVec3| DVec2::new((x - frame.0).dot(frame.1), (x - frame.0).dot(frame.2));
        let flat: Vec<DVec2> = face.iter().map(|&v| flat_of(pos[v as usize])).collect();
        let boundary: Vec<(DVec2, DVec2)> = (0..k).map(|i| (flat[i], flat[(i + 1) % k])).collect();
        let kernel = flat_of(g);
        for i in 0..k {
            let v = face[i];
            if net.inside(v) {
                continue;
            }
            let (fu, fv, fw) = (flat[(i + k - 1) % k], flat[i], flat[(i + 1) % k]);
            let short = (fu - fv).length().min((fw - fv).length());
            if (kernel - fv).length() <= GUARD_REACH * short {
                continue;
            }
            let Some(mut fan) = net.fan(v).filter(|x| x.closed) else {
                continue;
            };
            let m = fan.faces.len();
            let at: Vec<usize> = (0..m).filter(|&j| fan.faces[j] == p as u32).collect();
            let [j] = at[..] else { continue };
            // The neighbours across V's two edges of f: in V's fan, f lies between ring[j]
            // and ring[j + 1]; the face before it shares edge V–ring[j], the one after
            // V–ring[j + 1]. A nearly flat one whose guard changes along that edge (a step
            // (5') cell there) qualifies.
            let has_cell = |w: u32| {
                let key = (v.min(w), v.max(w));
                net.cells
                    .iter()
                    .any(|c| (c.v[0].min(c.v[1]), c.v[0].max(c.v[1])) == key)
            };
            let flat_neighbour = [
                (fan.faces[(j + m - 1) % m], fan.ring[j]),
                (fan.faces[(j + 1) % m], fan.ring[(j + 1) % m]),
            ]
            .iter()
            .any(|&(q, w)| net.pieces.normal[q as usize].dot(n) > FLAT_COS && has_cell(w));
            if !flat_neighbour {
                continue;
            }
            let Some(gn) = place(fu, fv, fw, kernel, &flat, &boundary, short) else {
                continue;
            };
            let g3 = frame.0 + gn.x * frame.1 + gn.y * frame.2;
            let q = net.pieces.faces.len() as u32;
            net.pieces.faces.push(face.clone());
            net.pieces.parent.push(f);
            net.pieces.normal.push(n);
            net.pieces.guard.push(true);
            net.pieces.center.push(g3 - n.dot(g3 - mean) * n);
            net.region.push(r);
            fan.faces[j] = q;
            net.set_fan(v, fan);
            // The two edges of f at V get their step (5') cells anew (f's guard now changes
            // along both).
            for w in [face[(i + k - 1) % k], face[(i + 1) % k]] {
                let key = (v.min(w), v.max(w));
                net.cells
                    .retain(|c| (c.v[0].min(c.v[1]), c.v[0].max(c.v[1])) != key);
                if let Some(cell) = flatnet::edge_cell(net, key.0, key.1) {
                    net.cells.push(cell);
                }
            }
            out.push((f, v, q));
        }
    }
    out
}

/// The new guard of corner fv (edges fu → fv → fw, counter-clockwise) on its interior bisector
/// at [`RADIUS`] × `short`, halved until it sees both edges and the segment to the kernel guard
/// crosses no edge of the polygon.
fn place(
    fu: DVec2,
    fv: DVec2,
    fw: DVec2,
    kernel: DVec2,
    flat: &[DVec2],
    boundary: &[(DVec2, DVec2)],
    short: f64,
) -> Option<DVec2> {
    let (du, dw) = ((fu - fv).normalize(), (fw - fv).normalize());
    let mut angle = dw.angle_to(du);
    if angle <= 0.0 {
        angle += std::f64::consts::TAU;
    }
    let half = 0.5 * angle;
    let dir = DVec2::new(
        dw.x * half.cos() - dw.y * half.sin(),
        dw.x * half.sin() + dw.y * half.cos(),
    );
    let mut r = RADIUS * short;
    for _ in 0..12 {
        let g = fv + r * dir;
        if flatnet::sees_corner(g, fu, fv, fw, flat, boundary)
            && !flatnet::crosses(g, kernel, boundary)
        {
            return Some(g);
        }
        r *= 0.5;
    }
    None
}
