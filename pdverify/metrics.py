"""Error measures shared by the scenes (each names the paper equation it follows)."""
from __future__ import annotations

import numpy as np


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


def rel_l2_error(u, u_ref) -> float:
    """||u - u_ref||_2 / ||u_ref||_2 over the given (real) nodes (DESIGN.md)."""
    u = np.asarray(u, dtype=float).ravel()
    u_ref = np.asarray(u_ref, dtype=float).ravel()
    return float(np.linalg.norm(u - u_ref) / np.linalg.norm(u_ref))
