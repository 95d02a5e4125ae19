"""What pdverify may write over, checked before any work (issue 31).

Outputs own only what pdverify created:

- a report folder (``report --out``) is written only if it does not exist, is empty, or is
  a previous pdverify report: a folder holding the marker file :data:`MARKER` and nothing
  but the files that marker lists (or a report written before the marker existed,
  recognised by its exact shape, :func:`_legacy_report`). Never the cache folder, a
  folder inside it or holding it, the current folder unless it is a report, a folder
  holding an input of the command, or a folder inside another report;
- a file (``run --json``, ``run --vtu``, ``compare --summary``) is never an input of the
  same command (``os.path.samefile``), never a FIFO or a device, and, if it exists, is a
  file pdverify wrote (:func:`is_pdverify_file`) unless ``--force`` is given.

Links are resolved first and the same rules apply to their target, which is where the
output is written (the link itself stays). Storage is checked too: the cache folder takes
a probe file, and the output's file system has room for an estimate of the output.
"""
from __future__ import annotations

import fcntl
import glob
import json
import os
import re
import shutil
import stat
import tempfile
from contextlib import contextmanager

from .errors import InputError

#: The marker file of a report folder (JSON, :data:`MARKER_SCHEMA`): written by pdverify
#: into every report folder, listing every file and folder the report holds.
MARKER = ".pdverify-report"
MARKER_SCHEMA = "pdverify.report-folder/1"
#: The first line of every VTU file pdverify writes (after the XML declaration).
VTU_MARK = "<!-- written by pdverify"
CACHE_ENV = "PDVERIFY_CACHE_DIR"

#: A report folder written before the marker existed holds these names only; its
#: figures/ and fields/ hold only files with these endings.
_LEGACY_TOP = {"results.json", "index.html", "figures", "fields"}
_LEGACY_EXT = {"figures": (".png", ".svg", ".gif", ".html"), "fields": (".vtu",)}
#: What a report writes at its top level beyond the legacy shape (issue 34): the CSV of
#: each scene's runs and the log of the progress lines. A staging folder of a killed
#: report may hold them (:func:`is_own_leftover`).
REPORT_EXTRA = {"tables", "report.log"}
_RESULTS_HEAD = '{\n "schema": "pdverify.results/1"'
_COMPARE_HEAD = '{\n "schema": "pdverify.compare/1"'
#: a compare --summary JSON written before it carried a schema
_OLD_SUMMARY = re.compile(r'\{\n "baseline": ".*",\n "new": ".*",\n "regressions": \d+,\n '
                          r'"changes": \[')
_MARKDOWN_HEAD = "# pdverify compare: "

#: Free space a command that writes results files needs at least (a run's results.json
#: is a few kB, a compare summary less; the cache's largest entry measured, a FEM
#: reference of sheet2d-clamped, is 0.28 MB).
MIN_FREE_FILE = 1 << 20
MIN_FREE_CACHE = 16 << 20


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if abs(n) < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} TB"  # pragma: no cover


# ------------------------------------------------------------------------------ paths

