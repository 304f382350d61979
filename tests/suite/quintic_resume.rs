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
    export_with(scene, out, resume, &[])
}

/// [`export`] with more environment variables.
fn export_with(scene: &Path, out: &Path, resume: Option<&Path>, env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_apatch"));
    c.args(["export", "patches"]).arg(scene).arg("-o").arg(out);
    for v in [
        "APATCH_QUINTIC_RESUME",
        "APATCH_HOLE_CHECKPOINT",
        "APATCH_HOLE_STOP_AFTER",
        "APATCH_HOLE_CHECKPOINT_EVERY",
        "APATCH_HOLE_EXIT_AFTER",
    ] {
        c.env_remove(v);
    }
    if let Some(r) = resume {
        c.env("APATCH_QUINTIC_RESUME", r);
    }
    c.envs(env.iter().copied());
    c.output().expect("run apatch")
}

/// The shipped scene `name` (paper1994) copied with an absolute model path, `repair_holes`
/// set as asked and Theorem 2.1's pins off (so the torus has holes to repair).
fn scene(name: &str, repair: bool) -> PathBuf {
    scene_with(
        name,
        &format!("repair_holes = {repair}"),
        &repair.to_string(),
    )
}

/// [`scene`] with the scheme keys `keys` instead, saved under a name ending in `tag`.
fn scene_with(name: &str, keys: &str, tag: &str) -> PathBuf {
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
            &format!("type = \"quintic-c2\"\n{keys}"),
        );
    let path = tmp(&format!("{name}_{tag}.toml"));
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

