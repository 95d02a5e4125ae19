"""Sparse LU under a geometric nested-dissection ordering
(:func:`pdverify.solvers.ordering.nested_dissection`), in double precision or, from
:data:`~pdverify.solvers.policy.MIXED_FROM_UNKNOWNS` unknowns, as a single-precision
:class:`SplitLU` (the two halves of the top split factored in parallel) refined in double
(:mod:`pdverify.solvers.mixed`)."""
from __future__ import annotations

import itertools
import os
import traceback
import weakref
from concurrent import futures

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import NumericalError
from . import policy
from .checks import checked_condition, equilibrate, refuse_near_singular, relative_residual
from .lu import factor
from .frontal import FrontalLU
from .mixed import refine_with_probe, scaled_solve
from .ordering import nested_dissection

#: SuperLU's diagonal pivot threshold under the nested-dissection ordering: a diagonal
#: entry is kept as pivot unless it is below 1e-3 of its column's largest, so the ordering
#: survives. Measured on the plane-strain plate's augmented system at h = 0.01 (a side
#: measurement): 1e-3 and 1e-2 give the same accuracy (solution error 7e-13, PARDISO's
#: 6e-13); 0.1 is 1.7x slower, and 1.0 (full partial pivoting) 9.8x slower with 3.3x the
#: fill.
ND_PIVOT_THRESHOLD = 1e-3
ND_OPTIONS = dict(permc_spec="NATURAL", diag_pivot_thresh=ND_PIVOT_THRESHOLD,
                  options=dict(SymmetricMode=True))

#: ... and the single-precision factor's (:class:`SplitLU` in float32): 0.1 (issue 32),
#: which bounds the element growth that eps_single multiplies. Measured
#: (``benchmarks/mixed_precision.py --threshold``; one process each, the machine shared)
#: on the 3D boxes' systems whose plain refinement stalls at 1e-3: at 0.1 it converges,
#: with 2-4% more fill: body3d-manufactured's order-2 Taylor system (12,880 unknowns,
#: condition 1.2e7) 7 steps, 3 s, against GMRES-IR's 55-60 iterations per correction
#: (~40 s with the estimator); body3d-traction's order-1 7 steps, 1.2 s, against 18 s;
#: body3d-manufactured's order-3 surface-node system 4 steps, 1.7 s, against 8.9 s. Over
#: the report's float32 runs (each run at both thresholds alternating, a busy machine):
#: the five 3D runs that took GMRES-IR at 1e-3 took 58.4 -> 20.7 s (Taylor order 2),
#: 28.7 -> 19.7, 51.8 -> 37.9, 57.0 -> 21.6, 25.9 -> 19.2 s; a 3D run whose plain
#: refinement converged at 1e-3 pays 14 % more fill (surface nodes order 1: 44.9 -> 51.1
#: M entries, CPU 15.5 -> 17.5 s), the 57 float32 runs of the 2D plates and sheets 74.4
#: against 74.5 s; every metric the same to 1e-9 relative or round-off. At 1e-3
#: (ND_PIVOT_THRESHOLD, kept for the double factor) the symmetric 576-unknown operator
#: with 200 small eigenvalues of tests/pdverify/test_split_lu.py (kappa 1e8) converges by
#: GMRES-IR, at 0.1 by neither refinement (the double LU then solves it).
FLOAT32_PIVOT_THRESHOLD = 0.1


def _options(dtype):
    """SuperLU's options of a :class:`SplitLU` factor of this ``dtype``."""
    if np.dtype(dtype) == np.float32:
        return {**ND_OPTIONS, "diag_pivot_thresh": FLOAT32_PIVOT_THRESHOLD}
    return ND_OPTIONS


#: Shift of the separator blocks of the two halves' matrices (see :class:`SplitLU`; the
#: factorisation is exact for any shift, it only sets how much float32 round-off the
#: separator's Schur complement picks up). Measured on the plate at h = 0.01 (entries
#: <= 1 after equilibration; condition of the halves' Schur complements / refinement
#: steps to LAPACK's test): 0 -> 8.5e4, stalls at 1e-5 relative residual; 1 -> 110, 3;
#: 2 -> 19, 3; 4 -> 5.5, 3; 8 -> 2.4, 3.
SEPARATOR_SHIFT = 2.0
#: At most this many separator rows may be pivoted into a half by SuperLU's threshold
#: pivoting (each costs two solves and a rank-one term in :class:`SplitLU`); beyond it the
#: whole matrix is factored in one piece. The plate at h = 0.0125: 1 of 741.
MAX_CROSSED_PIVOTS = 32

