"""The report's data files: the seed papers and the deviations from them."""
from __future__ import annotations

from pathlib import Path

import pytest

from pdverify.deviations import DEVIATIONS, for_scene
from pdverify.papers import PAPERS, seed_of
from pdverify.report import html
from pdverify.scenes import all_scenes


def test_every_scene_has_its_paper_and_every_doi_was_checked():
    for scene in all_scenes():
        # a scene of pdverify's own (issue 35's shapes) says so instead of naming a paper
        assert seed_of(scene.seed) in PAPERS or scene.seed.startswith("ours"), scene.id
    for key, p in PAPERS.items():
        assert p["authors"] and p["title"], key
        # a DOI only with the page it was checked against (never recalled)
        assert (p["doi"] is None) == (p["doi_checked"] is None), key
        if p["doi"]:
            assert p["doi"] in p["doi_checked"], key


def test_every_deviation_names_existing_scenes_and_every_scene_has_one():
    ids = [s.id for s in all_scenes()]
    for d in DEVIATIONS:
        assert d.kind in ("erratum", "choice", "finding"), d
        for pattern in d.scenes:   # a typo would silently hide the entry
            if pattern.endswith("*"):
                assert any(i.startswith(pattern[:-1]) for i in ids), pattern
            else:
                assert pattern in ids, pattern
    assert all(for_scene(i) for i in ids), [i for i in ids if not for_scene(i)]


def test_the_scene_section_shows_its_deviations_and_paper():
    scene = next(s for s in all_scenes() if s.id == "sheet2d-clamped")
    text = html.scene_section(scene, [], [])
    assert "Deviations from the paper" in text and "swaps the edges" in text
    assert "Ritter" in text
    page_papers = html.papers(all_scenes())
    assert "doi:10.1007/s42102-022-00094-1" in page_papers


def _cited_in_tests(key: str) -> bool:
    here = Path(__file__).resolve()
    return any(key in p.read_text() for p in Path(__file__).parents[1].rglob("*.py")
               if p.resolve() != here)


def test_every_finding_has_one_tested_source():
    """Issue 30, one source per finding: every measured finding of ``deviations.py`` has
    a unique key, and that key is cited where it is checked: by a published number of a
    scene (``Published.deviation``: the report and ``compare --against-published`` check
    it) or by the test that measures it (a test file naming the key)."""
    from pdverify.deviations import DEVIATIONS
    from pdverify.scenes import all_scenes
    keys = [d.key for d in DEVIATIONS if d.key]
    assert len(keys) == len(set(keys)), "duplicate deviation keys"
    published = {p.deviation for s in all_scenes() for p in s.published if p.deviation}
    assert published <= set(keys), published - set(keys)   # no citation of a missing key
    untested = [d.text[:60] for d in DEVIATIONS if d.kind == "finding"
                and not (d.key and (d.key in published or _cited_in_tests(d.key)))]
    assert not untested, untested


def test_the_finding_check_can_fail(monkeypatch):
    """A finding without a key, or with a key nothing cites, is found."""
    import pdverify.deviations as dv
    fake = dv.Deviation(("bar1d-traction",), "finding", "made up", "nowhere",
                        key="000-nothing-cites-this-" + "key")
    monkeypatch.setattr(dv, "DEVIATIONS", dv.DEVIATIONS + (fake,))
    with pytest.raises(AssertionError):
        test_every_finding_has_one_tested_source()
