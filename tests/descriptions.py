"""Descriptions the tests share: a state-based box as a
:class:`~pdverify.pd.problem.StaticProblem` with no conditions of its own, which a test
hands to the package's assemblies (``pdverify.corrections.plain``,
``surface_nodes``, ``taylor_fictitious``) and then imposes what it checks."""
from __future__ import annotations

import numpy as np

from pdverify.pd import get_influence, state_based_stencil
from pdverify.pd.problem import StaticProblem


def box_problem(lengths, origin, spacing, m_ratio, constants, *, quadrature="partial-volume",
                influence="gaussian", conditions=None, exact=np.zeros_like, solver="auto",
                thickness=1.0, complete_m="stencil") -> StaticProblem:
    """A box of cell-centred nodes; ``conditions`` by face name (none: a free box),
    ``exact(x)`` the prescribed values (zero)."""
    inf = get_influence(influence)
    return StaticProblem(tuple(lengths), tuple(origin), float(spacing),
                         state_based_stencil(len(lengths), m_ratio, spacing, inf, quadrature),
                         constants, inf, dict(conditions or {}), exact=exact,
                         thickness=thickness, solver=solver, complete_m=complete_m)


def bar_system(method: str = "none", **overrides):
    """Seed 000's traction bar (``bar1d-traction``, Table 3's values unless
    ``overrides``) as its scene describes it, assembled by the treatment ``method``."""
    from pdverify.scenes import get_scene
    scene = get_scene("bar1d-traction")
    p = scene.resolve(method, overrides)
    return scene.treatment(method).assemble(scene.problem(p, f"test {method}"), p)
