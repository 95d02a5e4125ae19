"""The report's data files: the seed papers and the deviations from them."""
from __future__ import annotations

from pdverify.deviations import DEVIATIONS, for_scene
from pdverify.papers import PAPERS, seed_of
from pdverify.report import html
from pdverify.scenes import all_scenes


def test_every_scene_has_its_paper_and_every_doi_was_checked():
    for scene in all_scenes():
        assert seed_of(scene.seed) in PAPERS, scene.id
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
