"""Preconditioned conjugate gradients for SPD PD stiffnesses, with a two-level
smoothed-aggregation preconditioner whose aggregates are lattice blocks one horizon wide.

Why this preconditioner: a PD operator is nonlocal,
so its high-frequency spectrum is flat (~ a constant times the identity) and weighted
Jacobi smooths it well; what Jacobi cannot reach are the smooth modes, above all the
rigid-body motions. A coarse space spanned by the rigid-body modes of lattice blocks about
one horizon wide (seed 003's m = 6 nodes), smoothed once by Jacobi, captures them. On the
indentation-size bond-based stiffness (50,880 unknowns) CG converges to 1e-10 in 12
iterations, 0.41 s a solve, where pyamg's smoothed aggregation took 1.5 s (record
solvers-2026-11-22-cg-two-level).

The aggregates' width hardly matters: widths 3 to 8 lattice nodes took 19 to 23 iterations
on a tangent of the half indentation model (record
indentation-2026-11-27-aggregate-width): the Jacobi smoother, not the coarse space, sets
the rate, and one horizon (m = 6) is as fast as any.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import NumericalError

#: Relative residual ||K u - f|| / ||f|| at which CG stops. The solution error is then at
#: most kappa(K) * 1e-10; the record carries an estimate of it (``solver_error_estimate``)
#: that each run compares with its method error (:func:`solver_error_warnings`).
CG_RTOL = 1e-10
#: The solver error must stay below this fraction of the method error it serves (issue 12).
SOLVER_ERROR_FRACTION = 1e-3
#: Jacobi weight, as a fraction of 1 / rho(D^-1 K): 1.3 the better of 1.0 and 1.3 on the
#: indentation-size stiffness (record solvers-2026-11-22-smoother-weight); the smoother
#: converges below 2.
SMOOTHER_WEIGHT = 1.3
#: Weight of the prolongator's Jacobi smoothing step, as a fraction of 1 / rho(D^-1 K).
PROLONGATOR_WEIGHT = 0.6


@dataclass(frozen=True)
class Lattice:
    """Where each unknown sits: lattice index (n, D) of its node, coordinates (n, D) and
    component (n,). Builds the coarse space of :class:`TwoLevelPreconditioner`."""

    index: np.ndarray
    x: np.ndarray
    comp: np.ndarray

    @classmethod
    def component_major(cls, index, x, dim: int) -> "Lattice":
        """Unknowns ordered component-major over nodes (k * n_nodes + node)."""
        n = index.shape[0]
        return cls(np.tile(index, (dim, 1)), np.tile(x, (dim, 1)), np.repeat(np.arange(dim), n))

    @property
    def dim(self) -> int:
        return self.index.shape[1]

    def take(self, sel) -> "Lattice":
        return Lattice(self.index[sel], self.x[sel], self.comp[sel])


#: rotations in the (i, j) planes (u_i = -x_j, u_j = x_i): the rigid-body modes beside the
#: translations, per dimension
ROTATIONS = {1: (), 2: ((0, 1),), 3: ((0, 1), (1, 2), (2, 0))}


def _tentative_prolongator(lattice: Lattice, agg, n_agg: int, rel):
    """Rigid-body modes per aggregate (about its centroid), orthonormalised aggregate by
    aggregate and cut to their rank: an aggregate on one line of nodes, or one left with a
    single component by the supports, spans fewer modes (batched eigh of the per-aggregate
    Gram matrices; eigenvalues below 1e-10 of the aggregate's largest are dropped)."""
    n, dim, comp = agg.size, lattice.dim, lattice.comp
    modes = np.zeros((n, dim + len(ROTATIONS[dim])))
    modes[np.arange(n), comp] = 1.0
    for r, (i, j) in enumerate(ROTATIONS[dim]):
        modes[:, dim + r] = np.where(comp == i, -rel[:, j], np.where(comp == j, rel[:, i], 0.0))
    k = modes.shape[1]
    gram = np.zeros((n_agg, k, k))
    for p in range(k):
        for q in range(p, k):
            gram[:, p, q] = gram[:, q, p] = np.bincount(agg, modes[:, p] * modes[:, q], n_agg)
    lam, vec = np.linalg.eigh(gram)
    keep = lam > 1e-10 * lam[:, -1:]
    scale = np.where(keep, 1.0 / np.sqrt(np.where(keep, lam, 1.0)), 0.0)
    W = vec * scale[:, None, :]                              # (n_agg, k, k), zero columns cut
    vals = np.einsum("np,npq->nq", modes, W[agg])
    cols = agg[:, None] * k + np.arange(k)[None, :]
    live = keep[agg]
    T = sp.csr_matrix((vals[live], (np.repeat(np.arange(n), k).reshape(n, k)[live], cols[live])),
                      shape=(n, n_agg * k))
    used = np.flatnonzero(np.diff(T.tocsc().indptr) > 0)
    return T[:, used].tocsr()


def _inverse_diagonal(K) -> np.ndarray:
    """1 / diag(K), or :class:`NumericalError` if a diagonal entry is not positive."""
    diag = K.diagonal()
    if np.any(diag <= 0) or not np.all(np.isfinite(diag)):
        raise NumericalError("CG preconditioner: the stiffness has a non-positive diagonal "
                             "entry, so it is not symmetric positive definite")
    return 1.0 / diag


def _jacobi_radius(K, d_inv, formed: bool = True) -> float:
    """rho(D^-1 K), estimated to 1 % (ARPACK on D^-1/2 K D^-1/2; ``formed=False``: that
    matrix applied as s * (K @ (s * x)) instead of multiplied out, which saves two copies
    of K and rounds differently)."""
    s = np.sqrt(d_inv)
    if formed:
        scaled = sp.diags(s) @ K @ sp.diags(s)
    else:
        scaled = spla.LinearOperator(K.shape, matvec=lambda x: s * (K @ (s * x)), dtype=float)
    # a fixed start vector: ARPACK's own random one differs between calls in a process,
    # which made rho, hence CG's iterates and a Newton run's last digits, depend on
    # what ran before in the same worker
    start = np.random.default_rng(0).standard_normal(K.shape[0])
    return float(spla.eigsh(scaled, k=1, which="LA", tol=1e-2, v0=start,
                            return_eigenvectors=False)[0])


#: A refresh keeps the build's spectral radius estimate while rho(D^-1 K) of the new
#: matrix stays below this multiple of it: the Jacobi smoother (weight SMOOTHER_WEIGHT /
#: rho) converges, and the preconditioner stays SPD, below 2 / SMOOTHER_WEIGHT = 1.54
#: times; the margin covers the estimates' 1 % tolerance.
REFRESH_RADIUS_GROWTH = 1.45


class TwoLevelPreconditioner:
    """Symmetric two-level smoothed aggregation: Jacobi, coarse correction, Jacobi.

    Aggregates: blocks of ``width`` x ... lattice nodes; per aggregate the rigid-body modes
    about its centroid span the tentative prolongator T; P = (I - w D^-1 K) T; the coarse
    matrix P^T K P is factored by dense Cholesky. Applying it costs two products with K.
    ``K`` may later be replaced by a nearby matrix (a Newton tangent): the preconditioner
    stays symmetric positive definite, so CG stays valid; only its quality changes.
    """

    def __init__(self, K, lattice: Lattice, width: int, fused: bool = False):
        t0 = time.perf_counter()
        K = sp.csr_matrix(K)
        dim = lattice.dim
        width = max(int(width), 1)
        blocks = lattice.index // width
        key = np.ravel_multi_index(tuple((blocks - blocks.min(0)).T), tuple(np.ptp(blocks, 0) + 1))
        _, agg = np.unique(key, return_inverse=True)
        n_agg = int(agg.max()) + 1
        count = np.bincount(agg, minlength=n_agg)
        centroid = np.stack([np.bincount(agg, lattice.x[:, k], n_agg) / count
                             for k in range(dim)], axis=1)
        T = _tentative_prolongator(lattice, agg, n_agg, lattice.x - centroid[agg])
        d_inv = _inverse_diagonal(K)
        self.rho = rho = _jacobi_radius(K, d_inv)
        P = (T - sp.diags((PROLONGATOR_WEIGHT / rho) * d_inv) @ (K @ T)).tocsr()
        # The preconditioner works in single precision (CG itself in double): it only has
        # to be a fixed SPD approximation, and halving its bytes took a 12-iteration solve
        # from 0.47 to 0.40 s (record solvers-2026-11-22-float32-preconditioner).
        self._P32 = P.astype(np.float32).tocsr()
        self._PT32 = self._P32.T.tocsr()
        self._P = P
        # fused: K (x1 + P e) = K x1 + (K P) e, one product with K per application instead
        # of two; the same operator in exact arithmetic (float32 round-off apart), a third
        # less time an application (record indentation-2026-11-24-fused)
        self.fused = fused
        self._operator_parts(K, d_inv, (P.T @ (K @ P)).toarray())
        self.setup_s = time.perf_counter() - t0

    def _operator_parts(self, K, d_inv, coarse, KP32=None) -> None:
        """What the preconditioner takes from K: its float32 copy, the Jacobi weights, the
        inverse of the coarse matrix ``coarse`` = P^T K P, and K P if fused (``KP32``, or
        the product of the float32 copies)."""
        try:
            chol = sl.cho_factor(coarse)
        except sl.LinAlgError:
            raise NumericalError("CG preconditioner: the coarse matrix is not positive "
                                 "definite (the stiffness is singular or not SPD)") from None
        coarse_inv = sl.cho_solve(chol, np.eye(coarse.shape[0]))
        f32 = np.float32
        self._K32 = K.astype(f32)
        self._coarse_inv32 = ((coarse_inv + coarse_inv.T) / 2).astype(f32)
        self._w32 = ((SMOOTHER_WEIGHT / self.rho) * d_inv).astype(f32)
        if self.fused:
            self._KP32 = (self._K32 @ self._P32).tocsr() if KP32 is None else KP32
        else:
            self._KP32 = None
        self.K = K
        self.coarse_size = coarse.shape[0]

    def refresh(self, K) -> bool:
        """Adapt to a nearby matrix ``K`` of the same size (a later Newton tangent, perhaps
        with more prescribed unknowns): the smoother's diagonal, the products with K and
        the coarse matrix P^T K P are K's; the aggregates, the prolongator P (smoothed with
        the first K) and the spectral radius estimate stay. Returns False, changing nothing,
        when rho(D^-1 K) has grown past :data:`REFRESH_RADIUS_GROWTH` times the build's
        (the caller then builds anew), else True; either way its time is added to
        :attr:`setup_s`.

        Why: on the paper grid's half indentation a refreshed preconditioner needed 18 CG
        iterations where one built on an earlier tangent needed 31, for about half a
        build's time (record indentation-2026-11-27-refresh)."""
        t0 = time.perf_counter()
        K = sp.csr_matrix(K)
        d_inv = _inverse_diagonal(K)
        if _jacobi_radius(K, d_inv, formed=False) > REFRESH_RADIUS_GROWTH * self.rho:
            self.setup_s += time.perf_counter() - t0
            return False         # the smoother would diverge with the build's weight
        KP = (K @ self._P).tocsr()
        self._operator_parts(K, d_inv, (self._P.T @ KP).toarray(),
                             KP.astype(np.float32) if self.fused else None)
        self.setup_s += time.perf_counter() - t0
        return True

    def apply(self, r):
        r = np.asarray(r).astype(np.float32)
        x = self._w32 * r
        if self._KP32 is not None:
            r1 = r - self._K32 @ x
            e = self._coarse_inv32 @ (self._PT32 @ r1)
            x += self._P32 @ e
            r1 -= self._KP32 @ e
            x += self._w32 * r1
            return x.astype(float)
        x += self._P32 @ (self._coarse_inv32 @ (self._PT32 @ (r - self._K32 @ x)))
        x += self._w32 * (r - self._K32 @ x)
        return x.astype(float)

    def operator(self):
        return spla.LinearOperator(self.K.shape, matvec=self.apply, dtype=float)


def cg_solve(K, f, precond, *, where: str, rtol: float = CG_RTOL, maxiter: int = 1000):
    """CG on K u = f with ``precond`` (a :class:`TwoLevelPreconditioner` or a
    :class:`JacobiPreconditioner`; ``K`` a sparse matrix or, e.g.
    :class:`CondensedOperator`, anything with ``shape`` and ``@``); returns ``(u, info)``.

    ``info``: iterations, the relative residual ||K u - f|| / ||f||, the tolerance, setup
    and solve time, and ``solver_error_estimate``: the relative error left, estimated from
    the last step and the mean convergence factor rho as ||u_k - u_{k-1}|| rho / (1 - rho)
    / ||u_k|| (a geometric tail). Non-convergence (``maxiter`` reached: a stall) and
    non-finite values raise :class:`NumericalError` naming ``where``.
    """
    f = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(f)) or (sp.issparse(K) and not np.all(np.isfinite(K.data))):
        raise NumericalError(f"{where}: the system has non-finite entries")
    nf = float(np.linalg.norm(f))
    if nf == 0.0:
        u = np.zeros_like(f)
        return u, _cg_info(K, precond, 0, 0.0, 0.0, 0.0, rtol)
    state = {"k": 0, "prev": None, "step": 0.0}

    def callback(xk):
        if state["prev"] is not None:
            state["step"] = float(np.linalg.norm(xk - state["prev"]))
        state["prev"] = xk.copy()
        state["k"] += 1

    t0 = time.perf_counter()
    u, code = spla.cg(K, f, M=precond.operator(), rtol=rtol, atol=0.0, maxiter=maxiter,
                      callback=callback)
    solve_s = time.perf_counter() - t0
    if not np.all(np.isfinite(u)):
        raise NumericalError(f"{where}: CG produced non-finite values")
    res = float(np.linalg.norm(K @ u - f) / nf)
    if code != 0 or res > 10 * rtol:
        raise NumericalError(f"{where}: CG did not converge in {state['k']} iterations "
                             f"(relative residual {res:.2e} > {rtol:.0e})")
    k = max(state["k"], 1)
    rho = min(res ** (1.0 / k), 0.99)
    nu = float(np.linalg.norm(u))
    err = state["step"] * rho / (1.0 - rho) / nu if nu > 0 else 0.0
    return u, _cg_info(K, precond, state["k"], res, err, solve_s, rtol)


