"""The engine's grid, stencil and contract: placements, volumes, one-way imports, the CLI switch."""
import ast
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from pdverify.pd import BoxGrid, build_stencil, partial_volumes, stencil_offsets

EPS = np.finfo(float).eps
PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "pdverify"


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_on_surface_grid_volumes_tile_the_box(dim):
    # seed 003 (ERRATA): nodes on the surface carry half a cell on faces (edges in 2D), a
    # quarter at 2D corners (an eighth at 3D corners); together the nodes tile the box
    lengths = (0.5, 0.3, 0.4)[:dim]
    g = BoxGrid(lengths, (0.0,) * dim, 0.1, placement="on-surface")
    assert g.n_interior == np.prod([round(L / 0.1) + 1 for L in lengths])
    np.testing.assert_allclose(g.node_volume.sum(), np.prod(lengths), rtol=50 * EPS)
    corner = g.ext_id([0] * dim)
    assert g.node_volume[corner] == pytest.approx(0.1 ** dim / 2 ** dim, rel=EPS)
    assert g.x[corner] == pytest.approx(np.zeros(dim))
    full = BoxGrid(lengths, (0.0,) * dim, 0.1, placement="on-surface", boundary_volume="full")
    np.testing.assert_array_equal(full.node_volume, np.full(full.n_ext, 0.1 ** dim))


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_cell_centred_grid_with_layers_and_surface_nodes(dim):
    g = BoxGrid((0.4,) * dim, (0.0,) * dim, 0.1, layers=3)
    assert g.n_interior == 4 ** dim and g.n_ext == 10 ** dim
    assert np.all(g.kind[g.interior_ids] == 0) and np.sum(g.kind == 1) == g.n_ext - g.n_interior
    # one surface node per boundary cell face, on the surface, with an outward normal
    assert g.n_surface == 2 * dim * 4 ** (dim - 1)
    on = np.isclose(g.surface_x, 0.0) | np.isclose(g.surface_x, 0.4)
    assert np.all(on.any(axis=1))
    axis = np.abs(g.surface_normal).argmax(axis=1)
    np.testing.assert_array_equal(g.surface_face // 2, axis)


@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("m_ratio", [1.0, 2.5, 3.0, 4.0])
def test_partial_volumes_sum_to_the_ball(dim, m_ratio):
    # the cell fractions of a full stencil plus the node's own cell add up to the ball
    # (interval, disk, sphere) of radius m_ratio in units of cells: exact to round-off
    k = stencil_offsets(dim, m_ratio)
    ball = {1: 2 * m_ratio, 2: np.pi * m_ratio ** 2, 3: 4 / 3 * np.pi * m_ratio ** 3}[dim]
    own = 1.0  # the node's own cell lies inside the ball for m_ratio >= 1
    # closed-form areas (2D) and 24-point Gauss per smooth piece (3D): round-off, ~1e4 eps
    assert partial_volumes(k, m_ratio).sum() + own == pytest.approx(ball, rel=1e-12)


def test_the_1d_stencil_is_seed_000s():
    # ERRATA seed 000: cell-centred nodes, beta = 1/2 for the node at |xi| = delta
    s = build_stencil(1, 3.0)
    np.testing.assert_array_equal(s.half_offsets[:, 0], [1, 2, 3])
    np.testing.assert_array_equal(s.half_beta, [1.0, 1.0, 0.5])
    with pytest.raises(ValueError, match="moment-corrected"):
        build_stencil(1, 3.0, quadrature="moment-corrected", moment_weight=lambda k: k[:, 0])


def _imports(path):
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            yield ("." * node.level) + (node.module or "")
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names)


def test_the_engine_imports_neither_corrections_nor_scenes():
    # dependencies run one way: scenes -> corrections -> engine
    bad = [(p.name, mod) for p in (PACKAGE / "pd").glob("*.py") for mod in _imports(p)
           if "corrections" in mod or "scenes" in mod or "report" in mod]
    assert bad == []
    up = [(p.name, mod) for p in (PACKAGE / "corrections").glob("*.py") for mod in _imports(p)
          if "scenes" in mod or "report" in mod]
    assert up == []


def test_no_model_module_is_left_at_the_package_root():
    gone = {"operators", "bondbar1d", "micromodulus1d", "statebased_nd", "bonds", "bonds_nd",
            "grid", "materials"}
    assert gone.isdisjoint(p.stem for p in PACKAGE.glob("*.py"))


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, timeout=120)


def test_influence_is_one_set_away_on_a_2d_scene():
    res = _cli("run", "plate2d-plane-strain", "--method", "surface-nodes",
               "--set", "spacing=0.05", "--set", "influence=hyperbolic")
    assert res.returncode == 0, res.stderr
    default = _cli("run", "plate2d-plane-strain", "--method", "surface-nodes",
                   "--set", "spacing=0.05")
    pick = [next(ln for ln in r.stdout.splitlines() if "max_error_u_pct" in ln)
            for r in (res, default)]
    assert pick[0] != pick[1]  # the influence function reached the model


@pytest.mark.parametrize("args, words", [
    (("body3d-manufactured", "--set", "influence=conical"), "allowed: gaussian"),
    (("plate2d-plane-strain", "--set", "influence=cubic"),
     "allowed: conical, constant, gaussian, hyperbolic"),
    (("wave1d-surface-nodes", "--set", "influence=gaussian"), "unknown key 'influence'"),
])
def test_unsupported_influence_is_one_line_exit_2(args, words):
    res = _cli("run", *args)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in res.stderr
