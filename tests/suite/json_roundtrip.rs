//! The patch-complex JSON: bit-exact round trips and a clear error for every kind of bad input.

use apatch::complex::{Patch, PatchComplex, RationalTerm, Role, SheetRule};
use apatch::complex_io::{from_json_str, read_json_file, to_json_string, write_json_file};
use apatch::error::Error;
use apatch::fixtures::{quadric_complex, Quadric};
use glam::DVec3;
use std::path::{Path, PathBuf};

/// Awkward doubles: subnormals, -0, 0.1+0.2, huge and tiny, and many-digit values.
fn awkward() -> Vec<f64> {
    vec![
        f64::from_bits(1),
        f64::from_bits(0x000f_ffff_ffff_ffff),
        f64::MIN_POSITIVE,
        -0.0,
        0.0,
        0.1 + 0.2,
        1e300,
        -1e300,
        f64::MAX,
        f64::MIN,
        f64::EPSILON,
        1.0 / 3.0,
        -2.0f64.sqrt(),
        123_456_789.123_456_78,
        5e-324,
        9_007_199_254_740_993.0,
        std::f64::consts::PI,
        1e-300,
        -7.0,
        0.5,
    ]
}

fn awkward_complex() -> PatchComplex {
    let mut c = PatchComplex::new("cubic-c1");
    c.continuity = Some(2);
    let a = awkward();
    c.vertices = vec![[a[0], a[3], a[5]], [a[6], a[11], a[2]]];
    c.normals = vec![[a[3], a[4], 1.0], [a[12], a[13], a[1]]];
    c.patches.push(Patch {
        tet: [
            [0.1 + 0.2, -0.0, 0.0],
            [1.0, 1e-3, 0.0],
            [0.0, 1.0, 1.0 / 3.0],
            [0.0, 0.0, 1.0],
        ],
        degree: 3,
        weights: a.clone(),
        rational: vec![RationalTerm {
            index: [1, 1, 1, 0],
            terms: [
                (a[0], [0, 1, 1, 0]),
                (a[3], [1, 0, 1, 0]),
                (a[6], [1, 1, 0, 0]),
            ]
            .into(),
        }],
        sheet: SheetRule::Shooting {
            base: [0, 1, 2].into(),
            top: [3].into(),
        },
        role: Role::Face,
        element: 7,
        jvertex: None,
        jedge: None,
    });
    c
}

fn bits(c: &PatchComplex) -> Vec<u64> {
    let mut out = Vec::new();
    for v in c.vertices.iter().chain(&c.normals) {
        out.extend(v.map(f64::to_bits));
    }
    for p in &c.patches {
        out.extend(p.tet.iter().flatten().map(|x| x.to_bits()));
        out.extend(p.weights.iter().map(|x| x.to_bits()));
        for r in &p.rational {
            out.extend(r.terms.iter().map(|(w, _)| w.to_bits()));
        }
    }
    out
}

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("json_roundtrip_{name}"))
}

#[test]
fn awkward_numbers_round_trip_bit_for_bit() {
    let c = awkward_complex();
    let text = to_json_string(&c).unwrap();
    let back = from_json_str(&text, Path::new("mem.json")).unwrap();
    assert_eq!(bits(&back), bits(&c));
    assert_eq!(back.patches[0].sheet, c.patches[0].sheet);
    assert_eq!(back.patches[0].rational[0].index, [1, 1, 1, 0]);
    assert_eq!(back.continuity, Some(2));
    assert_eq!(back.patches[0].role, Role::Face);
    // -0.0 keeps its sign.
    assert!(back.patches[0].weights[3].is_sign_negative());
    // Writing again gives the same text.
    assert_eq!(to_json_string(&back).unwrap(), text);
}

#[test]
fn file_round_trip_of_a_fixture() {
    let q = Quadric::ellipsoid(DVec3::new(0.1, 0.2, -0.3), DVec3::new(0.9, 0.7, 1.1));
    let c = quadric_complex(&q, DVec3::splat(-1.3), DVec3::splat(1.1), 2, 5);
    let path = tmp("fixture.json");
    write_json_file(&c, &path).unwrap();
    let back = read_json_file(&path).unwrap();
    assert_eq!(bits(&back), bits(&c));
    assert_eq!(back, c);
    // Optional fields are omitted when empty / default.
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(!text.contains("\"rational\""));
    assert!(!text.contains("\"sheet\""));
    assert!(!text.contains("\"continuity\""));
    assert!(text.starts_with("{\"format\":\"apatch-patches\",\"version\":1,"));
}

/// A valid one-patch file with `patch` spliced in as the only patch.
fn with_patch(patch: &str) -> String {
    format!(
        r#"{{"format":"apatch-patches","version":1,"scheme":"test","vertices":[],"normals":[],
"patches":[{GOOD},
{patch}]}}"#
    )
}

const GOOD: &str = r#"{"tet":[[0,0,0],[1,0,0],[0,1,0],[0,0,1]],"degree":1,"weights":[1,2,3,4],"role":"face","element":0}"#;

