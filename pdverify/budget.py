"""Resource budget: every run's memory and time-step estimate, from its params alone,
checked against a limit before any allocation (issue 18).

A run above the limit is bad input: exit 2 with one line that names the run, the
estimate, what it is made of and the limit. The limit is ``--max-memory`` (``run`` and
``report``), else the environment variable ``PDVERIFY_MAX_MEMORY``, else half of the
machine's memory ceiling: the smallest of the physical memory (MemTotal), the cgroup's
memory limit (v2 ``memory.max`` or v1 ``memory.limit_in_bytes``) and ``RLIMIT_AS``. That
ceiling does not move with what else runs, so the same run is admitted or refused the
same way every time (the momentary MemAvailable did move, by 10 % within an hour).
Time-stepping runs are also held to :data:`MAX_TIME_STEPS`, implicit load-stepping runs
(each increment at least one linear solve) to :data:`MAX_LOAD_INCREMENTS`.

The memory model (:func:`linear_system`) counts what dominates a static PD or FEM solve:

- the assembled matrix and its assembly arrays, :data:`BYTES_PER_NONZERO` per stored
  non-zero, with nonzeros = unknowns x (unknowns per row: d x nodes within the stencil's
  reach r, counted on the lattice);
- the factor: a dense LU keeps two n x n copies (equilibrated matrix and LU), a sparse
  LU's fill follows nested dissection: the top separator of a D-dimensional body n nodes
  across is r layers thick, so the factor holds ~ d^2 max(N r, (r N^((D-1)/D))^2)
  entries, at :data:`BYTES_PER_FACTOR_ENTRY` each.

The two constants were measured (``benchmarks/budget_calibration.py`` prints estimate
against peak resident memory for every scene family at two sizes); the estimate is
meant to be an upper bound within a factor of about 3 of the measured peak above the
interpreter's own footprint
(benchmarks/records/budget_calibration-2026-11-22-estimate-ratios.json).
"""
from __future__ import annotations

import math
import os
import re
from contextlib import contextmanager
from dataclasses import dataclass

from .errors import InputError

MEMORY_ENV = "PDVERIFY_MAX_MEMORY"
#: share of the memory ceiling (:func:`memory_ceiling`) one run may plan to use when no
#: limit is given
DEFAULT_FRACTION = 0.5
#: ceiling on explicit time steps of one run (~ minutes of 1D stepping on this machine)
MAX_TIME_STEPS = 20_000_000
#: ceiling on implicit load increments of one run, each at least one linear solve: the FEM
#: indentation study (800 increments over its levels) took 5 s, so this is ~2 minutes there
MAX_LOAD_INCREMENTS = 20_000
#: matrix and assembly arrays per stored non-zero: measured 61 B on the 3D boxes
#: (benchmarks/records/budget_calibration-2026-11-22-bytes-per-nonzero.json)
BYTES_PER_NONZERO = 64.0
#: SuperLU factor per nested-dissection entry: measured 352-671 B on the 2D plates and
#: sheets; the same count with reach 2 bounds the Q2 FEM solves (benchmarks/records/
#: budget_calibration-2026-11-22-bytes-per-factor-entry.json)
BYTES_PER_FACTOR_ENTRY = 700.0

_UNITS = {"": 1, "b": 1, "k": 2 ** 10, "kb": 10 ** 3, "kib": 2 ** 10, "m": 2 ** 20,
          "mb": 10 ** 6, "mib": 2 ** 20, "g": 2 ** 30, "gb": 10 ** 9, "gib": 2 ** 30,
          "t": 2 ** 40, "tb": 10 ** 12, "tib": 2 ** 40}
_limit_override: int | None = None


