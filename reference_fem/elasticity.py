"""Linear elasticity with quadratic Lagrange elements on tensor-product meshes (scikit-fem)."""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Callable, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import (Basis, ElementHex2, ElementQuad2, ElementVector, FacetBasis,
                   LinearForm, MeshHex, MeshQuad, asm, condense)
from skfem.models.elasticity import lame_parameters, linear_elasticity

from .field import FieldSolution, midpoint_refined

MODES = ("plane_stress", "plane_strain", "3d")


@dataclass(frozen=True)
class Material:
    """Isotropic linear-elastic material.

    Attributes
    ----------
    E : Young's modulus (Pa).
    nu : Poisson's ratio.
    mode : ``"plane_stress"``, ``"plane_strain"`` (both 2D) or ``"3d"``.
    thickness : out-of-plane thickness (m) of a 2D model; stiffness, loads and
        reactions scale with it, displacements under given loads do not. Ignored in 3D.
    """

    E: float
    nu: float
    mode: str = "plane_stress"
    thickness: float = 1.0

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"mode {self.mode!r} unknown; allowed: {', '.join(MODES)}")
        if not self.E > 0:
            raise ValueError(f"E must be positive, got {self.E!r}")
        if not -1.0 < self.nu < 0.5:
            raise ValueError(f"nu must lie in (-1, 0.5), got {self.nu!r}")
        if not self.thickness > 0:
            raise ValueError(f"thickness must be positive, got {self.thickness!r}")

    @property
    def dim(self) -> int:
        return 3 if self.mode == "3d" else 2

    def lame(self) -> tuple[float, float]:
        """Effective Lame parameters (lambda, mu) of the model's dimension.

        Plane stress uses lambda* = E nu / (1 - nu^2) (sigma_zz = 0 eliminated);
        plane strain and 3D use the 3D lambda = E nu / ((1 + nu)(1 - 2 nu)).
        """
        lam, mu = lame_parameters(self.E, self.nu)
        if self.mode == "plane_stress":
            lam = self.E * self.nu / (1.0 - self.nu ** 2)
        return float(lam), float(mu)

    @property
    def scale(self) -> float:
        """Factor from a per-area 2D integral to the model (the thickness); 1 in 3D."""
        return self.thickness if self.dim == 2 else 1.0


class ElasticityBasis:
    """What every elasticity model here shares: DOF selection and the stiffness, from a
    vector ``basis`` with ``dof_coords``/``dof_component`` and a :class:`Material`."""

    def dofs(self, where: Callable[..., np.ndarray] | None = None,
             components: Sequence[int] | None = None) -> np.ndarray:
        """Global DOF numbers whose location satisfies ``where(x, y[, z])`` (vectorised
        boolean function; ``None`` = all) and whose component is in ``components``."""
        mask = np.ones(self.basis.N, dtype=bool)
        if where is not None:
            mask &= np.asarray(where(*self.dof_coords), dtype=bool)
        if components is not None:
            mask &= np.isin(self.dof_component, np.asarray(components))
        return np.flatnonzero(mask)

    @cached_property
    def stiffness(self) -> sp.csr_matrix:
        """Global stiffness matrix K (times the thickness in 2D)."""
        lam, mu = self.material.lame()
        K = asm(linear_elasticity(lam, mu), self.basis)
        return (self.material.scale * K).tocsr()

    def solve(self, f: np.ndarray, fixed: np.ndarray, values: np.ndarray | float = 0.0,
              K: sp.spmatrix | None = None) -> np.ndarray:
        """Solve K u = f with u[fixed] = values, by condensation (``skfem.condense``)
        and a sparse LU factorisation (SuperLU, symmetric ordering)."""
        K = self.stiffness if K is None else K
        fixed = np.asarray(fixed, dtype=np.int64)
        x = np.zeros(self.basis.N)
        x[fixed] = values
        A, b, x, I = condense(K, f, x=x, D=fixed)
        if A.shape[0] == 0:
            return x
        lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A")
        x[I] = lu.solve(b)
        if not np.all(np.isfinite(x)):
            raise FloatingPointError("solve: non-finite displacement (singular system? "
                                     "check the supports remove every rigid motion)")
        return x


