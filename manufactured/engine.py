"""Symbolic manufactured solutions of linear peridynamics for polynomial displacement fields."""
from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
from dataclasses import dataclass
from functools import lru_cache
from itertools import product
from pathlib import Path
from tokenize import TokenError

import numpy as np
import sympy as sp

from .constants import DELTA, PDConstants, check_model_args, constants as _constants
from .influence import radial_moment_unit, sphere_moment

X, Y, Z = sp.symbols("x y z")
COORDINATES = (X, Y, Z)
# Model symbols of the generic derivation (Derivation): horizon and PD constants.
C_THETA, K_THETA, K_E, C_BOND = sp.symbols("c_theta k_theta k_e c_bond")
RESERVED = ("x", "y", "z", "delta", "c_theta", "k_theta", "k_e", "c_bond")

CACHE_ENV = "PDVERIFY_CACHE_DIR"
_CACHE_FORMAT = 2  # 2: entries carry a SHA-256 of their content
# Working precision (decimal digits) of the numeric coefficients handed to lambdify; well
# beyond double precision so that every coefficient is correctly rounded.
_DPS = 30


@dataclass(frozen=True)
class Derivation:
    """Exact PD fields of one polynomial displacement, in terms of the model symbols.

    Expressions contain the coordinates, the field parameters, ``delta`` (:data:`DELTA`),
    the constants :data:`C_THETA`, :data:`K_THETA`, :data:`K_E` (state-based) or
    :data:`C_BOND` (bond-based micromodulus), and symbols ``R_k`` for the unit-horizon
    radial moments int_0^1 omega(t) t^k dt (so R_k delta^(k+1) = int_0^delta omega l^k dl),
    whose exact values are in `radial_moments`; :meth:`explicit` substitutes them.
    Seed 001's Delta_1 = R_4 delta^5 and Delta_2 = R_6 delta^7 / 2 (Gaussian).

    Attributes
    ----------
    model, dim, influence : as passed to :func:`derive`
    coordinates : tuple of sympy.Symbol, (x,), (x, y) or (x, y, z)
    displacement : sympy.ImmutableMatrix, shape (dim, 1)
    dilatation : sympy.Expr, theta(x) (seed 001, Eq. 9)
    body_force : sympy.ImmutableMatrix, shape (dim, 1), b(x) (seed 001, Eq. 46)
    stress : sympy.ImmutableMatrix, shape (dim, dim), tau(x) (seed 001, Eq. 47)
    radial_moments : dict, symbol R_k -> exact value for this influence function
    """

    model: str
    dim: int
    influence: str
    coordinates: tuple
    displacement: sp.ImmutableMatrix
    dilatation: sp.Expr
    body_force: sp.ImmutableMatrix
    stress: sp.ImmutableMatrix
    radial_moments: dict

    def explicit(self, expr):
        """`expr` (any of the fields) with the radial moments replaced by their values."""
        return expr.xreplace(self.radial_moments)


def radial_moment_symbol(k):
    """Symbol ``R_k`` for the unit-horizon radial moment int_0^1 omega(t) t^k dt."""
    return sp.Symbol(f"R_{int(k)}")


def _taylor(expr, coords):
    """Exact Taylor expansion of a polynomial: list of (alpha, D^alpha expr / alpha!)."""
    degree = sp.Poly(expr, *coords).total_degree() if expr != 0 else 0
    terms = []
    for alpha in product(range(degree + 1), repeat=len(coords)):
        if sum(alpha) > degree:
            continue
        d = expr
        for c, a in zip(coords, alpha):
            if a:
                d = sp.diff(d, c, a)
        if d != 0:
            terms.append((alpha, d / math.prod(math.factorial(a) for a in alpha)))
    return terms


