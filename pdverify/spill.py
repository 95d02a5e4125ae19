"""A report's run fields on disk instead of in the report process (issue 32).

A report collects hundreds of runs; their ``fields`` (node coordinates, displacements,
errors, energies, load curves) are read only by the figures, the scene pages and the VTU
export, one scene or one run at a time. (Measured: up to about 1 MB pickled per run, for
block2d-indentation; 16 MB over the 319 runs of ``report --quick``:
``benchmarks/report_cost.py``.)
As each result arrives from its worker, :meth:`Spill.spill` writes its fields once
into a folder of the report's own staging folder and puts a :class:`SpilledFields`
in their place: a read-only mapping with the same keys, which loads the file on first
access and keeps it until :func:`release`. The report releases the fields of a scene
once its figures or its section are done and those of a run once its VTU files are
written, so that the report process holds the fields of one scene at most. The values
come back as they were pickled (numpy arrays bit for bit), so the outputs are the same.

No drawing, no printing.
"""
from __future__ import annotations

import os
import pickle
import shutil
from collections.abc import Mapping

#: the spill folder's name inside a report's staging folder; the ``.tmp-`` prefix makes a
#: killed report's staging folder still pdverify's own leftover
#: (:func:`pdverify.outputs.is_own_leftover`)
FOLDER = ".tmp-fields-spill"


class SpilledFields(Mapping):
    """A run's fields in a file: the keys at hand, the values loaded on first access and
    kept until :meth:`release`. Truthy when the fields were not empty (as the dict was)."""

    __slots__ = ("path", "_keys", "_data")

    def __init__(self, path: str, keys):
        self.path = path
        self._keys = tuple(keys)
        self._data = None

    def _load(self) -> dict:
        if self._data is None:
            with open(self.path, "rb") as fh:
                self._data = pickle.load(fh)
        return self._data

    def __getitem__(self, key):
        if key not in self._keys:
            raise KeyError(key)
        return self._load()[key]

    def __contains__(self, key) -> bool:
        return key in self._keys

    def __iter__(self):
        return iter(self._keys)

    def __len__(self) -> int:
        return len(self._keys)

    @property
    def loaded(self) -> bool:
        return self._data is not None

    def release(self) -> None:
        """Drop the loaded values; the next access loads the file again."""
        self._data = None

    def __repr__(self) -> str:
        return f"SpilledFields({self.path!r}, {len(self._keys)} keys)"


def release(results) -> None:
    """Drop the loaded fields of every spilled run of ``results``."""
    for r in results:
        if isinstance(r.fields, SpilledFields):
            r.fields.release()


class Spill:
    """The spill folder ``folder/FOLDER``, created on the first :meth:`spill` and removed
    with every file in it by :meth:`close` (it holds only what this object wrote)."""

    def __init__(self, folder: str):
        self.folder = os.path.join(folder, FOLDER)
        self._count = 0

    def spill(self, result):
        """Write ``result.fields`` (if any) to a file and put a :class:`SpilledFields` in
        their place; returns ``result``."""
        fields = result.fields
        if not fields or isinstance(fields, SpilledFields):
            return result
        path = os.path.join(self.folder, f"{self._count:05d}.pickle")
        try:
            if self._count == 0:
                os.makedirs(self.folder, mode=0o700, exist_ok=False)
            self._count += 1
            with open(path, "xb") as fh:
                pickle.dump(fields, fh, protocol=pickle.HIGHEST_PROTOCOL)
        except OSError as exc:
            from .errors import OutputError
            raise OutputError(f"cannot set a run's fields aside in {path!r} "
                              f"({exc.strerror or exc})") from exc
        result.fields = SpilledFields(path, fields.keys())
        return result

    def close(self) -> None:
        if self._count:
            shutil.rmtree(self.folder, ignore_errors=True)
        self._count = 0
