"""Independent check of the engine by numerical quadrature of the defining integrals (no sympy)."""
import numpy as np
import pytest
from scipy import integrate
from scipy.special import roots_legendre

from manufactured import solution

# Agreement demanded by issue 6 ("Must show"): max |quadrature - engine| <= 1e-10 * max |engine|
# over the sampled points and components of each quantity. The rules below are exact in the
# angles (polynomial integrands) and converge exponentially in the radius, so they reach
# about 1e-14; 1e-10 leaves room for the cancellation of the odd terms.
RTOL = 1e-10

N_RADIAL = 24  # Gauss-Legendre nodes on [0, delta] (Gaussian omega: error ~ 1e-20 at this n)
N_S = 4  # Gauss-Legendre nodes for s in [0, r]; the s-integrand is a polynomial of degree <= 3


def _gauss(n, a, b):
    t, w = roots_legendre(n)
    return (a + b) / 2 + (b - a) / 2 * t, (b - a) / 2 * w


def _directions(dim, degree):
    """Quadrature on S^{d-1}, exact for polynomials in m of total degree <= `degree`.

    Circle: trapezoid rule in phi with degree + 2 nodes (exact for trigonometric degree
    <= degree + 1). Sphere: that rule times Gauss-Legendre in cos(theta) with
    degree // 2 + 2 nodes (exact to polynomial degree degree + 3). 1D: {-1, +1}.
    """
    if dim == 1:
        return np.array([[-1.0], [1.0]]), np.ones(2)
    nphi = degree + 2
    phi = 2 * np.pi * np.arange(nphi) / nphi
    wphi = np.full(nphi, 2 * np.pi / nphi)
    if dim == 2:
        return np.column_stack([np.cos(phi), np.sin(phi)]), wphi
    t, wt = roots_legendre(degree // 2 + 2)
    st = np.sqrt(1 - t**2)
    m = np.stack([np.outer(st, np.cos(phi)), np.outer(st, np.sin(phi)),
                  np.outer(t, np.ones(nphi))], axis=-1).reshape(-1, 3)
    return m, np.outer(wt, wphi).ravel()


OMEGA = {
    "gaussian": lambda l, d: np.exp(-(l / d) ** 2),  # seed 001, Eq. (7)
    "hyperbolic": lambda l, d: d / l,  # seed 000, Eq. (23)
    "conical": lambda l, d: 1 - l / d,
    "constant": lambda l, d: np.ones_like(l),
}


def _field(components):
    """numpy evaluator of the field strings, by Python's own eval (not sympy)."""
    code = [compile(c, "<field>", "eval") for c in components]

    def u(p):
        env = {"x": p[..., 0], "y": p[..., 1] if p.shape[-1] > 1 else None,
               "z": p[..., 2] if p.shape[-1] > 2 else None}
        return np.stack([np.broadcast_to(eval(c, {}, env), p.shape[:-1]) for c in code], axis=-1)
    return u


class Quadrature:
    """Brute-force quadrature of seed 001 Eqs. (8), (9), (46), (47) and their 2D analogues.

    State-based force (seed 001, Eq. 11, linearised, complete neighbourhoods):
    f(x, x') = [k_theta omega l (theta(x) + theta(x')) / m + 2 k_e omega e / m] m;
    bond-based: f = c omega (e / l) m. theta(x) at every node is itself a quadrature.
    """

    def __init__(self, components, dim, model, influence, horizon, consts, degree):
        self.u, self.dim, self.model, self.delta = _field(components), dim, model, horizon
        self.omega = lambda l: OMEGA[influence](l, horizon)
        self.c = consts
        self.l, self.wl = _gauss(N_RADIAL, 0.0, horizon)
        # theta integrand e m... has degree <= degree + 1 in m
        self.m_in, self.w_in = _directions(dim, degree + 1)
        # b and tau integrands: degree <= degree + 3 in m
        self.m_out, self.w_out = _directions(dim, degree + 3)
        self.weighted_volume = (self.w_in.sum() * np.sum(self.wl * self.omega(self.l) * self.l ** (dim + 1)))

    def theta(self, p):
        out = np.empty(p.shape[0])
        radial = self.wl * self.omega(self.l) * self.l * self.l ** (self.dim - 1)
        for start in range(0, p.shape[0], 512):
            q = p[start:start + 512]
            y = q[:, None, None, :] + self.l[None, :, None, None] * self.m_in[None, None, :, :]
            e = np.einsum("krnd,nd->krn", self.u(y) - self.u(q)[:, None, None, :], self.m_in)
            out[start:start + 512] = np.einsum("krn,r,n->k", e, radial, self.w_in)
        return self.c["c_theta"] / self.weighted_volume * out

    def _force(self, p, q, length, direction, theta_p=None):
        """Bond force f(p, q) for q - p = length * direction, arrays (..., dim).
        ``theta_p``: theta at p where p is one point broadcast (body_force), computed once
        there instead of at each of its copies."""
        e = np.einsum("...d,...d->...", self.u(q) - self.u(p), direction)
        om = self.omega(length)
        if self.model == "bond-based":
            mag = self.c["micromodulus"] * om * e / length
        else:
            m = self.weighted_volume
            if theta_p is None:
                theta_p = self.theta(p.reshape(-1, self.dim)).reshape(p.shape[:-1])
            th = theta_p + self.theta(q.reshape(-1, self.dim)).reshape(q.shape[:-1])
            mag = self.c["k_theta"] * om * length * th / m + 2 * self.c["k_e"] * om * e / m
        return mag[..., None] * direction

    def body_force(self, x):
        """Eq. (46): b = -int_S int_0^delta f(x, x + l m) l^(d-1) dl dOmega."""
        ll = np.broadcast_to(self.l[:, None], (len(self.l), len(self.w_out)))
        mm = np.broadcast_to(self.m_out[None], ll.shape + (self.dim,))
        xs = np.broadcast_to(x, mm.shape)
        theta_x = None if self.model == "bond-based" else self.theta(np.reshape(x, (1, -1)))[0]
        f = self._force(xs, xs + ll[..., None] * mm, ll, mm, theta_p=theta_x)
        w = (self.wl * self.l ** (self.dim - 1))[:, None] * self.w_out[None, :]
        return -np.einsum("rnd,rn->d", f, w)

    def stress(self, x):
        """Eq. (47): tau = 1/2 int_S int_0^delta int_s^delta f(x', x'') (x) m r^(d-1) dr ds dOmega.

        Integrated as int_0^delta dr int_0^r ds with x' = x - s m, x'' = x + (r - s) m.
        """
        sig, wsig = _gauss(N_S, 0.0, 1.0)
        r = self.l[:, None, None] * np.ones((1, N_S, len(self.w_out)))
        s = r * sig[None, :, None]
        mm = np.broadcast_to(self.m_out[None, None], r.shape + (self.dim,))
        xp = x - s[..., None] * mm
        xpp = x + (r - s)[..., None] * mm
        f = self._force(xp, xpp, r, mm)
        w = (self.wl * self.l * self.l ** (self.dim - 1))[:, None, None] * wsig[None, :, None] \
            * self.w_out[None, None, :]
        return 0.5 * np.einsum("rsnj,rsnk,rsn->jk", f, mm, w)


def _lame(E, nu):
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _constants(model, dim, plane, influence, horizon, E, nu):
    """PD constants from the closed forms in the seeds (not from the engine)."""
    lam, mu = _lame(E, nu)
    if model == "state-based":
        if dim == 1:  # seed 000, Eqs. (13)-(14) and (19)
            return {"c_theta": 1 - 2 * nu, "k_theta": nu * E / ((1 - 2 * nu) * (1 + nu)),
                    "k_e": E / (1 + nu)}
        if dim == 3:  # seed 001, below Eq. (11)
            return {"c_theta": 3, "k_theta": -3 * (1 - 4 * nu) * E / (2 * (1 + nu) * (1 - 2 * nu)),
                    "k_e": 15 * E / (2 * (1 + nu))}
        if plane == "strain":  # seed 001, Sec. 5
            return {"c_theta": 2, "k_theta": -(1 - 4 * nu) * E / ((1 + nu) * (1 - 2 * nu)),
                    "k_e": 4 * E / (1 + nu)}
        # plane stress: lambda -> lambda* = E nu / (1 - nu^2) in k_theta = 2 (lambda - mu)
        return {"c_theta": 2, "k_theta": -(1 - 3 * nu) * E / (1 - nu**2), "k_e": 4 * E / (1 + nu)}
    # bond-based: c = 6 mu / (R_d int_S m_1^4) in 2D/3D, c = E / R_1 in 1D (energy
    # equivalence; seed 004 quotes c = 6E/delta^2 for the 1D conical case); R_d by
    # scipy.integrate.quad, int_S m_1^4 = 4 pi / 5 (seed 001, Eq. 50) or 3 pi / 4 (circle)
    r_d = integrate.quad(lambda l: OMEGA[influence](l, horizon) * l**dim, 0, horizon,
                         epsabs=0, epsrel=1e-13)[0]
    if dim == 1:
        return {"c_theta": 1 - 2 * nu, "micromodulus": E / r_d}
    a4 = 4 * np.pi / 5 if dim == 3 else 3 * np.pi / 4
    return {"c_theta": dim, "micromodulus": 6 * mu / (r_d * a4)}


FIELDS = {
    1: {"cubic": ["x**3 - 0.5*x**2 + 0.2*x"]},
    3: {"seed001": ["0.05*x*y", "-0.06*x**3", "-0.02*x*z"],  # seed 001, Eq. (42)
        "cubic": ["x**2*y - 0.5*z**3 + 0.3*x*y*z + y**2 + 0.2*x",
                  "0.7*x*y*z - y**3 + 2*x*z**2 - 0.1*z",
                  "x*z**2 - 0.4*x**3 + 1.1*y**2*z + 0.5*x*y"]},
    2: {"cubic": ["x**2*y - 0.3*y**3 + 0.5*x", "0.8*x**3 - x*y**2 + 0.2*y**2"],
        "quadratic": ["x*y + 0.5*y**2 - 0.1*x", "x**2 - 0.25*x*y + 0.3*y"]},
}
DEGREE = {"seed001": 3, "cubic": 3, "quadratic": 2}

CASES = [(3, None, "state-based", f, infl, 0.3) for f in FIELDS[3] for infl in ("gaussian", "hyperbolic")]
CASES += [(2, plane, "state-based", f, infl, 0.3) for f in FIELDS[2] for infl in ("gaussian", "hyperbolic")
          for plane in ("strain", "stress")]
CASES += [(3, None, "bond-based", "cubic", "gaussian", 0.25),
          (3, None, "bond-based", "cubic", "conical", 0.25),
          (2, "stress", "bond-based", "cubic", "hyperbolic", 1 / 3),
          (2, "strain", "bond-based", "quadratic", "gaussian", 0.25)]
CASES += [(1, None, "state-based", "cubic", infl, 0.3) for infl in ("gaussian", "hyperbolic")]
CASES += [(1, None, "bond-based", "cubic", "conical", 0.3)]


@pytest.mark.parametrize("dim, plane, model, field, influence, nu", CASES)
def test_engine_matches_quadrature(rng, dim, plane, model, field, influence, nu):
    horizon, E = 0.3, 200e9
    comps = FIELDS[dim][field]
    sol = solution(comps, model=model, dim=dim, plane=plane, horizon=horizon, E=E, nu=nu,
                   influence=influence, cache=False)
    quad = Quadrature(comps, dim, model, influence, horizon,
                      _constants(model, dim, plane, influence, horizon, E, nu), DEGREE[field])
    pts = rng.uniform(-1.0, 1.0, size=(3, dim))

    theta_q = quad.theta(pts)
    b_q = np.array([quad.body_force(p) for p in pts])
    tau_q = np.array([quad.stress(p) for p in pts])
    checks = [("theta", theta_q, sol.dilatation(pts)), ("b", b_q, sol.body_force(pts)),
              ("tau", tau_q, sol.stress(pts))]
    for name, q, exact in checks:
        scale = np.max(np.abs(exact))
        assert scale > 0, name
        err = np.max(np.abs(q - exact)) / scale
        print(f"{dim}D {plane} {model} {field} {influence}: {name} rel. error {err:.1e}")
        assert err <= RTOL, f"{name}: relative error {err:.2e}"


def test_quadrature_check_detects_a_small_error(rng):
    # negative control: the same comparison with k_e off by 1e-8 (relative) must fail the
    # 1e-10 tolerance, so the check above is not vacuous.
    comps, horizon, E, nu = FIELDS[2]["cubic"], 0.3, 200e9, 0.3
    sol = solution(comps, model="state-based", dim=2, plane="strain", horizon=horizon, E=E, nu=nu,
                   influence="gaussian", cache=False)
    consts = _constants("state-based", 2, "strain", "gaussian", horizon, E, nu)
    consts["k_e"] *= 1 + 1e-8
    quad = Quadrature(comps, 2, "state-based", "gaussian", horizon, consts, 3)
    pts = rng.uniform(-1.0, 1.0, size=(3, 2))
    exact = sol.stress(pts)
    err = np.max(np.abs(np.array([quad.stress(p) for p in pts]) - exact)) / np.max(np.abs(exact))
    assert err > RTOL
