"""A damaged cache entry is a miss: the next run is correct and the entry is repaired
(issue 18). FEM entries (.npz) and the manufactured engine's entries (.json)."""
import json
import zipfile

import numpy as np
import pytest

import reference_fem as rf
from reference_fem.results import content_digest

SMALL = dict(spacing=1.0, levels=2)     # a 3 x 2 plate on 1 m then 0.5 m Q2 meshes


def _entry(tmp_path):
    files = sorted((tmp_path).glob("plate2d-clamped-*.npz"))
    assert len(files) == 1
    return files[0]


def _truncate(p):
    p.write_bytes(p.read_bytes()[: p.stat().st_size // 2])


def _zero(p):
    p.write_bytes(b"")


def _flip(p):
    data = bytearray(p.read_bytes())
    data[len(data) // 2] ^= 0xFF
    p.write_bytes(bytes(data))


def _edit_metric(p):
    # a well-formed archive whose max_displacement was edited: only the checksum tells
    with np.load(p, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["__meta__"]))
    meta["max_displacement"] *= 2
    arrays["__meta__"] = np.array(json.dumps(meta))
    with open(p, "wb") as fh:
        np.savez(fh, **arrays)


def _garbage(p):
    p.write_bytes(b"PK\x03\x04" + b"\x00" * 100)


@pytest.mark.parametrize("damage", [_truncate, _zero, _flip, _edit_metric, _garbage])
def test_damaged_fem_entry_is_recomputed_and_repaired(damage, tmp_path, monkeypatch):
    monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(tmp_path))
    first = rf.clamped_plate(**SMALL)
    assert not first.from_cache
    p = _entry(tmp_path)
    damage(p)
    again = rf.clamped_plate(**SMALL)
    assert not again.from_cache                          # a miss, recomputed
    assert again.max_displacement == pytest.approx(first.max_displacement, rel=1e-12)
    third = rf.clamped_plate(**SMALL)                    # and the entry is whole again
    assert third.from_cache
    assert third.max_displacement == pytest.approx(first.max_displacement, rel=1e-12)
    with zipfile.ZipFile(p) as z:
        assert "__checksum__.npy" in z.namelist()
    assert not list(tmp_path.glob("*.tmp*"))


def test_checksum_covers_every_entry():
    a = {"x": np.arange(3.0), "__meta__": np.array("{}")}
    b = {"x": np.nextafter(np.arange(3.0), 9), "__meta__": np.array("{}")}   # one ulp
    assert content_digest(a) != content_digest(b)
    assert content_digest(a) == content_digest(dict(a))
