"""One BLAS thread per run, so that a run's numbers do not depend on the machine.

OpenBLAS splits a long dot product (numpy's ``a @ b`` on vectors of more than ~10^4
entries, the norms of CG) among its threads and adds the parts in another order than one
thread does: the last bits differ with the thread count, which is the core count unless
``OPENBLAS_NUM_THREADS`` says otherwise. So the same run gave other numbers on another
machine, or in a report with ``--jobs 2`` if its workers shared the cores out. Every run
(:meth:`pdverify.scenes.base.Scene.run`) therefore computes with one BLAS thread: the
report's parallelism is its workers (``--jobs``), one run per core. It also bounds the
address space: each BLAS thread reserves buffers of its own, and under a 6 GB
``ulimit -v`` a 3D run exhausted it with two threads and passed with one, and on a
busy machine one thread can also be the faster
(benchmarks/records/blas_threads-2026-11-24-address-space.json). The cost is measured by
``benchmarks/blas_threads.py``.
"""
from __future__ import annotations

import contextlib

_controller = None


def _get_controller():
    """threadpoolctl's view of the BLAS libraries loaded (numpy's and scipy's), built once
    (0.03 ms a use afterwards, against 2 ms to look the libraries up each time); None when
    threadpoolctl is unavailable."""
    global _controller
    if _controller is None:
        try:
            import scipy.linalg  # noqa: F401  (loads scipy's BLAS, so that it is listed)
            from threadpoolctl import ThreadpoolController
        except ImportError:      # a declared dependency; a bare checkout may lack it
            _controller = False
        else:
            _controller = ThreadpoolController()
    return _controller or None


def one_thread():
    """Context in which the BLAS libraries use one thread; the previous setting is
    restored on leaving."""
    c = _get_controller()
    return c.limit(limits=1, user_api="blas") if c is not None else contextlib.nullcontext()


def threads() -> int:
    """The most threads any BLAS library of this process may use now (1 without
    threadpoolctl, where no library can be told)."""
    c = _get_controller()
    if c is None:
        return 1
    return max((lib.num_threads for lib in c.lib_controllers if lib.user_api == "blas"),
               default=1)
