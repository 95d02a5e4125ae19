"""The convergence studies as data (tests/test_vocabulary.py compares them with the
snapshot tests/data/studies_a694eb9.json taken at commit a694eb9, before the studies read
h and delta from Scene.discretisation): each study's scene, kind, labels and, per level
of the full and the quick report, the overrides and the refined length h, bit for bit."""
from __future__ import annotations

import json


def studies() -> list:
    from pdverify import convergence
    out = []
    for st in convergence.STUDIES:
        row = {"scene": st.scene, "kind": st.kind, "h_label": st.h_label,
               "metric": st.metric, "skip": list(st.skip)}
        for quick in (False, True):
            row["quick" if quick else "full"] = {
                "fixed": st.fixed_in(quick),
                "levels": [[level, st.h(level).hex()] for level in st.used_levels(quick)]}
        out.append(row)
    return out


if __name__ == "__main__":
    print(json.dumps(studies(), indent=1, sort_keys=True))
