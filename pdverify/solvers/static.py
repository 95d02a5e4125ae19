"""Direct sparse static solve with constraints by Lagrange multipliers (seed 000 Eq. 63)."""
from __future__ import annotations

import os
from concurrent import futures

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import NumericalError
from ..metrics import scaled_norm
from .ordering import nested_dissection

#: Above this 1-norm condition estimate the solution has lost (almost) every digit of
#: double precision (eps ~ 2.2e-16), so the run is refused as near-singular.
CONDITION_LIMIT = 1e14
#: Above this condition estimate a run stays ``ok`` but carries a warning: its solution is
#: trustworthy only to about kappa * eps >= 1e-6 relative, so smaller errors it reports
#: are round-off, not the method (e.g. bar1d-traction order 20 at 100 cells: 2.3e12).
WARN_CONDITION = 1e-6 / np.finfo(float).eps


#: SuperLU options for a symmetric positive definite K (no constraint rows): minimum
#: degree on A + A^T and diagonal pivots, which keep the symmetric fill; on a 2D
#: bond-based sheet (10k unknowns, 1.5 M non-zeros) 0.74 s against 1.87 s with the
#: default COLAMD column ordering (benchmarks/sheet_solvers.py).
SPD_OPTIONS = dict(permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options=dict(SymmetricMode=True))

# ``ordering`` of solve_constrained is SuperLU's permc_spec (COLAMD, MMD_AT_PLUS_A,
# MMD_ATA, NATURAL). Measured, not assumed (benchmarks/plate_solvers.py): minimum degree
# on A + A^T is ~3x faster than the default COLAMD on the seed-000 plate's Lagrange system,
# but ~1.6x slower on the seed-001 surface-node plate, so each scene states its choice.


def solve_constrained(K, f, B=None, c=None, *, where: str = "static solve", spd: bool = False,
                      ordering: str = "COLAMD"):
    """Solve [[K, B^T], [B, 0]] [u; lam] = [f; c] with a sparse LU factorisation.

    ``spd=True`` (only without constraints) declares K symmetric positive definite and
    factors it in SuperLU's symmetric mode (:data:`SPD_OPTIONS`); the residual and
    condition checks below guard the claim. Otherwise ``ordering`` is SuperLU's column
    ordering (``permc_spec``), with partial pivoting.

    Returns ``(u, lam, info)``; ``info`` holds the system size, the relative residual
    and a 1-norm condition estimate. Singular or near-singular systems, and non-finite
    solutions, raise :class:`NumericalError` naming ``where``.
    """
    K = sp.csr_matrix(K)
    n = K.shape[0]
    if B is not None and np.size(B):
        B = sp.csr_matrix(np.atleast_2d(B) if not sp.issparse(B) else B)
        c = np.atleast_1d(np.asarray(c, dtype=float))
        A = sp.bmat([[K, B.T], [B, None]], format="csc")
        rhs = np.concatenate([np.asarray(f, dtype=float), c])
    else:
        A = K.tocsc()
        rhs = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(A.data)) or not np.all(np.isfinite(rhs)):
        raise NumericalError(f"{where}: the system has non-finite entries")
    A_s, row_max, col_max = equilibrate(A, where)
    A_s = A_s.tocsc()
    lu = _factor(A_s, where, **(SPD_OPTIONS if spd and B is None else {"permc_spec": ordering}))
    sol = lu.solve(rhs / row_max) / col_max
    cond = _checked_condition(sol, A_s, lu, where)
    info = {"unknowns": int(A.shape[0]), "relative_residual": relative_residual(A, sol, rhs),
            "condition_estimate": float(cond),  # of the equilibrated system
            "solver": "sparse LU (SuperLU, " + ("symmetric mode)" if spd and B is None
                                                else f"{ordering} ordering)")}
    return sol[:n], sol[n:], info


