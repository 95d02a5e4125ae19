"""Mirror symmetry of the mode I crack scenes (issue 54): the body, the crack, the loads and
the pins of ``plate-crack`` and ``plate-edge-crack`` are symmetric about the crack line
y = 0, so the solution is: u_x even and u_y odd under y -> -y (the centre plate also
about x = 0: u_x odd, u_y even under x -> -x), to round-off.

Tolerance: a backward-stable solve's forward error is at most the condition number
times the backward error (Higham, Accuracy and Stability of Numerical Algorithms, 2nd
ed., Thm 7.2, to first order), here eps (the refinement stops at 2 eps,
``solvers.mixed.REFINE_STOP``; its factor at the unit roundoff) times kappa_1 of the
solved block of the displacement form: ``tol = eps kappa_1 max |u|``, with kappa_1 from
Higham & Tisseur's 1-norm estimator (``scipy.sparse.linalg.onenormest``, on K and on
K^-1 by its LU), computed at the size tested."""
import numpy as np
import pytest
import scipy.sparse.linalg as sla

from pdverify.scenes import get_scene
from pdverify.solvers.front import displacement_form, solve

#: a coarse grid: the fit's window is not needed (no measure), so h may be coarser than
#: the scenes allow; m = 3 as the scenes
SPACING = 0.05


def _solve(scene_id, method):
    scene = get_scene(scene_id)
    p = {**scene.default_params(), "spacing": SPACING}
    p.update({q.name: q.default for q in scene.method(method).params if q.name not in p})
    problem = scene.problem(p, "symmetry")
    system = scene.treatment(method).assemble(problem, p)
    x, _ = solve(system, where="symmetry")
    u, _ = scene.solution(system, x)
    K, _ = displacement_form(system)
    free = np.setdiff1d(np.arange(K.shape[0]), np.asarray(system.fixed, dtype=int))
    Kf = K[free][:, free].tocsc()
    lu = sla.splu(Kf)
    inv = sla.LinearOperator(Kf.shape, matvec=lu.solve, rmatvec=lambda v: lu.solve(v, "T"),
                             dtype=float)
    kappa = sla.onenormest(Kf) * sla.onenormest(inv)
    return scene.real_nodes(system), u, kappa


def _mirror(x, axis):
    """The row of the node mirrored about the axis's mid-line (lattice positions)."""
    y = x.copy()
    y[:, axis] = -y[:, axis]       # both bodies are centred on their mirror lines
    key = lambda z: [tuple(r) for r in np.round(z / (1e-3 * SPACING)).astype(np.int64)]
    where = {k: i for i, k in enumerate(key(x))}
    return np.array([where[k] for k in key(y)])


@pytest.mark.parametrize("scene_id", ["plate-crack", "plate-edge-crack"])
@pytest.mark.parametrize("method", ["none", "energy"])
def test_the_mode_i_solution_is_mirror_symmetric_about_the_crack_line(scene_id, method):
    x, u, kappa = _solve(scene_id, method)
    scale = np.abs(u).max()
    tol = np.finfo(float).eps * kappa * scale
    m = _mirror(x, 1)
    err_x = np.abs(u[m, 0] - u[:, 0]).max()
    err_y = np.abs(u[m, 1] + u[:, 1]).max()
    print(f"{scene_id}/{method}: kappa_1 {kappa:.3g}, tol {tol / scale:.2g} of max|u|; "
          f"u_x even to {err_x / scale:.2g}, u_y odd to {err_y / scale:.2g}")
    assert err_x <= tol and err_y <= tol
    # the check can fail: the opening is far above the tolerance
    assert np.abs(u[:, 1]).max() > 1e6 * tol
    if scene_id == "plate-crack":         # the centre crack: also about x = 0
        mx = _mirror(x, 0)
        assert np.abs(u[mx, 0] + u[:, 0]).max() <= tol
        assert np.abs(u[mx, 1] - u[:, 1]).max() <= tol


def test_finding_the_edge_crack_mouth_breaks_the_surface_nodes_symmetry():
    """Finding ``054-edge-crack-surface-nodes`` (pdverify.deviations): with the surface
    nodes the edge crack's mode I field is not mirror-symmetric about the crack line to
    the solver's accuracy (measured 5.9e-4 of max |u| at h = 0.05 m, against a round-off
    bound of 2.9e-9; largest near a loaded end's corner). Measured, not explained: this
    test fails once the defect falls to round-off (then the finding goes)."""
    x, u, kappa = _solve("plate-edge-crack", "surface-nodes")
    scale = np.abs(u).max()
    tol = np.finfo(float).eps * kappa * scale
    m = _mirror(x, 1)
    defect = np.maximum(np.abs(u[m, 0] - u[:, 0]), np.abs(u[m, 1] + u[:, 1]))
    print(f"kappa_1 {kappa:.3g}, tol {tol / scale:.2g}, defect {defect.max() / scale:.2g} "
          f"of max|u| at {x[np.argmax(defect)]}")
    # a defect ten times the round-off bound cannot be round-off (measured 2e5 times it)
    assert defect.max() > 10 * tol
