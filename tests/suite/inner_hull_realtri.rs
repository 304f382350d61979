//! The inner hull (1994) on the real triangle models: with the face-tetrahedron sides taken from
//! the convexity of T's edges and the apexes over their bases (`hull::inner::sides`), `verify`
//! (Definition 3.6, Lemmas 4.1–4.3) accepts spot, knot and bunny, and every edge of T joins its
//! two triangles on the side its convexity asks for.

use apatch::hull::inner::sides::edge_sides;
use apatch::hull::inner::{self, verify::euler_characteristic, InnerOptions};
use apatch::mesh::{self, NormalMethod, Topology};
use std::path::Path;

#[test]
fn real_triangle_models_give_valid_hulls() {
    for name in ["spot.obj", "knot1.obj", "bunny_npm_lowres.obj"] {
        let (m, _) = mesh::load(&Path::new("scenes/models").join(name)).unwrap();
        let normals = mesh::vertex_normals(&m, NormalMethod::Angle).unwrap();
        let (hull, report) =
            inner::build_with_report(&m, &normals, &InnerOptions::default()).unwrap();
        let v = inner::verify(&hull);
        assert!(
            v.is_empty(),
            "{name}: {} violations, first: {:?}",
            v.len(),
            v.iter().take(3).collect::<Vec<_>>()
        );
        // Closed T of the input's genus (V − E + F of the polyhedron).
        let topo = Topology::new(m.positions.len(), &m.faces);
        let chi = m.positions.len() as i64 - topo.edges.len() as i64 + m.faces.len() as i64;
        assert_eq!(euler_characteristic(&hull), Some(chi), "{name}");
        // Independent of verify's NoEdgeTetrahedra test: every edge's own side is present on
        // both its triangles (the construction's invariant, recomputed here).
        for e in hull.edges().unwrap() {
            let [a, b] = e.v.map(|i| i as usize);
            let need = edge_sides(
                hull.points[a],
                hull.normals[a],
                hull.points[b],
                hull.normals[b],
            );
            for f in e.faces {
                for (s, &needed) in need.iter().enumerate() {
                    assert!(
                        !needed || hull.apexes[f as usize][s].is_some(),
                        "{name}: triangle {f} lacks side {s} of its edge ({a}, {b})"
                    );
                }
            }
        }
        assert!(report.sides.rebuilt > 0 && report.sides.kept == 0, "{name}");
    }
}
