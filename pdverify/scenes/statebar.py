"""The seed-000 bar that two scene modules share (:mod:`pdverify.scenes.bar1d`: the
static family's loaded bars; :mod:`pdverify.scenes.bar1d_flux`: the force flux under a
constant strain): its parameters (Table 3), its state-based model on the engine, the
grid checks and the memory estimate. Not a scene."""
from __future__ import annotations

from .. import budget
from ..errors import InputError
from ..params import Param, grid_params, material_params, positive
from ..pd import StateBasedConstants, build_stencil, get_influence
from ..pd.build import Body, StateMaterial, build_model
from .base import cell_count, influence_param

#: Table 3 of seed 000.
BAR_PARAMS = (
    Param("length", 1.0, "bar length l [m]", positive),
    Param("area", 0.01, "cross-section A [m^2]", positive),
    *material_params(1e9, 0.3),
    *grid_params(0.05, 3.0),
    influence_param("hyperbolic", "seed 000, Eq. 23: delta / |xi|"),
    Param("quadrature", "partial-volume", "volume fractions beta: partial-volume (seed 000: "
          "the fraction of each cell inside the horizon, 1/2 for the node at |xi| = delta "
          "at whole m) or full-cells (beta = 1 for every node within delta)",
          choices=("partial-volume", "full-cells")),
    Param("complete_m", "stencil", "m of a complete neighbourhood, used by the corrected "
          "methods: stencil (the sum of Eq. 25 over the stencil's volumes) or continuum (its "
          "integral, A delta^3 for omega = delta/|xi|; seed 000 states both)",
          choices=("stencil", "continuum")),
)


def bar_model(p: dict, closure=None, fictitious: bool = False):
    """A seed-000 bar on the engine: real nodes at the cell centres x_i = (i - 1/2) Delta
    (Fig. 10), the 1D state-based model with ``influence`` (seed 000: hyperbolic) and the
    weights of ``quadrature``, cross-section ``area``; unset keys of ``p`` take the paper's
    values (Table 3). ``closure``: ``None`` (truncated neighbourhoods, m_i from Eq. (50)
    over real neighbours), a treatment's closure, or its closure of the grid
    (``pdverify.pd.build``), extended by one horizon of fictitious layers at both ends
    when ``fictitious``."""
    p = {**{q.name: q.default for q in BAR_PARAMS}, **p}
    stencil = build_stencil(1, p["m_ratio"], quadrature=p["quadrature"])
    return build_model(Body((p["length"],), (0.0,), p["spacing"], thickness=p["area"]),
                       stencil,
                       StateMaterial(StateBasedConstants("1d", p["E"], p["nu"]),
                                     get_influence(p["influence"]), p["complete_m"]),
                       closure, layers=stencil.reach if fictitious else 0)


def check_bar_grid(scene_id: str, method: str, p: dict, min_horizons: float = 0.0) -> int:
    """Common checks: the spacing divides the length into whole cells, and the bar is at
    least ``min_horizons`` horizons long; returns the number of cells."""
    where = f"{scene_id} --method {method}"
    n = cell_count(where, p["spacing"], "length", p["length"])
    if abs(n - round(n)) > 1e-9 * max(n, 1.0) or round(n) < 2:
        raise InputError(f"{where}: spacing={p['spacing']} must divide length={p['length']} "
                         f"into a whole number (>= 2) of cells")
    n = int(round(n))
    if min_horizons and p["length"] < min_horizons * p["m_ratio"] * p["spacing"]:
        raise InputError(f"{where}: length={p['length']} must be at least {min_horizons:g} "
                         f"horizons (m_ratio * spacing = {p['m_ratio'] * p['spacing']:g})")
    return n


def bar_estimate(p) -> budget.Estimate:
    """State-based bar: n + 1 nodes and m fictitious ones at each end; the dilatation
    couples nodes two horizons (2m spacings) apart."""
    m = p["m_ratio"]
    return budget.linear_system(p["length"] / p["spacing"] + 1 + 2 * m, 1, 1, 2 * m)
