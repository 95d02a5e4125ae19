"""plate-pulse: an elastic pulse in a plane-strain plate reflecting from a fixed edge, a free edge and a corner (issue 56, the classical elastodynamic reference of the PD pulse scene).

The problem (defaults; SI units):

- plate [0, 2] x [0, 1.6] m, plane strain (as the PD wave scenes' state-based plane-strain
  model), E = 200 GPa, nu = 0.25, rho = 7850 kg/m^3: c_P = sqrt((lambda + 2 mu) / rho)
  = 5529 m/s, c_S = sqrt(mu / rho) = 3192 m/s;
- the edge x = 0 fixed (u = 0), the three others free (traction-free); so the pulse
  reflects from a fixed edge, from free edges and from the free-free corner (2, 1.6);
- the load: a body force b(x, t) = B r(t) (x - x_s) / s exp(-|x - x_s|^2 / (2 s^2)),
  the gradient of a Gaussian (curl-free, so in an unbounded body it radiates P waves
  only), s = 0.08 m, at x_s = (1, 0.8), with r(t) the Ricker wavelet
  (1 - 2 (pi f_p tau)^2) exp(-(pi f_p tau)^2), tau = t - 1.5 / f_p, of peak frequency
  f_p = c_P / wavelength, wavelength = 0.4 m (13 horizons of the PD scene's default
  grid, 6.7 of its quick grid); r has zero mean and zero first moment, so no net impulse
  and no static offset is left behind;
- receivers (``receiver_offset`` = 0.25 m from the feature they face): ``fixed`` at
  (0.25, 0.8), ``free`` at (1.75, 0.8) (mirror images of each other about the source:
  the two signals differ by the edge alone), ``corner`` on the line from the source to
  the corner (2, 1.6), 0.25 m from it.

Discretisation: 9-node biquadratic elements (Q2, scikit-fem ``ElementQuad2``) on uniform
meshes of edge ``spacing / 2^l``; P2 rather than P1 because a wave's phase error per
wavelength falls as (k H)^4 for quadratic elements against (k H)^2 for linear ones, so
the finest level resolves the Ricker pulse's band with 16 element edges per peak
wavelength. Mass lumped by row sums (for Q2 on rectangles the tensor product of 1D
Simpson weights 1/6, 2/3, 1/6: positive, and the Gauss-Lobatto spectral-element mass of
degree 2). Time integration: the central difference in its velocity Verlet form (the PD
scene's integrator), explicit, one sparse product per step; step dt = ``cfl`` x
2 / omega_bound, omega_bound^2 the largest eigenvalue of one element's M_e^-1 K_e (every
element is the same rectangle; the element eigenvalue theorem bounds the assembled
system's largest eigenvalue by the elements' largest, so the step is stable without an
iterative estimate), shortened to divide ``duration`` into whole steps. Each level
halves the element edge and the step together (their ratio fixed), and the finest
mesh is run once more at half its step, so the study separates the time error.

Convergence (the refinement table; defaults, measured, not tuned): the change of the
receiver signals between successive levels, max over the receivers and the common
sample times of |s_l - s_(l-1)| over max |s_l|, was 35 % and 3.1 % (edges 0.1 -> 0.05
-> 0.025 m), and the finest mesh's change under halving its step 1.2 %. That measure
is severe for a wave (a shift of 0.1 us at the pulse's peak frequency changes it by
1 %); the quantities the PD scene compares changed less: the reflected pulses' arrival
times (:func:`window_peaks`) by 1.25 us and 0.53 us over the two refinements (0.24 % of
the 220 us travel time) and 0.18 us under the step halving, their amplitudes by 3.0 %
and 0.53 %. ``receiver_change_pct``, ``arrival_change_s``, ``amplitude_change_pct``
and ``time_change_pct`` carry a run's values. Cost: 83 s cold on 2 shared cores under
load (most of it the finest level and its half step), cached after.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementQuad2, ElementVector, LinearForm, MeshQuad, asm
from skfem.models.elasticity import linear_elasticity

from . import params as _p
from .cache import cached
from .elasticity import Material
from .field import FieldSolution, midpoint_refined
from .meshing import uniform
from .results import ReferenceResult, RefinementRow

REFERENCE = "plate-pulse"
RECEIVERS = ("fixed", "free", "corner")


@dataclass(frozen=True)
class PulseParams:
    """Parameters (module docstring)."""

    length: float = 2.0          # l_x (m)
    width: float = 1.6           # l_y (m)
    E: float = 200e9             # Pa
    nu: float = 0.25
    rho: float = 7850.0          # kg/m^3
    source_x: float = 1.0        # centre of the source (m)
    source_y: float = 0.8
    source_width: float = 0.08   # s of the Gaussian (m)
    wavelength: float = 0.4      # c_P / f_p of the Ricker wavelet (m)
    body_force: float = 1e9      # B (N/m^3)
    receiver_offset: float = 0.25  # distance of each receiver from its feature (m)
    duration: float = 4.8e-4     # run length (s)
    spacing: float = 0.1         # element edge of level 0 (m); must divide length and width
    levels: int = 3              # levels (finest edge = spacing / 2^(levels-1))
    cfl: float = 0.9             # step over the element bound's stable limit
    snapshots: int = 12          # stored fields of the finest level, evenly in time

    def __post_init__(self):
        _p.positive(REFERENCE, length=self.length, width=self.width, E=self.E,
                    rho=self.rho, source_width=self.source_width,
                    wavelength=self.wavelength, receiver_offset=self.receiver_offset,
                    duration=self.duration, spacing=self.spacing)
        _p.require(-1 < self.nu < 0.5, REFERENCE, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(self.body_force != 0 and math.isfinite(self.body_force), REFERENCE,
                   "body_force must be a finite nonzero number")
        _p.require(2 <= self.levels <= 5, REFERENCE, f"levels must be 2..5, got {self.levels}")
        _p.require(0 < self.cfl <= 1, REFERENCE, f"cfl must lie in (0, 1], got {self.cfl}")
        _p.require(1 <= self.snapshots <= 100, REFERENCE,
                   f"snapshots must be 1..100, got {self.snapshots}")
        _p.require(0 < self.source_x < self.length and 0 < self.source_y < self.width,
                   REFERENCE, f"source_x={self.source_x}, source_y={self.source_y}: the "
                   f"source must lie inside the plate [0, {self.length}] x [0, {self.width}]")
        for name, L in (("length", self.length), ("width", self.width)):
            n = L / self.spacing
            _p.require(abs(n - round(n)) < 1e-9 * n and round(n) >= 1, REFERENCE,
                       f"spacing {self.spacing} must divide {name} {L}")
        pts = self.receiver_points()
        inside = (pts > 0).all() and (pts[:, 0] < self.length).all() and \
            (pts[:, 1] < self.width).all()
        _p.require(bool(inside), REFERENCE, f"receiver_offset {self.receiver_offset} puts "
                   "a receiver outside the plate")

    # --- derived quantities ------------------------------------------------------------
    def lame(self) -> tuple[float, float]:
        return Material(self.E, self.nu, "plane_strain").lame()

    @property
    def c_p(self) -> float:
        lam, mu = self.lame()
        return math.sqrt((lam + 2 * mu) / self.rho)

    @property
    def c_s(self) -> float:
        return math.sqrt(self.lame()[1] / self.rho)

    @property
    def peak_frequency(self) -> float:
        return self.c_p / self.wavelength

    @property
    def delay(self) -> float:
        """The Ricker wavelet's centre 1.5 / f_p (s): r(0) ~ -2e-9 of its peak."""
        return 1.5 / self.peak_frequency

    def source_point(self) -> np.ndarray:
        return np.array([self.source_x, self.source_y])

    def corner(self) -> np.ndarray:
        return np.array([self.length, self.width])

    def receiver_points(self) -> np.ndarray:
        """(3, 2): ``fixed``, ``free``, ``corner`` (module docstring)."""
        s, c, d = self.source_point(), self.corner(), self.receiver_offset
        towards = (s - c) / np.linalg.norm(s - c)
        return np.array([[d, s[1]], [self.length - d, s[1]], c + d * towards])

    def ricker(self, t):
        a = (math.pi * self.peak_frequency * (np.asarray(t, dtype=float) - self.delay)) ** 2
        return (1.0 - 2.0 * a) * np.exp(-a)

    def body_force_shape(self, x, y):
        """b(x) / r(t) at points (vectorised over arrays): (b_x, b_y) in N/m^3."""
        dx, dy = x - self.source_x, y - self.source_y
        s = self.source_width
        g = self.body_force * np.exp(-(dx * dx + dy * dy) / (2 * s * s)) / s
        return g * dx, g * dy

    def base_steps(self) -> int:
        """Steps of level 0: the duration over cfl x the element bound's limit."""
        return max(1, math.ceil(self.duration / (self.cfl * element_limit(self, 0))))

    def ray_paths(self) -> dict:
        """P-wave ray lengths (m) from the source to each receiver: ``direct`` and the
        reflections of its feature (mirror images of the source): ``fixed``: off x = 0;
        ``free``: off x = length; ``corner``: off the two edges that meet at the corner
        and the double reflection off both (the corner's image)."""
        s, r = self.source_point(), self.receiver_points()
        L, W = self.length, self.width
        xs, ys = s
        images = {"fixed": [(-xs, ys)], "free": [(2 * L - xs, ys)],
                  "corner": [(2 * L - xs, ys), (xs, 2 * W - ys), (2 * L - xs, 2 * W - ys)]}
        out = {}
        for k, name in enumerate(RECEIVERS):
            paths = [float(np.linalg.norm(np.subtract(im, r[k]))) for im in images[name]]
            out[name] = {"direct": float(np.linalg.norm(s - r[k])), "reflected": paths}
        return out

    def windows(self) -> np.ndarray:
        """(3, 2): per receiver the time window of its feature's reflected pulse: from
        half a Ricker period before the first reflected P ray's arrival (delay + path /
        c_P) to one period after the last (the displacement of a Ricker force lags the
        ray time; the window is the same for every method compared)."""
        T = 1.0 / self.peak_frequency
        out = []
        for name in RECEIVERS:
            paths = self.ray_paths()[name]["reflected"]
            out.append((self.delay + min(paths) / self.c_p - 0.5 * T,
                        self.delay + max(paths) / self.c_p + T))
        return np.array(out)

    def finest_cells(self) -> tuple[int, int]:
        h = self.spacing / 2 ** (self.levels - 1)
        return round(self.length / h), round(self.width / h)


