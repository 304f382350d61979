#!/usr/bin/env python3
"""Regenerate the apatch-vs-Mitsuba comparison table (docs/mitsuba_table.md) and the side-by-side
pictures (renders/mitsuba/<scene>.png) for every scene in scenes/*.toml.

Per scene, in shaded mode at the same size and spp on both sides:
  1. `apatch export mitsuba` (tessellated surface as PLY, same sensor/film/emitters);
  2. Mitsuba renders the export (`scripts/mitsuba_render.py`, variant scalar_rgb), timed;
  3. `apatch render` renders the scene itself, timed;
  4. `apatch compare` gives PSNR and max error over R,G,B (and alpha), plus the picture.

Usage (from the repository root, after `bash .ci/run` or with MITSUBA_PYTHON set):

    cargo build --release
    python3 scripts/mitsuba_table.py [--width 400 --height 300] [--spp 256] [scenes/spot.toml ...]

Only the Python standard library is needed here; Mitsuba runs in MITSUBA_PYTHON or the venv
target/mitsuba-venv. Intermediate files (PLY, EXR) go to target/mitsuba-table/. Exit code 0 on
success, 2 on errors (one line on stderr).
"""

import argparse
import datetime
import glob
import json
import os
import platform
import re
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print("mitsuba_table: error: %s" % msg, file=sys.stderr)
    sys.exit(2)


def run(cmd, **kw):
    """Runs `cmd`, returning (stdout, stderr, wall seconds); fails with its stderr."""
    t = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    dt = time.monotonic() - t
    if r.returncode != 0:
        fail("%s: exit %d: %s" % (" ".join(cmd), r.returncode, r.stderr.strip()[-2000:]))
    return r.stdout, r.stderr, dt


def find_python(explicit):
    for p in (explicit, os.environ.get("MITSUBA_PYTHON"),
              os.path.join(ROOT, "target", "mitsuba-venv", "bin", "python")):
        if p and os.path.isfile(p):
            return p
    fail("no Mitsuba Python: set MITSUBA_PYTHON or run bash .ci/run (creates target/mitsuba-venv)")


def mitsuba_version(python):
    out, _, _ = run([python, "-c", "import mitsuba; print(mitsuba.__version__)"])
    return out.strip()


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


AUTO_TRIANGLES = 1_000_000


def one_scene(scene, args, python, work, previous):
    stem = os.path.splitext(os.path.basename(scene))[0]
    d = os.path.join(work, stem)
    os.makedirs(d, exist_ok=True)
    size = ["--width", str(args.width), "--height", str(args.height)] if args.width else []
    # 1. export; "auto" resolution: at least 8 intervals per patch edge, more (up to 64) until
    # the mesh has about AUTO_TRIANGLES triangles, so that chords of large patches (the cube's)
    # do not pull Mitsuba's silhouette inside apatch's.
    def export(res):
        out, _, t = run([args.apatch, "export", "mitsuba", scene, "-o", d, "--resolution",
                         str(res), "--spp", str(args.spp)] + size)
        m = re.search(r"\((\d+) vertices, (\d+) triangles\)", out)
        return (int(m.group(2)) if m else 0), t

    if args.resolution == "auto":
        res = 8
        triangles, t_export = export(res)
        if 0 < triangles < AUTO_TRIANGLES:
            res = min(64, int(8 * (AUTO_TRIANGLES / triangles) ** 0.5))
            triangles, t_export = export(res)
    else:
        try:
            res = int(args.resolution)
        except ValueError:
            fail("--resolution: expected a number or auto, got %r" % args.resolution)
        triangles, t_export = export(res)
    xml = os.path.join(d, stem + ".xml")
    mts_exr = os.path.join(d, "mitsuba.exr")
    # 2. Mitsuba (wall time of the whole process: PLY loading, BVH build and rendering)
    _, _, t_mts = run([python, os.path.join(ROOT, "scripts", "mitsuba_render.py"), xml, mts_exr,
                       "--quiet", "--variant", args.variant])
    # 3. apatch (wall time of the whole process: mesh, scheme, BVH, rendering)
    apatch_exr = os.path.join(d, "apatch.exr")
    old = previous.get(stem)
    if args.keep_apatch and old and os.path.isfile(apatch_exr) \
            and (old["width"], old["height"]) == (args.width or old["width"],
                                                  args.height or old["height"]):
        t_apatch, t_build, t_render = old["t_apatch"], old["t_build"], old["t_render"]
    else:
        _, err, t_apatch = run([args.apatch, "render", scene, "--mode", "shaded", "--spp",
                                str(args.spp), "--output", apatch_exr] + size)
        m = re.search(r"build ([0-9.]+) s, render ([0-9.]+) s", err)
        t_build, t_render = (float(m.group(1)), float(m.group(2))) if m else (None, None)
    # 4. compare
    pic = os.path.join(args.pictures, stem + ".png")
    out, _, _ = run([args.apatch, "compare", apatch_exr, mts_exr, "--channels", "R,G,B",
                     "--json", "--side-by-side", pic])
    rgb = json.loads(out)
    out, _, _ = run([args.apatch, "compare", apatch_exr, mts_exr, "--channels", "A", "--json"])
    alpha = json.loads(out)
    return {
        "scene": stem,
        "width": rgb["width"],
        "height": rgb["height"],
        "triangles": triangles,
        "resolution": res,
        "psnr": rgb["all"]["psnr"],
        "max": rgb["all"]["max_abs"],
        "rmse": rgb["all"]["rmse"],
        "ssim": rgb["ssim"],
        "alpha_psnr": alpha["all"]["psnr"],
        "t_export": t_export,
        "t_mitsuba": t_mts,
        "t_apatch": t_apatch,
        "t_build": t_build,
        "t_render": t_render,
        "picture": os.path.relpath(pic, ROOT),
    }


