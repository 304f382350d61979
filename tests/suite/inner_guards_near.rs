//! Corner guards near their corners (Algorithm 2 step (1) with Appendix B's corner guard
//! circles; `hull::inner::decompose::guard_is_near`, `hull::inner::guardnet`): a star-shaped
//! face whose kernel lies far from some corner (mpi_poly's face 7: corners at x = +10 served
//! from x = −8) is split and gets a corner guard net whose guards sit near the corners they
//! serve, and the hull built on it is smoothable.

use apatch::hull::inner::{
    self, coplanar, decompose, guardnet::GuardNet, verify::euler_characteristic, InnerOptions,
};
use apatch::mesh::{self, Mesh, NormalMethod};
use glam::DVec3;

/// An L prism (height 1) with a long arm along x whose end is chamfered: the corners of the
/// chamfer, (19.5, 0) → (20, 0.5) → (20, 1), have short edges (0.71 and 0.5) and lie 19.5 away
/// from the L's kernel, the unit square at the elbow (2.6 % of the area).
fn chamfered_l() -> (Mesh, Vec<(f64, f64)>) {
    let outline = vec![
        (0.0, 0.0),
        (19.5, 0.0),
        (20.0, 0.5),
        (20.0, 1.0),
        (1.0, 1.0),
        (1.0, 20.0),
        (0.0, 20.0),
    ];
    let n = outline.len() as u32;
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        p.extend(outline.iter().map(|&(x, y)| DVec3::new(x, y, z)));
    }
    let mut faces = vec![(0..n).rev().collect::<Vec<u32>>(), (n..2 * n).collect()];
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, j + n, i + n]);
    }
    (Mesh::new(p, faces), outline)
}

/// The caps' kernel guard is rejected (too far from the chamfer corners), so the caps are split
/// into convex pieces with a guard net; every corner's guard lies within
/// `GUARD_REACH` × its longer edge, far closer than the kernel guard.
#[test]
fn far_kernel_guard_is_replaced_by_a_near_guard_net() {
    let (m, outline) = chamfered_l();
    let merged = coplanar::merge_coplanar(&m);
    let top = &merged.faces[1];
    let g = decompose::kernel_guard(&merged.positions, top, DVec3::Z).expect("star shaped");
    // The kernel is the unit square at the elbow: its centroid (0.5, 0.5, 1).
    assert!((g - DVec3::new(0.5, 0.5, 1.0)).length() < 1e-9);
    assert!(!decompose::guard_is_near(&merged.positions, top, g));
    let pieces = decompose::convex_pieces(&merged).unwrap();
    assert!(pieces.star.is_empty(), "{:?}", pieces.star);
    assert_eq!(pieces.split.len(), 2, "{:?}", pieces.split);
    let net = GuardNet::build(&merged, pieces);
    assert!(net.fallback.is_empty(), "{:?}", net.fallback);
    assert_eq!(net.nets.len(), 2, "{:?}", net.nets);
    let k = outline.len();
    for cap in 0..2u32 {
        for i in 0..k {
            let v = cap * k as u32 + i as u32;
            let fan = net.fan(v).expect("closed fan");
            let pos = merged.positions[v as usize];
            // The cap's entry in the fan is the guard serving V in that cap.
            let guard = fan
                .faces
                .iter()
                .map(|&f| net.pieces.center[f as usize])
                .find(|c| (c.z - pos.z).abs() < 1e-12)
                .expect("a cap guard");
            let (a, b) = (outline[(i + k - 1) % k], outline[(i + 1) % k]);
            let here = outline[i];
            let e = ((a.0 - here.0).hypot(a.1 - here.1)).max((b.0 - here.0).hypot(b.1 - here.1));
            let d = (guard - pos).length();
            assert!(
                d <= decompose::GUARD_REACH * e,
                "corner {v} at {pos}: guard {guard} is {d} away, edges up to {e}"
            );
        }
    }
}

/// The hull on the guard net is smoothable (Definition 3.6, Lemmas 4.1–4.3) and T is a sphere.
/// Open: 8 overlaps remain between the outer face tetrahedron at the corner (0, 0) and the
/// hallway corner (1, 1)'s inner tetrahedra (depth 3.7e-3 of a unit-height prism).
#[test]
#[ignore = "open: 8 overlaps at the elbow of the chamfered L (see the doc comment)"]
fn chamfered_l_hull_verifies() {
    let (m, _) = chamfered_l();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let hull = inner::build(&m, &normals, &InnerOptions::default()).unwrap();
    let v = inner::verify(&hull);
    assert!(
        v.is_empty(),
        "{} violations: {:?}",
        v.len(),
        &v[..v.len().min(4)]
    );
    assert_eq!(euler_characteristic(&hull), Some(2));
}

/// The far kernel guards are remembered (`Pieces::far_star`), and `restore_stars` (used when
/// no guard net is found) puts such a polygon back whole with that guard.
#[test]
fn far_star_faces_can_be_restored_whole() {
    let (m, outline) = chamfered_l();
    let merged = coplanar::merge_coplanar(&m);
    let pieces = decompose::convex_pieces(&merged).unwrap();
    let far: Vec<u32> = pieces.far_star.iter().map(|&(f, _)| f).collect();
    assert_eq!(far, vec![0, 1]);
    let restored = pieces.restore_stars(&merged, &[1]);
    assert_eq!(restored.far_star.len(), 1);
    assert_eq!(restored.split.len(), 1);
    let whole: Vec<usize> = (0..restored.faces.len())
        .filter(|&p| restored.parent[p] == 1)
        .collect();
    assert_eq!(whole.len(), 1);
    let p = whole[0];
    assert_eq!(restored.faces[p].len(), outline.len());
    // The kernel guard of the top cap: (0.5, 0.5, 1) up to the clipping's rounding.
    assert!((restored.center[p] - DVec3::new(0.5, 0.5, 1.0)).length() < 1e-9);
    assert!(restored.star.iter().any(|&(f, _)| f == 1));
    // Every other piece is kept as it was.
    assert_eq!(
        restored.faces.len(),
        pieces.faces.len() - pieces.split.iter().find(|s| s.0 == 1).unwrap().1 + 1
    );
}
