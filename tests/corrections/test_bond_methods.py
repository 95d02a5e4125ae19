"""The energy and volume corrections (issue: the other corrections), the stiffness scenes
under homogeneous strain and the method x scene plumbing."""
import numpy as np
import pytest

from pdverify.corrections.energy import axis_factors, energy_factors
from pdverify.pd.work import uniaxial, work_density
from pdverify.corrections.registry import bond_methods
from pdverify.corrections.volume import horizon_volumes, volume_factors
from pdverify.errors import InputError
from pdverify.pd import (BondBasedModel, BoxGrid, Closure, StateBasedConstants, StateBasedModel,
                         build_stencil, get_influence, state_based_stencil)
from pdverify.scenes import get_scene
from pdverify.scenes.stiffness import strain_states

EPS = 1e-12  # machine-epsilon claims, relative (a few hundred summed terms of O(1))


def bond_model(m=3.0, cells=(12, 9), closure=None, placement="cell-centred"):
    g = BoxGrid(tuple(float(c) for c in cells), (0.0, 0.0), 1.0, placement=placement)
    return BondBasedModel(g, build_stencil(2, m), 1.0, get_influence("constant"), closure)


def state_model(m=2.0, cells=(8, 6, 5), closure=None):
    inf = get_influence("gaussian")
    g = BoxGrid(tuple(float(c) for c in cells), (0.0,) * 3, 1.0, 0)
    return StateBasedModel(g, state_based_stencil(3, m, 1.0, inf), StateBasedConstants("3d", 1.0, 0.3),
                           inf, closure)


def dist_to_surface(model):
    g = model.grid
    return g.distance_to_surface(g.x[g.interior_ids])


@pytest.mark.parametrize("build", [bond_model, state_model])
def test_bulk_work_density_is_a_complete_node(build):
    """The closed-form bulk W equals the work density of a node whose neighbourhood is
    complete (its own force state's share of each bond); machine epsilon."""
    model = build(cells=(14, 14) if build is bond_model else (11, 11, 11))
    d = model.dim
    far = np.flatnonzero(dist_to_surface(model) > model.horizon)
    assert far.size
    for _, eps in strain_states(d):
        W = work_density(model, eps)[model.grid.interior_ids]
        assert np.allclose(W[far], model.bulk_work_density(eps), rtol=EPS, atol=0)


def test_energy_factors_against_a_loop():
    """lambda_i^k = W_bulk / W_i by a plain loop over the bonds (bond-based energy density
    1/4 sum s e^2 / V_i); the ellipse reduces to g_k for bonds along an axis."""
    model = bond_model(closure=None)
    lam = axis_factors(model)
    V = model.node_volume
    for k in range(2):
        W = np.zeros(model.grid.n_ext)
        for a, b, s, n, x in zip(model.bond_a, model.bond_b, model.bond_stiffness, model.bond_n,
                                 model.bond_x):
            e = x * n[k] ** 2
            W[a] += 0.25 * s * e * e / V[a]
            W[b] += 0.25 * s * e * e / V[b]
        assert np.allclose(lam[:, k], model.bulk_work_density(uniaxial(2, k)) / W, rtol=EPS)
    G = energy_factors(model)
    along_x = np.abs(model.bond_n[:, 1]) < 1e-15
    g_x = 0.5 * (lam[model.bond_a, 0] + lam[model.bond_b, 0])
    assert np.allclose(G[along_x], g_x[along_x], rtol=EPS)


@pytest.mark.parametrize("build", [bond_model, state_model])
def test_corrections_leave_the_bulk_untouched(build):
    """Bonds whose two ends have complete neighbourhoods get factor 1 (volume and energy:
    a node's own work density depends on its own bonds only, for LPS too): both compare
    with the bulk lattice's own sums; machine epsilon."""
    model = build(cells=(14, 14) if build is bond_model else (11, 11, 11))
    dist = dist_to_surface(model)
    for factors in (volume_factors, energy_factors):
        complete = dist > model.horizon
        both = complete[model.bond_a] & complete[model.bond_b]
        assert both.any()
        assert np.allclose(factors(model)[both], 1.0, rtol=0, atol=EPS)


def test_horizon_volume_of_a_corner():
    """Cell-centred corner node of a constant-influence 2D lattice: its bonds reach the
    quadrant of the stencil with both offsets >= 0 minus itself: a loop over the stencil."""
    model = bond_model(m=3.0, cells=(10, 10))
    Vi = horizon_volumes(model)
    corner = int(np.argmin(np.sum(model.grid.x, axis=1)))
    st = model.stencil
    want = sum(b for o, b in zip(st.offsets, st.beta) if o[0] >= 0 and o[1] >= 0)
    assert Vi[corner] == pytest.approx(want, rel=EPS)
    assert volume_factors(model).max() > 1.0


