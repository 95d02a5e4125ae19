"""The report: run every scene and method, write results.json, figures and index.html.

Its modules, by job: :mod:`.build` (the main job: the runs, then every file of the
report), :mod:`.folder` (where a report goes, the room it needs, publishing it whole),
:mod:`.rerun` (``--failed``: what to run again and what to keep), :mod:`.drawing` (the
figure tasks in forked processes), :mod:`.files` (VTU fields, CSV tables),
:mod:`.summary` (the end-of-run summary and the front page's choices), :mod:`.html`
(index.html from ``templates/``), ``figures/`` (one module per kind of figure).
"""
from .build import build_report, exit_code
from .folder import default_out

__all__ = ["build_report", "default_out", "exit_code"]
