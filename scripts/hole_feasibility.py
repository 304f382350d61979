#!/usr/bin/env python3
"""Can a hole repair's local group meet its pins' signs at all? (exploration)

Reads a group dumped by the quintic hole repair (`APATCH_HOLE_DUMP='Face(38, 3)' apatch export
patches ...` writes /tmp/dump_<defect>_<unknowns>.json before each of its solves: the rows
A x = c over the re-solved weights, their values x0, the pins (column, sign x margin) and the
weights' names) and asks a linear program, with the pins as the sign conditions they stand for
(sign_j x_j >= t, not x_j = target):

  t* = max t  subject to  A x = c,  sign_j x_j >= t for every pin j,  |x - x0| <= 1.

t* > 0: the signs can all be met strictly (the repair's trouble is its equality pins or its
weights); t* = 0: the equations force a positive combination of the pinned weights to vanish,
so no margin, weight or number of solves meets them in this group (only a wider reach, other
data or another hull can). The dual of the program names the culprits: the pins with a
positive multiplier and the equations they are combined through.

Needs scipy (HiGHS): `python3 -m venv v && v/bin/pip install scipy`, then
`v/bin/python scripts/hole_feasibility.py /tmp/dump_Face_38__3__4841.json`.
"""

import json
import sys

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import csr_matrix, hstack, lil_matrix


def main(path):
    d = json.load(open(path))
    n, rows, pins = d["n"], d["rows"], d["pins"]
    c, x0 = np.array(d["c"]), np.array(d["x0"])
    names = d.get("names", [])

    def name(j):
        return names[j] if j < len(names) else f"Hessian unknown {j - len(names)}"

    m, p = len(rows), len(pins)
    a = lil_matrix((m, n))
    for i, row in enumerate(rows):
        for j, k in row:
            a[i, j] += k
    a = csr_matrix(a)
    # Variables [x, t]; -sign_j x_j + t <= 0; maximise t (capped at 1: the box is the scale).
    g = lil_matrix((p, n + 1))
    for i, (j, v) in enumerate(pins):
        g[i, j] = -np.sign(v)
        g[i, n] = 1.0
    cost = np.zeros(n + 1)
    cost[n] = -1.0
    bounds = [(x0[j] - 1.0, x0[j] + 1.0) for j in range(n)] + [(None, 1.0)]
    res = linprog(
        cost,
        A_ub=csr_matrix(g),
        b_ub=np.zeros(p),
        A_eq=hstack([a, csr_matrix((m, 1))]).tocsr(),
        b_eq=c,
        bounds=bounds,
        method="highs",
    )
    if res.status != 0:
        print(f"{path}: the program did not solve: {res.message}")
        return 1
    t = -res.fun
    margin = min(abs(v) for _, v in pins) if pins else 0.0
    print(
        f"{path}: {n} unknowns, {m} equations, {p} pins; rows at x0 missed by "
        f"{np.abs(a @ x0 - c).max():.2e}"
    )
    print(f"  t* = {t:.3e} (smallest pin margin {margin:.3e}): "
          + ("the signs can be met" if t > 0 else "no margin can be met"))
    lam = -res.ineqlin.marginals
    y = res.eqlin.marginals
    if t <= 0:
        print("  pins the equations combine to zero (multiplier, weight, value, target):")
        for i in np.argsort(-lam):
            if lam[i] < 1e-9:
                break
            j, v = pins[i]
            print(f"    {lam[i]:.3g}  {name(j)}  {x0[j]:.3g}  {v:.3g}")
        print("  through the equations (multiplier: largest terms):")
        for i in np.argsort(-np.abs(y))[:12]:
            if abs(y[i]) < 1e-9:
                break
            terms = sorted(rows[i], key=lambda tk: -abs(tk[1]))[:6]
            print(f"    {y[i]:.3g}: " + "; ".join(f"{k:.3g} {name(j)}" for j, k in terms))
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        print(__doc__)
        sys.exit(2)
    sys.exit(max(main(f) for f in sys.argv[1:]))