@dataclass(frozen=True)
class Estimate:
    """What one run will need: ``memory`` bytes above the interpreter's own footprint,
    ``time_steps`` explicit steps, and ``detail``, the sizes they come from."""

    memory: float
    detail: str
    time_steps: int = 0
    increments: int = 0

    def __add__(self, other: "Estimate") -> "Estimate":
        return Estimate(self.memory + other.memory, f"{self.detail}; {other.detail}",
                        self.time_steps + other.time_steps, self.increments + other.increments)


def step_count(steps: float) -> float:
    """ceil(steps), or inf when it overflows (a subnormal dt): :func:`check` refuses it."""
    return math.ceil(steps) if math.isfinite(steps) else math.inf


def larger(first: Estimate, then: Estimate) -> Estimate:
    """Two phases run one after the other: the peak is the larger of the two."""
    big = first if first.memory >= then.memory else then
    return Estimate(big.memory, f"{big.detail} (the larger phase)",
                    max(first.time_steps, then.time_steps),
                    max(first.increments, then.increments))


def parse_size(text: str, what: str) -> int:
    """Bytes from '4G', '512M', '1.5GB', '2GiB', '3e9'; k/M/G/T alone are binary."""
    m = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)\s*", str(text))
    unit = m.group(2).lower() if m else None
    if m is None or unit not in _UNITS:
        raise InputError(f"{what}={text!r} must be a size such as 4G, 512M, 1.5GB or a "
                         "number of bytes")
    value = float(m.group(1)) * _UNITS[unit]
    if not math.isfinite(value):
        raise InputError(f"{what}={text!r} is not a finite size (a double holds up to 1.8e308 "
                         "bytes)")
    if not value >= 2 ** 20:
        raise InputError(f"{what}={text!r} must be at least 1M")
    return int(value)


def set_limit(text: str | None) -> None:
    """``--max-memory``: overrides the environment and the default for this process."""
    global _limit_override
    _limit_override = None if text is None else parse_size(text, "--max-memory")


_CGROUP_LIMITS = ("/sys/fs/cgroup/memory.max",                     # cgroup v2
                  "/sys/fs/cgroup/memory/memory.limit_in_bytes")     # cgroup v1


def _read_limit(path: str) -> int | None:
    """A cgroup memory limit in bytes, None when absent or unlimited ("max", or v1's
    page-rounded 2^63)."""
    try:
        with open(path) as fh:
            text = fh.read().strip()
    except OSError:
        return None
    if not text.isdigit():
        return None
    value = int(text)
    return value if value < 2 ** 62 else None