# ---------------------------------------------------------------- the stiffness scenes
@pytest.fixture(scope="module")
def metrics(run_once):
    """The metrics of one run, shared through the session (``run_once`` in conftest)."""
    def get(scene, method, **over):
        r = run_once(scene, method, **over)
        assert r.status == "ok", r.message
        return r.metrics
    return get


def test_bond_based_bulk_is_exact_uncorrected(metrics):
    """Uncorrected bond-based sheet: nodes beyond one horizon have complete bonds, so
    W_i = W_bulk there to round-off (machine-epsilon claim, in percent)."""
    m = metrics("stiffness2d-sheet", "none", spacing=0.0025)
    assert m["interior_energy_error_pct"] < 1e-10


@pytest.mark.parametrize("scene,over", [("stiffness2d-sheet", {}),
                                        ("stiffness3d-box", {"spacing": 0.1}),
                                        ("stiffness2d-plate", {"spacing": 0.05})])
def test_energy_beats_none_under_homogeneous_strain(scene, over, metrics):
    """The energy correction lowers the largest and the RMS surface error of W_i/W_bulk
    (measured at the defaults: sheet 75 -> 40 %, box 39.4 -> 24.4 %, plate 27.5 -> 18.2 %)."""
    none, energy = metrics(scene, "none", **over), metrics(scene, "energy", **over)
    for key in ("surface_energy_error_pct", "surface_energy_rms_pct"):
        assert energy[key] < none[key]


def test_volume_beats_none_on_the_bond_based_sheet_only(metrics):
    """Measured finding: the volume correction helps the bond-based sheet (75 -> 48 % at
    the largest) but not the LPS box (39.4 -> 61.4 % at the default size) or plate
    (27.5 -> 38.2 %): an LPS bond force is already divided by m_i over the truncated
    family, so a surface node's uniaxial energy is partly restored without it, and the
    volume factor then overshoots."""
    none, vol = metrics("stiffness2d-sheet", "none"), metrics("stiffness2d-sheet", "volume")
    assert vol["surface_energy_error_pct"] < none["surface_energy_error_pct"]
    assert vol["surface_energy_rms_pct"] < none["surface_energy_rms_pct"]
    none, vol = metrics("stiffness3d-box", "none"), metrics("stiffness3d-box", "volume")
    assert vol["surface_energy_error_pct"] > none["surface_energy_error_pct"]


def test_energy_beats_none_on_boundary_value_problems(metrics):
    """The same correction on the displacement scenes (homogeneous stress; measured:
    sheet2d-tension u_x 301 -> 65 %, body3d-traction at h = 0.1 31 -> 24 %)."""
    none = metrics("sheet2d-tension", "none")
    energy = metrics("sheet2d-tension", "energy")
    assert energy["max_error_ux_pct"] < none["max_error_ux_pct"]
    assert energy["max_error_uy_pct"] < none["max_error_uy_pct"]
    none = metrics("body3d-traction", "none", spacing=0.1)
    energy = metrics("body3d-traction", "energy", spacing=0.1)
    assert energy["max_error_pct"] < none["max_error_pct"]


def test_factor_one_closure_is_the_uncorrected_model():
    """A force factor of exactly 1 reproduces the uncorrected state-based stiffness bit
    for bit (the hook itself changes nothing)."""
    plain = state_model()
    ones = state_model(closure=Closure(force_factor=lambda m: np.ones(m.bond_a.size)))
    assert (plain.stiffness() != ones.stiffness()).nnz == 0


# ---------------------------------------------------------------- plumbing
def test_every_bond_method_on_its_scenes():
    names = set(bond_methods())
    assert {"energy", "volume", "pals"} <= names
    for scene_id in ("stiffness2d-sheet", "sheet2d-tension", "body3d-traction", "bar1d-traction"):
        scene = get_scene(scene_id)
        want = {k for k, m in bond_methods().items() if m.serves(scene)}
        assert {"energy", "volume"} <= want
        assert want <= {m.name for m in scene.all_methods}
    # PALS: state-based models in 2D and 3D only
    assert "pals" in {m.name for m in get_scene("body3d-traction").all_methods}
    assert "pals" in {m.name for m in get_scene("plate2d-plane-strain").all_methods}
    for scene_id in ("bar1d-traction", "sheet2d-tension", "stiffness2d-sheet"):
        assert "pals" not in {m.name for m in get_scene(scene_id).all_methods}
    assert not {"energy", "volume"} & {m.name for m in get_scene("wave1d-surface-nodes").all_methods}


