"""1D linearised bond-based PD bar with a constant or triangular micromodulus (seed 004)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .bonds import bond_family_1d, partial_volumes_1d
from .errors import NumericalError

MICROMODULI = ("triangular", "constant")
END_WEIGHTS = ("full", "half")
CALIBRATIONS = ("discrete", "continuum")

#: Continuum micromodulus c_inf = FACTOR * E / (A delta^2) (Bobaru et al., quoted below
#: Eq. 6 of seed 004): constant 2, triangular 6.
CONTINUUM_FACTOR = {"constant": 2.0, "triangular": 6.0}


def split_horizon_ratio(horizon_ratio: float) -> tuple[int, float]:
    """(m, beta) with delta = (m + beta) Delta and beta in {0, 1/2} (seed 004 Eq. 7, Fig. 2).

    beta = 0: the horizon runs through the middle of element m ("through an element");
    beta = 1/2: it falls on the border between elements m and m + 1 ("between elements").
    Raises ``ValueError`` for any other ratio.
    """
    twice = 2.0 * float(horizon_ratio)
    if not np.isfinite(twice) or abs(twice - round(twice)) > 1e-12 or round(twice) < 2:
        raise ValueError(f"horizon_ratio={horizon_ratio!r} must be a whole or half-whole number "
                         ">= 1 (delta = m Delta or (m + 1/2) Delta)")
    twice_int = int(round(twice))
    return twice_int // 2, 0.5 * (twice_int % 2)


def bond_profile(horizon_ratio: float, micromodulus: str = "triangular"):
    """Offsets k >= 1 and the per-offset weights c(k Delta)/c1 * v_k of the discrete bar.

    c(xi)/c1 is 1 (constant) or 1 - xi/delta (triangular, Eq. 6); v_k is the fraction of
    element k inside the horizon (1/2 for the element the horizon cuts in two, 1 otherwise;
    :func:`pdverify.bonds.partial_volumes_1d`), which is the m(1/2 + beta) term of Eq. (9).
    Offsets whose weight vanishes (the triangle's tip at k = m when beta = 0) are dropped.
    """
    if micromodulus not in MICROMODULI:
        raise ValueError(f"micromodulus={micromodulus!r}; allowed: {', '.join(MICROMODULI)}")
    split_horizon_ratio(horizon_ratio)
    k, v = partial_volumes_1d(float(horizon_ratio))
    shape = 1.0 - k / float(horizon_ratio) if micromodulus == "triangular" else np.ones(k.size)
    weight = shape * v
    keep = weight > 0
    return k[keep], weight[keep]


def micromodulus_c1(horizon_ratio: float, *, E: float, area: float, spacing: float,
                    micromodulus: str = "triangular", calibration: str = "discrete") -> float:
    """The micromodulus constant c1 of Eq. (6) (c = c1 for the constant micromodulus).

    ``discrete``: equate the strain energy density of the discrete horizon to E eps^2 / 2,
    W_m = (c1 s^2 A / 2) sum_k c_k/c1 v_k k Delta^2 (Eqs. 9, 18), which gives Eq. (14)
    (beta = 0, = Eq. 26) and Eq. (22) (beta = 1/2, = Eq. 30) for the triangular
    micromodulus. ``continuum``: c_inf = 6E/(A delta^2) (triangular) or 2E/(A delta^2)
    (constant), exact only for infinitely many points in the horizon.
    """
    if calibration not in CALIBRATIONS:
        raise ValueError(f"calibration={calibration!r}; allowed: {', '.join(CALIBRATIONS)}")
    k, weight = bond_profile(horizon_ratio, micromodulus)
    if calibration == "continuum":
        horizon = horizon_ratio * spacing
        return CONTINUUM_FACTOR[micromodulus] * E / (area * horizon ** 2)
    return E / (area * spacing ** 2 * float(np.sum(k * weight)))


def micromodulus_factor(horizon_ratio: float, micromodulus: str = "triangular") -> float:
    """c1(m) / c_inf, the function f_1(m) of Eqs. (27) and (31) (Tables 1 and 2)."""
    args = dict(E=1.0, area=1.0, spacing=1.0, micromodulus=micromodulus)
    return (micromodulus_c1(horizon_ratio, calibration="discrete", **args)
            / micromodulus_c1(horizon_ratio, calibration="continuum", **args))


@dataclass
class BondBar1D:
    """A uniform bar of ``nodes`` points, x_i = (i - 1) Delta, linearised bond-based PD (Eq. 33).

    Each node carries the element volume A Delta, or A Delta / 2 at both ends with
    ``end_weight="half"`` (Fig. 1 shows full weight). A bond i-j of length k Delta has the
    spring stiffness

        s_ij = alpha_ij c1 A^2 Delta (c(k Delta)/c1) v_k w_i w_j / k,

    so that the force on i is s_ij (u_j - u_i) = c(|xi|) (u_j - u_i)/|xi| V_i V_j, i.e.
    Eq. (33) times the volume V_i of the subject point. w_i is the relative node weight
    (1 or 1/2), v_k the partial volume of :func:`bond_profile` and alpha_ij the end-bond
    factor: ``end_factors[k - 1]`` on the bonds (1, 1 + k) and (N, N - k), 1 elsewhere
    (Sec. 3.1; :mod:`pdverify.corrections.homogenized` computes them).

    ``K`` is the symmetric stiffness (K u = external nodal forces), assembled from the
    bond arrays in one sparse call (bonds come from the stencil of offsets by slicing).
    The paper's non-symmetric matrix S of Su = -b (force per unit volume, App. 2) is
    -diag(1/V) K; :meth:`equation_rows` returns it divided by c1 A, the scaling of the
    printed equations (34)-(98).
    """

    nodes: int
    spacing: float
    horizon_ratio: float
    E: float
    area: float = 1.0
    end_weight: str = "full"
    micromodulus: str = "triangular"
    calibration: str = "discrete"
    end_factors: tuple = ()

    def __post_init__(self):
        if self.end_weight not in END_WEIGHTS:
            raise ValueError(f"end_weight={self.end_weight!r}; allowed: {', '.join(END_WEIGHTS)}")
        self.m, self.beta = split_horizon_ratio(self.horizon_ratio)
        self.offsets, self.profile = bond_profile(self.horizon_ratio, self.micromodulus)
        if self.offsets.size == 0:
            raise ValueError(f"horizon_ratio={self.horizon_ratio}: no bond has a non-zero "
                             f"{self.micromodulus} micromodulus")
        if self.nodes < 2 * self.m + 1:
            raise ValueError(f"nodes={self.nodes} must be >= 2m + 1 = {2 * self.m + 1}")
        factors = np.asarray(self.end_factors, dtype=float)
        if factors.size and not (factors.size <= self.offsets.max() and np.all(factors > 0)):
            raise ValueError(f"end_factors={self.end_factors!r}: at most {self.offsets.max()} "
                             "positive factors")
        self.c1 = micromodulus_c1(self.horizon_ratio, E=self.E, area=self.area,
                                  spacing=self.spacing, micromodulus=self.micromodulus,
                                  calibration=self.calibration)
        self.horizon = self.horizon_ratio * self.spacing
        self.x = np.arange(self.nodes) * self.spacing
        self.weight = np.ones(self.nodes)
        if self.end_weight == "half":
            self.weight[[0, -1]] = 0.5
        self.volume = self.area * self.spacing * self.weight
        self._build(factors)

    def _build(self, factors):
        N = self.nodes
        i, j, which = bond_family_1d(N, self.offsets)
        k = self.offsets[which]
        alpha = np.ones(i.size)
        for kk, a in enumerate(factors, start=1):  # at most m - 1 offsets, not a loop over bonds
            alpha[(i == 0) & (j == kk)] = a
            alpha[(j == N - 1) & (i == N - 1 - kk)] = a
        s = (alpha * self.c1 * self.area ** 2 * self.spacing * self.profile[which]
             * self.weight[i] * self.weight[j] / k)
        self.bond_i, self.bond_j, self.bond_k, self.bond_stiffness = i, j, k, s
        # K = sum_b s_b (e_i - e_j)(e_i - e_j)^T; duplicates are summed by the COO -> CSR step
        self.K = sp.csr_matrix((np.r_[s, s, -s, -s], (np.r_[i, j, i, j], np.r_[i, j, j, i])),
                               shape=(N, N))

    # ------------------------------------------------------------------ queries
    def equation_rows(self) -> np.ndarray:
        """Dense S / (c1 A): row i is the left-hand side of Eq. (33) / (c1 A) for point i."""
        return -(self.K.toarray() / self.volume[:, None]) / (self.c1 * self.area)

    def lumped_mass(self, density: float) -> np.ndarray:
        """Nodal masses rho V_i (half at both ends for half-weight end elements)."""
        return density * self.volume

    def cut_stiffness(self) -> sp.csr_matrix:
        """F with F d = the force through every cut, d_c = u_{c+1} - u_c (c = 1..N-1).

        A bond i-j crosses the cuts i..j-1 and its extension is the sum of their gaps
        (G d); the force through cut c is the summed force of the bonds crossing it,
        so F = G^T diag(s) G, banded (half-width = the bond reach) and SPD.
        """
        i, j, s = self.bond_i, self.bond_j, self.bond_stiffness
        span = j - i
        rows = np.repeat(np.arange(i.size), span)
        start = np.repeat(np.cumsum(span) - span, span)
        cols = np.repeat(i, span) + (np.arange(rows.size) - start)
        G = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(i.size, self.nodes - 1))
        return (G.T @ sp.diags(s) @ G).tocsr()

    def end_force_displacement(self, force: float) -> np.ndarray:
        """Displacements under -force at point 1 and +force at point N, centre at rest.

        Node i's equation is flux(i-1) - flux(i) + f_i = 0, so end forces +-F put the force
        F through every cut: N - 1 equations F d = F 1 for the N - 1 gaps. This statically
        determinate form is solved instead of K u = f with a pinned node because its
        condition number stays bounded as N grows (K's grows like N^2, which costs about
        1e-12 of f(N) at N = 1001), and the strain factor needs round-off accuracy there.
        """
        F = self.cut_stiffness().tocsc()
        gaps = spla.spsolve(F, np.full(self.nodes - 1, float(force)))
        if not np.all(np.isfinite(gaps)):
            raise NumericalError("end-loaded bar: the cut system gave non-finite gaps")
        u = np.concatenate([[0.0], np.cumsum(gaps)])
        N = self.nodes
        return u - 0.5 * (u[(N - 1) // 2] + u[N // 2])

    def size(self) -> dict:
        return {"nodes": int(self.nodes), "dofs": int(self.nodes), "bonds": int(self.bond_i.size)}