/// `APATCH_HOLE_CHECKPOINT`: a repair stopped after its first wave (`APATCH_HOLE_STOP_AFTER`,
/// as if its process had ended) and taken up again from its checkpoint gives the whole
/// build's complex, bit for bit.
#[test]
fn a_repair_taken_up_from_its_checkpoint_equals_the_whole_build() {
    let repairing = scene("torus_quad_quintic", true);
    let direct = tmp("ckpt_direct.json");
    let o = export(&repairing, &direct, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ckpt = tmp("torus.ckpt");
    let _ = std::fs::remove_file(&ckpt);
    let ckpt_s = ckpt.to_str().unwrap();
    let stopped = tmp("ckpt_stopped.json");
    let o = export_with(
        &repairing,
        &stopped,
        None,
        &[
            ("APATCH_HOLE_CHECKPOINT", ckpt_s),
            ("APATCH_HOLE_STOP_AFTER", "1"),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(ckpt.exists(), "the stopped repair saved its checkpoint");
    // Stopped part way: the whole repair mends more than its first wave.
    assert!(holes(&stopped) > holes(&direct));
    // Taken up with no wave to run (`APATCH_HOLE_STOP_AFTER=0`): the checkpoint's values as
    // they are, the stopped run's complex bit for bit, and the checkpoint left as it was.
    let saved = std::fs::read(&ckpt).unwrap();
    let as_saved = tmp("ckpt_as_saved.json");
    let o = export_with(
        &repairing,
        &as_saved,
        None,
        &[
            ("APATCH_HOLE_CHECKPOINT", ckpt_s),
            ("APATCH_HOLE_STOP_AFTER", "0"),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        std::fs::read(&as_saved).unwrap() == std::fs::read(&stopped).unwrap(),
        "the checkpoint's values differ from the stopped repair's"
    );
    assert!(std::fs::read(&ckpt).unwrap() == saved);
    let taken_up = tmp("ckpt_taken_up.json");
    let o = export_with(
        &repairing,
        &taken_up,
        None,
        &[
            ("APATCH_HOLE_CHECKPOINT", ckpt_s),
            ("APATCH_HOLE_TRACE", "1"),
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    // It did start from the checkpoint (a fresh repair would give the same complex too).
    assert!(err.contains("taken up from"), "{err}");
    assert!(
        std::fs::read(&taken_up).unwrap() == std::fs::read(&direct).unwrap(),
        "the repair taken up from its checkpoint differs from the whole build's"
    );
    // A file that is not a checkpoint is refused, naming it (a checkpoint of another repair
    // is refused the same way: `quintic_c2::checkpoint`'s unit test).
    std::fs::write(&ckpt, b"not a checkpoint").unwrap();
    let other = tmp("ckpt_other.json");
    let _ = std::fs::remove_file(&other);
    let o = export_with(
        &repairing,
        &other,
        None,
        &[("APATCH_HOLE_CHECKPOINT", ckpt_s)],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(ckpt_s) && err.contains("APATCH_HOLE_CHECKPOINT"),
        "{err}"
    );
    assert!(!other.exists(), "no output on bad input");
}

/// A repair whose process ends midway through a wave (`APATCH_HOLE_EXIT_AFTER`, with a
/// checkpoint after every finished repair) is taken up from the repairs of that wave saved so
/// far and gives the whole build's complex, bit for bit.
#[test]
fn a_repair_killed_midway_through_a_wave_is_taken_up_from_its_checkpoint() {
    let repairing = scene("torus_quad_quintic", true);
    let direct = tmp("mid_direct.json");
    let o = export(&repairing, &direct, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ckpt = tmp("torus_mid.ckpt");
    let _ = std::fs::remove_file(&ckpt);
    let ckpt_s = ckpt.to_str().unwrap();
    let killed = tmp("mid_killed.json");
    let _ = std::fs::remove_file(&killed);
    let o = export_with(
        &repairing,
        &killed,
        None,
        &[
            ("APATCH_HOLE_CHECKPOINT", ckpt_s),
            ("APATCH_HOLE_CHECKPOINT_EVERY", "0"),
            ("APATCH_HOLE_EXIT_AFTER", "1"),
        ],
    );
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(ckpt.exists() && !killed.exists());
    let taken_up = tmp("mid_taken_up.json");
    let o = export_with(
        &repairing,
        &taken_up,
        None,
        &[
            ("APATCH_HOLE_CHECKPOINT", ckpt_s),
            ("APATCH_HOLE_TRACE", "1"),
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    // Taken up at the first pass with the first repair of its first wave decided.
    assert!(err.contains("at pass 1 (1 defects decided)"), "{err}");
    assert!(
        std::fs::read(&taken_up).unwrap() == std::fs::read(&direct).unwrap(),
        "the repair taken up midway through a wave differs from the whole build's"
    );
}

/// `repair_widen`: a repair finished with fewer passes is taken up from its checkpoint by one
/// that asks for more, and gives the whole wider build's complex, bit for bit; one whose passes
/// differ from the checkpoint's is refused, naming the file. The torus without its pins,
/// started at 1 ring (`APATCH_HOLE_RINGS`, so that the second pass has something to do): one
/// pass leaves 20 of its 40 crossed faces, a second at 2 rings closes them.
#[test]
fn a_finished_repair_is_taken_up_with_more_passes() {
    let keys = |widen: usize, hessians: &str| {
        format!("repair_holes = true\nrepair_hessians = {hessians}\nrepair_widen = {widen}")
    };
    let narrow = scene_with("torus_quad_quintic", &keys(0, "\"all\""), "widen0");
    let wide = scene_with("torus_quad_quintic", &keys(1, "\"all\""), "widen1");
    let ckpt = tmp("torus_widen.ckpt");
    let _ = std::fs::remove_file(&ckpt);
    let ckpt_s = ckpt.to_str().unwrap();
    let run = |scene: &Path, out: &str, ckpt: bool| {
        let out = tmp(out);
        let _ = std::fs::remove_file(&out);
        let mut env = vec![("APATCH_HOLE_RINGS", "1"), ("APATCH_HOLE_TRACE", "1")];
        if ckpt {
            env.push(("APATCH_HOLE_CHECKPOINT", ckpt_s));
        }
        let o = export_with(scene, &out, None, &env);
        (out, o)
    };
    let ok = |o: &Output| assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (direct, o) = run(&wide, "widen_direct.json", false);
    ok(&o);
    let (first, o) = run(&narrow, "widen_first.json", true);
    ok(&o);
    // The one pass leaves holes the wider pass closes.
    assert!(
        holes(&first) > holes(&direct),
        "{} {}",
        holes(&first),
        holes(&direct)
    );
    let (taken_up, o) = run(&wide, "widen_taken_up.json", true);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("at pass 2 (0 defects decided)"), "{err}");
    assert!(
        std::fs::read(&taken_up).unwrap() == std::fs::read(&direct).unwrap(),
        "the repair taken up with more passes differs from the whole wider build's"
    );
    // Other passes than the checkpoint's (its first one with the Hessians held): refused.
    let other = scene_with("torus_quad_quintic", &keys(1, "true"), "widen1_last");
    let (out, o) = run(&other, "widen_other.json", true);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(ckpt_s) && err.contains("pass 1"), "{err}");
    assert!(!out.exists(), "no output on bad input");
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
