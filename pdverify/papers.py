"""The seed papers: authors, title, year, venue and DOI, for the report's list of papers.

Authors, titles and years are those printed in the seed texts (``../shared/seeds``). A
DOI is given only where it was checked against the publisher's page (``doi_checked``);
the seed texts print none of their own DOIs, so the others are left empty rather than
recalled.
"""
from __future__ import annotations

PAPERS = {
    "000": {
        "authors": "F. Scabbia, M. Zaccariotto, U. Galvanetto",
        "title": "A novel and effective way to impose boundary conditions and to mitigate "
                 "the surface effect in state-based Peridynamics",
        "year": 2021, "venue": "International Journal for Numerical Methods in Engineering",
        "doi": None, "doi_checked": None},
    "001": {
        "authors": "F. Scabbia, M. Zaccariotto, U. Galvanetto",
        "title": "A New Surface Node Method to Accurately Model the Mechanical Behavior of "
                 "the Boundary in 3D State-Based Peridynamics",
        "year": 2023, "venue": "Journal of Peridynamics and Nonlocal Modeling",
        "doi": "10.1007/s42102-022-00094-1",
        "doi_checked": "https://link.springer.com/article/10.1007/s42102-022-00094-1"},
    "002": {
        "authors": "F. Scabbia, M. Zaccariotto, U. Galvanetto, F. Bobaru",
        "title": "Peridynamic simulation of elastic wave propagation by applying the "
                 "boundary conditions with the surface node method",
        "year": None, "venue": None, "doi": None, "doi_checked": None},
    "003": {
        "authors": "J. Ritter, S. Sheguftha, P. Steinmann, M. Zaiser",
        "title": "An energetically consistent surface correction method for bond-based "
                 "peridynamics",
        "year": None, "venue": None, "doi": None, "doi_checked": None},
    "004": {
        "authors": "K. Eriksson, C. Stenström",
        "title": "Homogenization of the 1D Peri-static/dynamic Bar with Triangular "
                 "Micromodulus",
        "year": 2020, "venue": "Journal of Peridynamics and Nonlocal Modeling",
        "doi": "10.1007/s42102-020-00042-x",
        "doi_checked": "https://link.springer.com/article/10.1007/s42102-020-00042-x"},
}


def seed_of(scene_seed: str) -> str:
    """The paper key of a scene's ``seed`` field, e.g. ``"001 §4.1"`` -> ``"001"``; ""
    for a scene without a seed (e.g. a plugin's or a test's)."""
    parts = (scene_seed or "").split()
    return parts[0] if parts else ""