def _cg_info(K, precond, iterations, res, err, solve_s, rtol):
    label = getattr(precond, "label", None) or (
        f"two-level smoothed aggregation (coarse {precond.coarse_size})")
    return {"unknowns": int(K.shape[0]), "relative_residual": float(res),
            "solver": f"CG + {label}",
            "iterations": int(iterations), "rtol": float(rtol),
            "solver_error_estimate": float(err),
            "preconditioner_setup_s": float(precond.setup_s), "cg_solve_s": float(solve_s)}


def solve_spd(K, f, lattice: Lattice, width: int, *, where: str):
    """One CG solve with a fresh preconditioner (see :class:`TwoLevelPreconditioner`)."""
    K = sp.csr_matrix(K)
    precond = TwoLevelPreconditioner(K, lattice, width)
    return cg_solve(K, f, precond, where=where)


def solver_error_warnings(diagnostics, metrics) -> list[str]:
    """A warning when an iterative solve's error estimate is not below
    :data:`SOLVER_ERROR_FRACTION` of the run's ``rel_l2_error`` (the method error)."""
    est = diagnostics.get("solver_error_estimate") if hasattr(diagnostics, "get") else None
    method = metrics.get("rel_l2_error")
    if est is None or method is None or not np.isfinite(method) or method <= 0:
        return []
    if est <= SOLVER_ERROR_FRACTION * method:
        return []
    return [f"iterative solver error ~{est:.1e} is not below {SOLVER_ERROR_FRACTION:g} of the "
            f"method error rel_l2_error = {method:.1e}; use solver=direct"]


