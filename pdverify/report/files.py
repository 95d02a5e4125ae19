"""The report's data files beside its page: each run's VTU fields and a CSV table per scene."""
from __future__ import annotations

import os
import shutil

from .. import outputs
from ..results import atomic_write_text


def export_fields(results, out) -> None:
    """Every run's fields as VTU files in ``out/fields`` (:mod:`pdverify.export`), named
    by the run's place in ``results.json``; each run lists its files under ``files``."""
    from ..export import write_run_fields
    for k, r in enumerate(results):
        if not r.fields:
            continue
        stem = os.path.join(out, "fields", f"{k:03d}-{r.scene}-{r.method}")
        r.files = [os.path.relpath(p, out) for p in write_run_fields(r, stem)]


def keep_fields(results, final, out) -> None:
    """``report --failed``: the VTU files of the runs kept from the previous report in
    ``final``, copied into ``out`` under their run's new place in results.json."""
    for k, r in enumerate(results):
        if r.fields or not r.files:
            continue
        files = []
        for rel in r.files:
            head, name = os.path.split(rel)
            new = os.path.join(head, f"{k:03d}-" + name.split("-", 1)[-1])
            src = os.path.join(final, rel)
            if outputs.outside(final, rel) or outputs.outside(out, new):
                continue     # never read or write outside the two reports (checked before)
            if os.path.isfile(src):
                os.makedirs(os.path.join(out, head), exist_ok=True)
                shutil.copyfile(src, os.path.join(out, new))
                files.append(new)
        r.files = files


def write_tables(results, out) -> list[str]:
    """One CSV per scene, ``out/tables/<scene>.csv``: a row per run (method, outcome,
    message, every parameter, every metric, the run's time), for a spreadsheet or pandas.
    Returns the files written, relative to ``out``."""
    import csv
    import io
    from ..results import _plain
    by_scene: dict[str, list] = {}
    for r in results:
        by_scene.setdefault(r.scene, []).append(r)
    written = []
    for scene_id, runs in by_scene.items():
        params = list(dict.fromkeys(k for r in runs for k in r.params))
        metrics = list(dict.fromkeys(k for r in runs for k in r.metrics))
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["scene", "method", "outcome", "status", "message"] + params + metrics
                   + ["total_s"])
        for r in runs:
            p, m = _plain(r.params), _plain(r.metrics)
            w.writerow([r.scene, r.method, r.outcome, r.status, r.message]
                       + [p.get(k, "") for k in params] + [m.get(k, "") for k in metrics]
                       + [_plain(r.timings.get("total_s", ""))])
        rel = os.path.join("tables", f"{scene_id}.csv")
        atomic_write_text(os.path.join(out, rel), buf.getvalue())
        written.append(rel)
    return written
