#!/usr/bin/env python3
"""How far is F from a signed distance at the points of T? (exploration)

Reads an exported 1994 quintic complex (`apatch export patches -o X.json scene.toml`) and, at
every point of T (the complex's interpolated vertices), reads the Hessian H of F exactly from
the weights of every patch with a corner there (the Bernstein basis at a corner, below), in the
frame of the point's normal n (the complex's `normals`) and over |grad F|:

  bend     n.H.n / |grad F|           what `hessian_normal = "bend"` holds at 0
  mixed    |P H n| / |grad F|         with bend, what `hessian_normal = "column"` holds at 0
  tangent  max |eig(P H P)| / |grad F|  the level set's largest principal curvature

(P = I - n n^T, the tangent plane's projector.) The jets the scheme starts from
(`quintic_c2::jets`) make F a signed distance to second order: bend and mixed 0, tangent the
surface's curvature (the icosahedron on its sphere of radius 0.795: 1.26; the rounded cylinder
of radius 0.5: 2.0). Where the joint stars free the Hessians (`joint_stars`: every point
relaxed at level 2) the solve and the sign fit move them where they are cheap: in a tetrahedron
of height h over its base a change of H enters the number 2 weights as ~h^2/20 of it (the
rounded cylinder with `joint_stars`: tangent 8.0, mixed up to 2.6; fandisk with `hessian_normal
= "bend"`: tangent median 35, mixed median 114 and 5.4e4 at point 9448, where the deepest
crossed faces are; docs/quintic.md, session 67).

Each figure is the median over the point's patches; C2 makes them equal up to the Hessian jumps
`apatch check` reports, and the spread (largest - smallest) is printed too. (Until session 67
this script read the bend by central differences in one patch a point, with a step set by the
patch's size, not its height: in fandisk's thin tetrahedra that gave bends of 18-293 where the
weights give at most 3e-6, and its earlier figures for fandisk are of that kind.)

At a corner a, with d_j = u . grad(lambda_j): the derivative along u is 5 sum_j d_j w[4a + j],
and u^T H v = 20 sum_jk (u . grad lambda_j)(v . grad lambda_k) w[3a + j + k].

Usage: normal_curvature.py X.json [N] [HOLES]   (the N points largest in each part, default
20; with HOLES, an `apatch check --holes` file, the parts at the corners of its crossed faces
and their rank among all points)
Needs numpy.
"""

import json
import sys

import numpy as np

PARTS = ("bend", "mixed", "tangent")


def multi_indices(n):
    """The order of `bb::multi_indices`: a, b, c descending."""
    return [
        (a, b, c, n - a - b - c)
        for a in range(n, -1, -1)
        for b in range(n - a, -1, -1)
        for c in range(n - a - b, -1, -1)
    ]


def parts_at(patch, a, n, slot):
    """(bend, mixed, tangent) at corner a of the patch, or None where grad F is 0."""
    corners = np.array(patch["tet"])
    w = patch["weights"]
    # Rows: the gradients of the barycentric coordinates.
    grads = np.linalg.inv(np.vstack([corners.T, np.ones(4)]))[:, :3]

    def weight(*steps):
        m = [0, 0, 0, 0]
        m[a] = 5 - len(steps)
        for j in steps:
            m[j] += 1
        return w[slot[tuple(m)]]

    g = 5 * sum(grads[j] * weight(j) for j in range(4))
    size = np.linalg.norm(g)
    if size == 0:
        return None
    h = 20 * sum(
        np.outer(grads[j], grads[k]) * weight(j, k) for j in range(4) for k in range(4)
    )
    p = np.eye(3) - np.outer(n, n)
    return (
        float(n @ h @ n / size),
        float(np.linalg.norm(p @ h @ n) / size),
        float(np.abs(np.linalg.eigvalsh(p @ h @ p)).max() / size),
    )


def main():
    complex_ = json.load(open(sys.argv[1]))
    top = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    holes = json.load(open(sys.argv[3])) if len(sys.argv) > 3 else None
    if complex_.get("scheme") != "quintic-c2":
        sys.exit(f"{sys.argv[1]}: not a quintic-c2 complex")
    slot = {m: k for k, m in enumerate(multi_indices(5))}
    points = np.array(complex_["vertices"])
    normals = np.array(complex_["normals"], dtype=float)
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    index = {tuple(p): i for i, p in enumerate(points)}
    read = {}
    for patch in complex_["patches"]:
        for a, corner in enumerate(patch["tet"]):
            i = index.get(tuple(corner))
            if i is None:
                continue
            got = parts_at(patch, a, normals[i], slot)
            if got is not None:
                read.setdefault(i, []).append(got)
    if not read:
        sys.exit(f"{sys.argv[1]}: no patch has a corner at a point of T")
    ids = sorted(read)
    median = np.array([np.median(np.array(read[i]), axis=0) for i in ids])
    spread = np.array([np.ptp(np.array(read[i]), axis=0) for i in ids])
    print(f"{len(ids)} points of T; each part over |grad F|, the median over a point's patches")
    for k, name in enumerate(PARTS):
        size = np.abs(median[:, k])
        print(
            f"{name:8} median {np.median(size):.4g}, p90 {np.percentile(size, 90):.4g}, "
            f"p99 {np.percentile(size, 99):.4g}, largest {size.max():.4g} "
            f"(spread over a point's patches: largest {spread[:, k].max():.3g})"
        )
    at = {i: r for r, i in enumerate(ids)}
    for k, name in enumerate(PARTS):
        order = np.argsort(-np.abs(median[:, k]))[:top]
        print(f"largest {name}:")
        for r in order:
            p = points[ids[r]]
            print(
                f"  point {ids[r]}: {median[r, k]:.4g} ({len(read[ids[r]])} patches) "
                f"at ({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f})"
            )
    if holes is not None:
        corners = sorted(
            {
                index[tuple(q)]
                for face in holes["faces"]
                for q in face["corners"]
                if tuple(q) in index and index[tuple(q)] in at
            },
            key=lambda i: -abs(median[at[i], 1]),
        )
        print(f"the {len(corners)} points of T at crossed faces (rank: share of points below):")
        for i in corners:
            r = at[i]
            text = ", ".join(
                f"{name} {median[r, k]:.3g} (rank {np.mean(np.abs(median[:, k]) < abs(median[r, k])):.4f})"
                for k, name in enumerate(PARTS)
            )
            print(f"  point {i}: {text}")


if __name__ == "__main__":
    main()
