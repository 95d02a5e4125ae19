"""Sweep of odd inputs, as a new user would try them (issue 31): every case runs
``python -m pdverify`` in a fresh folder with its own cache and a time limit, and is
classified by exit code and first line; a traceback, a hang or a silent exit (no output at
all) is a defect. Prints the outcome table and the counts; exits 1 on any defect.

    PYTHONPATH=$PWD python benchmarks/odd_inputs.py [--timeout S]
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile

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


def classify(argv, timeout, env):
    with tempfile.TemporaryDirectory() as cwd:
        env = {**env, "PDVERIFY_CACHE_DIR": os.path.join(cwd, "cache")}
        try:
            r = subprocess.run([sys.executable, "-m", "pdverify", *argv], cwd=cwd, env=env,
                               capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return None, "HANG", False, False
    text = (r.stderr if r.stderr.strip() else r.stdout).strip()
    first = text.splitlines()[0] if text else ""
    traceback = "Traceback (most recent call last)" in r.stderr
    silent = not (r.stdout.strip() or r.stderr.strip())
    return r.returncode, first, traceback, silent


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--timeout", type=float, default=120.0)
    args = ap.parse_args()
    env = dict(os.environ)
    defects, rows = 0, []
    for name, argv in CASES:
        code, first, tb, silent = classify(argv, args.timeout, env)
        bad = tb or silent or code is None
        defects += bad
        rows.append((name, code, first, bad))
        print(f"{'DEFECT ' if bad else ''}{name:30s} exit {code}  {first[:200]}", flush=True)
    codes = {}
    for _, code, _, _ in rows:
        codes[code] = codes.get(code, 0) + 1
    print(f"\n{len(rows)} cases; exit codes: "
          + ", ".join(f"{k}: {v}" for k, v in sorted(codes.items(), key=str))
          + f"; tracebacks: {sum('Traceback' in r[2] for r in rows)}; defects (traceback, "
          f"hang or silent exit): {defects}")
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main())
