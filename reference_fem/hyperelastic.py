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
    """Internal force vector and tangent of ``model``'s 2D mesh and material at
    displacement ``u`` (both times the thickness, like ``TensorElasticity.stiffness``).

    Assembled from scikit-fem's basis data (the quadrature weights, the element dofs and
    the gradients of the local basis functions) with batched matrix products over the
    elements and quadrature points: f_r = sum_q P : grad phi_r dx and
    K_rs = sum_q grad phi_r : A : grad phi_s dx, A_iKjL = dP_iK / dF_jL
    = delta_ij S_KL + F_iM C_MKNL F_jN. Local vector function r = 2 a + i is the scalar
    function a times the unit vector e_i (scikit-fem's ``ElementVector`` order, checked
    here), so only the 9 scalar gradients enter the products. Every element of a
    tensor-product mesh is an axis-aligned box (checked), so its gradients are the first
    element's times 1 / h_K: the displacement gradient and the internal force are then one
    contraction each with those 9 x 2 x n_q numbers. The global matrix is summed into a
    CSR pattern fixed at construction. (A scikit-fem ``BilinearForm`` evaluates its form
    per pair of local basis functions; that took 1.5-2.5 s per tangent at 12,826 dofs;
    ``numpy.einsum`` over all 18 vector functions 0.07-0.2 s, these products 0.02-0.05 s;
    the residual 0.007-0.017 s before, 0.002-0.005 s now: loaded 2-core machine.)
    """

    def __init__(self, model: TensorElasticity):
        if model.dim != 2:
            raise ValueError(f"StVenantKirchhoff: 2D models only, got dim = {model.dim}")
        self.model, self.basis = model, model.basis
        self.lam, self.mu = model.material.lame()
        self.scale = model.material.scale
        b = self.basis
        # grad of every local vector basis function: (local, component, derivative, el, qp)
        self.dphi = dphi = np.stack([b.basis[r][0].grad for r in range(b.Nbfun)])
        grad = dphi[0::2, 0]                                   # scalar gradients (a, K, e, q)
        if not (np.array_equal(dphi[1::2, 1], grad) and not dphi[0::2, 1].any()
                and not dphi[1::2, 0].any()):
            raise RuntimeError("StVenantKirchhoff: local basis is not (scalar function) x "
                               "(unit vector) in the order 2 a + i")
        self.n_el, self.n_qp = b.dx.shape
        self._grad = np.ascontiguousarray(grad.transpose(2, 3, 0, 1))   # (e, q, a, K)
        self._grad_t = np.ascontiguousarray(grad.transpose(2, 0, 3, 1)).reshape(
            self.n_el, grad.shape[0], -1)                               # (e, a, (q, K))
        # every element is an axis-aligned box (tensor-product mesh): its gradients are
        # the first element's times 1 / h_K (h_K: the element's edge along K)
        self._ghat = grad[:, :, 0, :].reshape(grad.shape[0], -1)     # (a, (K, q))
        self._inv_h = (np.abs(grad).sum(axis=(0, 3))
                       / np.abs(grad[:, :, 0, :]).sum(axis=(0, 2))[:, None])   # (K, e)
        affine = grad[:, :, 0, None, :] * self._inv_h[None, :, :, None]
        if np.max(np.abs(affine - grad)) > 1e-12 * np.max(np.abs(grad)):
            raise RuntimeError("StVenantKirchhoff: the elements are not axis-aligned boxes")
        self.dx = b.dx
        self.dofs = b.element_dofs                             # (local, el)
        # CSR pattern of the global matrix and where each element entry (e, r, s) goes
        N, nloc = b.N, b.Nbfun
        rows = np.broadcast_to(self.dofs.T[:, :, None], (self.n_el, nloc, nloc)).ravel()
        cols = np.broadcast_to(self.dofs.T[:, None, :], (self.n_el, nloc, nloc)).ravel()
        keys, self._slot = np.unique(rows.astype(np.int64) * N + cols, return_inverse=True)
        self._indices = (keys % N).astype(np.int32)
        self._indptr = np.searchsorted(keys // N, np.arange(N + 1)).astype(np.int32)
        self._nnz = keys.size

    def _state(self, u):
        """F and S per quadrature point, each (i, K, e, q)."""
        ne, nq = self.n_el, self.n_qp
        ue = np.asarray(u)[self.dofs].reshape(-1, 2, ne)                # (a, i, e)
        # grad u[i, K, e, q] = sum_a u[a, i, e] grad phi_a[K, q] / h_K[e]: one product
        # (np.einsum, not a BLAS product: threaded BLAS on these thin shapes was 20-80
        # times slower on a loaded 2-core machine; benchmarks/fem_indentation.py)
        G = np.einsum("aie,ak->iek", ue, self._ghat).reshape(2, ne, 2, nq)
        F = G.transpose(0, 2, 1, 3) * self._inv_h[None, :, :, None]
        F[0, 0] += 1.0
        F[1, 1] += 1.0
        return F, self._stress(F)

    def _stress(self, F):
        """The second Piola-Kirchhoff stress S(F), (K, L, e, q)."""
        E = np.empty_like(F)
        for K in range(2):
            for L in range(K, 2):
                E[K, L] = E[L, K] = 0.5 * (F[0, K] * F[0, L] + F[1, K] * F[1, L] - (K == L))
        S = 2.0 * self.mu * E
        tr = self.lam * (E[0, 0] + E[1, 1])
        S[0, 0] += tr
        S[1, 1] += tr
        return S

    def internal_force(self, u) -> np.ndarray:
        F, S = self._state(u)
        ne = self.n_el
        W = np.empty((2, ne, 2, self.n_qp))                              # (i, e, K, q)
        for i in range(2):
            for K in range(2):
                W[i, :, K] = ((F[i, 0] * S[0, K] + F[i, 1] * S[1, K]) * self.dx
                              * self._inv_h[K][:, None])
        # f[a, i, e] = sum_{K, q} P[i, K, e, q] dx[e, q] grad phi_a[K, q] / h_K[e]
        fe = np.einsum("iek,ak->aie", W.reshape(2, ne, -1), self._ghat)
        return self.scale * np.bincount(self.dofs.ravel(), fe.ravel(), self.basis.N)

    def tangent(self, u) -> sp.csr_matrix:
        F, S = self._state(u)                                  # (i, K, e, q)
        A = self._moduli(F, S)
        A *= self.dx[:, :, None, None, None, None]
        # Y[e, q, (K, i, j), b] = sum_L A[..., L] grad[e, q, b, L]
        Y = A.reshape(self.n_el, self.n_qp, 8, 2) @ np.swapaxes(self._grad, 2, 3)
        # Ke[e, a, (i, j, b)] = sum_{q, K} grad[e, q, a, K] Y[e, q, K, (i, j, b)]
        nb = self._grad.shape[2]
        Ke = self._grad_t @ Y.reshape(self.n_el, 2 * self.n_qp, 4 * nb)
        Ke = Ke.reshape(self.n_el, nb, 2, 2, nb).transpose(0, 1, 2, 4, 3)  # (e, a, i, b, j)
        data = np.bincount(self._slot, Ke.ravel(), self._nnz)
        N = self.basis.N
        return sp.csr_matrix((self.scale * data, self._indices, self._indptr), shape=(N, N))

    def _moduli(self, F, S):
        """A[e, q, K, i, j, L] = dP_iK / dF_jL per quadrature point."""
        lam, mu = self.lam, self.mu
        FFt = np.einsum("iMeq,jMeq->ijeq", F, F)
        # A[e, q, K, i, j, L] = delta_ij S_KL + lam F_iK F_jL + mu (F_iL F_jK + (F F^T)_ij
        # delta_KL), times the quadrature weight; laid out so the products below need no
        # transposition
        A = np.empty((self.n_el, self.n_qp, 2, 2, 2, 2))
        for K in range(2):
            for i in range(2):
                for j in range(2):
                    for L in range(2):
                        a = lam * F[i, K] * F[j, L] + mu * F[i, L] * F[j, K]
                        if i == j:
                            a += S[K, L]
                        if K == L:
                            a += mu * FFt[i, j]
                        A[:, :, K, i, j, L] = a
        return A

    def min_jacobian(self, u) -> tuple[float, np.ndarray]:
        """The smallest det F over all quadrature points and where it is (x, y): <= 0 means
        the mesh has folded (an inverted element)."""
        F, _ = self._state(u)
        det = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
        k = np.unravel_index(np.argmin(det), det.shape)
        x = self.basis.mapping.F(self.basis.X)[:, k[0], k[1]]
        return float(det[k]), x


class NeoHookean(StVenantKirchhoff):
    """The compressible neo-Hookean law with the same Lame parameters, on the same mesh
    machinery: W = mu / 2 (tr C - 2 - 2 ln J) + lam / 2 (ln J)^2 (2D), so
    S = mu (I - C^-1) + lam ln J C^-1 and, with G = F C^-1 = F^-T and c = mu - lam ln J,
    A_iKjL = delta_ij S_KL + lam G_iK G_jL + c (delta_ij C^-1_KL + G_iL G_jK) (the
    material tangent lam C^-1 (x) C^-1 + c (C^-1_IK C^-1_JL + C^-1_IL C^-1_JK) pushed
    through F, using F C^-1 F^T = I). For small strains both laws reduce to the same linear
    elasticity; in compression the neo-Hookean law stiffens (ln J -> -inf as J -> 0) where
    St Venant-Kirchhoff softens. A state with J <= 0 has no energy: its stress is NaN, so
    Newton's line search rejects the step and the mesh-folding check names it.
    """

    def _inverse_c(self, F):
        """(C^-1 (K, L, e, q), J, G = F^-T (i, K, e, q))."""
        J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            G = np.empty_like(F)                         # F^-T
            G[0, 0], G[1, 1] = F[1, 1] / J, F[0, 0] / J
            G[0, 1], G[1, 0] = -F[1, 0] / J, -F[0, 1] / J
        Ci = np.einsum("iKeq,iLeq->KLeq", G, G)          # C^-1 = F^-1 F^-T
        return Ci, J, G

    def _stress(self, F):
        Ci, J, _ = self._inverse_c(F)
        with np.errstate(divide="ignore", invalid="ignore"):
            lnJ = np.where(J > 0, np.log(np.where(J > 0, J, 1.0)), np.nan)
        S = -self.mu * Ci + self.lam * lnJ * Ci
        S[0, 0] += self.mu
        S[1, 1] += self.mu
        return S

    def _moduli(self, F, S):
        Ci, J, G = self._inverse_c(F)
        with np.errstate(divide="ignore", invalid="ignore"):
            lnJ = np.where(J > 0, np.log(np.where(J > 0, J, 1.0)), np.nan)
        c = self.mu - self.lam * lnJ
        eye = np.eye(2)
        A = (np.einsum("ij,KLeq->eqKijL", eye, S + c * Ci)
             + self.lam * np.einsum("iKeq,jLeq->eqKijL", G, G)
             + np.einsum("eq,iLeq,jKeq->eqKijL", c, G, G))
        return np.ascontiguousarray(A)


#: the finite-strain material laws by name
LAWS = {"saint-venant-kirchhoff": StVenantKirchhoff, "neo-hookean": NeoHookean}
