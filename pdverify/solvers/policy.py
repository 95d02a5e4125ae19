"""Which solver a run uses: every threshold of the choice in one place.

The front door (:func:`pdverify.solvers.front.solve`, :func:`~pdverify.solvers.front.
solve_with_dirichlet`, :func:`~pdverify.solvers.front.factor`) asks this module which
implementation to call; the implementations (``lu``: sparse LU with constraints;
``dense``: LAPACK LU; ``nested``: nested dissection and its single-precision factor;
``mixed``: single-precision factor refined in double; ``iterative``: CG with the lattice
preconditioner; ``modal``: eigenvalues) read their crossovers from here at call time, so
a test can move one by patching this module. Nothing here solves, and this module imports
no other module of the package.
"""
from __future__ import annotations

import numpy as np

# -- the solvers a run can ask for ----------------------------------------------------

#: every solver name :func:`pdverify.solvers.front.solve_with_dirichlet` knows
SOLVERS = ("auto", "direct", "cg", "nested-dissection")
#: the choices of a scene whose system is SPD on a lattice (bond-based): no coordinates
#: are passed, so nested dissection is not among them
SPD_LATTICE_SOLVERS = ("auto", "direct", "cg")
#: the solvers a static state-based problem can ask for
STATIC_SOLVERS = ("auto", "direct", "nested-dissection")

# -- refusing a system ----------------------------------------------------------------

#: Above this 1-norm condition estimate the solution has lost (almost) every digit of
#: double precision (eps ~ 2.2e-16), so the run is refused as near-singular.
CONDITION_LIMIT = 1e14
#: Above this condition estimate a run stays ``ok`` but carries a warning: its solution is
#: trustworthy only to about kappa * eps >= 1e-6 relative, so smaller errors it reports
#: are round-off, not the method (e.g. bar1d-traction order 20 at 100 cells: 2.3e12).
WARN_CONDITION = 1e-6 / np.finfo(float).eps

# -- direct: dense or sparse LU -------------------------------------------------------

#: Above this fill (nnz / n^2) a dense LAPACK LU beats SuperLU: in 3D state-based PD every
#: node couples to all nodes within two horizons, i.e. to a large part of a small body.
DENSE_FILL = 0.1
#: ... and below this many unknowns SuperLU is used whatever the fill
DENSE_MIN_UNKNOWNS = 2000


def dense_lu(n, nnz) -> bool:
    """Whether ``direct`` factors an n x n matrix with ``nnz`` stored entries by the dense
    LAPACK LU (:data:`DENSE_MIN_UNKNOWNS`, :data:`DENSE_FILL`) rather than SuperLU."""
    return n >= DENSE_MIN_UNKNOWNS and nnz >= DENSE_FILL * n * n


# -- auto on SPD lattices: CG or direct -----------------------------------------------

#: ``solver="auto"`` picks CG (SPD systems with a lattice) from this many free unknowns:
#: below it the direct solve takes about a second (1.1 s at the sheets' default 10,150
#: unknowns: record sheet_solvers-2026-11-28-repeat-3) and is exact to round-off, and the
#: report's default-size runs keep their direct solutions bit for bit.
AUTO_ITERATIVE_UNKNOWNS = 20000


def lattice_uses_cg(requested: str, iterative_ok: bool, free_unknowns: int) -> bool:
    """Whether a linear solve of an SPD lattice system runs CG: asked for, or ``auto`` on
    a system CG applies to (``iterative_ok``) from :data:`AUTO_ITERATIVE_UNKNOWNS` free
    unknowns."""
    return requested == "cg" or (requested == "auto" and iterative_ok
                                 and free_unknowns >= AUTO_ITERATIVE_UNKNOWNS)


#: ... and below it, on a 2D lattice, nested dissection (the lattice's coordinates give
#: the ordering) from :data:`ND_FROM_UNKNOWNS` free unknowns unless the dense LU applies
#: (:func:`dense_lu`): sheet2d-clamped's full-report runs 92 -> 73 s, the metrics equal to
#: 6e-12 relative (record lattice_nd-2026-11-26-full-report).
LATTICE_ND_DIMS = (2,)


