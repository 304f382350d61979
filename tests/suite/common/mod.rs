//! Helpers shared by the integration tests.

/// Sets `key` of a mesh scene's `[scheme]` table (a test's override of a shipped scene's
/// option); panics for scenes without a mesh model.
pub fn set_scheme(scene: &mut apatch::scene::Scene, key: &str, value: impl Into<toml::Value>) {
    let apatch::scene::Model::Mesh { scheme, .. } = &mut scene.model else {
        panic!("{}: not a mesh scene", scene.path.display());
    };
    scheme.insert(key.into(), value.into());
}

/// The angles (degrees) of triangle `v` at its three corners, in order.
pub fn corner_angles(v: [glam::DVec3; 3]) -> [f64; 3] {
    std::array::from_fn(|k| {
        (v[(k + 1) % 3] - v[k])
            .angle_between(v[(k + 2) % 3] - v[k])
            .to_degrees()
    })
}
