"""The report page's height in CSS pixels at a given width, measured with headless Chromium.

    python benchmarks/page_height.py REPORT_DIR [--width 1400] [--open-all]

A copy of ``index.html`` with a one-line script that writes ``document.documentElement
.scrollHeight`` into the DOM is loaded beside the report's figures (a temporary folder
whose ``figures`` links to the report's), the DOM dumped and the number read back. The
report itself is not touched. ``--open-all`` measures with every ``<details>`` open.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

PROBE = ("<script>window.addEventListener('load', () => {{ {open}"
         "const h = document.documentElement.scrollHeight;"
         "const p = document.createElement('pre'); p.id = 'page-height'; p.textContent = h;"
         "document.body.appendChild(p); }});</script>")


def page_height(report: str, width: int = 1400, open_all: bool = False) -> int:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        raise SystemExit("page_height: no chromium on PATH")
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(report, "index.html"), encoding="utf-8") as fh:
            html = fh.read()
        opener = ("document.querySelectorAll('details').forEach(d => d.open = true);"
                  if open_all else "")
        html = html.replace("</body>", PROBE.format(open=opener) + "</body>")
        page = os.path.join(tmp, "index.html")
        with open(page, "w", encoding="utf-8") as fh:
            fh.write(html)
        os.symlink(os.path.abspath(os.path.join(report, "figures")),
                   os.path.join(tmp, "figures"))
        out = subprocess.run(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
             f"--window-size={width},1000", "--virtual-time-budget=60000", "--dump-dom",
             "file://" + page], capture_output=True, text=True, timeout=300).stdout
    m = re.search(r'<pre id="page-height">(\d+)</pre>', out)
    if m is None:
        raise SystemExit("page_height: the probe did not report (page not loaded?)")
    return int(m.group(1))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("report")
    ap.add_argument("--width", type=int, default=1400)
    ap.add_argument("--open-all", action="store_true")
    a = ap.parse_args(argv)
    print(page_height(a.report, a.width, a.open_all))
    return 0


if __name__ == "__main__":
    sys.exit(main())
