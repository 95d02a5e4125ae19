"""Nothing of the user's is ever lost (issue 31): outputs write only where pdverify owns
the place (a new or empty folder, a previous report, a file it wrote, or --force), never
over an input or the cache; storage is checked before work; a report that cannot be
written whole never replaces a complete one."""
import errno
import hashlib
import json
import os
import re
import shutil
import stat
import subprocess
import sys

import pytest

from pdverify import outputs
from pdverify.cli import main

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = "bar1d-traction"        # the cheapest report: a few analytic runs, 2 figures


def _runs_of_the_report() -> int:
    """How many runs the quick report of SCENE has (every treatment it offers)."""
    from pdverify.scenes import get_scene
    return len(get_scene(SCENE).report_cases(quick=True))
GOOD_RUN = {"scene": SCENE, "method": "none", "params": {}, "reference": "analytic",
            "status": "ok", "message": "", "metrics": {"max_error_pct": 1.0}}


def _tree_hash(root) -> dict:
    """Every entry below ``root`` (and ``root`` itself): its kind, mode and, for a file,
    the SHA-256 of its bytes; a link: its target."""
    out = {}
    root = str(root)
    for dirpath, dirnames, filenames in os.walk(root):
        for n in [""] + dirnames + filenames:
            p = os.path.join(dirpath, n) if n else dirpath
            rel = os.path.relpath(p, root)
            st = os.lstat(p)
            if stat.S_ISLNK(st.st_mode):
                out[rel] = ("link", os.readlink(p))
            elif stat.S_ISREG(st.st_mode):
                with open(p, "rb") as fh:
                    out[rel] = ("file", st.st_mode, hashlib.sha256(fh.read()).hexdigest())
            else:
                out[rel] = ("dir", st.st_mode)
    return out


