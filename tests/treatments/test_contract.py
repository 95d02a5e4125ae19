"""The treatment contract: scenes of a problem family never name a method outside their
``cases`` and published numbers, every empty cell of the method x scene matrix has its
one-line reason, and the package's import graph runs one way."""
import ast
from pathlib import Path

import pytest

import pdverify
from pdverify.corrections.registry import treatments
from pdverify.corrections.registry import from_name
from pdverify.errors import InputError
from pdverify.scenes import all_scenes

PACKAGE = Path(pdverify.__file__).parent


SCENES = PACKAGE / "scenes"


def _scene_modules():
    """Every module of ``pdverify/scenes`` (the family bases and the scenes alike)."""
    return sorted(str(p) for p in SCENES.glob("*.py"))


def _is_call(node, name):
    f = node.func if isinstance(node, ast.Call) else None
    return (isinstance(f, ast.Name) and f.id == name) or (
        isinstance(f, ast.Attribute) and f.attr == name)


def _allowed_nodes(tree):
    """Nodes where a method name belongs: a ``cases`` method, the published numbers (a
    ``published = (...)`` assignment or a ``Published(...)`` call), the documented
    findings (``expected_failures``), the runs a docstring quotes (``doc_quotes``, a
    ``Quote(...)``: they name runs as the published numbers do), and strings that are not method names although
    they may read like one: a parameter's definition (``Param(...)``: a choice such as
    ``predictor="none"``) and dictionaries' keys and values other than a ``"method"``
    key's (field names such as ``"energy"``, parameter values)."""
    allowed = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.name == "cases":
            allowed |= {id(n) for n in ast.walk(node)}
        if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id in ("published", "expected_failures")
                for t in node.targets):
            allowed |= {id(n) for n in ast.walk(node)}
        if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == "doc_quotes" for t in node.targets):
            allowed |= {id(n) for n in ast.walk(node)}
        if _is_call(node, "Published") or _is_call(node, "Param"):
            allowed |= {id(n) for n in ast.walk(node)}
        if isinstance(node, ast.Dict):
            for k, v in zip(node.keys, node.values):
                if k is not None:
                    allowed.add(id(k))
                if not (isinstance(k, ast.Constant) and k.value == "method"):
                    allowed |= {id(n) for n in ast.walk(v)} if isinstance(v, ast.Constant) \
                        else set()
    return allowed


def _names():
    """The registry's treatments, less the scenes' references (``fem``: a scene states
    its reference, which is no boundary treatment)."""
    return set(treatments()) - {s.reference for s in all_scenes()}


def _reference_test(node) -> bool:
    """``FEM.name`` or ``self.reference``: a branch on the scene's reference run."""
    return isinstance(node, ast.Attribute) and (
        (node.attr == "name" and isinstance(node.value, ast.Name) and node.value.id == "FEM")
        or node.attr == "reference")


def _method_branches(tree):
    """Comparisons of a ``method`` variable with anything but the reference or a kind
    test (``method in self.bond_methods()``): a branch on a method's name."""
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Compare):
            continue
        sides = [node.left, *node.comparators]
        if not any(isinstance(n, ast.Name) and n.id == "method" for n in sides):
            continue
        others = [n for n in sides if not (isinstance(n, ast.Name) and n.id == "method")]
        if any(_names_a_method(n) for n in others):
            out.append(node)
    return out


def _names_a_method(node) -> bool:
    """A string, a collection of strings, a module constant (``NONE``) or a spec's name
    (``HOMOGENIZED.name``) other than the reference's; not a variable (``method_of``,
    matching a published entry to a run) and not a call (a kind test)."""
    if _reference_test(node) or isinstance(node, ast.Call):
        return False
    if isinstance(node, ast.Constant):
        return isinstance(node.value, str)
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return any(_names_a_method(e) for e in node.elts)
    if isinstance(node, ast.Name):
        return node.id.isupper()
    return isinstance(node, ast.Attribute) and node.attr == "name"


