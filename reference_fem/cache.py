"""On-disk cache of converged references, keyed by a hash of everything that defines them."""
from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Callable

from . import results

ENV_VAR = "PDVERIFY_CACHE_DIR"
_PACKAGE_DIR = Path(__file__).resolve().parent


def cache_dir() -> Path:
    """Cache folder: ``$PDVERIFY_CACHE_DIR`` if set, else
    ``$XDG_CACHE_HOME/pdverify/reference_fem`` (default ``~/.cache/pdverify/reference_fem``)."""
    env = os.environ.get(ENV_VAR)
    if env:
        return Path(env).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "pdverify" / "reference_fem"


def _source_digest() -> str:
    """Digest of the package's own source, so a code change invalidates the cache even
    when the version string was not bumped."""
    h = hashlib.sha256()
    for p in sorted(_PACKAGE_DIR.glob("*.py")):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def cache_key(reference: str, params: dict) -> str:
    """SHA-256 over the reference id, every parameter (canonical JSON; floats by repr),
    the package version, scikit-fem's version and the package source."""
    import skfem

    from . import __version__

    payload = json.dumps({"reference": reference, "params": params, "version": __version__,
                          "skfem": skfem.__version__, "source": _source_digest()},
                         sort_keys=True, allow_nan=True)
    return hashlib.sha256(payload.encode()).hexdigest()


def cached(reference: str, params: dict, compute: Callable[[], results.ReferenceResult],
           classes: dict, use_cache: bool = True) -> results.ReferenceResult:
    """Return the cached result for (reference, params) or compute, store and return it.

    The file is written to a temporary name and renamed, so parallel runs never read a
    partial file. Any entry that cannot be read back whole (truncated, empty, corrupted,
    or content that no longer matches its checksum) is a miss: recomputed and replaced.
    """
    key = cache_key(reference, params)
    path = cache_dir() / f"{reference}-{key[:24]}.npz"
    if not use_cache:
        return dataclasses.replace(compute(), cache_key=key, from_cache=False)
    hit = _read(path, key, classes)
    if hit is not None:
        return hit
    path.parent.mkdir(parents=True, exist_ok=True)
    with _key_lock(path):
        # a process that held the lock may have computed it meanwhile: one study per key,
        # however many runs of a report need it at once
        hit = _read(path, key, classes)
        if hit is not None:
            return hit
        res = dataclasses.replace(compute(), cache_key=key, from_cache=False)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp.npz")
        os.close(fd)
        try:
            results.to_npz(res, Path(tmp))
            os.chmod(tmp, 0o644)  # mkstemp creates 0600; the cache is plain shared data
            # the temporary name ends in .npz, so np.savez writes exactly that file
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return res


def _read(path: Path, key: str, classes: dict):
    """The cached result at ``path`` if it reads back whole and carries ``key``, else
    None (a miss)."""
    if not path.is_file():
        return None
    try:
        res = results.from_npz(path, classes)
        if res.cache_key == key:
            return dataclasses.replace(res, from_cache=True)
    except Exception:  # noqa: BLE001 - any unreadable entry is a miss (BadZipFile, EOFError, ...)
        pass
    return None


@contextlib.contextmanager
def _key_lock(path: Path):
    """An exclusive lock on ``path``'s key while its reference is computed, so that two
    runs needing the same reference at once (a report's workers: the FEM run and a PD run
    of the same scene) compute it once; the other waits, then reads it. The lock file
    (``<entry>.lock``, empty) stays in the cache folder; the kernel releases the lock
    when its process ends, however it ends. Without ``fcntl`` (not POSIX): no lock."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    with open(path.parent / (path.name + ".lock"), "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)
