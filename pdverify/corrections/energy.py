"""The energy surface correction (Le and Bobaru 2018, after Madenci and Oterkus 2014), as
Peridynamics.jl applies it to its bond-based and ordinary state-based materials.

For each axis k the body is stretched uniformly along k (u = eps x_k e_k). Node i's
strain energy density W_i^k under that stretch is compared with a node's of the bulk
lattice: lambda_i^k = W_inf^k / W_i^k. A bond a-b gets the ellipse of its ends' mean
factors, G = (sum_k n_k^2 / g_k^2)^(-1/2), g_k = (lambda_a^k + lambda_b^k) / 2, as a
factor on its force (``Closure.force_factor``).

Our choices where the sources leave room:
- W_inf is the complete neighbourhood of the same lattice, not the continuum W: the
  bulk is then untouched (G = 1 exactly away from the surface) and the correction is
  about the surface alone. Peridynamics.jl divides the continuum W by the discrete one,
  which also rescales the bulk by the lattice's quadrature error.
- W_i is the model's own energy density at node i (``pdverify.pd.work.work_density``: the
  work of node i's own force state on its bonds). For bond-based models this is the
  sum Peridynamics.jl uses. For state-based models Peridynamics.jl takes the
  bond-based sum too, but an LPS model with m over the truncated family already
  stiffens its surface bonds by 1/m_i, and factors from the bond-based sum (all > 1)
  then correct in the wrong direction: measured on body3d-traction at h = 0.1, 31 %
  (none) became 100 %. We calibrate the state-based model's own energy density
  instead (21 % there); the factor multiplies the bond force, m and the dilatation
  keep their weights, as in Peridynamics.jl.
- Consequence (finding): in 1D, LPS with m over the truncated family has the exact
  energy density at every node under a uniform stretch (theta_i = c_theta eps and
  sum omega e^2 / m_i = eps^2 whatever the family), so every factor is 1 and the
  seed-000 bars' ``energy`` runs equal ``none``: their error is the imposition of the
  boundary conditions, not a stiffness defect. (An earlier reading split each bond's
  work evenly between its ends; that is not the node's energy for state-based models,
  and it gave those bars 14 % instead of 24 %.)
- The ellipse for bonds along an axis reduces to g_k, in any dimension.
"""
from __future__ import annotations

import numpy as np

from ..pd.closure import Closure
from ..pd.work import uniaxial, work_density
from .factors import guarded_ratio


def axis_factors(model) -> np.ndarray:
    """lambda_i^k (n_ext, d): the bulk's over node i's energy density under a uniaxial
    stretch along k (1 where a node has no energy: no bonds)."""
    d = model.dim
    out = np.empty((model.grid.n_ext, d))
    for k in range(d):
        strain = uniaxial(d, k)
        out[:, k] = guarded_ratio(model.bulk_work_density(strain), work_density(model, strain))
    return out


def energy_factors(model) -> np.ndarray:
    """The bond factors G of the energy method (module docstring)."""
    lam = axis_factors(model)
    g = 0.5 * (lam[model.bond_a] + lam[model.bond_b])
    return 1.0 / np.sqrt(np.sum(model.bond_n ** 2 / g ** 2, axis=1))


def energy_closure(params=None) -> Closure:
    return Closure(force_factor=energy_factors)
