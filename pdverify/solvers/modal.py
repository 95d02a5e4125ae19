"""Extreme natural frequencies of K u = omega^2 M u with a lumped mass (free unknowns only)."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import policy


def _scaled(stiffness, mass, fixed):
    """M^-1/2 K M^-1/2 on the free unknowns (symmetric, same eigenvalues as M^-1 K)."""
    K = sp.csr_matrix(stiffness)
    mass = np.asarray(mass, dtype=float)
    free = np.setdiff1d(np.arange(K.shape[0]), np.asarray(fixed, dtype=int))
    scale = sp.diags(1.0 / np.sqrt(mass[free]))
    return (scale @ K[free][:, free] @ scale).tocsc()


def max_angular_frequency(stiffness, mass, *, fixed=()) -> float:
    """omega_max = sqrt(lambda_max(M^-1 K)), the operator's own value (not a bound).

    Dense for small systems, LAPACK's banded solver for narrow bands, else Lanczos
    (``eigsh``) converged to machine precision.
    """
    A = _scaled(stiffness, mass, fixed)
    n = A.shape[0]
    if n == 0:
        return 0.0
    coo = A.tocoo()
    lower = coo.row >= coo.col
    band = int(np.max(coo.row - coo.col)) if coo.nnz else 0
    if n <= policy.EIGEN_DENSE_LIMIT:
        lam = sla.eigvalsh(A.toarray(), subset_by_index=[n - 1, n - 1])[0]
    elif band <= policy.EIGEN_BANDED_LIMIT:
        ab = np.zeros((band + 1, n))
        np.add.at(ab, (coo.row[lower] - coo.col[lower], coo.col[lower]), coo.data[lower])
        lam = sla.eigvals_banded(ab, lower=True, select="i", select_range=(n - 1, n - 1))[0]
    else:
        # a seeded start vector: ARPACK's own is random, which moved the limit in its
        # last digits from one report to the next (the wave scenes' dt_limit)
        v0 = np.random.default_rng(0).standard_normal(n)
        lam = spla.eigsh(A, k=1, which="LA", tol=0, v0=v0, return_eigenvectors=False)[0]
    return float(np.sqrt(max(lam, 0.0)))


def min_angular_frequency(stiffness, mass, *, fixed=()) -> float:
    """omega_1 = sqrt(lambda_min(M^-1 K)) (shift-invert Lanczos about 0 for large systems;
    K restricted to the free unknowns must then be non-singular)."""
    A = _scaled(stiffness, mass, fixed)
    n = A.shape[0]
    if n == 0:
        return 0.0
    if n <= policy.EIGEN_DENSE_LIMIT:
        lam = sla.eigvalsh(A.toarray(), subset_by_index=[0, 0])[0]
    else:
        lam = spla.eigsh(A, k=1, sigma=0.0, which="LM", tol=0, return_eigenvectors=False,
                         v0=np.random.default_rng(0).standard_normal(n))[0]
    return float(np.sqrt(max(lam, 0.0)))


def exact_stability_limit(stiffness, mass, *, fixed=()) -> float:
    """Sharp central-difference step limit 2 / omega_max for a symmetric K (inf if K = 0)."""
    omega = max_angular_frequency(stiffness, mass, fixed=fixed)
    return np.inf if omega == 0 else 2.0 / omega
