"""What the checks of the outputs and the storage cost before a command's work (issue 31:
under 50 ms per run).

Plain script (no test runner):

    python benchmarks/output_checks.py [--repeat N] [--entries N] [--report DIR]

Times, as medians over ``--repeat`` calls (default 200), each check that ``run``,
``report`` and ``compare`` make before any work: ``--out`` onto a previous report folder
(walked and matched against its marker), the cache folder's probe file, the free space
of the output's disk, and ``--json``/``--summary`` onto a file pdverify wrote. The report
folder is ``--report DIR`` (a copy is used) or a ``report --quick --only bar1d-traction``
made here; it is padded with dummy figures and VTU files, listed in its marker, up to
``--entries`` entries (default 1000, above the few hundred of a full report), so that
the walk costs what it costs on a large report.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import harness


def _median_ms(fn, repeat: int) -> float:
    fn()                                   # warm: imports, the OS's caches
    return 1e3 * harness.alternate({"x": fn}, repeat, collect=False)["x"].median


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=200)
    ap.add_argument("--entries", type=int, default=1000)
    ap.add_argument("--report", default=None, metavar="DIR")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        return _measure(args, rec)


def _measure(args, rec) -> int:
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    sys.path.insert(0, here)
    from pdverify import outputs, validate
    from pdverify.report.folder import estimate_bytes

    with tempfile.TemporaryDirectory() as tmp:
        os.environ["PDVERIFY_CACHE_DIR"] = os.path.join(tmp, "cache")
        os.makedirs(os.environ["PDVERIFY_CACHE_DIR"])
        rep = os.path.join(tmp, "rep")
        if args.report:
            shutil.copytree(args.report, rep, symlinks=True)
        else:
            env = {**os.environ, "PYTHONPATH": here + os.pathsep + os.environ.get("PYTHONPATH", "")}
            subprocess.run([sys.executable, "-m", "pdverify", "report", "--quick", "--only",
                            "bar1d-traction", "--out", rep], env=env, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        n = len(outputs._tree(rep))
        for k in range(max(0, args.entries - n)):
            sub, ext = ("figures", ".png") if k % 3 == 0 else ("fields", ".vtu")
            os.makedirs(os.path.join(rep, sub), exist_ok=True)
            with open(os.path.join(rep, sub, f"pad-{k:05d}{ext}"), "wb") as fh:
                fh.write(b"x" * 100)
        outputs.write_marker(rep, complete=True)
        assert outputs.folder_state(rep) == ("report", "")
        summary = os.path.join(tmp, "s.md")
        with open(summary, "w") as fh:
            fh.write("# pdverify compare: 0 regression(s), 0 other change(s)\n")
        os.chdir(tmp)
        checks = {
            "--out onto a previous report (validate.output_dir)":
                lambda: validate.output_dir(rep),
            "cache folder probe (outputs.check_cache)": outputs.check_cache,
            "free space for the report (outputs.check_free)":
                lambda: outputs.check_free(tmp, estimate_bytes(range(300)), "--out"),
            "--summary onto its own file (validate.output_file)":
                lambda: validate.output_file(summary, "--summary",
                                             inputs=((rep + "/results.json", "baseline"),)),
        }
        print(f"report folder: {len(outputs._tree(rep))} entries; median of {args.repeat}")
        total = {}
        for name, fn in checks.items():
            total[name] = _median_ms(fn, args.repeat)
            print(f"  {name:55s} {total[name]:7.3f} ms")
        report_total = sum(v for k, v in total.items() if "summary" not in k)
        print(f"  {'report: --out + cache + free space':55s} {report_total:7.3f} ms "
              f"(budget 50 ms: {'met' if report_total < 50 else 'MISSED'})")
        rec.update({"entries": len(outputs._tree(rep)), "repeat": args.repeat,
                    "median_ms": total, "report_checks_ms": report_total})
        os.chdir(here)
    return 0


if __name__ == "__main__":
    sys.exit(main())