@pytest.fixture
def env(tmp_path, monkeypatch):
    """A private cache folder, and the test's folder as the current one."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(cache))
    monkeypatch.chdir(tmp_path)
    return {**os.environ, "PDVERIFY_CACHE_DIR": str(cache),
            "PYTHONPATH": REPO + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _foreign_project(folder):
    (folder / "src").mkdir(parents=True)
    (folder / "src" / "a.py").write_text("print('mine')\n")
    (folder / "README").write_text("my project\n")


def _one_error_line(err):
    assert err.count("\n") == 1 and err.startswith("pdverify: error: "), err
    assert "Traceback" not in err
    return err


def _report(out, *extra):
    return main(["report", "--quick", "--only", SCENE, "--out", str(out), *extra])


@pytest.fixture(scope="module")
def made_report(tmp_path_factory):
    """One real report, made once; tests copy it as their previous report."""
    root = tmp_path_factory.mktemp("made")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PDVERIFY_CACHE_DIR", str(root / "cache"))
        mp.chdir(root)
        assert _report(root / "rep") == 0
    return root / "rep"


def _previous(made_report, rep):
    shutil.copytree(made_report, rep, symlinks=True)
    assert outputs.folder_state(str(rep)) == ("report", "")


# ------------------------------------------------------------------------------ --out

def test_foreign_folder_as_out_is_refused_and_left_byte_identical(tmp_path, env):
    """The issue's case, end to end: ``report --out proj`` on a folder holding src/a.py and
    a README: exit 2, one line naming the folder, the folder byte-identical and nothing
    created next to it (no lock file, no staging folder)."""
    proj = tmp_path / "proj"
    _foreign_project(proj)
    before, around = _tree_hash(proj), sorted(os.listdir(tmp_path))
    p = subprocess.run([sys.executable, "-m", "pdverify", "report", "--quick", "--only", SCENE,
                        "--out", "proj"], cwd=tmp_path, env=env, capture_output=True,
                       text=True, timeout=120)
    assert p.returncode == 2, p.stderr
    err = _one_error_line(p.stderr)
    assert "--out 'proj' is a folder pdverify did not create" in err
    assert "'README', 'src'" in err
    assert _tree_hash(proj) == before
    assert sorted(os.listdir(tmp_path)) == around


def test_out_is_the_current_folder_when_it_is_not_a_report(tmp_path, env, capsys):
    _foreign_project(tmp_path / "here")
    os.chdir(tmp_path / "here")
    before = _tree_hash(tmp_path / "here")
    for out in (".", str(tmp_path / "here")):
        assert _report(out) == 2
        err = _one_error_line(capsys.readouterr().err)
        assert "is the current folder, which is not a pdverify report" in err
    assert _tree_hash(tmp_path / "here") == before
    empty = tmp_path / "empty"                 # an empty current folder is no report either
    empty.mkdir()
    os.chdir(empty)
    assert _report(".") == 2
    assert "is the current folder" in capsys.readouterr().err
    assert os.listdir(empty) == []
    os.chdir(tmp_path / "here" / "src")        # an ancestor of the current folder
    assert _report(str(tmp_path / "here")) == 2
    assert "contains the current folder" in capsys.readouterr().err
    assert _tree_hash(tmp_path / "here") == before


@pytest.mark.parametrize("where", ["equal", "inside", "containing"])
def test_out_never_touches_the_cache_folder(tmp_path, env, capsys, where):
    cache = tmp_path / "cache"
    (cache / "reference_fem").mkdir(parents=True)
    (cache / "reference_fem" / "entry.npz").write_bytes(b"\x93NUMPY cached reference")
    out = {"equal": cache, "inside": cache / "reports", "containing": tmp_path}[where]
    before = _tree_hash(tmp_path)
    assert _report(out) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert {"equal": "is the cache folder", "inside": "is inside the cache folder",
            "containing": "contains the cache folder"}[where] in err
    assert str(cache) in err and "$PDVERIFY_CACHE_DIR" in err
    assert _tree_hash(tmp_path) == before


def test_the_default_cache_folder_is_protected_too(tmp_path, monkeypatch, capsys):
    """Without $PDVERIFY_CACHE_DIR the cache is $XDG_CACHE_HOME/pdverify, as both caches
    resolve it."""
    monkeypatch.delenv("PDVERIFY_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.chdir(tmp_path)
    from manufactured.engine import cache_dir as manufactured_cache
    from reference_fem import cache_dir as fem_cache
    root = os.path.join(str(tmp_path / "xdg"), "pdverify")
    assert outputs.cache_root() == root
    assert str(fem_cache()) == os.path.join(root, "reference_fem")
    assert str(manufactured_cache()) == root
    (tmp_path / "xdg" / "pdverify").mkdir(parents=True)
    assert _report(tmp_path / "xdg" / "pdverify") == 2
    assert "is the cache folder" in capsys.readouterr().err
    monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(tmp_path / "c"))
    assert outputs.cache_root() == str(fem_cache()) == str(manufactured_cache())


def test_a_link_as_out_is_resolved_and_leaves_nothing_behind(made_report, tmp_path, env,
                                                             capsys):
    proj = tmp_path / "proj"
    _foreign_project(proj)
    os.symlink(proj, tmp_path / "to-proj")
    before = _tree_hash(tmp_path)
    assert _report(tmp_path / "to-proj") == 2
    err = _one_error_line(capsys.readouterr().err)
    assert f"(a link to '{proj}') is a folder pdverify did not create" in err
    assert _tree_hash(tmp_path) == before
    # a link to a previous report: the report is written at the link's target, the link
    # stays a link, and no '.link.old-*' or staging folder is left
    rep = tmp_path / "rep"
    _previous(made_report, rep)
    os.symlink(rep, tmp_path / "link")
    (rep / "results.json").write_text('{\n "schema": "pdverify.results/1", "runs": []}')
    assert _report(tmp_path / "link") == 0
    assert os.path.islink(tmp_path / "link") and os.readlink(tmp_path / "link") == str(rep)
    assert len(json.loads((rep / "results.json").read_text())["runs"]) == _runs_of_the_report()
    assert outputs.folder_state(str(rep)) == ("report", "")
    assert [e for e in os.listdir(tmp_path) if ".old-" in e or ".staging-" in e] == []


def test_a_previous_report_is_replaced_but_not_with_a_file_the_user_added(
        made_report, tmp_path, env, capsys):
    rep = tmp_path / "rep"
    _previous(made_report, rep)
    capsys.readouterr()
    from pdverify.report.folder import estimate_bytes
    size = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(rep) for f in fs)
    assert size < estimate_bytes(range(4))       # the free-space estimate covers it
    marker = json.loads((rep / outputs.MARKER).read_text())
    assert marker["schema"] == outputs.MARKER_SCHEMA and marker["complete"] is True
    assert {"results.json", "index.html", "figures/", outputs.MARKER} <= set(marker["entries"])
    assert _report(rep) == 0                      # a previous report: replaced
    capsys.readouterr()
    (rep / "figures" / "my-notes.txt").write_text("mine")
    before = _tree_hash(rep)
    assert _report(rep) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert "is a pdverify report, but it holds 'figures/my-notes.txt'" in err
    assert _tree_hash(rep) == before
    assert _report(rep / "figures" / "sub") == 2   # a folder inside a report
    assert "is inside the pdverify report" in capsys.readouterr().err
    (rep / "figures" / "my-notes.txt").unlink()
    (rep / outputs.MARKER).write_text('{"schema": "someone else"}')
    assert _report(rep) == 2
    assert "was not written by pdverify" in capsys.readouterr().err


def test_a_report_from_before_the_marker_is_recognised_by_its_exact_shape(tmp_path, env,
                                                                         capsys):
    rep = tmp_path / "rep"
    assert _report(rep) == 0
    capsys.readouterr()
    (rep / outputs.MARKER).unlink()              # what a report of an earlier version is:
    (rep / "report.log").unlink()                # no marker, no log and no tables (issue 34)
    shutil.rmtree(rep / "tables")
    assert outputs.folder_state(str(rep)) == ("report", "")
    assert _report(rep) == 0
    assert (rep / outputs.MARKER).is_file()      # marked from now on
    capsys.readouterr()
    (rep / outputs.MARKER).unlink()
    (rep / "report.log").unlink()
    shutil.rmtree(rep / "tables")
    (rep / "results.json").write_text('{\n "schema": "other/1"}')
    before = _tree_hash(rep)
    assert _report(rep) == 2
    assert "its results.json is not a pdverify results file" in capsys.readouterr().err
    assert _tree_hash(rep) == before


def test_an_input_inside_the_out_folder_is_never_replaced(tmp_path):
    """``check_out_dir(inputs=...)``: a folder holding an input of the command is refused
    whatever it is (a report included)."""
    (tmp_path / "r").mkdir()
    (tmp_path / "r" / "baseline.json").write_text("{}")
    from pdverify.errors import InputError
    with pytest.raises(InputError, match="holds the input file"):
        outputs.check_out_dir(str(tmp_path / "r"), inputs=[str(tmp_path / "r" / "baseline.json")])


def test_leftovers_that_are_not_pdverify_s_are_kept(tmp_path, env):
    """The next report removes staging folders that killed reports left, but only its own:
    a folder that merely has such a name and holds the user's files stays."""
    rep = tmp_path / "rep"
    mine = tmp_path / ".rep.staging-mine"
    mine.mkdir()
    (mine / "thesis.tex").write_text("mine")
    stale = tmp_path / ".rep.staging-abc123"     # what a SIGKILL during the figures leaves
    stale.mkdir()
    outputs.write_marker(str(stale), complete=False)
    (stale / "figures").mkdir()
    (stale / "figures" / "half.png").write_bytes(b"\x89PNG")
    (stale / ".tmp-abc").write_text("{")
    fake = tmp_path / ".rep.old-fake"              # someone else's marker: not ours
    fake.mkdir()
    (fake / outputs.MARKER).write_text("not json")
    assert _report(rep) == 0
    assert (mine / "thesis.tex").read_text() == "mine"
    assert (fake / outputs.MARKER).read_text() == "not json"
    assert not stale.exists()


