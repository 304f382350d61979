//! Hostile and malformed inputs: every file in `tests/corpus/` (listed with its expected outcome
//! in `tests/corpus/EXPECTED.tsv`) gives the documented error or finding through the library, and
//! the matching exit code through `apatch info` — never a panic or a hang.

use apatch::mesh::{self, Format};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

struct Case {
    file: String,
    expect: String,
    what: String,
}

fn cases() -> Vec<Case> {
    let text = std::fs::read_to_string(corpus_dir().join("EXPECTED.tsv")).unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let mut p = l.split('\t');
            Case {
                file: p.next().unwrap().into(),
                expect: p.next().unwrap().into(),
                what: p.next().unwrap().into(),
            }
        })
        .collect()
}

/// Runs `apatch info` on `path` with a hang guard (the guard is not a speed test: a healthy run
/// takes milliseconds; 60 s only separates "finished" from "hung" on a loaded CI machine).
fn info(path: &Path) -> (ExitStatus, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_apatch"))
        .arg("info")
        .arg(path)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status, err);
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().ok();
            panic!("apatch info {} hung", path.display());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn corpus_has_at_least_30_hostile_inputs() {
    let hostile = cases().iter().filter(|c| c.expect != "note").count();
    assert!(hostile >= 30, "only {hostile} hostile inputs");
    // Every file in the directory is listed (so none is silently untested).
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name != "EXPECTED.tsv" {
            assert!(
                cases().iter().any(|c| c.file == name),
                "{name} is not in EXPECTED.tsv"
            );
        }
    }
}

#[test]
fn corpus_library_outcomes() {
    for c in cases() {
        let path = corpus_dir().join(&c.file);
        let result = mesh::load(&path);
        match (c.expect.as_str(), result) {
            ("error", Err(e)) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(&c.what),
                    "{}: error `{msg}` lacks `{}`",
                    c.file,
                    c.what
                );
                assert!(
                    msg.contains(&c.file),
                    "{}: error `{msg}` does not name the file",
                    c.file
                );
            }
            ("error", Ok(_)) => panic!("{}: loaded, expected an error", c.file),
            (_, Err(e)) => panic!("{}: unexpected error {e}", c.file),
            (expect, Ok((_, report))) => {
                let kinds: Vec<String> = report
                    .findings
                    .iter()
                    .map(|f| serde_json::to_string(&f.kind).unwrap().replace('"', ""))
                    .collect();
                assert!(
                    kinds.contains(&c.what),
                    "{}: findings {kinds:?} lack {}",
                    c.file,
                    c.what
                );
                assert_eq!(
                    report.has_warnings(),
                    expect == "warning",
                    "{}: {kinds:?}",
                    c.file
                );
            }
        }
    }
}

#[test]
fn corpus_cli_exit_codes() {
    for c in cases() {
        let (status, err) = info(&corpus_dir().join(&c.file));
        let want = match c.expect.as_str() {
            "error" => 2,
            "warning" => 1,
            _ => 0,
        };
        assert_eq!(status.code(), Some(want), "{}: stderr {err}", c.file);
        assert!(!err.contains("panicked"), "{}: {err}", c.file);
        if want == 2 {
            // One line naming the file.
            assert_eq!(err.lines().count(), 1, "{}: {err}", c.file);
            assert!(err.contains(&c.file), "{}: {err}", c.file);
        }
    }
}

/// Generated, not committed: a face with a million vertices on one line, a vertex line with a
/// million values, and a million-character junk token.
#[test]
fn million_element_lines_fail_fast() {
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for k in 0..1_000_000 {
        obj.push_str(if k % 3 == 0 {
            " 1"
        } else if k % 3 == 1 {
            " 2"
        } else {
            " 3"
        });
    }
    obj.push('\n');
    let e = mesh::load_bytes(obj.as_bytes(), Format::Obj, Path::new("big.obj")).unwrap_err();
    assert!(
        e.to_string()
            .contains("line 4: face has more than 4096 vertices"),
        "{e}"
    );

    let mut v = String::from("v");
    for _ in 0..1_000_000 {
        v.push_str(" 1.5");
    }
    let e = mesh::load_bytes(v.as_bytes(), Format::Obj, Path::new("v.obj")).unwrap_err();
    assert!(
        e.to_string().contains("line 1: vertex needs 3 coordinates"),
        "{e}"
    );

    let junk = "x".repeat(1_000_000);
    let e = mesh::load_bytes(junk.as_bytes(), Format::Obj, Path::new("j.obj")).unwrap_err();
    // The token is shortened in the message.
    assert!(e.to_string().len() < 200, "{e}");

    let mut off = String::from("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000");
    for k in 0..1_000_000 {
        off.push_str(if k % 2 == 0 { " 0" } else { " 1" });
    }
    let e = mesh::load_bytes(off.as_bytes(), Format::Off, Path::new("big.off")).unwrap_err();
    assert!(e.to_string().contains("at most 4096"), "{e}");
}
