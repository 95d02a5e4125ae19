"""pdverify/solvers/dense.py, reached through the direct solver of the front door
(front.solve_square; the switch is policy.dense_lu): the dense LAPACK path used for full 3D
state-based systems."""
import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.errors import NumericalError
from pdverify.solvers.front import solve_square

EPS = np.finfo(float).eps


def test_dense_path_solves_to_round_off(rng):
    n = 2100  # above the dense threshold (policy: n >= 2000 and fill > 10 %)
    A = rng.uniform(-1, 1, (n, n)) + n * np.eye(n)
    A[:, 5] *= 1e8  # badly scaled columns are equilibrated away
    x = rng.uniform(-1, 1, n)
    u, info = solve_square(sp.csr_matrix(A), A @ x, where="test")
    assert info["solver"].startswith("dense")
    # diagonally dominant after equilibration: cond ~ a few; 100 * cond * eps is generous
    assert np.linalg.norm(u - x) / np.linalg.norm(x) < 100 * info["condition_estimate"] * EPS


def test_dense_path_refuses_singular_systems(rng):
    n = 2100
    A = rng.uniform(-1, 1, (n, n))
    A[:, 7] = A[:, 3]  # two equal columns
    with pytest.raises(NumericalError, match="singular"):
        solve_square(sp.csr_matrix(A), np.ones(n), where="test")


def test_sparse_systems_stay_on_superlu():
    n = 3000
    K = sp.diags([np.full(n, 4.0), np.full(n - 1, -1.0), np.full(n - 1, -1.0)], [0, 1, -1])
    u, info = solve_square(K, K @ np.ones(n), where="test")
    assert info["solver"].startswith("sparse")
    np.testing.assert_allclose(u, 1.0, rtol=1e-13)  # cond ~ 3: round-off only
