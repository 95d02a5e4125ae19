"""Seed 001 scenes: the 'Must show' items of issue 7 (3D ones are slow)."""
import numpy as np
import pytest

from pdverify.scenes import get_scene
from pdverify.corrections.surface_nodes import surface_node_model
from pdverify.pd import StateBasedConstants
from descriptions import box_problem


@pytest.fixture(scope="module")
def _run(run_once):
    """One run of the scene, shared through the session (``run_once`` in conftest)."""
    return lambda scene, method, **over: _checked(run_once(scene, method, **over), scene,
                                                  method, over)


def _checked(r, scene, method, over):
    assert r.status == "ok", r.message
    print(f"{scene} {method} {over}: " + ", ".join(
        f"{k}={v:.4g}" for k, v in r.metrics.items() if "max_error" in k and "_u_" not in k
        and "_v_" not in k), f"total {r.timings['total_s']:.1f} s")
    return r


def _discrete_plate_strain_error(p, m_ratio):
    """Strain error of the discrete PD material under the plate's uniaxial stress.

    The discrete material (exact partial areas, m_ratio) has moduli C11, C12 slightly off
    the continuum (the lattice's fourth moment is not isotropic); they are read off the
    force flux of a unit strain, and sigma = (0, p) gives the homogeneous strains.
    """
    c = StateBasedConstants("plane-strain", p["E"], p["nu"])
    model, P = surface_node_model(box_problem((0.3, 0.3), (0.0, 0.0), 0.02, m_ratio, c), 1)
    g = model.grid
    eps = np.diag([1.0, 0.0])

    def u(x):
        return x @ eps.T
    rows = model.rows_of_state(u(g.x), model.dilatation_of_field(u, g.x), P).reshape(2, -1).T
    flux = rows[g.n_interior:] / g.face_area
    C11 = flux[g.face_start[1], 0]
    C12 = flux[g.face_start[3], 1]
    ex, ey = np.linalg.solve([[C11, C12], [C12, C11]], [0.0, p["traction"]])
    E, nu, t = p["E"], p["nu"], p["traction"]
    return abs(ex / (-nu * (1 + nu) * t / E) - 1) * 100, abs(ey / ((1 - nu ** 2) * t / E) - 1) * 100


def test_plate_uncorrected_above_5_pct(_run):
    r = _run("plate2d-plane-strain", "none")
    assert r.metrics["max_error_pct"] > 5.0  # issue 7 'Must show'


def test_plate_surface_nodes_is_the_discrete_material_response(_run):
    """With surface nodes the plate deforms homogeneously, exactly as the discrete material.

    The whole remaining error is the discrete material's own stiffness error (lattice
    anisotropy of the m = 3 stencil), not the boundary treatment.
    """
    scene = get_scene("plate2d-plane-strain")
    r = _run("plate2d-plane-strain", "surface-nodes")
    eu, ev = _discrete_plate_strain_error(scene.resolve("surface-nodes", {}), 3.0)
    print(f"discrete-material strain error: u {eu:.4f} %, v {ev:.4f} %")
    # a linear field solved to round-off (cond ~1e5 here): agreement to 1e-6 of the error
    np.testing.assert_allclose(r.metrics["max_error_u_pct"], eu, rtol=1e-6)
    np.testing.assert_allclose(r.metrics["max_error_v_pct"], ev, rtol=1e-6)
    # homogeneous: the boundary layer is no worse than the interior (1e-6 as above)
    np.testing.assert_allclose(r.metrics["boundary_rel_l2_error"],
                               r.metrics["interior_rel_l2_error"], rtol=1e-6)


# finding 001-plate-lattice (pdverify.deviations): the m = 3 lattice's own 1.2 %
@pytest.mark.xfail(strict=True, reason="issue 7 expects < 0.1 %; with exact partial areas at "
                   "m = 3 the discrete 2D material itself is off by 1.2 % in u (lattice "
                   "anisotropy, see test above); it falls to 0.098 % at m = 5 and to "
                   "round-off with quadrature=moment-corrected (test below)")
def test_plate_surface_nodes_below_0p1_pct(_run):
    assert _run("plate2d-plane-strain", "surface-nodes").metrics["max_error_pct"] < 0.1


def test_plate_surface_nodes_with_moment_corrected_quadrature_is_exact(_run):
    """Isotropic lattice moments: the discrete material is the continuum one, so the
    surface node method reproduces the linear field of Eq. (43) to round-off."""
    r = _run("plate2d-plane-strain", "surface-nodes", quadrature="moment-corrected")
    assert r.metrics["max_error_pct"] < 0.1       # issue 7 'Must show'
    # exactness claim: round-off of a solve with condition estimate ~1e5-1e6 (eps * cond
    # ~ 1e-10 relative = 1e-8 %)
    assert r.metrics["max_error_pct"] < 1e-8, r.diagnostics
    none = _run("plate2d-plane-strain", "none", quadrature="moment-corrected")
    assert none.metrics["max_error_pct"] > 5.0    # the boundary error is not the material's


