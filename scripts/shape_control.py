#!/usr/bin/env python3
"""Shape-control strip of the 1994 cubic scheme (§7.1, in the spirit of Figs. 7.10-7.11).

Renders scenes/paper1994/octahedron.toml in isophote mode at 256x256 (fov 16) with the settings in PANELS
(keys set in the scene's [scheme] table) and joins them left to right with scripts/png_strip.py
into renders/paper1994/shape_control_octahedron.png. A panel that sets `level` (or `levels` for
an element) uses the level rule for those free weights; the default panel uses the fair rule.

Usage: python3 scripts/shape_control.py [--apatch target/release/apatch]
Temporary scenes are written beside the scene (its paths are relative) and removed; the single
renders go to renders/tmp/shape_control/ (ignored by git).
"""
import argparse
import pathlib
import subprocess

from cut_distances import with_keys  # same [scheme] rewriting as the distance table

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes/paper1994/octahedron.toml"
OUT = ROOT / "renders/paper1994/shape_control_octahedron.png"
PANELS = [
    ("level03", {"level": "0.3"}),
    ("default", {}),
    ("level07", {"level": "0.7"}),
    ("alpha03", {"alpha": "0.3"}),
    ("alpha07", {"alpha": "0.7"}),
    ("levels", {"levels": '{ "0" = 0.8, "1" = 0.8 }'}),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--apatch", default=str(ROOT / "target/release/apatch"))
    args = ap.parse_args()
    tmp = ROOT / "renders/tmp/shape_control"
    tmp.mkdir(parents=True, exist_ok=True)
    # Closer view than the scene's (fov 30) so each 256-pixel panel shows the surface large.
    text = SCENE.read_text().replace("\nfov = 30\n", "\nfov = 16\n")
    assert "fov = 16" in text, "octahedron.toml's camera changed: adjust the fov override"
    pngs = []
    for name, keys in PANELS:
        scene = SCENE.with_name(f".shape_control_{name}.toml")
        scene.write_text(with_keys(text, keys))
        png = tmp / f"{name}.png"
        try:
            subprocess.run([args.apatch, "render", str(scene), "--mode", "isophote",
                            "--width", "256", "--height", "256", "--output", str(png)], check=True)
        finally:
            scene.unlink()
        pngs.append(str(png))
    subprocess.run(["python3", str(ROOT / "scripts/png_strip.py"), str(OUT)] + pngs, check=True)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
