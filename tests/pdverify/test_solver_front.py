"""The solvers' one front door (issue 30): elimination (condense), the choice (policy) and
the implementations kept apart, the dispatch in front."""
import ast
import pathlib

import numpy as np
import pytest
import scipy.sparse as sp

import pdverify.solvers as solvers
from pdverify.solvers import front, policy
from pdverify.solvers.condense import condense
from pdverify.solvers.iterative import Lattice

EPS = np.finfo(float).eps
SOLVERS_DIR = pathlib.Path(solvers.__file__).parent


def chain(n=40):
    """A 1D SPD chain (tridiagonal 2, -1; condition ~ n^2 = 1.6e3, numpy.linalg.cond)."""
    return sp.diags([np.full(n, 2.0), np.full(n - 1, -1.0), np.full(n - 1, -1.0)],
                    [0, 1, -1], format="csr")


def test_condense_solve_expand_is_the_full_solve():
    K = chain()
    rng = np.random.default_rng(3)
    f = rng.standard_normal(K.shape[0])
    fixed, values = np.array([0, 17, 39]), np.array([0.5, -1.0, 2.0])
    K_ff, f_f, expand = condense(K, f, fixed, values)
    assert K_ff.shape == (37, 37) and np.array_equal(expand.free,
                                                      np.setdiff1d(np.arange(40), fixed))
    u = expand(np.linalg.solve(K_ff.toarray(), f_f))
    assert np.array_equal(u[fixed], values)          # the prescribed values, exactly
    # the free rows of K u = f hold: residual at round-off of a solve of condition ~1.6e3
    # (chain's docstring), 1e2 * cond * eps relative to |f| + |K||u| is ample
    r = (K @ u - f)[expand.free]
    assert np.abs(r).max() <= 1e2 * 1.6e3 * EPS * (np.abs(f).max() + 4 * np.abs(u).max())
    # expand returns a new array each time, the values untouched
    assert expand(np.zeros(37)) is not u and np.array_equal(expand(np.zeros(37))[fixed], values)


def test_condense_without_prescribed_unknowns_keeps_the_system():
    K = chain(5)
    f = np.arange(5.0)
    K_ff, f_f, expand = condense(K, f, np.zeros(0, dtype=int), np.zeros(0))
    assert (K_ff != K).nnz == 0 and np.array_equal(f_f, f)
    assert np.array_equal(expand(f_f), f)


def test_front_dispatches_each_solver_name():
    K = chain(60)
    f = np.ones(60)
    fixed, values = np.array([0, 59]), np.zeros(2)
    lattice = Lattice.component_major(np.arange(60)[:, None], np.arange(60.0)[:, None], 1)
    coords = np.arange(60.0)[:, None]
    u_d, info_d = front.solve_with_dirichlet(K, f, fixed, values, "t", spd=True)
    assert info_d["solver"].startswith("sparse LU") and "solver_choice" not in info_d
    u_c, info_c = front.solve_with_dirichlet(K, f, fixed, values, "t", spd=True,
                                             solver="cg", lattice=lattice)
    assert "iterations" in info_c
    u_n, info_n = front.solve_with_dirichlet(K, f, fixed, values, "t",
                                             solver="nested-dissection", coords=coords)
    assert info_n["solver"].endswith("nested-dissection ordering)")
    _, info_a = front.solve_with_dirichlet(K, f, fixed, values, "t", spd=True,
                                           solver="auto", lattice=lattice)
    assert info_a["solver_choice"].startswith("auto: direct (58 free unknowns")
    # all solve the same system: CG to its relative residual 1e-10 (iterative.CG_RTOL)
    # times the condition ~1.5e3 (chain), the two LUs to round-off
    assert np.abs(u_n - u_d).max() <= 1e3 * EPS * np.abs(u_d).max()
    assert np.abs(u_c - u_d).max() <= 1e-10 * 1.5e3 * np.abs(u_d).max()
    with pytest.raises(ValueError, match="allowed"):
        front.solve_with_dirichlet(K, f, fixed, values, "t", solver="pardiso")


def test_the_choice_is_read_from_the_policy_at_call_time(monkeypatch):
    K = chain(60)
    lattice = Lattice.component_major(np.arange(60)[:, None], np.arange(60.0)[:, None], 1)
    monkeypatch.setattr(policy, "AUTO_ITERATIVE_UNKNOWNS", 58)
    _, info = front.solve_with_dirichlet(K, np.ones(60), np.array([0, 59]), np.zeros(2), "t",
                                         spd=True, solver="auto", lattice=lattice)
    assert info["solver_choice"].startswith("auto: cg (58 free unknowns; cg from 58")
    # the direct solver's dense switch, likewise
    monkeypatch.setattr(policy, "DENSE_MIN_UNKNOWNS", 10)
    monkeypatch.setattr(policy, "DENSE_FILL", 0.0)
    _, info = front.solve_square(chain(20), np.ones(20), where="t")
    assert info["solver"] == "dense LU (LAPACK)"


def test_policy_is_a_leaf_and_every_threshold_names_its_source():
    """policy.py imports no module of the package (the implementations read it, not the
    other way), and each of its thresholds (an upper-case number) has a ``#:`` comment."""
    src = (SOLVERS_DIR / "policy.py").read_text()
    tree = ast.parse(src)
    relative = [n for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.level]
    assert relative == []
    lines = src.splitlines()
    for node in tree.body:
        if (isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name)
                and node.targets[0].id.isupper()
                and not isinstance(node.value, ast.Tuple)):
            assert lines[node.lineno - 2].startswith("#:"), node.targets[0].id


def test_no_dispatch_outside_the_front_door():
    """Only front.py dispatches among the solver names; the implementations never name
    another solver's module (dense.py no longer holds the dispatcher)."""
    for path in SOLVERS_DIR.glob("*.py"):
        if path.name in ("front.py", "policy.py", "__init__.py"):
            continue
        assert "solve_with_dirichlet" not in path.read_text().replace(
            "front.solve_with_dirichlet", ""), path.name
    assert not (SOLVERS_DIR / "static.py").exists()