NOTES = """
Notes:
- Pictures (`renders/mitsuba/<scene>.png`): apatch | Mitsuba | per-pixel max |difference| over
  R, G, B, false colour scaled to the largest difference (legend at the bottom).
- Emitters: the scenes have a `directional` light and a `constant` environment. apatch shadows
  every delta light per sample and lights the environment by one cosine-weighted ray; Mitsuba's
  `direct` picks one emitter at random per sample, which alone keeps 256-spp comparisons near
  36 dB (measured on spot at 400×300: 36.3 dB, pure noise: mean difference 2e-4, 8×8-block RMSE
  1/8 of the pixel RMSE). The export therefore gives the `constant` emitter `sampling_weight` 0
  when a delta light is present: the environment is then reached by BSDF sampling alone with MIS
  weight 1, the same estimator and the same expected image (spot: mean difference 1e-5).
  `emitter_samples` > 1 is no alternative: Mitsuba 3.9.1 scales the emitter term by the count.
- Remaining differences: silhouette pixels (Mitsuba's independent sampler estimates coverage
  with sd up to 0.031 at 256 spp; apatch uses a low-discrepancy pattern) and the tessellation
  that Mitsuba renders (flat triangles with interpolated normals; chords lie inside the surface,
  so a coarse export shrinks Mitsuba's silhouette: at resolution 8 the cube, whose few patches
  fill the frame, gave 34.8 dB with the error all along the silhouette, hence the automatic
  resolution; under a directional light facets that face away from it shadow themselves, the
  "shadow terminator").
  The max error sits on silhouette and shadow-boundary pixels.
- `--keep-apatch` reuses the apatch renders (and their times) of the previous run at the same
  size: apatch's image does not depend on the export resolution.
- Emitters are hidden from camera rays (`hide_emitters`), so both backgrounds are 0 and both
  alphas are coverage.
"""


def fmt_db(x):
    return "∞" if x is None else "%.1f" % x


