"""Fig. 4 of seed 003 draws the finite-strain FEM of each material law beside the PD
runs' reference, and its caption states each law's force at full depth over the
small-strain FEM's, from the curves drawn (issue 33: the labels say which reference a
curve is)."""
from types import SimpleNamespace

import numpy as np

from pdverify.report.figures.indentation import _law_note, _other_laws, fem_label


def _fem(law, forces, kinematics="finite", status="ok"):
    return SimpleNamespace(status=status, params={"kinematics": kinematics, "law": law},
                           fields={"depths": np.array([0.0, 1e-3, 2e-3]),
                                   "forces": np.asarray(forces, dtype=float)})


def test_other_laws_are_the_finite_strain_runs_of_another_law():
    runs = [_fem("saint-venant-kirchhoff", [0, 400, 894]),
            _fem("neo-hookean", [0, 450, 1012]),
            _fem("neo-hookean", [0, 1, 2], status="failed"),
            _fem("saint-venant-kirchhoff", [0, 450, 1000], kinematics="small")]
    others = _other_laws(runs)
    assert [name for name, _, _ in others] == ["FEM, finite strain, neo-Hookean"]
    assert others[0][2][-1] == 1012


def test_the_caption_states_each_law_against_small_strain():
    fem = {"forces": np.array([0, 400, 894.0]), "small": np.array([0, 450, 1000.0]),
           "others": [(fem_label("finite", "neo-hookean"), None, np.array([0, 450, 1012.0]))]}
    note = _law_note(fem)
    assert "St Venant-Kirchhoff 0.894" in note and "neo-Hookean: 1.012" in note
    assert _law_note({**fem, "others": []}) == ""
