"""What a report shows while its runs go on: a live display on a terminal, plain lines else.

Display only: nothing here computes a result. :func:`pdverify.runner.run_cases` tells a
:class:`RunProgress` when a run starts and when it finishes, always from the main
(report) process, never from a worker.
"""
from __future__ import annotations

import os
import threading
import time

#: at most this many runs in flight are listed by name in the live display
SHOWN_IN_FLIGHT = 8
#: the ETA's calibration of known times (:meth:`RunProgress.predicted`) starts as if this
#: many seconds of runs had taken their predicted time (a prior at speed 1): replayed on
#: the full and quick reports' records (benchmarks/eta_replay.py), the first runs to end,
#: hundredths of a second each, otherwise set the speed of the whole report
SPEED_PRIOR_S = 20.0
#: how often the local pool wakes to refresh the live display's clock [s]
TICK_S = 0.25
#: on a non-terminal, a heartbeat line names the runs in flight at least this often [s]
#: while no run finishes (CI kills a job silent for 10 minutes; a log should show life)
HEARTBEAT_S = 60.0
#: the environment variable that sets another heartbeat interval in seconds (tests)
HEARTBEAT_ENV = "PDVERIFY_HEARTBEAT_S"


def heartbeat_interval() -> float:
    """:data:`HEARTBEAT_S`, or ``$PDVERIFY_HEARTBEAT_S`` when it is a positive number."""
    try:
        value = float(os.environ.get(HEARTBEAT_ENV, ""))
    except ValueError:
        return HEARTBEAT_S
    return value if value > 0 and value == value else HEARTBEAT_S


class Tee:
    """A text stream that writes to ``stream`` and to the report's log file ``log``; a
    terminal when ``stream`` is (the live display draws on ``stream`` only, and the log
    gets the plain lines)."""

    def __init__(self, stream, log):
        self.stream, self.log = stream, log

    def write(self, text):
        self.stream.write(text)
        self.log.write(text)
        return len(text)

    def flush(self):
        self.stream.flush()
        self.log.flush()

    def isatty(self):
        return is_terminal(self.stream)


def screen_and_log(stream):
    """``(screen, log)`` of a progress stream: a :class:`Tee`'s two streams (what is drawn
    for a terminal goes to ``screen`` only, and ``log`` gets plain text), else ``(stream,
    None)``."""
    if isinstance(stream, Tee):
        return stream.stream, stream.log
    return stream, None


#: the live display's colour of a finished run's line by its outcome
#: (:attr:`pdverify.results.RunResult.outcome`): a documented failure is shown as
#: expected, in pytest's colour for an expected failure, never as a failure
OUTCOME_STYLE = {"ok": None, "expected-failure": "yellow", "failed": "red",
                 "unexpected-pass": "red"}


def counts_text(failed: int, expected: int) -> str:
    """`` (2 failed, 8 failed as expected)``: the failures that count, then the documented
    ones; empty when there are none."""
    parts = ([f"{failed} failed"] if failed else []) + (
        [f"{expected} failed as expected"] if expected else [])
    return f" ({', '.join(parts)})" if parts else ""


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


def _outcome(res) -> str:
    """The run's outcome (``ok``, ``failed``, ``expected-failure``, ``unexpected-pass``);
    a record without one (a test's stand-in) by its status."""
    return getattr(res, "outcome", None) or ("ok" if res.status == "ok" else "failed")