def test_unsupported_method_lists_the_scene_methods():
    with pytest.raises(InputError, match="not supported by this scene; allowed: none, "
                                         "taylor-fictitious, surface-nodes, mirror-nodes, "
                                         "energy, energy-directional, volume, pals"):
        get_scene("stiffness3d-box").resolve("virtual-nodes")


def test_report_runs_each_bond_method_once():
    cases = get_scene("body3d-traction").report_cases(quick=True)
    assert ("energy", {"spacing": 0.1}) in cases and ("volume", {"spacing": 0.1}) in cases
    assert len([c for c in cases if c[0] == "energy"]) == 1


# ---------------------------------------------------------------- perifit (optional)
def test_perifit_missing_is_listed_unavailable_with_the_install_command(monkeypatch):
    """Without the optional extra the method is listed, unavailable, and a run of it is
    refused as bad input naming the install command (not an error of the suite)."""
    from pdverify.corrections import perifit_weights, registry
    monkeypatch.setattr(perifit_weights, "installed_version", lambda: None)
    registry.reload()
    try:
        bm = bond_methods()["perifit"]
        assert bm.unavailable and 'pip install ".[peers]"' in bm.unavailable
        assert ("perifit", {}) not in get_scene("stiffness2d-sheet").report_cases()
        with pytest.raises(InputError, match=r"unavailable here: needs the optional extra"):
            get_scene("stiffness2d-sheet").resolve("perifit")
    finally:
        monkeypatch.undo()
        registry.reload()


def test_perifit_weights_on_the_sheet(metrics, run_once):
    """With perifit installed: its weights beat none on the bond-based sheet under
    homogeneous strain (measured: 75 -> 51 % at the largest, 33.5 -> 20.4 % RMS), and
    every run records the perifit version that produced them."""
    pytest.importorskip("perifit")
    from importlib.metadata import version
    none, pf = metrics("stiffness2d-sheet", "none"), metrics("stiffness2d-sheet", "perifit")
    for key in ("surface_energy_error_pct", "surface_energy_rms_pct"):
        assert pf[key] < none[key]
    r = run_once("stiffness2d-sheet", "perifit")
    assert r.params["perifit_version"] == version("perifit")


# ---------------------------------------------------------------- every scene it applies to
def test_bond_based_box_energy_and_volume_beat_none(metrics):
    """stiffness3d-box-bond (the box in the formulation the peers' corrections were
    written for): energy and volume lower the largest and the RMS surface error at the
    default size (measured: largest 83.2 -> 53.5 / 59.2 %, RMS 39.0 -> 20.8 / 23.1 %)."""
    none = metrics("stiffness3d-box-bond", "none")
    for method in ("energy", "volume"):
        m = metrics("stiffness3d-box-bond", method)
        for key in ("surface_energy_error_pct", "surface_energy_rms_pct"):
            assert m[key] < none[key], (method, key)


def test_perifit_beats_none_on_the_bond_based_box(metrics):
    """With perifit installed: its bb weights beat none on the bond-based box (measured:
    largest 83.2 -> 61.7 %, RMS 39.0 -> 28.3 %)."""
    pytest.importorskip("perifit")
    none, pf = metrics("stiffness3d-box-bond", "none"), metrics("stiffness3d-box-bond", "perifit")
    for key in ("surface_energy_error_pct", "surface_energy_rms_pct"):
        assert pf[key] < none[key]


def _lps_box(quadrature, closure):
    inf = get_influence("gaussian")
    st = (build_stencil(3, 3.0, quadrature="full-cells") if quadrature == "full-cells"
          else state_based_stencil(3, 3.0, 0.05, inf, quadrature))
    g = BoxGrid((1.0, 0.5, 0.5), (0.0,) * 3, 0.05, 0)
    return StateBasedModel(g, st, StateBasedConstants("3d", 200e9, 0.3), inf, closure)


def _largest_surface_error(model):
    g = model.grid
    near = g.distance_to_surface(g.x[g.interior_ids]) <= model.horizon * (1 + 1e-12)
    return max(np.abs(work_density(model, eps)[g.interior_ids][near]
                      / model.bulk_work_density(eps) - 1).max() * 100
               for _, eps in strain_states(3))


