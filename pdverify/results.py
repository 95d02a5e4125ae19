"""The result record of one (scene, method, params) run and its JSON (pdverify.results/1)."""
from __future__ import annotations

import json
import os
import platform
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import Any

import numpy as np

SCHEMA = "pdverify.results/1"
#: the JSON Schema of :data:`SCHEMA`, published with the package for other tools
SCHEMA_FILE = os.path.join(os.path.dirname(__file__), "schema", "results-1.schema.json")


@dataclass
class RunResult:
    """One run. ``fields`` holds arrays for figures and is never written to JSON."""

    scene: str
    method: str
    params: dict
    reference: str
    status: str = "ok"
    message: str = ""
    metrics: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    size: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    fields: dict = field(default_factory=dict, repr=False)
    #: files written from ``fields`` (VTU, relative to the report folder), if any
    files: list = field(default_factory=list)
    #: why this run is expected to fail (a documented finding, like pytest's strict
    #: xfail); empty when it is expected to succeed
    expected_failure: str = ""
    #: the papers' numbers for this method and these params (:mod:`pdverify.published`)
    published: list = field(default_factory=list)
    #: what the run cost beside its time, not reproducible bit for bit (like
    #: ``timings``): ``peak_rss_gb``, the peak resident size of the process that ran it,
    #: from the run's start (:func:`pdverify.budget.reset_peak_rss`; Linux only)
    resources: dict = field(default_factory=dict)

    @property
    def key(self) -> tuple:
        return run_key(self.scene, self.method, self.params)

    @property
    def outcome(self) -> str:
        """``ok``, ``failed``, ``expected-failure`` (failed, as documented) or
        ``unexpected-pass`` (ok although a failure is documented: the finding is out of
        date, strict like pytest's xfail)."""
        return outcome(self.status, self.expected_failure)

    @property
    def counts_as_failure(self) -> bool:
        """What makes ``run`` and ``report`` exit 1: an unexpected failure, or an expected
        failure that did not happen."""
        return self.outcome in ("failed", "unexpected-pass")

    def to_json(self) -> dict:
        return {
            "scene": self.scene,
            "method": self.method,
            "params": _plain(self.params),
            "reference": self.reference,
            "status": self.status,
            "message": self.message,
            "metrics": _plain(self.metrics),
            "timings": _plain(self.timings),
            "size": _plain(self.size),
            "diagnostics": _plain(self.diagnostics),
            "warnings": list(self.warnings),
            **({"files": list(self.files)} if self.files else {}),
            **({"expected_failure": self.expected_failure} if self.expected_failure else {}),
            **({"published": _plain(self.published)} if self.published else {}),
            **({"resources": _plain(self.resources)} if self.resources else {}),
        }

    @classmethod
    def from_json(cls, run: dict) -> "RunResult":
        """A run as results.json holds it (no ``fields``: those are never written)."""
        return cls(scene=run["scene"], method=run["method"], params=dict(run["params"]),
                   reference=run.get("reference", ""), status=run["status"],
                   message=run.get("message", ""), metrics=dict(run["metrics"]),
                   timings=dict(run.get("timings", {})), size=dict(run.get("size", {})),
                   diagnostics=dict(run.get("diagnostics", {})),
                   warnings=list(run.get("warnings", [])), files=list(run.get("files", [])),
                   expected_failure=run.get("expected_failure", ""),
                   resources=dict(run.get("resources", {})))


OUTCOMES = ("ok", "failed", "expected-failure", "unexpected-pass")


def outcome(status: str, expected_failure: str) -> str:
    """The outcome of a run from its status and its documented expectation."""
    if not expected_failure:
        return status
    return "expected-failure" if status == "failed" else "unexpected-pass"


def run_key(scene: str, method: str, params: dict) -> tuple:
    """Identity of a run across result files: scene, method and canonical params."""
    return scene, method, json.dumps(_plain(params), sort_keys=True)


#: The timing of setup work a run read from pdverify's cache instead of doing it: the
#: seconds that work took when it was computed (perifit's weights: its CPU seconds on
#: one thread). Part of the run's cost
#: (:func:`cost_s`), so that a warm cache does not make a method look cheaper than it is.
CACHED_SETUP = "cached_setup_s"


def cost_s(timings: dict) -> float:
    """A run's cost: its setup and solve time plus the setup it read from the cache at
    the time that took (:data:`CACHED_SETUP`); the metrics and fields computed afterwards
    are not counted (``total_s`` includes them)."""
    return sum(float(timings.get(k, 0.0) or 0.0) for k in ("setup_s", "solve_s", CACHED_SETUP))


def time_s(timings: dict):
    """A run's time as the report shows it: ``total_s`` and the setup it read from the
    cache at the time that took (:data:`CACHED_SETUP`); ``total_s`` as it is (None if
    absent, text for an external run) when nothing came from the cache."""
    total, cached = timings.get("total_s"), timings.get(CACHED_SETUP)
    return total + cached if cached and total is not None else total


