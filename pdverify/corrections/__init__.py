"""Boundary treatments ('methods'), one module per method; this is their name index."""

METHODS = {
    "none": "uncorrected PD: truncated neighbourhoods, BCs on the nodes nearest the boundary",
    "taylor-fictitious": "seed 000: fictitious layer by nearest-node Taylor extrapolation, "
                         "Dirichlet/Neumann via Lagrange multipliers",
    "surface-nodes": "seeds 001/002: surface nodes carry the boundary conditions, fictitious layer "
                     "by Taylor extrapolation about the nearest surface node",
    "homogenized": "seed 004: stiffness factors on the end bonds (1, 1+k), (N, N-k) so that a "
                   "linear field satisfies every equilibrium equation (1D bond-based)",
    "fem": "classical-elasticity FEM reference (reference_fem)",
}


def describe(name: str) -> str:
    return METHODS.get(name, "")