#: The whole-matrix float32 factor (separator too large to split at) is the multifrontal
#: :class:`~pdverify.solvers.frontal.FrontalLU` (dense BLAS-3 fronts), with SuperLU's as
#: the fallback when it fails (issue 32). Measured (``benchmarks/frontal.py``: a fresh
#: process each, one BLAS thread, alternating, medians of 3; SuperLU -> FrontalLU): the
#: order-1 Taylor system of body3d-traction (12,840 unknowns) factor 27.7 -> 6.3 s,
#: 72.0 -> 75.7 M entries, plain refinement 6 -> 5 steps, 2.1 -> 1.5 s, peak 678 -> 616
#: MB; body3d-manufactured's order-2 Taylor system (12,880) 14.3 -> 3.3 s, 7 -> 8 steps,
#: 1.2 -> 1.2 s, 679 -> 629 MB; its order-3 surface-node system (10,700) 11.7 -> 4.7 s,
#: 61.6 -> 77.6 M entries, 4 -> 5 steps, 784 -> 921 MB; body3d-traction's uncorrected
#: system (7,880) 5.3 -> 3.0 s, 21.6 -> 40.7 M entries, 334 -> 486 MB. The refined
#: displacements differ from SuperLU's path by 4e-13, 8e-14, 1.5e-12 and 5e-14 of their
#: largest entry (condition 3e7, 1e7, 9e6, 6e4: round-off; on the third the double LU and
#: PARDISO differ by 1.3e-12). The report's runs on this path (body3d-traction,
#: body3d-manufactured, plate2d-plane-strain): every metric the same to 1e-9 relative;
#: body3d-traction's ten runs 155-188 s -> 88-103 s in all, body3d-manufactured's 21 on
#: this path 159-165 s -> 104-148 s (two report passes each, alternating, the machine
#: shared and busy).
FRONTAL_FACTOR = True


class NestedFactor:
    """Sparse LU of the square ``A`` under a geometric nested-dissection ordering
    (:func:`pdverify.solvers.ordering.nested_dissection`; ``coords``: one row per
    unknown), after the equilibration of :func:`~pdverify.solvers.checks.equilibrate`.

    ``mixed`` (default: :func:`~pdverify.solvers.policy.mixed_precision`): factor in single
    precision (:class:`SplitLU`, or :class:`~pdverify.solvers.frontal.FrontalLU` when the
    separator is too large to split at) and refine each solve in double as LAPACK's dsgesv
    does, or, when that stalls (condition ~1/eps_single = 1.7e7), by GMRES preconditioned
    with the same factor (:mod:`~pdverify.solvers.mixed`); a system whose single-precision
    factor fails or that neither refinement solves is factored in double instead (once),
    with the reason in the diagnostics (``mixed_precision``). A random right-hand side is
    refined alongside (a near-singular system cannot converge on it) and gives the
    condition estimate (:func:`~pdverify.solvers.mixed.probe_condition_estimate`).
    :meth:`solve` checks each solution (:class:`NumericalError` naming ``where``) and
    leaves its diagnostics in :attr:`info`: the refinement's steps and relative residuals
    (``refinement_steps``, ``refinement_residuals``, the probe's final residual
    ``refinement_probe_residual``), the top separator's size and the separator rows
    pivoted into a half."""

    def __init__(self, A, coords, *, where: str = "static solve", mixed: bool | None = None):
        A = sp.csr_matrix(A)
        if not np.all(np.isfinite(A.data)):
            raise NumericalError(f"{where}: the system has non-finite entries")
        self.A, self.where = A, where
        n = A.shape[0]
        self.A_p, self.row_max, self.perm, (n1, n2), self.col_max, tree = ordered_matrix(
            A, coords, where)
        self.mixed = policy.mixed_precision(n) if mixed is None else mixed
        self.single = self.single_note = self.single_failed = None
        if self.mixed:
            try:
                self.single, self.single_note = single_precision_factor(self.A_p, n1, n2, tree)
            except RuntimeError as exc:  # "Factor is exactly singular" in single precision
                self.single_failed = (f"not used: single-precision factor failed ({exc}); "
                                      "double LU")
        self.double = None
        self.info: dict = {}

    def _double(self):
        """SuperLU's double factor (made once, when first needed)."""
        if self.double is None:
            # SuperLU takes CSC: the CSR copy goes before the factor is made (memory)
            self.A_p = self.A_p.tocsc()
            self.double = factor(self.A_p, self.where, **ND_OPTIONS)
        return self.double

    def solve(self, rhs) -> np.ndarray:
        rhs = np.asarray(rhs, dtype=float)
        if not np.all(np.isfinite(rhs)):
            raise NumericalError(f"{self.where}: the system has non-finite entries")
        b_p = (rhs / self.row_max)[self.perm]
        info: dict = {"unknowns": int(self.A.shape[0])}
        y = None
        if self.single is not None:
            y, cond, diag = _refined(self.A_p, b_p, self.single, self.single_note)
            info.update(diag)
        elif self.single_failed is not None:
            info["mixed_precision"] = self.single_failed
        if y is None:
            lu = self._double()
            y = lu.solve(b_p)
            cond = checked_condition(y, self.A_p, lu, self.where)
            info["factor_entries"] = int(lu.nnz)
            info["solver"] = "sparse LU (SuperLU, nested-dissection ordering)"
        else:
            refuse_near_singular(cond, self.where)
        sol = np.empty_like(y)
        sol[self.perm] = y
        sol /= self.col_max
        info["relative_residual"] = relative_residual(self.A, sol, rhs)
        info["condition_estimate"] = float(cond)   # of the equilibrated system
        self.info = info
        return sol


