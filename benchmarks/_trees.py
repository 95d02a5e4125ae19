"""Shared by the benchmark scripts: another git revision's package, to time beside this
tree's."""
from __future__ import annotations

import subprocess
import tarfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def extract(rev: str, into: Path) -> Path:
    """The ``pdverify`` package (and what it reads at run time) of git revision ``rev``,
    extracted into the folder ``into``; returns ``into``."""
    data = subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", rev, "pdverify",
                           "reference_fem", "manufactured"],
                          check=True, capture_output=True).stdout
    tar = into / "src.tar"
    tar.write_bytes(data)
    with tarfile.open(tar) as t:
        t.extractall(into, filter="data")
    return into
