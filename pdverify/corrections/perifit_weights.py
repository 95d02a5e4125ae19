"""Operator-matching weights of the ``perifit`` package (PyPI; Shojaei and Hermann,
Helmholtz-Zentrum Hereon), applied as bond weights: an optional peer method.

perifit computes one scalar weight w_i per node such that the truncated neighbourhood's
operators match their full-sphere counterparts (a local least-squares problem per node,
coupled through a global sparse system); a bond a-b then carries (w_a + w_b) / 2 in
place of the unit influence (its README). It supports 3D bond-based (``bb``) and LPS
(``osb``) models and 2D bond-based ones (``compute_weights_2d``).

Our choices: perifit is given our model's families (the bonds the engine keeps, partial
cells included) and node volumes, so the weights belong to the same bonds; the bond
factor multiplies the bond's weight wherever it enters (``Closure.weight_factor``: m and
the dilatation too, as its README says to replace omega everywhere). perifit's own
kernels (q = 3 bond-based, q = 2 LPS) are what it calibrates against; the scenes' influence
functions are not passed (its API has no such input). The version that produced the
weights is a parameter of every run (``perifit_version``), so it is in results.json.

The weights are cached (issue 32): they depend only on perifit's code and on what it is
given (node positions and volumes, horizon, families, model kind), and perifit's own
assembly loops over nodes (``compute_weights_2d``: about a tenth of a full report's run
time, record report_cost-2026-11-27-perifit-weights). An entry of the
cache folder's ``perifit`` folder (:func:`pdverify.outputs.cache_root`) is keyed by a
SHA-256 of all of these, perifit's version and the digest of its source; a run that
reads it records the CPU seconds the weights took when computed (perifit runs on one
thread: its time on an idle core; a cached wall time would carry the load of the machine
that computed it into every later report) as :data:`pdverify.results.CACHED_SETUP`, part
of its cost, and says so in its diagnostics (``perifit_weights``). An entry that does not
read back whole is a miss.
"""
from __future__ import annotations

import hashlib
import time
from functools import lru_cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np

from .. import blas
from ..outputs import cache_root
from ..pd.closure import Closure
from ..pd.statebased import StateBasedModel
from ..results import CACHED_SETUP, atomic_write, note

INSTALL = 'pip install ".[peers]" (perifit from PyPI)'
#: scenes whose model perifit supports: 3D LPS and bond-based, 2D bond-based
SCENES = ("stiffness3d-box", "stiffness3d-box-bond", "body3d-traction", "body3d-manufactured",
          "stiffness2d-sheet", "sheet2d-tension", "sheet2d-clamped", "block2d-indentation")


def installed_version() -> str | None:
    try:
        return version("perifit")
    except PackageNotFoundError:
        return None


def families(model) -> list[list[int]]:
    """Each grid node's neighbours over the model's bonds."""
    a, b, n = model.bond_a, model.bond_b, model.grid.n_ext
    node = np.r_[a, b]
    other = np.r_[b, a]
    order = np.argsort(node, kind="stable")
    counts = np.bincount(node, minlength=n)
    return [list(map(int, f)) for f in np.split(other[order], np.cumsum(counts)[:-1])]


def _kind(model) -> str:
    g = model.grid
    state = isinstance(model, StateBasedModel)
    if g.dim == 3:
        return "osb" if state else "bb"
    if g.dim == 2 and not state:
        return "bb-2d"
    raise ValueError("perifit: 3D bond-based and LPS models and 2D bond-based ones only")


def _compute(model, kind: str) -> np.ndarray:
    """perifit's weights, with one BLAS thread as in a run (pdverify.blas), so that a
    cached entry holds what any run would compute, wherever it was computed."""
    import perifit
    g = model.grid
    fam = families(model)
    with blas.one_thread():
        if kind == "bb-2d":
            return perifit.compute_weights_2d(g.x, model.node_volume, model.horizon,
                                              families=fam)
        return perifit.compute_weights(g.x, model.node_volume, model.horizon, model=kind,
                                       families=fam)


@lru_cache(maxsize=1)
def _perifit_digest() -> str:
    """perifit's version and a digest of its Python source, so that an edited install
    misses the cache even when its version was not bumped."""
    import perifit
    root = Path(perifit.__file__).parent
    h = hashlib.sha256(str(installed_version()).encode())
    for p in sorted(root.rglob("*.py")):
        h.update(p.relative_to(root).as_posix().encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def cache_key(model, kind: str) -> str:
    """SHA-256 over everything perifit's weights depend on: the model kind, node positions
    and volumes, the horizon, the bonds (the families are their ends), perifit's version
    and source."""
    h = hashlib.sha256(f"perifit-weights/2 {kind} {model.horizon!r} "
                       f"{model.grid.n_ext} {_perifit_digest()}".encode())
    for a in (model.grid.x, model.node_volume, model.bond_a, model.bond_b):
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _entry(key: str) -> Path:
    return Path(cache_root()) / "perifit" / f"{key[:32]}.npz"


def _load(key: str, n: int):
    """``(weights, seconds)`` of the cache entry of ``key``, or None (a miss): missing, or
    not read back whole with this key and ``n`` finite weights."""
    try:
        with np.load(_entry(key)) as z:
            w, seconds = np.array(z["weights"], dtype=float), float(z["seconds"])
            if str(z["key"]) == key and w.shape == (n,) and np.all(np.isfinite(w)):
                return w, seconds
    except Exception:  # noqa: BLE001 - any unreadable entry is a miss: computed again
        pass
    return None


def _store(key: str, w: np.ndarray, seconds: float) -> None:
    """The entry of ``key``, written whole or not at all (parallel runs read it)."""
    try:
        atomic_write(_entry(key), lambda fh: np.savez(fh, weights=w, seconds=seconds, key=key))
    except OSError:
        pass   # a read-only or full cache only costs time


def node_weights(model) -> np.ndarray:
    """perifit's w_i at every grid node of a plain grid's model, read from the cache when
    an entry of the same inputs is there (module docstring); the run in progress is told
    which (:func:`pdverify.results.note`)."""
    kind = _kind(model)
    key = cache_key(model, kind)
    hit = _load(key, model.grid.n_ext)
    if hit is not None:
        w, seconds = hit
        # the diagnostics hold no time (a machine's cost, not the run's numbers, which
        # are the same bit for bit on any machine): the time is in the timings
        note(diagnostics={"perifit_weights": "read from the cache (their computing time "
                                             "in timings.cached_setup_s)"},
             timings={CACHED_SETUP: seconds})
        return w
    # the CPU time is what is kept: perifit runs on one thread (its time on an idle core),
    # and a cached time outlives the load of the machine that computed it
    t0 = time.process_time()
    w = np.asarray(_compute(model, kind), dtype=float)
    seconds = time.process_time() - t0
    _store(key, w, seconds)
    note(diagnostics={"perifit_weights": "computed"})
    return w


def perifit_factors(model) -> np.ndarray:
    w = node_weights(model)
    return 0.5 * (w[model.bond_a] + w[model.bond_b])


def perifit_closure(params=None) -> Closure:
    return Closure(weight_factor=perifit_factors)