def _tidy(expr, coords):
    """Expand in the coordinates and cancel each coefficient (ratios of moments simplify)."""
    expr = sp.expand(expr)
    if expr == 0:
        return sp.Integer(0)
    poly = sp.Poly(expr, *coords)
    return sp.Add(*[sp.cancel(coef) * sp.Mul(*[c**p for c, p in zip(coords, monom)])
                    for monom, coef in poly.terms()])


def _unit(dim, *indices):
    exps = [0] * dim
    for i in indices:
        exps[i] += 1
    return tuple(exps)


def _add(alpha, extra):
    return tuple(a + b for a, b in zip(alpha, extra))


@lru_cache(maxsize=256)
def _derive_cached(components, model, dim, influence):
    coords = COORDINATES[:dim]
    u = [sp.sympify(c) for c in components]
    used = set()

    def R(k):  # R_k = int_0^delta omega l^k dl = delta^(k+1) * (unit moment, kept as a symbol)
        used.add(k)
        return radial_moment_symbol(k) * DELTA ** (k + 1)

    A = sphere_moment  # A(beta) = int_S m^beta dOmega
    m = A((0,) * dim) * R(dim + 1)  # Eq. (8)
    taylor_u = [_taylor(ui, coords) for ui in u]

    # Eq. (9): theta = c_theta/m int omega l e dV, e = sum_alpha D^a u_i/a! l^|a| m^a m_i
    theta = sp.Integer(0)
    for i, terms in enumerate(taylor_u):
        for alpha, coef in terms:
            n = sum(alpha)
            if n >= 1:
                theta += coef * R(n + dim) * A(_add(alpha, _unit(dim, i)))
    theta = _tidy(C_THETA / m * theta, coords)
    taylor_theta = _taylor(theta, coords) if model == "state-based" else []

    body = []
    for j in range(dim):
        bj = sp.Integer(0)
        for i, terms in enumerate(taylor_u):
            for alpha, coef in terms:
                n = sum(alpha)
                if n == 0:
                    continue
                ang = A(_add(alpha, _unit(dim, i, j)))
                if ang == 0:
                    continue
                if model == "state-based":  # 2 k_e omega e / m
                    bj += 2 * K_E / m * coef * R(n + dim - 1) * ang
                else:  # c omega e / l
                    bj += C_BOND * coef * R(n + dim - 2) * ang
        for alpha, coef in taylor_theta:  # k_theta omega l (theta(x) + theta(x'))/m
            n = sum(alpha)
            ang = A(_add(alpha, _unit(dim, j)))
            if n >= 1 and ang != 0:
                bj += K_THETA / m * coef * R(n + dim) * ang
        body.append(_tidy(-bj, coords))

    stress = sp.zeros(dim, dim)
    for j in range(dim):
        for k in range(j, dim):
            t = sp.Integer(0)
            for i, terms in enumerate(taylor_u):
                for alpha, coef in terms:
                    n = sum(alpha)
                    if n % 2 == 0:  # int_0^r [(r-s)^n - (-s)^n] ds = 0 for even n
                        continue
                    ang = A(_add(alpha, _unit(dim, i, j, k)))
                    if ang == 0:
                        continue
                    s_int = sp.Rational(2, n + 1)  # times r^(n+1)
                    if model == "state-based":
                        t += coef * s_int * 2 * K_E / m * R(n + dim) * ang
                    else:
                        t += coef * s_int * C_BOND * R(n + dim - 1) * ang
            for alpha, coef in taylor_theta:
                n = sum(alpha)
                if n % 2:  # int_0^r [(r-s)^n + (-s)^n] ds = 0 for odd n
                    continue
                ang = A(_add(alpha, _unit(dim, j, k)))
                if ang != 0:
                    t += coef * sp.Rational(2, n + 1) * K_THETA / m * R(n + dim + 1) * ang
            stress[j, k] = stress[k, j] = _tidy(t / 2, coords)
    moments = {radial_moment_symbol(k): radial_moment_unit(influence, k) for k in sorted(used)}
    return Derivation(model=model, dim=dim, influence=influence, coordinates=coords,
                      displacement=sp.ImmutableMatrix(u), dilatation=theta,
                      body_force=sp.ImmutableMatrix(body), stress=sp.ImmutableMatrix(stress),
                      radial_moments=moments)


