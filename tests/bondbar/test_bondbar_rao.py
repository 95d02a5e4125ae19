"""Rao's series, seed 004 Eq. (105), and its exact sum (manufactured.vibration1d)."""
import ast
import pathlib

import numpy as np
import pytest

import manufactured.vibration1d as rao

EPS = np.finfo(float).eps
C = rao.wave_speed(200e9, 7850.0)
L, STRAIN = 1.0, 1e-3
ARGS = dict(strain=STRAIN, length=L, wave_speed=C)
X = np.linspace(0.0, L, 41)
T = np.linspace(0.0, 3 * 4 * L / C, 121)


@pytest.mark.parametrize("terms", [10, 100, 2000])
def test_series_converges_to_the_closed_sum_within_the_tail_bound(terms):
    diff = np.abs(rao.rao_series(X, T, terms=terms, **ARGS) - rao.rao_displacement(X, T, **ARGS))
    bound = rao.series_tail_bound(strain=STRAIN, length=L, terms=terms)
    # the bound, plus the round-off of summing `terms` terms of size <= eps L
    assert diff.max() <= bound + 4 * terms * EPS * STRAIN * L
    assert diff.max() >= 0.5 * bound  # the bound is tight (reached at x = L, t = 0)


def test_closed_sum_meets_the_initial_and_boundary_conditions():
    u = rao.rao_displacement(X, T, **ARGS)
    np.testing.assert_allclose(u[0], STRAIN * X, rtol=0, atol=4 * EPS * STRAIN * L)  # eps x
    np.testing.assert_allclose(u[:, 0], 0.0, rtol=0, atol=4 * EPS * STRAIN * L)  # fixed at x = 0
    h = 1e-6 * L  # free at x = L: the extension is even about L, so u_x(L) = 0 to round-off / h
    du = rao.rao_displacement([L - h, L + h], T, **ARGS)
    np.testing.assert_allclose((du[:, 1] - du[:, 0]) / (2 * h), 0.0, rtol=0,
                               atol=16 * EPS * STRAIN * L / h)


def test_free_end_is_a_triangle_wave_of_the_first_mode_period():
    f1 = rao.first_mode_frequency(length=L, wave_speed=C)
    assert f1 == pytest.approx(C / (4 * L), rel=EPS)
    theta = np.angle(np.exp(1j * 2 * np.pi * f1 * T))  # in (-pi, pi]
    np.testing.assert_allclose(rao.rao_displacement([L], T, **ARGS)[:, 0],
                               STRAIN * L * (1 - 2 * np.abs(theta) / np.pi), rtol=0,
                               atol=64 * EPS * STRAIN * L)


def test_reference_side_never_imports_pdverify():
    tree = ast.parse(pathlib.Path(rao.__file__).read_text())
    names = {a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names}
    names |= {node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert not any(n.split(".")[0] == "pdverify" for n in names)
