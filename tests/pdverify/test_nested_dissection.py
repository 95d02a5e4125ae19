"""Nested-dissection sparse LU of the augmented state-based system (dilatations as unknowns)."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from pdverify.errors import NumericalError
from pdverify.pd import StateBasedConstants
from pdverify.scenes import get_scene
from pdverify.corrections.plain import assemble_plain
from pdverify.corrections.surface_nodes import assemble_surface_nodes
from descriptions import box_problem
from pdverify.solvers.policy import ND3D_FROM_UNKNOWNS, ND_FROM_UNKNOWNS, static_solver
from pdverify.solvers.ordering import nested_dissection
from pdverify.solvers.nested import solve_nested

EPS = np.finfo(float).eps


def lattice_operator(n, reach):
    """A nonsymmetric operator coupling lattice nodes within ``reach`` (2D)."""
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    d = np.abs(ij[:, None, :] - ij[None, :, :]).max(-1)
    rng = np.random.default_rng(1)
    A = np.where(d <= reach, rng.uniform(-1, 0, d.shape), 0.0)
    np.fill_diagonal(A, 0.0)
    np.fill_diagonal(A, -A.sum(1) + 1.0)      # diagonally dominant, nonsymmetric
    return sp.csr_matrix(A), ij.astype(float)


def test_ordering_is_a_permutation_whose_separators_separate():
    A, x = lattice_operator(24, 2)
    perm = nested_dissection(A, x, leaf=16)
    assert np.array_equal(np.sort(perm), np.arange(A.shape[0]))
    # the property the LU needs: fewer factor entries than SuperLU's default COLAMD
    Ap = A[perm][:, perm].tocsc()
    nd = spla.splu(Ap, permc_spec="NATURAL", diag_pivot_thresh=1e-3,
                   options=dict(SymmetricMode=True))
    colamd = spla.splu(A.tocsc(), permc_spec="COLAMD")
    assert nd.L.nnz + nd.U.nnz < colamd.L.nnz + colamd.U.nnz


def reference_nested_dissection(A, coords, leaf):
    """The ordering's definition, one subdomain at a time (the first implementation)."""
    G = (abs(sp.csr_matrix(A)) + abs(sp.csr_matrix(A)).T).tocsr()
    G.data[:] = 1.0
    n = G.shape[0]
    on_right = np.zeros(n)
    pieces = []
    stack = [(np.arange(n), False)]
    while stack:
        idx, emit = stack.pop()
        if emit or idx.size <= leaf:
            pieces.append(idx)
            continue
        x = coords[idx]
        axis = int(np.argmax(np.ptp(x, axis=0)))
        left = x[:, axis] < np.median(x[:, axis])
        if left.all() or not left.any():
            left = np.zeros(idx.size, bool)
            left[np.argsort(x[:, axis], kind="stable")[: idx.size // 2]] = True
        L, R = idx[left], idx[~left]
        on_right[R] = 1.0
        touches = (G[L] @ on_right) > 0
        on_right[R] = 0.0
        stack += [(L[touches], True), (R, False), (L[~touches], False)]
    return np.concatenate(pieces)


@pytest.mark.parametrize("n, reach, leaf, coords", [
    (24, 2, 16, "lattice"), (30, 1, 5, "lattice"), (9, 3, 4, "lattice"),
    (20, 2, 16, "ties"), (20, 2, 8, "3d")])
def test_level_by_level_ordering_is_the_recursive_one(n, reach, leaf, coords):
    """All subdomains of a depth are split at once: the permutation is exactly the
    one-at-a-time post-order, also with tied coordinates (halved by rank) and in 3D."""
    A, x = lattice_operator(n, reach)
    A = A.tocsr()
    row = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    A.data[((row == 0) & (A.indices == 1)) | ((row == 1) & (A.indices == 0))] = 0.0
    # (0, 1) and (1, 0) are stored zeros now, which couple nothing
    assert A.nnz == lattice_operator(n, reach)[0].nnz and (A.data == 0).sum() == 2
    if coords == "ties":
        x[:, 0] = 0.0
    elif coords == "3d":
        x = np.c_[x, np.round(np.random.default_rng(0).uniform(size=len(x)), 1)]
    expected = reference_nested_dissection(A, x, leaf)
    assert np.array_equal(nested_dissection(A, x, leaf), expected)
    perm, (n1, n2) = nested_dissection(A, x, leaf, top_split=True)
    assert np.array_equal(perm, expected)
    Ap = A[perm][:, perm]
    assert Ap[:n1, n1:n1 + n2].nnz == 0 and Ap[n1:n1 + n2, :n1].nnz == 0


def test_solve_nested_matches_a_direct_solve():
    A, x = lattice_operator(20, 2)
    b = np.random.default_rng(2).normal(size=A.shape[0])
    u, info = solve_nested(A, b, x, where="test", mixed=False)
    exact = spla.spsolve(A.tocsc(), b)
    # condition 18 (numpy.linalg.cond), n = 400: a backward-stable LU's error is below
    # ~ kappa * n * eps = 7e3 eps
    assert np.linalg.norm(u - exact) / np.linalg.norm(exact) < 1e4 * EPS
    assert info["relative_residual"] < 1e2 * EPS
    assert info["solver"].endswith("nested-dissection ordering)")


def test_singular_system_is_refused():
    A, x = lattice_operator(10, 1)
    A = A.tolil()
    A[5, :] = A[4, :]
    with pytest.raises(NumericalError, match="test: (singular|near-singular)"):
        solve_nested(A.tocsr(), np.ones(A.shape[0]), x, where="test")


@pytest.mark.parametrize("order", [None, 1, 2])
def test_augmented_schur_complement_is_the_stiffness(order):
    """The treatments assemble one form, the augmented system; the solver layer's
    elimination of its dilatation unknowns (``front.condensed``, what a direct solve
    factors) gives back K: bit for bit for the uncorrected model (the products of
    ``StateBasedModel.stiffness`` in its order), and for surface nodes K's shape with
    more non-zeros than the augmented form (a free box, uncorrected ``order=None`` or
    with surface nodes)."""
    from pdverify.solvers.front import condensed
    problem = box_problem((0.3, 0.2), (0.0, 0.0), 0.02, 3.0,
                          StateBasedConstants("plane-strain", 200e9, 0.3), solver="auto")
    system = (assemble_plain(problem) if order is None
              else assemble_surface_nodes(problem, order))
    A, s = system.K, system.scalars
    n = A.shape[0] - s
    assert n == system.dofs and s == system.model.A_theta.shape[0]
    assert abs(A[n:, n:] + sp.identity(s)).max() == 0
    assert not np.any(system.rhs[n:])
    K, G = condensed(A, s)
    assert K.shape == (n, n) and A.nnz < K.nnz
    assert system.coords.shape == (A.shape[0], 2)
    if order is None:
        direct = system.model.stiffness(system.model.equilibrium_rows())
        K.sort_indices()
        direct = direct.tocsr()
        direct.sort_indices()
        # exactness claim: the same products in the same order
        assert np.array_equal(K.indptr, direct.indptr)
        assert np.array_equal(K.indices, direct.indices)
        assert np.array_equal(K.data, direct.data)


@pytest.mark.parametrize("mixed_from", [None, 0])
def test_plate_nested_dissection_agrees_with_direct(monkeypatch, mixed_from):
    """Also with the single-precision factor and refinement forced on (mixed_from = 0)."""
    from pdverify.solvers import policy
    if mixed_from is not None:
        monkeypatch.setattr(policy, "MIXED_FROM_UNKNOWNS", mixed_from)
    scene = get_scene("plate2d-plane-strain")
    small = {"spacing": 0.05}
    a = scene.run("surface-nodes", {**small, "solver": "nested-dissection"})
    b = scene.run("surface-nodes", {**small, "solver": "direct"})
    assert a.status == b.status == "ok"
    assert a.diagnostics["solver"].endswith("nested-dissection ordering)")
    assert ("float32" in a.diagnostics["solver"]) == (mixed_from == 0)
    # both are direct solves of the same equations, condition ~1e5 after equilibration:
    # the metrics agree to 1e5 * eps relative, far inside the compare gate's 1e-8
    for k, v in b.metrics.items():
        assert a.metrics[k] == pytest.approx(v, rel=1e-9, abs=1e-12), k


def test_auto_picks_nested_dissection_for_large_systems():
    p = get_scene("plate2d-plane-strain").resolve("surface-nodes")
    assert static_solver(p["solver"], 2, ND_FROM_UNKNOWNS) == "nested-dissection"
    assert static_solver(p["solver"], 2, ND_FROM_UNKNOWNS - 1) == "direct"
    assert static_solver(p["solver"], 3, ND3D_FROM_UNKNOWNS) == "nested-dissection"
    assert static_solver(p["solver"], 3, ND3D_FROM_UNKNOWNS - 1) == "direct"
    assert static_solver("direct", 2, 10 ** 6) == "direct"
    assert static_solver("direct", 3, 10 ** 6) == "direct"


@pytest.mark.parametrize("scene_id", ["body3d-traction", "body3d-manufactured"])
def test_3d_auto_nested_dissection_agrees_with_the_dense_lu(monkeypatch, scene_id):
    """In 3D, ``auto`` takes the augmented system from ND3D_FROM_UNKNOWNS unknowns (here
    lowered to h = 0.1's 1,500, with the float32 factor forced on as at the default
    h = 0.05's 9,000) and records why; every metric equals that of the LU of K to the
    compare gate's 1e-8 (issue 12: metrics unchanged at --rtol 1e-8). Both are direct
    solves (condition ~1e6 after equilibration): the solutions agree to ~1e-12, and an
    error metric ~1e-3 of the solution (max_error_pct 0.077 %) to ~1e-9 relative."""
    from pdverify.solvers import policy
    monkeypatch.setattr(policy, "ND3D_FROM_UNKNOWNS", 1000)
    monkeypatch.setattr(policy, "MIXED_FROM_UNKNOWNS", 0)
    scene = get_scene(scene_id)
    a = scene.run("surface-nodes", {"spacing": 0.1})
    b = scene.run("surface-nodes", {"spacing": 0.1, "solver": "direct"})
    assert a.status == b.status == "ok"
    assert a.diagnostics["solver_choice"].startswith("auto: nested-dissection (1500 unknowns")
    assert "float32" in a.diagnostics["solver"]
    assert "nested-dissection" not in b.diagnostics["solver"]      # K, multiplied out
    for k, v in b.metrics.items():
        assert a.metrics[k] == pytest.approx(v, rel=1e-8, abs=1e-12), k


def _spd_lattice(n, reach):
    """A bond-based-like SPD stiffness on an n x n lattice (2 components per node,
    component-major), couplings within ``reach`` (L-infinity), and its Lattice."""
    from pdverify.solvers.iterative import Lattice
    A, x = lattice_operator(n, reach)
    S = (A + A.T) / 2                      # symmetric; SPD here (test docstring)
    K = sp.block_diag([S, S]).tocsr()
    idx = x.astype(int)
    return K, Lattice.component_major(idx, x, 2)


def test_auto_on_a_2d_spd_lattice_takes_nested_dissection_unless_the_lu_is_dense():
    """issue 32: ``solver=auto`` of an SPD lattice system (the sheets) below CG's size
    takes nested dissection from ND_FROM_UNKNOWNS free unknowns, unless the dense LU
    applies; the solution is the direct solve's: two backward-stable solves of a system
    of condition 20 (the free block's eigenvalues 0.92 to 18.7, numpy's eigvalsh) differ
    by O(kappa eps); 1e3 eps is that with a factor 50 for the factors' growth."""
    from pdverify.solvers import policy
    from pdverify.solvers.front import solve_with_dirichlet
    K, lat = _spd_lattice(24, 2)                         # 1,152 unknowns, 2.8 % full
    f = np.random.default_rng(2).standard_normal(K.shape[0])
    fixed, values = np.arange(10), np.zeros(10)
    assert K.shape[0] - fixed.size >= ND_FROM_UNKNOWNS
    u_auto, info = solve_with_dirichlet(K, f, fixed, values, "t", spd=True, solver="auto",
                                        lattice=lat)
    u_dir, info_d = solve_with_dirichlet(K, f, fixed, values, "t", spd=True,
                                         solver="direct", lattice=lat)
    assert "nested-dissection" in info["solver"] and "nested-dissection" in info["solver_choice"]
    assert "symmetric mode" in info_d["solver"]
    assert np.abs(u_auto - u_dir).max() <= 1e3 * EPS * np.abs(u_dir).max()
    # below the threshold, or where the LU would be dense, ``auto`` stays direct
    small, lat_s = _spd_lattice(16, 2)                    # 512 unknowns
    _, info_s = solve_with_dirichlet(small, f[:512], fixed, values, "t", spd=True,
                                     solver="auto", lattice=lat_s)
    assert "nested" not in info_s["solver"]
    assert not policy.lattice_uses_nd("auto", False, 2, 5000, int(0.2 * 5000 ** 2))
    assert policy.lattice_uses_nd("auto", False, 2, 5000, 50 * 5000)
    assert not policy.lattice_uses_nd("auto", True, 2, 5000, 50 * 5000)    # CG chosen
    assert not policy.lattice_uses_nd("direct", False, 2, 5000, 50 * 5000)
    assert not policy.lattice_uses_nd("auto", False, 3, 5000, 50 * 5000)