def _counts_as_failure(res) -> bool:
    return _outcome(res) in ("failed", "unexpected-pass")


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
                 line=None, costs=None, heartbeat_s=None):
        self.cases = list(cases)
        self.total = len(self.cases)
        self.workers = max(1, int(workers or 1))
        self.stream = stream
        self.live = stream is not None and is_terminal(stream)
        #: the report's log (a :class:`Tee`'s file): the plain lines, also under the live
        #: display, which draws on the terminal only (never screen frames in the log)
        self.screen, self.log = screen_and_log(stream)
        #: each case's predicted cost (:func:`pdverify.schedule.case_costs`): ("known",
        #: its seconds in the previous report), ("size", the budget's size model in its
        #: own unit) or (None, None)
        self.costs = list(costs) if costs is not None else [(None, None)] * self.total
        self.heartbeat_s = heartbeat_interval() if heartbeat_s is None else heartbeat_s
        self._next_beat = time.monotonic() + self.heartbeat_s
        self._beats = None      # the heartbeat thread of the cluster path
        self.auto_refresh = auto_refresh
        self.line = line or (lambda k, res: describe(self.cases[k]))
        self.t0 = time.monotonic()
        self.done = 0
        #: runs that count as failures (:attr:`~pdverify.results.RunResult.counts_as_failure`)
        #: and documented failures that happened (``expected-failure``)
        self.failed = 0
        self.expected = 0
        self.in_flight: dict[int, float | None] = {}  # case index -> start time, if known
        self.durations: list[float] = []
        self._took: dict[int, float] = {}     # case index -> its run time
        self._lock = threading.Lock()
        self._live = None

    # -- the numbers --------------------------------------------------------------------
    def elapsed(self) -> float:
        return time.monotonic() - self.t0

    def predicted(self) -> list[float | None]:
        """Each case's predicted seconds from its cost (:attr:`costs`), calibrated by the
        finished runs (ratios of sums, so the long runs weigh most):

        - a previous or measured time ("known"): times the ratio of this report's to
          those times over the finished runs that have one (1 before any finished);
        - a cold reference's time ("reference": a run that computes its scene's
          reference, its measured time with a cold cache): times the same ratio, never
          part of it (on a warm cache the run takes a fraction of that time);
        - a size (the budget's model, in its own unit): times the seconds per unit of
          the finished runs of the same scene (a size is comparable within a scene only:
          across scenes, fixed costs that the model does not see dominate small runs);
        - otherwise, or before a run of that scene finished: the mean finished run time;
          None before any run finished."""
        known = [(self._took[k], c) for k, (kd, c) in enumerate(self.costs)
                 if kd == "known" and k in self._took and c]
        # the ratio starts from SPEED_PRIOR_S seconds at the predicted speed: the first
        # runs done are short ones, whose ratio alone says little
        speed = ((sum(t for t, _ in known) + SPEED_PRIOR_S)
                 / (sum(c for _, c in known) + SPEED_PRIOR_S))
        per_scene: dict[str, list[float]] = {}
        for k, (kind, cost) in enumerate(self.costs):
            if kind == "size" and k in self._took and cost:
                acc = per_scene.setdefault(self.cases[k][0], [0.0, 0.0])
                acc[0] += self._took[k]
                acc[1] += cost
        mean = sum(self.durations) / len(self.durations) if self.durations else None
        out = []
        for k, (kind, cost) in enumerate(self.costs):
            acc = per_scene.get(self.cases[k][0])
            if kind in ("known", "reference") and cost is not None:
                out.append(cost * speed)
            elif kind == "size" and cost and acc and acc[1] > 0:
                out.append(cost * acc[0] / acc[1])
            else:
                out.append(mean)
        return out

    def eta(self) -> float | None:
        """Seconds left: the predicted times (:meth:`predicted`) of the runs not started
        and what is left of those in flight, over the worker count (so it assumes that
        every worker stays busy), and at least what is left of the longest; None while
        nothing predicts the runs left."""
        pred = self.predicted()
        now = time.monotonic()
        left = longest = 0.0
        for k in range(self.total):
            if k in self._took:
                continue
            if pred[k] is None:
                return None
            start = self.in_flight.get(k)
            mine = max(pred[k] - (now - start if start is not None else 0.0), 0.0)
            left += mine
            longest = max(longest, mine)
        # a run is not shared out among workers: the report lasts at least its longest
        return max(left / self.workers, longest)

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
            self.failed += _counts_as_failure(res)
            self.expected += _outcome(res) == "expected-failure"
            took = (time.monotonic() - start if start is not None
                    else float(res.timings.get("total_s", 0.0) or 0.0))
            self.durations.append(took)
            self._took[k] = took
            self._next_beat = time.monotonic() + self.heartbeat_s
            done, eta, elapsed = self.done, self.eta(), self.elapsed()
        if self.stream is None:
            return
        text = f"[{done}/{self.total}] {self.line(k, res)}"
        plain = f"{text.rstrip()} | elapsed {clock(elapsed)}, ETA {clock(eta)}"
        if self._live is not None:
            from rich.text import Text
            self._live.console.print(Text(text, style=OUTCOME_STYLE.get(_outcome(res), "red")),
                                     soft_wrap=True)
            self._live.refresh()
            if self.log is not None:
                print(plain, file=self.log, flush=True)
        else:
            print(plain, file=self.stream, flush=True)

    def heartbeat(self) -> str:
        """``... running: scene method params 1:02, ... | 3/10 done, elapsed 2:00, ETA
        1:00``: the runs in flight and their time so far."""
        now = time.monotonic()
        with self._lock:
            flight = sorted(self.in_flight.items(), key=lambda kv: kv[1] or now)
            done, eta, elapsed = self.done, self.eta(), self.elapsed()
        runs = "; ".join(f"{describe(self.cases[k])} {clock(now - t)}" if t is not None
                         else f"{describe(self.cases[k])} (submitted)" for k, t in flight)
        return (f"... running: {runs or 'nothing'} | {done}/{self.total} done, elapsed "
                f"{clock(elapsed)}, ETA {clock(eta)}")

    def _beat_if_due(self) -> None:
        """Print a heartbeat on a non-terminal when :attr:`heartbeat_s` passed since the
        last line (a finished run or a heartbeat) and runs are in flight."""
        if self.stream is None or self.live or time.monotonic() < self._next_beat:
            return
        if self.in_flight:
            print(self.heartbeat(), file=self.stream, flush=True)
        self._next_beat = time.monotonic() + self.heartbeat_s

    def tick(self) -> None:
        """Redraw the live display (its clock moves even while no run finishes), or print
        a heartbeat line on a non-terminal when one is due."""
        if self._live is not None and not self.auto_refresh:
            self._live.refresh()
        elif not self.auto_refresh:
            self._beat_if_due()

    @property
    def tick_s(self) -> float | None:
        """How long the caller may block before calling :meth:`tick` (None: forever)."""
        if self._live is not None and not self.auto_refresh:
            return TICK_S
        if self.stream is not None and not self.live and not self.auto_refresh:
            return max(0.0, self._next_beat - time.monotonic())
        return None

    # -- the live display ---------------------------------------------------------------
    def __rich__(self):
        from rich.console import Group
        from rich.progress_bar import ProgressBar
        from rich.table import Table
        from rich.text import Text
        with self._lock:
            done, eta, elapsed = self.done, self.eta(), self.elapsed()
            counts = counts_text(self.failed, self.expected)
            flight = list(self.in_flight.items())
        now = time.monotonic()
        head = Table.grid(padding=(0, 1))
        head.add_row(ProgressBar(total=max(self.total, 1), completed=done, width=30),
                     Text(f"{done}/{self.total} runs{counts}"
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
            console = Console(file=self.screen, force_terminal=True)
            self._live = Live(self, console=console, auto_refresh=self.auto_refresh,
                              refresh_per_second=4, transient=False,
                              redirect_stdout=False, redirect_stderr=False)
            self._live.start(refresh=True)
        elif self.stream is not None and self.auto_refresh:
            # the cluster path blocks its main thread on the cluster: a thread beats
            stop = threading.Event()

            def beat():
                while not stop.wait(min(self.heartbeat_s, max(0.05, self._next_beat
                                                                - time.monotonic()))):
                    self._beat_if_due()
            thread = threading.Thread(target=beat, daemon=True, name="pdverify-heartbeat")
            self._beats = (stop, thread)
            thread.start()
        return self

    def __exit__(self, *exc):
        if self._beats is not None:
            stop, thread = self._beats
            stop.set()
            thread.join(timeout=1)
            self._beats = None
        live, self._live = self._live, None
        if live is not None:
            live.stop()  # also on Ctrl-C / SIGTERM: the final state, the cursor back
        return False