def test_a_foreign_lock_file_is_not_overwritten(tmp_path, env, capsys):
    (tmp_path / ".rep.lock").write_text("my file that happens to have this name")
    assert _report(tmp_path / "rep") == 2
    assert "is not pdverify's lock file" in capsys.readouterr().err
    assert (tmp_path / ".rep.lock").read_text() == "my file that happens to have this name"


def test_files_added_while_the_report_runs_are_kept(made_report, tmp_path, env, monkeypatch,
                                                    capsys):
    """A file put into the previous report while the new one runs makes it the user's: the
    new report stays in its staging folder (exit 1)."""
    from pdverify.report import figures
    rep = tmp_path / "rep"
    _previous(made_report, rep)
    real = figures.draw

    def draw_and_meddle(*args):
        (rep / "added.txt").write_text("mine")
        return real(*args)
    monkeypatch.setattr(figures, "draw", draw_and_meddle)
    capsys.readouterr()
    assert _report(rep) == 1
    err = capsys.readouterr().err.splitlines()[-1]
    assert "changed while the report ran" in err and "'added.txt'" in err
    assert (rep / "added.txt").read_text() == "mine"
    staging = [e for e in os.listdir(tmp_path) if e.startswith(".rep.staging-")]
    assert len(staging) == 1 and staging[0] in err