@dataclass(frozen=True, eq=False, kw_only=True)
class PulseResult(ReferenceResult):
    """The converged pulse (see :class:`ReferenceResult` for the common fields; ``field``
    is the finest level's displacement at the last snapshot).

    Attributes
    ----------
    times : (n_t,) the finest level's step times (s), 0 .. duration.
    receivers : (3, n_t, 2) displacement at the receivers ``fixed``, ``free``, ``corner``
        at ``times`` (m).
    receiver_points : (3, 2) their positions (m).
    snapshot_times : (n_s,) times of the stored fields (s), on the common sample grid.
    snapshots : (n_s, n_x', n_y', 2) the finest level's displacement on its Q2 node grid
        at ``snapshot_times`` (:meth:`snapshot` gives each as a :class:`FieldSolution`).
    energy : (3, n_t) kinetic, strain energy and work of the load (J per m of
        thickness) at ``times``.
    receiver_change_pct : the last level's change of the receiver signals.
    time_change_pct : the finest mesh's change under halving its step;
        ``time_arrival_change_s`` the change of the arrival times under it.
    arrivals : (3, 2) arrival time (s) and amplitude (m) of the largest |u| in each
        receiver's window (:func:`window_peaks`); windows (3, 2) those windows (s).
    dt : the finest level's step (s); dt_limit the element bound's limit at that level.
    """

    times: np.ndarray
    receivers: np.ndarray
    receiver_points: np.ndarray
    snapshot_times: np.ndarray
    snapshots: np.ndarray
    energy: np.ndarray
    receiver_change_pct: float
    time_change_pct: float
    time_arrival_change_s: float
    arrivals: np.ndarray
    windows: np.ndarray
    dt: float
    dt_limit: float
    energy_balance_pct: float

    def snapshot(self, k: int) -> FieldSolution:
        f = self.field
        return FieldSolution(coords=f.coords, values=self.snapshots[k], lam=f.lam, mu=f.mu)

    def metrics(self) -> dict:
        return {"receiver_change_pct": float(self.receiver_change_pct),
                "time_change_pct": float(self.time_change_pct),
                "time_arrival_change_s": float(self.time_arrival_change_s),
                "refinement_change_pct": float(self.refinement_change_pct),
                "arrival_change_s": float(self.refinement[-1].extra["arrival_change_s"]),
                "amplitude_change_pct": float(
                    self.refinement[-1].extra["amplitude_change_pct"]),
                "energy_balance_pct": float(self.energy_balance_pct),
                "dt": float(self.dt), "dt_limit": float(self.dt_limit)}


