"""One home for analytic content: seed 001's hand-written Eqs. (40)-(41) agree with the engine."""
import numpy as np
import pytest

import manufactured
from manufactured import surface3d as s3


@pytest.fixture(scope="module")
def engine(tmp_path_factory):
    # seed 001 §4.2: u = (c_u x y, c_v x^3, c_w x z); ERRATA choices E = 200 GPa, nu = 0.3;
    # horizon 3 h = 0.15 m
    field = [f"{s3.C_U}*x*y", f"{s3.C_V}*x**3", f"{s3.C_W}*x*z"]
    return manufactured.solution(field, model="state-based", dim=3, horizon=0.15, E=200e9,
                                 nu=0.3, influence="gaussian")


def test_closed_forms_match_the_symbolic_engine(engine, rng):
    # Both evaluate the same exact polynomial expressions, so they agree to round-off:
    # 1e-12 relative to the largest entry (a few hundred flops in double precision).
    pts = rng.uniform([0, -0.25, -0.25], [1, 0.25, 0.25], size=(50, 3))
    k_theta, k_e = s3.constants_3d(200e9, 0.3)
    b = s3.manufactured_body_force(pts, k_theta=k_theta, k_e=k_e)
    tau = s3.manufactured_stress(pts, k_theta=k_theta, k_e=k_e, horizon=0.15)
    np.testing.assert_allclose(s3.manufactured_displacement(pts), engine.displacement(pts),
                               rtol=0, atol=1e-15)
    np.testing.assert_allclose(b, engine.body_force(pts), rtol=0, atol=1e-12 * np.abs(b).max())
    np.testing.assert_allclose(tau, engine.stress(pts), rtol=0, atol=1e-12 * np.abs(tau).max())
