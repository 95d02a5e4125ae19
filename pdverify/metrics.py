"""Error measures shared by the scenes (each names the paper equation it follows), and the
regions they are split into."""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from .errors import NumericalError


def max_relative_error_pct(u, u_ref) -> float:
    """Largest nodal relative error in percent, seed 000 Eq. (64).

    eps_i = |u_i - u_ref(x_i)| / |u_ref(x_i)| * 100. Nodes where the reference is
    exactly zero are skipped (the ratio is undefined there).
    """
    u = np.asarray(u, dtype=float)
    u_ref = np.asarray(u_ref, dtype=float)
    mask = u_ref != 0
    return float(np.max(np.abs(u[mask] - u_ref[mask]) / np.abs(u_ref[mask])) * 100.0)


def nodal_relative_error_pct(u, u_ref) -> np.ndarray:
    """Per-node relative error of Eq. (64) (NaN where the reference is zero)."""
    u = np.asarray(u, dtype=float)
    u_ref = np.asarray(u_ref, dtype=float)
    out = np.full(u.shape, np.nan)
    mask = u_ref != 0
    out[mask] = np.abs(u[mask] - u_ref[mask]) / np.abs(u_ref[mask]) * 100.0
    return out


def max_error_of_peak_pct(u, u_ref, peak: float | None = None) -> float:
    """max |u - u_ref| in percent of ``peak`` (default: max |u_ref|), e.g. seed 000 Eq. (70)."""
    u = np.asarray(u, dtype=float)
    u_ref = np.asarray(u_ref, dtype=float)
    scale = float(np.max(np.abs(u_ref))) if peak is None else float(peak)
    return float(np.max(np.abs(u - u_ref)) / scale * 100.0)


def scaled_norm(v) -> float:
    """||v||_2 computed as m ||v / m|| with m = max |v|: no square under- or overflows, so
    values of 1e+-300 give the same relative measures as values of 1."""
    v = np.asarray(v, dtype=float).ravel()
    m = float(np.max(np.abs(v))) if v.size else 0.0
    return 0.0 if m == 0.0 or not np.isfinite(m) else m * float(np.linalg.norm(v / m))


def rel_l2_error(u, u_ref) -> float:
    """||u - u_ref||_2 / ||u_ref||_2 over the given (real) nodes (DESIGN.md), scale-free
    (:func:`scaled_norm`); NaN when the reference is zero."""
    u = np.asarray(u, dtype=float).ravel()
    u_ref = np.asarray(u_ref, dtype=float).ravel()
    ref = scaled_norm(u_ref)
    return float(scaled_norm(u - u_ref) / ref) if ref > 0 else float("nan")


def _harmonic_residual(t, y, frequency, harmonics) -> float:
    """Least-squares residual of y against 1, cos(h w t), sin(h w t) for h in ``harmonics``."""
    w = 2.0 * np.pi * frequency
    cols = [np.ones_like(t)]
    for h in harmonics:
        cols += [np.cos(h * w * t), np.sin(h * w * t)]
    A = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    return float(np.sum((A @ coef - y) ** 2))