# -- the condensed state-based system, applied without forming it -----------------------
class JacobiPreconditioner:
    """x = r / diag(K): the preconditioner of :func:`solve_condensed`. On the 3D box's
    condensed LPS system (``none``) it was the fastest of scipy CG with Jacobi, with an
    incomplete LU of the bond block A_uu and with pyamg's smoothed aggregation of A_uu
    (rigid-body modes as near-null space), and of the multifrontal direct solve, at h =
    0.05, 1/24, 1/30 and 1/36 (benchmarks/refine3d.py; under load, so CPU seconds compare
    them: Jacobi 4.8 and 7.1 s of CPU for set-up and solve at h = 1/30 and 1/36, pyamg 5.4
    and 8.1 s, records refine3d-2026-11-28-cpu-none-1-30 and -1-36; the multifrontal
    solve 2.0 GB at 1/30 against CG's 0.9 GB, record
    refine3d-2026-11-28-levels-0.05-to-1-36). A PD operator's high-frequency
    spectrum is flat, and on these boxes (m = 3, at most 30 cells a side) the smooth modes
    CG must still resolve are few: 91, 109, 137 iterations at h = 0.05, 1/24, 1/30 (~1/h)
    cost less than pyamg's set-up and cycles (15-19 iterations). Its iterations grow as
    1/h and pyamg's do not, so the gap narrows (12 % at 1/36): on boxes larger than the
    report's, pyamg may become the better choice."""

    label = "Jacobi"

    def __init__(self, diag):
        t0 = time.perf_counter()
        diag = np.asarray(diag, dtype=float)
        if np.any(diag <= 0) or not np.all(np.isfinite(diag)):
            raise NumericalError("CG preconditioner: the stiffness has a non-positive diagonal "
                                 "entry, so it is not symmetric positive definite")
        self._inv = 1.0 / diag
        self.setup_s = time.perf_counter() - t0

    def operator(self):
        n = self._inv.size
        return spla.LinearOperator((n, n), matvec=lambda r: self._inv * r, dtype=float)


