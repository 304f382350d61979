//! `check` on complexes of the rational C1 scheme (2001): a real scheme's promise is kept, and
//! breaking one rational weight is caught — through the library and the CLI.

use apatch::check::{check, CheckOptions};
use apatch::complex::{PatchComplex, Role};
use apatch::complex_io::write_json_file;
use apatch::scheme::rational_c1::{build, RationalOptions};
use std::path::Path;
use std::process::Command;

/// A unit icosahedron with normals tilted by `tilt` (deterministic) and one vertex pulled out.
fn icosahedron_complex(tilt: f64) -> PatchComplex {
    let (mut v, f) = apatch::fixtures::icosahedron();
    let n = apatch::fixtures::tilted_normals(&v, tilt);
    v[0] *= 1.0 + tilt;
    build(&v, &f, &n, &RationalOptions::default())
        .expect("icosahedron builds")
        .complex
}

#[test]
fn rational_c1_keeps_its_promise() {
    for tilt in [0.0, 0.2] {
        let c = icosahedron_complex(tilt);
        assert!(c.patches.iter().any(|p| !p.rational.is_empty()));
        let r = check(&c, &CheckOptions::default());
        assert_eq!(r.continuity, 1);
        assert_eq!(r.faces.overshared + r.faces.t_junctions, 0, "{r}");
        assert!(r.faces.shared > 0);
        // C1 by construction: rounding only (tolerance is the default 1e-9).
        assert!(r.value_jump.worst < 1e-12, "{r}");
        assert!(r.gradient_jump.worst < 1e-12, "{r}");
        // Not C2: the Hessian jumps are O(1), so the measure is not vacuous.
        assert!(r.hessian_jump.worst > 1e-3, "{r}");
        assert_eq!(r.interpolation.value.samples, 120);
        assert!(r.interpolation.normal_angle.worst < 1e-12, "{r}");
        assert!(r.sheets.shooting_lines > 0);
        assert_eq!(r.sheets.non_simple, 0, "{r}");
        assert!(r.passed(), "{r}");
        // Held to C2 it fails on the Hessian only.
        let c2 = CheckOptions {
            continuity: Some(2),
            ..CheckOptions::default()
        };
        assert_eq!(check(&c, &c2).failures(), vec!["hessian jump"]);
    }
}

#[test]
fn broken_rational_weight_is_caught() {
    let mut c = icosahedron_complex(0.1);
    // Term (4.1) of a face patch blends a, b, c; `a` (monomial α2α3) alone shapes the gradient
    // on the side face α1 = 0, shared with an edge tetrahedron.
    let (pi, p) = c
        .patches
        .iter_mut()
        .enumerate()
        .find(|(_, p)| p.role == Role::Face && !p.rational.is_empty())
        .unwrap();
    let term = p.rational[0]
        .terms
        .iter_mut()
        .find(|(_, mu)| *mu == [0, 1, 1, 0])
        .expect("α2α3 monomial");
    term.0 += 1e-4;
    let r = check(&c, &CheckOptions::default());
    assert!(r.value_jump.worst < 1e-12, "values untouched: {r}");
    assert!(r.gradient_jump.worst > 1e-6, "{r}");
    assert!(
        r.gradient_jump.at.as_ref().unwrap().patches.contains(&pi),
        "{r}"
    );
    assert!(!r.passed());

    // The same through the CLI: exit 1, jump reported; the intact complex exits 0.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let broken = dir.join("check_rational_broken.json");
    write_json_file(&c, &broken).unwrap();
    let good = dir.join("check_rational_good.json");
    write_json_file(&icosahedron_complex(0.1), &good).unwrap();
    let run = |p: &Path| {
        Command::new(env!("CARGO_BIN_EXE_apatch"))
            .arg("check")
            .arg(p)
            .output()
            .unwrap()
    };
    let o = run(&good);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let o = run(&broken);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(out.contains("FAILED: gradient jump"), "{out}");
}
