//! `APATCH_QUINTIC_RESUME`: the quintic's last steps (here the hole repair) started from a
//! complex exported earlier from the same scene give what the whole build gives, bit for bit;
//! a complex of another scene is refused, naming the file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("quintic_resume_{name}"))
}

/// `apatch export patches scene -o out`, resumed from `resume` when given.
fn export(scene: &Path, out: &Path, resume: Option<&Path>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_apatch"));
    c.args(["export", "patches"]).arg(scene).arg("-o").arg(out);
    c.env_remove("APATCH_QUINTIC_RESUME");
    if let Some(r) = resume {
        c.env("APATCH_QUINTIC_RESUME", r);
    }
    c.output().expect("run apatch")
}

/// The shipped scene `name` (paper1994) copied with an absolute model path, `repair_holes`
/// set as asked and Theorem 2.1's pins off (so the torus has holes to repair).
fn scene(name: &str, repair: bool) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(format!("scenes/paper1994/{name}.toml")))
        .unwrap()
        .replace(
            "\"../models/",
            &format!("\"{}/", root.join("scenes/models").display()),
        )
        .replace("\nsigns = true", "\n")
        .replace(
            "type = \"quintic-c2\"",
            &format!("type = \"quintic-c2\"\nrepair_holes = {repair}"),
        );
    let path = tmp(&format!("{name}_{repair}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn holes(path: &Path) -> usize {
    let c = apatch::complex_io::read_json_file(path).unwrap();
    let r = apatch::check::check(&c, &apatch::check::CheckOptions::default());
    r.holes.crossing
}

#[test]
fn resumed_repair_equals_the_whole_build() {
    let plain = tmp("torus_plain.json");
    let o = export(&scene("torus_quad_quintic", false), &plain, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let repairing = scene("torus_quad_quintic", true);
    let direct = tmp("torus_direct.json");
    let o = export(&repairing, &direct, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed = tmp("torus_resumed.json");
    let o = export(&repairing, &resumed, Some(&plain));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The repair had work to do (the plain solve leaves holes), and did it on the resumed
    // values exactly as after the solve.
    assert!(holes(&plain) > 0);
    assert_eq!(holes(&resumed), holes(&direct));
    assert!(
        std::fs::read(&resumed).unwrap() == std::fs::read(&direct).unwrap(),
        "the resumed repair differs from the whole build's"
    );
}

#[test]
fn a_complex_of_another_scene_is_refused() {
    let other = tmp("l_rounded.json");
    let o = export(&scene("l_rounded_quintic", false), &other, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = tmp("refused.json");
    let _ = std::fs::remove_file(&out);
    let o = export(&scene("torus_quad_quintic", true), &out, Some(&other));
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&other.display().to_string()) && err.contains("APATCH_QUINTIC_RESUME"),
        "{err}"
    );
    assert!(!out.exists(), "no output on bad input");
}
