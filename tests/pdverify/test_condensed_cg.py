"""CG on the condensed 3D state-based systems (``auto`` from policy.CG3D_FROM_UNKNOWNS
unknowns; pdverify.solvers.iterative.solve_condensed), checked against the direct solve
at a size where both run (h = 0.1 on the 3D box, the threshold lowered)."""
from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.scenes import get_scene
from pdverify.solvers import front, iterative, policy
from pdverify.solvers.condense import condense

SCENE = "body3d-manufactured"


def _system(method, spacing=0.1):
    scene = get_scene(SCENE)
    p = scene.resolve(method, {"spacing": spacing})
    return scene.treatment(method).assemble(scene.problem(p, "test"), p)


def _condition(system) -> float:
    """kappa_2 of the condensed K on the free unknowns (dense: 675 unknowns at h = 0.1)."""
    K, _ = front.condensed(system.K, system.scalars)
    K_ff, _, _ = condense(K, np.zeros(K.shape[0]), system.fixed, system.values)
    ev = np.linalg.eigvalsh(K_ff.toarray())
    assert ev[0] > 0
    return float(ev[-1] / ev[0])


@pytest.mark.parametrize("method", ["none", "volume", "pals"])
def test_cg_matches_the_direct_solve_within_its_bound(monkeypatch, method):
    """The symmetric systems (LPS, and the bond methods that keep its energy) are solved by
    CG under ``auto``; the solution differs from the LU's by at most kappa(K) times CG's
    relative residual (the SPD bound ||e|| / ||u|| <= kappa ||r|| / ||f||; the LU's own
    error, ~kappa eps, is far below it)."""
    system = _system(method)
    x_d, info_d = front.solve(replace(system, solver="direct"),
                              where="test")
    monkeypatch.setattr(policy, "CG3D_FROM_UNKNOWNS", 0)
    x_c, info_c = front.solve(system, where="test")
    assert info_c["static_solver"] == "cg" and info_d["static_solver"] == "direct"
    assert info_c["solver_choice"].startswith(f"auto: cg ({system.dofs} unknowns")
    assert info_c["iterations"] > 0 and info_c["relative_residual"] <= iterative.CG_RTOL
    assert info_c["symmetry_defect"] <= policy.SYMMETRY_TOL
    n = system.dofs
    err = np.linalg.norm(x_c[:n] - x_d[:n]) / np.linalg.norm(x_d[:n])
    assert err <= _condition(system) * info_c["relative_residual"]
    # the dilatations follow the displacements (theta = G u), as the direct solve's
    assert np.allclose(x_c[n:], x_d[n:], rtol=0, atol=1e-6 * np.abs(x_d[n:]).max())


def test_scene_run_under_cg_matches_the_direct_run(monkeypatch):
    """Through the scene: the method error (the study's rel_l2_error, ~1 at h = 0.1) moves
    by at most the solution's relative change, kappa x 1e-10 < 1e-6 here (kappa ~ 7e2), and
    the run carries CG's error estimate (checked against the method error by
    solver_error_warnings)."""
    scene = get_scene(SCENE)
    b = scene.run("none", {"spacing": 0.1, "solver": "direct"})
    monkeypatch.setattr(policy, "CG3D_FROM_UNKNOWNS", 0)
    a = scene.run("none", {"spacing": 0.1})
    assert a.status == b.status == "ok"
    assert a.diagnostics["solver"].startswith("CG + Jacobi")
    assert a.metrics["rel_l2_error"] == pytest.approx(b.metrics["rel_l2_error"], abs=1e-6)
    assert a.size["augmented_nnz"] > 0 and not a.warnings


def test_a_system_that_is_not_symmetric_falls_back_to_nested_dissection(monkeypatch):
    """The energy method's K is not symmetric (its factors are not symmetric per bond):
    ``auto`` says why CG does not apply and solves it by nested dissection, as before."""
    system = _system("energy")
    monkeypatch.setattr(policy, "CG3D_FROM_UNKNOWNS", 0)
    x, info = front.solve(system, where="test")
    assert info["static_solver"] == "nested-dissection"
    assert "cg does not apply: K not symmetric" in info["solver_choice"]
    x_d, _ = front.solve(replace(system, solver="direct"),
                         where="test")
    n = system.dofs
    assert np.linalg.norm(x[:n] - x_d[:n]) <= 1e-8 * np.linalg.norm(x_d[:n])


def test_a_stalled_cg_is_a_named_failed_run(monkeypatch):
    """CG that does not reach its tolerance within its iteration limit ends the run as
    failed, naming the run and the residual reached (never a silent, unconverged answer)."""
    monkeypatch.setattr(policy, "CG3D_FROM_UNKNOWNS", 0)
    monkeypatch.setattr(iterative, "CONDENSED_CG_MAXITER", 3)
    res = get_scene(SCENE).run("none", {"spacing": 0.1})
    assert res.status == "failed"
    assert f"{SCENE}/none: CG did not converge in 3 iterations" in res.message


def test_the_operator_is_the_condensed_matrix():
    """CondensedOperator applies K = A_uu + A_ut G on the free unknowns without forming
    it: the same products as the formed K_ff to round-off, its exact diagonal, and the
    right-hand side with the prescribed values moved over."""
    system = _system("pals")
    op = iterative.CondensedOperator(system.K, system.rhs, system.scalars, system.fixed,
                                     system.values)
    K, _ = front.condensed(system.K, system.scalars)
    n = K.shape[0]
    K_ff, r, _ = condense(K, np.asarray(system.rhs)[:n], system.fixed, system.values)
    x = np.random.default_rng(1).standard_normal(op.shape[0])
    scale = abs(K_ff).max() * np.abs(x).sum()
    assert np.abs(op @ x - K_ff @ x).max() <= 1e-13 * scale
    assert np.allclose(op.diagonal(), K_ff.diagonal(), rtol=1e-13, atol=0)
    assert np.abs(op.rhs - r).max() <= 1e-13 * max(np.abs(r).max(), 1.0)
    assert isinstance(K_ff, sp.csr_matrix)


def test_auto_takes_cg_in_3d_above_every_default_run():
    """``auto`` picks CG from CG3D_FROM_UNKNOWNS unknowns in 3D only; the report's 3D runs at
    h = 0.05 (surface nodes: 9,000 unknowns) stay below it, so they keep their direct
    solutions."""
    assert policy.static_solver("auto", 3, policy.CG3D_FROM_UNKNOWNS) == "cg"
    assert policy.static_solver("auto", 3, 9000) == "nested-dissection"
    assert policy.static_solver("auto", 2, 10 ** 6) == "nested-dissection"
    assert policy.static_solver("direct", 3, 10 ** 6) == "direct"
    assert policy.condensed_cg(0.0, True).startswith("constraint rows")
    assert policy.condensed_cg(np.nan, False).startswith("K not symmetric")