@pytest.mark.parametrize("influence", ["hyperbolic", "constant", "conical"])
def test_plate_exactness_holds_for_every_influence_function(influence, _run):
    """The same claim with another registered influence (``--set influence=...``): the
    lattice error depends on the influence, the method's exactness does not."""
    exact = _run("plate2d-plane-strain", "surface-nodes", influence=influence,
                 quadrature="moment-corrected", spacing=0.05)
    assert exact.metrics["max_error_pct"] < 1e-8, exact.diagnostics  # as above: eps * cond
    lattice = _run("plate2d-plane-strain", "surface-nodes", influence=influence, spacing=0.05)
    assert lattice.metrics["max_error_pct"] > 1e-3   # exact partial areas: a lattice error


def test_plate_discrete_material_error_falls_with_m_ratio():
    p = get_scene("plate2d-plane-strain").resolve("none", {})
    errs = [max(_discrete_plate_strain_error(p, m)) for m in (3.0, 4.0, 5.0)]
    print("discrete plate strain error by m-ratio 3, 4, 5:", errs)
    assert errs[0] > errs[1] > errs[2]


@pytest.mark.slow
def test_body3d_traction_must_show(_run):
    none = _run("body3d-traction", "none")
    sn = _run("body3d-traction", "surface-nodes", order=1)
    assert none.metrics["max_error_pct"] > 20.0   # issue 7 (paper: > 30 %)
    assert sn.metrics["max_error_pct"] < 0.1      # issue 7 (paper: 0.06 %)
    # linear field: with isotropic lattice moments the method is exact (round-off of a
    # dense solve, eps * cond ~ 1e-16 * 1e6 -> 1e-8 %)
    mc = _run("body3d-traction", "surface-nodes", order=1, quadrature="moment-corrected")
    assert mc.metrics["max_error_pct"] < 1e-8, mc.diagnostics


@pytest.fixture(scope="module")
def manufactured_runs(_run):
    runs = {"none": _run("body3d-manufactured", "none")}
    runs.update({n: _run("body3d-manufactured", "surface-nodes", order=n) for n in (1, 2, 3)})
    return runs


@pytest.mark.slow
def test_body3d_manufactured_must_show(manufactured_runs):
    runs = manufactured_runs
    err = {k: r.metrics["max_error_pct"] for k, r in runs.items()}
    assert err["none"] > 100.0                    # issue 7 (paper: > 130 %)
    assert err[2] < 1.0 and err[3] < 1.0          # issue 7 (paper: < 1 %; 0.4 % at N = 3)
    assert err[3] < err[1]                        # issue 7
    # orders 2 and 3 both reproduce the field's curvature; the paper notes they are close
    assert err[3] <= err[2]
    for n in (1, 2, 3):  # surface nodes beat the baseline by well over an order of magnitude
        assert err[n] < err["none"] / 20


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 7 expects < 1 % for N = 1 too; on the ERRATA body "
                   "(1 x 0.5 x 0.5 m, h = 0.05) N = 1 gives 1.88 %: its own linear Taylor "
                   "truncation on the body edges (0.41 % with quadratic extrapolation)")
def test_body3d_manufactured_order_1_below_1_pct(manufactured_runs):
    assert manufactured_runs[1].metrics["max_error_pct"] < 1.0


@pytest.mark.slow
def test_body3d_manufactured_error_falls_as_h_falls_at_fixed_delta(_run):
    """Fixed delta = 0.15 m on a smaller body; h = 0.05, 0.0375, 0.03 (m = 3, 4, 5), N = 3."""
    hs = np.array([0.05, 0.0375, 0.03])
    errs, l2 = [], []
    for h in hs:
        r = _run("body3d-manufactured", "surface-nodes", order=3, lx=0.45, ly=0.3, lz=0.3,
                 spacing=float(h), m_ratio=round(0.15 / h))
        errs.append(r.metrics["max_error_pct"])
        l2.append(r.metrics["rel_l2_error"])
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    slope_l2 = np.polyfit(np.log(hs), np.log(l2), 1)[0]
    print("errors", errs, "slope", slope, "l2 slope", slope_l2)
    # consistency error of the discrete operator is O(h^2) at fixed delta (mid-point
    # quadrature with exact cell fractions, lattice flux sum of Eq. 35); margin 0.5 below
    # that rate for both fitted trends
    assert slope > 1.5 and slope_l2 > 1.5
    # the fitted trend is what issue 7 asks for; the levels are not monotone: the lattice
    # error of the flux sum (Eq. 35) depends on m, and m = 4 is unusually accurate
    # (observed max 0.69, 0.19, 0.32 %; L2 0.0057, 0.0011, 0.0022). The finest level is
    # still below the coarsest in both norms.
    assert errs[-1] < errs[0] and l2[-1] < l2[0]