class CondensedOperator(spla.LinearOperator):
    """The condensed state-based stiffness K = A_uu + A_ut G of an augmented system
    ``A = [[A_uu, A_ut], [G, -I]]`` (its last ``scalars`` unknowns theta = G u), on the
    displacement unknowns left free by ``fixed``, applied as A_uu x + A_ut (G x): K couples
    nodes two horizons apart (at h = 1/30 on the 3D box it would hold ~55 M non-zeros, the
    augmented blocks 15 M), so it is never formed. ``rhs``: the augmented right-hand side
    (zero on the scalars' rows, as :class:`~pdverify.pd.problem.LinearSystem` has it)."""

    def __init__(self, A, rhs, scalars: int, fixed, values):
        A = sp.csr_matrix(A)
        n = A.shape[0] - int(scalars)
        keep = np.ones(n, dtype=bool)
        keep[np.asarray(fixed, dtype=int)] = False
        self.free = np.flatnonzero(keep)
        self.u0 = np.zeros(n)
        self.u0[np.asarray(fixed, dtype=int)] = values
        self._G_all = A[n:, :n].tocsr()
        A_uu, A_ut = A[:n, :n], A[:n, n:]
        rhs = np.asarray(rhs, dtype=float)
        if np.any(rhs[n:]):
            raise ValueError("the condensed operator needs a zero right-hand side on the "
                             "scalars' rows (theta = G u)")
        self.rhs = (rhs[:n] - A_uu @ self.u0 - A_ut @ (self._G_all @ self.u0))[self.free]
        self._A = A_uu[self.free][:, self.free].tocsr()
        self._At = A_ut[self.free].tocsr()
        self._G = self._G_all[:, self.free].tocsr()
        self.blocks_nnz = int(self._A.nnz + self._At.nnz + self._G.nnz)
        super().__init__(float, (self.free.size, self.free.size))

    def _matvec(self, x):
        x = np.asarray(x, dtype=float).ravel()
        return self._A @ x + self._At @ (self._G @ x)

    def diagonal(self) -> np.ndarray:
        """diag(K) exactly: diag(A_uu) + sum_k A_ut[i, k] G[k, i]."""
        return (self._A.diagonal()
                + np.asarray(self._At.multiply(self._G.T).sum(axis=1)).ravel())

    def finite(self) -> bool:
        return all(np.all(np.isfinite(M.data)) for M in (self._A, self._At, self._G))

    def asymmetry(self) -> float:
        """|b.Ka - a.Kb| / (|b| |Ka|) for two fixed random vectors: 0 for a symmetric K up
        to the products' round-off (measured 1e-18 to 4e-17 on the 3D box's LPS systems),
        2e-5 to 1e-4 for the energy method's (its factors are not symmetric per bond)."""
        rng = np.random.default_rng(0)
        a, b = rng.standard_normal(self.shape[0]), rng.standard_normal(self.shape[0])
        Ka = self @ a
        denom = float(np.linalg.norm(b) * np.linalg.norm(Ka))
        return float(abs(b @ Ka - a @ (self @ b)) / denom) if denom > 0 else 0.0

    def expand(self, u_free) -> np.ndarray:
        """Every unknown of the augmented system: u (the prescribed values in place), then
        theta = G u."""
        u = self.u0.copy()
        u[self.free] = u_free
        return np.r_[u, self._G_all @ u]


