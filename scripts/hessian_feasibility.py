#!/usr/bin/env python3
"""Could each point's Hessian alone give its boundary faces their sign? (exploration)

Reads an exported 1994 quintic complex (`apatch export patches -o X.json scene.toml`) and, for
every point of T (the complex's interpolated vertices), gathers the boundary faces of the hull
through it (faces of one patch only) and their number 2 weights at it: with the 2-jet (0, g, H)
at p, the weight at the domain point p^3 a b is the blossom g.(a - p + b - p)/5 +
(a - p)^T H (b - p)/20, linear in H. Each face must keep the sign its number 1 weights at p give
it (`apatch check --holes` names it), so per point a linear program asks

  t* = max t  over H  subject to  sign_f * w(H) >= t * |a - p| |b - p| / 20  for every such weight,
                                   t <= 1,

once with H free (6 entries) and once with its tangent part only (3: what `hessian_signs` fits).
t* > 0: some Hessian meets every boundary face's number 2 signs at p strictly, so a face held by
a Hessian (`held_by = "hessian"`) there is held by what the solve did to the jet, not by the
data; t* < 0: no Hessian can, and only the normals or the hull can change it. The margin the
complex has now (the same quantity at its Hessian, recovered from its weights) is printed beside.

Needs numpy and scipy (HiGHS): `python3 -m venv v && v/bin/pip install scipy`, then
`v/bin/python scripts/hessian_feasibility.py X.json [holes.json]` (the `--holes` file of
`apatch check`, to split its crossed faces by their corners' verdicts).
"""

import collections
import json
import sys

import numpy as np
from scipy.optimize import linprog


def multi_indices(n):
    """The crate's order of the degree-n multi-indices (`bb::multi_indices`)."""
    return [
        (a, b, c, n - a - b - c)
        for a in range(n, -1, -1)
        for b in range(n - a, -1, -1)
        for c in range(n - a - b, -1, -1)
    ]


def sym_coefficients(a, b):
    """a^T H b / 20 as a row over H's entries (xx, xy, xz, yy, yz, zz)."""
    return (
        np.array(
            [
                a[0] * b[0],
                a[0] * b[1] + a[1] * b[0],
                a[0] * b[2] + a[2] * b[0],
                a[1] * b[1],
                a[1] * b[2] + a[2] * b[1],
                a[2] * b[2],
            ]
        )
        / 20.0
    )