def solve_nested(A, rhs, coords, *, where: str = "static solve", mixed: bool | None = None):
    """Solve the square system A x = rhs by :class:`NestedFactor` (its docstring: the
    ordering, ``mixed``, the checks and the diagnostics). Returns ``(x, info)``."""
    rhs = np.asarray(rhs, dtype=float)
    if not np.all(np.isfinite(sp.csr_matrix(A).data)) or not np.all(np.isfinite(rhs)):
        raise NumericalError(f"{where}: the system has non-finite entries")
    lu = NestedFactor(A, coords, where=where, mixed=mixed)
    x = lu.solve(rhs)
    return x, lu.info


def ordered_matrix(A, coords, where: str):
    """``(A_p, row_max, perm, (n1, n2), col_max, tree)``: ``A`` equilibrated
    (:func:`~pdverify.solvers.checks.equilibrate`) and permuted to the geometric
    nested-dissection order (``perm``; the top split's halves ``n1``, ``n2``; the
    ordering's separator tree); the solution of ``A x = rhs`` is ``x[perm] = y / col_max``
    for ``A_p y = (rhs / row_max)[perm]``."""
    A_s, row_max, col_max = equilibrate(A, where)
    perm, halves, tree = nested_dissection(A_s, coords, top_split=True, tree=True)
    A_p = A_s[perm][:, perm].tocsr()
    del A_s     # memory: one copy of the system fewer while it is factored (issue 32)
    return A_p, row_max, perm, halves, col_max, tree


def ordered_system(A, rhs, coords, where: str, *, tree: bool = False):
    """:func:`ordered_matrix` with the right-hand side permuted alongside:
    ``(A_p, b_p, perm, (n1, n2), col_max)`` (``tree=True``: and the separator tree)."""
    A_p, row_max, perm, halves, col_max, sep_tree = ordered_matrix(A, coords, where)
    out = (A_p, (np.asarray(rhs, dtype=float) / row_max)[perm], perm, halves, col_max)
    return out + ((sep_tree,) if tree else ())


def single_precision_factor(A_p, n1: int, n2: int, tree=None):
    """``(lu, note)``: the :class:`SplitLU` of ``A_p`` on its top split, or of the whole
    matrix (``note`` says why) when the separator is too large to split at
    (:func:`~pdverify.solvers.policy.split_too_large`; given the ordering's separator
    ``tree``, by :class:`~pdverify.solvers.frontal.FrontalLU`, :data:`FRONTAL_FACTOR`) or
    SuperLU's pivoting crosses between the blocks. Raises RuntimeError when the whole
    matrix's float32 factor fails too."""
    note = ""
    separator = A_p.shape[0] - n1 - n2
    if n1 and n2 and policy.split_too_large(separator, A_p.shape[0]):
        n1 = n2 = 0
        note = f" (whole matrix: separator of {separator} unknowns too large to split at)"
        if FRONTAL_FACTOR and tree is not None:
            try:
                return FrontalLU(A_p, tree), note
            except RuntimeError as exc:
                note += f" (SuperLU: the multifrontal factor failed: {exc})"
    try:
        return SplitLU(A_p, n1, n2), note
    except RuntimeError as exc:
        return SplitLU(A_p, 0, 0), f" (whole matrix: {exc})"


