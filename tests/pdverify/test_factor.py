"""The solver layer's one door for direct solves: ``factor(A, precision) -> Factor``
(``pdverify.solvers.front``), whose ``solve(b)`` checks each solution and leaves its
diagnostics in ``info``."""
import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.errors import NumericalError
from pdverify.solvers import front, nested, policy
from pdverify.solvers.dense import DenseFactor
from pdverify.solvers.lu import SuperLUFactor
from pdverify.solvers.nested import NestedFactor

EPS = np.finfo(float).eps


def lattice(n=40, seed=2):
    """A nonsymmetric 2D lattice operator (5-point stencil plus a random skew part,
    diagonally dominant: condition ~ n^2 / 4 ~ 400 at n = 40) and its nodes."""
    rng = np.random.default_rng(seed)
    T = sp.diags([np.full(n, 2.0), np.full(n - 1, -1.0), np.full(n - 1, -1.0)], [0, 1, -1])
    A = (sp.kronsum(T, T) + 0.1 * sp.random(n * n, n * n, density=2 / (n * n),
                                             random_state=rng)).tocsr()
    A = A + sp.diags(np.abs(A).sum(axis=1).A1 * 0.01)
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    return A.tocsr(), ij.astype(float)


@pytest.mark.parametrize("precision", ["auto", "double", "mixed"])
def test_every_factor_solves_to_round_off(precision):
    """Each implementation behind the door solves A x = b to a backward error of a few
    eps (the refinement's REFINE_STOP = 2 eps for the float32 factor; SuperLU's and the
    ND double factor's O(eps) backward stability), and says which it is."""
    A, x = lattice()
    b = np.random.default_rng(5).standard_normal(A.shape[0])
    lu = front.factor(A, precision, where="test", coords=x)
    assert isinstance(lu, front.Factor) and isinstance(lu, NestedFactor)
    u = lu.solve(b)
    assert lu.info["relative_residual"] < 1e2 * EPS
    assert ("float32" in lu.info["solver"]) == (precision == "mixed")
    plain = front.factor(A, precision if precision != "mixed" else "double", where="test")
    assert isinstance(plain, SuperLUFactor)
    v = plain.solve(b)
    # two backward-stable solves of a system of condition ~400 (lattice's docstring)
    assert np.abs(u - v).max() <= 1e3 * 400 * EPS * np.abs(v).max()


def test_a_full_matrix_goes_to_the_dense_lu(monkeypatch):
    A, _ = lattice(12)
    monkeypatch.setattr(policy, "DENSE_MIN_UNKNOWNS", 10)
    monkeypatch.setattr(policy, "DENSE_FILL", 0.0)
    lu = front.factor(A, "double", where="test")
    assert isinstance(lu, DenseFactor)
    b = np.ones(A.shape[0])
    lu.solve(b)
    assert lu.info["solver"] == "dense LU (LAPACK)" and lu.info["relative_residual"] < 1e2 * EPS


def test_one_factor_serves_many_right_hand_sides(monkeypatch):
    """The float32 factor is made once: a second solve refines on the same factor."""
    A, x = lattice()
    made = []
    real = nested.single_precision_factor
    monkeypatch.setattr(nested, "single_precision_factor",
                        lambda *a, **k: made.append(1) or real(*a, **k))
    lu = front.factor(A, "mixed", where="test", coords=x)
    rng = np.random.default_rng(1)
    for _ in range(3):
        lu.solve(rng.standard_normal(A.shape[0]))
        assert lu.info["relative_residual"] < 1e2 * EPS
    assert len(made) == 1


def test_the_door_refuses_what_it_cannot_do():
    A, x = lattice(8)
    with pytest.raises(ValueError, match="precision='single'"):
        front.factor(A, "single", where="test")
    with pytest.raises(ValueError, match="test: precision='mixed' needs the unknowns' coord"):
        front.factor(A, "mixed", where="test")
    singular = A.tolil()
    singular[3, :] = singular[2, :]
    for how in ({}, {"coords": x}):
        with pytest.raises(NumericalError, match="test: (singular|near-singular)"):
            front.factor(singular.tocsr(), "double", where="test", **how).solve(
                np.ones(A.shape[0]))
    with pytest.raises(NumericalError, match="test: the system has non-finite entries"):
        front.factor(A, "double", where="test").solve(np.full(A.shape[0], np.nan))