# finding 001-lps-box-peers (pdverify.deviations): the peers on the LPS box
@pytest.mark.slow  # slow tier (issue 32): a finding at the default box, 11 s and 9 s (loaded machine)
@pytest.mark.parametrize("quadrature", ["partial-volume", "full-cells"])
def test_perifit_does_not_beat_none_on_the_lps_box_in_any_reading(quadrature):
    """Finding (with perifit installed), stiffness3d-box at its default size: no reading
    of perifit's osb weights beats the uncorrected LPS box. The weights on the bond's
    weight with m over the weighted truncated family (ours), with m of a complete
    neighbourhood, or on the bond force only; with the scene's partial volumes, or with
    whole cells (the only volumes perifit's API takes). Measured, largest surface error
    (none 39.4 / 40.5 %): 55.8 / 64.3, 88.2 / 59.7, 83.9 / 193.5 %. LPS with m over the
    truncated family is exact for a surface node on a flat face in the continuum limit
    (half a ball has the ball's moment ratios), so weights fitted to restore the ball's
    operators reweight bonds that needed none."""
    pytest.importorskip("perifit")
    from pdverify.corrections.perifit_weights import node_weights
    none = _lps_box(quadrature, None)
    w = node_weights(none)

    def factors(model):
        return 0.5 * (w[model.bond_a] + w[model.bond_b])

    base = _largest_surface_error(none)
    for closure in (Closure(weight_factor=factors),
                    Closure(weight_factor=factors, weighted_volume="complete"),
                    Closure(force_factor=factors)):
        assert _largest_surface_error(_lps_box(quadrature, closure)) > base, closure


@pytest.mark.parametrize("scene,key,best", [
    ("bar1d-homogenization", "max_error_pct", True),
    ("bar1d-constraints", "max_error_pct", True),
    ("bar1d-vibration", "max_error_pct", False)])
def test_energy_and_volume_on_the_seed_004_bars(scene, key, best, metrics):
    """The bond-based bars of seed 004 take energy and volume beside homogenized. Both
    lower none's error (measured, max_error_pct: tension 21.8 -> 12.2 / 10.5, constraints
    10.9 -> 6.1 / 5.2, vibration 29.4 -> 6.5 / 8.7); the end-bond homogenisation stays
    exact in statics (0 to round-off) but not in the vibration, whose full-weight free end
    carries a tip mass none of the stiffness corrections removes (13.9 %)."""
    scene_obj = get_scene(scene)
    assert {"energy", "volume"} <= {m.name for m in scene_obj.all_methods}
    none = metrics(scene, "none")[key]
    homog = metrics(scene, "homogenized")[key]
    for method in ("energy", "volume"):
        m = metrics(scene, method)[key]
        assert m < none, method
        assert (homog < m) == best, method


def test_bond_bar_takes_one_boundary_treatment():
    from pdverify.corrections.homogenized import bond_bar
    with pytest.raises(ValueError, match="two boundary treatments"):
        bond_bar(nodes=9, spacing=1.0, horizon_ratio=4.0, E=1.0, end_factors=(2.0, 1.5, 1.0),
                 closure=Closure())


def test_bond_methods_on_the_clamped_plate(metrics):
    """plate2d-clamped (seed 000's plate, LPS) takes energy, volume and PALS, clamped as
    none is (the ring at the FEM value). Measured at Table 4's grid, max_error_u_pct:
    none 7.43, energy 6.52, volume 6.40, PALS 10.29, taylor-fictitious (n = 1) 1.47.
    Finding: PALS makes every node's energy exact under homogeneous strain, yet the
    clamped ring it shares with none leaves it worse here."""
    none = metrics("plate2d-clamped", "none")["max_error_u_pct"]
    got = {m: metrics("plate2d-clamped", m)["max_error_u_pct"]
           for m in ("energy", "volume", "pals")}
    assert got["energy"] < none and got["volume"] < none
    assert got["pals"] > none
    assert max(got.values()) > metrics("plate2d-clamped", "taylor-fictitious")["max_error_u_pct"]


@pytest.mark.slow  # slow tier (issue 32): 13 s: three indentation curves (loaded machine)
def test_energy_and_volume_on_the_indentation(metrics):
    """block2d-indentation takes energy and volume (and perifit when installed) at the
    quick report's coarse grid (spacing 1 mm, m = 6): both reach 2 mm where none folds at
    1.8 mm, yet stay far softer than the FEM (measured force_error_pct: none 66.8, energy
    50.3, volume 53.7, energy-directional 4.8 %): corrections calibrated on a small
    uniaxial stretch do not restore the stiffness under the indenter that seed 003's
    directional factor does. (At the paper's grid, in the full report, all three fail by
    a Newton stall at 1.0-1.1 mm, later than none's 0.7 mm: a finding in the scene's
    docstring.)"""
    scene = get_scene("block2d-indentation")
    coarse = scene.quick_overrides
    assert {"energy", "volume"} <= {m.name for m in scene.all_methods}
    r = scene.run("none", coarse)
    assert r.status == "failed" and r.metrics["depth_reached_mm"] < 2
    directional = metrics("block2d-indentation", "energy-directional", **coarse)
    for method in ("energy", "volume"):
        m = metrics("block2d-indentation", method, **coarse)
        assert m["depth_reached_mm"] == pytest.approx(2.0)
        assert directional["force_error_pct"] < m["force_error_pct"] < r.metrics["force_error_pct"]