def derive(displacement, *, model, dim, influence, params=None):
    """Derive theta, b and tau of a polynomial field in terms of the PD constants.

    The infinite-body fields of linear ordinary state-based peridynamics as seed 001
    writes it (Sec. 2.1, Eqs. 8, 9, 11, linearised: e = (u(x') - u(x)) . m with m the
    bond direction in the reference configuration, and m(x) = m(x') = m for the complete
    neighbourhood):

        f(x, x') = [k_theta (theta(x) + theta(x')) omega l / m + 2 k_e omega e / m] m,
        theta(x) = c_theta / m int_H omega l e dV,   m = int_H omega l^2 dV,

    or of bond-based peridynamics with f(x, x') = c_bond omega(l) (e / l) m, and

        b(x) = -int_S int_0^delta f(x, x + l m) l^(d-1) dl dOmega            (Eq. 46)
        tau(x) = 1/2 int_S int_0^delta int_s^delta f(x', x'') (x) m r^(d-1) dr ds dOmega
                 with x' = x - s m, x'' = x + (r - s) m                     (Eq. 47)

    with dV = l^(d-1) dl dOmega (d = 1: Omega = {-1, +1}, counting measure); Eq. (47) is
    derived for d = 3 with r^2 and carries over with r^(d-1). For a polynomial u every
    integrand is a finite Taylor sum of D^alpha u(x) l^|alpha| m^alpha / alpha!, so the
    integrals reduce to exact angular moments int_S m^beta dOmega, radial moments
    R_k = int_0^delta omega l^k dl (see :mod:`manufactured.influence`) and, in Eq. (47),
    int_0^r [(r - s)^n -+ (-s)^n] ds = r^(n+1) (1 -+ (-1)^n) / (n + 1) after swapping the
    s and r integrations. Nothing is approximated.

    Choices (where the seeds are silent or differ):

    * Linearisation: e = (u(x') - u(x)) . m and the force along the reference direction m,
      as in seed 001's appendix (Eq. 57); "infinite body": m(x) = m(x') is the complete
      neighbourhood value (seed 001 Eq. 56 for the Gaussian).
    * f(x, x') is the force on x from x' (so b = -int f dV, Eq. 4); in Eq. (47),
      f(x', x'') is the force on x' (the end with (x - x') . m >= 0) from x''.
    * 2D and 1D analogues of Eq. (47) replace r^2 dOmega (S^2) by r dphi (circle) and by
      a sum over m = +-1; this is the force per unit length / per unit area across the
      line / point through x (Lehoucq and Silling 2008, seed 001 ref. [54]).
    * The dilatation is reported with the c_theta of
      :func:`manufactured.constants.derive_constants` (theta = tr eps for affine fields
      in 2D/3D, (1 - 2 nu) eps in 1D); a bond-based model does not use theta, it is
      reported with the same c_theta and m for comparison.
    * Bond-based micromodulus: c_bond omega(l) is the micromodulus function, so the
      influence function also shapes bond-based kernels (constant -> c_0, conical ->
      c_0 (1 - l/delta) as in seed 004, Eq. 6).

    Parameters
    ----------
    displacement : sequence of str or sympy expression, length dim
        Components of u in x, y, z (the first `dim` of them) and the names in `params`.
    model : {"bond-based", "state-based"}
    dim : {1, 2, 3}
    influence : {"gaussian", "hyperbolic", "constant", "conical"}
    params : dict, optional
        Parameter names of the field; their values are ignored here (kept symbolic).

    Returns
    -------
    Derivation
    """
    check_model_args(model=model, dim=dim, plane="strain" if dim == 2 else None,
                     influence=influence)
    u = _parse_displacement(displacement, dim, params)
    return _derive_cached(tuple(sp.srepr(c) for c in u), model, dim, influence)


