"""Boundary treatments ('methods'), one module per method; this is their name index."""

METHODS = {
    "none": "uncorrected PD: truncated neighbourhoods, BCs on the nodes nearest the boundary",
    "taylor-fictitious": "seed 000: fictitious layer by nearest-node Taylor extrapolation (1D "
                         "series along the normal; 2D corners by Eq. 69), Dirichlet/Neumann "
                         "via Lagrange multipliers",
    "surface-nodes": "seeds 001/002: surface nodes carry the boundary conditions, fictitious layer "
                     "by Taylor extrapolation about the nearest surface node",
    "homogenized": "seed 004: stiffness factors on the end bonds (1, 1+k), (N, N-k) so that a "
                   "linear field satisfies every equilibrium equation (1D bond-based)",
    "energy-directional": "seed 003: bond stiffness times (phi(x, e) + phi(x', -e))/2, phi the "
                          "Eq. (14) ratio of the horizon's radial integral to its truncated part "
                          "along the bond direction (bond-based)",
    "virtual-nodes": "seed 003 §4.1.2: buffer layers of thickness delta outside the clamped edges, "
                     "displaced rigidly (bond-based)",
    "mirror-nodes": "seed 001 §5: a delta-thick fictitious layer whose nodes copy mirror "
                    "nodes inside the body (odd reflection for Dirichlet components, the "
                    "traction through the Neumann relation)",
    "pddo": "seed 001 §5: peridynamic differential operator (moment matrices exact for "
            "quadratics) for the boundary rows and the equilibrium within 2 delta, LPS beyond",
    "fem": "classical-elasticity FEM reference (reference_fem)",
}


def describe(name: str) -> str:
    if name in METHODS:
        return METHODS[name]
    from .registry import bond_methods
    m = bond_methods().get(name)
    return "" if m is None else m.description
