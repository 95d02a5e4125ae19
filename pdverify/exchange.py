"""A static scene's uncorrected problem as a node set for another PD code, and the
score of the displacements that code computed on it (``pdverify export``, ``score``):
the ``static-state`` family's scenes (state-based; the treatment ``none`` assembles
them) and the bond-based seed-003 sheets (a description each, assembled by the generic bond
assembly: ``bond_problem`` and ``measure`` of
:class:`pdverify.scenes.bondfamily.BondStaticScene`).

The node set is the ``none`` treatment's: the real nodes of the scene's grid with their
volumes, the prescribed components of each boundary condition (the nodes nearest the
face, at the value the scene prescribes there) and the loads as nodal forces (the
right-hand side the uncorrected model assembles: body force times node volume plus the
force of each loaded boundary cell face on its node). Scoring puts a file's displacements
where the ``none`` solve would put its solution and calls the scene's own ``measure``, so
an external code's numbers are measured exactly as ours. Writers of the files are in
:mod:`pdverify.decks`. No printing, no drawing.
"""
from __future__ import annotations

import csv
import io
import json
import math
import os
from dataclasses import dataclass

import numpy as np

from .errors import InputError
from .nodeset import (  # noqa: F401  (node_set_of re-exported: the export's node set)
    NodeSet, _lattice_k2, equilibrium, node_set_of, not_in_equilibrium, solution_vector,
    written_horizon)

#: the marker file of an export folder (it lists every file the export wrote) and its
#: schema (:mod:`pdverify.decks` writes it; score finds an export by it)
MARKER = ".pdverify-export"
MARKER_SCHEMA = "pdverify.export-folder/1"
#: The one method whose problem is exported: the uncorrected model (its conditions on
#: real nodes only, which a node-set deck can state; the corrections add nodes, rows or
#: bond factors no other code reads).
METHOD = "none"
#: A file's node matches ours within this fraction of the grid spacing. Nodes are one
#: spacing apart, so any tolerance below 1/2 pairs them unambiguously; 1e-3 admits
#: coordinates written in single precision (7 digits) for bodies up to ~1e4 spacings
#: across, and refuses a node moved by a thousandth of a cell.
MATCH_TOLERANCE = 1e-3
AXES = "xyz"
#: the file's values on prescribed nodes may differ from ours by this fraction of its
#: largest displacement before the record warns: a result written with 9 significant
#: digits or more stays below it; a code that imposed other values does not
PRESCRIBED_RTOL = 1e-9
#: the length units a CSV column may name in brackets (``ux [mm]``) and how many of each
#: make a metre (a value is divided by it: an exact integer, so a value in mm becomes the
#: double nearest its metres); no unit is metres. ``µm`` with the micro sign or Greek mu.
LENGTH_UNITS = {"m": 1.0, "cm": 1e2, "mm": 1e3, "um": 1e6, "\u00b5m": 1e6, "nm": 1e9}
_UNIT_ALIASES = {"\u03bcm": "\u00b5m"}


def bond_based(scene) -> bool:
    """A bond-based scene that describes and measures its own problem
    (:class:`~pdverify.scenes.bondfamily.BondStaticScene` with ``bond_problem`` and
    ``measure``)."""
    from .scenes.bondfamily import BondStaticScene
    return (isinstance(scene, BondStaticScene)
            and type(scene).bond_problem is not BondStaticScene.bond_problem
            and type(scene).measure is not BondStaticScene.measure)


def exportable(scene) -> bool:
    """A scene of the ``static-state`` family that states its problem (the stiffness
    scenes of the family prescribe every node and solve nothing), or a bond-based sheet
    that builds and measures its own (:func:`bond_based`); not a scene that states an
    ``export_refusal`` (a problem a node set does not carry)."""
    from .scenes.family import StaticStateScene
    if getattr(scene, "export_refusal", None):
        return False
    return bond_based(scene) or (isinstance(scene, StaticStateScene)
                                 and type(scene).problem is not StaticStateScene.problem
                                 and type(scene).measure is not StaticStateScene.measure)


def exportable_ids() -> list[str]:
    from .scenes import all_scenes
    return [s.id for s in all_scenes() if exportable(s)]


def scene_of(scene_id: str):
    """The scene ``scene_id`` if it can be exported, else InputError naming those that
    can (an unknown id: the registry's message with close matches)."""
    from .scenes import get_scene
    scene = get_scene(scene_id)
    why = getattr(scene, "export_refusal", None)
    if why:
        raise InputError(f"scene {scene_id!r} cannot be exported or scored: {why}; these "
                         f"can: {', '.join(exportable_ids())}")
    if not exportable(scene):
        raise InputError(f"scene {scene_id!r} is not a static problem with a node set "
                         "(the static-state family or a bond-based sheet) and cannot be "
                         f"exported or scored; these can: {', '.join(exportable_ids())}")
    return scene


def check_method(method: str | None) -> str:
    if method not in (None, METHOD):
        raise InputError(f"--method {method!r}: only the uncorrected problem ('none') is "
                         "exported; a correction's extra nodes, rows or bond factors are "
                         "not part of a node set another code reads")
    return METHOD


