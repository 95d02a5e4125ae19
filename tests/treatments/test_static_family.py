"""The static-state family: every treatment assembles the same problem description, and
each one that claims exactness for a class of fields reproduces it to round-off on a
box of every dimension it serves (affine fields: a homogeneous stress state with its
tractions on free faces; seed 000 App. D for the Taylor orders)."""
import numpy as np
import pytest

from pdverify.corrections.registry import treatments
from pdverify.pd import StateBasedConstants, build_stencil, get_influence, state_based_stencil
from pdverify.pd.problem import FaceCondition, StaticProblem
from pdverify.solvers.front import solve

KIND = {1: "1d", 2: "plane-strain", 3: "3d"}
E, NU = 200e9, 0.3
#: round-off bound of an exact reproduction: the solves' relative residual is ~1e-15 and
#: the condition estimates of these small systems stay below 1e7 (diagnostics), so the
#: solution error is below ~1e7 * 2.2e-16 ~ 2e-9 relative to the largest displacement
EXACT = 1e-8


def _affine(dim):
    """u = G x with a fixed, full gradient G (shear and stretch in every component)."""
    rng = np.random.default_rng(7)
    G = rng.uniform(-1e-3, 1e-3, (dim, dim))
    return G


def _stress(G, constants):
    lam, mu = constants.moduli()
    eps = 0.5 * (G + G.T)
    return lam * np.trace(eps) * np.eye(len(G)) + 2 * mu * eps


def _problem(dim, quadrature="moment-corrected", faces_prescribed=("x-",), m=3.0):
    """A box with u prescribed (every component) on ``faces_prescribed`` and the affine
    field's traction sigma . n on every other face; moment-corrected weights give the
    discrete material the continuum moduli, so the affine field is the PD solution."""
    h = 0.05
    lengths = (0.4, 0.3, 0.3)[:dim]
    c = StateBasedConstants(KIND[dim], E, NU)
    inf = get_influence("gaussian")
    stencil = (build_stencil(1, m) if dim == 1
               else state_based_stencil(dim, m, h, inf, quadrature))
    G = _affine(dim)
    S = _stress(G, c) if dim > 1 else np.array([[E * G[0, 0]]])
    names = ("x-", "x+", "y-", "y+", "z-", "z+")[:2 * dim]
    cond = {f: (FaceCondition(prescribed=tuple(range(dim))) if f in faces_prescribed
                else FaceCondition(traction=lambda x, n: n @ S.T)) for f in names}
    return StaticProblem(lengths, (0.0,) * dim, h, stencil, c, inf, cond,
                         exact=lambda x: x @ G.T, thickness=1.0, solver="direct",
                         where="test")


def _error(problem, name, **params):
    t = treatments()[name]
    system = t.assemble(problem, params)
    x, info = solve(system, where=f"test/{name}")
    g = system.model.grid
    xr = g.x[g.interior_ids]
    u = system.displacements(x)[:g.n_interior]
    ref = problem.exact(xr)
    return np.abs(u - ref).max() / np.abs(ref).max()


@pytest.mark.parametrize("dim", [1, 2])
def test_taylor_fictitious_is_exact_for_affine_fields(dim):
    """seed 000 App. D: order n reproduces degree-n fields; in 2D the tractions enter as
    the force flux of each boundary cell face (Lagrange rows)."""
    assert _error(_problem(dim), "taylor-fictitious", order=1) < EXACT


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_surface_nodes_are_exact_for_affine_fields(dim):
    assert _error(_problem(dim), "surface-nodes", order=1) < EXACT


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_mirror_nodes_full_traction_are_exact_for_affine_fields(dim):
    """With the full traction relation and the mirror mismatch corrected (our variant,
    ``mirror_point=corrected``) the mirror relations reproduce an affine field; the
    method's nearest node does so only where the mirror point is a node (1D, faces away
    from corners), so in 2D and 3D a general affine field is missed near the corners."""
    err = _error(_problem(dim), "mirror-nodes", neumann="full-traction",
                 mirror_point="corrected")
    assert err < EXACT
    nearest = _error(_problem(dim), "mirror-nodes", neumann="full-traction",
                     mirror_point="nearest")
    assert (nearest < EXACT) == (dim == 1)


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_pddo_is_exact_for_affine_fields(dim):
    """PDDO's operators are exact for quadratics, the LPS bulk for affine fields."""
    assert _error(_problem(dim), "pddo") < EXACT


@pytest.mark.parametrize("dim", [2, 3])
def test_none_is_not_exact_so_the_affine_tests_can_fail(dim):
    """The uncorrected model misses the same field by far more than round-off (the
    surface effect), so the tests above discriminate."""
    assert _error(_problem(dim), "none") > 1e-3



# finding 001-body3d-mirror-pddo (pdverify.deviations)
def test_finding_mirror_and_pddo_on_the_manufactured_box():
    """The finding in pdverify/deviations.py (body3d-manufactured): mirror nodes and PDDO
    stay far from surface nodes on the cubic manufactured field (h = 0.1: about 151 and
    188 % against 0.97 %; Eq. 38). If either comes within 50x of surface nodes the
    finding is out of date (the margin: the measured ratios are 155x and 193x)."""
    from pdverify.scenes import get_scene
    scene = get_scene("body3d-manufactured")
    err = {m: scene.run(m, {"spacing": 0.1}).metrics["max_error_pct"]
           for m in ("surface-nodes", "mirror-nodes", "pddo")}
    assert err["surface-nodes"] < 2.0          # seed 001 Fig. 12: < 1 % at h = 0.05
    assert err["mirror-nodes"] > 50 * err["surface-nodes"]
    assert err["pddo"] > 50 * err["surface-nodes"]
