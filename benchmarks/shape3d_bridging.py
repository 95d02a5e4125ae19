"""How many bonds of block3d-cavity's fictitious layer bridge the cavity (issue 55): a
real node bonded to a fictitious node whose closest boundary point lies on a plane part
that it sees only through the cavity; the node-adding treatments give such a bond a
value of its own (``Closure.shadow``, found by ``Shape3D.hides``). This counts them
independently of ``Shape3D.hides`` (the segment against the ball, in closed form) and
is the check of its count (``bridging_bonds`` of the runs: 49 at h = 0.1).

Plain script (no test runner):

    python benchmarks/shape3d_bridging.py [--spacing H ...] [--no-record] [--tag TAG]

For every stencil bond of a real and a fictitious node (the bonds the treatments keep),
the fictitious node's closest point p (``Shape3D.closest``) and whether the segment from
the real node to p crosses the open ball r < a (the cavity) at more than 1e-9 of its
length from p: the 2D test's reading (``Shape.hides``: a segment through the body's
exterior other than p's own part). The quarter cylinder is convex: no bond can bridge.

Measured 2026-11-28 (counts, no timing): 49 of 93 624 real-fictitious bonds at the
scene's h = 0.1, 72 of 20 466 at the quick grid's h = 0.2, 156 of 221 394 at h = 1/15.
"""
from __future__ import annotations

import argparse

import numpy as np

import harness

SPACINGS = (0.1, 0.2, 1 / 15)


def bridging_count(h: float) -> tuple[int, int]:
    """(real-fictitious bonds, those whose real end sees the fictitious end's closest
    point only through the cavity) of block3d-cavity at spacing h."""
    from pdverify.pd.bonds import bond_pairs
    from pdverify.scenes import get_scene
    scene = get_scene("block3d-cavity")
    p = {**scene.default_params(), "spacing": h}
    problem = scene.problem(p, "shape3d_bridging")
    g, st, shape = problem.body.grid(problem.stencil.reach), problem.stencil, problem.shape
    a, b, _ = bond_pairs(g.ext_shape, st.offsets[st.half])
    keep = (g.is_interior[a] | g.is_interior[b]) & ~g.is_void[a] & ~g.is_void[b]
    mixed = np.flatnonzero(keep & (g.is_interior[a] != g.is_interior[b]))
    real = np.where(g.is_interior[a[mixed]], a[mixed], b[mixed])
    fict = np.where(g.is_interior[a[mixed]], b[mixed], a[mixed])
    P, _, _, part = shape.closest(g.x[fict])
    x = g.x[real]
    radius = float(p["radius"])
    d = P - x                                     # |x + s d|^2 = a^2: the chord's s1, s2
    A = np.einsum("ij,ij->i", d, d)
    B = 2 * np.einsum("ij,ij->i", x, d)
    C = np.einsum("ij,ij->i", x, x) - radius ** 2
    disc = B * B - 4 * A * C
    root = np.sqrt(np.maximum(disc, 0.0))
    s1, s2 = (-B - root) / (2 * A), (-B + root) / (2 * A)
    hit = (disc > 0) & (s2 > 0) & (s1 < 1 - 1e-9) & (s2 - s1 > 1e-9)
    off_cavity = part != shape.part_names.index("cavity")
    return int(mixed.size), int(np.sum(hit & off_cavity))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacing", type=float, nargs="+", default=list(SPACINGS))
    harness.add_arguments(ap)
    args = ap.parse_args()
    with harness.Record(__file__, args) as rec:
        for h in args.spacing:
            total, bridging = bridging_count(h)
            print(f"h = {h:.4g}: {bridging} of {total} real-fictitious bonds bridge the cavity")
            rec[f"h={h:.6g}"] = {"real_fictitious_bonds": total, "bridging": bridging}
            rec.save()


if __name__ == "__main__":
    main()
