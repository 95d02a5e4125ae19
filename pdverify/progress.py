"""What a report shows while its runs go on: a live display on a terminal, plain lines else.

Display only: nothing here computes a result. :func:`pdverify.runner.run_cases` tells a
:class:`RunProgress` when a run starts and when it finishes, always from the main
(report) process, never from a worker.
"""
from __future__ import annotations

import threading
import time

#: at most this many runs in flight are listed by name in the live display
SHOWN_IN_FLIGHT = 8
#: how often the local pool wakes to refresh the live display's clock [s]
TICK_S = 0.25


def is_terminal(stream) -> bool:
    """True if ``stream`` is an interactive terminal (False for a pipe, a file, CI's log,
    pytest's capture, or an object without ``isatty``)."""
    isatty = getattr(stream, "isatty", None)
    if isatty is None:
        return False
    try:
        return bool(isatty())
    except (ValueError, OSError):  # a closed or detached stream
        return False


def clock(seconds) -> str:
    """``0:07``, ``12:34``, ``1:02:03``; ``?`` when unknown."""
    if seconds is None:
        return "?"
    s = max(0, int(round(seconds)))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


def format_overrides(overrides) -> str:
    return " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                    for k, v in sorted(overrides.items()))


def describe(case) -> str:
    """``scene method key=value ...`` of a (scene, method, overrides) case."""
    scene_id, method, overrides = case
    return " ".join(x for x in (scene_id, method, format_overrides(overrides)) if x)


class RunProgress:
    """The progress of ``cases`` on ``workers`` workers, written to ``stream``.

    On a terminal: a live display (``rich``) with the runs done / total, the elapsed time,
    the ETA and the runs in flight, and one line per finished run scrolling above it.
    Else (a pipe, a file, CI, pytest): one plain line per finished run,
    ``[done/total] scene method params ... ok (1.23 s) metrics | elapsed 0:12, ETA 0:40``.
    ``stream`` None: nothing is shown. Use as a context manager around the runs.

    ``auto_refresh``: let rich redraw from its own thread (for the Dask path, whose main
    thread blocks on the cluster). The local pool forks workers, and a fork while another
    thread holds a lock (the stream's, the console's) can deadlock the child: it
    refreshes from the main thread instead, via :meth:`tick`.
    """

    def __init__(self, cases, workers: int, stream, *, auto_refresh: bool = False,
                 line=None):
        self.cases = list(cases)
        self.total = len(self.cases)
        self.workers = max(1, int(workers or 1))
        self.stream = stream
        self.live = stream is not None and is_terminal(stream)
        self.auto_refresh = auto_refresh
        self.line = line or (lambda k, res: describe(self.cases[k]))
        self.t0 = time.monotonic()
        self.done = 0
        self.failed = 0
        self.in_flight: dict[int, float | None] = {}  # case index -> start time, if known
        self.durations: list[float] = []
        self._lock = threading.Lock()
        self._live = None

    # -- the numbers --------------------------------------------------------------------
    def elapsed(self) -> float:
        return time.monotonic() - self.t0

    def eta(self) -> float | None:
        """Seconds left, estimated as the mean time per finished run x the runs left /
        the worker count (so it assumes the runs left cost what the finished ones did on
        average, and that every worker stays busy); None before the first run is done."""
        if not self.durations:
            return None
        left = self.total - self.done
        return sum(self.durations) / len(self.durations) * left / self.workers

    # -- events (main process only) -------------------------------------------------------
    def started(self, k: int, timed: bool = True) -> None:
        """Case ``k`` went to a worker; ``timed=False``: it was queued somewhere we do not
        see it start (a Dask cluster), so its own run time stands for its duration."""
        with self._lock:
            self.in_flight[k] = time.monotonic() if timed else None

    def finished(self, k: int, res) -> None:
        with self._lock:
            start = self.in_flight.pop(k, None)
            self.done += 1
            self.failed += res.status != "ok"
            self.durations.append(time.monotonic() - start if start is not None
                                  else float(res.timings.get("total_s", 0.0) or 0.0))
            done, eta, elapsed = self.done, self.eta(), self.elapsed()
        if self.stream is None:
            return
        text = f"[{done}/{self.total}] {self.line(k, res)}"
        if self._live is not None:
            from rich.text import Text
            self._live.console.print(Text(text, style=None if res.status == "ok" else "red"),
                                     soft_wrap=True)
            self._live.refresh()
        else:
            print(f"{text.rstrip()} | elapsed {clock(elapsed)}, ETA {clock(eta)}",
                  file=self.stream, flush=True)

    def tick(self) -> None:
        """Redraw the live display (its clock moves even while no run finishes)."""
        if self._live is not None and not self.auto_refresh:
            self._live.refresh()

    @property
    def tick_s(self) -> float | None:
        """How long the caller may block before calling :meth:`tick` (None: forever)."""
        return TICK_S if self._live is not None and not self.auto_refresh else None

    # -- the live display ---------------------------------------------------------------
    def __rich__(self):
        from rich.console import Group
        from rich.progress_bar import ProgressBar
        from rich.table import Table
        from rich.text import Text
        with self._lock:
            done, failed, eta, elapsed = self.done, self.failed, self.eta(), self.elapsed()
            flight = list(self.in_flight.items())
        now = time.monotonic()
        head = Table.grid(padding=(0, 1))
        head.add_row(ProgressBar(total=max(self.total, 1), completed=done, width=30),
                     Text(f"{done}/{self.total} runs"
                          + (f" ({failed} failed)" if failed else "")
                          + f"  elapsed {clock(elapsed)}  ETA {clock(eta)}"))
        rows = [head]
        for k, start in flight[:SHOWN_IN_FLIGHT]:
            # a timed run is running in a local worker; an untimed one was submitted to
            # a cluster, where it may still wait for a worker
            what = (f"running {describe(self.cases[k])}  {clock(now - start)}"
                    if start is not None else f"submitted {describe(self.cases[k])}")
            rows.append(Text(f"  {what}", style="dim"))
        if len(flight) > SHOWN_IN_FLIGHT:
            rows.append(Text(f"  ... and {len(flight) - SHOWN_IN_FLIGHT} more "
                             + ("running" if flight[0][1] is not None else "submitted"),
                             style="dim"))
        return Group(*rows)

    def __enter__(self):
        if self.live:
            from rich.console import Console
            from rich.live import Live
            console = Console(file=self.stream, force_terminal=True)
            self._live = Live(self, console=console, auto_refresh=self.auto_refresh,
                              refresh_per_second=4, transient=False,
                              redirect_stdout=False, redirect_stderr=False)
            self._live.start(refresh=True)
        return self

    def __exit__(self, *exc):
        live, self._live = self._live, None
        if live is not None:
            live.stop()  # also on Ctrl-C / SIGTERM: the final state, the cursor back
        return False