def _parse_displacement(displacement, dim, params):
    names = _check_params(params)
    coords = COORDINATES[:dim]
    if dim == 1 and (isinstance(displacement, (str, int, float)) or
                     isinstance(displacement, sp.Basic) and not isinstance(displacement, sp.MatrixBase)):
        displacement = [displacement]
    if isinstance(displacement, sp.MatrixBase):
        displacement = list(displacement)
    if isinstance(displacement, (str, bytes)) or not hasattr(displacement, "__len__") \
            or len(displacement) != dim:
        raise ValueError(f"displacement: expected {dim} component(s) in "
                         f"{', '.join(map(str, coords))} (got {displacement!r})")
    local = {str(c): c for c in COORDINATES}
    local.update({n: sp.Symbol(n) for n in names})
    allowed = {str(c) for c in coords} | set(names)
    out = []
    for comp in displacement:
        try:
            if isinstance(comp, str):
                expr = sp.parse_expr(comp, local_dict=local)
            else:
                expr = sp.sympify(comp)
        except (sp.SympifyError, SyntaxError, TypeError, TokenError) as exc:
            raise ValueError(f"displacement: cannot parse {comp!r} ({exc})") from None
        if not isinstance(expr, sp.Expr):
            raise ValueError(f"displacement: component {comp!r} is not a scalar expression")
        # match symbols by name, whatever assumptions the caller gave them
        expr = expr.xreplace({s: local[s.name] for s in expr.free_symbols if s.name in local})
        unknown = sorted(s.name for s in expr.free_symbols if s.name not in allowed)
        if unknown:
            raise ValueError(f"displacement: unknown symbol(s) {', '.join(unknown)}; allowed: "
                             f"{', '.join(map(str, coords))} and the keys of params")
        if not expr.is_polynomial(*coords):
            raise ValueError(f"displacement: {comp!r} is not a polynomial in "
                             f"{', '.join(map(str, coords))}")
        out.append(sp.expand(expr))
    return out


def _check_params(params):
    if params is None:
        return []
    if not isinstance(params, dict):
        raise ValueError(f"params: expected a dict name -> number (got {type(params).__name__})")
    for name, value in params.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"params: names must be identifiers (got {name!r})")
        if name in RESERVED:
            raise ValueError(f"params: name {name!r} is reserved; reserved: {', '.join(RESERVED)}")
        if isinstance(value, bool) or not _finite_real(value):
            raise ValueError(f"params: value of {name!r} must be a finite real number (got {value!r})")
    return sorted(params)


def _finite_real(value):
    try:
        return math.isfinite(float(value))
    except (TypeError, ValueError):
        return False


def _number(value):
    """Sympy number: ints and sympy numbers as given; a float as the decimal of its shortest
    round-tripping repr at _DPS digits (0.05 -> 0.05000..., which rounds back to the same double)."""
    if isinstance(value, (float, np.floating)):
        return sp.Float(repr(float(value)), _DPS)
    return sp.sympify(value)


# --------------------------------------------------------------------------- cache


def cache_dir():
    """Directory of the on-disk expression cache.

    ``$PDVERIFY_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/pdverify`` or
    ``~/.cache/pdverify``; derived expressions live in its ``manufactured`` folder.
    """
    env = os.environ.get(CACHE_ENV)
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "pdverify"


@lru_cache(maxsize=1)
def _code_version():
    try:
        from importlib.metadata import PackageNotFoundError, version
        try:
            pkg = version("pdverify")
        except PackageNotFoundError:
            pkg = "uninstalled"
    except ImportError:  # pragma: no cover
        pkg = "unknown"
    here = Path(__file__).parent
    digest = hashlib.sha256()
    for name in ("engine.py", "constants.py", "influence.py"):
        digest.update((here / name).read_bytes())
    return f"{pkg}+{digest.hexdigest()[:16]}+sympy{sp.__version__}"


