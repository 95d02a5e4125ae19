"""Report cases on a Dask distributed cluster (``report --scheduler ADDRESS``).

The default stays the local supervised process pool (``--jobs``). With a scheduler, each
case is one task, ``pdverify.runner.run_case`` on a worker, so a worker must have the same
pdverify installed (and, for bit-identical numbers, the same NumPy/SciPy/BLAS build).
Results come back in the order of the cases. A task whose worker dies (a segfault, an
out-of-memory kill) runs again on another worker (Dask's ``distributed.scheduler.
allowed-failures``, 3 by default); one that killed that many workers comes back as a failed
run naming it, and the report goes on. A scheduler lost mid-report (the client's
connection to it closed) ends the report with one line, :class:`~pdverify.errors.
ClusterError` (exit 1), nothing published.

The client is not made the process's default (``connect``), so every ``distributed``
helper that would look one up is given the client or its event loop explicitly.
"""
from __future__ import annotations

import importlib.util
import os
import re

from .errors import ClusterError, InputError

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
    """A client of the scheduler at ``address``; unreachable is bad input (exit 2).

    The client's own log records (``distributed``'s loggers: reconnect attempts and their
    tracebacks when the scheduler goes away) are silenced in this process: what matters
    reaches the user as one line (:class:`~pdverify.errors.ClusterError`, or a failed
    run naming the task's error)."""
    import logging

    from distributed import Client  # its import sets up its loggers
    for name in ["distributed", *logging.root.manager.loggerDict]:
        if name == "distributed" or name.startswith("distributed."):  # some set their own
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)    # level (dask config)
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
    the runner). A task cancelled under us (the scheduler lost) raises ClusterError."""
    from distributed import as_completed

    address = _address(client)
    futures = [client.submit(run_case, case, pure=False, retries=0) for case in cases]
    index = {f.key: k for k, f in enumerate(futures)}
    results = [None] * len(cases)
    done = 0
    try:
        # loop=: without it as_completed looks for a default client, and ours is not one
        # ("No clients found"); the keyword is in every distributed release since 1.x
        for fut in as_completed(futures, loop=client.loop):
            k = index[fut.key]
            if fut.cancelled():  # the client cancels every future when its scheduler goes
                raise ClusterError(f"--scheduler: lost the Dask scheduler at {address} after "
                                   f"{done} of {len(cases)} runs ({_why(client)}); nothing "
                                   "was published")
            try:
                res = fut.result()
            except Exception as exc:  # KilledWorker, or an error outside Scene.run
                res = died_on_cluster(cases[k], exc)
            results[k] = res
            done += 1
            note(k, res)
    finally:
        if done < len(cases) and client.status == "running":
            try:
                client.cancel(futures)
            except Exception:  # the scheduler is going away too: nothing left to cancel
                pass
    return results


def _address(client) -> str:
    """The scheduler's address as the client knows it (for messages)."""
    try:
        return client.scheduler.address
    except AttributeError:
        return "the given address"


def _why(client) -> str:
    """Why the futures were cancelled: the client lost its scheduler, or someone else
    cancelled them (another client of the same scheduler)."""
    if client.status != "running":
        return "the connection to it closed"
    return "a task was cancelled on the scheduler"