#: The collectors of the runs in progress in this process (innermost last): what code deep
#: inside a run reports beside its metrics (:func:`note`), merged into its result by
#: :meth:`pdverify.scenes.base.Scene.run`.
_NOTES: list[dict] = []


@contextmanager
def collecting_notes():
    """Collect :func:`note` calls of the code run inside: yields ``{"diagnostics": {},
    "timings": {}}``."""
    notes: dict = {"diagnostics": {}, "timings": {}}
    _NOTES.append(notes)
    try:
        yield notes
    finally:
        _NOTES.pop()


def note(diagnostics: dict | None = None, timings: dict | None = None) -> None:
    """Report facts (``diagnostics``) and seconds (``timings``, summed per key) to the run
    in progress; outside a run (:func:`collecting_notes`) nothing happens."""
    if not _NOTES:
        return
    notes = _NOTES[-1]
    notes["diagnostics"].update(diagnostics or {})
    for k, v in (timings or {}).items():
        notes["timings"][k] = notes["timings"].get(k, 0.0) + float(v)


class Timer:
    """Accumulates wall time per phase (``setup``, ``solve``) of one run."""

    def __init__(self):
        self.phases: dict[str, float] = {}
        self._start = time.perf_counter()

    @contextmanager
    def phase(self, name: str):
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.phases[name] = self.phases.get(name, 0.0) + time.perf_counter() - t0

    def as_dict(self) -> dict:
        out = {f"{k}_s": v for k, v in self.phases.items()}
        out.setdefault("setup_s", 0.0)
        out.setdefault("solve_s", 0.0)
        out["total_s"] = time.perf_counter() - self._start
        return out


def _plain(value: Any) -> Any:
    """JSON-ready copy: numpy scalars to Python, non-finite floats to strings."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, (np.floating, float)):
        v = float(value)
        if v != v or v in (float("inf"), float("-inf")):
            return str(v)
        return v
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


#: the libraries whose versions decide whether two machines' numbers agree bit for bit
#: (recorded in ``machine.libraries``; a missing one is "not installed")
LIBRARIES = ("numpy", "scipy", "scikit-fem", "meshio", "pyvista")


def library_versions() -> dict:
    """The installed versions of :data:`LIBRARIES` (package metadata: no import)."""
    from importlib.metadata import PackageNotFoundError, version
    out = {}
    for name in LIBRARIES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def blas_info() -> list[dict]:
    """The BLAS/LAPACK libraries numpy and scipy call: through threadpoolctl when it is
    importable (what is loaded: library, version, threading layer, threads), else from
    numpy's build configuration (what numpy was built against), marked by ``source``."""
    try:
        from threadpoolctl import threadpool_info
    except ImportError:
        threadpool_info = None
    if threadpool_info is not None:
        return [{"source": "threadpoolctl", "api": i.get("internal_api"),
                 "version": i.get("version"), "threading_layer": i.get("threading_layer"),
                 "num_threads": i.get("num_threads"), "library": os.path.basename(
                     i.get("filepath") or "")}
                for i in threadpool_info() if i.get("user_api") == "blas"]
    out = []
    try:
        config = np.show_config(mode="dicts")
        deps = config.get("Build Dependencies", {})
        for part in ("blas", "lapack"):
            d = deps.get(part) or {}
            out.append({"source": "numpy build config (threadpoolctl unavailable)",
                        "api": part, "library": d.get("name"), "version": d.get("version")})
    except Exception as exc:  # an older numpy without mode="dicts"
        out.append({"source": "unavailable", "reason": f"{type(exc).__name__}: {exc}"})
    return out


def machine_info() -> dict:
    return {"python": platform.python_version(), "platform": platform.platform(),
            "cpus": os.cpu_count(), "libraries": library_versions(), "blas": blas_info()}


def document(runs: list[RunResult], extra: dict | None = None) -> dict:
    """The results document; ``extra``: further top-level sections (e.g. the report's
    ``convergence`` studies), written after ``runs``."""
    from . import __version__
    return {
        "schema": SCHEMA,
        "pdverify_version": __version__,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "machine": machine_info(),
        "runs": [r.to_json() for r in runs],
        **{k: _plain(v) for k, v in (extra or {}).items()},
    }


