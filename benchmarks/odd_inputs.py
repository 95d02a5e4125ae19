"""Sweep of odd inputs, as a new user would try them (issues 31 and 50): every case runs
``python -m pdverify`` in a fresh folder with its own cache and a time limit, and is
classified by exit code and first line; a traceback, a hang, a silent exit (no output at
all), data loss (a file the case's folder held before that pdverify did not create is
changed or gone, or a case's own check fails) or an exit status other than the one a case
expects (a wrong verdict) is a defect. Prints the outcome table (each case's exit status,
peak memory and first line) and the counts; exits 1 on any defect.

    PYTHONPATH=$PWD python benchmarks/odd_inputs.py [--timeout S] [--group NAME]

``--group issue50-files`` runs the file, export, score and published-check cases of
issue 50 only.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

R = ["run"]
#: (id, argv): the cases of issue 31's robustness part first, then further odd inputs
CASES = [
    # ------------------------------------------------------------ listed in issue 31
    ("issue-spacing-subnormal", R + ["bar1d-traction", "--set", "spacing=5e-324"]),
    ("issue-length-huge", R + ["bar1d-traction", "--set", "length=1e308"]),
    ("issue-3d-m-ratio", R + ["stiffness3d-box", "--set", "m_ratio=1e300"]),
    ("issue-scheduler-inproc", ["report", "--scheduler", "inproc://x"]),
    ("issue-fem-n-steps", R + ["block2d-indentation", "--set", "n_steps=100000000"]),
    ("issue-wave-one-term", R + ["wave1d-surface-nodes", "--set", "n_terms=1"]),
    ("issue-wave-five-terms", R + ["wave1d-surface-nodes", "--set", "n_terms=5"]),
    ("issue-force-subnormal", R + ["bar1d-traction", "--set", "force=1e-320"]),
    ("issue-depth-tiny", R + ["block2d-indentation", "--set", "depth=1e-12"]),
    ("issue-order-hex", R + ["bar1d-traction", "--method", "taylor-fictitious", "--set",
                             "order=0x2"]),
    ("issue-ratio-digits", R + ["bar1d-vibration", "--set", "dt_factor=1.0003"]),
    # ------------------------------------------------------------ further odd inputs
    ("force-minus-zero", R + ["bar1d-traction", "--set", "force=-0.0"]),
    ("force-smallest-allowed", R + ["bar1d-traction", "--set", "force=5e-307"]),
    ("force-below-smallest", R + ["bar1d-traction", "--set", "force=4e-307"]),
    ("force-largest-double", R + ["bar1d-traction", "--set", "force=1.7e308"]),
    ("force-plus-inf", R + ["bar1d-traction", "--set", "force=+inf"]),
    ("force-spaces", R + ["bar1d-traction", "--set", "force= 1e4 "]),
    ("force-suffix", R + ["bar1d-traction", "--set", "force=1e4x"]),
    ("force-negative-tiny", R + ["bar1d-sine-load", "--set", "bs=-1e-140"]),
    ("E-1e-300", R + ["bar1d-traction", "--set", "E=1e-300"]),
    ("E-1e300", R + ["bar1d-traction", "--set", "E=1e300"]),
    ("E-above-1e300", R + ["bar1d-traction", "--set", "E=2e300"]),
    ("spacing-1e-100", R + ["bar1d-traction", "--set", "spacing=1e-100"]),
    ("spacing-exp-form", R + ["bar1d-traction", "--set", "spacing=0.05e0"]),
    ("m-ratio-1e15", R + ["bar1d-traction", "--set", "m_ratio=1e15"]),
    ("nu-near-half", R + ["bar1d-traction", "--set", "nu=0.4999999999999"]),
    ("nu-near-minus-one", R + ["bar1d-traction", "--set", "nu=-0.9999999"]),
    ("influence-upper-case", R + ["bar1d-traction", "--set", "influence=HYPERBOLIC"]),
    ("order-plus-sign", R + ["bar1d-traction", "--method", "taylor-fictitious", "--set",
                             "order=+1"]),
    ("order-one-point-zero", R + ["bar1d-traction", "--method", "taylor-fictitious", "--set",
                                 "order=1.0"]),
    ("order-minus-zero", R + ["bar1d-traction", "--method", "taylor-fictitious", "--set",
                              "order=-0"]),
    ("order-binary", R + ["bar1d-traction", "--method", "taylor-fictitious", "--set",
                          "order=0b1"]),
    ("wave-n-terms-zero", R + ["wave1d-surface-nodes", "--set", "n_terms=0"]),
    ("wave-n-terms-20", R + ["wave1d-surface-nodes", "--set", "n_terms=20"]),
    ("wave-n-terms-huge", R + ["wave1d-surface-nodes", "--set", "n_terms=1e308"]),
    ("wave-dt-1e-100", R + ["wave1d-surface-nodes", "--set", "dt=1e-100"]),
    ("wave-m-ratio-1e6", R + ["wave1d-surface-nodes", "--set", "m_ratio=1e6"]),
    ("wave-horizon-half", R + ["wave1d-surface-nodes", "--set", "horizon=0.5"]),
    ("vibration-two-nodes", R + ["bar1d-vibration", "--set", "nodes=2"]),
    ("vibration-periods-1e9", R + ["bar1d-vibration", "--set", "periods=1e9"]),
    ("homogenization-ratio-huge", R + ["bar1d-homogenization", "--set",
                                       "horizon_ratio=1e308"]),
    ("homogenization-nodes-huge", R + ["bar1d-homogenization", "--set", "nodes=1e308"]),
    ("indent-depth-below-smallest", R + ["block2d-indentation", "--set", "depth=2.99e-7"]),
    ("indent-n-steps-zero", R + ["block2d-indentation", "--set", "n_steps=0"]),
    ("indent-radius-1e-100", R + ["block2d-indentation", "--set", "radius=1e-100"]),
    ("sheet-m-ratio-1e15", R + ["stiffness2d-sheet", "--set", "m_ratio=1e15"]),
    ("box-spacing-1e-100", R + ["body3d-traction", "--set", "spacing=1e-100"]),
    ("box-m-ratio-huge", R + ["body3d-traction", "--set", "m_ratio=1e308"]),
    ("box-spacing-coarse", R + ["stiffness3d-box", "--set", "spacing=0.5"]),
    ("clamped-elements-zero", R + ["sheet2d-clamped", "--set", "elements=0"]),
    ("plate-levels-100", R + ["plate2d-clamped", "--set", "levels=100"]),
    ("scheduler-no-host", ["report", "--scheduler", "tcp://"]),
    ("scheduler-ucx", ["report", "--scheduler", "ucx://a:1"]),
    ("scheduler-ws-scheme-only", ["report", "--scheduler", "ws://"]),
    ("jobs-exponent", ["report", "--jobs", "1e3"]),
    ("max-memory-overflow", R + ["bar1d-traction", "--max-memory", "1e400"]),
    ("max-memory-negative", R + ["bar1d-traction", "--max-memory", "-1G"]),
    ("set-empty", R + ["bar1d-traction", "--set", ""]),
    ("scene-empty", R + [""]),
    ("method-empty", R + ["bar1d-traction", "--method", ""]),
    ("list-extra-flag", ["list", "--nonsense"]),
    ("no-command", []),
]



# ------------------------------------------------------------------ issue 50: files pdverify reads
BASE57 = "/work/runs/base57/results.json"   # a full report of 7c77775 (the baseline)
VICTIM = "victim.txt"                        # in every case's folder: must stay as it was


def _pdverify(cwd, *argv):
    return subprocess.run([sys.executable, "-m", "pdverify", *argv], cwd=cwd,
                          capture_output=True, text=True, timeout=600)


def _export(cwd, out="ex", fmt="csv", scene="bar1d-traction"):
    assert _pdverify(cwd, "export", scene, "--format", fmt, "--out", out).returncode == 0


def _marker_add(cwd, folder, name, *entries):
    path = os.path.join(cwd, folder, name)
    with open(path) as fh:
        doc = json.load(fh)
    doc["entries"] += list(entries)
    with open(path, "w") as fh:
        json.dump(doc, fh)


def _export_marker(*entries):
    def setup(cwd):
        _export(cwd)
        _marker_add(cwd, "ex", ".pdverify-export",
                    *[e.replace("{cwd}", cwd) for e in entries])
    return setup


def _score_marker_outside(cwd):
    _export(cwd)
    _marker_add(cwd, "ex", ".pdverify-export", "/etc/passwd")
    with open(os.path.join(cwd, "ex", "back.csv"), "w") as fh:
        fh.write("x,ux\n0.025,1e-9\n")


def _export_symlink(cwd):
    _export(cwd)
    os.mkdir(os.path.join(cwd, "outside"))
    with open(os.path.join(cwd, "outside", "kept.txt"), "w") as fh:
        fh.write("theirs")
    os.symlink(os.path.join(cwd, "outside"), os.path.join(cwd, "ex", "link"))
    _marker_add(cwd, "ex", ".pdverify-export", "link", "link/kept.txt")


def _report_marker(cwd):
    from pdverify.outputs import write_marker
    os.mkdir(os.path.join(cwd, "rep"))
    write_marker(os.path.join(cwd, "rep"), complete=True)
    _marker_add(cwd, "rep", ".pdverify-report", "../" + VICTIM)


def _record(path, files, method="external:mycode"):
    from pdverify.results import RunResult, write_results
    write_results(path, [RunResult(scene="bar1d-traction", method=method, params={},
                                   reference="analytic", metrics={"max_error_pct": 1.0},
                                   files=list(files))])


def _include_outside(cwd):
    _record(os.path.join(cwd, "ext.json"), ["../" + VICTIM])


def _failed_outside(cwd):
    from pdverify.outputs import write_marker
    os.mkdir(os.path.join(cwd, "rep"))
    _record(os.path.join(cwd, "rep", "results.json"), ["../" + VICTIM], method="none")
    write_marker(os.path.join(cwd, "rep"), complete=True)


class Skip(Exception):
    """A case this machine cannot set up (printed as skipped, not a defect)."""


def _nearly_full(cwd):
    """A previous export on a 2 MB file system (a tmpfs, mounted as root; otherwise the
    case is skipped) filled to a few kB free: the next export must be refused before it
    touches the previous one."""
    tiny = os.path.join(cwd, "tiny")
    os.mkdir(tiny)
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", tiny],
                      capture_output=True).returncode != 0:
        raise Skip("mounting a small tmpfs needs root")
    _export(cwd, out="tiny/ex")
    fd = os.open(os.path.join(tiny, "filler"), os.O_WRONLY | os.O_CREAT, 0o644)
    try:
        while True:
            os.write(fd, b"\0" * 4096)
    except OSError:
        pass
    finally:
        os.close(fd)


def _unmount(cwd):
    subprocess.run(["umount", os.path.join(cwd, "tiny")], capture_output=True)


_nearly_full.teardown = _unmount


def _parent_file(cwd):
    with open(os.path.join(cwd, "plain"), "w") as fh:
        fh.write("a file")


def _sparse(size):
    def setup(cwd):
        with open(os.path.join(cwd, "big.csv"), "wb") as fh:
            fh.truncate(size)
    return setup


def _valid_177mb(cwd):
    """A valid displacement CSV of 177 MB (rows of x, y, ux, uy), as for sheet2d-tension
    but far more rows than its export's 5151 nodes."""
    row = "0.0123456789012345,0.0234567890123456,1.23456789012345e-06,2.34567890123456e-07\n"
    rows = 177_000_000 // len(row)
    with open(os.path.join(cwd, "big.csv"), "w") as fh:
        fh.write("x,y,ux,uy\n")
        block = row * 10_000
        for _ in range(rows // 10_000):
            fh.write(block)


def _exodus(name, steps, coords):
    def setup(cwd):
        import numpy as np
        from scipy.io import netcdf_file
        nc = netcdf_file(os.path.join(cwd, name), "w")
        nc.createDimension("time_step", None)
        nc.createDimension("num_nodes", 2)
        nc.createDimension("num_nod_var", 2)
        nc.createDimension("len_name", 4)
        for c in coords:
            nc.createVariable(c, "d", ("num_nodes",))[:] = [0.0, 1.0]
        t = nc.createVariable("time_whole", "d", ("time_step",))
        nc.createVariable("name_nod_var", "c", ("num_nod_var", "len_name"))[:] = np.array(
            [list("ux  "), list("uy  ")], dtype="S1")
        a = nc.createVariable("vals_nod_var1", "d", ("time_step", "num_nodes"))
        b = nc.createVariable("vals_nod_var2", "d", ("time_step", "num_nodes"))
        if steps:
            t[0], a[0, :], b[0, :] = 1.0, [1e-3, 2e-3], [0.0, 1e-3]
        nc.close()
    return setup


def _text(name, data: bytes):
    def setup(cwd):
        with open(os.path.join(cwd, name), "wb") as fh:
            fh.write(data)
    return setup


def _published(edit):
    """base57's results file, edited by ``edit(doc)``, as r.json."""
    def setup(cwd):
        with open(BASE57) as fh:
            doc = json.load(fh)
        edit(doc)
        with open(os.path.join(cwd, "r.json"), "w") as fh:
            json.dump(doc, fh)
    return setup


def _row2(doc):
    """The run of seed 003 Table 2, row 2 (sheet2d-clamped, none; a known difference)."""
    return next(r for r in doc["runs"] if r["scene"] == "sheet2d-clamped"
                and r["method"] == "none" and any(
                    e["source"] == "seed 003 Table 2, row 2" for e in r.get("published", [])))


def _set999(doc):
    _row2(doc)["metrics"]["tensile_stress_mpa"] = 999.0


def _widen(doc):
    r = _row2(doc)
    r["metrics"]["tensile_stress_mpa"] = 999.0
    for e in r["published"]:
        e.update(tolerance=1e9, known_difference=False)


def _first_entry(field, value):
    def edit(doc):
        r = next(r for r in doc["runs"] if r.get("published"))
        r["published"][0][field] = value
    return edit


def _ours_huge(doc):
    r = _row2(doc)
    r["metrics"]["tensile_stress_mpa"] = 10 ** 400


def _complete_export(folder="ex"):
    """A check: ``folder`` is a whole export (every entry its marker lists is there, and
    nothing else), or absent."""
    def check(cwd):
        root = os.path.join(cwd, folder)
        if not os.path.exists(root):
            return None
        try:
            with open(os.path.join(root, ".pdverify-export")) as fh:
                listed = set(json.load(fh)["entries"]) | {".pdverify-export"}
        except (OSError, ValueError, KeyError) as exc:
            return f"{folder} has no readable marker ({exc})"
        have = set()
        for dirpath, dirnames, filenames in os.walk(root):
            rel = os.path.relpath(dirpath, root)
            pre = "" if rel == "." else rel + "/"
            have |= {pre + d + "/" for d in dirnames} | {pre + f for f in filenames}
        if have != listed:
            return f"{folder} is partial: {sorted(listed ^ have)[:3]}"
        return None
    return check


def _unchanged(*paths):
    """A check: these files (set up by the case) are as the setup left them."""
    def check(cwd, before):
        for p in paths:
            if before.get(p) != _digest(os.path.join(cwd, p)):
                return f"{p} changed or gone"
        return None
    check.wants_before = paths
    return check


EX = ["export", "bar1d-traction", "--format", "csv", "--out"]
SC2 = ["score", "sheet2d-tension"]
CMP = ["compare", "--against-published", "r.json"]
#: (id, argv, setup(cwd) or None, expected exit status or None, check or None); a
#: ``"CONCURRENT"`` argv element runs the argv after it twice at once
FILE_CASES = [
    # markers and results files that name paths outside their folder
    ("marker-lists-dotdot", EX + ["ex"], _export_marker("../" + VICTIM), 2, None),
    ("marker-lists-absolute", EX + ["ex"], _export_marker("{cwd}/" + VICTIM), 2, None),
    ("marker-lists-via-symlink", EX + ["ex"], _export_symlink, 2,
     _unchanged("outside/kept.txt")),
    ("score-marker-absolute", ["score", "bar1d-traction", "ex/back.csv", "--name", "c"],
     _score_marker_outside, 2, None),
    ("report-marker-dotdot", ["report", "--quick", "--only", "bar1d-traction", "--out",
                              "rep"], _report_marker, 2, None),
    ("include-files-outside", ["report", "--quick", "--only", "bar1d-traction", "--include",
                               "ext.json", "--out", "rep"], _include_outside, 2, None),
    ("failed-files-outside", ["report", "--quick", "--only", "bar1d-traction", "--failed",
                              "--out", "rep"], _failed_outside, 2, None),
    # export as safe as report
    # two exports of a node set that takes a while into one folder at once: one waits
    # or is refused, the folder is one whole export
    ("export-concurrent", ["CONCURRENT", "export", "body3d-traction", "--format", "vtu",
                           "--out", "ex"], None, None, _complete_export()),
    ("export-over-previous", ["export", "bar1d-traction", "--format", "vtu", "--out", "ex"],
     lambda cwd: _export(cwd), 0, _complete_export()),
    ("export-nearly-full-disk", ["export", "bar1d-traction", "--format", "vtu", "--out",
                                 "tiny/ex"], _nearly_full, 2, _complete_export("tiny/ex")),
    ("export-name-300", EX + ["a" * 300], None, 2, None),
    ("export-parent-is-file", EX + ["plain/ex"], _parent_file, 2, _unchanged("plain")),
    ("export-current-folder", EX + ["."], None, 2, None),
    ("export-foreign-folder", EX + ["foreign"], lambda cwd: os.makedirs(
        os.path.join(cwd, "foreign", "notes")), 2, None),
    # export solves nothing: a memory limit far below any solve does not refuse it
    ("export-under-small-memory-limit", ["ENV:PDVERIFY_MAX_MEMORY=1M", "export",
                                         "body3d-traction", "--format", "csv", "--out", "ex"],
     None, 0, _complete_export()),
    ("run-under-small-memory-limit", ["ENV:PDVERIFY_MAX_MEMORY=1M", "run", "body3d-traction"],
     None, 2, None),
    ("export-3d-default", ["export", "body3d-traction", "--format", "csv", "--out", "ex"],
     None, 0, _complete_export()),
    # score: size and shape before reading
    ("score-sparse-20GB", SC2 + ["big.csv", "--name", "c"], _sparse(20 << 30), 2, None),
    ("score-valid-177MB", SC2 + ["big.csv", "--name", "c"], _valid_177mb, 2, None),
    ("score-exodus-no-steps", SC2 + ["empty.e", "--name", "c"],
     _exodus("empty.e", 0, ("coordx", "coordy")), 2, None),
    ("score-exodus-one-coordinate", SC2 + ["one.e", "--name", "c"],
     _exodus("one.e", 1, ("coordx",)), 2, None),
    ("score-csv-one-coordinate", SC2 + ["one.csv", "--name", "c"],
     _text("one.csv", b"x,ux,uy\n0,1e-3,0\n"), 2, None),
    ("score-utf8-bom", SC2 + ["bom.csv", "--name", "c"],
     _text("bom.csv", b"\xef\xbb\xbfx,y,ux,uy\n0,0,1e-3,0\n"), 2, None),
    ("score-utf16-bom", SC2 + ["u16.csv", "--name", "c"],
     _text("u16.csv", "x,y,ux,uy\n0,0,1e-3,0\n".encode("utf-16")), 2, None),
    ("score-nul-bytes", SC2 + ["nul.csv", "--name", "c"],
     _text("nul.csv", b"x,y,ux,uy\n" + b"\0" * 1000), 2, None),
    # compare --against-published from the package, not the file
    ("published-base57", ["compare", "--against-published", BASE57], None, 0, None),
    ("published-known-diff-999", CMP, _published(_set999), 1, None),
    ("published-widened-tolerance", CMP, _published(_widen), 1, None),
    ("published-nan-tolerance", CMP, _published(_first_entry("tolerance", float("nan"))),
     2, None),
    ("published-negative-tolerance", CMP, _published(_first_entry("tolerance", -1.0)), 2,
     None),
    ("published-401-digit-target", CMP, _published(_first_entry("target", 10 ** 400)), 2,
     None),
    ("published-401-digit-ours", CMP, _published(_ours_huge), 2, None),
]

GROUPS = {"issue50-files": FILE_CASES}


def _digest(path):
    try:
        with open(path, "rb") as fh:
            return hashlib.sha256(fh.read()).hexdigest()
    except OSError:
        return None


def _run(argv, cwd, env, timeout):
    """(exit status or None on a hang, stdout, stderr, peak resident MB of the process)."""
    out, err = tempfile.TemporaryFile(), tempfile.TemporaryFile()
    proc = subprocess.Popen([sys.executable, "-m", "pdverify", *argv], cwd=cwd, env=env,
                            stdout=out, stderr=err)
    deadline = time.monotonic() + timeout
    code, peak = None, 0.0
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            code, peak = os.waitstatus_to_exitcode(status), usage.ru_maxrss / 1024
            proc.returncode = code
            break
        if time.monotonic() > deadline:
            proc.kill()
            os.wait4(proc.pid, 0)
            proc.returncode = -9
            break
        time.sleep(0.02)
    texts = []
    for fh in (out, err):
        fh.seek(0)
        texts.append(fh.read().decode("utf-8", "replace"))
        fh.close()
    return code, texts[0], texts[1], peak


def classify(argv, timeout, env, setup=None, check=None):
    """(exit status or None, first line, traceback?, silent?, data lost (text or None),
    peak MB)."""
    with tempfile.TemporaryDirectory() as cwd:
        env = {**env, "PDVERIFY_CACHE_DIR": os.path.join(cwd, "cache")}
        with open(os.path.join(cwd, VICTIM), "w") as fh:
            fh.write("the user's own file")
        try:
            if setup is not None:
                setup(cwd)
            return _classify(argv, timeout, env, cwd, check)
        finally:
            getattr(setup, "teardown", lambda cwd: None)(cwd)


def _classify(argv, timeout, env, cwd, check):
    while argv and argv[0].startswith("ENV:"):     # an environment variable of the case
        key, _, value = argv[0][4:].partition("=")
        env, argv = {**env, key: value}, argv[1:]
    before = {p: _digest(os.path.join(cwd, p))
              for p in getattr(check, "wants_before", ())}
    if argv and argv[0] == "CONCURRENT":
        results = [None, None]

        def one(k):
            results[k] = _run(argv[1:], cwd, env, timeout)
        threads = [threading.Thread(target=one, args=(k,)) for k in (0, 1)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        codes = [r[0] for r in results]
        code = None if None in codes else max(codes)
        stdout = "\n".join(r[1] for r in results)
        stderr = "\n".join(r[2] for r in results)
        peak = max(r[3] for r in results)
        first = " | ".join(f"exit {r[0]}: " + ((r[2] if r[2].strip() else r[1]).strip()
                                               .splitlines() or [""])[0][:90]
                           for r in results)
    else:
        code, stdout, stderr, peak = _run(argv, cwd, env, timeout)
        text = (stderr if stderr.strip() else stdout).strip()
        lines = text.splitlines()
        first = lines[0] if lines else ""
        if first.startswith("verdict "):   # compare --against-published: its table's
            # header; show the first failure or the summary instead
            first = next((ln for ln in lines if ln.startswith("fails:")), lines[-1])
    lost = None
    if _digest(os.path.join(cwd, VICTIM)) != hashlib.sha256(
            b"the user's own file").hexdigest():
        lost = f"{VICTIM} changed or gone"
    elif check is not None:
        lost = check(cwd, before) if hasattr(check, "wants_before") else check(cwd)
    if code is None:
        return None, "HANG", False, False, lost, peak
    traceback = "Traceback (most recent call last)" in stderr
    silent = not (stdout.strip() or stderr.strip())
    return code, first, traceback, silent, lost, peak


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--group", choices=sorted(GROUPS), default=None,
                    help="run only this group of cases")
    args = ap.parse_args()
    env = dict(os.environ)
    cases = (GROUPS[args.group] if args.group else
             [(n, a, None, None, None) for n, a in CASES] + FILE_CASES)
    rows = []
    counts = {"traceback": 0, "hang": 0, "silent exit": 0, "data loss": 0,
              "unexpected exit": 0}
    skipped = 0
    for name, argv, setup, expect, check in cases:
        try:
            code, first, tb, silent, lost, peak = classify(argv, args.timeout, env, setup,
                                                           check)
        except Skip as exc:
            skipped += 1
            print(f"{name:30s} skipped: {exc}", flush=True)
            continue
        why = [w for w, bad in (("traceback", tb), ("hang", code is None),
                                ("silent exit", silent), ("data loss", lost is not None),
                                ("unexpected exit", expect is not None and code is not None
                                 and code != expect)) if bad]
        for w in why:
            counts[w] += 1
        rows.append((name, code, first, why))
        print(f"{'DEFECT (' + ', '.join(why) + ') ' if why else ''}{name:30s} exit {code}"
              + (f" (expected {expect})" if expect is not None else "")
              + f"  {peak:7.0f} MB  {first[:200]}" + (f"  [{lost}]" if lost else ""),
              flush=True)
    codes = {}
    for _, code, _, _ in rows:
        codes[code] = codes.get(code, 0) + 1
    defects = sum(bool(r[3]) for r in rows)
    print(f"\n{len(rows)} cases; exit codes: "
          + ", ".join(f"{k}: {v}" for k, v in sorted(codes.items(), key=str))
          + "; " + ", ".join(f"{k}: {v}" for k, v in counts.items())
          + f"; defects: {defects}" + (f"; skipped: {skipped}" if skipped else ""))
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main())