def _refined(A_p, b_p, lu, note: str):
    """Refinement in double (:func:`~pdverify.solvers.mixed.refine_with_probe`) of the
    equilibrated, permuted ``A_p y = b_p`` with the single-precision factor ``lu``
    (:func:`single_precision_factor`, whose ``note`` says how it was made):
    ``(y, condition estimate, diagnostics)``, or ``(None, None, diagnostics)`` with the
    reason in ``diagnostics['mixed_precision']`` when the double LU must take over."""
    y, cond, diag = refine_with_probe(A_p, b_p, lu)
    if y is None:
        return None, None, diag
    gmres = diag.get("refinement") == "GMRES-IR"
    diag.update(mixed_precision="float32 LU" + note + (
                    ", refined in float64 by GMRES-IR (plain refinement stalled)" if gmres
                    else ", refined in float64 (LAPACK dsgesv's test)"),
                factor_entries=lu.factor_entries, separator_unknowns=lu.separator,
                separator_rows_pivoted_into_halves=lu.crossed_pivots,
                solver=f"sparse LU ({getattr(lu, 'kind', 'SuperLU')} in float32 + "
                       + ("GMRES-IR" if gmres else
                                                             "refinement")
                       + ", nested-dissection ordering)")
    return y, cond, diag


class SplitLU:
    """A single-precision LU of ``A = [[A11, 0, A1s], [0, A22, A2s], [As1, As2, Ass]]`` (the
    top split of a nested-dissection ordering) whose two halves are factored in parallel.

    Each half is factored by SuperLU with the separator last, ``M_i = [[Aii, Ais],
    [Asi, D_i]]``, ``D_i = Ass / 2 + g I`` (g = :data:`SEPARATOR_SHIFT`); the trailing block
    of its LU is ``T_i = D_i - Asi Aii^-1 Ais``, read off the factor and multiplied out in
    double. The Schur complement of the separator is then ``S = Ass - sum (D_i - T_i)
    = T_1 + T_2 - 2 g I`` (SuperLU in double). A solve: ``M_i [z_i; w_i] = [b_i; 0]`` gives
    ``Asi Aii^-1 b_i = -T_i w_i``, so ``x_s = S^-1 (b_s + T_1 w_1 + T_2 w_2)``, and then
    ``M_i [x_i; x_s] = [b_i; T_i (x_s - w_i)]``. Should SuperLU's threshold pivoting take
    a separator row as pivot of a half's column, the trailing block is the Schur complement
    for the rows so pivoted; T_i follows from it by a rank-c correction (c such rows, at
    most :data:`MAX_CROSSED_PIVOTS`; two solves each).

    Without a split (``n1 = 0`` or ``n2 = 0``) it is one SuperLU factor of the whole
    matrix. ``solve(B, trans="N")`` takes one or several right-hand sides; ``trans="T"``
    solves with A^T (SuperLU's convention). Raises RuntimeError (from SuperLU, also for a
    singular S, or for more crossed pivots).
    """

    def __init__(self, A, n1: int, n2: int, dtype=np.float32):
        A = sp.csr_matrix(A)
        n = A.shape[0]
        self.dtype = dtype
        self.sizes = (n1, n2)
        self.separator = n - n1 - n2 if n1 and n2 else 0
        self.crossed_pivots = 0
        if not self.separator:
            self.lus = [spla.splu(A.tocsc().astype(dtype), **_options(dtype))]
            self.factor_entries = int(self.lus[0].nnz)
            return
        s, g = self.separator, SEPARATOR_SHIFT
        C = A.tocsc()
        # M_i = the half's and the separator's rows and columns, with D_i in the corner
        corner = (0.5 * C[n1 + n2:, n1 + n2:] - g * sp.identity(s, format="csc")).tocsc()
        pools = _pools()
        keys = [(k, next(_KEYS)) for k in (0, 1)]
        jobs = [pools[k].submit(self._factor_half, C, np.r_[a:a + m, n1 + n2:n], corner, m,
                                dtype, key)
                for (k, key), (a, m) in zip(keys, ((0, n1), (n1, n2)))]
        futures.wait(jobs)      # both halves done (or failed) before anything is raised
        failed = next((job.exception() for job in jobs if job.exception() is not None), None)
        if failed is not None:
            del jobs            # their results hold a half factored beside the failed one,
            _release(keys)      # which its thread then drops
            raise failed
        out = [job.result() for job in jobs]
        del jobs
        try:
            self.lus = [o[0] for o in out]
            self.factor_entries = int(sum(lu.nnz for lu in self.lus))
            blocks = [self._separator_block(lu, L_ss, U_ss, m)
                      for (lu, L_ss, U_ss), m in zip(out, (n1, n2))]
            self.T = [T for T, _ in blocks]
            self.crossed_pivots = int(sum(c for _, c in blocks))
            # S by SuperLU (partial pivoting) in double, as LAPACK's threads stall when
            # the machine is shared (measured, 921 unknowns, one of two cores busy:
            # scipy's lu_factor 0.21 s, SuperLU 0.08 s, lu_factor with one BLAS thread
            # 0.02 s)
            S = self.T[0] + self.T[1] - 2 * g * np.eye(s)
            self.S_lu = spla.splu(sp.csc_matrix(S), permc_spec="NATURAL")
        except BaseException as exc:
            # the finished frames of the traceback (a _separator_block's) hold a factor
            traceback.clear_frames(exc.__traceback__)
            out = self.lus = None
            _release(keys)
            raise
        # held by their threads (_HELD) until this object goes (_release)
        weakref.finalize(self, _release, keys).atexit = False

    @staticmethod
    def _factor_half(C, idx, corner, m: int, dtype, key):
        """SuperLU of M_i (in its half's thread, which holds it in :data:`_HELD` under
        ``key``): ``(lu, L_ss, U_ss)``, the trailing blocks of its factors in double."""
        M = C[:, idx][idx, :]
        M = (M - sp.block_diag([sp.csc_matrix((m, m)), corner], format="csc")).astype(dtype)
        lu = _HELD[key] = spla.splu(M, **_options(dtype))
        if np.any(lu.perm_c[:m] >= m):
            del _HELD[key], lu          # freed here, not by the traceback's frame
            raise RuntimeError("SuperLU's column order mixed a half with the separator")
        L, U = lu.L, lu.U
        return lu, L[m:, m:].toarray().astype(float), U[m:, m:].toarray().astype(float)

    @staticmethod
    def _separator_block(lu, L_ss, U_ss, m: int):
        """T_i of a factored M_i: ``(T_i, separator rows pivoted into the half)``. The
        products run here, after both halves are factored: BLAS's threads would compete
        with the other half's factorisation."""
        s = L_ss.shape[0]
        pr, pc = lu.perm_r, lu.perm_c
        # P_r M P_c = L U: the trailing L_ss U_ss is the Schur complement T' of M with
        # respect to its rows pivoted into the leading positions and the half's columns,
        # rows the rows pivoted to the trailing positions R', columns the separator's
        trailing = L_ss @ U_ss
        rows = np.argsort(pr)[m:]           # R', in trailing order
        cols = np.argsort(pc)[m:] - m       # separator unknowns, in trailing order
        moved_in = np.setdiff1d(np.arange(m, m + s), rows)   # separator rows now leading
        if moved_in.size > MAX_CROSSED_PIVOTS:
            raise RuntimeError(f"pivoting moved {moved_in.size} separator rows into a half")
        moved_out = np.sort(rows[rows < m])                  # half rows now trailing
        # B: T' with each row placed at its separator unknown; a half row j in R' takes the
        # place of the separator row k it is paired with (moved_out[i] with moved_in[i])
        slot = rows - m
        slot[rows < m] = moved_in[np.searchsorted(moved_out, rows[rows < m])] - m
        B = np.empty((s, s))
        B[np.ix_(slot, cols)] = trailing
        if not moved_in.size:
            return B, 0
        # T_i^-1 = (M^-1)[S, S], whose columns at the pairs' slots are (M^-1 e_k)[S] where
        # T'^-1 = (M^-1)[S, R'] has (M^-1 e_j)[S]: a rank-c change of B^-1, inverted by
        # the Woodbury identity
        E = np.zeros((m + s, 2 * moved_in.size), dtype=lu.L.dtype)
        E[moved_in, np.arange(moved_in.size)] = 1.0
        E[moved_out, moved_in.size + np.arange(moved_in.size)] = 1.0
        Z = lu.solve(E)[m:].astype(float)
        W = Z[:, :moved_in.size] - Z[:, moved_in.size:]
        BW = B @ W
        K = moved_in - m
        core = np.eye(moved_in.size) + BW[K]
        return B - BW @ np.linalg.solve(core, B[K]), moved_in.size

    def _half(self, i, rhs, trans):
        return self.lus[i].solve(np.asarray(rhs, dtype=self.dtype), trans=trans).astype(float)

    def solve(self, b, trans: str = "N"):
        return scaled_solve(b, trans, self._solve)

    def _solve(self, b, trans):
        if not self.separator:
            return self._half(0, b, trans)
        n1, n2 = self.sizes
        s = self.separator
        T = [t.T for t in self.T] if trans == "T" else self.T
        parts = (b[:n1], b[n1:n1 + n2])
        b_s = b[n1 + n2:]
        zero = np.zeros((s,) + b.shape[1:])
        # the halves' solves run in their two threads (SuperLU releases the GIL)
        pools = _pools()
        w = [job.result() for job in [
            pools[i].submit(lambda i: self._half(i, np.concatenate([parts[i], zero]),
                                                 trans)[-s:], i) for i in (0, 1)]]
        x_s = self.S_lu.solve(b_s + _matvec(T[0], w[0]) + _matvec(T[1], w[1]), trans=trans)
        x = [job.result() for job in [
            pools[i].submit(lambda i: self._half(i, np.concatenate(
                [parts[i], _matvec(T[i], x_s - w[i])]), trans)[:-s], i) for i in (0, 1)]]
        return np.concatenate([x[0], x[1], x_s])


