"""The house drawn as text: for each package folder of the middle of the stack
(``pdverify/corrections``, ``pdverify/scenes``, ``pdverify/solvers``) every module's line
count and the pdverify modules it imports (``module -> imports``; a lazy import, inside a
function, is marked ``~``; one for the type checker only, under ``if TYPE_CHECKING:``,
``:``), then the lines per folder.

    python benchmarks/house.py [FOLDER ...]

Reads the source only (``ast``); imports nothing of pdverify.
"""
from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = ("pdverify/corrections", "pdverify/scenes", "pdverify/solvers")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _resolve(node: ast.ImportFrom, here: str, is_package: bool) -> list[str]:
    """The absolute module names an ``from ... import ...`` names (a name imported from
    a package may be a submodule: both are listed when the submodule exists)."""
    if node.level:
        base = here.split(".")
        base = base[:len(base) - node.level + (1 if is_package else 0)]
        mod = ".".join(base + ([node.module] if node.module else []))
    else:
        mod = node.module or ""
    out = [mod]
    for alias in node.names:
        sub = f"{mod}.{alias.name}"
        if (ROOT / Path(*sub.split("."))).with_suffix(".py").exists() or \
                (ROOT / Path(*sub.split(".")) / "__init__.py").exists():
            out.append(sub)
    return out


def imports_of(path: Path) -> dict[str, str]:
    """pdverify modules imported by ``path``: name -> ``""`` (at import), ``"~"`` (only
    lazily, in a function body) or ``":"`` (only for the type checker)."""
    tree = ast.parse(path.read_text())
    here = _module_name(path)
    is_package = path.name == "__init__.py"
    found: dict[str, str] = {}
    rank = {"": 0, "~": 1, ":": 2}

    def visit(node, mark: str):
        for child in ast.iter_child_nodes(node):
            inner = mark
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                inner = mark or "~"
            elif isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                inner = ":"
            if isinstance(child, ast.Import):
                names = [a.name for a in child.names]
            elif isinstance(child, ast.ImportFrom):
                names = _resolve(child, here, is_package)
            else:
                visit(child, inner)
                continue
            for name in names:
                if name.startswith("pdverify"):
                    old = found.get(name, ":")
                    found[name] = mark if rank[mark] < rank[old] else old
    visit(tree, "")
    # a module and its parent package both listed: keep the most specific
    return {m: lazy for m, lazy in found.items()
            if not any(o.startswith(m + ".") for o in found)}


def draw(folder: str) -> tuple[list[str], int]:
    lines, total = [], 0
    pkg = folder.replace("/", ".")
    for path in sorted((ROOT / folder).glob("*.py")):
        n = len(path.read_text().splitlines())
        total += n
        name = _module_name(path)
        short = name.removeprefix(pkg + ".") if name != pkg else "__init__"
        deps = []
        for m, lazy in sorted(imports_of(path).items()):
            label = m.removeprefix(pkg + ".") if m.startswith(pkg + ".") else \
                m.removeprefix("pdverify.").replace("pdverify", "(pdverify)")
            if m.startswith(pkg + ".") or m == pkg:
                label = label if m != pkg else "(package)"
            else:
                label = "../" + label
            deps.append(lazy + label)
        lines.append(f"  {short:<24} {n:>5}  -> {', '.join(deps) if deps else '-'}")
    return lines, total


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="*", metavar="FOLDER",
                    help=f"package folders (default: {' '.join(FOLDERS)})")
    folders = ap.parse_args(argv).folders or list(FOLDERS)
    totals = {}
    for folder in folders:
        lines, total = draw(folder)
        totals[folder] = total
        print(f"{folder}/  ({total} lines; '../x' outside the folder, '~' lazy import, "
              "':' type checker only)")
        print("\n".join(lines))
        print()
    print("lines per folder:")
    for folder, total in totals.items():
        print(f"  {folder:<24} {total:>6}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