#: SuperLU's diagonal pivot threshold under the nested-dissection ordering: a diagonal
#: entry is kept as pivot unless it is below 1e-3 of its column's largest, so the ordering
#: survives. Measured on the plane-strain plate's augmented system at h = 0.01 (a side
#: measurement): 1e-3 and 1e-2 give the same accuracy (solution error 7e-13, PARDISO's
#: 6e-13); 0.1 is 1.7x slower, and 1.0 (full partial pivoting) 9.8x slower with 3.3x the
#: fill.
ND_PIVOT_THRESHOLD = 1e-3
ND_OPTIONS = dict(permc_spec="NATURAL", diag_pivot_thresh=ND_PIVOT_THRESHOLD,
                  options=dict(SymmetricMode=True))

#: From this many unknowns :func:`solve_nested` factors in single precision (two halves in
#: parallel, see :class:`SplitLU`) and refines in double. Measured on the plane-strain
#: plate (augmented system; float64 LU against mixed, medians of 5): 2,025 unknowns
#: 0.065 s / 0.083 s; 5,040: 0.22 / 0.20; 7,800: 0.45 / 0.32; 19,680: 1.86 / 1.03;
#: 30,600: 3.2 / 1.55.
MIXED_FROM_UNKNOWNS = 5000
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
#: :class:`SplitLU` splits at the top separator only while its dense blocks (s^2 entries,
#: s^3 work) stay small against the halves: s^2 <= this many times the unknowns. The 2D
#: plates have s^2 / n ~ 28 at every h (m = 3; 921 of 30,600 unknowns at h = 0.01), the
#: 3D bodies 236 (h = 0.1) and 336 (h = 0.05), where the split gains nothing over one
#: float32 LU of the whole matrix (h = 0.05, quiet machine, the whole solve: 7.8-8.1 s
#: against 7.5-8.5 s; each half's factor with the separator 1.9 s and 3.3 s against 0.5 s
#: for a half alone: the separator's coupling, not the parallel factors, costs).
SPLIT_MAX_SEPARATOR = 100
#: LAPACK's mixed-precision dsgesv: at most 30 refinement steps, converged when
#: ||r||_inf <= ||x||_inf ||A||_inf eps sqrt(n); otherwise the double LU takes over.
REFINE_MAX_STEPS = 30
#: ... and a solution is refined on to this relative residual (that measure), the level of
#: a backward-stable double solve (|r| <= c eps |A| |x| with c ~ 1; the double LU reaches
#: 1.4 eps on the plate's mirror-node system at h = 0.0125): stopping at dsgesv's test
#: leaves up to sqrt(n) times more, visible in metrics at round-off level (7x on that
#: system's exact solution).
REFINE_STOP = 2 * np.finfo(float).eps


def solve_nested(A, rhs, coords, *, where: str = "static solve", mixed: bool | None = None):
    """Solve the square system A x = rhs by sparse LU under a geometric nested-dissection
    ordering (:func:`pdverify.solvers.ordering.nested_dissection`; ``coords``: one row
    per unknown). Same checks and diagnostics as :func:`solve_constrained`: equilibration,
    a 1-norm condition estimate, :class:`NumericalError` on (near-)singular systems.

    ``mixed`` (default: from :data:`MIXED_FROM_UNKNOWNS` unknowns): factor in single
    precision (:class:`SplitLU`) and refine in double as LAPACK's dsgesv does; a system
    whose single-precision factor fails or whose refinement does not converge (condition
    ~1/eps_single = 8e6 or worse) is solved by the double LU instead, with the reason in
    the diagnostics (``mixed_precision``). A random right-hand side is refined alongside
    (a near-singular system cannot converge on it) and gives the condition estimate
    (:func:`_probe_condition_estimate`). The diagnostics record the refinement's steps and
    relative residuals (``refinement_steps``, ``refinement_residuals``, the probe's final
    residual ``refinement_probe_residual``), the top separator's size and the separator
    rows pivoted into a half.
    """
    A = sp.csr_matrix(A)
    rhs = np.asarray(rhs, dtype=float)
    if not np.all(np.isfinite(A.data)) or not np.all(np.isfinite(rhs)):
        raise NumericalError(f"{where}: the system has non-finite entries")
    n = A.shape[0]
    A_s, row_max, col_max = equilibrate(A, where)
    perm, (n1, n2) = nested_dissection(A_s, coords, top_split=True)
    A_p = A_s[perm][:, perm].tocsr()
    b_p = (rhs / row_max)[perm]
    use_mixed = n >= MIXED_FROM_UNKNOWNS if mixed is None else mixed
    info: dict = {"unknowns": int(n)}
    y = None
    if use_mixed:
        y, cond, diag = _solve_mixed(A_p, b_p, n1, n2)
        info.update(diag)
    if y is None:
        lu = _factor(A_p.tocsc(), where, **ND_OPTIONS)
        y = lu.solve(b_p)
        cond = _checked_condition(y, A_p, lu, where)
        info["factor_entries"] = int(lu.L.nnz + lu.U.nnz)
        info["solver"] = "sparse LU (SuperLU, nested-dissection ordering)"
    else:
        _refuse_near_singular(cond, where)
    sol = np.empty_like(y)
    sol[perm] = y
    sol /= col_max
    info["relative_residual"] = relative_residual(A, sol, rhs)
    info["condition_estimate"] = float(cond)   # of the equilibrated system
    return sol, info


