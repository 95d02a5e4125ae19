"""On-disk cache of converged references, keyed by a hash of everything that defines them."""
from __future__ import annotations

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
    if use_cache and path.is_file():
        try:
            res = results.from_npz(path, classes)
            if res.cache_key == key:
                return dataclasses.replace(res, from_cache=True)
        except Exception:  # noqa: BLE001 - any unreadable entry is a miss (BadZipFile, EOFError, ...)
            pass
    res = dataclasses.replace(compute(), cache_key=key, from_cache=False)
    if use_cache:
        path.parent.mkdir(parents=True, exist_ok=True)
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