@BilinearForm
def _mass(u, v, w):
    return u[0] * v[0] + u[1] * v[1]


def _model(p: PulseParams, h: float):
    """(basis, K, lumped mass, the source's load vector, fixed dofs) of edge h."""
    xs = uniform(0.0, p.length, round(p.length / h))
    ys = uniform(0.0, p.width, round(p.width / h))
    mesh = MeshQuad.init_tensor(xs, ys)
    basis = Basis(mesh, ElementVector(ElementQuad2()))
    lam, mu = p.lame()
    K = asm(linear_elasticity(lam, mu), basis).tocsr()
    mass = p.rho * np.asarray(asm(_mass, basis).sum(axis=1)).ravel()

    @LinearForm
    def load(v, w):
        bx, by = p.body_force_shape(w.x[0], w.x[1])
        return bx * v[0] + by * v[1]

    f = asm(load, basis)
    fixed = np.flatnonzero(basis.doflocs[0] < 1e-9 * p.length)
    return (xs, ys), basis, K, mass, f, fixed


def element_limit(p: PulseParams, level: int) -> float:
    """2 / omega_bound of level ``level``: omega_bound^2 the largest eigenvalue of one
    element's lumped M_e^-1 K_e (every element of the uniform mesh is the same)."""
    h = p.spacing / 2 ** level
    _, _, K, m, _, _ = _one_element(p, h)
    s = 1.0 / np.sqrt(m)
    top = np.linalg.eigvalsh((s[:, None] * K.toarray() * s[None, :]))[-1]
    return 2.0 / math.sqrt(top)


