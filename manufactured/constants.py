"""Peridynamic material constants by energy equivalence, per dimension, plane condition and influence."""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from itertools import product

import sympy as sp

from .influence import check_influence, radial_moment, sphere_moment, weighted_volume

MODELS = ("bond-based", "state-based")
PLANES = ("strain", "stress")
DIMS = (1, 2, 3)

# Plain (assumption-free) symbols so that user expressions built with sp.Symbol("E") match.
E_SYM, NU_SYM, DELTA = sp.symbols("E nu delta")

# |nu - nu_required| below this counts as equal for bond-based models: nu = 1/3 given as a
# float is off by ~2e-17, far below it (a choice, not a published number).
_BOND_NU_TOL = 1e-12


def check_model_args(*, model, dim, plane, influence, horizon=None, E=None, nu=None):
    """Validate the model arguments shared by :func:`constants` and the engine.

    Raises ValueError with a one-line message naming the argument and what is allowed.
    Numeric checks are skipped for symbolic (sympy) values.
    """
    if model not in MODELS:
        raise ValueError(f"model: unknown {model!r}; allowed: {', '.join(MODELS)}")
    if isinstance(dim, bool) or dim not in DIMS:
        raise ValueError(f"dim: must be 1, 2 or 3 (got {dim!r})")
    if dim == 2 and plane not in PLANES:
        raise ValueError(f"plane: 2D needs plane='strain' or plane='stress' (got {plane!r})")
    if dim != 2 and plane is not None:
        raise ValueError(f"plane: only for dim=2; must be None for dim={dim} (got {plane!r})")
    check_influence(influence)
    for name, value in (("horizon", horizon), ("E", E)):
        if value is None or isinstance(value, sp.Basic) and not value.is_number:
            continue
        if not _is_real(value) or not (0 < float(value) < math.inf):
            raise ValueError(f"{name}: must be a finite positive number (got {value!r})")
    if nu is None or isinstance(nu, sp.Basic) and not nu.is_number:
        return
    if not _is_real(nu):
        raise ValueError(f"nu: must be a real number (got {nu!r})")
    upper = 1.0 if (dim == 2 and plane == "stress") else 0.5
    if not (-1.0 < float(nu) < upper):
        raise ValueError(f"nu: must lie in (-1, {upper}) for dim={dim}"
                         f"{', plane ' + plane if plane else ''} (got {nu!r})")