def memory_ceiling() -> tuple[int, str]:
    """The smallest of the physical memory, the cgroup limit and ``RLIMIT_AS`` (bytes),
    and which one it is. None of them depends on what else runs at the moment."""
    found = [(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"), "total memory")]
    for path in _CGROUP_LIMITS:
        value = _read_limit(path)
        if value is not None:
            found.append((value, "the cgroup's memory limit"))
    try:
        import resource
        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY and soft > 0:
            found.append((soft, "RLIMIT_AS"))
    except (ImportError, OSError, ValueError):
        pass
    return min(found)


def memory_limit() -> tuple[int, str]:
    """The limit in bytes and where it comes from."""
    if _limit_override is not None:
        return _limit_override, "--max-memory"
    env = os.environ.get(MEMORY_ENV)
    if env:
        return parse_size(env, MEMORY_ENV), MEMORY_ENV
    ceiling, what = memory_ceiling()
    return int(DEFAULT_FRACTION * ceiling), (
        f"default: {DEFAULT_FRACTION:.0%} of {what}; change with --max-memory "
        f"or {MEMORY_ENV}")


def format_bytes(n: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} B"


_ASSEMBLY_ONLY = {"on": False}


@contextmanager
def assembly_only():
    """While held, :func:`check` refuses only a size that overflows: the command (``pdverify
    export``) assembles the problem and solves nothing, so the solver's memory estimate,
    time steps and load increments do not apply to it."""
    before = _ASSEMBLY_ONLY["on"]
    _ASSEMBLY_ONLY["on"] = True
    try:
        yield
    finally:
        _ASSEMBLY_ONLY["on"] = before


def check(where: str, estimate: Estimate | None) -> None:
    """Raise :class:`InputError` when ``estimate`` exceeds the memory limit or the step
    ceiling; one line with the estimate, its sizes and the limit."""
    if estimate is None:
        return
    if _ASSEMBLY_ONLY["on"]:
        if not math.isfinite(estimate.memory):
            raise InputError(f"{where}: the size overflows ({estimate.detail})")
        return
    if estimate.time_steps > MAX_TIME_STEPS:
        raise InputError(f"{where}: needs ~{estimate.time_steps:.3g} time steps "
                         f"({estimate.detail}), above the ceiling of {MAX_TIME_STEPS:.3g}")
    if estimate.increments > MAX_LOAD_INCREMENTS:
        raise InputError(f"{where}: needs ~{estimate.increments:.3g} load increments "
                         f"({estimate.detail}), above the ceiling of {MAX_LOAD_INCREMENTS}")
    if not math.isfinite(estimate.memory):
        raise InputError(f"{where}: the size overflows ({estimate.detail}); no run of this "
                         "size fits any memory")
    limit, source = memory_limit()
    if estimate.memory > limit:
        raise InputError(f"{where}: needs ~{format_bytes(estimate.memory)} of memory "
                         f"({estimate.detail}), above the limit of {format_bytes(limit)} "
                         f"({source})")


_PEAK_WRAPPER = ("import resource, subprocess, sys; "
                 "code = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, "
                 "stderr=subprocess.DEVNULL).returncode; "
                 "print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")


def measured_peak(args, env=None) -> float:
    """Peak resident memory (bytes) of the command ``args``, for calibrating and testing
    the estimates. A small wrapper process starts it: a child's peak counts the memory
    of whatever forked it, so timing it straight from a large process (a test session)
    would measure that process instead. Raises RuntimeError if the command fails."""
    import subprocess
    import sys
    out = subprocess.run([sys.executable, "-c", _PEAK_WRAPPER, *args], env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    if out[0] != "0":
        raise RuntimeError(f"{' '.join(args)} exited with {out[0]}")
    return float(out[1]) * 1024.0


def lattice_neighbours(dim: int, reach: float) -> float:
    """Lattice points within ``reach`` spacings of a node (itself included), ~ the ball."""
    r = float(reach)
    if not math.isfinite(r):       # a reach that overflowed: so does the count (refused)
        return math.inf
    # products, not powers: r ** 3 raises OverflowError where r * r * r becomes inf
    return {1: 2 * math.floor(r) + 1, 2: math.pi * r * r + 1,
            3: 4.0 / 3.0 * math.pi * r * r * r + 1}[dim]


def _unknowns_and_nonzeros(nodes: float, dim: int, dofs_per_node: int, reach: float):
    """Unknowns, and stored non-zeros of a lattice operator whose rows reach ``reach``
    spacings (at most a full matrix)."""
    n = float(nodes) * dofs_per_node
    return n, min(n * dofs_per_node * lattice_neighbours(dim, reach), n * n)


def linear_system(nodes: float, dim: int, dofs_per_node: int, reach: float,
                  dense_allowed: bool = False, extra_bytes: float = 0.0) -> Estimate:
    """Memory of assembling and factoring a static system on ``nodes`` lattice nodes in
    ``dim`` dimensions whose stencil reaches ``reach`` node spacings (see the module
    docstring); ``dense_allowed``: the solver switches to dense LU when it is full."""
    # the direct solver's switch to its dense path (solvers.policy; imported here: the CLI
    # imports this module and must stay light)
    from .solvers.policy import dense_lu
    n, nnz = _unknowns_and_nonzeros(nodes, dim, dofs_per_node, reach)
    sep = reach * float(nodes) ** ((dim - 1) / dim)
    factor = dofs_per_node ** 2 * max(float(nodes) * reach, sep * sep)
    dense = dense_allowed and dense_lu(n, nnz)
    memory = BYTES_PER_NONZERO * nnz + extra_bytes + (
        2 * 8.0 * n * n if dense else min(BYTES_PER_FACTOR_ENTRY * factor, 24.0 * n * n))
    how = "dense LU" if dense else "sparse LU"
    return Estimate(memory, f"{nodes:.4g} nodes, {n:.4g} unknowns, ~{nnz:.3g} non-zeros, "
                            f"{how}")


def iterative_system(nodes: float, dim: int, dofs_per_node: int, reach: float,
                     extra_bytes: float = 0.0, copies: int = 2) -> Estimate:
    """Memory of a system solved by preconditioned CG on ``nodes`` lattice nodes: no
    factor, ``copies`` matrices of the stencil's non-zeros (the system, and the
    preconditioner's products bounded by one more), and ``extra_bytes``."""
    n, nnz = _unknowns_and_nonzeros(nodes, dim, dofs_per_node, reach)
    return Estimate(copies * BYTES_PER_NONZERO * nnz + extra_bytes,
                    f"{nodes:.4g} nodes, {n:.4g} unknowns, ~{nnz:.3g} non-zeros, CG (no "
                    "factor)")


#: nested dissection of a 3D lattice body: the factor holds the top separator's block and
#: those of every level below, 2^k separators of (1/2^(2/3))^k its size at depth k, a
#: geometric sum of 1 / (1 - 2^(-1/3)) = 4.85 top-separator blocks, for L and U each
ND3D_LEVELS = 2.0 / (1.0 - 2.0 ** (-1.0 / 3.0))
#: the mixed-precision nested-dissection solve (SuperLU in float32, refined in double) per
#: factor entry, on top of the matrix: measured 16-23 B on body3d-traction, surface nodes,
#: rounded up so that the whole estimate bounds all three sizes measured
#: (benchmarks/records/budget_calibration-2026-11-23-nd3d-entry.json)
BYTES_PER_ND3D_ENTRY = 28.0


def nested_dissection_3d(nodes: float, dofs_per_node: int, reach: float,
                         extra_bytes: float = 0.0) -> Estimate:
    """Memory of the 3D nested-dissection solve on ``nodes`` lattice nodes whose stencil
    reaches ``reach`` spacings: the matrix as :func:`linear_system` counts it, and a factor
    of ~ :data:`ND3D_LEVELS` d^2 (r N^(2/3))^2 entries at :data:`BYTES_PER_ND3D_ENTRY` (the
    count is within 1.3x of SuperLU's at h = 0.05 and of PARDISO's predicted 8.8e8 at
    h = 0.025)."""
    n, nnz = _unknowns_and_nonzeros(nodes, 3, dofs_per_node, reach)
    sep = reach * float(nodes) ** (2.0 / 3.0)
    factor = min(ND3D_LEVELS * dofs_per_node ** 2 * sep * sep, n * n)
    memory = BYTES_PER_NONZERO * nnz + extra_bytes + BYTES_PER_ND3D_ENTRY * factor
    return Estimate(memory, f"{nodes:.4g} nodes, {n:.4g} unknowns, ~{nnz:.3g} non-zeros, "
                            f"nested-dissection LU with ~{factor:.3g} factor entries")


#: the 2D nested-dissection solve (``solvers.nested``, the ``auto`` choice of the crack
#: scenes) per factor entry of :func:`nested_dissection_2d`'s count, on top of the
#: matrix: the peaks of benchmarks/budget_nd2d.py (fresh processes, plate-crack and
#: plate-edge-crack at 7 200 .. 43 200 nodes, plate2d-plane-strain's report cases)
#: imply 27-32 B for the uncorrected model and surface nodes and 56-63 B for PALS (whose
#: setup holds more than the factor); 80 B bounds the largest, 63.4 B, with a margin of
#: 1.26: the estimate is 1.19-2.21x the measured peaks of the ten cases, where the
#: sparse LU's was 1.84-3.58x (record budget_nd2d-2026-11-28-default.json)
BYTES_PER_ND2D_ENTRY = 80.0


def nested_dissection_2d(nodes: float, dofs_per_node: int, reach: float,
                         extra_bytes: float = 0.0) -> Estimate:
    """Memory of the 2D nested-dissection solve on ``nodes`` lattice nodes whose stencil
    reaches ``reach`` spacings: the matrix as :func:`linear_system` counts it, and a factor
    of ``d^2 r^2 N log2(N / r^2)`` entries (d = ``dofs_per_node``, r = ``reach``, N =
    ``nodes``: a separator of a 2D lattice is a band r nodes wide, and each of the
    log2(N / r^2) levels of the dissection holds separators whose dense blocks add to
    d^2 r^2 N entries; George 1973's O(N log N) fill of nested dissection on a 2D grid)
    at :data:`BYTES_PER_ND2D_ENTRY`. ``linear_system``'s sparse LU, which it replaces for
    this solver, overestimated the measured peaks 3.0-3.15x (benchmarks/budget_nd2d.py)."""
    n, nnz = _unknowns_and_nonzeros(nodes, 2, dofs_per_node, reach)
    r = float(reach)
    factor = min(dofs_per_node ** 2 * r * r * float(nodes)
                 * math.log2(max(float(nodes) / (r * r), 2.0)), n * n)
    memory = BYTES_PER_NONZERO * nnz + extra_bytes + BYTES_PER_ND2D_ENTRY * factor
    return Estimate(memory, f"{nodes:.4g} nodes, {n:.4g} unknowns, ~{nnz:.3g} non-zeros, "
                            f"nested-dissection LU with ~{factor:.3g} factor entries")


def quadratic_elements(cells) -> Estimate:
    """A Q2 (9- or 27-node) vector FEM solve on a tensor mesh with ``cells`` elements per
    axis: (2 n + 1) nodes per axis, one element spans two node spacings."""
    nodes = math.prod(2 * int(n) + 1 for n in cells)
    est = linear_system(nodes, len(cells), len(cells), 2)
    return Estimate(est.memory, f"FEM {' x '.join(str(int(n)) for n in cells)} Q2 elements, "
                                + est.detail)


def release_freed_memory() -> None:
    """Give the pages that freed memory left in the C allocator's heaps back to the system
    (glibc's ``malloc_trim(0)``; elsewhere nothing). glibc raises its mmap threshold up to
    32 MB as large blocks are freed, so the arrays of one run come from the heaps and their
    pages stay with the worker after it: a run's measured peak (from :func:`reset_peak_rss`)
    then includes what earlier runs of the same worker left, e.g. plate2d-plane-strain's
    Taylor run 1.45 GB in one full report and 1.93 GB in the next. Only pages no object
    uses are returned, so no computed number changes."""
    import ctypes
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):      # not glibc
        pass


def load_average() -> float | None:
    """The machine's 1-minute load average (``os.getloadavg``: the runnable and waiting
    processes, averaged), None where the system does not offer it. A run's time is
    comparable with another's only at similar loads: at a load above the CPU count the
    runs share the cores."""
    try:
        return float(os.getloadavg()[0])
    except (OSError, AttributeError):
        return None


def reset_peak_rss() -> bool:
    """Linux: set this process's peak resident size (``VmHWM``) back to its current size
    (``/proc/self/clear_refs``, value 5), so that :func:`peak_rss` measures from now.
    False where the kernel does not offer it (the run then records no peak)."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def peak_rss() -> float | None:
    """This process's peak resident size in bytes since its start or the last
    :func:`reset_peak_rss` (``VmHWM`` of /proc/self/status); None where unavailable."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    return None
