"""Containment of plugin code (issue 50): a call into a plugin runs where its exit, a
signal it sends itself, a hang or an exception cannot end or stall pdverify.

- :func:`in_child` runs one call in a forked child process under the plugin time limit
  and hands back its value or what went wrong (raised, ended the process, killed by a
  signal, did not return in time). pdverify uses it for the calls it makes in its own
  process: the load of every entry point (:func:`probe`: one child tries them all, a new
  one takes over after a death) and the checks of a plugin's parameters and treatment.
- In a report's worker process (and ``run`` of a plugin method, which goes to one), the
  calls of the run itself (closure, the functions it hands the model, assembly) mark
  :data:`WATCH` while they run; the supervisor (:mod:`pdverify.runner`) kills a worker
  whose plugin call outlasts the limit and names the plugin when a worker dies inside one.

The limit: :func:`limit_s`, ``$PDVERIFY_PLUGIN_TIMEOUT`` seconds, default
:data:`DEFAULT_LIMIT_S`.
"""
from __future__ import annotations

import os
import pickle
import select
import signal
import sys
import time

#: seconds a single call into a plugin's code may take (its import, a check, its closure,
#: its assembly); ``$PDVERIFY_PLUGIN_TIMEOUT`` replaces it
DEFAULT_LIMIT_S = 60.0
ENV = "PDVERIFY_PLUGIN_TIMEOUT"


def limit_s() -> float:
    raw = os.environ.get(ENV)
    if raw:
        try:
            value = float(raw)
        except ValueError:
            value = -1.0
        if value > 0 and value < float("inf"):
            return value
        from ..errors import InputError
        raise InputError(f"${ENV}={raw!r} must be a positive number of seconds")
    return DEFAULT_LIMIT_S


def what_it_did(exc: BaseException) -> str:
    """``SystemExit(3)``, ``ValueError: bad factor``: the exception in one short phrase."""
    if isinstance(exc, SystemExit):
        return f"SystemExit({exc.code!r})"
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def how_it_ended(status: int) -> str:
    """``exit code 3``, ``signal SIGTERM``: a ``waitpid`` status as a phrase."""
    if os.WIFSIGNALED(status):
        n = os.WTERMSIG(status)
        try:
            return f"signal {signal.Signals(n).name}"
        except ValueError:
            return f"signal {n}"
    return f"exit code {os.WEXITSTATUS(status)}"


