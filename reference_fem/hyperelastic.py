"""St Venant-Kirchhoff finite-strain elasticity on a :class:`TensorElasticity` mesh
(scikit-fem): internal forces and the consistent tangent for Newton's method.

Material: S = lambda tr(E) I + 2 mu E with the Green-Lagrange strain E = (F^T F - I) / 2
and P = F S. In 2D the Lame parameters are the model's (``Material.lame``), so a
plane-stress model uses lambda* = E nu / (1 - nu^2): a 2D (membrane) St Venant-Kirchhoff
law that reduces to plane-stress linear elasticity for small strains. A true finite-strain
plane-stress state would solve for the thickness stretch as well; at the few percent of
strain of the indentation the two differ in terms of second order in the strain.

The tangent is dP = dF S + F dS with dS = lambda tr(dE) I + 2 mu dE, dE = sym(F^T dF).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .elasticity import TensorElasticity


class StVenantKirchhoff:
    """Internal force vector and tangent of ``model``'s mesh and material at displacement
    ``u`` (both times the thickness in 2D, like ``TensorElasticity.stiffness``).

    Assembled here from scikit-fem's basis data (the gradients of the local vector basis
    functions, the quadrature weights and the element dofs) with one contraction per
    quantity: f_r = sum_q P : grad phi_r dx and
    K_rs = sum_q grad phi_r : A : grad phi_s dx, A_iKjL = dP_iK / dF_jL
    = delta_ij S_KL + F_iM C_MKNL F_jN. (A scikit-fem ``BilinearForm`` evaluates its form per
    pair of local basis functions; that took 1.5-2.5 s per tangent at 12,826 dofs.)
    """

    def __init__(self, model: TensorElasticity):
        self.model, self.basis = model, model.basis
        self.lam, self.mu = model.material.lame()
        self.scale = model.material.scale
        b = self.basis
        # grad of every local vector basis function: (local, component, derivative, el, qp)
        self.dphi = np.stack([b.basis[r][0].grad for r in range(b.Nbfun)])
        self.dx = b.dx
        self.dofs = b.element_dofs
        nloc = b.Nbfun
        self._rows = np.repeat(self.dofs[:, None, :], nloc, axis=1).ravel()
        self._cols = np.repeat(self.dofs[None, :, :], nloc, axis=0).ravel()

    def _state(self, u):
        dim = self.model.dim
        ue = np.asarray(u)[self.dofs]                      # (local, el)
        G = np.einsum("riKeq,re->iKeq", self.dphi, ue)
        eye = np.eye(dim)[:, :, None, None]
        F = G + eye
        E = 0.5 * (np.einsum("kiep,kjep->ijep", F, F) - eye)
        S = 2.0 * self.mu * E + self.lam * np.trace(E)[None, None] * eye
        return F, S

    def internal_force(self, u) -> np.ndarray:
        F, S = self._state(u)
        P = np.einsum("ikep,kjep->ijep", F, S)
        fe = np.einsum("riKeq,iKeq,eq->re", self.dphi, P, self.dx)
        return self.scale * np.bincount(self.dofs.ravel(), fe.ravel(), self.basis.N)

    def tangent(self, u):
        F, S = self._state(u)
        dim = self.model.dim
        lam, mu = self.lam, self.mu
        eye = np.eye(dim)
        # A_iKjL = delta_ij S_KL + lam F_iK F_jL + mu (F_iL F_jK + (F F^T)_ij delta_KL)
        FFt = np.einsum("iMeq,jMeq->ijeq", F, F)
        A = (np.einsum("ij,KLeq->iKjLeq", eye, S)
             + lam * np.einsum("iKeq,jLeq->iKjLeq", F, F)
             + mu * np.einsum("iLeq,jKeq->iKjLeq", F, F)
             + mu * np.einsum("ijeq,KL->iKjLeq", FFt, eye))
        Z = np.einsum("iKjLeq,sjLeq,eq->siKeq", A, self.dphi, self.dx)
        Ke = np.einsum("riKeq,siKeq->rse", self.dphi, Z)
        N = self.basis.N
        K = sp.csr_matrix((Ke.ravel(), (self._rows, self._cols)), shape=(N, N))
        return self.scale * K

    def min_jacobian(self, u) -> tuple[float, np.ndarray]:
        """The smallest det F over all quadrature points and where it is (x, y): <= 0 means
        the mesh has folded (an inverted element)."""
        F, _ = self._state(u)
        det = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
        k = np.unravel_index(np.argmin(det), det.shape)
        x = self.basis.mapping.F(self.basis.X)[:, k[0], k[1]]
        return float(det[k]), x
