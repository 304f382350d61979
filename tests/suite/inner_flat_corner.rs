//! Face tetrahedra stand off their base for the quintic (`hull::inner::degenerate::repair_below`
//! with `verify::C2_MIN_VOLUME`): a nearly flat trihedral corner (three faces a few 1e-5 rad
//! apart, beyond `coplanar::NORMAL_TOL`, so not merged) gets Algorithm 1 step (3)'s triangle
//! C_1C_2C_3 with the apex V almost in its plane, a sliver that verify's degeneracy bound keeps.
//! The nut has one (input vertex 445, relative volumes 7e-8 and 2e-8); its C2 rows carry the
//! sliver's barycentrics squared (7e10).

use apatch::fixtures::flattest_face_tet;
use apatch::hull::inner::{self, verify::C2_MIN_VOLUME, InnerOptions};
use apatch::mesh::{self, Mesh, NormalMethod};
use glam::DVec3;
use std::path::Path;

/// A tetrahedron whose bottom face is split at its centroid, the centre moved out by `h`: the
/// centre is a trihedral corner whose three faces are nearly coplanar.
fn split_tetrahedron(h: f64) -> Mesh {
    let positions = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(1.0 / 3.0, 1.0 / 3.0, -h),
    ];
    // Counter-clockwise from outside; the bottom [0 2 1] (normal −z) split at vertex 4.
    let faces = vec![
        vec![0, 1, 3],
        vec![1, 2, 3],
        vec![2, 0, 3],
        vec![0, 2, 4],
        vec![2, 1, 4],
        vec![1, 0, 4],
    ];
    Mesh::new(positions, faces)
}

/// The cubic keeps verify's bound (its hull has the flat trihedral tetrahedron, which it
/// tolerates); with the quintic's bound every face tetrahedron is rebuilt to at least
/// `C2_MIN_VOLUME` and the hull still verifies.
#[test]
fn nearly_flat_trihedral_corner_stands_off_its_base_for_the_quintic() {
    // 1e-5 out of a unit face: its three parts' normals are ~4e-5 rad apart (not merged).
    let m = split_tetrahedron(1e-5);
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let cubic = inner::build(&m, &normals, &InnerOptions::default()).unwrap();
    let sliver = flattest_face_tet(&cubic);
    // The sliver: the apex V stands ~1e-5 off the centroids' plane (measured below 1e-4).
    assert!(sliver < 1e-4, "{sliver:e}");
    let opts = InnerOptions {
        min_volume: C2_MIN_VOLUME,
        ..InnerOptions::default()
    };
    let (quintic, report) = inner::build_with_report(&m, &normals, &opts).unwrap();
    assert!(report.degenerate_repaired >= 1, "{report:?}");
    let thick = flattest_face_tet(&quintic);
    assert!(thick >= C2_MIN_VOLUME, "{thick:e}");
    let v = inner::verify(&quintic);
    assert!(v.is_empty(), "{v:?}");
}

/// `InnerOptions::from_toml` takes the quintic's bound from the scheme type; the cubic keeps
/// verify's.
#[test]
fn scheme_type_sets_the_stand_off_bound() {
    let scene = Path::new("x.toml");
    let q: toml::Table = toml::from_str("type = \"quintic-c2\"").unwrap();
    let c: toml::Table = toml::from_str("type = \"cubic-c1\"").unwrap();
    assert_eq!(
        InnerOptions::from_toml(&q, scene).unwrap().min_volume,
        C2_MIN_VOLUME
    );
    assert_eq!(
        InnerOptions::from_toml(&c, scene).unwrap().min_volume,
        inner::verify::DEGENERATE_VOLUME
    );
}

/// The nut (its scene's `ring_normals = 1`): the quintic's hull has no sliver left (the
/// flattest face tetrahedron was 1.9e-8; the next flattest, 2.9e-3, is untouched) and
/// verifies; the cubic's hull is unchanged (the sliver stays: `scenes/paper1994/nut.toml`
/// passes with it).
#[test]
fn nut_quintic_hull_has_no_sliver() {
    let (m, _) = mesh::load(Path::new("scenes/models/nut_pyvista.obj")).unwrap();
    let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
    let cubic = InnerOptions {
        ring_normals: 1.0,
        ..InnerOptions::default()
    };
    let quintic = InnerOptions {
        min_volume: C2_MIN_VOLUME,
        ..cubic.clone()
    };
    let hc = inner::build(&m, &normals, &cubic).unwrap();
    // Measured 1.89e-8 (hull triangle 1967).
    assert!(
        flattest_face_tet(&hc) < 1e-7,
        "{:e}",
        flattest_face_tet(&hc)
    );
    let (hq, report) = inner::build_with_report(&m, &normals, &quintic).unwrap();
    assert_eq!(report.degenerate_repaired, 1);
    // Measured 2.906e-3: the next flattest of the cubic's hull.
    assert!(
        flattest_face_tet(&hq) >= C2_MIN_VOLUME,
        "{:e}",
        flattest_face_tet(&hq)
    );
    let v = inner::verify(&hq);
    assert!(
        v.is_empty(),
        "{} violations: {:?}",
        v.len(),
        &v[..v.len().min(5)]
    );
    // Only the sliver's triangle changed.
    let changed: Vec<usize> = (0..hc.triangles.len())
        .filter(|&t| hc.apexes[t] != hq.apexes[t])
        .collect();
    assert_eq!(changed, vec![1967]);
}
