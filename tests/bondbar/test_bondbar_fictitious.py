"""Taylor's fictitious nodes (seed 000 §7: its bond-based form) and the surface nodes
(seed 001 read for bond-based PD) on seed 004's bars (issue 55): the end force sigma A
as the traction sigma on the bar's end faces, the held midpoint as the plane of
symmetry, the held end of the half bar as u = 0 at its surface point.

The claim checked is seed 000's exactness for a linear field (§5.1): the extrapolation
reproduces u = sigma x / E on the layer, so with the discrete calibration (the lattice's
modulus is E) it solves every real equation and the flux rows. The uncorrected bar
misses it by 22 % on the same bar (f(9) = 1.2178540, Table 12), so the tests can fail.
"""
import pytest

from pdverify.corrections.registry import treatments
from pdverify.errors import InputError
from pdverify.scenes import get_scene
from pdverify.scenes.bar1d import MACHINE_PRECISION_PCT

METHODS = ("taylor-fictitious", "surface-nodes")
#: |f - 1| of a round-off solution: the scene's machine-precision bound (1e-10 relative,
#: condition < 1e6 x eps, pdverify.scenes.bar1d.MACHINE_PRECISION) as a ratio
ROUND_OFF = MACHINE_PRECISION_PCT / 100.0


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("over", [{}, {"nodes": 10}, {"nodes": 101, "order": 2},
                                  {"horizon_ratio": 4.5, "nodes": 21}])
def test_end_loaded_bar_is_classical(method, over):
    """Odd and even N (the centre between two nodes or on one), order 1 and 2, the
    horizon through and between elements: f = 1 and u = sigma x / E to round-off."""
    run = get_scene("bar1d-homogenization").run(method, over)
    assert run.status == "ok", run.message
    assert abs(run.metrics["strain_factor"] - 1.0) < ROUND_OFF
    assert run.metrics["max_error_pct"] < MACHINE_PRECISION_PCT
    assert run.size["fictitious_nodes"] > 0
    # the loaded end's flux is the load: the row the solve imposed (round-off)
    assert abs(run.diagnostics["end_flux_over_load"] - 1.0) < ROUND_OFF


def test_the_uncorrected_bar_misses_it():
    run = get_scene("bar1d-homogenization").run("none", {})
    assert run.status == "ok", run.message
    assert run.metrics["strain_factor"] - 1.0 > 0.2     # Table 12: f(9) = 1.2178


@pytest.mark.parametrize("method", METHODS)
def test_half_bar_is_the_symmetry_half(method):
    """Bar (b), its end held at the surface, is bar (a)'s half on their shared nodes, and
    both are classical; bar (c) (seed 004's discrete variant) is not run."""
    run = get_scene("bar1d-constraints").run(method, {})
    assert run.status == "ok", run.message
    m = run.metrics
    assert m["half_vs_full_max_diff"] < ROUND_OFF
    assert m["max_error_pct"] < MACHINE_PRECISION_PCT
    assert m["error_b_pct"] < MACHINE_PRECISION_PCT
    assert "horizon_constraint_vs_full_max_diff" not in m and "x_c" not in run.fields
    assert run.fields["x_b"].size == (run.params["nodes"] + 1) // 2 - 1


def test_uncorrected_half_bar_is_not_the_half():
    run = get_scene("bar1d-constraints").run("none", {})
    assert run.metrics["half_vs_full_max_diff"] > 1e-3


@pytest.mark.parametrize("over, words", [({"end_weight": "half"}, "end_weight=full only"),
                                         ({"order": 4}, "order <= 3")])
def test_bad_input_is_one_line(over, words):
    with pytest.raises(InputError, match=words):
        get_scene("bar1d-homogenization").resolve("taylor-fictitious", over)


@pytest.mark.parametrize("method", METHODS + ("pddo", "mirror-nodes"))
def test_vibration_refusal_is_the_mathematical_reason(method):
    why = treatments()[method].why_not(get_scene("bar1d-vibration"))
    assert why is not None and "not wired" not in why
    assert ("index-1" if method != "mirror-nodes" else "non-symmetric") in why
    if method in METHODS:
        assert "differential-algebraic" in why


@pytest.mark.parametrize("method", ["pddo", "mirror-nodes"])
@pytest.mark.parametrize("scene, metric", [("bar1d-homogenization", "strain_factor"),
                                           ("bar1d-constraints", "half_vs_full_max_diff")])
def test_pddo_and_mirror_nodes_on_the_bars_are_classical(method, scene, metric):
    """PDDO's bond-based form (pdverify.corrections.pddo_bond: exact for quadratic fields
    with the lattice's own tensor; it adds no node) and the mirror nodes' (affine fields
    exact with the lattice's C11: corrections.mirror_nodes.bond_lattice_moduli, C12 = 0
    in 1D) on the same bars meet the linear field to round-off."""
    run = get_scene(scene).run(method, {})
    assert run.status == "ok", run.message
    target = 1.0 if metric == "strain_factor" else 0.0
    assert abs(run.metrics[metric] - target) < ROUND_OFF
    assert run.metrics["max_error_pct"] < MACHINE_PRECISION_PCT
    if method == "pddo":
        assert run.size.get("fictitious_nodes", 0) == 0