def cache_root() -> str:
    """The cache folder as ``reference_fem`` and ``manufactured`` resolve it:
    ``$PDVERIFY_CACHE_DIR``, else ``$XDG_CACHE_HOME/pdverify``, else
    ``~/.cache/pdverify`` (the FEM references in its ``reference_fem``, the derived
    expressions in its ``manufactured`` folder)."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return os.path.abspath(os.path.expanduser(env))
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.abspath(os.path.join(base, "pdverify"))


def _within(path: str, folder: str) -> bool:
    """``path`` is ``folder`` or lies inside it (both resolved, absolute)."""
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def _resolved(path) -> tuple[str, str]:
    """(the path made absolute, the same with every link resolved)."""
    given = os.path.abspath(os.path.expanduser(str(path)))
    return given, os.path.realpath(given)


def _shown(path, given: str, full: str) -> str:
    """``'path'``, plus the target when ``path`` is a link."""
    return f"{str(path)!r}" + (f" (a link to {full!r})" if os.path.islink(given) else "")


def file_kind(mode: int) -> str:
    for test, name in ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISDIR, "a folder")):
        if test(mode):
            return name
    return "not a regular file"


# ------------------------------------------------------------------------------ listed paths

def outside(folder: str, entry) -> bool:
    """True when the path ``entry``, which a file of ``folder`` lists (a marker's entry,
    a results file's ``files``), does not lie inside ``folder`` once joined to it and
    every link resolved: an absolute path, ``..`` above it, a link pointing out, an
    empty name or a NUL byte. A file pdverify reads names paths; it never directs where
    pdverify writes or deletes outside the folder it belongs to."""
    if not isinstance(entry, str) or not entry.strip("/") or "\0" in entry:
        return True
    if os.path.isabs(entry) or entry.startswith("~"):
        return True
    base = os.path.realpath(folder)
    try:
        full = os.path.realpath(os.path.join(base, entry))
    except (OSError, ValueError):
        return True
    return full == base or not _within(full, base)


def check_listed(folder: str, entries, what: str) -> None:
    """InputError naming the first entry of ``entries`` (listed by ``what``, a file of
    ``folder``) that lies outside ``folder`` (:func:`outside`)."""
    for entry in entries:
        if outside(folder, entry):
            raise InputError(f"{what} lists {entry!r}, which is not a path inside "
                             f"{folder!r}; the file is refused (pdverify writes and deletes "
                             "only inside the folder a file belongs to)")


# ------------------------------------------------------------------------------ report folders

def _head(path: str, n: int = 4096) -> str:
    try:
        with open(path, "rb") as fh:
            return fh.read(n).decode("utf-8", "replace")
    except OSError:
        return ""


def read_marker(folder: str) -> dict | None:
    """The marker of ``folder`` if it is pdverify's (a JSON object of our schema whose
    ``entries`` is a list of strings), else None."""
    try:
        with open(os.path.join(folder, MARKER), "rb") as fh:
            doc = json.loads(fh.read(1 << 22))
    except (OSError, ValueError, RecursionError):
        return None
    if (not isinstance(doc, dict) or doc.get("schema") != MARKER_SCHEMA
            or not isinstance(doc.get("entries"), list)
            or not all(isinstance(e, str) for e in doc["entries"])):
        return None
    return doc


def _tree(folder: str) -> list[str]:
    """Every file and folder below ``folder``, relative, folders ending in '/'; links are
    listed, not followed."""
    out = []
    for dirpath, dirnames, filenames in os.walk(folder):
        rel = os.path.relpath(dirpath, folder)
        prefix = "" if rel == "." else rel.replace(os.sep, "/") + "/"
        for d in list(dirnames):
            if os.path.islink(os.path.join(dirpath, d)):   # a link is an entry, not a folder
                dirnames.remove(d)
                out.append(prefix + d)
            else:
                out.append(prefix + d + "/")
        out.extend(prefix + f for f in filenames)
    return sorted(out)


def write_marker(folder: str, *, complete: bool) -> None:
    """Mark ``folder`` as a pdverify report: the marker lists every entry below it (the
    marker included), so a file added later by someone else is recognised as theirs.
    ``complete=False`` while the report is still being written (its staging folder)."""
    from . import __version__
    from .results import atomic_write_text
    entries = sorted(set(_tree(folder)) | {MARKER})
    doc = {"schema": MARKER_SCHEMA, "pdverify_version": __version__, "complete": complete,
           "entries": entries}
    atomic_write_text(os.path.join(folder, MARKER), json.dumps(doc, indent=1) + "\n")


def _legacy_report(folder: str, entries: list[str]) -> str | None:
    """None if ``folder`` has the exact shape of a report written before the marker
    existed (results.json of schema pdverify.results/1, index.html titled 'pdverify
    report', figures/ and fields/ holding only figures and VTU files), else why not."""
    extra = sorted(set(entries) - _LEGACY_TOP)
    if extra:
        return f"it holds {extra[0]!r}"
    for name in ("results.json", "index.html"):
        if not os.path.isfile(os.path.join(folder, name)) or os.path.islink(
                os.path.join(folder, name)):
            return f"it has no {name} of a pdverify report"
    if not _head(os.path.join(folder, "results.json")).startswith(_RESULTS_HEAD):
        return "its results.json is not a pdverify results file"
    if "<title>pdverify report</title>" not in _head(os.path.join(folder, "index.html"), 512):
        return "its index.html is not a pdverify report page"
    for sub, endings in _LEGACY_EXT.items():
        path = os.path.join(folder, sub)
        if sub not in entries:
            continue
        if os.path.islink(path) or not os.path.isdir(path):
            return f"its {sub} is not a folder"
        for name in sorted(os.listdir(path)):
            p = os.path.join(path, name)
            if not name.endswith(endings) or os.path.islink(p) or not os.path.isfile(p):
                return f"it holds {sub}/{name}"
    return None


def folder_state(folder: str) -> tuple[str, str]:
    """('missing' | 'empty' | 'report' | 'foreign', why it is foreign)."""
    try:
        entries = os.listdir(folder)
    except FileNotFoundError:
        return "missing", ""
    except NotADirectoryError:
        return "foreign", "it is not a folder"
    except OSError as exc:
        return "foreign", f"it cannot be listed ({exc.strerror})"
    if not entries:
        return "empty", ""
    if MARKER in entries:
        marker = read_marker(folder)
        if marker is None:
            return "foreign", f"its {MARKER} was not written by pdverify"
        bad = next((e for e in marker["entries"] if outside(folder, e)), None)
        if bad is not None:
            return "foreign", f"its {MARKER} lists {bad!r}, which is not a path inside it"
        known = set(marker["entries"]) | {MARKER}
        stray = [e for e in _tree(folder) if e not in known]
        if stray:
            more = f" and {len(stray) - 1} more" if len(stray) > 1 else ""
            return "foreign", f"a pdverify report, but it holds {stray[0]!r}{more}, which " \
                              "pdverify did not write"
        return "report", ""
    why = _legacy_report(folder, entries)
    if why is None:
        return "report", ""
    names = sorted(entries)
    listed = ", ".join(repr(n) for n in names[:2]) + (f" and {len(names) - 2} more"
                                                     if len(names) > 2 else "")
    return "foreign", f"it holds {listed} and no {MARKER} marker" if why.startswith(
        "it holds") else f"{why}, and it has no {MARKER} marker"


def is_own_leftover(path: str) -> bool:
    """A staging or set-aside folder of an earlier, killed report: pdverify's to remove.

    That is a complete report (its marker lists everything in it), an empty folder, or a
    folder whose top level holds only what a report writes while it runs (results.json,
    index.html, figures/, fields/, atomic writes' .tmp-* files and the marker, which a
    staging folder gets first and which lists its files only at the end, and the
    :data:`REPORT_EXTRA` tables/ and report.log)."""
    if os.path.islink(path) or not os.path.isdir(path):
        return False
    state, _ = folder_state(path)
    if state in ("report", "empty"):
        return True
    try:
        entries = os.listdir(path)
    except OSError:
        return False
    if MARKER in entries and read_marker(path) is None:
        return False
    return all(e in _LEGACY_TOP or e in REPORT_EXTRA or e == MARKER or e.startswith(".tmp-")
               for e in entries)


def check_out_dir(path, flag: str = "--out", inputs=()) -> str:
    """The folder a report may replace, resolved (links followed); InputError otherwise.

    ``inputs``: files the command reads, which the report must not replace."""
    given, full = _resolved(path)
    shown = _shown(path, given, full)
    if os.path.exists(full) and not os.path.isdir(full):
        raise InputError(f"{flag} {shown} is a file; give a folder")
    cache = os.path.realpath(cache_root())
    where = f"${CACHE_ENV}" if os.environ.get(CACHE_ENV) else "the default"
    if _within(full, cache):
        rel = "is" if full == cache else "is inside"
        raise InputError(f"{flag} {shown} {rel} the cache folder {cache!r} ({where}); "
                         "choose another folder")
    if _within(cache, full):
        raise InputError(f"{flag} {shown} contains the cache folder {cache!r} ({where}); "
                         "choose another folder")
    try:
        cwd = os.path.realpath(os.getcwd())
    except OSError:
        cwd = None
    if cwd is not None and cwd != full and _within(cwd, full):
        raise InputError(f"{flag} {shown} contains the current folder; choose another folder")
    for inp in inputs:
        if inp is not None and _within(os.path.realpath(inp), full):
            raise InputError(f"{flag} {shown} holds the input file {str(inp)!r}, which the "
                             "report would replace; choose another folder")
    parent = os.path.dirname(full)
    while True:
        if os.path.isfile(os.path.join(parent, MARKER)):
            raise InputError(f"{flag} {shown} is inside the pdverify report {parent!r}, "
                             "which a report into it would replace; choose another folder")
        up = os.path.dirname(parent)
        if up == parent:
            break
        parent = up
    state, why = folder_state(full)
    if full == cwd and state != "report":
        raise InputError(f"{flag} {shown} is the current folder, which is not a pdverify "
                         "report; give a new or empty folder")
    if state == "foreign" and why.startswith("a pdverify report"):
        raise InputError(f"{flag} {shown} is {why}; move that away or choose another folder")
    if state == "foreign":
        raise InputError(f"{flag} {shown} is a folder pdverify did not create ({why}); give "
                         "a new or empty folder, or a previous pdverify report")
    return full


# ------------------------------------------------------------------------------ files

def is_pdverify_file(path: str) -> bool:
    """A results file, a compare summary (JSON or Markdown) or a VTU file that pdverify
    wrote, recognised by its first bytes."""
    head = _head(path)
    return (head.startswith((_RESULTS_HEAD, _COMPARE_HEAD, _MARKDOWN_HEAD))
            or _OLD_SUMMARY.match(head) is not None
            or (head.startswith("<?xml") and VTU_MARK in head[:512]))


def check_out_file(path, flag: str, *, force: bool = False, inputs=()) -> str:
    """A file an output may replace, resolved (links followed); InputError otherwise.

    ``inputs``: (path, what) pairs the command reads; the output is never one of them,
    ``--force`` or not."""
    given, full = _resolved(path)
    shown = _shown(path, given, full)
    try:
        st = os.stat(full)
    except FileNotFoundError:
        return full
    except OSError as exc:
        raise InputError(f"{flag} {shown}: cannot be checked ({exc.strerror})") from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(f"{flag} {shown} is {file_kind(st.st_mode)}, not a file; give a file "
                         "name")
    for inp, what in inputs:
        try:
            same = inp is not None and os.path.samefile(full, inp)
        except OSError:
            same = False
        if same:
            raise InputError(f"{flag} {shown} is the {what} of this command; writing it would "
                             "overwrite it: give another file name")
    if not force and not is_pdverify_file(full):
        raise InputError(f"{flag} {shown} exists and was not written by pdverify; give "
                         "another file name, or --force to replace it")
    return full


def vtu_files(path: str) -> list[str]:
    """The existing files ``run --vtu PATH`` may write: PATH, and PATH's stem with the
    suffix of a further node set (``_a``) or of the FEM grid (``-fem-grid``)."""
    stem = path[: -len(".vtu")]
    found = [path] if os.path.lexists(path) else []
    found += sorted(glob.glob(glob.escape(stem) + "_*.vtu"))
    grid = stem + "-fem-grid.vtu"
    return found + ([grid] if os.path.lexists(grid) else [])


# ------------------------------------------------------------------------------ storage

def existing_ancestor(folder: str) -> str:
    """``folder`` or its nearest existing ancestor."""
    probe = folder
    while not os.path.exists(probe):
        up = os.path.dirname(probe)
        if up == probe:
            break
        probe = up
    return probe


def _probe(folder: str, nbytes: int) -> str | None:
    """Write ``nbytes`` into a probe file in ``folder`` and remove it; None, or the reason
    it failed."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".pdverify-probe-", dir=folder)
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(b"\0" * nbytes)
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    finally:
        try:
            os.unlink(tmp)
        except OSError:
            pass
    return None


def free_bytes(folder: str) -> int:
    """Bytes an unprivileged user may still write on ``folder``'s file system."""
    st = os.statvfs(existing_ancestor(folder))
    return st.f_bavail * st.f_frsize


def check_free(folder: str, need: int, what: str) -> None:
    """InputError naming ``what`` unless ``folder``'s file system has ``need`` bytes free."""
    try:
        free = free_bytes(folder)
    except OSError as exc:
        raise InputError(f"{what}: cannot read the free space ({exc.strerror})") from None
    if free < need:
        raise InputError(f"{what}: only {_size(free)} free on its disk, {_size(need)} needed; "
                         "free some space or choose another place")


def check_cache() -> None:
    """The cache folder takes files: it (or, while it does not exist yet, the nearest
    folder above it, where it would be created) is a folder, a probe file can be written
    into it and removed, and its disk has :data:`MIN_FREE_CACHE` free. Exit 2 otherwise:
    pdverify does not run uncached (a FEM reference would be computed and then lost)."""
    root = cache_root()
    where = f"${CACHE_ENV}" if os.environ.get(CACHE_ENV) else "default; set $" + CACHE_ENV
    what = f"cache folder {root!r} ({where})"
    fix = f"; set ${CACHE_ENV} to a writable folder"
    folders = [root] + [os.path.join(root, s) for s in ("reference_fem", "manufactured")
                        if not os.environ.get(CACHE_ENV) or s == "manufactured"]
    for folder in folders:
        probe = existing_ancestor(folder)
        if not os.path.isdir(probe):
            raise InputError(f"{what}: {probe!r} is a file, not a folder{fix}")
        if probe != folder and folder != root:
            continue          # a missing subfolder: the root's probe covers it
        reason = _probe(probe, 4096)
        if reason is not None:
            raise InputError(f"{what}: cannot write there ({reason}){fix}")
    try:
        check_free(root, MIN_FREE_CACHE, what)
    except InputError as exc:
        raise InputError(f"{exc}{fix}") from None


def check_out_file_space(path: str, flag: str) -> None:
    check_free(os.path.dirname(path), MIN_FREE_FILE, f"{flag} {path!r}")


# ------------------------------------------------------------------------------ lock, stage, swap
#: what a lock file holds while its holder writes: "pdverify report (pid N)", "pdverify
#: export (pid N)"
_LOCK_TEXT = "pdverify "


@contextmanager
def output_lock(out: str, what: str = "report"):
    """Hold ``<parent>/.<name>.lock`` while ``out`` is written (a report or an export):
    a second writer into the same folder exits 2 naming the holder instead of
    interleaving with this one."""
    parent, name = os.path.split(os.path.abspath(out))
    path = os.path.join(parent, f".{name}.lock")
    if os.path.lexists(path) and not _own_lock(path):
        raise InputError(f"--out {out!r}: {path!r} exists and is not pdverify's lock file; "
                         "move it away or choose another folder")
    try:
        os.makedirs(parent, exist_ok=True)
        fh = open(path, "a+")
    except OSError as exc:
        raise InputError(f"--out {out!r}: cannot create its lock file {path!r} "
                         f"({exc.strerror or exc})") from None
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        fh.seek(0)
        holder = fh.read().strip() or "another process"
        fh.close()
        raise InputError(f"--out {out!r} is being written by {holder}; wait for it or "
                         "choose another folder") from None
    try:  # who holds it, for the message of a second writer; a full disk costs only that
        fh.seek(0)
        fh.truncate()
        fh.write(f"{_LOCK_TEXT}{what} (pid {os.getpid()})")
        fh.flush()
    except OSError:
        pass
    try:
        yield
    finally:
        fh.close()  # releases the lock; the empty lock file may stay


def _own_lock(path: str) -> bool:
    """The lock file is pdverify's: a regular file, empty or holding our holder text."""
    try:
        if os.path.islink(path) or not os.path.isfile(path) or os.path.getsize(path) > 200:
            return False
        with open(path, "rb") as fh:
            text = fh.read()
    except OSError:
        return False
    return text == b"" or text.startswith(_LOCK_TEXT.encode())


def clean_stale(parent: str, name: str, own) -> None:
    """Remove staging folders that earlier, killed writers into ``name`` left behind (only
    while holding the lock, so none of them belongs to a live one), and only those that
    ``own(path)`` recognises as pdverify's."""
    for entry in os.listdir(parent):
        if entry.startswith(f".{name}.staging-") or entry.startswith(f".{name}.old-"):
            path = os.path.join(parent, entry)
            if own(path):
                shutil.rmtree(path, ignore_errors=True)


def new_staging(parent: str, name: str, own, who: str, nothing: str) -> str:
    """A fresh staging folder for ``name`` in ``parent`` (the stale ones of killed writers
    removed first, :func:`clean_stale`); one that cannot be made is an OutputError naming
    ``who`` (``report``, ``export``) and what that means (``nothing``: "nothing was
    run")."""
    from .errors import OutputError
    clean_stale(parent, name, own)
    try:
        return tempfile.mkdtemp(prefix=f".{name}.staging-", dir=parent)
    except OSError as exc:
        raise OutputError(f"{who}: cannot create its staging folder in {parent!r} "
                          f"({exc.strerror or exc}); {nothing}") from None


def swap_in(staging: str, out: str) -> None:
    """Replace ``out`` by ``staging`` as a whole: the old folder is renamed aside, the new
    one renamed in, the old one deleted. A reader sees the old folder or the new one."""
    parent, name = os.path.split(out)
    old = None
    if os.path.exists(out):
        old = tempfile.mkdtemp(prefix=f".{name}.old-", dir=parent)
        os.rmdir(old)
        os.rename(out, old)
    try:
        os.rename(staging, out)
    except BaseException:
        if old is not None:
            os.rename(old, out)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


#: the longest suffix a staging or set-aside folder adds to the target's name
#: (``.NAME.staging-XXXXXXXX``: a dot, ".staging-" and mkdtemp's 8 characters)
STAGING_EXTRA = len("..staging-") + 8


def check_target(out: str, flag: str = "--out", shown=None) -> None:
    """Before any work: ``out``'s name, with the staging folder's suffix, fits the file
    system's name limit, and its parent (or the nearest existing ancestor, where it
    would be created) takes a file. InputError naming ``out`` otherwise."""
    full = os.path.abspath(out)
    out = full if shown is None else shown
    probe = existing_ancestor(os.path.dirname(full))
    try:
        limit = os.pathconf(probe, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    for part in full.split(os.sep):
        if len(part.encode("utf-8", "surrogateescape")) > limit:
            raise InputError(f"{flag} {out!r}: the name {part[:40]!r}... is "
                             f"{len(part.encode('utf-8', 'surrogateescape'))} bytes, above "
                             f"the file system's limit of {limit}; choose a shorter name")
    name = os.path.basename(full)
    if len(name.encode("utf-8", "surrogateescape")) + STAGING_EXTRA > limit:
        raise InputError(f"{flag} {out!r}: the name is too long for its staging folder "
                         f"(at most {limit - STAGING_EXTRA} bytes on this file system); "
                         "choose a shorter name")
    if not os.path.isdir(probe):
        raise InputError(f"{flag} {out!r}: {probe!r} is a file, not a folder")
    reason = _probe(probe, 1)
    if reason is not None:
        raise InputError(f"{flag} {out!r}: cannot write into {probe!r} ({reason}); choose "
                         "another place")