def fitted_frequency(t, signal, guess: float, *, harmonics=(1, 3, 5, 7), rel_span: float = 0.3,
                     max_samples: int = 4000) -> float:
    """Fundamental frequency [Hz] of ``signal`` by a least-squares harmonic fit.

    The model is a constant plus cos/sin pairs at the multiples ``harmonics`` of one
    fundamental f; the linear coefficients are eliminated (variable projection) and
    the residual is minimised over f in two stages: the fundamental alone on a grid over
    ``guess`` (1 +- rel_span) (spacing 1/40 of a Fourier bin at five periods), then all
    harmonics near that minimum (within a seventh of half a bin, the width of the basin
    of the highest harmonic). Higher harmonics in the model keep the fit from being
    biased by the signal's own (a triangle wave's third harmonic moves a one-term fit
    by 0.04 % over five periods; with 1, 3, 5, 7 the bias is 0.004 %). At most
    ``max_samples`` evenly strided samples are used.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(signal, dtype=float)
    stride = max(1, int(np.ceil(t.size / max_samples)))
    t, y = t[::stride], y[::stride]
    grid = guess * np.linspace(1.0 - rel_span, 1.0 + rel_span, int(rel_span * 400) + 1)
    first = np.array([_harmonic_residual(t, y, f, (1,)) for f in grid])
    k = int(np.argmin(first))
    h = grid[1] - grid[0]
    coarse = minimize_scalar(lambda f: _harmonic_residual(t, y, f, (1,)),
                             bounds=(grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]),
                             method="bounded", options={"xatol": 1e-9 * guess}).x
    half_bin = 0.5 / (t[-1] - t[0])
    reach = min(h, half_bin / max(harmonics))
    return float(minimize_scalar(lambda f: _harmonic_residual(t, y, f, harmonics),
                                 bounds=(coarse - reach, coarse + reach), method="bounded",
                                 options={"xatol": 1e-10 * guess}).x)


def error_metrics(x, u, u_ref, dist, horizon, dim) -> tuple[dict, np.ndarray]:
    """Eq. (38) (3D) / Eq. (44) (2D) errors in percent, overall and split at delta.

    u_max per component is the largest |u_ref| over the interior nodes. ``boundary_``
    metrics are over nodes within one horizon of the surface, ``interior_`` over the rest.
    """
    scale = np.max(np.abs(u_ref), axis=0)
    tiny = np.flatnonzero(~(scale > np.finfo(float).tiny))
    if tiny.size:
        raise NumericalError(f"Eq. ({38 if dim == 3 else 44}) divides each component's "
                             f"error by its largest reference value, and component "
                             f"{'xyz'[tiny[0]]} of the reference is {scale[tiny[0]]:.3g} "
                             "everywhere (e.g. nu = 0 gives no lateral displacement): the "
                             "error is undefined")
    comp = np.abs(u - u_ref) / scale * 100.0        # (n, d) per-component percent
    mag = np.sqrt(np.sum(comp ** 2, axis=1))         # Eq. (38)
    near = dist <= horizon
    regions = {"": np.ones(x.shape[0], dtype=bool), "boundary_": near, "interior_": ~near}
    if dim == 3:
        return region_errors(mag, regions, {"max_error_pct": None}, u, u_ref), mag
    columns = {"max_error_pct": None, "max_error_u_pct": 0, "max_error_v_pct": 1}
    return region_errors(comp, regions, columns, u, u_ref), comp


def region_errors(err, regions, columns, u=None, u_ref=None) -> dict:
    """The one error-by-region function: the largest of the per-node errors ``err``
    ((n,) or (n, d), in %) over each region, ``regions`` = {metric prefix: node mask} (a
    region without nodes is left out), one metric per ``columns`` entry {name: column of
    ``err``, None: every column}; with ``u`` and ``u_ref`` each region's
    ``rel_l2_error`` after its maxima."""
    out = {}
    for prefix, mask in regions.items():
        if not np.any(mask):
            continue
        for name, col in columns.items():
            out[prefix + name] = float((err[mask] if col is None else err[mask, col]).max())
        if u is not None:
            out[prefix + "rel_l2_error"] = rel_l2_error(u[mask], u_ref[mask])
    return out


def plate_regions(x, lengths, horizon) -> dict:
    """Masks of the nodes ``x`` of a rectangle [0, l_x] x [0, l_y]: ``boundary_`` within
    one horizon of an edge, ``corner_`` within one horizon of two edges, ``interior_``
    the rest."""
    dx = np.minimum(x[:, 0], lengths[0] - x[:, 0])
    dy = np.minimum(x[:, 1], lengths[1] - x[:, 1])
    near = np.minimum(dx, dy) < horizon
    return {"boundary_": near, "corner_": np.maximum(dx, dy) < horizon, "interior_": ~near}


def plate_errors(x, u, u_ref, lengths, horizon) -> tuple[dict, np.ndarray]:
    """Eq. (70) of seed 000 in percent, overall and split by region.

    Both components are normalised by max |u^FEM| over the PD nodes, u the x-displacement
    (the paper's bold u; at the Table 4 load max |v| is 6 % of it). Regions: ``boundary``
    = nodes within one horizon of an edge, ``corner`` = within one horizon of two edges,
    ``interior`` = the rest.
    """
    scale = np.max(np.abs(u_ref[:, 0]))
    err = np.abs(u - u_ref) / scale * 100.0
    regions = {"": np.ones(x.shape[0], dtype=bool), **plate_regions(x, lengths, horizon)}
    out = region_errors(err, regions, {"max_error_u_pct": 0, "max_error_v_pct": 1})
    out["rel_l2_error"] = rel_l2_error(u, u_ref)
    return out, err


def surface_error_pct(u_extra, u_ref_extra, scale) -> float:
    """Largest component error of the extra (surface) nodes, in % of ``scale``."""
    return float(np.max(np.abs(u_extra - u_ref_extra) / scale) * 100.0)
