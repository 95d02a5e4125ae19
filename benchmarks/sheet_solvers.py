"""Time SuperLU orderings on the seed-003 tension sheet's SPD stiffness, side by side.

Plain script (no test runner): python benchmarks/sheet_solvers.py [--repeat N]
Prints the median time of each alternative on the same matrix and the ratios to the
default (COLAMD) ordering; the choice it supports is ``pdverify.solvers.lu.SPD_OPTIONS``.
"""
from __future__ import annotations

import argparse

import numpy as np

import harness
from _splu_timing import time_splu
from pdverify.scenes import get_scene
from pdverify.solvers.lu import SPD_OPTIONS


def sheet_matrix(method="energy-directional"):
    """The free-DOF stiffness of sheet2d-tension at its defaults (51 x 101 nodes, m = 5)."""
    from pdverify.corrections.energy_directional import directional_closure
    from pdverify.pd import BondBasedModel, BoxGrid, Closure, get_influence
    scene = get_scene("sheet2d-tension")
    p = scene.resolve(method)
    W, H, h, delta = p["width"], p["length"], p["spacing"], p["horizon"]
    grid = BoxGrid((W, H), (-W / 2, -H / 2), h, placement="on-surface")
    inf = get_influence(p["micromodulus"])
    closure = (directional_closure(grid, (-W / 2, -H / 2), (W / 2, H / 2), delta, inf)
               if method == "energy-directional" else Closure())
    model = BondBasedModel(grid, scene.stencil(p, delta / h), scene.micromodulus(p, delta),
                           inf, closure)
    n, x = grid.n_ext, grid.x
    fixed = np.r_[np.flatnonzero(np.isclose(x[:, 0], 0)), n + np.flatnonzero(np.isclose(x[:, 1], 0))]
    free = np.setdiff1d(np.arange(2 * n), fixed)
    return model.K.tocsr()[free][:, free].tocsc()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)


def _measure(args, rec):
    K = sheet_matrix()
    alternatives = {
        "splu COLAMD (default)": {},
        "splu MMD_AT_PLUS_A": dict(permc_spec="MMD_AT_PLUS_A"),
        "splu SPD_OPTIONS (symmetric mode)": SPD_OPTIONS,
    }
    medians = time_splu(K, alternatives, args.repeat)
    base = medians["splu COLAMD (default)"]
    print(f"matrix: {K.shape[0]} unknowns, {K.nnz} non-zeros; median of {args.repeat}")
    for name, med in medians.items():
        print(f"  {name:36s} {med:7.3f} s   ratio to default {med / base:5.2f}")
    rec.update({"unknowns": K.shape[0], "non_zeros": K.nnz, "repeat": args.repeat,
                "median_s": medians, "ratio_to_default": harness.ratios(
                    medians, "splu COLAMD (default)")})


if __name__ == "__main__":
    main()
