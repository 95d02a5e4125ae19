"""Error types: bad input (exit 2) versus numerical trouble (a failed run)."""


class InputError(ValueError):
    """Bad user input: unknown scene/method/key or a value out of range.

    The message is one line that names the offending input and what is allowed;
    the CLI prints it and exits with code 2 before any work starts.
    """


class NumericalError(RuntimeError):
    """Numerical trouble during a run (singular system, NaN, unstable step, ...).

    The message says what happened and where; the run is recorded as failed and
    never aborts a report.

    ``partial``: what the run computed before the trouble (an ``Outcome`` of metrics and
    fields, e.g. a load curve up to the depth where the lattice folded); the failed record
    keeps it so that a report can show where and how the run broke down.
    """

    def __init__(self, message: str, partial=None):
        super().__init__(message)
        self.partial = partial


#: Set when the process was asked to stop (SIGTERM, Ctrl-C): a step that finishes after a
#: library swallowed the interrupt checks it before publishing anything.
STOP_REQUESTED = {"flag": False}


class OutputError(RuntimeError):
    """An output could not be written after the work started (disk full, read-only, ...).

    The message is one line naming the file or folder and the cause; the CLI prints it and
    exits with code 1. Nothing is published half-written: a report stays in its staging
    folder, a results file keeps its previous content.
    """


class ClusterError(RuntimeError):
    """The Dask cluster of ``report --scheduler`` went away after the work started (the
    client lost its scheduler). The message is one line naming the scheduler and how
    far the report got; the CLI prints it and exits with code 1. Nothing is published.
    """


def did_you_mean(name, allowed) -> str:
    """``" (did you mean a or b?)"`` naming the close matches of a mistyped ``name`` among
    ``allowed`` (difflib's similarity ratio >= 0.75, case ignored, at most three, best
    first), else ``""``: put right after the mistyped name in a one-line bad-input
    message."""
    import difflib
    by_lower = {}
    for a in allowed:
        by_lower.setdefault(str(a).lower(), str(a))
    close = difflib.get_close_matches(str(name).lower(), list(by_lower), n=3, cutoff=0.75)
    return f" (did you mean {' or '.join(by_lower[c] for c in close)}?)" if close else ""
