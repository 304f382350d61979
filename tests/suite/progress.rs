//! The library's progress messages (`apatch::progress`): a quintic scene's build names its
//! steps to an installed sink, in order, and the build is the same with or without one. Its own
//! test binary: the sink is process-wide.

use std::path::Path;
use std::sync::{Arc, Mutex};

#[test]
fn a_quintic_build_reports_its_steps_and_is_unchanged_by_them() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper1994/l_prism_quintic.toml");
    let scene = apatch::scene::load(&path).unwrap();
    let quiet = apatch::scene::build_complex(&scene).unwrap();

    let seen = Arc::new(Mutex::new(Vec::<String>::new()));
    let sink = Arc::clone(&seen);
    apatch::progress::set_sink(Some(Box::new(move |m: &str| {
        sink.lock().unwrap().push(m.to_string());
    })));
    let heard = apatch::scene::build_complex(&scene).unwrap();
    apatch::progress::set_sink(None);
    assert_eq!(heard, quiet, "a sink changed the patches");

    let heard_all = Arc::clone(&seen);
    let seen = seen.lock().unwrap().clone();
    let at = |what: &str| {
        seen.iter()
            .position(|m| m.starts_with(what))
            .unwrap_or_else(|| panic!("no `{what}` in {seen:#?}"))
    };
    // The hull first, then the first pass's stages in the paper's order.
    let hull = at("building the inner hull");
    let pass = at("quintic-c2 solve: pass 1");
    let middles = at("quintic-c2 solve: edge middles");
    let stars = at("quintic-c2 solve: vertex stars");
    let last = at("quintic-c2 solve: edge tetrahedra");
    assert!(
        hull < pass && pass < middles && middles < stars && stars < last,
        "{seen:#?}"
    );

    // The sink removed, a build reaches it no more.
    apatch::scene::build_complex(&scene).unwrap();
    assert_eq!(heard_all.lock().unwrap().len(), seen.len());
}