# ------------------------------------------------------------------------------ files

def _doc(runs):
    return json.dumps({"schema": "pdverify.results/1", "runs": runs})


def test_summary_onto_an_input_is_refused_force_or_not(tmp_path, env, capsys):
    (tmp_path / "a.json").write_text(_doc([GOOD_RUN]))
    (tmp_path / "b.json").write_text(_doc([GOOD_RUN]))
    os.link(tmp_path / "a.json", tmp_path / "hard.json")
    os.symlink(tmp_path / "b.json", tmp_path / "soft.json")
    before = _tree_hash(tmp_path)
    for summary, what in (("a.json", "baseline"), ("b.json", "new results file"),
                          ("hard.json", "baseline"), ("soft.json", "new results file")):
        for force in ([], ["--force"]):
            assert main(["compare", "a.json", "b.json", "--summary", summary, *force]) == 2
            err = _one_error_line(capsys.readouterr().err)
            assert f"is the {what} of this command" in err
    assert _tree_hash(tmp_path) == before


def test_an_existing_file_is_replaced_only_if_pdverify_wrote_it_or_with_force(tmp_path, env,
                                                                             capsys):
    (tmp_path / "a.json").write_text(_doc([GOOD_RUN]))
    for name in ("s.json", "s.md"):
        (tmp_path / name).write_text("my notes\n")
        assert main(["compare", "a.json", "a.json", "--summary", name]) == 2
        assert "was not written by pdverify" in capsys.readouterr().err
        assert (tmp_path / name).read_text() == "my notes\n"
        assert main(["compare", "a.json", "a.json", "--summary", name, "--force"]) == 0
        assert (tmp_path / name).read_text() != "my notes\n"
        assert main(["compare", "a.json", "a.json", "--summary", name]) == 0  # its own now
    assert json.loads((tmp_path / "s.json").read_text())["schema"] == "pdverify.compare/1"
    # a summary of an earlier version (no schema) is recognised by its exact start
    old = {"baseline": "a.json", "new": "a.json", "regressions": 0, "changes": []}
    (tmp_path / "s.json").write_text(json.dumps(old, indent=1) + "\n")
    assert main(["compare", "a.json", "a.json", "--summary", "s.json"]) == 0
    capsys.readouterr()
    # run --json and --vtu
    (tmp_path / "r.json").write_text("mine")
    (tmp_path / "f.vtu").write_text("<?xml version='1.0'?><VTKFile/>")
    for argv in (["--json", "r.json"], ["--vtu", "f.vtu"]):
        assert main(["run", SCENE, *argv]) == 2
        assert "was not written by pdverify" in capsys.readouterr().err
    assert (tmp_path / "r.json").read_text() == "mine"
    assert main(["run", SCENE, "--json", "r.json", "--vtu", "f.vtu", "--force"]) == 0
    assert outputs.is_pdverify_file(str(tmp_path / "r.json"))
    assert outputs.is_pdverify_file(str(tmp_path / "f.vtu"))
    import meshio                                     # the marked VTU still reads
    assert len(meshio.read(tmp_path / "f.vtu").points) > 0
    assert main(["run", SCENE, "--json", "r.json", "--vtu", "f.vtu"]) == 0   # pdverify's
    capsys.readouterr()
    assert main(["run", SCENE, "--json", "x.vtu", "--vtu", "x.vtu"]) == 2
    assert "is also the --json file" in capsys.readouterr().err


