"""Start-up time of the CLI, two checkouts side by side (issue 34: sympy is imported only
where the symbolic engine runs).

    python benchmarks/startup.py [--base /path/to/other/checkout] [--repeat 7]

Times ``python -m pdverify --version`` and ``python -m pdverify run bar1d-traction`` as
whole processes (wall clock, interpreter start included), alternating the two checkouts
run by run so that a busy machine weighs on both alike; prints the median of each, the
difference and the ratio, and whether the process imported sympy (``-X importtime``).
Each checkout runs with ``PYTHONPATH`` set to its own root. The FEM and expression
caches are not involved (bar1d-traction's reference is a closed form).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys

import harness

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COMMANDS = {"--version": ["--version"], "run bar1d-traction": ["run", "bar1d-traction"]}


def once(root: str, args: list[str]) -> None:
    env = {**os.environ, "PYTHONPATH": root}
    subprocess.run([sys.executable, "-m", "pdverify", *args], cwd=root, env=env,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)


def imports_sympy(root: str, args: list[str]) -> bool:
    env = {**os.environ, "PYTHONPATH": root}
    done = subprocess.run([sys.executable, "-X", "importtime", "-m", "pdverify", *args],
                          cwd=root, env=env, capture_output=True, text=True)
    return any(line.split("|")[-1].strip() == "sympy" for line in done.stderr.splitlines()
               if line.startswith("import time:"))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", default=None, help="the other checkout (before the change)")
    ap.add_argument("--repeat", type=int, default=7)
    harness.add_arguments(ap)
    a = ap.parse_args(argv)
    with harness.Record(__file__, a, argv=argv) as rec:
        _measure(a, rec)


def _measure(a, rec) -> None:
    roots = {"this": HERE}
    if a.base:
        roots = {"base": os.path.abspath(a.base), "this": HERE}
    print(f"python {sys.version.split()[0]}; {a.repeat} runs each, alternating; medians")
    print(f"{'command':22s} " + " ".join(f"{n:>12s}" for n in roots)
          + ("   difference   ratio" if len(roots) == 2 else "") + "   sympy imported")
    for name, args in COMMANDS.items():
        for root in roots.values():       # warm the file cache and .pyc files once
            once(root, args)
        t = harness.alternate({n: (lambda root=root: once(root, args))
                               for n, root in roots.items()}, a.repeat)
        med = {n: t[n].median for n in roots}
        line = f"{name:22s} " + " ".join(f"{med[n]:10.3f} s" for n in roots)
        if len(roots) == 2:
            line += f"   {med['base'] - med['this']:+8.3f} s   {med['base'] / med['this']:5.2f}x"
        sympy = {n: imports_sympy(r, args) for n, r in roots.items()}
        line += "   " + ", ".join(f"{n}: {'yes' if v else 'no'}" for n, v in sympy.items())
        print(line, flush=True)
        rec[name] = {**harness.summary(t, base="this"), "imports_sympy": sympy,
                     "roots": roots}


if __name__ == "__main__":
    main()
