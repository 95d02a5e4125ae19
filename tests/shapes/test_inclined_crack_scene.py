"""The ``plate-inclined-crack`` scene (issue 54, mixed mode): a crack of zero length is the
uncracked plate, the K fit reads the FEM field at the PD nodes to its stated accuracy, the
treatments that cannot serve crack faces say why, bad input is one line."""
import json
import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from pdverify.scenes import get_scene

ID = "plate-inclined-crack"


def _run(tmp_path, *sets, method="none"):
    out = tmp_path / "run.json"
    r = subprocess.run([sys.executable, "-m", "pdverify", "run", ID, "--method", method,
                        *[a for s in sets for a in ("--set", s)], "--json", str(out)],
                       capture_output=True, text=True)
    return r, (json.loads(out.read_text())["runs"][0] if r.returncode == 0 else None)


def test_a_crack_of_zero_length_is_the_uncracked_plate():
    """The stiffness with a = 0 equals, bit for bit, that of the outline without cracks;
    with the inclined crack it does not (the check can fail)."""
    from pdverify.corrections.plain import assemble_plain
    from pdverify.scenes.cracks import plate_outline
    from pdverify.scenes.inclined_crack import inclined_plate
    scene = get_scene(ID)
    p = {**scene.default_params(), "spacing": 0.25}

    def stiffness(shape):
        problem = replace(scene.problem(p, "test"), shape=shape)
        return assemble_plain(problem, None).K.tocsr()

    k0 = stiffness(inclined_plate(1.0, 1.0, 0.0, 30.0, 0.25))
    kp = stiffness(plate_outline(1.0, 1.0, 0.25))
    assert k0.shape == kp.shape and (k0 != kp).nnz == 0
    kc = stiffness(inclined_plate(1.0, 1.0, 0.5, 30.0, 0.25))
    assert (kc != kp).nnz > 0


def test_no_kept_bond_crosses_the_inclined_slit():
    """The lattice is not aligned with the crack: the bonds of the default grid that
    cross the open slit (ends on different sides, crossing strictly between the tips)
    are exactly the ones the shape cuts, and there are some at every node row along it."""
    from scipy.spatial import cKDTree

    from pdverify.scenes.inclined_crack import inclined_plate
    h, a, b = 0.025, 0.5, math.radians(30.0)
    shape = inclined_plate(1.0, 1.0, a, 30.0, h)
    c = -1 + (np.arange(80) + 0.5) * h
    X, Y = np.meshgrid(c, c, indexing="ij")
    x = np.stack([X.ravel(), Y.ravel()], 1)
    i, j = cKDTree(x).query_pairs(3 * h, output_type="ndarray").T
    e = np.array([math.cos(b), math.sin(b)])
    nrm = np.array([-e[1], e[0]])
    si, sj = x[i] @ nrm, x[j] @ nrm
    apart = np.sign(si) != np.sign(sj)
    t = si / np.where(apart, si - sj, 1.0)
    along = (x[i] + t[:, None] * (x[j] - x[i])) @ e
    crossing = apart & (np.abs(along) < a)
    cut = shape.severs(x[i], x[j])
    assert np.array_equal(cut, crossing)
    assert np.all(np.abs(si) > 1e-9 * h) and np.all(np.abs(sj) > 1e-9 * h)  # none on it


def test_the_fit_reads_the_fem_field_to_its_stated_accuracy(tmp_path):
    """At the quick grid (h = 1/30) the K fit applied to the FEM field at the PD nodes
    reads the FEM's interaction-integral K_I and K_II within 0.05 % (the fit's measured
    bias 0.005 % and 0.031 %, pdverify.pd.cracks), and the uncorrected run's metrics are
    finite and consistent (k_error_pct is the vector's)."""
    r, run = _run(tmp_path, "spacing=0.03333333333333333")
    assert r.returncode == 0, r.stderr
    m = run["metrics"]
    assert abs(m["k1_fit_bias_pct"]) < 0.05 and abs(m["k2_fit_bias_pct"]) < 0.05
    assert m["tip_zone_nodes"] > 0
    _, fem = _run(tmp_path, method="fem")
    ref = fem["metrics"]
    d1 = (m["k1_ratio"] - 1) * ref["k1"]
    d2 = (m["k2_ratio"] - 1) * ref["k2"]
    assert m["k_error_pct"] == pytest.approx(100 * math.hypot(d1, d2)
                                             / math.hypot(ref["k1"], ref["k2"]), rel=1e-9)


def test_the_list_shows_why_the_node_adding_treatments_do_not_run():
    out = subprocess.run([sys.executable, "-m", "pdverify", "list", ID],
                         capture_output=True, text=True, check=True).stdout
    assert "pddo: crack faces are not served yet" in out
    assert set(get_scene(ID).offered()) == {"none", "energy", "volume", "pals",
                                            "energy-directional", "taylor-fictitious",
                                            "surface-nodes", "peer:lammps"}


def test_the_cases_are_every_method_at_the_defaults_and_the_quick_grid():
    scene = get_scene(ID)
    assert {m for m, _ in scene.cases()} == {"fem", "none", "energy", "volume", "pals",
                                             "energy-directional", "taylor-fictitious",
                                             "surface-nodes"}
    quick = scene.cases(quick=True)
    assert {q.get("spacing") for m, q in quick if m != "fem"} == {1 / 30}


@pytest.mark.parametrize("assignment, words", [
    ("angle=0", "K_II vanishes at 0"),
    ("spacing=0.3", "must divide"),
    ("m_ratio=8", "thinner than two spacings"),
    ("angle=50", "W tan(angle)"),
])
def test_bad_input_is_one_line_before_any_work(tmp_path, assignment, words):
    r, _ = _run(tmp_path, assignment)
    assert r.returncode == 2, r.stderr
    assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_the_pd_solution_is_point_symmetric():
    """The lattice, the two cracks from the centre and the pins (at the FEM's values,
    point symmetric to 1e-7 of its largest displacement: tests/reference_fem/
    test_inclined_crack.py) are point symmetric, so the PD field is, u(-x) = -u(x), and
    the fit reads the same K_I, K_II at both tips; bound 1e-7 (the pins' values; measured
    2e-10 for the field, 2e-13 for K)."""
    from scipy.spatial import cKDTree

    from pdverify.pd.cracks import fit_k_mixed
    res = get_scene(ID).run("none", {"spacing": 1 / 30})
    x, u = np.asarray(res.fields["x"]), np.asarray(res.fields["u"])
    d, i = cKDTree(x).query(-x)
    assert d.max() < 1e-12
    assert np.abs(u + u[i]).max() < 1e-7 * np.abs(u).max()
    e = np.array([math.cos(math.pi / 6), math.sin(math.pi / 6)])
    kw = dict(E=1e9, nu=0.3, plane="plane-stress", horizon=0.1, reach=0.4)
    right = fit_k_mixed(x, u, 0.5 * e, e, **kw)
    left = fit_k_mixed(x, u, -0.5 * e, -e, **kw)
    assert abs(left.k1 / right.k1 - 1) < 1e-7 and abs(left.k2 / right.k2 - 1) < 1e-7
