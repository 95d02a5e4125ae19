"""Checks of the command line's paths and flags, before any work (bad input: exit 2).

Parameters are checked by ``pdverify.params`` and each scene's ``check``; this module
covers what is not a parameter: output paths, ``--jobs``, ``--run-timeout`` and ``--only``.
"""
from __future__ import annotations

import os
import tempfile

from . import outputs
from .errors import InputError


def _probe_folder(folder: str, flag: str, shown: str) -> None:
    """Prove that ``folder`` could be created (if missing) and take a file, without leaving
    anything behind: its nearest existing ancestor must be a folder that takes a file."""
    probe = outputs.existing_ancestor(folder)
    if not os.path.isdir(probe):
        raise InputError(f"{flag} {shown!r}: {probe!r} is a file, not a folder")
    try:
        fd, tmp = tempfile.mkstemp(prefix=".probe-", dir=probe)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(f"{flag} {shown!r}: cannot write there ({reason})") from None


def output_dir(path, flag: str = "--out", inputs=()) -> str:
    """A report folder: a non-empty path that is not a file, whose ``results.json`` and
    ``index.html`` are not folders and whose ``figures`` is not a file, in a writable
    parent, and that pdverify may replace (:func:`pdverify.outputs.check_out_dir`: new,
    empty or a previous report). Returns the path with links resolved."""
    if path is None:
        raise InputError(f"{flag}: a folder is required")
    if not str(path).strip():
        raise InputError(f"{flag} {path!r}: empty path; give a folder")
    full = os.path.realpath(os.path.abspath(os.path.expanduser(str(path))))
    if os.path.exists(full) and not os.path.isdir(full):
        raise InputError(f"{flag} {path!r} is a file; give a folder")
    for name, want_dir in (("results.json", False), ("index.html", False), ("figures", True)):
        p = os.path.join(full, name)
        if os.path.exists(p) and os.path.isdir(p) != want_dir:
            kind = "a folder" if not want_dir else "a file"
            raise InputError(f"{flag} {path!r}: {name} there is {kind}; remove it or choose "
                             "another folder")
    full = outputs.check_out_dir(path, flag, inputs)
    _probe_folder(os.path.dirname(full), flag, str(path))
    return full


def output_file(path, flag: str = "--json", *, force: bool = False, inputs=()) -> str:
    """A file to write: non-empty, not a folder, in a writable folder with room, never an
    input (``inputs``: (path, what) pairs) and, if it exists, a file pdverify wrote unless
    ``force`` (:func:`pdverify.outputs.check_out_file`). Returns it with links resolved."""
    if not str(path).strip():
        raise InputError(f"{flag} {path!r}: empty path; give a file name")
    full = os.path.abspath(os.path.expanduser(str(path)))
    if os.path.isdir(full) or str(path).endswith(os.sep):
        raise InputError(f"{flag} {path!r} is a folder; give a file name")
    _probe_folder(os.path.dirname(full), flag, str(path))
    full = outputs.check_out_file(path, flag, force=force, inputs=inputs)
    outputs.check_free(os.path.dirname(full), outputs.MIN_FREE_FILE, f"{flag} {str(path)!r}")
    return full


def vtu_file(path, *, force: bool = False, json_path=None) -> str:
    """``run --vtu``: a writable file name ending in ``.vtu``; none of the files it may
    write (:func:`pdverify.outputs.vtu_files`) is the ``--json`` file or, unless
    ``force``, an existing file pdverify did not write."""
    if not str(path).endswith(".vtu"):
        raise InputError(f"--vtu {path!r}: the file name must end in .vtu")
    full = output_file(path, "--vtu", force=force)
    for target in outputs.vtu_files(full):
        if json_path is not None and os.path.realpath(target) == json_path:
            raise InputError(f"--vtu {path!r} would write {target!r}, the --json file; give "
                             "them different names")
        outputs.check_out_file(target, "--vtu", force=force)
    if json_path is not None and full == json_path:
        raise InputError(f"--vtu {path!r} is also the --json file; give them different names")
    return full


def input_file(path, what: str) -> str:
    """A file to read: exists and is a regular file (not a folder, FIFO or device)."""
    if not str(path).strip():
        raise InputError(f"{what} {path!r}: empty path")
    if os.path.isdir(path):
        raise InputError(f"{what} {path!r} is a folder, not a results file")
    if not os.path.isfile(path):
        if os.path.exists(path):
            kind = outputs.file_kind(os.stat(path).st_mode)
            raise InputError(f"{what} {path!r} is {kind}, not a file; give a results file")
        raise InputError(f"{what} {path!r} does not exist")
    return path


def jobs(value: int | None) -> int:
    """``--jobs``: 1 .. the number of CPUs; None: the cores available to this process."""
    if value is None:
        from .schedule import default_jobs
        return default_jobs()
    cpus = os.cpu_count() or 1
    if not 1 <= value <= cpus:
        raise InputError(f"--jobs={value} must be between 1 and {cpus} (the CPUs of this machine)")
    return value


def run_timeout(value: float | None) -> float | None:
    """``--run-timeout``: a positive, finite number of seconds, or None (no limit)."""
    import math
    if value is not None and not (math.isfinite(value) and value > 0):
        raise InputError(f"--run-timeout={value:g} must be a positive number of seconds")
    return value


def _once_each(values, flag: str, what: str) -> list | None:
    """``values`` as a list, each at most once (None stays None)."""
    if values is None:
        return None
    seen = set()
    for v in values:
        if v in seen:
            raise InputError(f"{flag}: {what} {v!r} is given twice")
        seen.add(v)
    return list(values)


def only(scenes) -> list | None:
    """``--only``: every scene at most once."""
    return _once_each(scenes, "--only", "scene")


def methods(names) -> list | None:
    """``report --method``: every method at most once (whether the selected scenes offer
    it is checked by :func:`pdverify.runner.plan`, with the close matches)."""
    return _once_each(names, "--method", "method")