# ------------------------------------------------------------------------------ horizon
def _horizon_shells(ns: NodeSet) -> dict:
    """The model's bond offsets (its stencil, in spacings) against the lattice's shells
    of equal |k|^2: ``k2_max`` (the largest |k|^2 of a bond offset), ``k2_next`` (the
    smallest sum of d integer squares above it), ``offsets`` (bond offsets of a full
    neighbourhood, both signs), ``within`` (those with |k| <= m), ``beyond`` (|k| > m:
    nodes outside the horizon m h whose cells the horizon sphere cuts, kept by the
    partial-volume quadratures), ``beta_beyond`` and ``beta_total`` (their weights beta,
    in cells), ``added`` (lattice offsets with |k|^2 <= k2_max the stencil leaves out:
    a shell the stencil splits, e.g. partial-volume 3D at m >= 5) and ``jitter`` (the
    shape grid's node moves, a fraction of h; 0 on the lattice). The offsets are
    :attr:`NodeSet.bond_offsets` (a bond-based model's: those that carry a bond)."""
    model = ns.system.model
    off, beta = ns.bond_offsets
    off = np.asarray(off, dtype=np.int64)
    k2 = np.sum(off * off, axis=1)
    k2_max = int(k2.max())
    lattice = _lattice_k2(ns.dim, math.isqrt(k2_max) + 1)   # holds (r, 0, ..), r^2 > k2_max
    beyond = np.sqrt(k2) > float(model.m_ratio) * (1.0 + 1e-12)   # build_stencil's closed test
    return {"k2_max": k2_max, "k2_next": int(lattice[lattice > k2_max].min()),
            "offsets": int(len(off)), "within": int(np.count_nonzero(~beyond)),
            "beyond": int(np.count_nonzero(beyond)),
            "beta_beyond": float(np.sum(beta[beyond])), "beta_total": float(np.sum(beta)),
            "added": int(np.count_nonzero((lattice > 0) & (lattice <= k2_max))) - len(off),
            "jitter": float(getattr(model.grid, "jitter", 0.0) or 0.0)}


def export_horizon(ns: NodeSet) -> float:
    """The horizon to write [m]: ``h sqrt((K + K_next) / 2)``, K the largest |k|^2 of
    the model's bond offsets k (in spacings; K = m^2 for whole cells at an integer m, up
    to 14 for partial volumes at m = 3 in 3D, whose stencil holds the nodes beyond m h
    whose cells the horizon cuts) and K_next the next sum of d integer squares (the next
    lattice shell). Halfway between the two shells in |xi|^2, a code that keeps a bond
    when |xi|^2 <= delta^2, computed from the written coordinates, keeps every bond of
    the model and adds none (the margin, at least h^2 / 2 in |xi|^2, exceeds the
    rounding of coordinates written with 17 digits, ~4 eps L |xi| on a body of size L,
    up to L ~ 1e13 h), where the stencil is whole shells (:func:`_horizon_shells`:
    ``added`` lattice offsets otherwise, kept too)."""
    return written_horizon(ns)


def _horizon_rule(ns: NodeSet) -> str:
    """The written horizon's rule and what it keeps, as one paragraph (problem.json and
    the export README)."""
    s = _horizon_shells(ns)
    m, d = float(ns.system.model.m_ratio), ns.dim
    text = (f"horizon_written_m = h sqrt((K + K_next)/2) = {export_horizon(ns)!r} m with h the "
            f"spacing, K = {s['k2_max']} the largest |k|^2 of the model's bond offsets k (in "
            f"spacings) and K_next = {s['k2_next']} the next |k|^2 of the {d}D lattice: a "
            "code that keeps a bond when |xi|^2 <= horizon_written_m^2, from the written "
            f"coordinates, keeps the model's {s['offsets']} bond offsets per full "
            f"neighbourhood ({s['within']} with |xi| <= m h = horizon_m")
    if s["beyond"]:
        text += (f", and {s['beyond']} with |xi| > m h: the nodes beyond horizon_m whose cells "
                 "the horizon sphere cuts, whose weights beta sum to "
                 f"{s['beta_beyond']:.6g} of the neighbourhood's {s['beta_total']:.6g} cells")
    text += ")"
    if s["added"]:
        text += (f" and {s['added']} offset(s) more: the model's stencil (m = {m:g}) takes "
                 "part of a shell of equal |k|^2, which no spherical horizon can; those "
                 "are bonds the model does not have")
    else:
        text += ", and no other"
    if s["jitter"]:
        kw = 0.5 * (s["k2_max"] + s["k2_next"])
        gap = min(math.sqrt(kw) - math.sqrt(s["k2_max"]), math.sqrt(s["k2_next"]) - math.sqrt(kw))
        move = s["jitter"] * math.sqrt(d)
        text += (f". The nodes are moved off the lattice (jitter = {s['jitter']:g}), which "
                 f"changes a pair's |xi| by up to {move:.3g} h against a margin of "
                 f"{gap:.3g} h: " + ("the distance test still keeps exactly those pairs"
                                     if move < gap else
                                     "pairs near the written horizon may fall on its other "
                                     "side, so the kept set is not guaranteed"))
    return text + "."


def node_set(scene, overrides=None) -> NodeSet:
    """Assemble the ``none`` system of ``scene`` at ``overrides`` (bad input: InputError
    from the scene's own checks, before any work): by the treatment ``none`` of the
    static-state family, or by a bond-based sheet's description (``bond_system``)."""
    p = scene.resolve(METHOD, overrides)
    where = f"{scene.id}/{METHOD}"
    if bond_based(scene):
        return node_set_of(scene, p, *scene.bond_system(METHOD, p, where))
    problem = scene.problem(p, where)
    treatment = scene.treatment(METHOD)
    return node_set_of(scene, p, problem, treatment.assemble(problem, p))


