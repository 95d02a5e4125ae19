"""Real peridynamic codes run on pdverify's scenes (``peer:NAME`` methods).

A peer is another program that solves a scene's uncorrected node set (the export of
:mod:`pdverify.exchange`) with its own model; its displacements are scored exactly as a
file given to ``pdverify score`` is: the scene's own ``measure``, and the equilibrium
check of :func:`pdverify.exchange.equilibrium`. Today: LAMMPS's PERI package
(:mod:`pdverify.peers.lammps`).
"""
