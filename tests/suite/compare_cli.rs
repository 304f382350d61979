//! `apatch compare` end to end: EXRs written here with the `exr` crate (f32 like apatch, f16
//! like Mitsuba's default hdrfilm), JSON output, pictures, and one-line errors with exit 2.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("apatch-compare-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes a one-layer EXR; `half` stores f16 samples.
fn write_exr(path: &Path, w: usize, h: usize, chans: &[(&str, Vec<f32>)], half: bool) {
    use exr::prelude::*;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = chans
        .iter()
        .map(|(n, v)| {
            let s = if half {
                FlatSamples::F16(v.iter().map(|x| f16::from_f32(*x)).collect())
            } else {
                FlatSamples::F32(v.clone())
            };
            AnyChannel::new(*n, s)
        })
        .collect();
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("test"),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

fn rgba(w: usize, h: usize, offset: f32) -> Vec<(&'static str, Vec<f32>)> {
    let base = |k: usize| -> Vec<f32> {
        (0..w * h)
            .map(|i| 0.25 + 0.125 * ((i + k) % 4) as f32 + offset)
            .collect()
    };
    vec![
        ("R", base(0)),
        ("G", base(1)),
        ("B", base(2)),
        ("A", base(3)),
    ]
}

fn apatch(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_apatch"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn json_reports_known_rmse_and_writes_pictures() {
    let d = scratch("json");
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    // apatch-like file with extra channels; reference in f16 without them. Values are
    // multiples of 1/8 (exact in f16) so the offset 0.25 is exact.
    let mut ca = rgba(20, 10, 0.0);
    ca.push(("Z", vec![3.0; 200]));
    ca.push(("normal.X", vec![0.5; 200]));
    write_exr(&a, 20, 10, &ca, false);
    write_exr(&b, 20, 10, &rgba(20, 10, 0.25), true);
    let (diff, sbs) = (d.join("diff.png"), d.join("sbs.png"));
    let out = apatch(&[
        "compare",
        s(&a),
        s(&b),
        "--json",
        "--diff",
        s(&diff),
        "--side-by-side",
        s(&sbs),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = j["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["R", "G", "B", "A"]);
    // Exact binary fractions: RMSE exactly 0.25, PSNR = 20 log10(4) dB (1e-12: log rounding).
    assert_eq!(j["all"]["rmse"], 0.25);
    let psnr = j["all"]["psnr"].as_f64().unwrap();
    assert!((psnr - 20.0 * 4f64.log10()).abs() < 1e-12);
    assert_eq!(j["all"]["above_threshold"], 1.0);
    assert!(j["ssim"].as_f64().unwrap() < 1.0);

    let di = image::open(&diff).unwrap();
    let legend = apatch::compare::picture::LEGEND_HEIGHT as u32;
    // The picture is at least 96 px wide so the legend's labels fit.
    assert_eq!((di.width(), di.height()), (96, 10 + legend));
    let sb = image::open(&sbs).unwrap();
    assert_eq!(
        (sb.width(), sb.height()),
        (96, 10 + legend),
        "3·20 + 2·4 < 96"
    );
    // A constant difference maps every difference pixel to the top of the scale.
    let top = sb.to_rgb8().get_pixel(2 * 24 + 3, 4).0;
    assert_eq!(top, [255, 255, 190]);
    // Atomic writes leave no temporary files behind.
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".partial-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn identical_files_report_null_psnr_and_text_inf() {
    let d = scratch("same");
    let a = d.join("a.exr");
    write_exr(&a, 8, 8, &rgba(8, 8, 0.0), false);
    let out = apatch(&["compare", s(&a), s(&a), "--json"]);
    assert!(out.status.success());
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(j["all"]["psnr"].is_null());
    assert_eq!(j["ssim"], 1.0);
    let out = apatch(&["compare", s(&a), s(&a), "--channels", "G"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains(" inf "), "{text}");
    assert!(!text.contains("\nR "), "only G compared: {text}");
    std::fs::remove_dir_all(&d).unwrap();
}

fn expect_error(args: &[&str], needle: &str) {
    let out = apatch(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.contains(needle), "{err} lacks {needle}");
}

#[test]
fn bad_inputs_are_one_line_errors() {
    let d = scratch("bad");
    let (a, small, text) = (d.join("a.exr"), d.join("small.exr"), d.join("t.exr"));
    write_exr(&a, 8, 8, &rgba(8, 8, 0.0), false);
    write_exr(&small, 8, 4, &rgba(8, 4, 0.0), false);
    std::fs::write(&text, "not an image\n").unwrap();
    expect_error(&["compare", s(&a), s(&small)], "sizes differ: 8×8 vs 8×4");
    expect_error(&["compare", s(&a), s(&text)], "t.exr: not a readable EXR");
    expect_error(
        &["compare", s(&a), s(&d.join("missing.exr"))],
        "missing.exr",
    );
    expect_error(
        &["compare", s(&a), s(&a), "--channels", "R,Z"],
        "channel Z is missing from the first image",
    );
    expect_error(&["compare", s(&a), s(&a), "--peak", "0"], "--peak");
    let nan = d.join("nan.exr");
    let mut c = rgba(8, 8, 0.0);
    c[1].1[10] = f32::NAN;
    write_exr(&nan, 8, 8, &c, false);
    expect_error(
        &["compare", s(&a), s(&nan)],
        "channel G pixel (2, 1) is NaN",
    );
    // A failed comparison writes no picture.
    let diff = d.join("never.png");
    expect_error(&["compare", s(&a), s(&small), "--diff", s(&diff)], "sizes");
    assert!(!diff.exists());
    std::fs::remove_dir_all(&d).unwrap();
}