# ------------------------------------------------------------------------------ reading
@dataclass
class Displacements:
    """Positions (n, 3 or fewer) and displacements (n, <= 3) read from a file."""

    path: str
    kind: str
    x: np.ndarray
    u: np.ndarray
    time_s: float | None = None


def _column_name(text: str) -> str:
    """``"ux [m]"`` -> ``"ux"``: the name before a unit in brackets, lower case."""
    return text.split("[", 1)[0].strip().lower()


def _per_metre(path: str, header: str) -> float:
    """How many of the unit a column ``header`` names in brackets make a metre (``"ux
    [mm]"`` -> 1000; no brackets: metres, 1); another unit is InputError naming the
    column and the allowed units."""
    if "[" not in header:
        return 1.0
    unit = header.split("[", 1)[1].rsplit("]", 1)[0].strip()
    unit = _UNIT_ALIASES.get(unit, unit)
    if unit not in LENGTH_UNITS:
        raise InputError(f"displacement file {path!r}: column {header.strip()!r} has unit "
                         f"{unit!r}; allowed length units: {', '.join(LENGTH_UNITS)} "
                         "(none: m)")
    return LENGTH_UNITS[unit]


#: names of a displacement component's column (CSV) or array (VTU, Exodus): ux, u_x, ...
_U_NAMES = ("u{a}", "u_{a}", "displacement_{a}", "displacements_{a}", "displacement{a}",
            "displacements{a}")


#: the most bytes a displacement file may hold per node of the export, and the bytes it may
#: hold beyond that (headers, comments, an Exodus file's metadata): a CSV row of six doubles
#: in repr is at most 6 x 25 = 150 bytes, a VTU point with a dozen float64 arrays ~130
#: bytes in base64, and an Exodus node 8 bytes per variable and time step (100 steps of
#: three displacements and two more variables: 4 kB). A file above this cannot be the
#: export's displacements and is refused before it is read (a sparse 20 GB file, a file
#: of another, finer node set).
SCORE_BYTES_PER_NODE = 4096
SCORE_BYTES_FIXED = 64 << 20


def check_size(path: str, nodes: int) -> None:
    """InputError naming the file, its size and the limit when ``path`` holds more bytes
    than the displacements of ``nodes`` nodes can (:data:`SCORE_BYTES_PER_NODE`)."""
    limit = SCORE_BYTES_FIXED + SCORE_BYTES_PER_NODE * int(nodes)
    try:
        size = os.stat(path).st_size
    except OSError as exc:
        raise InputError(f"displacement file {path!r} cannot be read ({exc.strerror})") from None
    if size > limit:
        raise InputError(f"displacement file {path!r} holds {size} bytes, more than the "
                         f"displacements of the export's {nodes} nodes can ({limit} bytes at "
                         f"most: {SCORE_BYTES_FIXED >> 20} MiB and {SCORE_BYTES_PER_NODE} "
                         "bytes a node); is it the file of another node set?")


