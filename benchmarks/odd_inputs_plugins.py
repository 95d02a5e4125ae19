"""Sweep of hostile plugins and signals (issue 50), on the machinery of
``benchmarks/odd_inputs.py`` (its :func:`classify`: a fresh folder, its own cache, a time
limit, exit status and first line; a traceback, a hang or a silent exit is a defect).

The plugins of ``tests/plugins/broken_plugins`` (``pdverify_hostile``,
``pdverify_hang_at_import``, ``pdverify_misbehaving``, ``pdverify_exit_at_import``) are
laid out with their entry points in a temporary site folder, as ``pip install --target``
does: plugins that exit (``sys.exit``, ``os._exit``), signal themselves (SIGTERM,
SIGSEGV), hang (in a check, a closure, ``params_for``, at import), raise in
``params_for``, or carry escape codes in their names. Besides the four defects of
odd_inputs, a case is a defect when

- a file pdverify did not create changed (data loss): a user's file beside every
  report's output folder, and the previous report in that folder must stay whole
  (replaced only by a whole new one);
- raw control characters reach the terminal (an ESC or BEL in stdout or stderr);
- a stop by a signal ends with another status than the documented one (130 SIGINT,
  143 SIGTERM, 129 SIGHUP; or death by that same signal, -n, which a shell shows as the
  same 128 + n), e.g. -14 (SIGALRM) or 130 for a SIGTERM.

    PYTHONPATH=$PWD python benchmarks/odd_inputs_plugins.py [--plugin-timeout S]

``--plugin-timeout`` sets $PDVERIFY_PLUGIN_TIMEOUT for the cases (default 10 s, to keep
the sweep short); one case lists with the default limit (60 s) to show it holds unset.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from odd_inputs import classify  # noqa: E402  (the sweep's machinery, reused)

PLUGINS = HERE.parent / "tests" / "plugins" / "broken_plugins"
ENTRY_POINTS = {
    "pdverify_hostile": [f"{n} = pdverify_hostile:{a}" for n, a in (
        ("role-check-exit", "ROLE_CHECK_EXIT"), ("check-sys-exit", "CHECK_SYS_EXIT"),
        ("check-hang", "CHECK_HANG"), ("closure-os-exit", "CLOSURE_OS_EXIT"),
        ("closure-signal", "CLOSURE_SIGNAL"), ("closure-segv", "CLOSURE_SEGV"),
        ("closure-hang", "CLOSURE_HANG"), ("called", "CALLED"),
        ("params-for-raises", "PARAMS_FOR_RAISES"), ("params-for-hangs", "PARAMS_FOR_HANGS"),
        ("escapes", "ESCAPES"), ("esc\x1b[2Jname\x07", "MISSING"))],
    "pdverify_hang_at_import": ["hang-at-import = pdverify_hang_at_import:METHOD"],
    "pdverify_misbehaving": [f"{n} = pdverify_misbehaving:{a}" for n, a in (
        ("closure-exit", "CLOSURE_EXIT"), ("factor-exit", "FACTOR_EXIT"),
        ("check-exit", "CHECK_EXIT"))],
    "pdverify_exit_at_import": ["exit-at-import = pdverify_exit_at_import:METHOD"],
}

R = ["run", "bar1d-traction", "--method"]


def cases(work: Path):
    rep = str(work / "reports" / "rep")
    a, b = str(work / "a.json"), str(work / "b.json")
    return [
        # --------------------------------------------------------- load: list, built-ins
        ("list", ["list"]),
        ("list-scene", ["list", "bar1d-traction"]),
        ("list-json", ["list", "--json"]),
        ("run-builtin", ["run", "bar1d-traction"]),
        ("run-builtin-timeout", ["run", "bar1d-traction", "--run-timeout", "100"]),
        ("run-hang-at-import", R + ["hang-at-import"]),
        ("run-exit-at-import", R + ["exit-at-import"]),
        ("run-params-for-raises", R + ["params-for-raises"]),
        ("run-params-for-hangs", R + ["params-for-hangs"]),
        # --------------------------------------------------------- checks (main process)
        ("run-role-check-exit", ["run", "wave1d-surface-nodes", "--method",
                                 "role-check-exit"]),
        ("run-check-sys-exit", R + ["check-sys-exit"]),
        ("run-check-hang", R + ["check-hang"]),
        ("run-check-hang-run-timeout", R + ["check-hang", "--run-timeout", "5"]),
        ("run-param-check-exit", ["run", "stiffness2d-sheet", "--method", "check-exit",
                                  "--set", "gain=2"]),
        # --------------------------------------------------------- the run (worker)
        ("run-closure-exit", R + ["closure-exit"]),
        ("run-factor-exit", R + ["factor-exit"]),
        ("run-closure-os-exit", R + ["closure-os-exit"]),
        ("run-closure-sigterm", R + ["closure-signal"]),
        ("run-closure-sigsegv", R + ["closure-segv"]),
        ("run-closure-hang", R + ["closure-hang"]),
        ("run-closure-hang-run-timeout", R + ["closure-hang", "--run-timeout", "1000"]),
        ("run-escapes", R + ["escapes"]),
        # --------------------------------------------------------- reports
        ("report-unselected", ["report", "--quick", "--only", "bar1d-traction", "--method",
                               "none", "--jobs", "1", "--out", rep]),
        ("report-hostile", ["report", "--quick", "--only", "bar1d-traction", "--method",
                            "none", "closure-os-exit", "closure-signal", "closure-segv",
                            "closure-hang", "check-hang", "check-sys-exit", "closure-exit",
                            "--jobs", "2", "--out", rep]),
        ("report-role-check-exit", ["report", "--quick", "--only", "wave1d-surface-nodes",
                                    "--method", "role-check-exit", "--jobs", "1", "--out",
                                    rep]),
        ("report-failed", ["report", "--quick", "--only", "bar1d-traction", "--failed",
                           "--jobs", "2", "--out", rep]),
        # --------------------------------------------------------- names from files
        ("compare-escapes", ["compare", a, b]),
    ]


def lay_out(site: Path) -> None:
    """The broken plugins laid out in ``site`` as ``pip install --target`` does (the
    tests' own helper, tests/reliability/plugin_site.py)."""
    sys.path.insert(0, str(HERE.parent / "tests" / "reliability"))
    import plugin_site
    plugin_site.install(site, ENTRY_POINTS)


def results_files(work: Path, env) -> None:
    """a.json (one run) and b.json (it and a run whose names carry escape codes)."""
    a = work / "a.json"
    subprocess.run([sys.executable, "-m", "pdverify", "run", "bar1d-traction", "--json",
                    str(a)], env={k: v for k, v in env.items() if k != "PYTHONPATH"}
                   | {"PYTHONPATH": str(HERE.parent)}, capture_output=True, check=True)
    data = json.loads(a.read_text())
    data["runs"].append(dict(data["runs"][0], method="none\x1b[2J\x1b[31m\x07",
                             status="failed", message="boom\x1b]0;title\x07"))
    (work / "b.json").write_text(json.dumps(data))


def snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def report_whole(rep: Path) -> bool:
    """No report yet, or a whole one: results.json parses and index.html is there."""
    if not rep.exists():
        return True
    try:
        json.loads((rep / "results.json").read_text())
    except (OSError, ValueError):
        return False
    return (rep / "index.html").is_file()


def run_case(argv, timeout, env):
    """classify() of odd_inputs, plus whether raw control characters were printed."""
    raw = {}

    real = subprocess.run

    def capture(*a, **k):
        r = real(*a, **k)
        raw["out"] = (r.stdout or "") + (r.stderr or "")
        return r

    subprocess.run = capture
    try:
        code, first, tb, silent = classify(argv, timeout, env)
    finally:
        subprocess.run = real
    escapes = any(c in raw.get("out", "") for c in "\x1b\x07\x9b")
    return code, first, tb, silent, escapes


EXPECTED = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGHUP: 129}


