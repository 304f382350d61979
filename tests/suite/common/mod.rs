//! Helpers shared by the integration tests.

/// Sets `key` of a mesh scene's `[scheme]` table (a test's override of a shipped scene's
/// option); panics for scenes without a mesh model.
pub fn set_scheme(scene: &mut apatch::scene::Scene, key: &str, value: impl Into<toml::Value>) {
    let apatch::scene::Model::Mesh { scheme, .. } = &mut scene.model else {
        panic!("{}: not a mesh scene", scene.path.display());
    };
    scheme.insert(key.into(), value.into());
}