#: byte-order marks a text file may start with; only UTF-8's is read (and skipped)
_BOMS = ((b"\xef\xbb\xbf", "UTF-8"), (b"\xff\xfe\x00\x00", "UTF-32"),
         (b"\x00\x00\xfe\xff", "UTF-32"), (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16"))


def _check_text_encoding(path: str) -> None:
    """A text file in UTF-16 or UTF-32 (its byte-order mark) is InputError naming it."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4)
    except OSError as exc:
        raise InputError(f"displacement file {path!r} cannot be read ({exc.strerror})") from None
    for mark, name in _BOMS:
        if head.startswith(mark) and name != "UTF-8":
            raise InputError(f"displacement file {path!r} cannot be read: it starts with a "
                             f"{name} byte-order mark; save it as UTF-8 (with or without its "
                             "byte-order mark)")


def read_displacements(path: str, dim: int) -> Displacements:
    """Positions and displacements from a CSV (header row: ``x, y, z`` and ``ux, uy,
    uz`` or ``u_x``..., a length unit in brackets scaled to metres (:data:`LENGTH_UNITS`),
    ``#`` lines skipped, a UTF-8 byte-order mark allowed), a VTU (meshio: points and a
    point array ``u``/``displacement(s)`` or its components), an Exodus file
    (:func:`_read_exodus`: its last time step) or a LAMMPS text dump
    (:func:`_read_lammps_dump`: its last snapshot, with the reference positions). Any problem is InputError naming the
    file, and so is a file without nodes, with fewer coordinates than ``dim`` or whose
    displacements are all zero (an initial state: every exported problem has a load or
    a prescribed value that is not zero)."""
    from .validate import input_file
    input_file(path, "displacement file")
    ext = os.path.splitext(path)[1].lower()
    if ext in (".csv", ".txt", ".dump", ".lammpstrj"):
        _check_text_encoding(path)
    if ext in (".csv", ".txt"):
        got = _read_csv(path, dim)
    elif ext == ".vtu":
        got = _read_mesh(path, dim, "vtu")
    elif ext in (".e", ".exo", ".ex2", ".exodus"):
        got = _read_exodus(path, dim)
    elif ext in (".dump", ".lammpstrj"):
        got = _read_lammps_dump(path, dim)
    else:
        raise InputError(f"displacement file {path!r}: unknown kind "
                         f"{ext or '(no extension)'!r}; allowed: .csv, .vtu, .e/.exo "
                         "(Exodus), .dump (LAMMPS text dump)")
    if not len(got.x):
        raise InputError(f"displacement file {path!r} holds no nodes"
                         + (" (no data rows below its header)" if got.kind == "csv" else ""))
    if got.x.shape[1] < dim:
        raise InputError(f"displacement file {path!r}: its nodes have {got.x.shape[1]} "
                         f"coordinate(s), the scene {dim} ({', '.join(AXES[:dim])})")
    if not np.any(got.u):
        raise InputError(f"displacement file {path!r}: every displacement is zero (an "
                         "initial state, not a solution: the exported problem has loads or "
                         "prescribed values that are not zero)")
    return got


def _read_csv(path: str, dim: int) -> Displacements:
    """The CSV read row by row (never the whole text at once): the header row, then the
    named columns of each data row into one array of doubles."""
    from array import array
    try:
        fh = open(path, encoding="utf-8-sig", newline="")   # a UTF-8 BOM is skipped
    except OSError as exc:
        raise InputError(f"displacement file {path!r} cannot be read ({exc})") from None
    try:
        with fh:
            reader = csv.reader(ln for ln in fh
                                if ln.strip() and not ln.lstrip().startswith("#"))
            header = next(reader, None)
            if header is None:
                raise InputError(f"displacement file {path!r} is empty (no header row)")
            names = [_column_name(c) for c in header]
            want_x = list(AXES[:dim])
            want_u = []
            for a in AXES[:dim]:
                hit = next((n.format(a=a) for n in _U_NAMES if n.format(a=a) in names), None)
                want_u.append(hit or f"u{a}")
            missing = [c for c in want_x + want_u if c not in names]
            if missing:
                raise InputError(
                    f"displacement file {path!r}: missing column(s) {', '.join(missing)}; it "
                    f"has {', '.join(names) or 'none'} (need {', '.join(want_x)} and "
                    f"{', '.join(f'u{a}' for a in AXES[:dim])})")
            cols = [names.index(c) for c in want_x + want_u]
            per_metre = np.array([_per_metre(path, header[c]) for c in cols])
            values = array("d")
            for i, row in enumerate(reader):
                try:
                    values.extend(float(row[c]) for c in cols)
                except (ValueError, IndexError):
                    raise InputError(f"displacement file {path!r}: data row {i + 1} is not "
                                     f"{len(cols)} numbers in the named columns: "
                                     f"{[c[:20] for c in row[:8]]!r}") from None
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"displacement file {path!r} cannot be read as UTF-8 CSV "
                         f"({type(exc).__name__}: {exc})") from None
    except OSError as exc:
        raise InputError(f"displacement file {path!r} cannot be read ({exc})") from None
    data = np.frombuffer(values, dtype=float).reshape(-1, 2 * dim).copy()
    _check_finite(path, data)
    data = data / per_metre   # metres (a column in m keeps its values bit for bit)
    return Displacements(path, "csv", data[:, :dim], data[:, dim:])


def _read_mesh(path: str, dim: int, kind: str) -> Displacements:
    import contextlib
    import meshio
    said = io.StringIO()
    try:   # meshio prints its own error and calls sys.exit on a file it cannot read
        with contextlib.redirect_stderr(said), contextlib.redirect_stdout(said):
            mesh = meshio.read(path, file_format=kind)
    except ModuleNotFoundError as exc:
        raise InputError(f"displacement file {path!r}: reading {kind} needs the package "
                         f"{exc.name!r} (python -m pip install {exc.name})") from None
    except (Exception, SystemExit) as exc:
        why = " ".join(said.getvalue().split()) or f"{type(exc).__name__}: {exc}"
        raise InputError(f"displacement file {path!r} cannot be read as {kind} "
                         f"({why})") from None
    data = {k.lower(): np.asarray(v, dtype=float) for k, v in mesh.point_data.items()}
    u = _nodal_vectors(path, dim, data, list(mesh.point_data))
    x = np.asarray(mesh.points, dtype=float)
    _check_finite(path, np.c_[x[:, :dim], u])
    return Displacements(path, kind, x[:, :dim], u)


def _nodal_vectors(path, dim, data: dict, have) -> np.ndarray:
    """The displacement among point arrays ``data`` (lower-case names): a vector ``u``
    or ``displacement(s)``, or its components (``ux``, ``displacementx`` as Peridigm's
    Exodus output names them, ``displacementsx`` as PeriLab's, ...)."""
    u = next((data[k] for k in ("u", "displacement", "displacements") if k in data), None)
    if u is None:
        comps = [next((data[n.format(a=a)] for n in _U_NAMES if n.format(a=a) in data),
                      None) for a in AXES[:dim]]
        if all(c is not None for c in comps):
            u = np.column_stack(comps)
    if u is None:
        raise InputError(f"displacement file {path!r}: no point array 'u', 'displacement' "
                         f"or its components; it has {', '.join(have) or 'none'}")
    u = np.asarray(u, dtype=float)
    u = u.reshape(len(u), -1)
    if u.shape[1] < dim:
        raise InputError(f"displacement file {path!r}: its displacement has {u.shape[1]} "
                         f"components, the scene {dim}")
    return u[:, :dim]


def _read_exodus(path: str, dim: int) -> Displacements:
    """An Exodus II file's node coordinates and the displacement of its LAST time step
    (a static run's output holds the initial state first; meshio's reader takes the
    first step only, so it is not used). NetCDF classic and 64-bit-offset files are read
    by scipy; NetCDF-4 (HDF5) files need the netCDF4 package."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
    except OSError as exc:
        raise InputError(f"displacement file {path!r} cannot be read ({exc})") from None
    try:
        if head.startswith(b"CDF"):
            from scipy.io import netcdf_file
            with netcdf_file(path, "r", mmap=False) as nc:
                found = {k: np.array(v[:]) for k, v in nc.variables.items()}
        elif head.startswith(b"\x89HDF"):
            import netCDF4
            with netCDF4.Dataset(path) as nc:
                found = {}
                for k, v in nc.variables.items():
                    v.set_auto_mask(False)
                    found[k] = np.array(v[:])
        else:
            raise InputError(f"displacement file {path!r} is not an Exodus (NetCDF) file")
    except ModuleNotFoundError as exc:
        raise InputError(f"displacement file {path!r}: reading a NetCDF-4 Exodus file "
                         f"needs the package {exc.name!r} (python -m pip install "
                         f"{exc.name})") from None
    except InputError:
        raise
    except Exception as exc:
        raise InputError(f"displacement file {path!r} cannot be read as Exodus "
                         f"({type(exc).__name__}: {exc})") from None

    def text(rows):
        return [b"".join(np.atleast_1d(r).astype("S1")).decode("utf-8", "replace")
                .strip("\x00 ") for r in np.atleast_2d(rows)]

    if "coord" in found:
        x = np.asarray(found["coord"], dtype=float).T
    elif "coordx" in found:
        x = np.column_stack([found[k] for k in ("coordx", "coordy", "coordz") if k in found])
    else:
        raise InputError(f"displacement file {path!r}: no node coordinates (coordx / coord)")
    names = text(found["name_nod_var"]) if "name_nod_var" in found else []
    steps = [np.shape(v)[0] for k, v in found.items()
             if k == "time_whole" or k.startswith("vals_nod_var")]
    if steps and min(steps) == 0:
        raise InputError(f"displacement file {path!r}: the Exodus file has no time steps "
                         "(time_whole or its nodal variables are empty): no result written")
    step = -1
    data = {}
    for k, name in enumerate(names):
        if f"vals_nod_var{k + 1}" in found:
            values = found[f"vals_nod_var{k + 1}"]
            data[name.lower()] = values[step]
        elif "vals_nod_var" in found:
            data[name.lower()] = found["vals_nod_var"][step, k]
    u = _nodal_vectors(path, dim, data, names)
    times = found.get("time_whole")
    x = x.reshape(len(x), -1)
    if len(x) != len(u):
        raise InputError(f"displacement file {path!r}: {len(x)} nodes but {len(u)} values")
    _check_finite(path, np.c_[x[:, :dim], u])
    return Displacements(path, "exodus", x[:, :dim], u,
                         None if times is None or not len(times) else float(times[step]))


#: the columns of a LAMMPS dump's reference positions: the deck's ``fix x0 all store/state
#: 0 x y z`` (``f_x0[1]``...), or ``x0 y0 z0``
_DUMP_REFERENCE = (("f_x0[1]", "f_x0[2]", "f_x0[3]"), ("x0", "y0", "z0"))


def _read_lammps_dump(path: str, dim: int) -> Displacements:
    """The last snapshot of a LAMMPS text dump (``ITEM: ATOMS id x y z ...``): positions
    the reference columns (:data:`_DUMP_REFERENCE`), displacements the current positions
    less them; rows in any order (sorted by id)."""
    try:
        with open(path, encoding="utf-8-sig") as fh:
            lines = fh.read().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"displacement file {path!r} cannot be read ({exc})") from None
    starts = [i for i, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS")]
    if not starts:
        raise InputError(f"displacement file {path!r}: no 'ITEM: ATOMS' line (not a LAMMPS "
                         "text dump)")
    head = lines[starts[-1]].split()[2:]
    ref = next((cols for cols in _DUMP_REFERENCE if all(c in head for c in cols[:dim])), None)
    need = ["id", *"xyz"[:dim]]
    if ref is None or any(c not in head for c in need):
        raise InputError(f"displacement file {path!r}: a LAMMPS dump needs the columns "
                         f"id, {', '.join('xyz'[:dim])} and the reference positions "
                         f"({' '.join(_DUMP_REFERENCE[0][:dim])}, as the deck writes them); "
                         f"it has {' '.join(head) or 'none'}")
    cols = [head.index(c) for c in need + list(ref[:dim])]
    rows = [ln.split() for ln in lines[starts[-1] + 1:] if ln.strip()]
    try:
        data = np.array([[float(r[c]) for c in cols] for r in rows]).reshape(len(rows), -1)
    except (ValueError, IndexError):
        raise InputError(f"displacement file {path!r}: a row of its last snapshot is not "
                         f"{len(head)} numbers") from None
    data = data[np.argsort(data[:, 0], kind="stable")] if len(data) else np.zeros((0, 1 + 2 * dim))
    x, x0 = data[:, 1:1 + dim], data[:, 1 + dim:]
    _check_finite(path, np.c_[x, x0])
    return Displacements(path, "lammps-dump", x0, x - x0)


def _check_finite(path, data) -> None:
    bad = np.argwhere(~np.isfinite(data))
    if len(bad):
        raise InputError(f"displacement file {path!r}: node {bad[0][0] + 1} holds a "
                         "non-finite number")


# ------------------------------------------------------------------------------ matching
def _at(x) -> str:
    return "(" + ", ".join(f"{v:.10g}" for v in x) + ")"


def match_nodes(ns: NodeSet, given: Displacements) -> np.ndarray:
    """``order`` with ``given.x[order[i]]`` the file's node at our node i: every node of
    the file within :data:`MATCH_TOLERANCE` spacings of a distinct node of ours, and as
    many nodes as ours. Else InputError naming the first mismatching node."""
    from scipy.spatial import cKDTree
    tol = MATCH_TOLERANCE * ns.spacing
    n, m = len(ns.x), len(given.x)
    dist, ours = cKDTree(ns.x).query(given.x)
    owner = np.full(n, -1)
    for j in range(m):   # one pass over the file's nodes, first offender reported
        if dist[j] > tol:
            raise InputError(f"{given.path}: node {j + 1} of the file at {_at(given.x[j])} "
                             f"is {dist[j]:.3g} m from the nearest exported node (node "
                             f"{ours[j] + 1} at {_at(ns.x[ours[j]])}); tolerance "
                             f"{tol:.3g} m ({MATCH_TOLERANCE:g} spacings)")
        if owner[ours[j]] >= 0:
            raise InputError(f"{given.path}: node {j + 1} of the file at {_at(given.x[j])} "
                             f"matches exported node {ours[j] + 1} at "
                             f"{_at(ns.x[ours[j]])}, which node {owner[ours[j]] + 1} of the "
                             "file matched already")
        owner[ours[j]] = j
    if m != n:
        free = np.flatnonzero(owner < 0)
        raise InputError(f"{given.path}: {m} nodes, the exported set has {n}; exported "
                         f"node {free[0] + 1} at {_at(ns.x[free[0]])} has no node in the file")
    return owner


# ------------------------------------------------------------------------------ scoring
#: the record's warning when no export was found for the file (:func:`score`)
NO_EXPORT_WARNING = ("the parameters could not be checked against an export: no "
                     "--export DIR given and no .pdverify-export in the file's folder or "
                     "its parents; scored at the given --set (defaults elsewhere)")


def _find_export(path: str, export: str | None) -> str | None:
    """The export folder the displacement file ``path`` answers: ``export`` (``--export
    DIR``), else the first of the file's folder and its parents that holds the marker
    ``.pdverify-export``; None when there is none."""
    if export is not None:
        if not str(export).strip() or not os.path.isdir(export):
            raise InputError(f"--export {export!r} is not a folder; give the folder "
                             "pdverify export wrote")
        if not os.path.isfile(os.path.join(export, MARKER)):
            raise InputError(f"--export {export!r} holds no pdverify export (no {MARKER})")
        return os.path.abspath(export)
    folder = os.path.dirname(os.path.abspath(path))
    while True:
        if os.path.isfile(os.path.join(folder, MARKER)):
            return folder
        parent = os.path.dirname(folder)
        if parent == folder:
            return None
        folder = parent


def _export_params(scene, folder: str, given: bool, overrides) -> dict:
    """The params of the export in ``folder`` (its ``problem.json``), checked: its scene
    is ``scene``, and each ``--set`` in ``overrides`` takes the export's value. Returns
    ``diagnostics.external.export``."""
    where = (f"--export {folder!r}" if given else
             f"the export {folder!r} (the first folder above the displacement file holding "
             f"{MARKER}; give --export DIR for another)")
    try:
        with open(os.path.join(folder, MARKER), encoding="utf-8") as fh:
            marker = json.load(fh)
        with open(os.path.join(folder, "problem.json"), encoding="utf-8") as fh:
            doc = json.load(fh)
    except (OSError, ValueError) as exc:
        raise InputError(f"{where}: cannot read its {MARKER} and problem.json "
                         f"({type(exc).__name__}: {exc})") from None
    if (not isinstance(marker, dict) or marker.get("schema") != MARKER_SCHEMA
            or not isinstance(doc, dict) or doc.get("schema") != "pdverify.export/1"
            or not isinstance(doc.get("params"), dict) or not isinstance(doc.get("scene"), str)):
        raise InputError(f"{where}: its {MARKER} or problem.json is not pdverify's "
                         f"(schemas {MARKER_SCHEMA} and pdverify.export/1 with scene and params)")
    from .outputs import check_listed
    entries = marker.get("entries", [])
    check_listed(folder, entries if isinstance(entries, list) else [repr(entries)],
                 f"{where}: its {MARKER}")
    if doc["scene"] != scene.id:
        raise InputError(f"{where} is an export of scene {doc['scene']!r}, not {scene.id!r}")
    try:
        ours = scene.resolve(METHOD, doc["params"])
    except InputError as exc:
        raise InputError(f"{where}: its problem.json params do not resolve ({exc})") from None
    with_set = scene.resolve(METHOD, {**doc["params"], **dict(overrides or {})})
    for key, raw in (overrides or {}).items():
        if with_set[key] != ours[key]:
            raise InputError(f"--set {key}={raw}: {where} was made with {key}={ours[key]!r}; "
                             "drop the --set, or score against the export made with it")
    return {"folder": folder, "found_by": "--export" if given else MARKER,
            "pdverify_version": marker.get("pdverify_version"), "nodes": doc.get("nodes"),
            "params": ours}


def score(scene_id: str, path: str, *, name: str, overrides=None, export=None):
    """The run record of the displacements in ``path`` on the exported node set of
    ``scene_id`` (module docstring); bad input is InputError before the measure.

    Provenance: the export the file answers (``export``, else :func:`_find_export`)
    gives the params (a ``--set`` in ``overrides`` must agree with it) and is recorded
    in ``diagnostics.external.export``; without one, the file is scored at
    ``overrides`` and the record warns (:data:`NO_EXPORT_WARNING`)."""
    scene = scene_of(scene_id)
    if not name or any(c.isspace() for c in name):
        raise InputError(f"--name {name!r}: give a non-empty name without spaces "
                         "(the run's method becomes external:NAME)")
    folder = _find_export(path, export)
    origin = None
    if folder is not None:
        origin = _export_params(scene, folder, export is not None, overrides)
        overrides = origin["params"]
    record = _score_file(scene, path, name=name, overrides=overrides, origin=origin)
    if origin is None:
        record.warnings.insert(0, NO_EXPORT_WARNING)
    return record


def _score_file(scene, path: str, *, name: str, overrides, origin):
    """:func:`score` at ``overrides``, the params of the export ``origin`` (or None)."""
    from .results import RunResult
    scene.resolve(METHOD, overrides)                 # bad --set before reading the file
    ns = node_set(scene, overrides)
    check_size(path, len(ns.x))                      # before reading: a size it can have
    given = read_displacements(path, scene.dim)
    if origin is not None and origin["nodes"] not in (None, len(ns.x)):
        raise InputError(f"the export {origin['folder']!r} has {origin['nodes']} nodes, the "
                         f"node set of its params {len(ns.x)} here (written by pdverify "
                         f"{origin['pdverify_version']}); export it again")
    order = match_nodes(ns, given)
    U = given.u[order]
    n = len(ns.x)
    x = solution_vector(ns.system, U)
    deviation = 0.0
    for k, (nodes, values) in ns.fixed.items():
        if len(nodes):
            deviation = max(deviation, float(np.max(np.abs(U[nodes, k] - values))))
    source = {"file": os.path.abspath(path), "kind": given.kind, "nodes": n,
              **({"time": given.time_s} if given.time_s is not None else {}),
              "match_tolerance_m": MATCH_TOLERANCE * ns.spacing,
              "prescribed_max_deviation_m": deviation,
              "cost_measured": False, **({"export": origin} if origin is not None else {})}
    info = {"solver": "external", "external": source}
    held = equilibrium(ns, U)
    source["equilibrium"] = held
    outcome = ns.scene.measure(ns.params, ns.problem, ns.system, x, info)
    outcome.metrics["equilibrium_residual"] = held["residual"]
    outcome.metrics["equilibrium_distance"] = held["distance"]
    record = RunResult(scene=scene.id, method=f"external:{name}", params=ns.params,
                       reference=scene.reference, metrics=outcome.metrics,
                       size=outcome.size, diagnostics=outcome.diagnostics,
                       timings={"setup_s": 0.0, "solve_s": 0.0, "total_s": 0.0})
    if not held["in_equilibrium"]:
        record.status, record.message = "failed", not_in_equilibrium(held)
    scale = float(np.max(np.abs(U))) if U.size else 0.0
    if deviation > PRESCRIBED_RTOL * scale:
        record.warnings.append(
            f"the file's displacements on the prescribed nodes differ from the values the "
            f"scene prescribes by up to {deviation:.3g} m ({deviation / scale:.2g} of the "
            "largest displacement): the code imposed other conditions than the export's")
    record.fields = outcome.fields
    return record


def is_external(method: str) -> bool:
    return method.startswith("external:")


def load_external(paths) -> list:
    """The external runs (method ``external:NAME``) of the results files ``paths``, for
    ``report --include``; anything else is InputError naming the file, before work."""
    from .results import RunResult, load_results
    from .scenes import get_scene
    from .validate import input_file
    out, seen = [], {}
    for path in paths:
        input_file(path, "--include")
        try:
            doc = load_results(path)
        except (OSError, ValueError) as exc:
            raise InputError(f"--include {path!r}: {exc}") from None
        for k, run in enumerate(doc["runs"]):
            if not is_external(run["method"]):
                raise InputError(f"--include {path!r}: runs[{k}] has method "
                                 f"{run['method']!r}, not an external run (external:NAME, "
                                 "written by pdverify score)")
            get_scene(run["scene"])          # an unknown scene: exit 2, close matches
            from .outputs import check_listed
            check_listed(os.path.dirname(os.path.abspath(path)), run.get("files", []),
                         f"--include {path!r}: runs[{k}].files")
            r = RunResult.from_json(run)
            r.files = []     # the record's own files are not the report's (score writes none)
            if r.key in seen:
                raise InputError(f"--include: {r.scene} {r.method} is in {seen[r.key]!r} "
                                 f"and {path!r} with the same params")
            seen[r.key] = path
            out.append(r)
    return out


def describe_json(ns: NodeSet) -> dict:
    """What ``problem.json`` holds: the scene, its params, the model's constants, its
    horizon m h (``horizon_m``, the influence function's delta) and the horizon the decks
    write (``horizon_written_m``, :func:`export_horizon`) with its rule as text."""
    from .results import _plain
    inf = ns.problem.influence
    if ns.theory == "bond-based":
        material = bond_material(ns)
        influence = {"name": inf.name, "omega": inf.description,
                     "what": "the micromodulus's shape: c(xi) = c omega(|xi|)"}
    else:
        c = ns.problem.constants
        material = {"model": "linear ordinary state-based (LPS)", "kind": c.kind,
                    "E_Pa": c.E, "nu": c.nu, "c_theta": c.c_theta, "k_theta_Pa": c.k_theta,
                    "k_e_Pa": c.k_e}
        influence = {"name": inf.name, "omega": inf.description}
    return _plain({
        "schema": "pdverify.export/1", "scene": ns.scene.id, "method": METHOD,
        "params": ns.params, "reference": ns.scene.reference, "dim": ns.dim,
        "nodes": len(ns.x), "spacing_m": ns.spacing, "horizon_m": ns.horizon,
        "m_ratio": ns.horizon / ns.spacing, "horizon_written_m": export_horizon(ns),
        "horizon_rule": _horizon_rule(ns), "bond_offsets": _horizon_shells(ns),
        "thickness_m": float(ns.problem.thickness),
        "material": material, "influence": influence,
        "quadrature": ns.params.get("quadrature", "partial-volume"),
        "prescribed": {AXES[k]: int(len(v[0])) for k, v in ns.fixed.items()},
        "loaded_nodes": int(np.count_nonzero(np.any(ns.forces != 0, axis=1))),
    })


def bond_material(ns: NodeSet) -> dict:
    """problem.json's ``material`` of a bond-based node set: the model, the moduli its
    micromodulus was calibrated to, c and what it multiplies (BondBasedModel)."""
    pr, model = ns.problem, ns.system.model
    partial = ns.params.get("quadrature") == "partial-volume"
    return {
        "model": "linear bond-based (pairwise forces along the reference bond direction, "
                 "linearised in the displacements)",
        "kind": pr.kind, "E_Pa": float(pr.E), "nu": float(pr.nu),
        "micromodulus": pr.influence.name, "c_N_per_m6": float(model.c),
        "force_density": (
            "force density on node a [N/m^3] = sum over its bonds b of c omega(|xi|) "
            "(e / |xi|) V_b" + (" beta_b" if partial else "") + " along n, with xi the "
            "reference bond vector, n = xi / |xi|, e = n . (u_b - u_a) the linearised "
            "extension, omega the micromodulus's shape (influence) and V_b the "
            "neighbour's volume as written (volume [m^3] in nodes.csv: the cell's area "
            "times the thickness)" + (", beta_b the fraction of its cell inside the "
                                      "horizon (quadrature=partial-volume)" if partial else "")
            + "; so c is in N/m^6 and the nodal force is that density times V_a"),
        "c_calibration": (
            f"c = {float(model.c)!r} N/m^6 matches E and nu of a complete continuous "
            f"horizon of radius horizon_m in {pr.kind.replace('-', ' ')} (9 E / (pi "
            "delta^3) for the constant micromodulus) per unit thickness, and is not "
            "divided by the thickness: with V_a and V_b both holding it, the model's "
            "stiffness grows with thickness_m squared where its loads grow with "
            "thickness_m, so the calibration holds at thickness_m = 1 m (the scenes' "
            "default)"),
    }


def dumps(doc: dict) -> str:
    return json.dumps(doc, indent=1, allow_nan=False) + "\n"


# ------------------------------------------------------------------------------ commands
def score_command(scene_id: str, path: str, *, name: str, overrides=None, export=None,
                  out=None, force=False, stream=None) -> int:
    """``pdverify score``: check, read, match, measure, print, write the record."""
    import sys
    from . import validate
    from .results import write_results
    stream = stream or sys.stdout
    scene_of(scene_id)
    validate.input_file(path, "displacement file")
    json_path = (validate.output_file(out, "--out", force=force,
                                      inputs=((path, "displacement file"),))
                 if out is not None else None)
    from .outputs import check_cache
    check_cache()       # a FEM reference is computed once and cached
    record = score(scene_id, path, name=name, overrides=overrides, export=export)
    src = record.diagnostics["external"]
    print(f"{record.scene} --method {record.method} (reference: {record.reference}): "
          f"{record.status}", file=stream)
    for key, value in record.metrics.items():
        print(f"  {key:24s} {value:.10g}" if isinstance(value, float)
              else f"  {key:24s} {value}", file=stream)
    for text in record.warnings:
        print(f"  warning: {text}", file=stream)
    print(f"  displacements: {path} ({src['kind']}, {src['nodes']} nodes matched within "
          f"{src['match_tolerance_m']:.3g} m); prescribed values: largest deviation "
          f"{src['prescribed_max_deviation_m']:.3g} m; cost not measured", file=stream)
    if "export" in src:
        print(f"  parameters: those of the export {src['export']['folder']} (its "
              "problem.json; scene and --set checked)", file=stream)
    else:
        print("  parameters: not checked against an export (see the warning)", file=stream)
    if json_path:
        write_results(json_path, [record])
    return 0
