"""1D node distributions for tensor-product meshes: uniform, power-graded, geometric."""
from __future__ import annotations

import numpy as np


def uniform(a: float, b: float, n: int) -> np.ndarray:
    """n equal elements on [a, b]."""
    return np.linspace(a, b, int(n) + 1)


def power_graded(a: float, b: float, n: int, power: float, ends: str = "both") -> np.ndarray:
    """n elements on [a, b], refined toward ``ends`` ("a", "b" or "both") by the map
    t -> t^power of a uniform parameter (t = distance to the end / half or full length).

    Power grading with power > k / lambda recovers the optimal rate O(n^-k) of degree-k
    elements for a corner singularity u ~ r^lambda (Babuska-Guo, Schwab: p- and hp-FEM
    1998, ch. 4); the elements at the end shrink like n^-power.
    """
    n = int(n)
    if ends == "both":
        if n % 2:
            raise ValueError(f"power_graded(ends='both') needs an even n, got {n}")
        half = (np.arange(n // 2 + 1) / (n // 2)) ** power
        mid = 0.5 * (a + b)
        left = a + (mid - a) * half
        return np.concatenate([left, (a + b - left[::-1])[1:]])
    t = (np.arange(n + 1) / n) ** power
    x = a + (b - a) * t
    if ends == "a":
        return x
    if ends == "b":
        return (a + b - x)[::-1]
    raise ValueError(f"ends must be 'a', 'b' or 'both', got {ends!r}")


def geometric_from(a: float, b: float, h0: float, ratio: float) -> np.ndarray:
    """Nodes from a to b (either order) starting with spacing h0 at a and growing by
    ``ratio`` per element; the last element is merged so no element is thinner than
    its predecessor. Returned in increasing order."""
    length = abs(b - a)
    sign = 1.0 if b > a else -1.0
    steps = [0.0]
    h = h0
    while steps[-1] + h < length - 1e-12 * length:
        steps.append(steps[-1] + h)
        h *= ratio
    if len(steps) > 1 and length - steps[-1] < 0.5 * (steps[-1] - steps[-2]):
        steps[-1] = length
    else:
        steps.append(length)
    x = a + sign * np.array(steps)
    return np.sort(x)


def fine_then_geometric(a: float, b: float, fine_a: float, fine_b: float, h: float,
                        ratio: float) -> np.ndarray:
    """Uniform spacing about h on [fine_a, fine_b] (clipped to [a, b]), growing
    geometrically by ``ratio`` toward a and b outside it."""
    fine_a, fine_b = max(a, fine_a), min(b, fine_b)
    n = max(1, int(round((fine_b - fine_a) / h)))
    hf = (fine_b - fine_a) / n
    core = np.linspace(fine_a, fine_b, n + 1)
    parts = [core]
    if fine_a > a:
        parts.insert(0, geometric_from(fine_a, a, hf * ratio, ratio)[:-1])
    if fine_b < b:
        parts.append(geometric_from(fine_b, b, hf * ratio, ratio)[1:])
    return np.concatenate(parts)
