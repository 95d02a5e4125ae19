"""Which linear solver a static run uses: every threshold of ``solver=auto`` in one place.

The solvers themselves live beside this module (``static``: sparse LU with constraints,
nested dissection, mixed precision; ``dense``: dense LU and Dirichlet elimination;
``iterative``: CG with the lattice preconditioner); :func:`pdverify.solvers.front.solve`
is the one front door the problem families call.
"""
from __future__ import annotations

#: ``solver=auto`` solves the augmented system (dilatations as unknowns) under nested
#: dissection from this many displacement unknowns in 2D; below it the direct solve of K
#: takes a few seconds at most (1.7 s at the seed-001 plate's default 5,000) and the
#: report's default-size 2D runs keep their solutions bit for bit.
ND_FROM_UNKNOWNS = 8000
#: the same in 3D, where K is a dense LU: whole runs (assembly and solve) of body3d-traction,
#: surface nodes, direct against nested dissection (benchmarks/solvers.py --only
#: crossover3d, median of 3, quiet machine): 0.85 / 0.99 s at 2,376 unknowns, 1.79 / 2.02 s
#: at 3,528, 4.22 / 2.99 s at 4,992 (where the float32 factor starts), and at the default
#: 9,000 15.7 / 7.9 s with peak memory 2.67 / 1.33 GB (``pdverify run``, /usr/bin/time)
ND3D_FROM_UNKNOWNS = 4000
#: the solvers a static state-based problem can ask for
STATIC_SOLVERS = ("auto", "direct", "nested-dissection")


def static_solver(requested: str, dim: int, unknowns: int) -> str:
    """The solver a static state-based run uses: ``requested``, or for ``auto`` nested
    dissection from :data:`ND_FROM_UNKNOWNS` unknowns in 2D (11x faster than the direct
    solve at h = 0.01) and :data:`ND3D_FROM_UNKNOWNS` in 3D (2x faster and half the
    memory of the dense LU at h = 0.05): benchmarks/solvers.py. 1D: always direct."""
    if requested != "auto":
        return requested
    if dim == 1:
        return "direct"
    return ("nested-dissection" if unknowns >= (ND_FROM_UNKNOWNS if dim == 2
                                                 else ND3D_FROM_UNKNOWNS) else "direct")


def auto_note(solver: str, unknowns: int) -> str:
    """The ``solver_choice`` a run records when ``auto`` chose."""
    return (f"auto: {solver} ({unknowns} unknowns; nested dissection from "
            f"{ND_FROM_UNKNOWNS} in 2D, {ND3D_FROM_UNKNOWNS} in 3D)")
