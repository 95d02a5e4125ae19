"""Operator-matching weights of the ``perifit`` package (PyPI; Shojaei and Hermann,
Helmholtz-Zentrum Hereon), applied as bond weights: an optional peer method.

perifit computes one scalar weight w_i per node such that the truncated neighbourhood's
operators match their full-sphere counterparts (a local least-squares problem per node,
coupled through a global sparse system); a bond a-b then carries (w_a + w_b) / 2 in
place of the unit influence (its README). It supports 3D bond-based (``bb``) and LPS
(``osb``) models and 2D bond-based ones (``compute_weights_2d``).

Our choices: perifit is given our model's families (the bonds the engine keeps, partial
cells included) and node volumes, so the weights belong to the same bonds; the bond
factor multiplies the bond's weight wherever it enters (``Closure.weight_factor``: m and
the dilatation too, as its README says to replace omega everywhere). perifit's own
kernels (q = 3 bond-based, q = 2 LPS) are what it calibrates against; the scenes' influence
functions are not passed (its API has no such input). The version that produced the
weights is a parameter of every run (``perifit_version``), so it is in results.json.
"""
from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

import numpy as np

from ..pd.closure import Closure
from ..pd.statebased import StateBasedModel

INSTALL = 'pip install ".[peers]" (perifit from PyPI)'
#: scenes whose model perifit supports: 3D LPS and bond-based, 2D bond-based
SCENES = ("stiffness3d-box", "stiffness3d-box-bond", "body3d-traction", "body3d-manufactured",
          "stiffness2d-sheet", "sheet2d-tension", "sheet2d-clamped", "block2d-indentation")


def installed_version() -> str | None:
    try:
        return version("perifit")
    except PackageNotFoundError:
        return None


def families(model) -> list[list[int]]:
    """Each grid node's neighbours over the model's bonds."""
    a, b, n = model.bond_a, model.bond_b, model.grid.n_ext
    node = np.r_[a, b]
    other = np.r_[b, a]
    order = np.argsort(node, kind="stable")
    counts = np.bincount(node, minlength=n)
    return [list(map(int, f)) for f in np.split(other[order], np.cumsum(counts)[:-1])]


def node_weights(model) -> np.ndarray:
    """perifit's w_i at every grid node of a plain grid's model."""
    import perifit
    g = model.grid
    state = isinstance(model, StateBasedModel)
    fam = families(model)
    if g.dim == 3:
        return perifit.compute_weights(g.x, model.node_volume, model.horizon,
                                       model="osb" if state else "bb", families=fam)
    if g.dim == 2 and not state:
        return perifit.compute_weights_2d(g.x, model.node_volume, model.horizon, families=fam)
    raise ValueError("perifit: 3D bond-based and LPS models and 2D bond-based ones only")


def perifit_factors(model) -> np.ndarray:
    w = node_weights(model)
    return 0.5 * (w[model.bond_a] + w[model.bond_b])


def perifit_closure(params=None) -> Closure:
    return Closure(weight_factor=perifit_factors)