def lattice_uses_nd(requested: str, use_cg: bool, dim: int, free_unknowns: int,
                    nnz: int) -> bool:
    """Whether ``auto`` solves an SPD lattice system (not by CG) under nested dissection."""
    return (requested == "auto" and not use_cg and dim in LATTICE_ND_DIMS
            and free_unknowns >= ND_FROM_UNKNOWNS and not dense_lu(free_unknowns, nnz))


def lattice_note(use_cg: bool, free_unknowns: int, nd: bool = False) -> str:
    """The ``solver_choice`` a linear solve records when ``auto`` chose."""
    chosen = "cg" if use_cg else ("nested-dissection" if nd else "direct")
    return (f"auto: {chosen} ({free_unknowns} free unknowns; cg from "
            f"{AUTO_ITERATIVE_UNKNOWNS} on SPD systems, nested dissection from "
            f"{ND_FROM_UNKNOWNS} on 2D lattices unless the LU is dense)")


#: The indentation's Newton steps
#: (:class:`~pdverify.solvers.newton.DirichletLinearSolver`): ``solver=auto`` uses CG from
#: this many unknowns: on the quick grid (3,362 unknowns) the corrected curve took 13 s
#: with a sparse LU per Newton step, 2.6 s with CG (record
#: indentation-2026-11-23-newton-cg).
NEWTON_CG_FROM_UNKNOWNS = 1000


def newton_solver(requested: str, unknowns) -> str:
    """The linear solver of a Newton run's tangents: ``requested`` (``cg`` or ``direct``),
    or for ``auto`` ``cg`` from :data:`NEWTON_CG_FROM_UNKNOWNS` unknowns."""
    return ("cg" if requested == "cg" or (requested == "auto"
                                          and unknowns >= NEWTON_CG_FROM_UNKNOWNS)
            else "direct")


# -- auto on state-based problems: nested dissection or direct ------------------------

#: ``solver=auto`` solves the augmented system (dilatations as unknowns) under nested
#: dissection from this many displacement unknowns in 2D: whole runs of
#: plate2d-plane-strain 1.8x faster than the direct solve at 960 unknowns, 3.0-3.7x at h =
#: 0.025-0.02 (record solvers-2026-11-26-crossover2d). It was 8,000 until issue 32; the
#: default-size runs now change at round-off (compare --rtol 1e-9 finds nothing).
ND_FROM_UNKNOWNS = 1000
#: the same in 3D, where K is a dense LU: body3d-traction at the default 9,000 unknowns 2x
#: faster and half the peak memory under nested dissection (record
#: solvers-2026-11-23-crossover3d)
ND3D_FROM_UNKNOWNS = 4000


#: ... and from this many displacement unknowns in 3D, CG on the condensed K (applied, not
#: formed; Jacobi-preconditioned, :func:`~pdverify.solvers.iterative.solve_condensed`) when K
#: is symmetric (:func:`condensed_cg`), else nested dissection. The multifrontal solve
#: reaches its end at h = 1/30 on the 3D box (20,250 unknowns: 2.0 GB, the 2 GB a run may
#: take), where CG took 0.9 GB; CG is faster from h = 0.05 on (6,000 unknowns: 1 s against
#: 16 s, under load), but the threshold sits above every 3D run of the report at h = 0.05
#: (surface nodes: 9,000), so those keep their direct solutions bit for bit (record
#: refine3d-2026-11-28-levels-0.05-to-1-36).
CG3D_FROM_UNKNOWNS = 10000
#: K counts as symmetric when |b.Ka - a.Kb| / (|b| |Ka|) of two random vectors is below
#: this: round-off of the products gave 1e-18 to 4e-17 on the symmetric LPS systems of the
#: 3D box, the energy method's non-symmetric K 2e-5 to 1e-4 (benchmarks/refine3d.py), so
#: the line sits four orders above the one and seven below the other.
SYMMETRY_TOL = 1e-12


