"""Result records of the FEM references: refinement rows, converged results, (de)serialisation."""
from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .field import FieldSolution
from .mesh_field import MeshField
from .solid3d import TetField

#: the arrays of a MeshField, stored as ``<name>.<array>``
_MESH_FIELD_ARRAYS = ("node_coords", "elements", "values", "box", "disks", "rects")
#: the arrays of a TetField (3D), stored as ``<name>.<array>``
_TET_FIELD_ARRAYS = ("node_coords", "elements", "values")


@dataclass(frozen=True)
class RefinementRow:
    """One level of a refinement study.

    Attributes
    ----------
    level : 0 = coarsest.
    dofs : number of degrees of freedom (before condensation).
    h_min : smallest element edge (m).
    quantity : the compared quantity at this level (unit of the result's ``quantity``).
    change_pct : 100 |q_l - q_{l-1}| / |q_l| (NaN at level 0).
    setup_s : mesh, basis and assembly wall time (s).
    solve_s : condensation, factorisation, solve(s) and post-processing wall time (s).
    extra : further compared values of this level (name -> number).
    """

    level: int
    dofs: int
    h_min: float
    quantity: float
    change_pct: float
    setup_s: float
    solve_s: float
    extra: dict = field(default_factory=dict)


def field_change_pct(new: np.ndarray, old: np.ndarray) -> float:
    """100 max |new - old| / max_i |new_i| over sample points (rows: displacement
    vectors), the field-change measure of the refinement tables (as ``plate.py``)."""
    peak = np.max(np.abs(new))        # scale-free: normalise before squaring
    scale = peak * np.max(np.linalg.norm(new / peak, axis=1))
    return float(100 * np.max(np.abs(new - old)) / scale)


def change_pct(new: float, old: float) -> float:
    """100 |new - old| / |new|; NaN without a previous value."""
    if old is None or not np.isfinite(old):
        return float("nan")
    return float(100.0 * abs(new - old) / abs(new)) if new != 0 else float("inf")


@dataclass(frozen=True, eq=False, kw_only=True)
class ReferenceResult:
    """Converged FEM reference (fields common to every reference).

    Attributes
    ----------
    reference : scene id (e.g. ``"plate2d-clamped"``).
    params : every parameter of the run, defaults filled in (JSON types).
    quantity_name : name and unit of the compared quantity.
    quantity : compared quantity at the converged (finest) level.
    refinement : the refinement table, coarsest level first.
    refinement_change_pct : change of ``quantity`` over the last refinement (percent).
    setup_s, solve_s : wall times of the converged level (s).
    study_s : wall time of the whole refinement study (s).
    field : displacement field of the converged level (a :class:`FieldSolution` on a
        box, a :class:`MeshField` on any other domain).
    cache_key : hash of (reference, params, package version, package source).
    from_cache : True when this object was loaded from the on-disk cache.
    """

    reference: str
    params: dict
    quantity_name: str
    quantity: float
    refinement: tuple
    refinement_change_pct: float
    setup_s: float
    solve_s: float
    study_s: float
    field: FieldSolution | MeshField
    cache_key: str = ""
    from_cache: bool = False

    def evaluate(self, points: np.ndarray) -> np.ndarray:
        """Displacement (m) at arbitrary points, shape (n, dim); ``ValueError`` for points
        outside the domain (how many, and the first)."""
        return self.field.evaluate(points)

    def strain_energy_density(self, points: np.ndarray) -> np.ndarray:
        """Strain energy per unit volume (J/m^3) at points."""
        return self.field.strain_energy_density(points)

    def to_vtu(self, path: str | Path) -> Path:
        """Write the converged field to VTU (meshio)."""
        return self.field.to_vtu(path)

    def metrics(self) -> dict:
        """Scene metrics of issue 5 (floats): the reference-specific ones plus
        ``refinement_change_pct``."""
        return {"refinement_change_pct": float(self.refinement_change_pct)}

    def timings(self) -> dict:
        """Wall times (s): converged level setup and solve, and the whole study."""
        return {"setup_s": float(self.setup_s), "solve_s": float(self.solve_s),
                "total_s": float(self.study_s)}

    def sample_grid(self, shape: tuple = (81, 81)) -> dict:
        """Fields on a regular grid over the domain box (for plots): ``x``, ``y`` of the
        given shape ('ij' indexing), displacement ``ux``, ``uy`` (m) and
        ``strain_energy_density`` (J/m^3); NaN at grid points outside a domain that is
        not a box (a :class:`MeshField`)."""
        b = self.field.bounds
        axes = [np.linspace(lo, hi, n) for (lo, hi), n in zip(b, shape)]
        grids = np.meshgrid(*axes, indexing="ij")
        pts = np.stack([g.ravel() for g in grids], axis=1)
        if isinstance(self.field, MeshField):
            # a domain that is not its box: NaN at the grid points outside it
            inside = self.field.contains(pts)
            u = np.full((len(pts), 2), np.nan)
            u[inside] = self.field.evaluate(pts[inside])
            w = np.full(len(pts), np.nan)
            w[inside] = self.field.strain_energy_density(pts[inside])
            return {"x": grids[0], "y": grids[1], "ux": u[:, 0].reshape(shape),
                    "uy": u[:, 1].reshape(shape), "strain_energy_density": w.reshape(shape)}
        u = self.field.evaluate(pts)
        out = {"x": grids[0], "y": grids[1], "ux": u[:, 0].reshape(shape),
               "uy": u[:, 1].reshape(shape),
               "strain_energy_density": self.field.strain_energy_density(pts).reshape(shape)}
        return out

    def refinement_table(self) -> list[dict]:
        """The refinement study as a list of plain dicts (for JSON or a report table)."""
        return [dataclasses.asdict(r) for r in self.refinement]


