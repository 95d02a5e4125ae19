"""The HTML report in a real browser: it renders, its images load, its tables fit.

A small report (two scenes, ``--quick``) is written to a temporary folder, copied, and
a <script> is injected at the end of the copy's ``index.html``. On window 'load' (after
every image has loaded or failed) the script measures the page and writes the result as
JSON into a ``<pre id="pdverify-check">``; headless Chromium prints the DOM
(``--dump-dom``) and the test reads that element back. No Python dependency beyond the
standard library; Chromium is the Debian package ``chromium``, installed with apt-get
when missing (root only), else the tests are skipped.
"""
from __future__ import annotations

import html
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

# The report under test: one 1D scene and one 2D scene with several methods, so the page
# has the overview table, per-scene tables and figures; ~7 s with --quick.
SCENES = ["bar1d-traction", "plate2d-plane-strain"]

# Viewport of the check: 1400 px is a common laptop/desktop browser width; the report's
# body is max-width 1250 px, so anything wider than the window is a layout overflow.
WINDOW_W, WINDOW_H = 1400, 900
# 1 px: sub-pixel layout rounding (getBoundingClientRect returns fractional px).
LAYOUT_SLACK_PX = 1
# 10 s of virtual time: far more than a local file:// page with a dozen PNGs needs to
# reach 'load'; virtual time only advances while the page is idle, so it costs nothing.
VIRTUAL_TIME_BUDGET_MS = 10_000
# 120 s wall clock for one headless Chromium run (start-up is ~1-3 s; generous for CI).
CHROMIUM_TIMEOUT_S = 120
# 300 s for `apt-get install -y chromium` (~100 MB of packages on a slow mirror).
APT_TIMEOUT_S = 300
# 300 s for the two-scene --quick report (measured ~7 s; generous for a loaded CI box).
REPORT_TIMEOUT_S = 300

CHECK_ID = "pdverify-check"

CHECK_SCRIPT = r"""
<script>
window.addEventListener("load", function () {
  var out = {};
  try {
    // folded sections (every metric of every run) must fit too: open them all first
    Array.prototype.forEach.call(document.querySelectorAll("details"),
                                 function (d) { d.open = true; });
    var h1 = document.querySelector("h1");
    out.h1 = h1 ? h1.textContent.trim() : null;
    out.innerWidth = window.innerWidth;
    out.clientWidth = document.documentElement.clientWidth;
    out.scrollWidth = document.documentElement.scrollWidth;
    out.images = Array.prototype.map.call(document.images, function (img) {
      return {src: img.getAttribute("src"), complete: img.complete,
              naturalWidth: img.naturalWidth};
    });
    var heads = Array.prototype.slice.call(document.querySelectorAll("h1, h2, h3"));
    out.tables = Array.prototype.map.call(document.querySelectorAll("table"),
                                          function (t, i) {
      var h2 = null, head = null;  // nearest preceding <h2> / any h1-h3 in document order
      heads.forEach(function (h) {
        if (h.compareDocumentPosition(t) & Node.DOCUMENT_POSITION_FOLLOWING) {
          head = h;
          if (h.tagName === "H2") { h2 = h; }
        }
      });
      var r = t.getBoundingClientRect();
      // for the message only: a scrolling/clipping ancestor hides the overflow from the
      // page's own scrollbar, but the table is still that wide
      var box = null;
      for (var a = t.parentElement; a && a !== document.body; a = a.parentElement) {
        if (getComputedStyle(a).overflowX !== "visible") {
          box = a.getBoundingClientRect().width; break;
        }
      }
      var row = t.rows.length ? t.rows[0].cells.length : 0;
      return {index: i, h2_id: h2 ? h2.id : null,
              heading: head ? head.textContent.trim().slice(0, 80) : null,
              left: r.left, right: r.right, width: r.width, columns: row,
              scroll_box_width: box};
    });
  } catch (e) {
    out.error = String(e && e.stack || e);
  }
  var pre = document.createElement("pre");
  pre.id = "%(id)s";
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>
""" % {"id": CHECK_ID}