def _is_real(value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        return False
    return not isinstance(value, bool) and math.isfinite(v)


def classical_moduli(dim, plane):
    """Classical moduli (lambda, mu) whose energy W = lambda/2 (tr eps)^2 + mu eps:eps is matched.

    3D and 2D plane strain: Lame constants; 2D plane stress: lambda* = E nu / (1 - nu^2);
    1D (bar in uniaxial stress, seed 000): W = E eps^2 / 2, returned as (None, None).
    """
    mu = E_SYM / (2 * (1 + NU_SYM))
    if dim == 1:
        return None, None
    if dim == 2 and plane == "stress":
        return E_SYM * NU_SYM / (1 - NU_SYM**2), mu
    return E_SYM * NU_SYM / ((1 + NU_SYM) * (1 - 2 * NU_SYM)), mu


def _strain_matrix(dim):
    eps = sp.Matrix(dim, dim, lambda i, j: sp.Symbol(f"eps{min(i, j) + 1}{max(i, j) + 1}"))
    return eps, sorted(eps.free_symbols, key=str)


def _classical_energy(dim, plane, eps):
    if dim == 1:
        return E_SYM * eps[0, 0] ** 2 / 2
    lam, mu = classical_moduli(dim, plane)
    return lam / 2 * eps.trace() ** 2 + mu * sum(eps[i, j] ** 2 for i in range(dim) for j in range(dim))


def _angular_quartic(dim, eps):
    """int_S (eps : m m)^2 dOmega, exactly."""
    total = sp.Integer(0)
    for i, j, k, l in product(range(dim), repeat=4):
        exps = [0] * dim
        for a in (i, j, k, l):
            exps[a] += 1
        total += eps[i, j] * eps[k, l] * sphere_moment(tuple(exps))
    return sp.expand(total)


@lru_cache(maxsize=None)
def derive_constants(model, dim, influence, plane=None):
    """Derive the PD constants symbolically (in E, nu, delta) by energy equivalence.

    Energies for a homogeneous strain eps of an infinite body, e = l eps : m m (m the bond
    direction, l the bond length, dV = l^(d-1) dl dOmega):

    * state-based (seed 001, Eqs. 8, 9, 11; seed 000, Eq. A6):
      W = k_theta theta^2 / (2 c_theta) + k_e / (2 m) int_H omega e^2 dV,
      theta = c_theta / m int_H omega l e dV, m = int_H omega l^2 dV, whose Frechet
      derivative is the scalar force state t = k_theta omega l theta / m + k_e omega e / m;
    * bond-based: pairwise force c omega(l) s m with stretch s = e / l, energy
      W = 1/4 int_H c omega e^2 / l dV (half of each bond energy c omega s^2 l / 2).

    W is matched to W = lambda/2 (tr eps)^2 + mu eps:eps (:func:`classical_moduli`), or to
    E eps^2 / 2 in 1D. c_theta is fixed first so that theta = tr eps in 2D and 3D
    (c_theta = d; in 2D the in-plane trace for both plane conditions) and
    theta = (1 - 2 nu) eps in 1D (seed 000, Eqs. 13-14). Only the product c_theta k_theta
    enters the forces, so this choice changes the reported dilatation, not b or tau.
    In 1D energy equivalence fixes only c_theta k_theta + k_e = E (seed 000, Remark 1);
    the second condition is seed 000's calibration k_e = G_hat = 2 mu = E / (1 + nu)
    (Eqs. 18-19). A bond-based model matches both terms of W only for one Poisson ratio,
    returned as ``required_nu`` (1/4 in 3D and plane strain, 1/3 in plane stress).

    Parameters
    ----------
    model : {"bond-based", "state-based"}
    dim : {1, 2, 3}
    influence : {"gaussian", "hyperbolic", "constant", "conical"}
    plane : {"strain", "stress"} or None
        Required for dim = 2, None otherwise.

    Returns
    -------
    dict
        ``c_theta``, ``weighted_volume``, and either ``k_theta`` and ``k_e``
        (state-based) or ``micromodulus`` and ``required_nu`` (bond-based), as sympy
        expressions in :data:`E_SYM`, :data:`NU_SYM` and :data:`DELTA`.
    """
    check_model_args(model=model, dim=dim, plane=plane, influence=influence)
    eps, eps_symbols = _strain_matrix(dim)
    m = weighted_volume(influence, dim, DELTA)
    w_classical = _classical_energy(dim, plane, eps)
    quartic = _angular_quartic(dim, eps)  # int_S (eps:mm)^2 dOmega

    # c_theta from theta(homogeneous eps) = target dilatation.
    c_theta_sym = sp.Symbol("c_theta")
    theta_unit = sp.expand(c_theta_sym / m * radial_moment(influence, dim + 1, DELTA) * sum(
        eps[i, i] * sphere_moment(tuple(2 if a == i else 0 for a in range(dim)))
        for i in range(dim)))
    target = (1 - 2 * NU_SYM) * eps[0, 0] if dim == 1 else eps.trace()
    c_theta = sp.solve(sp.Poly(theta_unit - target, *eps_symbols).coeffs(), c_theta_sym, dict=True)
    c_theta = sp.simplify(c_theta[0][c_theta_sym])
    theta = theta_unit.subs(c_theta_sym, c_theta)

    out = {"c_theta": c_theta, "weighted_volume": m}
    if model == "state-based":
        k_theta, k_e = sp.symbols("k_theta k_e")
        w_pd = (k_theta * theta**2 / (2 * c_theta)
                + k_e / (2 * m) * radial_moment(influence, dim + 1, DELTA) * quartic)
        eqs = sp.Poly(sp.expand(w_pd - w_classical), *eps_symbols).coeffs()
        if dim == 1:
            eqs.append(k_e - E_SYM / (1 + NU_SYM))  # seed 000, Eqs. (18)-(19): k_e = G_hat = 2 mu
        sol = sp.solve(eqs, [k_theta, k_e], dict=True)
        if len(sol) != 1:
            raise RuntimeError(f"energy equivalence has {len(sol)} solutions for {model}, dim={dim}")
        out["k_theta"] = sp.factor(sp.simplify(sol[0][k_theta]))
        out["k_e"] = sp.factor(sp.simplify(sol[0][k_e]))
        return out

    c = sp.Symbol("c")
    w_pd = c / 4 * radial_moment(influence, dim, DELTA) * quartic
    eqs = sp.Poly(sp.expand(w_pd - w_classical), *eps_symbols).coeffs()
    if dim == 1:
        sol = sp.solve(eqs, [c], dict=True)
        out["micromodulus"] = sp.simplify(sol[0][c])
        out["required_nu"] = None
        return out
    # the eps12^2 coefficient (pure shear) fixes c; the rest fixes nu
    shear = sp.Poly(sp.expand(w_pd - w_classical), *eps_symbols).coeff_monomial(eps[0, 1] ** 2)
    c_value = sp.simplify(sp.solve(shear, c)[0])
    rest = [sp.simplify(q.subs(c, c_value)) for q in eqs]
    nus = set()
    for q in rest:
        if q != 0:
            nus.update(sp.solve(sp.numer(sp.together(q)), NU_SYM))
    if len(nus) != 1:
        raise RuntimeError(f"bond-based {dim}D: expected one admissible nu, got {nus}")
    out["micromodulus"] = c_value
    out["required_nu"] = nus.pop()
    return out


@dataclass(frozen=True)
class PDConstants:
    """Peridynamic constants of one model, as sympy numbers or expressions.

    Attributes
    ----------
    model, dim, plane, influence : as passed
    horizon, E, nu : as passed (sympified)
    c_theta : dilatation coefficient (seed 001, Eq. 9)
    weighted_volume : m of a complete neighbourhood (seed 001, Eq. 8)
    k_theta, k_e : state-based constants (seed 001, Eq. 11); None for bond-based
    micromodulus : c in the bond force c omega(l) s m; None for state-based
    """

    model: str
    dim: int
    plane: str | None
    influence: str
    horizon: sp.Expr
    E: sp.Expr
    nu: sp.Expr
    c_theta: sp.Expr
    weighted_volume: sp.Expr
    k_theta: sp.Expr | None = None
    k_e: sp.Expr | None = None
    micromodulus: sp.Expr | None = None

    def as_floats(self):
        """The numeric constants as a dict of floats (fails if any is still symbolic)."""
        names = ("horizon", "E", "nu", "c_theta", "weighted_volume", "k_theta", "k_e", "micromodulus")
        return {n: float(getattr(self, n)) for n in names if getattr(self, n) is not None}


def constants(*, model, dim, influence, horizon, E, nu, plane=None):
    """PD constants for given material and horizon (see :func:`derive_constants`).

    Parameters
    ----------
    model : {"bond-based", "state-based"}
    dim : {1, 2, 3}
    influence : {"gaussian", "hyperbolic", "constant", "conical"}
    horizon, E, nu : float or sympy expression
        Horizon delta, Young's modulus and Poisson's ratio.
    plane : {"strain", "stress"} or None
        Plane condition, required for dim = 2 and None otherwise.

    Returns
    -------
    PDConstants

    Raises
    ------
    ValueError
        For an unknown model, dimension, plane or influence, a non-positive horizon or E,
        nu out of range, or a bond-based model with a Poisson ratio it cannot represent.

    Notes
    -----
    Closed forms (lambda, mu Lame; lambda* = E nu/(1 - nu^2)):
    3D: c_theta = 3, k_theta = 3 (lambda - mu), k_e = 15 mu (seed 001, Eq. 11).
    2D plane strain: c_theta = 2, k_theta = 2 (lambda - mu), k_e = 8 mu (seed 001, Sec. 5).
    2D plane stress: c_theta = 2, k_theta = 2 (lambda* - mu), k_e = 8 mu.
    1D: c_theta = 1 - 2 nu, k_theta = nu E / ((1 + nu)(1 - 2 nu)), k_e = E / (1 + nu)
    (seed 000, Eq. 19). State-based constants do not depend on the influence function
    (it enters through m); the bond-based micromodulus does:
    c = 6 mu / (R_d int_S m_1^4 dOmega) in 2D and 3D, c = E / R_1 in 1D,
    with R_k = int_0^delta omega l^k dl.
    """
    check_model_args(model=model, dim=dim, plane=plane, influence=influence,
                     horizon=horizon, E=E, nu=nu)
    sym = derive_constants(model, dim, influence, plane)
    horizon, E, nu = sp.sympify(horizon), sp.sympify(E), sp.sympify(nu)
    if model == "bond-based" and sym["required_nu"] is not None and nu.is_number:
        if abs(float(nu) - float(sym["required_nu"])) > _BOND_NU_TOL:
            where = f"{dim}D" + (f" plane {plane}" if plane else "")
            raise ValueError(f"nu: bond-based peridynamics in {where} requires nu = "
                             f"{sym['required_nu']} (got {nu})")
    subs = {E_SYM: E, NU_SYM: nu, DELTA: horizon}
    values = {k: (v.subs(subs) if isinstance(v, sp.Basic) else v) for k, v in sym.items()
              if k != "required_nu"}
    return PDConstants(model=model, dim=dim, plane=plane, influence=influence,
                       horizon=horizon, E=E, nu=nu, **values)
