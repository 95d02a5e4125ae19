"""Series references check their own truncation (issue 31): the estimate is honest (it
bounds the omitted part, and is attained), it is recorded with every run, and a run whose
reference is not below 1e-3 of the error it measures fails saying so."""
import numpy as np
import pytest

from manufactured import vibration1d as rao
from manufactured import wave1d as wv
from pdverify.cli import main
from pdverify.scenes import get_scene
from pdverify.scenes.base import TRUNCATION_SHARE

V = float(np.sqrt(2e11 / 8000))   # the wave scene's defaults: E = 200 GPa, rho = 8000


@pytest.mark.parametrize("n_terms", [1, 3, 5, 10, 20])
def test_wave_truncation_estimate_bounds_and_is_attained(n_terms):
    """Against the 400-mode series (its own tail 3.4e-13, see below), over the whole bar
    and the scene's sampling window: the actual truncation never exceeds the estimate
    (|sin cos| <= 1 bounds each omitted mode) and reaches it within 1e-3 (at t = 0 and
    x = l/2 every odd mode has |sin| = 1 and the same sign pattern as its coefficient)."""
    x = np.linspace(0.0, 1.0, 2001)
    t = np.linspace(0.0, 2e-4, 41)
    ref = wv.wave_series(horizon=0.1, wave_speed=V, n_terms=400)
    s = wv.wave_series(horizon=0.1, wave_speed=V, n_terms=n_terms)
    actual = np.max(np.abs(s.displacement(x, t) - ref.displacement(x, t)))
    assert actual <= s.tail * (1 + 1e-9) + ref.tail
    assert actual >= (1 - 1e-3) * s.tail


def test_wave_with_one_term_fails_naming_its_truncation(capsys):
    code = main(["run", "wave1d-surface-nodes", "--set", "n_terms=1"])
    first = capsys.readouterr().out.splitlines()[0]
    assert code == 1
    assert ("failed (wave1d-surface-nodes/surface-nodes: the reference series (n_terms=1; "
            "omitted modes ~65.4 % of the peak): its truncation error estimate 65.4 is not "
            "below 0.001 of the max_error_pct 34.02 it measures") in first, first


def test_wave_default_records_its_estimate_far_below_its_error():
    res = get_scene("wave1d-surface-nodes").run("surface-nodes", {})
    assert res.status == "ok", res.message
    est = res.diagnostics["series_truncation_pct"]
    # what remains at 40 modes is the pulse's end values, 2 x 0.02 exp(-25) = 5.6e-13 m,
    # i.e. 2.8e-9 % of the 0.02 m peak, plus the projections' round-off (~1e-18 m)
    assert 2.7e-9 < est < 3.5e-9
    assert est < 1e-9 * res.metrics["max_error_pct"]


def test_rao_exact_sum_rounding_bound_holds_in_extended_precision():
    """The closed-form sum in float64 against the same formula in x87 extended precision
    (eps 1.1e-19, so its own error is ~2000x below the bound): the difference stays below
    the bound, which is no more than ~100x loose (a bound, not an estimate)."""
    if np.finfo(np.longdouble).eps > 1e-18:
        pytest.skip("no extended precision on this platform")
    L, eps_s, c = 1.0, 1e-3, float(np.sqrt(2e11 / 7850))
    t = np.linspace(0.0, 5 * 4 * L / c, 4001)
    x = np.array([L / 99, L])
    u = rao.rao_displacement(x, t, strain=eps_s, length=L, wave_speed=c)
    Ld, cd, ed = np.longdouble(L), np.longdouble(c), np.longdouble(eps_s)

    def ext(s):
        r = np.mod(s + Ld, 4 * Ld) - Ld
        return ed * np.where(r <= Ld, r, 2 * Ld - r)

    ct = cd * t.astype(np.longdouble)[:, None]
    xd = x.astype(np.longdouble)[None, :]
    exact = (ext(xd - ct) + ext(xd + ct)) / 2
    diff = float(np.max(np.abs(u - exact)))
    bound = rao.exact_sum_error_bound(strain=eps_s, length=L, wave_speed=c, t_max=t[-1])
    assert diff <= bound
    assert bound < 100 * max(diff, 1e-3 * bound)


def test_vibration_records_its_reference_bound():
    res = get_scene("bar1d-vibration").run("none", {})
    assert res.status == "ok", res.message
    bound = res.diagnostics["reference_error_bound_pct"]
    assert 0 < bound < TRUNCATION_SHARE * res.metrics["max_error_pct"]
