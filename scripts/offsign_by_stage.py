#!/usr/bin/env python3
"""Which stage of the 1994 quintic solve left each defect's weights off their sign? (exploration)

Reads an exported quintic complex, the `--holes` file `apatch check` wrote for it, and the slot
dump of the same build (`APATCH_SLOT_DUMP=slots.bin apatch export patches ...`: per patch and
weight, in the complex's order, the slot's pass stage and the sign Theorem 2.1 asks of it, one
signed byte each). For every j-sheet patch and every patch with a crossed face it lists the
weights off their sign (beyond 1e-12 of the complex's largest weight, the solves' rounding) with
the stage that fixed them: 2 the joint group (stars, edge middles and Hessians with
`joint_stars`), 4 far face weights, 5 face middles (number 10 and 11), 6 the rest of the edge
tetrahedra. Counts first, then one line per j-sheet patch.

Pure Python (no numpy): `python3 scripts/offsign_by_stage.py X.json X.holes slots.bin`.
"""

import collections
import json
import sys


def multi_indices(n):
    """The BB multi-indices of degree n in the order of `bb::multi_indices`."""
    out = []
    for a in range(n, -1, -1):
        for b in range(n - a, -1, -1):
            for c in range(n - a - b, -1, -1):
                out.append((a, b, c, n - a - b - c))
    return out


def main():
    complex_path, holes_path, dump_path = sys.argv[1:4]
    with open(complex_path) as f:
        patches = json.load(f)["patches"]
    with open(holes_path) as f:
        holes = json.load(f)
    with open(dump_path, "rb") as f:
        dump = f.read()
    nw = len(patches[0]["weights"])
    if len(dump) != 2 * nw * len(patches):
        sys.exit(f"{dump_path}: {len(dump)} bytes, the complex needs {2 * nw * len(patches)}")
    names = ["".join(map(str, m)) for m in multi_indices(5)]
    wmax = max(abs(w) for p in patches for w in p["weights"])
    tiny = 1e-12 * wmax

    def off(pi):
        w = patches[pi]["weights"]
        out = []
        for k in range(nw):
            stage = dump[2 * (pi * nw + k)]
            req = dump[2 * (pi * nw + k) + 1]
            req = req - 256 if req > 127 else req
            if req in (1, -1) and req * w[k] < -tiny:
                out.append((stage, names[k], w[k]))
        return out

    def count(ids, what):
        by_stage = collections.Counter()
        clean = 0
        for p in ids:
            o = off(p)
            clean += not o
            by_stage.update({s for s, _, _ in o})
        stages = ", ".join(f"stage {s}: {n}" for s, n in sorted(by_stage.items()))
        print(f"{what}: {len(ids)}, none off their sign: {clean}; with a weight off, by stage: {stages}")

    sheets = [s["patch"] for s in holes["j_sheets"]]
    crossed = sorted({f["patch"] for f in holes["faces"]})
    count(sheets, "j-sheet patches")
    count(crossed, "patches with a crossed face")
    pairs = collections.Counter(s for pi in range(len(patches)) for s, _, _ in off(pi))
    print("weights off their sign (per patch), by stage:", dict(sorted(pairs.items())))
    for p in sheets:
        o = off(p)
        shown = " ".join(f"{s}:{name}:{w:.2g}" for s, name, w in o[:8])
        print(f"  j-sheet patch {p} ({patches[p]['role']}): {shown}")


if __name__ == "__main__":
    main()
