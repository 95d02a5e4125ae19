"""What the plugin containment of issue 50 costs: ``list`` and a small report, before
(the tree at ``--before``, by default /work/base57, commit 7c77775) and after (this
tree), one run each way alternating, medians of the wall times.

Three settings: no plugin installed (the containment then forks nothing); the two
well-behaved example plugins of ``tests/plugins`` installed (``demo-uniform``, a bond
method, and ``image-nodes``, a treatment of its own class): ``list`` then pays one child
process that loads the entry points, and a report one child process per distinct check
of a plugin's case, and a supervised worker for the plugin's runs. The report is
``report --quick --only bar1d-traction --jobs 1`` (its plugin runs included).

The budget of the issue: at most 0.2 s of ``list`` and 2 % of a full report. A full
report is not timed here (151 s for 573 runs at 7c77775, /work/runs/base57/report.log);
its extra cost is extrapolated from the small report's extra cost per plugin case times
the full plan's plugin cases (counted with the example plugins installed), plus the
load's child process once.

    PYTHONPATH=$PWD python benchmarks/containment.py [--repeats N] [--before DIR]
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
AFTER = HERE.parent
PLUGINS = AFTER / "tests" / "plugins"
DEMOS = {"pdverify_demo_plugin": ("demo_plugin", "demo-uniform = pdverify_demo_plugin:METHOD"),
         "pdverify_image_nodes": ("demo_treatment_plugin",
                                  "image-nodes = pdverify_image_nodes:METHOD")}
FULL_REPORT_S = 151.0   # /work/runs/base57/report.log: the full report of 7c77775


def lay_out(site: Path) -> None:
    for package, (folder, ep) in DEMOS.items():
        shutil.copytree(PLUGINS / folder / package, site / package)
        info = site / f"{package}-0.1.0.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\n"
                                       "Version: 0.1.0\n")
        (info / "entry_points.txt").write_text(f"[pdverify.methods]\n{ep}\n")


def timed(tree: Path, argv, site, work: Path) -> float:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        ([str(site)] if site else []) + [str(tree)]),
        PDVERIFY_CACHE_DIR=str(work / f"cache-{tree.name}-{bool(site)}"))
    out = work / "out"
    shutil.rmtree(out, ignore_errors=True)
    argv = [a if a != "OUT" else str(out) for a in argv]
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "pdverify", *argv], env=env, cwd=work,
                       capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    if r.returncode not in (0,):
        raise SystemExit(f"{tree}: {' '.join(argv)} -> exit {r.returncode}: "
                         f"{(r.stderr or r.stdout)[-500:]}")
    return seconds


def plugin_cases(site: Path, argv_only=None) -> tuple[int, int]:
    """(plugin cases, all cases) of the full report's plan with the example plugins."""
    code = ("import sys; from pdverify.runner import plan, is_plugin; "
            "from pdverify.scenes import get_scene; "
            f"cs = plan(only={argv_only!r}); "
            "print(sum(is_plugin(get_scene(s), m) for s, m, _ in cs), len(cs))")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(AFTER)]))
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       check=True)
    a, b = r.stdout.split()
    return int(a), int(b)


def mechanism_costs(site: Path, repeats: int) -> str:
    """The containment's own costs, timed inside one process (little disturbed by the
    other load): the load's child process for the example plugins' entry points (the
    probe alone, then the whole load of the plugins: probe and import), and one contained
    check (a child process for a call that returns at once)."""
    code = f"""
import statistics, time
from pdverify.scenes import all_scenes
from pdverify.corrections import containment, registry
all_scenes()
def med(fn, n={repeats * 4}):
    out = []
    for _ in range(n):
        t0 = time.perf_counter(); fn(); out.append(time.perf_counter() - t0)
    return statistics.median(out)
from importlib.metadata import entry_points
eps = list(entry_points(group="pdverify.methods"))
probe = med(lambda: containment.probe(len(eps), lambda k: registry._load(eps[k])[1]))
def load():
    registry.reload(); registry.treatments()
whole = med(load)
check = med(lambda: containment.in_child(lambda: None))
print(f"{{len(eps)}} {{probe:.4f}} {{whole:.4f}} {{check:.4f}}")
"""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(AFTER)]))
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    if r.returncode:
        return f"(mechanism timing failed: {r.stderr[-300:]})"
    n, probe, whole, check = r.stdout.split()
    return (f"inside one process, medians: the load's child process for {n} entry points "
            f"{1e3 * float(probe):.1f} ms (the whole load of the plugins, probe and "
            f"import: {1e3 * float(whole):.1f} ms); one contained check "
            f"{1e3 * float(check):.1f} ms")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--before", default="/work/base57")
    args = ap.parse_args()
    before = Path(args.before)
    work = Path(tempfile.mkdtemp(prefix="containment-"))
    site = work / "site"
    site.mkdir()
    lay_out(site)
    settings = [
        ("list, no plugin", ["list"], None),
        ("list, 2 example plugins", ["list"], site),
        ("report --quick --only bar1d-traction, no plugin",
         ["report", "--quick", "--only", "bar1d-traction", "--jobs", "1", "--out", "OUT"],
         None),
        ("report --quick --only bar1d-traction, 2 example plugins",
         ["report", "--quick", "--only", "bar1d-traction", "--jobs", "1", "--out", "OUT"],
         site),
    ]
    print(f"before: {before} | after: {AFTER} | {args.repeats} alternating runs each; "
          "under load (shared machine)")
    rows = []
    for name, argv, s in settings:
        timed(AFTER, argv, s, work)          # warm the caches of both trees once
        timed(before, argv, s, work)
        b, a = [], []
        for _ in range(args.repeats):
            b.append(timed(before, argv, s, work))
            a.append(timed(AFTER, argv, s, work))
        mb, ma = statistics.median(b), statistics.median(a)
        rows.append((name, mb, ma))
        print(f"{name:58s} before {mb:7.3f} s  after {ma:7.3f} s  extra {ma - mb:+.3f} s "
              f"({100 * (ma - mb) / mb:+.1f} %)", flush=True)
    small_plugin, small_all = plugin_cases(site, ["bar1d-traction"])
    full_plugin, full_all = plugin_cases(site)
    extra_small = rows[3][2] - rows[3][1]
    extra_load = max(0.0, rows[1][2] - rows[1][1])
    per_case = max(0.0, extra_small - extra_load) / max(1, small_plugin)
    full_extra = extra_load + per_case * full_plugin
    print(f"\nsmall report: {small_plugin} plugin cases of {small_all}; full plan with the "
          f"example plugins: {full_plugin} plugin cases of {full_all}")
    print(f"extrapolated extra of a full report with the example plugins: {full_extra:.2f} s "
          f"= {100 * full_extra / FULL_REPORT_S:.2f} % of {FULL_REPORT_S:g} s "
          f"(no plugin installed: {rows[2][2] - rows[2][1]:+.3f} s on the small report)")
    print(mechanism_costs(site, args.repeats))
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
