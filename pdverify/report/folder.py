"""The report's folder: where it goes, whether its disk takes it, how it is published whole."""
from __future__ import annotations

import errno
import hashlib
import os
import shutil

from .. import outputs
from ..errors import STOP_REQUESTED, OutputError
from ..results import umask_mode

DEFAULT_OUT = os.path.join("reports", "latest")


def default_out(only=None, quick=False, methods=None) -> str:
    """Where a report goes without ``--out``: the full report in ``reports/latest``, a
    ``--quick`` one in ``reports/quick`` and an ``--only`` one in a folder named after its
    scenes, so that neither ever replaces the full report; ``--method`` adds the methods
    (``reports/only-SCENE-method-M``, ``reports/method-M``)."""
    if methods:
        ids = list(dict.fromkeys(methods))
        tail = "method-" + (ids[0] if len(ids) == 1 else f"{ids[0]}+{len(ids) - 1}-more-"
                            + hashlib.sha1("\0".join(sorted(ids)).encode()).hexdigest()[:6])
        base = default_out(only, quick)
        if not only:
            return os.path.join("reports", ("quick-" if quick else "") + tail)
        return f"{base}-{tail}"
    if only:
        ids = list(dict.fromkeys(only))
        name = ids[0] if len(ids) == 1 else f"{ids[0]}+{len(ids) - 1}-more-" + hashlib.sha1(
            "\0".join(sorted(ids)).encode()).hexdigest()[:6]
        return os.path.join("reports", ("quick-" if quick else "") + "only-" + name)
    return os.path.join("reports", "quick") if quick else DEFAULT_OUT


#: Bytes a report needs on disk, per run and once (figures of the overview, pages), from
#: the largest --quick --only SCENE report per run measured: see "Storage" in docs/command-line.md.
REPORT_BYTES_PER_RUN = 256_000
REPORT_BYTES_FIXED = 2_000_000


def estimate_bytes(cases) -> int:
    """A generous estimate of a report's size on disk (see :data:`REPORT_BYTES_PER_RUN`)."""
    return REPORT_BYTES_FIXED + REPORT_BYTES_PER_RUN * len(cases)


def check_storage(cases, out: str) -> None:
    """Before any work: the cache takes files, and ``out``'s disk has room for the new
    report next to the previous one (which stays until the new one is complete)."""
    outputs.check_cache()
    outputs.check_target(out)
    outputs.check_free(os.path.dirname(out), estimate_bytes(cases),
                       f"--out {out!r} (a report of {len(cases)} runs)")


def publish(out: str, build) -> int:
    """``build(staging)``, the report's body, into a staging folder next to ``out``, then
    swapped in as ``out``; returns what ``build`` returns. Call it under
    :func:`pdverify.outputs.output_lock` on ``out``.

    A report that could not be written whole (:class:`OutputError`: a figure, a VTU file,
    a page or results.json failed to write) is not swapped in: the previous report stays,
    the partial one stays in its staging folder, and OutputError names both."""
    parent, name = os.path.split(out)
    staging = outputs.new_staging(parent, name, outputs.is_own_leftover, "report",
                                  "nothing was run")
    keep = False
    try:
        try:
            os.chmod(staging, umask_mode(0o777))  # mkdtemp gives 0700
            outputs.write_marker(staging, complete=False)
        except OSError as exc:
            raise OutputError(f"report: cannot write into its staging folder {staging!r} "
                              f"({exc.strerror or exc}); nothing was run") from None
        try:
            code = build(staging)
            _write_marker(staging)
        except OutputError as exc:
            keep = True
            previous = ("the previous report in " + repr(out) + " is unchanged"
                        if os.path.exists(out) else "nothing was published at " + repr(out))
            raise OutputError(f"report incomplete: {exc}; {previous}; the partial report is "
                              f"in {staging!r}") from None
        if STOP_REQUESTED["flag"]:  # an interrupt some library swallowed: publish nothing
            raise KeyboardInterrupt
        state, why = outputs.folder_state(out)
        if state == "foreign":  # someone put files there while the report ran
            keep = True
            raise OutputError(f"report: {out!r} changed while the report ran ({why}); it was "
                              f"left as it is; the new report is in {staging!r}")
        outputs.swap_in(staging, out)
    finally:
        if not keep and os.path.exists(staging):
            shutil.rmtree(staging, ignore_errors=True)
    return code


def _write_marker(folder: str) -> None:
    try:
        outputs.write_marker(folder, complete=True)
    except OSError as exc:
        raise OutputError(f"writing its marker {outputs.MARKER} failed "
                          f"({exc.strerror or exc})") from None


#: errno values of a storage failure: the disk, not the plotting code, is at fault
STORAGE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO}


def storage_failure(exc: BaseException) -> OSError | None:
    """The OSError of a storage failure (:data:`STORAGE_ERRNOS`) in ``exc`` or the
    exceptions it was raised from or during, if any."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in STORAGE_ERRNOS:
            return exc
        exc = exc.__cause__ or exc.__context__
    return None


def describe_os_error(exc: OSError) -> str:
    """``exc`` in a report's message: its text and, where known, the file."""
    text = exc.strerror or str(exc) or type(exc).__name__
    return f"{text}: {exc.filename!r}" if exc.filename else text