def _offenders(path, tree, names):
    allowed = _allowed_nodes(tree)
    out = [f"{Path(path).name}:{n.lineno} {n.value!r}" for n in ast.walk(tree)
           if isinstance(n, ast.Constant) and n.value in names and id(n) not in allowed]
    out += [f"{Path(path).name}:{n.lineno} branches on the method"
            for n in _method_branches(tree) if id(n) not in allowed]
    return out


def test_scene_modules_name_no_method_outside_cases_and_published():
    names = _names()
    mods = _scene_modules()
    assert {Path(m).name for m in mods} >= {"bar1d.py", "surface_nodes.py", "plate2d.py",
                                            "wave1d.py", "sheets.py", "indentation.py",
                                            "bar1d_bondbased.py", "bar1d_flux.py", "base.py"}
    offenders = []
    for path in mods:
        offenders += _offenders(path, ast.parse(Path(path).read_text()), names)
    assert not offenders, offenders


@pytest.mark.parametrize("body", [
    "        return method == 'surface-nodes'\n",
    "        return method == HOMOGENIZED.name\n",
    "        return method in ('none', 'virtual-nodes')\n",
    "        x = {'method': 'pddo'}\n",
])
def test_the_grep_can_fail(body):
    """A method name or a branch on it in a scene body is found (the test above can
    fail), whether literal or through a constant."""
    tree = ast.parse("class S:\n    def solve(self, method):\n" + body)
    assert _offenders("s.py", tree, _names())


@pytest.mark.parametrize("body", [
    "        return method == FEM.name\n",
    "        return method in self.bond_methods()\n",
    "        return {'energy': 1.0, 'predictor': 'none'}\n",
])
def test_the_grep_passes_the_reference_and_kind_tests(body):
    tree = ast.parse("class S:\n    def solve(self, method):\n" + body)
    assert _offenders("s.py", tree, _names()) == []


def test_every_empty_cell_has_a_reason():
    for scene in all_scenes():
        offered = {m.name for m in scene.all_methods}
        for name, t in treatments().items():
            reason = t.why_not(scene)
            if name in offered:
                assert reason is None, (scene.id, name, reason)
            else:
                assert reason, (scene.id, name)
                assert "\n" not in reason


def test_list_prints_the_reasons_and_the_counts():
    from pdverify.listing import format_matrix
    text = format_matrix()
    assert "why a cell is empty" in text
    assert "seed 004 derives its factors for the triangular micromodulus" in text
    assert "taylor-fictitious" in text.split("why a cell is empty", 1)[1]


def test_from_name_suggests_close_matches():
    with pytest.raises(InputError, match="did you mean surface-nodes"):
        from_name("surface-node")
    assert from_name("pddo").info()["kind"] == "family"


def _imports(module_path: Path, module: str):
    """The pdverify modules ``module`` imports (absolute and relative, at any depth)."""
    tree = ast.parse(module_path.read_text())
    pkg = module if module_path.name == "__init__.py" else module.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.startswith("pdverify"):
                out.add(target)
                out |= {f"{target}.{a.name}" for a in node.names}
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("pdverify")}
    return out


def _graph():
    mods = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        name = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        mods[name] = path
    graph = {m: {t for t in _imports(p, m) if t in mods and t != m} for m, p in mods.items()}
    return graph


def _cycles(graph):
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))
    for v in graph:
        if v not in index:
            visit(v)
    return out


#: the packages each layer may not import (the issue's one-way graph: scenes ->
#: corrections -> pd; solvers below scenes; report on top)
FORBIDDEN = {
    "pdverify.pd": ("pdverify.corrections", "pdverify.scenes", "pdverify.solvers",
                    "pdverify.report", "pdverify.runner", "pdverify.cli"),
    "pdverify.solvers": ("pdverify.corrections", "pdverify.scenes", "pdverify.report",
                         "pdverify.runner", "pdverify.cli"),
    "pdverify.corrections": ("pdverify.scenes", "pdverify.report", "pdverify.runner",
                             "pdverify.cli"),
    "pdverify.scenes": ("pdverify.report", "pdverify.runner", "pdverify.cli"),
}


