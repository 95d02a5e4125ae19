"""Screenshots of the report page with headless Chromium, at a given width.

    python benchmarks/page_shots.py REPORT_DIR OUT_DIR [ANCHOR ...] [--width 1400] [--height 1800]

One PNG per anchor (``top`` for the front page): a copy of ``index.html`` that shows only
the anchor's section is opened beside the report's figures (a temporary folder whose
``figures`` links to the report's); the report itself is not touched.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

#: shows the anchor's section alone under the page's bar (the body's children from the
#: anchor's heading to the next heading of its level; a scrolled headless screenshot
#: comes out blank)
SCROLL = ("<script>(() => {{ const t = document.getElementById({anchor!r});"
          "if (!t || t.id === 'top') return; let on = false;"
          "for (const e of Array.from(document.body.children)) {{"
          "if (e === t) on = true; else if (on && e.tagName === t.tagName) on = false;"
          "if (!on && e.tagName !== 'NAV' && e.tagName !== 'SCRIPT') e.style.display = 'none';"
          "}} }})();</script>")


def shoot(report: str, out: str, anchor: str, width: int, height: int) -> str:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        raise SystemExit("page_shots: no chromium on PATH")
    png = os.path.abspath(os.path.join(out, f"{anchor}.png"))
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(report, "index.html"), encoding="utf-8") as fh:
            html = fh.read().replace("</body>", SCROLL.format(anchor=anchor) + "</body>")
        page = os.path.join(tmp, "index.html")
        with open(page, "w", encoding="utf-8") as fh:
            fh.write(html)
        os.symlink(os.path.abspath(os.path.join(report, "figures")),
                   os.path.join(tmp, "figures"))
        subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu",
                        "--hide-scrollbars", f"--window-size={width},{height}",
                        "--virtual-time-budget=60000", f"--screenshot={png}",
                        "file://" + page], capture_output=True, timeout=300, check=True)
    return png


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("report")
    ap.add_argument("out")
    ap.add_argument("anchors", nargs="*", default=["top"])
    ap.add_argument("--width", type=int, default=1400)
    ap.add_argument("--height", type=int, default=1800)
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    for anchor in a.anchors:
        print(shoot(a.report, a.out, anchor, a.width, a.height))
    return 0


if __name__ == "__main__":
    sys.exit(main())