# --- (de)serialisation: arrays to .npz, everything else to one JSON string ---------------

_ROW_TUPLES = ("refinement", "uniform_refinement")


class MeshReferenceResult(ReferenceResult):
    """A converged reference on a mapped mesh (its ``field`` a ``MeshField``, or in 3D a
    ``TetField``), which also gives the stress anywhere in the domain."""

    def stress(self, points: np.ndarray) -> np.ndarray:
        """Cauchy stress (Pa) at points, shape (n, d, d)."""
        return self.field.stress(points)


def to_npz(result: ReferenceResult, path: Path) -> None:
    """Write a result to ``path`` (an ``.npz`` without pickles)."""
    arrays, meta = {}, {"class": type(result).__name__}
    for f in dataclasses.fields(result):
        v = getattr(result, f.name)
        if isinstance(v, FieldSolution):
            for k, c in enumerate(v.coords):
                arrays[f"{f.name}.coord{k}"] = c
            arrays[f"{f.name}.values"] = v.values
            meta[f.name] = {"__field__": len(v.coords), "lam": v.lam, "mu": v.mu}
        elif isinstance(v, MeshField):
            for a in _MESH_FIELD_ARRAYS:
                arrays[f"{f.name}.{a}"] = np.asarray(getattr(v, a))
            meta[f.name] = {"__mesh_field__": True, "lam": v.lam, "mu": v.mu}
        elif isinstance(v, TetField):
            for a in _TET_FIELD_ARRAYS:
                arrays[f"{f.name}.{a}"] = np.asarray(getattr(v, a))
            meta[f.name] = {"__tet_field__": True, "lam": v.lam, "mu": v.mu}
        elif isinstance(v, np.ndarray):
            arrays[f.name] = v
            meta[f.name] = {"__array__": True}
        elif f.name in _ROW_TUPLES:
            meta[f.name] = [dataclasses.asdict(r) for r in v]
        else:
            meta[f.name] = v
    arrays["__meta__"] = np.array(json.dumps(meta, allow_nan=True))
    arrays["__checksum__"] = np.array(content_digest(arrays))
    np.savez(path, **arrays)


def content_digest(arrays: dict) -> str:
    """SHA-256 over every entry's name, dtype, shape and bytes (sorted by name), so that a
    cache file whose content was altered in any way no longer matches its checksum."""
    h = hashlib.sha256()
    for name in sorted(k for k in arrays if k != "__checksum__"):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def from_npz(path: Path, classes: dict) -> ReferenceResult:
    """Read a result written by :func:`to_npz`; ``classes`` maps class names to types."""
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    if "__checksum__" not in arrays or str(arrays["__checksum__"]) != content_digest(arrays):
        raise ValueError(f"{path}: checksum does not match the content")
    z = arrays
    meta = json.loads(str(z["__meta__"]))
    cls = classes[meta.pop("class")]
    kwargs = {}
    for name, v in meta.items():
        if isinstance(v, dict) and "__field__" in v:
            coords = tuple(z[f"{name}.coord{k}"] for k in range(v["__field__"]))
            kwargs[name] = FieldSolution(coords=coords, values=z[f"{name}.values"],
                                         lam=v["lam"], mu=v["mu"])
        elif isinstance(v, dict) and "__mesh_field__" in v:
            kwargs[name] = MeshField(**{a: z[f"{name}.{a}"] for a in _MESH_FIELD_ARRAYS},
                                     lam=v["lam"], mu=v["mu"])
        elif isinstance(v, dict) and "__tet_field__" in v:
            kwargs[name] = TetField(*(z[f"{name}.{a}"] for a in _TET_FIELD_ARRAYS),
                                    lam=v["lam"], mu=v["mu"])
        elif isinstance(v, dict) and "__array__" in v:
            kwargs[name] = z[name]
        elif name in _ROW_TUPLES:
            kwargs[name] = tuple(RefinementRow(**r) for r in v)
        else:
            kwargs[name] = v
    return cls(**kwargs)