def _solve_mixed(A_p, b_p, n1: int, n2: int):
    """Single-precision LU of the equilibrated, permuted ``A_p`` (:class:`SplitLU`: the
    two halves of the top split in parallel, or, when SuperLU's pivoting crosses between
    the blocks, the whole matrix in one piece) and refinement in double: ``(y, condition
    estimate, diagnostics)``, or ``(None, None, diagnostics)`` with the reason in
    ``diagnostics['mixed_precision']`` when the double LU must take over."""
    note = ""
    separator = A_p.shape[0] - n1 - n2
    if n1 and n2 and separator ** 2 > SPLIT_MAX_SEPARATOR * A_p.shape[0]:
        n1 = n2 = 0
        note = f" (whole matrix: separator of {separator} unknowns too large to split at)"
    try:
        lu = SplitLU(A_p, n1, n2)
    except RuntimeError as exc:
        note = f" (whole matrix: {exc})"
        try:
            lu = SplitLU(A_p, 0, 0)
        except RuntimeError as exc:  # "Factor is exactly singular" in single precision
            return None, None, {"mixed_precision": f"not used: single-precision factor "
                                                   f"failed ({exc}); double LU"}
    # a second, random (normal) right-hand side is refined alongside: a consistent
    # right-hand side of a (near-)singular system can converge, a generic one cannot, and
    # its convergence is what makes the single-precision condition estimate trustworthy
    probe = np.random.default_rng(20211121).standard_normal(b_p.size)
    tol = np.sqrt(b_p.size) * np.finfo(float).eps        # the probe: to dsgesv's test
    Y, steps, history, ok = refine(A_p, np.column_stack([b_p, probe]), lu.solve,
                                   stop=[REFINE_STOP, tol])
    y = Y[:, 0]
    diag = {"refinement_steps": steps, "refinement_residuals": [h[0] for h in history],
            "refinement_probe_residual": history[-1][1]}
    if not ok:
        diag["mixed_precision"] = ("not used: refinement of the single-precision factor "
                                   "did not converge; double LU")
        return None, None, diag
    cond = _probe_condition_estimate(A_p, lu, probe, Y[:, 1])
    diag.update(mixed_precision="float32 LU" + note + ", refined in float64 (LAPACK "
                                "dsgesv's test)",
                factor_entries=lu.factor_entries, separator_unknowns=lu.separator,
                separator_rows_pivoted_into_halves=lu.crossed_pivots,
                solver="sparse LU (SuperLU in float32 + refinement, nested-dissection "
                       "ordering)")
    return y, cond, diag