def umask_mode(mode: int) -> int:
    """``mode`` under the process umask (what ``open`` would give a new file or folder)."""
    current = os.umask(0)
    os.umask(current)
    return mode & ~current


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` so that a reader sees the old file or the new, never half.

    The file gets the usual permissions (0666 under the umask), not mkstemp's 0600."""
    atomic_write(path, lambda fh: fh.write(text), binary=False)


def atomic_write(path: str | os.PathLike, write, *, binary: bool = True) -> None:
    """Write ``path`` by ``write(fh)`` (a binary file object, or text in UTF-8 when not
    ``binary``) so that a reader sees the old file or the new, never half; the usual
    permissions (0666 under the umask). An error leaves no temporary file and is raised."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", dir=folder)
    try:
        with (os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", encoding="utf-8")) as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, umask_mode(0o666))
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_results(path, runs: list[RunResult], extra: dict | None = None) -> dict:
    """Write the results document atomically; a file that cannot be written (disk full,
    read-only) raises :class:`~pdverify.errors.OutputError` naming it, the old file kept."""
    doc = document(runs, extra)
    text = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        from .errors import OutputError
        raise OutputError(f"cannot write {os.fspath(path)!r} ({exc.strerror or exc})") from exc
    return doc


#: What a run of pdverify.results/1 must hold (key -> allowed types), and may hold.
_RUN_FIELDS = {"scene": (str,), "method": (str,), "params": (dict,), "status": (str,),
               "metrics": (dict,)}
_OPTIONAL_RUN_FIELDS = {"reference": (str,), "message": (str,), "timings": (dict,),
                        "size": (dict,), "diagnostics": (dict,), "warnings": (list,),
                        "files": (list,), "expected_failure": (str,), "published": (list,)}
_TYPE_NAMES = {str: "a string", dict: "an object", list: "a list"}


def check_schema(doc, path) -> None:
    """Raise ValueError naming ``path`` and the first field that breaks pdverify.results/1."""
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise ValueError(f"{path}: schema is {doc.get('schema') if isinstance(doc, dict) else None!r}, "
                         f"expected {SCHEMA!r}")
    if not isinstance(doc.get("runs"), list):
        raise ValueError(f"{path}: 'runs' must be a list")
    for k, run in enumerate(doc["runs"]):
        if not isinstance(run, dict):
            raise ValueError(f"{path}: runs[{k}] must be an object, got {type(run).__name__}")
        for name in _RUN_FIELDS:
            if name not in run:
                raise ValueError(f"{path}: runs[{k}] has no {name!r}")
        for name, types in {**_RUN_FIELDS, **_OPTIONAL_RUN_FIELDS}.items():
            if name in run and not isinstance(run[name], types):
                raise ValueError(f"{path}: runs[{k}].{name} must be {_TYPE_NAMES[types[0]]}, "
                                 f"got {type(run[name]).__name__}")
        if run["status"] not in ("ok", "failed"):
            raise ValueError(f"{path}: runs[{k}].status must be 'ok' or 'failed', "
                             f"got {run['status']!r}")
        _check_values(run, f"{path}: runs[{k}]")
        if "published" in run:
            from .published import check_entry
            for j, entry in enumerate(run["published"]):
                check_entry(entry, f"{path}: runs[{k}].published[{j}]")
        for name, v in run["metrics"].items():
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                raise ValueError(f"{path}: runs[{k}].metrics.{name} must be a number or a "
                                 f"string, got {type(v).__name__}")
            if isinstance(v, int) and abs(v) > _FLOAT_MAX:
                raise ValueError(f"{path}: runs[{k}].metrics.{name} is an integer of "
                                 f"{len(str(abs(v)))} digits, beyond the range of a float")


_FLOAT_MAX = 1.7976931348623157e308
#: How deep a run's values may nest (pdverify writes at most a few levels).
MAX_DEPTH = 32


def _check_values(run: dict, where: str) -> None:
    """Every string of ``run`` (keys included) is valid Unicode (no lone surrogate, which
    no file can be printed or written with) and nothing nests deeper than MAX_DEPTH."""
    stack = [(run, 0, "")]
    while stack:
        value, depth, at = stack.pop()
        if depth > MAX_DEPTH:
            raise ValueError(f"{where}{at} nests deeper than {MAX_DEPTH} levels")
        items = (value.items() if isinstance(value, dict)
                 else enumerate(value) if isinstance(value, list) else None)
        if items is None:
            if isinstance(value, str):
                _check_text(value, f"{where}{at}")
            continue
        for key, v in items:
            if isinstance(key, str):
                _check_text(key, f"{where}{at}: a key")
            stack.append((v, depth + 1, f"{at}.{key}" if isinstance(key, str)
                          else f"{at}[{key}]"))


def _check_text(text: str, where: str) -> None:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise ValueError(f"{where.encode('utf-8', 'backslashreplace').decode()} holds a lone "
                         f"surrogate {text[exc.start]!r} (not valid Unicode)") from None


def load_results(path) -> dict:
    """Read a results file and check its schema; raises ValueError with the reason."""
    try:
        with open(path, encoding="utf-8") as fh:
            doc = json.load(fh)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: not valid JSON ({exc.msg} at line {exc.lineno})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text (UTF-8) file") from None
    except RecursionError:
        raise ValueError(f"{path}: JSON nested too deeply to read (a results file nests "
                         f"at most a few levels)") from None
    except ValueError as exc:  # e.g. an integer of more than 4300 digits
        raise ValueError(f"{path}: not a results file ({str(exc).splitlines()[0]})") from None
    check_schema(doc, path)
    return doc