def _cache_key(inputs):
    blob = json.dumps({"format": _CACHE_FORMAT, "code": _code_version(), **inputs}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


def _to_json(obj):
    """Nested dicts/lists of sympy objects -> JSON-able data (sympy objects as srepr)."""
    if isinstance(obj, dict):
        return {"dict": [[_to_json(k), _to_json(v)] for k, v in obj.items()]}
    if isinstance(obj, (list, tuple, sp.MatrixBase)):
        return {"list": [_to_json(v) for v in (obj.tolist() if isinstance(obj, sp.MatrixBase)
                                              else obj)]}
    if obj is None or isinstance(obj, (str, int)):
        return {"py": obj}
    return {"sympy": sp.srepr(obj)}


def _from_json(data):
    if "dict" in data:
        return {_from_json(k): _from_json(v) for k, v in data["dict"]}
    if "list" in data:
        return [_from_json(v) for v in data["list"]]
    if "py" in data:
        return data["py"]
    return sp.sympify(data["sympy"])


def _digest(payload) -> str:
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


def _cache_load(key):
    """The cached entry, or None for a miss: missing, unreadable, or content that does not
    match its checksum (checked before any expression is parsed)."""
    path = cache_dir() / "manufactured" / f"{key}.json"
    try:
        doc = json.loads(path.read_text())
        if not isinstance(doc, dict) or doc.get("sha256") != _digest(doc.get("entry")):
            return None
        return _from_json(doc["entry"])
    except Exception:  # noqa: BLE001 - any unreadable entry is a miss: derive again
        return None


def _cache_store(key, entry):
    folder = cache_dir() / "manufactured"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
        payload = _to_json(entry)
        try:
            with os.fdopen(fd, "w") as fh:
                json.dump({"sha256": _digest(payload), "entry": payload}, fh)
            os.replace(tmp, folder / f"{key}.json")
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    except OSError:
        pass  # a read-only or full cache only costs time


# --------------------------------------------------------------------------- solution


class ManufacturedSolution:
    """Exact PD fields of a polynomial displacement in an infinite body; see :func:`solution`.

    Attributes
    ----------
    model, dim, plane, influence : as passed to :func:`solution`
    constants : manufactured.constants.PDConstants
    coordinates : tuple of sympy.Symbol
    displacement_expr : sympy.ImmutableMatrix (dim, 1)
    dilatation_expr : sympy.Expr
    body_force_expr : sympy.ImmutableMatrix (dim, 1)
    stress_expr : sympy.ImmutableMatrix (dim, dim), symmetric
    symbolic : Derivation, the same fields in terms of the PD constants
    """

    def __init__(self, *, model, dim, plane, influence, constants, symbolic, exprs):
        self.model, self.dim, self.plane, self.influence = model, dim, plane, influence
        self.constants = constants
        self.symbolic = symbolic
        self.coordinates = COORDINATES[:dim]
        self.displacement_expr = sp.ImmutableMatrix(exprs["displacement"])
        self.dilatation_expr = exprs["dilatation"]
        self.body_force_expr = sp.ImmutableMatrix(exprs["body_force"])
        self.stress_expr = sp.ImmutableMatrix(dim, dim, list(exprs["stress"]))
        self._u = self._compile(list(self.displacement_expr))
        self._theta = self._compile([self.dilatation_expr])
        self._b = self._compile(list(self.body_force_expr))
        self._tau = self._compile(list(self.stress_expr))

    def _compile(self, exprs):
        exprs = [sp.N(e, _DPS) for e in exprs]
        return sp.lambdify(self.coordinates, exprs, modules="numpy", cse=True)

    def _points(self, points):
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != self.dim:
            raise ValueError(f"points: expected an array of shape (n, {self.dim}) "
                             f"(got shape {pts.shape})")
        return pts

    def _eval(self, func, points, shape):
        pts = self._points(points)
        n = pts.shape[0]
        values = func(*pts.T)
        out = np.empty((n, len(values)))
        for j, v in enumerate(values):  # loop over components; points stay vectorised
            out[:, j] = v
        return out.reshape((n,) + shape)

    def displacement(self, points):
        """u at `points` of shape (n, dim); returns (n, dim)."""
        return self._eval(self._u, points, (self.dim,))

    def dilatation(self, points):
        """theta (seed 001, Eq. 9) at `points` of shape (n, dim); returns (n,)."""
        return self._eval(self._theta, points, ())

    def body_force(self, points):
        """b = -int_H f dV (seed 001, Eq. 46) at `points` (n, dim); returns (n, dim)."""
        return self._eval(self._b, points, (self.dim,))

    def stress(self, points):
        """PD stress tensor tau (seed 001, Eq. 47) at `points` (n, dim); returns (n, dim, dim)."""
        return self._eval(self._tau, points, (self.dim, self.dim))

    def traction(self, points, normal):
        """Surface force tau(x) n at `points` (n, dim) for unit normal(s) (dim,) or (n, dim).

        Returns an array of shape (n, dim).
        """
        nrm = np.asarray(normal, dtype=float)
        if nrm.shape not in ((self.dim,), (len(np.atleast_2d(points)), self.dim)):
            raise ValueError(f"normal: expected shape ({self.dim},) or (n, {self.dim}) "
                             f"(got {nrm.shape})")
        return np.einsum("njk,...k->nj", self.stress(points), nrm)

    def traction_expr(self, normal):
        """tau(x) n as a sympy Matrix (dim, 1) for a constant normal vector."""
        return self.stress_expr * sp.Matrix(list(normal))


def solution(displacement, *, model, dim, horizon, E, nu, influence, plane=None, params=None,
             cache=True):
    """Manufactured PD solution of an infinite body for a polynomial displacement field.

    Derives (see :func:`derive` for the equations and every choice) the dilatation
    theta(x), the body force b(x) that makes `displacement` an equilibrium solution of
    the infinite body (seed 001, Eq. 46), the PD stress tensor tau(x) (Eq. 47), whose
    product with an outward normal is the surface force to apply on a cut-out finite
    body, with PD constants from energy equivalence (:func:`manufactured.constants.constants`).

    Parameters
    ----------
    displacement : sequence of str or sympy expression, length dim
        Polynomial components of u in x, y, z (the first `dim`) and names in `params`,
        e.g. ``["c_u*x*y", "c_v*x**3", "c_w*x*z"]``. For dim = 1 a single component may
        be given without a list.
    model : {"bond-based", "state-based"}
    dim : {1, 2, 3}
    horizon : float
        Horizon delta > 0.
    E, nu : float
        Young's modulus and Poisson's ratio (bond-based: nu = 1/4 in 3D and plane strain,
        1/3 in plane stress).
    influence : {"gaussian", "hyperbolic", "constant", "conical"}
    plane : {"strain", "stress"} or None
        Plane condition; required for dim = 2, None otherwise.
    params : dict of str -> float, optional
        Values of the named parameters of the field.
    cache : bool, default True
        Read and write derived expressions in :func:`cache_dir`, keyed by a hash of all
        inputs, the package version and the engine's source.

    Returns
    -------
    ManufacturedSolution
        With callables ``displacement``, ``dilatation``, ``body_force``, ``stress`` and
        ``traction`` on points of shape (n, dim), and the sympy expressions.

    Raises
    ------
    ValueError
        On any bad argument, with a one-line message naming it and what is allowed.

    Notes
    -----
    Numbers: floats are read as the decimal of their shortest repr (0.05 is 5/100) and
    the expressions carry 30-digit coefficients, so the lambdified callables use correctly
    rounded double coefficients. The numeric expressions (``*_expr``) are expanded
    polynomials in the coordinates; :attr:`ManufacturedSolution.symbolic` keeps the exact
    form in the PD constants.
    """
    check_model_args(model=model, dim=dim, plane=plane, influence=influence,
                     horizon=horizon, E=E, nu=nu)
    for name, value in (("horizon", horizon), ("E", E), ("nu", nu)):
        if isinstance(value, sp.Basic) and not value.is_number:
            raise ValueError(f"{name}: must be a number for solution() (got {value}); "
                             "use derive() for symbolic constants")
    horizon_n, E_n, nu_n = _number(horizon), _number(E), _number(nu)
    u = _parse_displacement(displacement, dim, params)
    param_values = {sp.Symbol(k): _number(v) for k, v in (params or {}).items()}
    key = _cache_key({
        "displacement": [sp.srepr(c) for c in u], "model": model, "dim": dim,
        "influence": influence, "plane": plane, "horizon": sp.srepr(horizon_n),
        "E": sp.srepr(E_n), "nu": sp.srepr(nu_n),
        "params": {k.name: sp.srepr(v) for k, v in param_values.items()}})
    build = dict(model=model, dim=dim, plane=plane, influence=influence,
                 horizon=horizon_n, E=E_n, nu=nu_n)
    entry = _cache_load(key) if cache else None
    if entry is not None:
        try:
            return _build_solution(entry, **build)
        except (KeyError, TypeError, ValueError, AttributeError, sp.SympifyError):
            pass  # a stale or damaged entry: derive again and overwrite it
    entry = _derive_entry(u, param_values, **build)
    if cache:
        _cache_store(key, entry)
    return _build_solution(entry, **build)


def _build_solution(entry, *, model, dim, plane, influence, horizon, E, nu):
    consts = PDConstants(model=model, dim=dim, plane=plane, influence=influence,
                         horizon=horizon, E=E, nu=nu, **entry["constants"])
    sym = entry["symbolic"]
    symbolic = Derivation(model=model, dim=dim, influence=influence,
                          coordinates=COORDINATES[:dim],
                          displacement=sp.ImmutableMatrix(sym["displacement"]),
                          dilatation=sym["dilatation"],
                          body_force=sp.ImmutableMatrix(sym["body_force"]),
                          stress=sp.ImmutableMatrix(sym["stress"]),
                          radial_moments=sym["radial_moments"])
    return ManufacturedSolution(model=model, dim=dim, plane=plane, influence=influence,
                                constants=consts, symbolic=symbolic, exprs=entry["numeric"])


def _derive_entry(u, param_values, *, model, dim, plane, influence, horizon, E, nu):
    """Constants, generic derivation and numeric expressions of one solution (cacheable)."""
    consts = _constants(model=model, dim=dim, influence=influence, horizon=horizon,
                        E=E, nu=nu, plane=plane)
    symbolic = _derive_cached(tuple(sp.srepr(c) for c in u), model, dim, influence)
    subs = dict(param_values)
    subs.update({DELTA: horizon, C_THETA: consts.c_theta})
    subs.update({k: sp.N(v, _DPS) for k, v in symbolic.radial_moments.items()})
    if model == "state-based":
        subs.update({K_THETA: consts.k_theta, K_E: consts.k_e})
    else:
        subs[C_BOND] = consts.micromodulus
    fix = lambda e: sp.expand(e.xreplace(subs))  # noqa: E731
    names = ("c_theta", "weighted_volume", "k_theta", "k_e", "micromodulus")
    return {
        "constants": {n: getattr(consts, n) for n in names},
        "symbolic": {"displacement": list(symbolic.displacement),
                     "dilatation": symbolic.dilatation,
                     "body_force": list(symbolic.body_force),
                     "stress": symbolic.stress.tolist(),
                     "radial_moments": dict(symbolic.radial_moments)},
        "numeric": {"displacement": [fix(c) for c in symbolic.displacement],
                    "dilatation": fix(symbolic.dilatation),
                    "body_force": [fix(c) for c in symbolic.body_force],
                    "stress": [fix(c) for c in symbolic.stress]},
    }
