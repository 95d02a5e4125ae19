"""Every field of a run as VTU files that ParaView, meshio and pyvista open.

A run's ``fields`` (:class:`pdverify.results.RunResult`) hold numpy arrays keyed by name.
They become VTU files by these rules, which cover every scene's fields:

- each node set ``x`` (or ``x_<s>``, e.g. the three bars of ``bar1d-constraints``) is a
  point cloud with one vertex cell per node; 1D and 2D positions get zero trailing
  coordinates;
- an array whose first axis has that set's length (``u``, ``u_ref``, ``error`` ...; for
  ``x_<s>``, the arrays ending in ``_<s>``) is point data: vectors with up to 3
  components are padded to 3, wider arrays are split by column (``name_0``, ...);
- an array of shape (T, N) next to a ``times`` or ``t`` array of length T (the wave's
  snapshots) is point data per time, ``name_t0`` ... ``name_t{T-1}``;
- the FEM reference's sampled ``grid`` (``x``, ``y`` and fields of one 2D shape) is a
  structured quadrilateral mesh of its own (``<stem>-fem-grid.vtu``);
- the run's numeric metrics are field data ``metric:<name>``; other arrays and numbers
  (load curves, horizon, spacing) are field data under their own names. Strings, lists
  of records and nested dicts other than ``grid`` are not written (the refinement table
  is in the report and ``results.json``).

No drawing, no printing: the report and ``run --vtu`` call :func:`write_run_fields`.
"""
from __future__ import annotations

import os
from xml.sax.saxutils import escape

import numpy as np

from .results import umask_mode


def _pad3(points: np.ndarray) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    p = p.reshape(len(p), -1)
    return np.hstack([p, np.zeros((len(p), 3 - p.shape[1]))]) if p.shape[1] < 3 else p


def _point_arrays(name: str, a: np.ndarray, n: int, times) -> dict:
    """``a`` as point data of a set of ``n`` nodes, or {} if it is not one."""
    if not isinstance(a, np.ndarray) or a.dtype.kind not in "biuf" or a.ndim == 0:
        return {}
    a = a.astype(float)
    if a.shape[0] == n and a.ndim == 1:
        return {name: a}
    if a.shape[0] == n and a.ndim == 2:
        if a.shape[1] <= 3:
            return {name: _pad3(a)}
        return {f"{name}_{k}": a[:, k] for k in range(a.shape[1])}
    if a.ndim == 2 and a.shape[1] == n and times is not None and a.shape[0] == len(times):
        return {f"{name}_t{k}": a[k] for k in range(a.shape[0])}
    return {}


def _field_data(fields: dict, used: set, metrics: dict) -> dict:
    out = {}
    for k, v in metrics.items():
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            out[f"metric:{k}"] = np.array([float(v)])
    for k, v in fields.items():
        if k in used:
            continue
        if isinstance(v, np.ndarray) and v.dtype.kind in "biuf":
            out[k] = v.astype(float).ravel()
        elif isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool):
            out[k] = np.array([float(v)])
        elif isinstance(v, tuple) and all(isinstance(e, (int, float)) for e in v) and v:
            out[k] = np.array(v, dtype=float)
    return out


def meshes(result) -> list[tuple[str, object]]:
    """The run's fields as ``(suffix, meshio.Mesh)`` pairs (suffix '' for the main node
    set); [] for a run without node fields."""
    import meshio
    f = result.fields or {}
    time_key = next((k for k in ("times", "t")
                     if isinstance(f.get(k), np.ndarray) and f[k].ndim == 1), None)
    times = f[time_key] if time_key else None
    sets = sorted(k for k in f if (k == "x" or k.startswith("x_"))
                  and isinstance(f[k], np.ndarray) and f[k].ndim in (1, 2)
                  and f[k].dtype.kind == "f")
    out, used = [], set(sets) | ({time_key} if time_key else set())
    groups = []
    for key in sets:
        suffix = key[1:]                        # '' or '_a'
        x = f[key]
        n = len(x)
        data = {}
        for name, a in f.items():
            if name in used:
                continue
            if suffix and not name.endswith(suffix):
                continue
            if not suffix and any(name.endswith(s[1:]) for s in sets if s != "x"):
                continue
            arrays = _point_arrays(name[: len(name) - len(suffix)] if suffix else name,
                                   a, n, times)
            if arrays:
                data.update(arrays)
                used.add(name)
        groups.append((suffix, x, data))
    grid = f.get("grid")
    if isinstance(grid, dict):
        used.add("grid")
    common = _field_data(f, used, result.metrics)
    for suffix, x, data in groups:
        pts = _pad3(x)
        cells = [("vertex", np.arange(len(pts)).reshape(-1, 1))]
        out.append((suffix, meshio.Mesh(pts, cells, point_data=data, field_data=common)))
    if isinstance(grid, dict) and "x" in grid and "y" in grid:
        out.append(("-fem-grid", _grid_mesh(grid, common)))
    return out


def _grid_mesh(grid: dict, field_data: dict):
    """The FEM reference sampled on a structured 2D grid, as quadrilaterals."""
    import meshio
    gx, gy = np.asarray(grid["x"], float), np.asarray(grid["y"], float)
    nx, ny = gx.shape
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    idx = np.arange(gx.size).reshape(nx, ny)
    quads = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(),
                             idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    data = {k: np.asarray(v, float).ravel() for k, v in grid.items()
            if k not in ("x", "y") and np.shape(v) == gx.shape}
    return meshio.Mesh(pts, [("quad", quads)], point_data=data, field_data=field_data)


def write_run_fields(result, stem: str) -> list[str]:
    """Write ``stem<suffix>.vtu`` for each mesh of the run; returns the paths written.

    A file that cannot be written (disk full, read-only) raises
    :class:`~pdverify.errors.OutputError` naming it."""
    import meshio
    paths = []
    path = stem
    try:
        os.makedirs(os.path.dirname(os.path.abspath(stem)), exist_ok=True)
        for suffix, mesh in meshes(result):
            path = f"{stem}{suffix}.vtu"
            meshio.write(path, mesh, file_format="vtu")
            _add_field_data(path, mesh.field_data)
            os.chmod(path, umask_mode(0o666))
            paths.append(path)
    except OSError as exc:
        from .errors import OutputError
        raise OutputError(f"cannot write {path!r} ({exc.strerror or exc})") from exc
    return paths


def _add_field_data(path: str, field_data: dict) -> None:
    """meshio 5 reads a VTU's ``<FieldData>`` but does not write it: add the block after
    ``<UnstructuredGrid>``, as ASCII Float64 with 17 significant digits (exact). The
    comment :data:`pdverify.outputs.VTU_MARK` goes first, so that a later ``--vtu`` may
    replace the file as pdverify's own."""
    from .outputs import VTU_MARK
    arrays = "".join(
        f'<DataArray type="Float64" Name="{escape(name, {chr(34): "&quot;"})}" '
        f'NumberOfTuples="{len(v)}" format="ascii">'
        + " ".join(repr(float(x)) for x in np.ravel(v)) + "</DataArray>\n"
        for name, v in field_data.items())
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    tag = "<UnstructuredGrid>"
    if text.count(tag) != 1:
        raise ValueError(f"{path}: unexpected VTU layout from meshio (no single {tag})")
    if arrays:
        text = text.replace(tag, f"{tag}\n<FieldData>\n{arrays}</FieldData>", 1)
    decl, sep, rest = text.partition("\n")
    if not decl.startswith("<?xml"):
        raise ValueError(f"{path}: unexpected VTU layout from meshio (no XML declaration)")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(f"{decl}\n{VTU_MARK} -->\n{rest}")
