"""The sweep of seed 003 §4.2's unstated solver choices (issue 33): the uncorrected run's
failure depth under each, as report cases and a table beside Fig. 4."""
from types import SimpleNamespace

import numpy as np
import pytest

from pdverify.report.figures.indentation import _failure_kind, _sweep_table
from pdverify.scenes import get_scene
from pdverify.scenes.indentation import UNSTATED_CHOICES


def test_the_full_report_runs_each_unstated_choice_on_the_uncorrected_run():
    scene = get_scene("block2d-indentation")
    cases = scene.cases()
    for choice in UNSTATED_CHOICES:
        assert ("none", choice) in cases
        scene.resolve("none", choice)          # each a valid run
    assert not any(c in scene.cases(quick=True) for c in [("none", v) for v in UNSTATED_CHOICES])


def _run(depth, message, **params):
    base = get_scene("block2d-indentation").resolve("none", {})
    return SimpleNamespace(method="none", params={**base, **params}, message=message,
                           metrics={"failure_depth_mm": depth}, status="failed")


def test_the_table_lists_each_choice_with_its_depth(tmp_path):
    scene = get_scene("block2d-indentation")
    runs = [_run(0.7, "Newton stalled, the line search found no step"),
            _run(0.5, "the tangent has lost definiteness: ...", predictor="none"),
            _run(1.3, "Newton stalled, the line search found no step", node_volumes="full")]
    name, caption = _sweep_table(scene, runs, str(tmp_path))
    assert (tmp_path / name).exists()
    assert "Closest: predictor=none at 0.5 mm" in caption
    assert _sweep_table(scene, runs[:1], str(tmp_path)) is None   # nothing to compare


@pytest.mark.parametrize("message, kind", [
    ("depth 0.5 mm: the tangent has lost definiteness: u_x", "tangent indefinite"),
    ("depth 0.7 mm: Newton stalled, the line search found no step", "line search stalls"),
    ("depth 1 mm: the lattice folds: node", "lattice folds")])
def test_failure_kinds(message, kind):
    assert _failure_kind(message) == kind


def test_line_search_off_takes_every_full_step():
    """newton(line_search=False) never cuts a step (the option the sweep varies)."""
    from pdverify.solvers import newton as nw

    class Quadratic:           # f(u) = u^3 - 1 per unknown: Newton overshoots from 0.1
        def internal_force(self, u):
            return u ** 3 - 1.0

        def tangent_data(self, u):
            return 3.0 * u ** 2

    class Solver:
        fixed = np.zeros(1, dtype=bool)

        def solve(self, data, rhs, eta, where):
            return rhs / data

    u = np.array([0.1])
    rep = nw.newton(Quadratic(), u, Solver(), where="test", line_search=False, maxiter=60)
    assert rep.line_search_cuts == 0 and abs(u[0] - 1.0) < 1e-6
    u = np.array([0.1])
    rep = nw.newton(Quadratic(), u, Solver(), where="test", maxiter=60)
    assert rep.line_search_cuts > 0 and abs(u[0] - 1.0) < 1e-6


def test_the_papers_numbers_sit_beside_our_solver_choices_only():
    """The sweep changes one of the solver's choices: its runs are not the paper's reading
    (a full report's --against-published once failed on node_volumes=full's force bias)."""
    scene = get_scene("block2d-indentation")
    assert scene.published_for("none", scene.resolve("none", {}))
    for choice in UNSTATED_CHOICES:
        assert not scene.published_for("none", scene.resolve("none", choice)), choice