def _matvec(M, v):
    """M @ v for the separator's dense blocks by numpy's own loops, one column of ``v`` at
    a time: BLAS would run them on its threads, which stall when the machine is shared
    (measured, one of two cores busy: a solve 0.15 s against 0.07 s)."""
    if v.ndim == 1:
        return np.einsum("ij,j->i", M, v)
    return np.stack([np.einsum("ij,j->i", M, c) for c in v.T], axis=1)


_POOLS: dict = {}
#: The halves' SuperLU factors of the live :class:`SplitLU` objects, by key, each held
#: here so that its last reference is dropped by the thread that made it
#: (:func:`_release`)
_HELD: dict = {}
_KEYS = itertools.count()


def _pools():
    """One worker thread per half of :class:`SplitLU` (made on first use in each process:
    a pool inherited through fork has no threads behind it). A half is factored, solved
    with and freed in its own thread: scipy's SuperLU frees a factor's memory only in the
    thread that made it (its allocations are tracked per thread), so a factor made in a
    pool thread and dropped in another thread was never freed (scipy issue 15921): 0.6 GB
    of address space and the factor's pages, ~60 MB resident, a sheet2d-tension run, each
    run of a process adding its own (the test workers grew from 0.3 to 0.95 GB resident
    over the fast tier)."""
    pid = os.getpid()
    if pid not in _POOLS:
        _POOLS.clear()
        _HELD.clear()           # a parent's factors: its threads are not here
        _POOLS[pid] = tuple(futures.ThreadPoolExecutor(max_workers=1,
                                                       thread_name_prefix=f"splitlu{k}")
                            for k in (0, 1))
    return _POOLS[pid]


def _release(keys) -> None:
    """Drop the factors held under ``keys`` (``(half, key)`` pairs), each in its half's
    thread, where SuperLU frees it (:func:`_pools`); a key not held is skipped."""
    if _POOLS.get(os.getpid()) is None:
        return
    pools = _pools()
    for k, key in keys:
        pools[k].submit(_drop, key)


def _drop(key) -> None:
    """(in a half's thread) Forget the factor held under ``key``; returns nothing, so that
    no future holds it."""
    _HELD.pop(key, None)
