#!/usr/bin/env python3
"""Distance of the 1994 cubic surface to its polyhedron for the default and two cut settings.

For every cubic scene of `scenes/paper1994/` (no `_quintic`), runs `apatch check --json` on the
scene as it is and on copies with other shape-control keys (§7.1): `level` (where F vanishes on
the segment from a face tetrahedron's base centroid to its apex: small cuts deep) and `alpha`
(pseudo-centroid of non-trihedral vertices: small cuts deep). Prints a Markdown table of the
largest and mean distance, relative to the bounding-box diagonal, and whether `check` passed.

Usage: python3 scripts/cut_distances.py [--apatch target/release/apatch] [--scenes a,b]
The copies are written beside the scene (paths in scenes are relative) and removed afterwards.
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SETTINGS = [
    ("default", {}),
    ("deep cut: level 0.3, alpha 0.3", {"level": 0.3, "alpha": 0.3}),
    ("shallow cut: level 0.7, alpha 0.7", {"level": 0.7, "alpha": 0.7}),
]


def with_keys(text, keys):
    """The scene text with `keys` set in its [scheme] table (replacing existing ones)."""
    out, in_scheme = [], False
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("["):
            in_scheme = stripped == "[scheme]"
            out.append(line)
            if in_scheme:
                out.extend(f"{k} = {v}" for k, v in keys.items())
            continue
        if in_scheme and stripped.split("=")[0].strip() in keys:
            continue
        out.append(line)
    return "\n".join(out) + "\n"


def run(apatch, scene):
    p = subprocess.run([apatch, "check", str(scene), "--json"], capture_output=True, text=True)
    if not p.stdout.strip():
        return None, p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "no output"
    d = json.loads(p.stdout)
    return d, None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--apatch", default=str(ROOT / "target/release/apatch"))
    ap.add_argument("--scenes", default="")
    a = ap.parse_args()
    scenes = sorted(
        s for s in (ROOT / "scenes/paper1994").glob("*.toml") if not s.stem.endswith("_quintic")
    )
    if a.scenes:
        keep = set(a.scenes.split(","))
        scenes = [s for s in scenes if s.stem in keep]
    print("| scene | " + " | ".join(name for name, _ in SETTINGS) + " |")
    print("| --- |" + " ---: |" * len(SETTINGS))
    for scene in scenes:
        cells = []
        text = scene.read_text()
        for _, keys in SETTINGS:
            path = scene
            if keys:
                path = scene.with_name(f".cut_{os.getpid()}_{scene.name}")
                path.write_text(with_keys(text, keys))
            try:
                d, err = run(a.apatch, path)
            finally:
                if keys:
                    path.unlink()
            if d is None:
                cells.append(f"error: {err}")
                continue
            dist = d["distance"]
            mark = "" if d["passed"] else " (fails check)"
            cells.append(f"{dist['max']:.2e} / {dist['mean']:.2e}{mark}")
        print(f"| {scene.stem} | " + " | ".join(cells) + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
