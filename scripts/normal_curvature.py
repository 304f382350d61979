#!/usr/bin/env python3
"""How far does F bend along the normal at each point of T? (exploration)

Reads an exported 1994 quintic complex (`apatch export patches -o X.json scene.toml`) and, for
every point of T (the complex's interpolated vertices), takes one patch with a corner there and
measures n^T (d^2 F) n / |grad F| at the point by central differences of the patch's polynomial
along the point's normal n (the complex's `normals`).

The jets the scheme starts from (`quintic_c2::jets`) make F a signed distance to second order:
that quantity is 0 (the icosahedron's complex gives ~4e-6, the differences' error). Where the joint stars
free the Hessians (`joint_stars`: every point relaxed at level 2) the solve and the sign fit may
move it anywhere; in a thin tetrahedron (height h over its base) it enters the number 2 weights
as ~h^2 * value / 20, so a large value is cheap for the solve and decides the signs of F on the
boundary faces there (fandisk, docs/quintic.md, session 65: the two deepest clusters of crossed
faces sit at the two points where it is largest, 50 times the model's median).

Usage: normal_curvature.py X.json [N]   (the N largest, default 20; and the median, p90, p99)
Needs numpy.
"""

import json
import sys
from math import factorial

import numpy as np


def multi_indices(n):
    """The order of `bb::multi_indices`: a, b, c descending."""
    return [
        (a, b, c, n - a - b - c)
        for a in range(n, -1, -1)
        for b in range(n - a, -1, -1)
        for c in range(n - a - b, -1, -1)
    ]


def main():
    complex_ = json.load(open(sys.argv[1]))
    top = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    if complex_.get("scheme") != "quintic-c2":
        sys.exit(f"{sys.argv[1]}: not a quintic-c2 complex")
    mi = multi_indices(5)
    powers = np.array(mi, dtype=float)
    multinomial = np.array(
        [factorial(5) / np.prod([factorial(k) for k in m]) for m in mi]
    )
    points = np.array(complex_["vertices"])
    normals = np.array(complex_["normals"])
    # One patch per point of T: the first with a corner exactly there.
    index = {tuple(p): i for i, p in enumerate(points)}
    owner = {}
    for t, patch in enumerate(complex_["patches"]):
        for k, corner in enumerate(patch["tet"]):
            i = index.get(tuple(corner))
            if i is not None and i not in owner:
                owner[i] = t
    rows = []
    for i, t in owner.items():
        patch = complex_["patches"][t]
        corners = np.array(patch["tet"])
        weights = np.array(patch["weights"])
        to_bary = np.linalg.inv(np.vstack([corners.T, np.ones(4)]))

        def f(x):
            lam = to_bary @ np.append(x, 1.0)
            return float(np.sum(weights * multinomial * np.prod(lam**powers, axis=1)))

        # A step of 1e-4 of the patch's size s: the difference's truncation (h^2/12 times the
        # fourth derivative, ~|w|/s^4) is ~1e-9 |w|/s^2, its rounding (~1e-16 |w| / h^2)
        # ~1e-8 |w|/s^2, both far below the values of interest (~|w|/s^2 and up).
        h = 1e-4 * np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))
        n = normals[i] / np.linalg.norm(normals[i])
        x = points[i]
        plus, mid, minus = f(x + h * n), f(x), f(x - h * n)
        slope = (plus - minus) / (2 * h)
        bend = (plus - 2 * mid + minus) / (h * h)
        rows.append((i, bend / abs(slope) if slope != 0 else float("nan"), t))
    if not rows:
        sys.exit(f"{sys.argv[1]}: no patch has a corner at a point of T")
    size = np.array([abs(r[1]) for r in rows])
    print(
        f"{len(rows)} points: |n.H.n|/|grad F| median {np.median(size):.4g}, "
        f"p90 {np.percentile(size, 90):.4g}, p99 {np.percentile(size, 99):.4g}"
    )
    rows.sort(key=lambda r: -abs(r[1]))
    for i, v, t in rows[:top]:
        p = points[i]
        print(f"point {i}: {v:.4g} (patch {t}) at ({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f})")


if __name__ == "__main__":
    main()