def signal_cases(env, work):
    """``run stiffness2d-sheet`` stopped by each signal at several times into it."""
    out = []
    for sig, delays in ((signal.SIGTERM, (0.5, 0.8, 1.0, 1.2, 1.5, 2.0)),
                        (signal.SIGINT, (1.0,)), (signal.SIGHUP, (1.0,))):
        for d in delays:
            p = subprocess.Popen([sys.executable, "-m", "pdverify", "run",
                                  "stiffness2d-sheet"], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, cwd=work,
                                 preexec_fn=lambda: signal.signal(signal.SIGINT,
                                                                  signal.SIG_DFL),
                                 env={k: v for k, v in env.items() if k != "PYTHONPATH"}
                                 | {"PYTHONPATH": str(HERE.parent)})
            time.sleep(d)
            p.send_signal(sig)
            so, se = p.communicate(timeout=120)
            text = (se if se.strip() else so).strip()
            first = text.splitlines()[-1] if text else ""
            code = p.returncode
            # 0: it finished first; -sig: the signal's default action, before the
            # interpreter ran pdverify or while it exited after its output (the handlers
            # are reset then), which a shell shows as the same 128 + n; never another
            # signal (-14: SIGALRM) nor another status
            ok = code in (0, EXPECTED[sig], -sig)
            out.append((f"{signal.Signals(sig).name.lower()}-at-{d:g}s", code, first,
                        not ok))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=240.0)
    ap.add_argument("--plugin-timeout", type=float, default=10.0)
    ap.add_argument("--no-default-limit", action="store_true",
                    help="skip the case at the default 60 s limit (2 min)")
    args = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="odd-plugins-"))
    site = work / "site"
    site.mkdir()
    lay_out(site)
    base_env = dict(os.environ)
    env = dict(base_env, PYTHONPATH=os.pathsep.join([str(site), str(HERE.parent)]),
               PDVERIFY_PLUGIN_TIMEOUT=f"{args.plugin_timeout:g}")
    results_files(work, base_env)
    (work / "reports").mkdir()
    mine = work / "reports" / "users-notes.txt"
    mine.write_text("a user's file beside the report folder\n")
    guarded = snapshot(work / "reports")
    rows = []
    all_cases = cases(work)
    if not args.no_default_limit:
        all_cases.append(("list-default-limit", ["list"]))
    for name, argv in all_cases:
        case_env = env
        if name == "list-default-limit":
            case_env = {k: v for k, v in env.items() if k != "PDVERIFY_PLUGIN_TIMEOUT"}
        t0 = time.monotonic()
        code, first, tb, silent, escapes = run_case(argv, args.timeout, case_env)
        seconds = time.monotonic() - t0
        now = snapshot(work / "reports")
        lost = any(now.get(k) != v for k, v in guarded.items()
                   if not k.startswith("rep/")) or not report_whole(work / "reports" / "rep")
        hang = code is None
        bad = tb or silent or hang or lost or escapes
        rows.append((name, code, first, tb, silent, hang, lost, escapes, bad))
        print(f"{'DEFECT ' if bad else ''}{name:30s} exit {code}  ({seconds:.1f} s)  "
              f"{first[:220]}", flush=True)
    for name, code, first, bad in signal_cases(env, work):
        rows.append((name, code, first, False, False, False, False, False, bad))
        print(f"{'DEFECT ' if bad else ''}{name:30s} exit {code}  {first[:220]}", flush=True)
    count = lambda i: sum(1 for r in rows if r[i])  # noqa: E731
    codes = {}
    for r in rows:
        codes[r[1]] = codes.get(r[1], 0) + 1
    print(f"\n{len(rows)} cases; exit codes: "
          + ", ".join(f"{k}: {v}" for k, v in sorted(codes.items(), key=str))
          + f"; data loss: {count(6)}; tracebacks: {count(3)}; silent exits: {count(4)}; "
          f"hangs: {count(5)}; raw control characters: {count(7)}; "
          f"defects: {count(8)}")
    shutil.rmtree(work, ignore_errors=True)
    return 1 if count(8) else 0


if __name__ == "__main__":
    sys.exit(main())