def _find_chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(scope="module")
def chromium():
    """Path of the Chromium binary; apt-get installs it once if missing (as root)."""
    path = _find_chromium()
    if path:
        return path
    apt = shutil.which("apt-get")
    if not apt or not hasattr(os, "geteuid") or os.geteuid() != 0:
        pytest.skip("chromium not found and cannot be installed "
                    "(needs apt-get and root: apt-get install -y chromium)")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    log = []
    # install first; on failure (e.g. empty package lists) update the lists and retry once
    for cmd in ([apt, "install", "-y", "chromium"],
                [apt, "update"],
                [apt, "install", "-y", "chromium"]):
        try:
            proc = subprocess.run(cmd, env=env, capture_output=True, text=True,
                                  timeout=APT_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pytest.skip(f"chromium not found; {' '.join(cmd)} timed out "
                        f"after {APT_TIMEOUT_S} s")
        log.append(f"$ {' '.join(cmd)} -> {proc.returncode}\n{proc.stderr[-500:]}")
        if cmd[1] == "install" and proc.returncode == 0:
            break
    path = _find_chromium()
    if not path:
        pytest.skip("chromium not found and apt-get could not install it:\n"
                    + "\n".join(log))
    return path


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    """A small --quick report written by the CLI, as a user would."""
    out = tmp_path_factory.mktemp("browser-report") / "report"
    cmd = [sys.executable, "-m", "pdverify", "report", "--quick", "--only", *SCENES,
           "--out", str(out)]
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True,
                          timeout=REPORT_TIMEOUT_S)
    assert proc.returncode == 0, (f"{' '.join(cmd[1:])} exited {proc.returncode}:\n"
                                  f"{proc.stderr[-3000:]}")
    assert (out / "index.html").is_file()
    return out


def run_browser_check(chromium_path, report, workdir):
    """Copy ``report`` into ``workdir``, inject the check script, load the copy in
    headless Chromium and return the script's measurements (a dict)."""
    page_dir = Path(workdir) / "page"
    shutil.copytree(report, page_dir)
    index = page_dir / "index.html"
    text = index.read_text(encoding="utf-8")
    if re.search(r"</body>", text, re.I):
        text = re.sub(r"</body>", lambda m: CHECK_SCRIPT + m.group(0), text, count=1,
                      flags=re.I)
    else:
        text += CHECK_SCRIPT
    index.write_text(text, encoding="utf-8")

    cmd = [chromium_path, "--headless", "--disable-gpu", "--no-sandbox",
           "--disable-dev-shm-usage", "--no-first-run", "--mute-audio",
           f"--user-data-dir={Path(workdir) / 'profile'}",
           f"--window-size={WINDOW_W},{WINDOW_H}",
           f"--virtual-time-budget={VIRTUAL_TIME_BUDGET_MS}",
           "--dump-dom", index.as_uri()]
    # own process group, so a hung browser and its helpers are all ended on timeout
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        dom, err = proc.communicate(timeout=CHROMIUM_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail(f"chromium did not finish within {CHROMIUM_TIMEOUT_S} s")
    m = re.search(r'<pre id="%s">(.*?)</pre>' % CHECK_ID, dom, re.S)
    assert m, (f"chromium (exit {proc.returncode}) printed no #{CHECK_ID} element; "
               f"the page did not reach 'load' or the script did not run.\n"
               f"stderr tail:\n{err[-2000:]}\nstdout head:\n{dom[:500]}")
    data = json.loads(html.unescape(m.group(1)))
    assert "error" not in data, f"the check script raised: {data['error']}"
    return data


@pytest.fixture(scope="module")
def page(chromium, report_dir, tmp_path_factory):
    t0 = time.perf_counter()
    data = run_browser_check(chromium, report_dir, tmp_path_factory.mktemp("browser"))
    data["seconds"] = time.perf_counter() - t0
    # the window size took effect, else the width check below would be meaningless
    assert data["innerWidth"] == WINDOW_W, data["innerWidth"]
    return data


@pytest.mark.slow  # slow tier (issue 32): its report and browser 108 s of the suite's 3811 s (loaded machine)
def test_report_renders(page):
    assert page["h1"] == "pdverify report"


@pytest.mark.slow  # slow tier (issue 32): shares the 108 s report (loaded machine)
def test_every_image_loaded(page):
    assert page["images"], "the report has no <img> at all"
    broken = [im["src"] for im in page["images"]
              if not (im["complete"] and im["naturalWidth"] > 0)]
    assert not broken, (f"{len(broken)} of {len(page['images'])} images did not load: "
                        + ", ".join(broken))


@pytest.mark.slow  # slow tier (issue 32): shares the 108 s report (loaded machine)
def test_no_table_wider_than_the_viewport(page):
    assert page["tables"], "the report has no <table> at all"
    limit = page["innerWidth"] + LAYOUT_SLACK_PX
    wide = [t for t in page["tables"] if t["right"] > limit]
    lines = [f"table #{t['index']} under h2 id={t['h2_id']!r} "
             f"(nearest heading: {t['heading']!r}): width {t['width']:.0f} px, "
             f"right edge {t['right']:.0f} px > window {page['innerWidth']} px "
             f"by {t['right'] - page['innerWidth']:.0f} px; {t['columns']} columns"
             + (f"; inside a {t['scroll_box_width']:.0f} px scroll box"
                if t["scroll_box_width"] is not None else "")
             for t in wide]
    assert not wide, (f"{len(wide)} of {len(page['tables'])} tables overflow a "
                      f"{WINDOW_W} px window (document scrollWidth "
                      f"{page['scrollWidth']} px):\n" + "\n".join(lines))