def _child_setup() -> None:
    """In a fresh child: default signal dispositions (the CLI's SIGTERM/SIGALRM handlers
    would unwind it into the parent's code), no Ctrl-C (the parent handles it), and the
    kernel ends it with the parent."""
    for sig in (signal.SIGTERM, signal.SIGALRM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        import ctypes
        ctypes.CDLL(None).prctl(1, int(signal.SIGKILL))    # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _fork():
    sys.stdout.flush()
    sys.stderr.flush()
    r, w = os.pipe()
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        pid = os.fork()
    except BaseException:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
        os.close(r)
        os.close(w)
        raise
    if pid == 0:
        os.close(r)
        _child_setup()
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
        return 0, w
    signal.pthread_sigmask(signal.SIG_SETMASK, old)
    os.close(w)
    return pid, r


def _send(w: int, item) -> None:
    data = pickle.dumps(item)
    os.write(w, len(data).to_bytes(8, "little"))
    view = memoryview(data)
    while view:
        n = os.write(w, view)
        view = view[n:]


class _Reader:
    """The parent's end of a child's pipe: whole pickled items, each by a deadline."""

    def __init__(self, fd: int):
        self.fd, self.buf, self.eof = fd, b"", False

    def item(self, deadline: float):
        """The next item; ``EOFError`` when the child closed the pipe (ended),
        ``TimeoutError`` past ``deadline``."""
        while True:
            if len(self.buf) >= 8:
                size = int.from_bytes(self.buf[:8], "little")
                if len(self.buf) >= 8 + size:
                    data, self.buf = self.buf[8:8 + size], self.buf[8 + size:]
                    return pickle.loads(data)
            if self.eof:
                raise EOFError
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError
            ready, _, _ = select.select([self.fd], [], [], left)
            if ready:
                chunk = os.read(self.fd, 1 << 16)
                if chunk:
                    self.buf += chunk
                else:
                    self.eof = True


def _end(pid: int, kill: bool) -> int:
    if kill:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return os.waitpid(pid, 0)[1]


def _outcome(fn, args):
    from ..errors import InputError
    try:
        return ("ok", fn(*args))
    except BaseException as exc:  # anything the call does is reported, never raised here
        return ("raised", isinstance(exc, InputError), what_it_did(exc), str(exc))


def in_child(fn, args=(), limit: float | None = None):
    """``fn(*args)`` in a forked child within ``limit`` seconds (default :func:`limit_s`):
    ``("ok", value)``, ``("raised", is_input_error, phrase, message)``,
    ``("ended", how)`` (exit or signal, no answer) or ``("hung", seconds)``. The value
    must pickle (else it is reported as raised)."""
    limit = limit_s() if limit is None else limit
    pid, fd = _fork()
    if pid == 0:                                         # the child
        code = 0
        try:
            item = _outcome(fn, args)
            try:
                _send(fd, item)
            except Exception as exc:  # the value does not pickle
                _send(fd, ("raised", False, f"its value cannot be passed back ({exc})",
                           str(exc)))
        except BaseException:
            code = 70
        os._exit(code)
    reader = _Reader(fd)
    try:
        item = reader.item(time.monotonic() + limit)
        _end(pid, kill=False)
        return item
    except EOFError:
        return ("ended", how_it_ended(_end(pid, kill=False)))
    except TimeoutError:
        _end(pid, kill=True)
        return ("hung", limit)
    except BaseException:  # Ctrl-C / SIGTERM while waiting: end the child, then unwind
        _end(pid, kill=True)
        raise
    finally:
        os.close(fd)


def probe(count: int, try_one, limit: float | None = None):
    """Try ``try_one(i)`` for ``i`` in ``range(count)`` in forked children (one for all,
    a new one after a death or a hang), each within ``limit`` seconds. Returns
    ``(answers, failures)`` by index: what ``try_one`` returned (it must pickle; a raise
    is ``("problem", phrase)``), and how an entry ended or stalled its child."""
    limit = limit_s() if limit is None else limit
    problems: dict[int, object] = {}
    failures: dict[int, str] = {}
    i = 0
    while i < count:
        pid, fd = _fork()
        if pid == 0:                                     # the child: quiet, every entry
            code = 0
            try:
                null = os.open(os.devnull, os.O_WRONLY)
                os.dup2(null, 1)
                os.dup2(null, 2)
                for k in range(i, count):
                    _send(fd, ("start", k))
                    item = _outcome(try_one, (k,))
                    answer = item[1] if item[0] == "ok" else ("problem", item[2])
                    try:
                        pickle.dumps(answer)
                    except Exception as exc:  # noqa: BLE001  (a value that does not pickle)
                        answer = ("problem", "its answers cannot be passed between "
                                             f"processes ({what_it_did(exc)})")
                    _send(fd, ("done", k, answer))
            except BaseException:
                code = 70
            os._exit(code)
        reader = _Reader(fd)
        current, start = None, time.monotonic()
        try:
            while True:
                try:
                    item = reader.item((start if current is not None
                                        else time.monotonic()) + limit)
                except EOFError:
                    status = _end(pid, kill=False)
                    if current is not None:
                        failures[current] = f"ended the process ({how_it_ended(status)})"
                        i = current + 1
                    else:
                        i = count
                    break
                except TimeoutError:
                    _end(pid, kill=True)
                    k = i if current is None else current
                    failures[k] = (f"did not return within {limit:g} s (the plugin time "
                                   f"limit, ${ENV}); its process was killed")
                    i = k + 1
                    break
                if item[0] == "start":
                    current, start = item[1], time.monotonic()
                else:
                    problems[item[1]] = item[2]
                    current = None
                    if item[1] == count - 1:
                        _end(pid, kill=False)
                        i = count
                        break
        except BaseException:
            _end(pid, kill=True)
            raise
        finally:
            os.close(fd)
    return problems, failures


#: in a worker process: shared memory the supervisor reads, ``(start time, text)`` of
#: the plugin call in progress (start 0: none); set by :func:`watching`
WATCH = None


def watch_buffers(ctx):
    """Shared memory for one worker's :data:`WATCH`: a start time and 240 bytes of text."""
    return ctx.RawArray("d", 1), ctx.RawArray("c", 240)


def watching(who_what: str):
    """Mark a plugin call in :data:`WATCH` (a no-op outside a worker); returns the
    previous mark, to be given back to :func:`unwatch`."""
    if WATCH is None:
        return None
    t, text = WATCH
    prev = (t[0], text.value)
    text.value = who_what.encode("utf-8", "replace")[:239]
    t[0] = time.monotonic()
    return prev


def unwatch(prev) -> None:
    if WATCH is None or prev is None:
        return
    t, text = WATCH
    text.value = prev[1]
    t[0] = prev[0]


def watched(buffers) -> tuple[float, str] | None:
    """The supervisor's view of a worker's buffers: ``(start, text)`` of the plugin call
    in progress, or None."""
    t, text = buffers
    if t[0] <= 0:
        return None
    return t[0], text.value.decode("utf-8", "replace")