fn error_of(text: &str) -> String {
    match from_json_str(text, Path::new("bad.json")) {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => {
            let m = e.to_string();
            assert!(m.starts_with("bad.json: "), "names the file: {m}");
            assert!(!m.contains('\n'), "one line: {m}");
            m
        }
    }
}

#[test]
fn good_template_is_accepted() {
    let c = from_json_str(&with_patch(GOOD), Path::new("ok.json")).unwrap();
    assert_eq!(c.patches.len(), 2);
}

#[test]
fn bad_numbers_name_the_patch() {
    for (weights, what) in [
        (r#"[1,2,"NaN",4]"#, "invalid type: string"),
        (r#"[1,2,null,4]"#, "invalid type: null"),
        (r#"[1,2,1e400,4]"#, "out of range"),
        (r#"[1,2,-1e999,4]"#, "out of range"),
        (r#"[1,2,NaN,4]"#, "expected value"),
    ] {
        let p = GOOD.replace("[1,2,3,4]", weights);
        let m = error_of(&with_patch(&p));
        assert!(m.contains("patch 1"), "{weights}: {m}");
        assert!(m.contains(what), "{weights}: {m}");
        assert!(m.contains("line 3"), "{weights}: {m}");
    }
}

#[test]
fn wrong_weight_count_and_degree() {
    let m = error_of(&with_patch(&GOOD.replace("[1,2,3,4]", "[1,2,3]")));
    assert!(m.contains("patch 1: 3 weights for degree 1"), "{m}");
    for (degree, msg) in [
        ("0", "degree 0 is not in 1..=7"),
        ("8", "degree 8 is not in 1..=7"),
        ("300", "patch 1"),
        ("-1", "patch 1"),
        ("2.5", "patch 1"),
    ] {
        let m = error_of(&with_patch(
            &GOOD.replace("\"degree\":1", &format!("\"degree\":{degree}")),
        ));
        assert!(m.contains(msg), "degree {degree}: {m}");
        assert!(m.contains("patch 1"), "degree {degree}: {m}");
    }
}

#[test]
fn bad_structure() {
    let cases = [
        (
            with_patch(GOOD).replace("apatch-patches", "other"),
            "not an apatch-patches file",
        ),
        (
            with_patch(GOOD).replace("\"version\":1", "\"version\":2"),
            "unsupported version 2",
        ),
        (with_patch(GOOD)[..60].to_string(), "EOF"),
        ("".to_string(), "EOF"),
        ("[1,2]".to_string(), "invalid type"),
        (
            with_patch(GOOD).replace("\"normals\":[]", "\"normals\":[[0,0,1]]"),
            "1 normals for 0 vertices",
        ),
        (
            with_patch(&GOOD.replace("[0,0,1]]", "[1,1,0]]")),
            "patch 1: degenerate tetrahedron",
        ),
        (
            with_patch(&GOOD.replace("[0,0,1]]", "[0,0,0]]")),
            "patch 1: degenerate tetrahedron",
        ),
        (
            with_patch(&GOOD.replace("\"face\"", "\"blob\"")),
            "patch 1: unknown variant",
        ),
        (
            with_patch(&GOOD.replace("\"tet\":[[0,0,0],", "\"tet\":[")),
            "patch 1",
        ),
        (
            with_patch(&GOOD.replace(
                "\"role\"",
                r#""rational":[{"index":[1,1,0,0],"terms":[[1,[1,0,0,0]]]}],"role""#,
            )),
            "patch 1: rational term 0: index [1, 1, 0, 0] sums to 2, not the degree 1",
        ),
        (
            with_patch(&GOOD.replace(
                "\"role\"",
                r#""rational":[{"index":[1,0,0,0],"terms":[]}],"role""#,
            )),
            "patch 1: rational term 0: no terms",
        ),
        (
            with_patch(&GOOD.replace(
                "\"role\"",
                r#""sheet":{"rule":"shooting","base":[0,1],"top":[1,3]},"role""#,
            )),
            "patch 1: sheet rule",
        ),
    ];
    for (text, msg) in cases {
        let m = error_of(&text);
        assert!(m.contains(msg), "expected `{msg}` in: {m}");
    }
}

#[test]
fn missing_file_is_an_io_error() {
    let e = read_json_file(Path::new("/nonexistent/patches.json")).unwrap_err();
    assert!(matches!(e, Error::Input { .. }));
    assert!(e.to_string().contains("cannot open"), "{e}");
    assert!(
        e.to_string().starts_with("/nonexistent/patches.json: "),
        "{e}"
    );
}

#[test]
fn writing_refuses_non_finite_numbers() {
    let mut c = awkward_complex();
    c.patches[0].weights[4] = f64::NAN;
    let e = to_json_string(&c).unwrap_err().to_string();
    assert!(e.contains("patch 0: weight 4 is not finite"), "{e}");
    let mut c = awkward_complex();
    c.vertices[1][0] = f64::INFINITY;
    assert!(to_json_string(&c).is_err());
    assert!(!tmp("never.json").exists() || std::fs::remove_file(tmp("never.json")).is_ok());
    assert!(write_json_file(&c, &tmp("never.json")).is_err());
    assert!(
        !tmp("never.json").exists(),
        "nothing written for invalid data"
    );
}