def _one_element(p, h):
    mesh = MeshQuad.init_tensor(np.array([0.0, h]), np.array([0.0, h]))
    basis = Basis(mesh, ElementVector(ElementQuad2()))
    lam, mu = p.lame()
    K = asm(linear_elasticity(lam, mu), basis)
    m = p.rho * np.asarray(asm(_mass, basis).sum(axis=1)).ravel()
    return None, basis, K, m, None, None


def _grid_values(basis, coords, u):
    """u on the midpoint-refined node grid, shape (n_x', n_y', 2) ('ij')."""
    gx, gy = midpoint_refined(coords[0]), midpoint_refined(coords[1])
    out = np.empty((gx.size, gy.size, 2))
    for c, idx in enumerate(basis.split_indices()):
        loc = basis.doflocs[:, idx]
        i = np.rint((loc[0] - gx[0]) / (gx[1] - gx[0])).astype(int)
        j = np.rint((loc[1] - gy[0]) / (gy[1] - gy[0])).astype(int)
        out[i, j, c] = u[idx]
    return out


def run_level(p: PulseParams, level: int, steps: int, snapshot_steps=()):
    """Central difference (velocity Verlet) on the mesh of ``level`` with ``steps`` steps
    over ``duration``. Returns a dict: ``receivers`` (3, steps + 1, 2), ``energy`` (3,
    steps + 1), ``snapshots`` (grid values at ``snapshot_steps``), the model's coords,
    ``dofs``, ``dt``, ``dt_limit``, ``setup_s``, ``solve_s``."""
    t0 = time.perf_counter()
    h = p.spacing / 2 ** level
    coords, basis, K, mass, f, fixed = _model(p, h)
    limit = element_limit(p, level)
    dt = p.duration / steps
    if dt > limit:
        raise FloatingPointError(f"{REFERENCE}: step {dt:.4g} s over the stable limit "
                                 f"{limit:.4g} s")
    free = np.ones(basis.N, dtype=bool)
    free[fixed] = False
    inv_m = np.where(free, 1.0 / mass, 0.0)       # fixed dofs never move
    P = basis.probes(p.receiver_points().T).tocsr()   # rows: component-major
    nr = len(RECEIVERS)
    t1 = time.perf_counter()
    u = np.zeros(basis.N)
    v = np.zeros(basis.N)
    a = inv_m * (p.ricker(0.0) * f)
    rec = np.empty((steps + 1, 2 * nr))
    energy = np.empty((3, steps + 1))
    rec[0] = P @ u
    energy[:, 0] = 0.0
    work, power = 0.0, float(v @ (p.ricker(0.0) * f))
    snaps, want = [], set(int(s) for s in snapshot_steps)
    if 0 in want:
        snaps.append(_grid_values(basis, coords, u))
    for k in range(1, steps + 1):
        v += 0.5 * dt * a
        u += dt * v
        Ku = K @ u
        fk = p.ricker(k * dt) * f
        a = inv_m * (fk - Ku)
        v += 0.5 * dt * a
        rec[k] = P @ u
        p1 = float(v @ fk)
        work += 0.5 * dt * (power + p1)
        power = p1
        energy[:, k] = 0.5 * float(v @ (mass * v)), 0.5 * float(u @ Ku), work
        if k in want:
            snaps.append(_grid_values(basis, coords, u))
    if not np.isfinite(u).all():
        raise FloatingPointError(f"{REFERENCE}: non-finite displacement at level {level}")
    receivers = rec.reshape(steps + 1, 2, nr).transpose(2, 0, 1)
    lam, mu = p.lame()
    return {"receivers": receivers, "energy": energy, "snapshots": snaps, "coords": coords,
            "dofs": int(basis.N), "dt": dt, "dt_limit": limit, "lam": lam, "mu": mu,
            "last": _grid_values(basis, coords, u), "setup_s": t1 - t0,
            "solve_s": time.perf_counter() - t1}