def _probe_condition_estimate(A, lu, probe, solution) -> float:
    """kappa_1(A) ~ ||A||_1 ||A^-1||_1 by one step of Hager's estimator started from the
    refined probe (``solution`` = A^-1 ``probe``): ||A^-1 x||_1 for x = probe / ||probe||_1,
    then for the unit vector e_j at the largest entry of A^-T sign(A^-1 x), and Higham's
    alternating-sign vector (LAPACK dlacn2's last test), the largest of the three. Two
    solves with ``lu`` (one transposed; the two others in one call) against scipy's
    onenormest's four of two columns on the double path; on the plane-strain plate:
    2.005e5 against 2.009e5 (h = 0.01), 1.358e5 against 1.318e5 (h = 0.0125)."""
    n = A.shape[0]
    scale = float(np.abs(probe).sum())
    z = lu.solve(np.sign(solution), trans="T")
    rhs = np.zeros((n, 2))
    rhs[int(np.argmax(np.abs(z))), 0] = 1.0
    rhs[:, 1] = (-1.0) ** np.arange(n) * (1.0 + np.arange(n) / max(n - 1, 1))
    Y = lu.solve(rhs)
    inv_norm = max(float(np.abs(solution).sum()) / scale, float(np.abs(Y[:, 0]).sum()),
                   2.0 * float(np.abs(Y[:, 1]).sum()) / (3.0 * n))
    return rounded_estimate(float(abs(A).sum(axis=0).max()) * inv_norm)