class TensorElasticity(ElasticityBasis):
    """Small-strain elasticity on a tensor-product mesh of quadratic elements.

    2D uses the 9-node biquadratic ``ElementQuad2``, 3D the 27-node triquadratic
    ``ElementHex2``, both as ``ElementVector``. On a tensor-product mesh every element
    is an axis-aligned box, so the element map is affine and the discrete space is exactly
    the piecewise tensor-product quadratics; the solution is therefore stored and
    evaluated on the midpoint-refined grid (see :class:`FieldSolution`).

    Parameters
    ----------
    coords : one strictly increasing 1D array of vertex coordinates per axis (2 or 3).
    material : :class:`Material`; its dimension must match ``len(coords)``.
    """

    def __init__(self, coords: Sequence[np.ndarray], material: Material):
        self.coords = tuple(np.asarray(c, dtype=float) for c in coords)
        if len(self.coords) != material.dim:
            raise ValueError(f"{len(self.coords)} coordinate axes for a {material.mode} material "
                             f"(needs {material.dim})")
        for k, c in enumerate(self.coords):
            if c.ndim != 1 or c.size < 2 or np.any(np.diff(c) <= 0):
                raise ValueError(f"axis {k}: coordinates must be 1D, >= 2 values, "
                                 "strictly increasing")
        self.material = material
        self.dim = material.dim
        if self.dim == 2:
            self.mesh = MeshQuad.init_tensor(*self.coords)
            self.element = ElementVector(ElementQuad2())
        else:
            self.mesh = MeshHex.init_tensor(*self.coords)
            self.element = ElementVector(ElementHex2())
        self.basis = Basis(self.mesh, self.element)
        self.grid = tuple(midpoint_refined(c) for c in self.coords)
        self._map_dofs_to_grid()

    # --- degrees of freedom -------------------------------------------------------------
    def _map_dofs_to_grid(self):
        """Map each global DOF to (component, index on the midpoint-refined grid)."""
        n = self.basis.N
        comp = np.empty(n, dtype=np.int64)
        flat = np.empty(n, dtype=np.int64)
        shape = tuple(g.size for g in self.grid)
        for c, idx in enumerate(self.basis.split_indices()):
            loc = self.basis.doflocs[:, idx]
            ijk = []
            for k, g in enumerate(self.grid):
                tol = 1e-9 * (g[-1] - g[0])
                i = np.clip(np.searchsorted(g, loc[k] - tol), 0, g.size - 1)
                if np.any(np.abs(g[i] - loc[k]) > tol):
                    raise RuntimeError("DOF locations do not match the refined tensor grid")
                ijk.append(i)
            comp[idx] = c
            flat[idx] = np.ravel_multi_index(tuple(ijk), shape)
        self.dof_component = comp
        self.dof_grid_index = flat
        self.dof_coords = self.basis.doflocs

    def body_load(self, b: Sequence[float]) -> np.ndarray:
        """Load vector of a uniform body force density b (N/m^3)."""
        b = np.asarray(b, dtype=float)

        @LinearForm
        def form(v, w):
            return sum(b[k] * v[k] for k in range(self.dim))

        return self.material.scale * asm(form, self.basis)

    def traction_load(self, on: Callable[..., np.ndarray], t: Sequence[float]) -> np.ndarray:
        """Load vector of a uniform traction t (Pa) on the boundary facets whose midpoints
        satisfy ``on(x, y[, z])``."""
        t = np.asarray(t, dtype=float)
        facets = self.mesh.facets_satisfying(lambda x: on(*x), boundaries_only=True)
        if facets.size == 0:
            raise ValueError("traction_load: no boundary facet satisfies the selector")
        fb = FacetBasis(self.mesh, self.element, facets=facets)

        @LinearForm
        def form(v, w):
            return sum(t[k] * v[k] for k in range(self.dim))

        return self.material.scale * asm(form, fb)

    # --- solution -----------------------------------------------------------------------
    def reactions(self, u: np.ndarray, f: np.ndarray | None = None) -> np.ndarray:
        """Reaction forces K u - f (N); nonzero only on constrained DOFs up to round-off."""
        r = self.stiffness @ u
        return r if f is None else r - f

    def strain_energy(self, u: np.ndarray) -> float:
        """Total strain energy 1/2 u^T K u (J; in 2D for the model's thickness)."""
        return 0.5 * float(u @ (self.stiffness @ u))

    def field(self, u: np.ndarray) -> FieldSolution:
        """The displacement field as a self-contained :class:`FieldSolution`."""
        shape = tuple(g.size for g in self.grid)
        values = np.empty((int(np.prod(shape)), self.dim))
        values[self.dof_grid_index, self.dof_component] = u
        lam, mu = self.material.lame()
        return FieldSolution(coords=self.coords, values=values.reshape(shape + (self.dim,)),
                             lam=lam, mu=mu)