def signal_change_pct(fine: np.ndarray, coarse: np.ndarray) -> float:
    """100 max |fine - coarse| / max |fine| over receivers, components and common
    times (both (3, n, 2) at the same times)."""
    return float(100.0 * np.max(np.abs(fine - coarse)) / np.max(np.abs(fine)))


def window_peaks(times, receivers, windows):
    """(3, 2): per receiver the arrival time (s) and amplitude (m) of the largest |u| in
    its window: the sampled maximum refined by the parabola through it and its two
    neighbours (arrival time and peak to second order in the sampling)."""
    out = np.empty((len(windows), 2))
    for k, (a, b) in enumerate(windows):
        idx = np.flatnonzero((times >= a) & (times <= b))
        mag = np.linalg.norm(receivers[k][idx], axis=1)
        j = int(np.argmax(mag))
        t, amp = times[idx[j]], mag[j]
        if 0 < j < idx.size - 1:
            y0, y1, y2 = mag[j - 1], mag[j], mag[j + 1]
            den = y0 - 2 * y1 + y2
            if den < 0:
                shift = 0.5 * (y0 - y2) / den
                dt = times[idx[1]] - times[idx[0]]
                t, amp = t + shift * dt, y1 - 0.25 * (y0 - y2) * shift
        out[k] = t, amp
    return out