@pytest.mark.parametrize("special", ["fifo", "device"])
def test_a_fifo_or_device_is_never_an_output(tmp_path, env, capsys, special):
    if special == "fifo":
        os.mkfifo(tmp_path / "pipe")
        path, kind = str(tmp_path / "pipe"), "is a FIFO, not a file"
    else:
        path, kind = os.devnull, "is a character device, not a file"
    (tmp_path / "a.json").write_text(_doc([GOOD_RUN]))
    for argv in (["run", SCENE, "--json", path], ["compare", "a.json", "a.json", "--summary",
                                                  path, "--force"]):
        assert main(argv) == 2
        assert kind in _one_error_line(capsys.readouterr().err)
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)


# ------------------------------------------------------------------------------ storage

def test_a_cache_that_cannot_take_files_is_refused_before_work(tmp_path, monkeypatch,
                                                              capsys):
    """The choice documented in docs/command-line.md: a cache folder that is a file, cannot be
    written or is full is exit 2 naming it (a FEM reference would be computed and lost)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "cachefile").write_text("x")
    for cache, needle in ((tmp_path / "cachefile", "is a file, not a folder"),
                          (tmp_path / "cachefile" / "sub", "is a file, not a folder"),
                          ("/proc/pdverify-cache", "cannot write there")):
        monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(cache))
        for argv in (["run", SCENE], ["report", "--quick", "--only", SCENE, "--out", "r"]):
            assert main(argv) == 2
            err = _one_error_line(capsys.readouterr().err)
            assert f"cache folder '{cache}' ($PDVERIFY_CACHE_DIR)" in err and needle in err
            assert "set $PDVERIFY_CACHE_DIR to a writable folder" in err
    assert sorted(os.listdir(tmp_path)) == ["cachefile"]


def test_a_missing_cache_folder_is_checked_without_creating_anything(tmp_path, monkeypatch):
    monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(tmp_path / "a" / "b"))
    outputs.check_cache()
    assert os.listdir(tmp_path) == []


@pytest.fixture
def small_disk(tmp_path):
    """A 16 MB tmpfs (root only; skipped where it cannot be mounted)."""
    mnt = tmp_path / "disk"
    mnt.mkdir()
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=16m", "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if p.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {p.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], check=False)


def _fill(disk, leave: int) -> None:
    """Take all but ``leave`` bytes of ``disk``'s free space."""
    free = outputs.free_bytes(str(disk))
    with open(disk / "filler", "ab") as fh:
        if free > leave:
            os.posix_fallocate(fh.fileno(), os.fstat(fh.fileno()).st_size, free - leave)
    assert outputs.free_bytes(str(disk)) <= leave


def test_a_full_disk_is_refused_before_work(made_report, small_disk, tmp_path, env, capsys):
    rep = small_disk / "rep"
    _previous(made_report, rep)
    capsys.readouterr()
    before = _tree_hash(rep)
    _fill(small_disk, 100_000)
    listing = sorted(os.listdir(small_disk))
    assert _report(rep) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert (f"--out '{rep}' (a report of {_runs_of_the_report()} runs): only" in err
            and "needed" in err)
    assert _tree_hash(rep) == before and sorted(os.listdir(small_disk)) == listing
    for argv in (["run", SCENE, "--json", str(small_disk / "r.json")],
                 ["compare", str(rep / "results.json"), str(rep / "results.json"),
                  "--summary", str(small_disk / "s.md")]):
        assert main(argv) == 2
        err = _one_error_line(capsys.readouterr().err)
        assert "free on its disk" in err
    os.environ["PDVERIFY_CACHE_DIR"] = str(small_disk / "cache")
    try:
        assert main(["run", SCENE]) == 2
        assert "cache folder" in _one_error_line(capsys.readouterr().err)
    finally:
        os.environ["PDVERIFY_CACHE_DIR"] = env["PDVERIFY_CACHE_DIR"]
    assert _tree_hash(rep) == before and sorted(os.listdir(small_disk)) == listing