def tangent_basis(g):
    """H = A t1 t1^T + B (t1 t2^T + t2 t1^T) + C t2 t2^T as columns over H's six entries."""
    n = g / np.linalg.norm(g)
    t1 = np.cross(n, [1.0, 0.0, 0.0])
    if np.linalg.norm(t1) < 0.1:
        t1 = np.cross(n, [0.0, 1.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    mats = [np.outer(t1, t1), np.outer(t1, t2) + np.outer(t2, t1), np.outer(t2, t2)]
    return np.array([[m[0, 0], m[0, 1], m[0, 2], m[1, 1], m[1, 2], m[2, 2]] for m in mats]).T


def main(path, holes_path=None):
    d = json.load(open(path))
    vid = {tuple(v): i for i, v in enumerate(d["vertices"])}
    mi = multi_indices(5)
    at = {m: j for j, m in enumerate(mi)}
    patches = d["patches"]
    if any(p["degree"] != 5 for p in patches):
        sys.exit(f"{path}: not a degree-5 complex")

    def face_key(tet, opp):
        return frozenset(tuple(tet[k]) for k in range(4) if k != opp)

    shared = collections.Counter(face_key(p["tet"], o) for p in patches for o in range(4))
    conds = collections.defaultdict(list)  # point -> (a, b, sign, weight now)
    grads = collections.defaultdict(list)
    for p in patches:
        tet = [np.array(x) for x in p["tet"]]
        w = p["weights"]
        scale = max(abs(x) for x in w)
        for k in range(4):
            pid = vid.get(tuple(p["tet"][k]))
            if pid is None:
                continue
            # The gradient at p from the patch's number 1 weights (b = g.(x - p)/5).
            others = [j for j in range(4) if j != k]
            e = np.array([tet[j] - tet[k] for j in others])
            first = []
            for j in others:
                m = [0] * 4
                m[k], m[j] = 4, 1
                first.append(5 * w[at[tuple(m)]])
            grads[pid].append(np.linalg.solve(e, np.array(first)))
            for opp in others:
                if shared[face_key(p["tet"], opp)] != 1:
                    continue
                pair = [j for j in others if j != opp]
                s = sum(
                    w[at[tuple(4 if i == k else (1 if i == j else 0) for i in range(4))]]
                    for j in pair
                )
                if abs(s) <= 1e-9 * scale:
                    continue  # a face in p's tangent plane: no sign from p
                for i1, i2 in [(pair[0], pair[0]), (pair[0], pair[1]), (pair[1], pair[1])]:
                    m = [0] * 4
                    m[k] = 3
                    m[i1] += 1
                    m[i2] += 1
                    conds[pid].append((tet[i1] - tet[k], tet[i2] - tet[k], np.sign(s), w[at[tuple(m)]]))

    verdict = {}
    for pid, cs in conds.items():
        g = np.mean(grads[pid], axis=0)
        rows, rhs = [], []
        for a, b, s, _ in cs:
            unit = np.linalg.norm(a) * np.linalg.norm(b) / 20.0
            # s (g.(a + b)/5 + coef.h) >= t unit  ->  -s coef.h + unit t <= s g.(a + b)/5
            rows.append(np.append(-s * sym_coefficients(a, b), unit))
            rhs.append(s * g.dot(a + b) / 5.0)
        rows, rhs = np.array(rows), np.array(rhs)
        big = 1e6
        full = linprog(np.append(np.zeros(6), -1.0), A_ub=rows, b_ub=rhs,
                       bounds=[(-big, big)] * 6 + [(None, 1.0)], method="highs")
        tb = tangent_basis(g)
        tan = linprog(np.append(np.zeros(3), -1.0), A_ub=np.hstack([rows[:, :6] @ tb, rows[:, 6:]]),
                      b_ub=rhs, bounds=[(-big, big)] * 3 + [(None, 1.0)], method="highs")
        now = min(s * v / (np.linalg.norm(a) * np.linalg.norm(b) / 20.0) for a, b, s, v in cs)
        verdict[pid] = (
            -full.fun if full.status == 0 else float("nan"),
            -tan.fun if tan.status == 0 else float("nan"),
            now,
        )
    # Margins within 1e-9 of 0 are the flat points (every condition zero).
    eps = 1e-9
    v = np.array(list(verdict.values()))
    print(f"{path}: {len(verdict)} points of T with boundary faces' number 2 conditions")
    for name, col, verb in [("H free", 0, "cannot meet"), ("tangent H", 1, "cannot meet"),
                            ("the complex now", 2, "miss")]:
        c = v[:, col]
        print(f"  {name:16s}: {int(np.sum(c < -eps))} points {verb} them, "
              f"{int(np.sum(np.abs(c) <= eps))} at margin 0")
    if holes_path:
        h = json.load(open(holes_path))
        split = collections.Counter()
        for f in h["faces"]:
            kinds = []
            for c in f["corners"]:
                pid = vid.get(tuple(c))
                if pid in verdict:
                    full, _, now = verdict[pid]
                    kinds.append("no H can" if full < -eps else ("missed now" if now < -eps else "met"))
            split[tuple(sorted(kinds))] += 1
        print(f"  {holes_path}: crossed faces by their corners' verdicts")
        for k, n in split.most_common():
            print(f"    {n:5d}  {', '.join(k) or 'no corner of T'}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(*sys.argv[1:3])