def energy_balance_pct(energy: np.ndarray) -> float:
    """max |E_kin + E_strain - W| over max (E_kin + E_strain), in % (starts at rest)."""
    kin, strain, work = energy
    total = kin + strain
    return float(100.0 * np.max(np.abs(total - work)) / np.max(total))


def compute(p: PulseParams) -> PulseResult:
    """The refinement study (no cache)."""
    t_start = time.perf_counter()
    n0 = p.base_steps()
    common_times = np.arange(n0 + 1) * (p.duration / n0)
    windows = p.windows()
    rows, prev = [], None
    for level in range(p.levels):
        scale = 2 ** level
        last = level == p.levels - 1
        snap_steps = (np.rint(np.linspace(0, n0, p.snapshots + 1)[1:]).astype(int) * scale
                      if last else ())
        run = run_level(p, level, n0 * scale, snap_steps)
        common = run["receivers"][:, ::scale]          # at the n0 + 1 common times
        extra = {"dt": run["dt"], "dt_limit": run["dt_limit"],
                 "energy_balance_pct": energy_balance_pct(run["energy"])}
        change = float("nan")
        peaks = window_peaks(common_times, common, windows)
        if prev is not None:
            change = signal_change_pct(common, prev)
            extra["receiver_change_pct"] = change
            extra["arrival_change_s"] = float(np.max(np.abs(peaks[:, 0] - prev_peaks[:, 0])))
            extra["amplitude_change_pct"] = float(
                100 * np.max(np.abs(peaks[:, 1] - prev_peaks[:, 1]) / peaks[:, 1]))
        prev_peaks = peaks
        rows.append(RefinementRow(level=level, dofs=run["dofs"], h_min=p.spacing / scale,
                                  quantity=float(np.max(np.abs(run["receivers"]))),
                                  change_pct=change, setup_s=run["setup_s"],
                                  solve_s=run["solve_s"], extra=extra))
        prev, fine = common, run
    # the finest mesh at half its step: the time error alone
    half = run_level(p, p.levels - 1, 2 * n0 * 2 ** (p.levels - 1))
    time_change = signal_change_pct(half["receivers"][:, ::2], fine["receivers"])
    steps = n0 * 2 ** (p.levels - 1)
    fine_times = np.arange(steps + 1) * fine["dt"]
    half_peaks = window_peaks(fine_times, half["receivers"][:, ::2], windows)
    fine_peaks = window_peaks(fine_times, fine["receivers"], windows)
    time_arrival_change = float(np.max(np.abs(half_peaks[:, 0] - fine_peaks[:, 0])))
    times = np.arange(steps + 1) * fine["dt"]
    snap_idx = np.rint(np.linspace(0, n0, p.snapshots + 1)[1:]).astype(int) * 2 ** (p.levels - 1)
    field = FieldSolution(coords=fine["coords"], values=fine["last"], lam=fine["lam"],
                          mu=fine["mu"])
    return PulseResult(
        reference=REFERENCE, params=_p.as_dict(p),
        quantity_name="max |u| at the receivers (m)", quantity=rows[-1].quantity,
        refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=fine["setup_s"], solve_s=fine["solve_s"],
        study_s=time.perf_counter() - t_start, field=field, times=times,
        receivers=fine["receivers"], receiver_points=p.receiver_points(),
        snapshot_times=snap_idx * fine["dt"], snapshots=np.array(fine["snapshots"]),
        energy=fine["energy"], receiver_change_pct=rows[-1].change_pct,
        time_change_pct=time_change, time_arrival_change_s=time_arrival_change,
        arrivals=fine_peaks, windows=windows, dt=fine["dt"], dt_limit=fine["dt_limit"],
        energy_balance_pct=energy_balance_pct(fine["energy"]))


def plate_pulse(*, use_cache: bool = True, **params) -> PulseResult:
    """Converged, cached FEM reference of the pulse in the plate (module docstring).

    Keyword arguments override :class:`PulseParams`; ``use_cache=False`` recomputes
    without reading or writing the cache."""
    p = _p.build(PulseParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p), {"PulseResult": PulseResult},
                  use_cache=use_cache)
