"""The position-aware linear solid (PALS; Mitchell, Silling and Littlewood 2015), as
Peridigm's ``pals.cxx`` computes it, on the linear state-based engine (seed 001 §5.1).

Each node i gets its own dilatation influence omega_i and deviatoric influence sigma_i,
the least change (in sum (.)^2 beta V) of reference functions omega_0, sigma_0 that
satisfies the *matching deformations* by Lagrange multipliers:

  omega_i(xi) = omega_0(|xi|) + sum_k lambda_ik E_k(xi),  E = (xi_x^2, xi_y^2, xi_z^2,
                2 xi_x xi_y, 2 xi_x xi_z, 2 xi_y xi_z)  (2D: the first two and 2 xi_x xi_y),
  sum_j omega_i E_k beta V_j = (1, 1, 1, 0, 0, 0)_k: theta_i = tr(eps) for every
  homogeneous strain, theta_i = sum_j omega_i |xi| e beta V_j;
  sigma_i(xi) = sigma_0(|xi|) + sum_k mu_ik D_k(xi)^2, D_k the deviatoric extension of
  the k-th matching deformation (uniaxial e_k (x) e_k: xi_k^2 / |xi| - |xi| / d; shear:
  2 xi_k xi_l / |xi|), sum_j sigma_i D_k^2 beta V_j = eps' : eps' of that deformation
  ((d - 1) / d for the uniaxial ones, 2 for the shears). In 2D the two uniaxial
  deviators are opposite (D_y = -D_x), so the deviatoric constraints are D_x and the
  shear (2 multipliers; 3D: 6).

Energy W_i = kappa theta_i^2 / 2 + mu sum_j sigma_i (e - theta_i |xi| / d)^2 beta V_j,
kappa = lambda + 2 mu / d, so under each matching deformation every node, surface nodes
included, has the continuum W exactly. The force state is its derivative, the one of
Peridigm (with d = 3: p = (K + 2 mu m_sigma / 9) theta - (2 mu / 3) sum sigma |xi| e V):
  t_i(xi) = q_i omega_i(xi) |xi| + 2 mu sigma_i(xi) (e - theta_i |xi| / d),
  q_i = (kappa + 2 mu m_sigma,i / d^2) theta_i - (2 mu / d) Q_i,
  m_sigma,i = sum_j sigma_i |xi|^2 beta V_j,  Q_i = sum_j sigma_i |xi| e beta V_j.
On the engine (``Closure.constitutive``) the bond force is K_e e + K_theta [theta; Q]:
two nodal scalars per node instead of LPS's one, so the stiffness is still a product of
sparse factors and is symmetric (an energy).

Our choices where the sources leave room:
- omega_0 = d omega(|xi|) / m_inf and sigma_0 = d (d + 2) omega(|xi|) / (2 m_inf), the
  LPS weights of a complete neighbourhood (m_inf its discrete weighted volume), so a
  bulk node's omega is LPS's to round-off; its sigma moves only by the lattice's fourth-
  moment anisotropy (PALS makes the bulk exactly isotropic: with exact partial areas at
  m = 3 the 2D lattice is 1 % anisotropic).
- The sums carry the partial-volume weights beta (Peridigm: whole neighbour volumes).
- Multipliers are solved per node with the matrices scaled to unit diagonal; a node
  whose system is singular to 1e-12 (too few bond directions) is a failed run naming
  the node, where Peridigm zeroes the row (its 2D-in-3D fix-up, not needed here: a 2D
  model has 3 multipliers).
- Peridigm's normalising constants are off (1.0), as there.
- Boundary conditions as the uncorrected model imposes them (seed 001 §5.1: PALS
  corrects the stiffness, not the imposition).
- Plain grids only (no fictitious nodes); 2D and 3D (in 1D the deviatoric part vanishes
  and the seed-000 bar is not a 1D continuum).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..pd.bonds import homogeneous_extensions
from ..pd.closure import Closure
from ..pd.grid import KIND_FICTITIOUS
from .factors import node_moments, node_sums, solve_per_node

def _pairs(d: int) -> list[tuple[int, int]]:
    diag = [(k, k) for k in range(d)]
    return diag + [(i, j) for i in range(d) for j in range(i + 1, d)]


def matching_targets(d: int):
    """The constraint values of the matching deformations: tr(eps_k) and eps_k' : eps_k'
    ((d - 1) / d for a stretch, 2 for a shear; 2D: the x stretch and the shear)."""
    pairs = _pairs(d)
    tr = np.array([1.0 if i == j else 0.0 for i, j in pairs])
    dev = np.array([(d - 1.0) / d if i == j else 2.0 for i, j in pairs])
    return tr, (dev[[0, 2]] if d == 2 else dev)


def matching_basis(xi: np.ndarray):
    """(E, D, rhs_dil, rhs_dev) for bond vectors xi (nb, d): E_k = xi . eps_k . xi of each
    matching deformation eps_k (uniaxial e_k (x) e_k, then the shears e_i (x) e_j +
    e_j (x) e_i), D_k = the deviatoric extension E_k / |xi| - tr(eps_k) |xi| / d (2D:
    without the y stretch's, which is -D_x), and the constraint values tr(eps_k) and
    eps_k' : eps_k'."""
    d = xi.shape[1]
    r = np.linalg.norm(xi, axis=1)
    E = np.stack([xi[:, i] * xi[:, j] * (1.0 if i == j else 2.0) for i, j in _pairs(d)], axis=1)
    tr, rhs_dev = matching_targets(d)
    D = E / r[:, None] - tr[None, :] * r[:, None] / d
    if d == 2:  # D_y = -D_x: one uniaxial deviator in 2D (the pair would be singular)
        D = D[:, [0, 2]]
    return E, D, tr, rhs_dev


class PalsConstitutive:
    """The PALS force state on a :class:`~pdverify.pd.statebased.StateBasedModel`'s bonds
    (module docstring); ``operators(model)`` is called by the model during construction."""

    def moduli(self, model):
        lam, mu = model.constants.moduli()
        return lam + 2.0 * mu / model.dim, mu

    def reference(self, model, r):
        """omega_0 and sigma_0 at bond lengths r."""
        d, om = model.dim, model.influence.omega(r, model.horizon)
        return d * om / model.m_inf, d * (d + 2) * om / (2.0 * model.m_inf)

    def influences(self, model):
        """Per bond, at end a and at end b: omega_i and sigma_i (four arrays), computed
        once per model."""
        cached = model.__dict__.get("_pals_influences")
        if cached is not None:
            return cached
        g, a, b = model.grid, model.bond_a, model.bond_b
        if np.any(g.kind == KIND_FICTITIOUS):
            raise ValueError("pals: plain grids only (no fictitious nodes)")
        E, DD = self.bases(model.bond_n * model.bond_x[:, None])
        om0, sg0 = self.reference(model, model.bond_x)
        V, beta = model.node_volume, model.bond_beta
        # end a's sums weigh a bond by beta V_b, end b's by beta V_a (xi -> -xi leaves
        # E and D unchanged: both are even)
        lam, mu_ = self.multipliers(np.r_[a, b], np.r_[beta * V[b], beta * V[a]],
                                    np.vstack([E, E]), np.vstack([DD, DD]),
                                    np.r_[om0, om0], np.r_[sg0, sg0], g.x)
        out = (om0 + np.sum(E * lam[a], axis=1), om0 + np.sum(E * lam[b], axis=1),
               sg0 + np.sum(DD * mu_[a], axis=1), sg0 + np.sum(DD * mu_[b], axis=1))
        model._pals_influences = out
        return out

    @staticmethod
    def bases(xi):
        """E and D^2 of the matching deformations at bond vectors xi."""
        E, D, _, _ = matching_basis(xi)
        return E, D ** 2

    @staticmethod
    def multipliers(nodes, w, E, DD, om0, sg0, x):
        """The Lagrange multipliers (lambda, mu) of every node from its bond ends (rows:
        the node, its weight beta V_j, E, D^2, omega_0, sigma_0)."""
        n, d = x.shape
        rhs_dil, rhs_dev = matching_targets(d)
        r_dil = rhs_dil[None, :] - node_sums(nodes, w * om0, E, n)
        r_dev = rhs_dev[None, :] - node_sums(nodes, w * sg0, DD, n)
        # the nodes with bonds (a shape's void nodes have none, and no multipliers)
        has = np.bincount(nodes, minlength=n) > 0
        lam, mu_ = np.zeros_like(r_dil), np.zeros_like(r_dev)
        lam[has] = solve_per_node(node_moments(nodes, w, E, n)[has], r_dil[has],
                                  "pals: the dilatation Lagrange system", x[has])
        mu_[has] = solve_per_node(node_moments(nodes, w, DD, n)[has], r_dev[has],
                                  "pals: the deviatoric Lagrange system", x[has])
        return lam, mu_

    def operators(self, model):
        """(K_e, K_theta, A_theta, A_Theta, end a's share of K_e) with the nodal
        scalars [theta; Q] (2 n)."""
        g, a, b, r = model.grid, model.bond_a, model.bond_b, model.bond_x
        d, n, nb = model.dim, g.n_ext, model.bond_a.size
        kappa, mu = self.moduli(model)
        om_a, om_b, sg_a, sg_b = self.influences(model)
        V, beta = model.node_volume, model.bond_beta
        wa, wb = beta * V[b], beta * V[a]
        m_sig = (np.bincount(a, sg_a * r * r * wa, n) + np.bincount(b, sg_b * r * r * wb, n))
        VV = beta * V[a] * V[b]
        rows = np.arange(nb)
        K_e = sp.diags(VV * 2.0 * mu * (sg_a + sg_b)).tocsr()
        k1a = VV * (om_a * r * (kappa + 2.0 * mu * m_sig[a] / d ** 2) - 2.0 * mu * sg_a * r / d)
        k1b = VV * (om_b * r * (kappa + 2.0 * mu * m_sig[b] / d ** 2) - 2.0 * mu * sg_b * r / d)
        k2a, k2b = -VV * 2.0 * mu / d * om_a * r, -VV * 2.0 * mu / d * om_b * r
        K_theta = sp.csr_matrix((np.r_[k1a, k1b, k2a, k2b],
                                 (np.r_[rows, rows, rows, rows], np.r_[a, b, n + a, n + b])),
                                shape=(nb, 2 * n))
        A_theta = sp.csr_matrix((np.r_[om_a * r * wa, om_b * r * wb, sg_a * r * wa, sg_b * r * wb],
                                 (np.r_[a, b, n + a, n + b], np.r_[rows, rows, rows, rows])),
                                shape=(2 * n, nb))
        return (K_e, K_theta, A_theta, sp.identity(2 * n, format="csr"),
                sg_a / (sg_a + sg_b))

    def node_energy(self, model, strain) -> np.ndarray:
        """W_i = kappa theta_i^2 / 2 + mu sum sigma_i (e - theta_i |xi| / d)^2 beta V_j
        under the homogeneous ``strain`` (the PALS energy, node by node)."""
        g, a, b, r = model.grid, model.bond_a, model.bond_b, model.bond_x
        d, n = model.dim, g.n_ext
        kappa, mu = self.moduli(model)
        om_a, om_b, sg_a, sg_b = self.influences(model)
        V, beta = model.node_volume, model.bond_beta
        wa, wb = beta * V[b], beta * V[a]
        e = homogeneous_extensions(r, model.bond_n, strain)
        theta = np.bincount(a, om_a * r * e * wa, n) + np.bincount(b, om_b * r * e * wb, n)
        dev = (np.bincount(a, sg_a * (e - theta[a] * r / d) ** 2 * wa, n)
               + np.bincount(b, sg_b * (e - theta[b] * r / d) ** 2 * wb, n))
        return 0.5 * kappa * theta ** 2 + mu * dev, theta

    def bulk_work_density(self, model, strain) -> float:
        """W of a node of the bulk lattice: its PALS weights from the complete stencil,
        then the energy above (equal to the bond-work attribution there, t_a = t_b)."""
        st, d = model.stencil, model.dim
        r, nvec = st.vectors(model.spacing)
        live = model.influence.omega(r, model.horizon) * st.beta > 0
        r, nvec = r[live], nvec[live]
        w = st.beta[live] * model.grid.volume * model.thickness
        E, DD = self.bases(nvec * r[:, None])
        om0, sg0 = self.reference(model, r)
        lam, mu_ = self.multipliers(np.zeros(r.size, dtype=int), w, E, DD, om0, sg0,
                                    np.zeros((1, d)))
        om, sg = om0 + E @ lam[0], sg0 + DD @ mu_[0]
        kappa, mu = self.moduli(model)
        e = homogeneous_extensions(r, nvec, strain)
        theta = np.sum(om * r * e * w)
        return float(0.5 * kappa * theta ** 2 + mu * np.sum(sg * (e - theta * r / d) ** 2 * w))


def pals_closure(params=None) -> Closure:
    return Closure(constitutive=PalsConstitutive())