def solve_condensed(op: CondensedOperator, *, where: str):
    """CG with the Jacobi preconditioner on a symmetric :class:`CondensedOperator` (the
    caller has checked :meth:`~CondensedOperator.asymmetry`); returns the augmented
    solution (:meth:`~CondensedOperator.expand`) and CG's diagnostics
    (:func:`cg_solve`; a stall or a non-positive diagonal is a :class:`NumericalError`
    naming ``where``), with ``symmetry_defect`` and ``operator_nnz`` (the non-zeros of
    the blocks it applies)."""
    if not op.finite():
        raise NumericalError(f"{where}: the system has non-finite entries")
    try:
        precond = JacobiPreconditioner(op.diagonal())
    except NumericalError as exc:
        raise NumericalError(f"{where}: {exc}") from None
    u, info = cg_solve(op, op.rhs, precond, where=where, maxiter=CONDENSED_CG_MAXITER)
    info["solver"] += " on K = A_uu + A_ut G applied, not formed"
    info["operator_nnz"] = op.blocks_nnz
    return op.expand(u), info


#: CG's iteration limit on the condensed systems: Jacobi-CG took 91, 109, 137, 165
#: iterations on the 3D box at h = 0.05, 1/24, 1/30, 1/36 (~ 4.6 / h; record
#: refine3d-2026-11-28-levels-0.05-to-1-36), so 2,000 is reached only by a stall (or a box
#: ~ 400 cells long, far beyond any 2 GB run)
CONDENSED_CG_MAXITER = 2000
