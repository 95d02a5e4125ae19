"""What the plugin containment of issue 50 costs: ``list`` and a small report, before
(the tree at ``--before``, by default /work/base57, commit 7c77775) and after (this
tree), one run each way alternating, medians of the wall times.

Three settings: no plugin installed (the containment then forks nothing); the two
well-behaved example plugins of ``tests/plugins`` installed (``demo-uniform``, a bond
method, and ``image-nodes``, a treatment of its own class): ``list`` then pays one child
process that loads the entry points, and a report one child process per distinct check
of a plugin's case, and a supervised worker for the plugin's runs. The report is
``report --quick --only bar1d-traction --jobs 1`` (its plugin runs included).

The budget of the issue: at most 0.2 s of ``list`` and 2 % of a full report. The wall
times of whole commands on this shared machine scatter by more than that budget, so the
containment's own costs are also timed inside fresh processes (the first load of the
plugins, before and after; one contained check). A full report is not timed here (151 s
for 573 runs at 7c77775, /work/runs/base57/report.log): it pays the load once (its
workers are forks of the report process) and one child process per distinct check of a
plugin's case that runs plugin code (none for the example plugins); the worst case, a
check on every plugin case of the full plan, is printed beside.

    PYTHONPATH=$PWD python benchmarks/containment.py [--repeats N] [--before DIR]
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

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


def load_costs(before: Path, site: Path, repeats: int):
    """The load of the plugins itself, timed inside fresh processes (the interpreter's
    start and the scenes' import left out, so little disturbed by other load): the first
    ``treatments()`` of a process with the example plugins installed, before and after,
    alternating; and one contained check (a child process for a call that returns at
    once)."""
    code = """
import time
from pdverify.scenes import all_scenes
all_scenes()
from pdverify.corrections import registry
t0 = time.perf_counter(); registry.treatments(); t1 = time.perf_counter()
try:
    from pdverify.corrections import containment
    c0 = time.perf_counter(); containment.in_child(lambda: None); c = time.perf_counter() - c0
except ImportError:
    c = float('nan')
print(t1 - t0, c)
"""
    times = {"before": [], "after": [], "check": []}
    for _ in range(repeats):
        for name, tree in (("before", before), ("after", AFTER)):
            env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(tree)]))
            r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                               text=True, check=True)
            load, check = map(float, r.stdout.split())
            times[name].append(load)
            if name == "after":
                times["check"].append(check)
    mb, ma = harness.median(times["before"]), harness.median(times["after"])
    check = harness.median(times["check"])
    return (f"first treatments() of a process, 2 example plugins: before {1e3 * mb:.1f} ms, "
            f"after {1e3 * ma:.1f} ms, extra {1e3 * (ma - mb):+.1f} ms; one contained "
            f"check {1e3 * check:.1f} ms"), ma - mb, check


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--before", default="/work/base57")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)


def _measure(args, rec):
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
        t = harness.alternate({"before": lambda: timed(before, argv, s, work),
                               "after": lambda: timed(AFTER, argv, s, work)}, args.repeats,
                              rotate=False)
        mb, ma = harness.median(t["before"].results), harness.median(t["after"].results)
        rows.append((name, mb, ma))
        rec[name] = {"before_s": t["before"].results, "after_s": t["after"].results,
                     "median_before_s": mb, "median_after_s": ma}
        print(f"{name:58s} before {mb:7.3f} s  after {ma:7.3f} s  extra {ma - mb:+.3f} s "
              f"({100 * (ma - mb) / mb:+.1f} %)", flush=True)
    full_plugin, full_all = plugin_cases(site)
    text, load_extra, check = load_costs(before, site, 2 * args.repeats)
    print(text)
    rec["load_costs"] = {"text": text, "load_extra_s": load_extra, "check_s": check}
    # a full report pays the load once (its workers are forks of the report process) and
    # a child process per distinct check of a plugin's case; the example plugins have no
    # check of their own (no child process); a plugin with a check on every case is the
    # worst case
    worst = max(0.0, load_extra) + full_plugin * check
    print(f"full plan with the example plugins: {full_plugin} plugin cases of {full_all}; "
          f"extra of a full report: {1e3 * max(0.0, load_extra):.0f} ms = "
          f"{100 * max(0.0, load_extra) / FULL_REPORT_S:.2f} % of {FULL_REPORT_S:g} s; "
          f"were every plugin case checked by the plugin: {worst:.2f} s = "
          f"{100 * worst / FULL_REPORT_S:.2f} %")
    shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