def static_solver(requested: str, dim: int, unknowns: int) -> str:
    """The solver a static state-based run uses: ``requested``, or for ``auto`` nested
    dissection from :data:`ND_FROM_UNKNOWNS` unknowns in 2D (11x faster than the direct
    solve at h = 0.01 with the float32 factor: commit aa3f0a1) and
    :data:`ND3D_FROM_UNKNOWNS` in 3D (2x faster and half the memory of the dense LU at h =
    0.05: record solvers-2026-11-23-crossover3d), and ``cg`` from
    :data:`CG3D_FROM_UNKNOWNS` in 3D (the front door falls back to nested dissection where
    CG does not apply: :func:`condensed_cg`). 1D: always direct."""
    if requested != "auto":
        return requested
    if dim == 1:
        return "direct"
    if dim == 3 and unknowns >= CG3D_FROM_UNKNOWNS:
        return "cg"
    return ("nested-dissection" if unknowns >= (ND_FROM_UNKNOWNS if dim == 2
                                                 else ND3D_FROM_UNKNOWNS) else "direct")


def condensed_cg(asymmetry: float, constraint_rows: bool) -> str | None:
    """Why CG cannot solve a condensed state-based system that ``auto`` gave it (None: it
    can): constraint rows (a saddle point, not SPD) or a K that is not symmetric
    (``asymmetry`` above :data:`SYMMETRY_TOL`)."""
    if constraint_rows:
        return "constraint rows: a saddle-point system"
    if not asymmetry <= SYMMETRY_TOL:
        return f"K not symmetric (defect {asymmetry:.1e} > {SYMMETRY_TOL:g})"
    return None


def auto_note(solver: str, unknowns: int, fallback: str | None = None) -> str:
    """The ``solver_choice`` a run records when ``auto`` chose (``fallback``: why CG, the
    first choice, did not apply)."""
    why = f"; cg does not apply: {fallback}" if fallback else ""
    return (f"auto: {solver} ({unknowns} unknowns; nested dissection from "
            f"{ND_FROM_UNKNOWNS} in 2D, {ND3D_FROM_UNKNOWNS} in 3D, CG on a symmetric K "
            f"from {CG3D_FROM_UNKNOWNS} in 3D{why})")


# -- nested dissection: single or double precision, split or whole --------------------

#: From this many unknowns :func:`~pdverify.solvers.nested.solve_nested` factors in single
#: precision (:func:`~pdverify.solvers.nested.single_precision_factor`) and refines in
#: double: on the plane-strain plate even at 5,040 unknowns, 2x faster at 30,600 (record
#: solvers-2026-11-23-mixed-precision).
MIXED_FROM_UNKNOWNS = 5000


def mixed_precision(unknowns: int) -> bool:
    """Whether nested dissection factors in single precision by default
    (:data:`MIXED_FROM_UNKNOWNS`)."""
    return unknowns >= MIXED_FROM_UNKNOWNS


#: The float32 factor is the multifrontal :class:`~pdverify.solvers.frontal.FrontalLU`
#: when the top separator of the nested-dissection ordering is large, s^2 > this many
#: times the unknowns: the 3D bodies have s^2 / n ~ 236 (h = 0.1) and 336 (h = 0.05), the
#: 2D plates ~28 at every h (m = 3). In 3D its dense fronts beat SuperLU's float32 factor
#: (``FRONTAL_FACTOR``'s note in :mod:`~pdverify.solvers.nested`); in 2D SuperLU's is the
#: cheaper (6.9 against 13.0 s of CPU over seven plate and sheet runs: record
#: split_lu-2026-11-28-all-cases).
FRONTAL_SEPARATOR_RATIO = 100


def frontal_factor(separator: int, unknowns: int) -> bool:
    """Whether a system with a top separator of ``separator`` of its ``unknowns`` is
    factored by the multifrontal LU (:data:`FRONTAL_SEPARATOR_RATIO`)."""
    return separator ** 2 > FRONTAL_SEPARATOR_RATIO * unknowns


# -- eigenvalues (modal) ----------------------------------------------------------------

#: Below this many free unknowns the eigenvalues come from a dense solver.
EIGEN_DENSE_LIMIT = 400
#: Up to this bandwidth the largest eigenvalue comes from LAPACK's banded solver (exact
#: and O(n b^2)); Lanczos converges slowly when the top of the spectrum is clustered, as
#: it is for the interior modes of a long bar.
EIGEN_BANDED_LIMIT = 64
