#!/usr/bin/env python3
"""Render a Mitsuba 3 scene (e.g. one written by `apatch export mitsuba`) to an EXR file.

Optional helper: apatch itself never needs Python. Set up once:

    python3 -m venv .venv && .venv/bin/pip install mitsuba numpy
    .venv/bin/python scripts/mitsuba_render.py scene.xml out.exr [--spp 64] [--variant NAME]

then compare with `apatch compare apatch.exr out.exr --side-by-side sbs.png`.

Variant: `--variant` if given; otherwise `llvm_ad_rgb` when a probe render succeeds in a child
process (drjit with an old libLLVM aborts the whole process, which Python cannot catch), else
`scalar_rgb`, which always works. `DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so`
selects a newer LLVM explicitly. The EXR is written to a temporary file beside the target and
renamed into place, so a failed render leaves no partial output. Exit code 0 on success, 2 on
errors (one line on stderr).
"""

import argparse
import os
import subprocess
import sys

FAST_VARIANT = "llvm_ad_rgb"
SAFE_VARIANT = "scalar_rgb"

PROBE = """
import mitsuba as mi
mi.set_variant(%r)
scene = mi.load_dict({
    "type": "scene",
    "shape": {"type": "sphere"},
    "light": {"type": "directional", "direction": [0, 0, -1]},
    "sensor": {"type": "perspective",
               "to_world": mi.ScalarTransform4f().look_at([0, 0, 4], [0, 0, 0], [0, 1, 0]),
               "film": {"type": "hdrfilm", "width": 8, "height": 8}},
})
img = mi.render(scene, spp=1)
assert img.shape[0] == 8
"""


def probe(variant, timeout=120):
    """True when `variant` can be selected and renders a tiny scene, tested in a child process."""
    try:
        r = subprocess.run(
            [sys.executable, "-c", PROBE % variant],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            timeout=timeout,
        )
    except (OSError, subprocess.TimeoutExpired):
        return False
    return r.returncode == 0


def choose_variant(requested, mi):
    available = mi.variants()
    if requested:
        if requested not in available:
            raise RuntimeError(
                "--variant %s: not available (have %s)" % (requested, ", ".join(available))
            )
        return requested
    if FAST_VARIANT in available and probe(FAST_VARIANT):
        return FAST_VARIANT
    return SAFE_VARIANT


def temp_path(path):
    head, name = os.path.split(path)
    # Keep the .exr extension: Mitsuba picks the file format from it.
    return os.path.join(head, ".%s.partial-%d.exr" % (name, os.getpid()))


def render(scene_path, out_path, spp, variant, quiet):
    try:
        import mitsuba as mi
    except ImportError:
        raise RuntimeError(
            "the mitsuba Python package is missing: "
            "python3 -m venv .venv && .venv/bin/pip install mitsuba numpy"
        )
    if not os.path.isfile(scene_path):
        raise RuntimeError("%s: no such file" % scene_path)
    out_dir = os.path.dirname(out_path) or "."
    if not os.path.isdir(out_dir):
        raise RuntimeError("%s: directory %s does not exist" % (out_path, out_dir))
    variant = choose_variant(variant, mi)
    mi.set_variant(variant)
    if not quiet:
        print("mitsuba %s, variant %s" % (mi.__version__, variant), file=sys.stderr)
    try:
        scene = mi.load_file(scene_path)
    except Exception as e:  # Mitsuba raises plain Exceptions with multi-line text
        raise RuntimeError("%s: cannot load scene (%s)" % (scene_path, str(e).splitlines()[0]))
    sensor = scene.sensors()[0]
    if spp is None:
        mi.render(scene, sensor=sensor)
    else:
        mi.render(scene, sensor=sensor, spp=spp)
    tmp = temp_path(out_path)
    try:
        sensor.film().write(tmp)
        os.replace(tmp, out_path)
    except Exception as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise RuntimeError("%s: cannot write EXR (%s)" % (out_path, str(e).splitlines()[0]))
    return variant


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", help="Mitsuba 3 scene XML")
    ap.add_argument("output", help="output EXR file")
    ap.add_argument("--spp", type=int, help="samples per pixel (default: the scene's sampler)")
    ap.add_argument("--variant", help="Mitsuba variant (default: %s if it works, else %s)"
                    % (FAST_VARIANT, SAFE_VARIANT))
    ap.add_argument("--quiet", action="store_true", help="print nothing on success")
    args = ap.parse_args(argv)
    if not args.output.lower().endswith(".exr"):
        print("mitsuba_render: error: output must end in .exr", file=sys.stderr)
        return 2
    if args.spp is not None and args.spp < 1:
        print("mitsuba_render: error: --spp must be >= 1", file=sys.stderr)
        return 2
    try:
        render(args.scene, args.output, args.spp, args.variant, args.quiet)
    except RuntimeError as e:
        print("mitsuba_render: error: %s" % e, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