def test_a_disk_that_fills_during_the_figures_keeps_the_previous_report(
        made_report, small_disk, tmp_path, env, monkeypatch, capsys):
    """The disk has room at the check before work, then fills up (another process) while
    the figures are drawn: matplotlib's write fails with ENOSPC, the report is incomplete,
    the previous report stays byte-identical, the partial one stays in its staging folder,
    exit 1 with one line naming both."""
    from pdverify.report import figures
    rep = small_disk / "rep"
    _previous(made_report, rep)
    before = _tree_hash(rep)
    real = figures.draw

    def draw_on_a_full_disk(*args):
        _fill(small_disk, 0)
        return real(*args)
    monkeypatch.setattr(figures, "draw", draw_on_a_full_disk)
    capsys.readouterr()
    assert _report(rep) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    last = err.splitlines()[-1]
    # the first task whose write failed: the overview is drawn first, by the other
    # drawing process, before or after the disk fills
    assert re.match(r"pdverify: error: report incomplete: writing the (figure for "
                    + re.escape(SCENE) + r"|error-against-cost figures) failed \(No space "
                    r"left on device", last), last
    assert f"the previous report in '{rep}' is unchanged" in last
    assert _tree_hash(rep) == before
    staging = [e for e in os.listdir(small_disk) if e.startswith(".rep.staging-")]
    assert len(staging) == 1 and f"the partial report is in '{small_disk / staging[0]}'" in last
    assert json.loads((small_disk / staging[0] / outputs.MARKER).read_text())["complete"] is False


def test_a_results_file_that_cannot_be_written_after_the_run_is_one_line(small_disk,
                                                                        tmp_path, env,
                                                                        monkeypatch, capsys):
    """``run --json`` on a disk that fills during the run: exit 1, one line naming the
    file, the previous file unchanged (written atomically)."""
    from pdverify import results
    target = small_disk / "r.json"
    assert main(["run", SCENE, "--json", str(target)]) == 0
    before = target.read_bytes()
    real = results.document

    def document_on_a_full_disk(*a, **k):
        _fill(small_disk, 0)
        return real(*a, **k)
    monkeypatch.setattr(results, "document", document_on_a_full_disk)
    capsys.readouterr()
    assert main(["run", SCENE, "--json", str(target)]) == 1
    err = _one_error_line(capsys.readouterr().err)
    assert f"cannot write '{target}' (No space left on device)" in err
    assert target.read_bytes() == before
    assert sorted(os.listdir(small_disk)) == ["filler", "r.json"]


def test_a_broken_figure_that_is_no_storage_failure_stays_a_note(tmp_path, env, monkeypatch,
                                                                capsys):
    """The rule: an exception of the plotting code is a note (the figure is missing, the
    numbers are kept); only a storage failure (ENOSPC, EDQUOT, EFBIG, EROFS, EIO in the
    exception or what it was raised from) makes the report incomplete."""
    from pdverify.report import figures
    from pdverify.report.folder import storage_failure

    def broken(*args):
        raise ValueError("no ink")
    monkeypatch.setattr(figures, "draw", broken)
    assert _report(tmp_path / "rep") == 0
    assert f"figure for {SCENE} failed: ValueError: no ink" in capsys.readouterr().err
    wrapped = RuntimeError("savefig failed")
    wrapped.__cause__ = OSError(errno.EDQUOT, "Disk quota exceeded")
    assert storage_failure(wrapped).errno == errno.EDQUOT
    assert storage_failure(OSError(errno.ENOENT, "no font")) is None