def table(rows, args, python):
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = [
        "# apatch vs Mitsuba 3",
        "",
        "Generated by `python3 scripts/mitsuba_table.py%s` on %s: shaded mode, %d spp on both sides, "
        "box filter; Mitsuba %s (`%s`, `direct` integrator) renders the `apatch export mitsuba` "
        "scene, whose surface is the A-patch tessellation (`--resolution`, intervals per patch "
        "edge, in the table). PSNR and max error over linear R, G, B (peak 1); alpha PSNR over "
        "coverage. Times are wall clock of the whole process on the same machine "
        "(%s, %d cores, load average %.1f at the end: shared with other jobs, so absolute "
        "times are noisy; apatch includes building the A-patches, Mitsuba includes loading the PLY)."
        % (" " + " ".join(args.argv) if args.argv else "", datetime.date.today().isoformat(),
           args.spp, mitsuba_version(python), args.variant, cpu_name(),
           os.cpu_count() or 0, load),
        "",
        "| scene | size | export resolution, triangles | PSNR RGB (dB) | max error | alpha PSNR (dB) | SSIM "
        "| apatch time (s) (build + render) | Mitsuba time (s) | side by side |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    for r in rows:
        split = ("%.1f (%.1f + %.1f)" % (r["t_apatch"], r["t_build"], r["t_render"])
                 if r["t_build"] is not None else "%.1f" % r["t_apatch"])
        lines.append(
            "| %s | %d×%d | %s, %d | %s | %.3f | %s | %.4f | %s | %.1f | [png](../%s) |"
            % (r["scene"], r["width"], r["height"], r.get("resolution", "8"), r["triangles"], fmt_db(r["psnr"]), r["max"],
               fmt_db(r["alpha_psnr"]), r["ssim"], split, r["t_mitsuba"], r["picture"]))
    if args.width:
        lines += [
            "",
            "Size: %d×%d instead of the scenes' own (same view and aspect) to keep the run short on "
            "a shared 2-core machine: apatch's shaded renders ran at 0.1–0.25 M samples/s under "
            "that load (9–17 min per scene at 800×600×256), Mitsuba's scalar_rgb at 0.4–0.85 M "
            "samples/s. Without `--width/--height` the script uses each scene's size."
            % (args.width, args.height),
        ]
    return "\n".join(lines) + "\n" + NOTES


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="*", help="scene files (default: scenes/*.toml)")
    ap.add_argument("--width", type=int, help="image width (default: each scene's)")
    ap.add_argument("--height", type=int, help="image height (default: each scene's)")
    ap.add_argument("--spp", type=int, default=256, help="samples per pixel on both sides")
    ap.add_argument("--resolution", default="auto",
                    help="tessellation intervals per patch edge of the exported mesh, or auto "
                    "(8, raised up to 64 until the mesh has about 1M triangles)")
    ap.add_argument("--keep-apatch", action="store_true",
                    help="reuse apatch renders (and their times) of an earlier run of the same "
                    "size from target/mitsuba-table; only re-export, re-run Mitsuba and compare")
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant")
    ap.add_argument("--python", help="Python with mitsuba (default: MITSUBA_PYTHON or the venv)")
    ap.add_argument("--apatch", default=os.path.join(ROOT, "target", "release", "apatch"),
                    help="apatch binary (default: target/release/apatch)")
    ap.add_argument("--pictures", default=os.path.join(ROOT, "renders", "mitsuba"),
                    help="directory of the side-by-side PNGs")
    ap.add_argument("--table", default=os.path.join(ROOT, "docs", "mitsuba_table.md"),
                    help="markdown file to write")
    ap.add_argument("--rows", help="only rewrite the table from a rows.json of an earlier run "
                    "(target/mitsuba-table/rows.json), rendering nothing")
    args = ap.parse_args(argv)
    args.argv = [a for i, a in enumerate(argv)
                 if a != "--rows" and (i == 0 or argv[i - 1] != "--rows")]
    if (args.width is None) != (args.height is None):
        fail("give both --width and --height, or neither")
    if args.spp < 1:
        fail("--spp must be >= 1")
    if not os.path.isfile(args.apatch):
        fail("%s: no such file (cargo build --release)" % args.apatch)
    python = find_python(args.python)
    scenes = args.scenes or sorted(glob.glob(os.path.join(ROOT, "scenes", "*.toml")))
    if not scenes:
        fail("no scenes")
    work = os.path.join(ROOT, "target", "mitsuba-table")
    os.makedirs(args.pictures, exist_ok=True)
    rows = []
    previous = {}
    if os.path.isfile(os.path.join(work, "rows.json")):
        with open(os.path.join(work, "rows.json")) as f:
            previous = {r["scene"]: r for r in json.load(f)}
    if args.rows:
        with open(args.rows) as f:
            rows = json.load(f)
        scenes = []
    for s in scenes:
        r = one_scene(s, args, python, work, previous)
        print("%s: PSNR %s dB, max %.3f, apatch %.1f s, Mitsuba %.1f s"
              % (r["scene"], fmt_db(r["psnr"]), r["max"], r["t_apatch"], r["t_mitsuba"]),
              file=sys.stderr)
        rows.append(r)
    text = table(rows, args, python)
    os.makedirs(os.path.dirname(args.table), exist_ok=True)
    with open(args.table, "w") as f:
        f.write(text)
    if not args.rows:
        with open(os.path.join(work, "rows.json"), "w") as f:
            json.dump(rows, f, indent=1)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
