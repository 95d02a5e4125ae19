"""Report cases on a Dask distributed cluster (``report --scheduler ADDRESS``).

The default stays the local supervised process pool (``--jobs``). With a scheduler, each
case is one task, ``pdverify.runner.run_case`` on a worker, so a worker must have the same
pdverify installed (and, for bit-identical numbers, the same NumPy/SciPy/BLAS build).
Results come back in the order of the cases. A task whose worker dies (a segfault, an
out-of-memory kill) comes back as a failed run naming it, and the report goes on.
"""
from __future__ import annotations

import importlib.util
import os
import re

from .errors import InputError

ENV = "PDVERIFY_SCHEDULER"
#: how long to wait for the scheduler before giving up (exit 2)
CONNECT_TIMEOUT_S = 10
#: the address schemes a separate scheduler process can be reached by with a plain
#: ``distributed`` install
SCHEMES = ("tcp", "tls", "ws", "wss")
_ADDRESS = re.compile(r"^(tcp|tls|inproc|ucx|ws|wss)://[^\s/]+$|^[A-Za-z0-9.\-\[\]:]+:\d+$")


def scheduler_address(flag: str | None) -> str | None:
    """The scheduler from ``--scheduler``, else ``PDVERIFY_SCHEDULER``, else None (local).
    A malformed address, or a missing ``distributed`` package, is bad input (exit 2)."""
    where, value = ("--scheduler", flag) if flag is not None else (ENV, os.environ.get(ENV))
    if value is None or (flag is None and not value.strip()):
        return None
    value = value.strip()
    if not _ADDRESS.match(value):
        raise InputError(f"{where}={value!r}: expected a Dask scheduler address such as "
                         "tcp://10.0.0.5:8786 or 10.0.0.5:8786")
    scheme = value.split("://", 1)[0] if "://" in value else "tcp"
    if scheme not in SCHEMES:
        raise InputError(f"{where}={value!r}: the scheme {scheme}:// is not supported; "
                         f"allowed: {', '.join(s + '://' for s in SCHEMES)} (inproc:// reaches "
                         "only a scheduler inside this process, ucx:// needs UCX-Py)")
    if importlib.util.find_spec("distributed") is None:
        raise InputError(f"{where}: running on a Dask cluster needs the 'distributed' package "
                         "(python -m pip install \"pdverify[cluster]\")")
    return value


def connect(address: str):
    """A client of the scheduler at ``address``; unreachable is bad input (exit 2)."""
    from distributed import Client
    try:
        return Client(address, timeout=f"{CONNECT_TIMEOUT_S}s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:  # ValueError: a scheme or address
        # distributed refuses only when it tries it
        raise InputError(f"--scheduler: cannot reach a Dask scheduler at {address} within "
                         f"{CONNECT_TIMEOUT_S} s ({type(exc).__name__})") from None


def run_cases_on(client, cases, note, run_case, died_on_cluster) -> list:
    """Submit every case, collect as they finish; ``note(k, result)`` per finished run.
    ``run_case(case)`` is the task, ``died_on_cluster(case, exc)`` the failed run of a
    task whose worker died (the runner's; passed in, so this module does not import
    the runner)."""
    from distributed import as_completed

    futures = [client.submit(run_case, case, pure=False, retries=0) for case in cases]
    index = {f.key: k for k, f in enumerate(futures)}
    results = [None] * len(cases)
    try:
        for fut in as_completed(futures):
            k = index[fut.key]
            try:
                res = fut.result()
            except Exception as exc:  # KilledWorker, or an error outside Scene.run
                res = died_on_cluster(cases[k], exc)
            results[k] = res
            note(k, res)
    finally:
        client.cancel(futures)
    return results