def test_import_graph_has_no_cycle_between_modules():
    """Package __init__ modules that only re-export are left out (a package imports its
    own modules by design); imports inside functions count."""
    graph = _graph()
    inits = {m for m in graph if (PACKAGE.parent / Path(*m.split("."))).is_dir()}
    g = {m: {t for t in ts if t not in inits} for m, ts in graph.items() if m not in inits}
    assert _cycles(g) == []


def test_import_graph_runs_one_way():
    graph = _graph()
    wrong = [(m, t) for m, ts in graph.items() for layer, bad in FORBIDDEN.items()
             if m.startswith(layer) for t in ts if t.startswith(bad)]
    assert wrong == []


def test_cycle_finder_can_fail():
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": set()}) == [["a", "b"]]


def test_a_whole_faces_only_treatment_is_refused_where_part_of_a_face_is_prescribed():
    """No built-in needs it since mirror-nodes and pddo choose their relation per boundary
    cell; a plugin that can impose a component only on whole faces declares
    ``whole_faces_only`` and gets its one-line reason on body3d-traction (its v and w
    constraints hold on one cell row of a face), not on body3d-manufactured."""
    import dataclasses
    from pdverify.scenes import get_scene
    t = dataclasses.replace(treatments()["mirror-nodes"], name="whole-faces-demo",
                            whole_faces_only=True, scope="whole faces only (demo)")
    reason = t.why_not(get_scene("body3d-traction"))
    assert reason and "prescribes a component on part of a face" in reason
    assert t.why_not(get_scene("body3d-manufactured")) is None


#: the modules of ``pdverify.corrections`` a scene may import: the generic ones (the
#: registry, the family's shared assembly, the plugin signatures), never a correction
GENERIC_CORRECTIONS = {"pdverify.corrections", "pdverify.corrections.registry",
                       "pdverify.corrections.assembly", "pdverify.corrections.protocols",
                       "pdverify.corrections.treatment"}


def _specific_corrections(graph):
    return sorted((m, t) for m, ts in graph.items() if m.startswith("pdverify.scenes")
                  for t in ts if t.startswith("pdverify.corrections")
                  and t not in GENERIC_CORRECTIONS
                  and t.rsplit(".", 1)[0] not in GENERIC_CORRECTIONS - {"pdverify.corrections"})


def test_no_scene_imports_a_specific_correction():
    """A scene reaches a treatment through the registry only (issue 51); what a scene
    measures with (work densities, the bar's calibration) lives in ``pdverify.pd``."""
    assert _specific_corrections(_graph()) == []


def test_the_correction_import_check_can_fail():
    graph = {"pdverify.scenes.x": {"pdverify.corrections.factors",
                                   "pdverify.corrections.factors.work_density",
                                   "pdverify.corrections.registry",
                                   "pdverify.corrections.registry.plugin_call"}}
    assert [t for _, t in _specific_corrections(graph)] == [
        "pdverify.corrections.factors", "pdverify.corrections.factors.work_density"]


def _fallback_defaults(text: str) -> list[str]:
    """``p.get(NAME, DEFAULT)`` / ``params.get(NAME, DEFAULT)``: a default stated again
    beside its declaration."""
    import re
    return re.findall(r"\b(?:p|params|q)\.get\(\s*['\"]\w+['\"]\s*,[^)]*\)", text)


def test_scenes_read_declared_defaults_not_fallbacks():
    """A scene reads a parameter's default from its declaration (``Scene.declared``, the
    treatment's parameter), never from a second literal beside the lookup (issue 51)."""
    found = {p.name: _fallback_defaults(p.read_text())
             for p in (PACKAGE / "scenes").glob("*.py")}
    assert {k: v for k, v in found.items() if v} == {}


def test_the_fallback_grep_can_fail():
    assert _fallback_defaults('x = p.get("solver", "direct")\nq.get("order", 2) == 2\n'
                              'y = p.get("solver") == "auto"') == [
        'p.get("solver", "direct")', 'q.get("order", 2)']