def refine(A, b, solve, *, stop=None, max_steps: int = REFINE_MAX_STEPS):
    """Iterative refinement of A x = b with an approximate inverse ``solve`` (residuals in
    double), one or several right-hand sides (columns of ``b``): ``(x, steps, history,
    converged)``, ``history`` per step the relative residuals ||r||_inf / (||A||_inf
    ||x||_inf) of the iterates (a list per step for several columns).

    Converged, as LAPACK's dsgesv, when every column's residual reaches sqrt(n) eps. A
    column is refined until its residual is at most ``stop`` (per column; default
    :data:`REFINE_STOP`, a backward-stable double solve's level: stopping at dsgesv's test
    would leave up to sqrt(n) times that) or a step fails to halve it; each column's best
    iterate is returned. Unconverged: a non-finite residual, or a column stalled above
    dsgesv's test."""
    n = A.shape[0]
    B = np.asarray(b, dtype=float)
    B2 = B.reshape(n, -1)
    norm_a = float(abs(A).sum(axis=1).max())
    tol = np.sqrt(n) * np.finfo(float).eps
    stop = np.broadcast_to(REFINE_STOP if stop is None else np.asarray(stop, float),
                           B2.shape[1:])
    X = solve(B2)
    best, best_rel = X.copy(), np.full(B2.shape[1], np.inf)
    active = np.ones(B2.shape[1], bool)
    history: list = []
    prev = np.full(B2.shape[1], np.inf)
    step = 0
    while True:
        R = B2 - A @ X
        scale = norm_a * np.abs(X).max(axis=0)
        rnorm = np.abs(R).max(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(scale > 0, rnorm / scale, np.where(rnorm == 0, 0.0, np.inf))
        history.append(rel.tolist() if B.ndim == 2 else float(rel[0]))
        if not np.all(np.isfinite(rel[active])):
            return best.reshape(B.shape), step, history, False
        better = active & (rel < best_rel)
        best[:, better], best_rel[better] = X[:, better], rel[better]
        active &= (rel <= 0.5 * prev) & (rel > stop)
        prev = rel
        if not active.any() or step == max_steps:
            return best.reshape(B.shape), step, history, bool(np.all(best_rel <= tol))
        step += 1
        X[:, active] += solve(R[:, active])


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
            self.lus = [spla.splu(A.tocsc().astype(dtype), **ND_OPTIONS)]
            self.factor_entries = int(self.lus[0].L.nnz + self.lus[0].U.nnz)
            return
        s, g = self.separator, SEPARATOR_SHIFT
        C = A.tocsc()
        # M_i = the half's and the separator's rows and columns, with D_i in the corner
        corner = (0.5 * C[n1 + n2:, n1 + n2:] - g * sp.identity(s, format="csc")).tocsc()
        jobs = [_pool().submit(self._factor_half, C, np.r_[a:a + m, n1 + n2:n], corner, m,
                               dtype) for a, m in ((0, n1), (n1, n2))]
        futures.wait(jobs)      # both halves done (or failed) before anything is raised
        out = [job.result() for job in jobs]
        self.lus = [o[0] for o in out]
        self.factor_entries = int(sum(lu.L.nnz + lu.U.nnz for lu in self.lus))
        blocks = [self._separator_block(lu, L_ss, U_ss, m)
                  for (lu, L_ss, U_ss), m in zip(out, (n1, n2))]
        self.T = [T for T, _ in blocks]
        self.crossed_pivots = int(sum(c for _, c in blocks))
        # S by SuperLU (partial pivoting) in double, as LAPACK's threads stall when the
        # machine is shared (measured, 921 unknowns, one of two cores busy: scipy's
        # lu_factor 0.21 s, SuperLU 0.08 s, lu_factor with one BLAS thread 0.02 s)
        S = self.T[0] + self.T[1] - 2 * g * np.eye(s)
        self.S_lu = spla.splu(sp.csc_matrix(S), permc_spec="NATURAL")

    @staticmethod
    def _factor_half(C, idx, corner, m: int, dtype):
        """SuperLU of M_i (in a worker thread): ``(lu, L_ss, U_ss)``, the trailing blocks of
        its factors in double."""
        M = C[:, idx][idx, :]
        M = (M - sp.block_diag([sp.csc_matrix((m, m)), corner], format="csc")).astype(dtype)
        lu = spla.splu(M, **ND_OPTIONS)
        if np.any(lu.perm_c[:m] >= m):
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
        b = np.asarray(b, dtype=float)
        if trans not in ("N", "T"):
            raise ValueError(f"trans={trans!r}: 'N' or 'T'")
        # each column scaled by a power of two near its largest entry (exact), so that
        # single precision neither overflows nor underflows: refinement residuals are
        # ~1e-16 of the solution, the equilibrated right-hand side can be of any size
        big = np.abs(b).max(axis=0)
        scale = np.exp2(np.round(np.log2(np.where(big > 0, big, 1.0))))
        return self._solve(b / scale, trans) * scale

    def _solve(self, b, trans):
        if not self.separator:
            return self._half(0, b, trans)
        n1, n2 = self.sizes
        s = self.separator
        T = [t.T for t in self.T] if trans == "T" else self.T
        parts = (b[:n1], b[n1:n1 + n2])
        b_s = b[n1 + n2:]
        zero = np.zeros((s,) + b.shape[1:])
        # the halves' solves run in two threads (SuperLU releases the GIL)
        w = list(_pool().map(lambda i: self._half(i, np.concatenate([parts[i], zero]),
                                                  trans)[-s:], (0, 1)))
        x_s = self.S_lu.solve(b_s + _matvec(T[0], w[0]) + _matvec(T[1], w[1]), trans=trans)
        x = list(_pool().map(lambda i: self._half(i, np.concatenate(
            [parts[i], _matvec(T[i], x_s - w[i])]), trans)[:-s], (0, 1)))
        return np.concatenate([x[0], x[1], x_s])


def _matvec(M, v):
    """M @ v for the separator's dense blocks by numpy's own loops, one column of ``v`` at
    a time: BLAS would run them on its threads, which stall when the machine is shared
    (measured, one of two cores busy: a solve 0.15 s against 0.07 s)."""
    if v.ndim == 1:
        return np.einsum("ij,j->i", M, v)
    return np.stack([np.einsum("ij,j->i", M, c) for c in v.T], axis=1)


_POOL: dict = {}


def _pool():
    """Two worker threads for :class:`SplitLU` (one per half), made on first use in each
    process (a pool inherited through fork has no threads behind it)."""
    pid = os.getpid()
    if pid not in _POOL:
        _POOL.clear()
        _POOL[pid] = futures.ThreadPoolExecutor(max_workers=2, thread_name_prefix="splitlu")
    return _POOL[pid]


def _factor(A, where: str, **options):
    """SuperLU of the equilibrated ``A``; an exactly singular factor is a NumericalError."""
    try:
        return spla.splu(A, **options)
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise NumericalError(f"{where}: singular system of size {A.shape[0]} ({exc})") from None


def _checked_condition(sol, A, lu, where: str) -> float:
    """The condition estimate of the factored ``A``, after refusing a non-finite solution
    or a near-singular system (NumericalError naming ``where``)."""
    if not np.all(np.isfinite(sol)):
        raise NumericalError(f"{where}: solution has non-finite values (singular system)")
    cond = _condition_estimate(A, lu)
    _refuse_near_singular(cond, where)
    return cond


def _refuse_near_singular(cond: float, where: str) -> None:
    """NumericalError naming ``where`` when the condition estimate ``cond`` of the
    equilibrated system exceeds :data:`CONDITION_LIMIT`."""
    if cond > CONDITION_LIMIT:
        raise NumericalError(f"{where}: near-singular system (condition estimate {cond:.2e} "
                             f"> {CONDITION_LIMIT:.0e} after equilibration)")


def relative_residual(A, x, b) -> float:
    """||A x - b|| / max(||b||, max|A| ||x||), scale-free: x and b are divided by max |x|
    first (and the norms are :func:`~pdverify.metrics.scaled_norm`), so solutions of
    1e+-300 neither overflow nor underflow."""
    s = float(np.max(np.abs(x))) if np.size(x) else 0.0
    if s == 0.0 or not np.isfinite(s):
        return 0.0 if s == 0.0 and not np.any(b) else float("inf")
    xs, bs = x / s, np.asarray(b, dtype=float) / s
    denom = max(scaled_norm(bs), float(abs(A).max()) * scaled_norm(xs), 1e-300)
    return float(scaled_norm(A @ xs - bs) / denom)


def equilibrate(A, where: str):
    """Row then column max-scaling of a sparse matrix: ``(A_scaled, row_max, col_max)``.

    Constraint rows (dimensionless Dirichlet rows, force-flux rows) and stiffness rows
    differ by many orders of magnitude, which would inflate a condition estimate without
    any loss of accuracy. An empty row or column is a singular system (NumericalError).
    Solve A x = b as A_scaled y = b / row_max, x = y / col_max.
    """
    A = sp.csr_matrix(A)
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    counts = np.diff(A.indptr)
    row_max = np.zeros(A.shape[0])
    filled = counts > 0
    row_max[filled] = np.maximum.reduceat(np.abs(A.data), A.indptr[:-1][filled])
    if np.any(row_max == 0):
        raise NumericalError(f"{where}: singular system (equation {int(np.argmin(row_max))} "
                             "has no entries)")
    # the products (1 / row_max) a_ij and then (1 / col_max) of those, as diagonal
    # scalings by sparse products would form them, without the products' copies
    data = A.data * np.repeat(1.0 / row_max, counts)
    col_max = np.zeros(A.shape[1])
    np.maximum.at(col_max, A.indices, np.abs(data))
    if np.any(col_max == 0):
        raise NumericalError(f"{where}: singular system (unknown {int(np.argmin(col_max))} "
                             "appears in no equation)")
    data *= (1.0 / col_max)[A.indices]
    A_s = sp.csr_matrix((data, A.indices.copy(), A.indptr.copy()), shape=A.shape)
    A_s.eliminate_zeros()       # as the products do: stored zeros are no structure
    return A_s, row_max, col_max


#: significant digits a condition estimate keeps. The estimators' NumPy sums can round
#: differently with the arrays' memory alignment (the same system gave 367.962170351635
#: and 367.9621703516349 in two processes), and an estimate good to a factor of a few
#: has no last bit to keep: rounded, it is the same in every process (a 1-ulp spread
#: straddles a 6-digit rounding boundary with probability ~1e-10).
ESTIMATE_DIGITS = 6


def rounded_estimate(value: float) -> float:
    return float(f"{value:.{ESTIMATE_DIGITS}g}")


def _condition_estimate(A, lu) -> float:
    """kappa_1(A) ~ ||A||_1 ||A^-1||_1: ||A||_1 exactly, ||A^-1||_1 by Higham's estimator
    on the LU solves. The estimator draws random +-1 start vectors from NumPy's global
    generator; it is seeded here (and the caller's state restored) so that the same system
    always gets the same estimate, and hence the same accept/refuse verdict."""
    n = A.shape[0]
    if n <= 2:
        return rounded_estimate(np.linalg.cond(A.toarray(), 1))
    inv = spla.LinearOperator(A.shape, matvec=lu.solve, rmatvec=lambda v: lu.solve(v, trans="T"),
                              dtype=float)
    norm_a = float(abs(A).sum(axis=0).max())
    state = np.random.get_state()
    try:
        np.random.seed(20211121)
        return rounded_estimate(norm_a * float(spla.onenormest(inv)))
    finally:
        np.random.set_state(state)
