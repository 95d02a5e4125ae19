"""pdverify: verification suite for peridynamic boundary corrections.

usage:
  python -m pdverify list [SCENE] [--json]                  scenes, their methods, parameters
  python -m pdverify run SCENE [--method M] [--set KEY=VALUE ...] [--json FILE]
                          [--vtu FILE] [--force] [--max-memory SIZE] [--run-timeout SECONDS]
  python -m pdverify report [--out DIR] [--quick] [--only SCENE ...] [--method M ...]
                          [--failed] [--jobs N] [--include FILE ...]
                          [--scheduler ADDRESS] [--max-memory SIZE] [--run-timeout SECONDS]
  python -m pdverify compare BASELINE.json NEW.json [--rtol R] [--atol A] [--summary FILE]
                          [--force]
  python -m pdverify compare --against-published RESULTS.json
  python -m pdverify export SCENE [--method none] [--set KEY=VALUE ...]
                          --format {csv,vtu,peridigm,perilab,lammps} --out DIR
  python -m pdverify score SCENE FILE [--export DIR] [--set KEY=VALUE ...] --name NAME
                          [--out FILE.json] [--force]

Exit codes: 0 success; 1 a run failed numerically, a regression was found, or an output
could not be written after the work (one line naming it; a report stays in its staging
folder), or report --scheduler lost its Dask scheduler (one line); 2 bad input (one line naming the input and what is allowed), a run above the
memory budget (its estimate and the limit), an output pdverify may not replace and a
cache or disk that cannot take the output included, all before any work; stopped by a
signal: 130 SIGINT (Ctrl-C), 143 SIGTERM, 129 SIGHUP (128 + the signal's number).

Plugins: every call into a plugin's code (its import, its checks, its closure and
assembly) runs contained and within 60 s ($PDVERIFY_PLUGIN_TIMEOUT seconds); a plugin
that raises, exits, signals itself or hangs is listed as broken, refused (exit 2) or a
failed run, each naming the plugin and its entry point.
"""
from __future__ import annotations

import argparse
import signal
import sys

from . import __version__, budget
from .errors import STOP_REQUESTED, ClusterError, InputError, OutputError
from .terminal import printable


RUN_TIMEOUT_HELP = ("kill a run that takes longer than SECONDS and record it as failed "
                    "('timed out after N s'); the report goes on (default: no limit; a "
                    "call into a plugin's code is limited to 60 s in any case, "
                    "$PDVERIFY_PLUGIN_TIMEOUT)")
MAX_MEMORY_HELP = ("refuse (exit 2) any run whose memory estimate exceeds SIZE, e.g. 4G, "
                   "512M (default: $PDVERIFY_MAX_MEMORY, else half of the smallest of total "
                   "memory, the cgroup limit and RLIMIT_AS)")


FORCE_HELP = ("replace an existing output file that pdverify did not write (never an input "
              "of the command)")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own usage errors: one line, exit 2
        raise InputError(message + _suggestion(self, message))


def _suggestion(parser, message) -> str:
    """Close matches of a mistyped command (``invalid choice: 'reprot'``) or flag
    (``unrecognized arguments: --metod``) among the commands or every flag."""
    import re
    from .errors import did_you_mean
    choice = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
    if choice:
        return did_you_mean(choice.group(1), re.findall(r"'([^']*)'", choice.group(2)))
    flags = re.match(r"unrecognized arguments: (\S+)", message)
    if flags and flags.group(1).startswith("--"):
        known = set()
        for action in parser._actions:
            known.update(action.option_strings)
            for sub in (getattr(action, "choices", None) or {}).values():
                if isinstance(sub, argparse.ArgumentParser):
                    for a in sub._actions:
                        known.update(a.option_strings)
        flag = flags.group(1).split("=")[0]
        return "" if flag in known else did_you_mean(flag, sorted(known))
    return ""


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="pdverify", description=__doc__,
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"pdverify {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)
    lst = sub.add_parser("list", help="list scenes, methods and parameters "
                                      "(name=default unit {allowed values})")
    lst.add_argument("scene", nargs="?", default=None,
                     help="show this scene only: its parameters with units and meaning, its "
                          "methods, and why the others are not offered")
    lst.add_argument("--json", action="store_true",
                     help="print the listing as JSON (schema pdverify.list/1)")
    run = sub.add_parser("run", help="run one scene with one method")
    run.add_argument("scene", help="scene id (see: python -m pdverify list)")
    run.add_argument("--method", default=None,
                     help="boundary treatment (default: the scene's first method)")
    run.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help="override a scene or method parameter; repeat for several")
    run.add_argument("--json", default=None, metavar="FILE",
                     help="also write the run as a one-run results.json")
    run.add_argument("--vtu", default=None, metavar="FILE",
                     help="also write the run's fields as VTU for ParaView (FILE.vtu; a run "
                          "with several node sets or a FEM grid adds a suffix per file)")
    run.add_argument("--force", action="store_true", help=FORCE_HELP)
    run.add_argument("--max-memory", default=None, metavar="SIZE", help=MAX_MEMORY_HELP)
    run.add_argument("--run-timeout", type=float, default=None, metavar="SECONDS",
                     help=RUN_TIMEOUT_HELP)
    rep = sub.add_parser("report", help="run every scene and method, write the HTML report")
    rep.add_argument("--out", default=None, metavar="DIR",
                     help="output folder, replaced as a whole; it must be new, empty or a "
                          "previous pdverify report (default: reports/latest; "
                          "reports/quick with --quick; reports/[quick-]only-SCENE with "
                          "--only, so that neither replaces the full report)")
    rep.add_argument("--quick", action="store_true",
                     help="smaller sweeps of the expensive scenes")
    rep.add_argument("--only", nargs="+", action="extend", default=None, metavar="SCENE",
                     help="run only these scenes (each once; repeated --only add up)")
    rep.add_argument("--method", nargs="+", default=None, metavar="M", dest="methods",
                     help="run only these methods (on the selected scenes)")
    rep.add_argument("--failed", action="store_true",
                     help="rerun only the runs that failed or were missing in the previous "
                          "report in the output folder, and merge them into it (exit 2 if "
                          "there is no previous report there)")
    rep.add_argument("--jobs", type=int, default=None,
                     help="worker processes, 1 to the number of CPUs (default: the cores "
                          "available to this process)")
    rep.add_argument("--scheduler", default=None, metavar="ADDRESS",
                     help="run the cases on the Dask cluster of this scheduler, e.g. "
                          "tcp://10.0.0.5:8786 (default: $PDVERIFY_SCHEDULER, else the "
                          "local processes of --jobs; needs the extra 'cluster')")
    rep.add_argument("--max-memory", default=None, metavar="SIZE", help=MAX_MEMORY_HELP)
    rep.add_argument("--run-timeout", type=float, default=None, metavar="SECONDS",
                     help=RUN_TIMEOUT_HELP)
    rep.add_argument("--include", nargs="+", default=None, metavar="FILE",
                     help="add the external runs of these results files (written by "
                          "pdverify score) to the report's tables, overview, figures and "
                          "results.json")
    cmp_ = sub.add_parser("compare", help="compare a results file against a baseline")
    cmp_.add_argument("baseline", nargs="?", help="the stored results.json")
    cmp_.add_argument("new", nargs="?", help="the new results.json")
    cmp_.add_argument("--against-published", default=None, metavar="RESULTS",
                      help="instead: check every published entry of RESULTS.json (the "
                           "papers' numbers, each with its tolerance); exit 1 if one fails")
    cmp_.add_argument("--rtol", type=float, default=None,
                      help="relative threshold of a change (default 1e-3)")
    cmp_.add_argument("--atol", type=float, default=None,
                      help="absolute threshold (default 1e-9; 1e-6 points for *_pct metrics)")
    cmp_.add_argument("--summary", default=None, metavar="FILE",
                      help="also write the changes as JSON (FILE.json) or Markdown (else)")
    cmp_.add_argument("--force", action="store_true", help=FORCE_HELP)
    exp = sub.add_parser("export", help="write a static scene's uncorrected problem "
                                        "as a node set or input deck for another PD code")
    exp.add_argument("scene", help="a static-state scene or a bond-based sheet "
                                   "(sheet2d-tension, sheet2d-clamped; see: python -m "
                                   "pdverify list)")
    exp.add_argument("--method", default=None,
                     help="only 'none' (the uncorrected problem) is exported")
    exp.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help="override a scene parameter; repeat for several")
    exp.add_argument("--format", required=True, dest="fmt",
                     choices=("csv", "vtu", "peridigm", "perilab", "lammps"),
                     help="csv files, a VTU file, or a Peridigm / PeriLab.jl / LAMMPS deck "
                          "(a bond-based sheet: no Peridigm deck)")
    exp.add_argument("--out", required=True, metavar="DIR",
                     help="output folder: new, empty or a previous export")
    sco = sub.add_parser("score", help="measure displacements another code computed on an "
                                       "exported node set, as pdverify measures its runs")
    sco.add_argument("scene", help="the scene that was exported")
    sco.add_argument("file", help="displacements: CSV (x, y, z, ux, uy, uz), VTU or Exodus")
    sco.add_argument("--export", default=None, metavar="DIR",
                     help="the export folder FILE answers: its problem.json gives the scene's "
                          "parameters (default: the first of FILE's folder and its parents "
                          "holding .pdverify-export; none found: the --set given, and the "
                          "record warns)")
    sco.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help="the --set of the export (with an export found, each must agree "
                          "with its value); repeat for several")
    sco.add_argument("--name", required=True,
                     help="the code's name; the run's method becomes external:NAME")
    sco.add_argument("--out", default=None, metavar="FILE.json",
                     help="write the run record (a one-run results file)")
    sco.add_argument("--force", action="store_true", help=FORCE_HELP)
    return parser


_RETRY_S = 0.02  # a stop that landed inside an import is raised this much later


def _inside_import_or_exec(frame) -> bool:
    """True while the main thread runs an import or a string given to ``exec``.

    A KeyboardInterrupt raised there escapes badly: an extension module's init turns it
    into ``ImportError: initialization failed``, and one raised inside ``exec`` (which
    dataclasses use to build their methods) makes CPython 3.11 end the process by SIGINT
    even after the CLI has caught it. Only frames above ``main`` count (``python -c``
    itself runs from a string). With ``main`` not on the stack (the handlers stay after
    an in-process ``main()`` has returned), the strings the program itself started from
    do not count either: the outermost frames of a ``python -c`` program, or of a
    pytest-xdist worker's bootstrap, return only when the process ends, so a stop
    deferred until then never landed (a forked pool worker of such a process ignored
    SIGTERM for good).
    """
    inside = []
    while frame is not None and frame.f_code is not main.__code__:
        name = frame.f_code.co_filename
        inside.append(name == "<string>" or name.startswith("<frozen importlib"))
        frame = frame.f_back
    if frame is None:
        while inside and inside[-1]:
            inside.pop()
    return any(inside)


def _cancel_retry() -> None:
    """Stop the re-check timer of :func:`_terminate`: armed when main returns, it would
    fire after the interpreter has put back SIGALRM's default action and end the process
    by SIGALRM (status -14) after its output."""
    try:
        signal.setitimer(signal.ITIMER_REAL, 0)
    except ValueError:
        pass


def _terminate(signum, frame):
    """SIGTERM, SIGHUP: unwind like Ctrl-C, so cleanups run (the exit status is the
    signal's, :data:`STOP_STATUS`). Inside an import or ``exec`` the interrupt waits
    (SIGALRM re-checks every 20 ms) until that code has returned."""
    STOP_REQUESTED["flag"] = True
    if signum in STOP_STATUS:
        STOP_REQUESTED["signal"] = signum
    if _inside_import_or_exec(frame):
        signal.setitimer(signal.ITIMER_REAL, _RETRY_S)
        return
    raise KeyboardInterrupt


def _retry(signum, frame):
    if STOP_REQUESTED["flag"]:
        _terminate(STOP_REQUESTED.get("signal", signal.SIGTERM), frame)


def _install_stop_handlers() -> None:
    try:
        signal.signal(signal.SIGTERM, _terminate)
        signal.signal(signal.SIGHUP, _terminate)
        signal.signal(signal.SIGALRM, _retry)
    except ValueError:  # not in the main thread (e.g. called from a test's worker thread)
        pass


#: the exit status of a stop by each signal pdverify handles: 128 + its number, as a
#: shell reports a process the signal killed (README, "Exit codes")
STOP_STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGHUP: 129}


def main(argv=None) -> int:
    _install_stop_handlers()
    STOP_REQUESTED.pop("signal", None)
    out, err = sys.stdout, sys.stderr
    try:
        args = build_parser().parse_args(argv)
        if args.command is None:
            print(__doc__)
            return 2
        if args.command != "report":   # the report escapes its lines itself (live display)
            from .terminal import EscapingStream
            sys.stdout, sys.stderr = EscapingStream(out), EscapingStream(err)
        return _dispatch(args)
    except InputError as exc:
        print(f"pdverify: error: {printable(exc)}", file=sys.stderr)
        return 2
    except (OutputError, ClusterError) as exc:
        print(f"pdverify: error: {printable(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        _cancel_retry()
        signum = STOP_REQUESTED.get("signal") or signal.SIGINT
        print("pdverify: " + ("interrupted" if signum == signal.SIGINT else
                              f"stopped by {signal.Signals(signum).name}"), file=sys.stderr)
        return STOP_STATUS.get(signum, 130)
    except BrokenPipeError:  # the reader of stdout went away (| head): stop quietly, and
        # point stdout at /dev/null so that the interpreter's final flush cannot fail too
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141  # 128 + SIGPIPE, as a shell reports a pipe's writer
    finally:
        _cancel_retry()
        sys.stdout, sys.stderr = out, err
        budget.set_limit(None)  # --max-memory holds for this command only


def _dispatch(args) -> int:
    if args.command == "list":
        from .listing import format_listing, format_matrix, format_scene, listing_json
        scenes = None
        if args.scene is not None:
            from .scenes import get_scene
            scenes = [get_scene(args.scene)]      # an unknown scene: exit 2, close matches
        if args.json:
            import json
            print(json.dumps(listing_json(scenes), indent=1))
        elif scenes:
            print(format_scene(scenes[0]))
        else:
            print(format_listing())
            print()
            print(format_matrix())
        return 0
    from . import validate
    if args.command in ("run", "report"):
        budget.set_limit(args.max_memory)
    if args.command == "run":
        from .params import parse_assignments
        from .runner import run_one
        json_path = (validate.output_file(args.json, force=args.force)
                     if args.json is not None else None)
        vtu_path = (validate.vtu_file(args.vtu, force=args.force, json_path=json_path)
                    if args.vtu is not None else None)
        from .outputs import check_cache
        check_cache()
        return run_one(args.scene, method=args.method, overrides=parse_assignments(args.set),
                       json_path=json_path, vtu_path=vtu_path,
                       run_timeout=validate.run_timeout(args.run_timeout))
    if args.command == "report":
        from .report import build_report, default_out
        only = validate.only(args.only)
        methods = validate.methods(args.methods)
        out = validate.output_dir(default_out(only, args.quick, methods) if args.out is None
                                  else args.out)
        from .cluster import scheduler_address
        return build_report(out=out, quick=args.quick, only=only, methods=methods,
                            failed=args.failed,
                            jobs=validate.jobs(args.jobs),
                            run_timeout=validate.run_timeout(args.run_timeout),
                            scheduler=scheduler_address(args.scheduler),
                            include=args.include)
    if args.command == "export":
        from .decks import export_command
        from .params import parse_assignments
        return export_command(args.scene, method=args.method,
                              overrides=parse_assignments(args.set), fmt=args.fmt, out=args.out)
    if args.command == "score":
        from .exchange import score_command
        from .params import parse_assignments
        return score_command(args.scene, args.file, name=args.name,
                             overrides=parse_assignments(args.set), export=args.export,
                             out=args.out, force=args.force)
    if args.command == "compare" and args.against_published is not None:
        extra = [f for f, v in (("BASELINE", args.baseline), ("NEW", args.new),
                                ("--rtol", args.rtol), ("--atol", args.atol),
                                ("--summary", args.summary)) if v is not None]
        if extra:
            raise InputError(f"compare --against-published takes one results file and no "
                             f"{', '.join(extra)}")
        validate.input_file(args.against_published, "results file")
        from .compare import compare_published
        return compare_published(args.against_published)
    if args.command == "compare":
        if args.new is None:
            raise InputError("compare needs BASELINE.json and NEW.json (or "
                             "--against-published RESULTS.json)")
        from .compare import compare_files
        for path, what in ((args.baseline, "baseline"), (args.new, "new results")):
            validate.input_file(path, what)
        summary = (validate.output_file(args.summary, "--summary", force=args.force,
                                        inputs=((args.baseline, "baseline"),
                                                (args.new, "new results file")))
                   if args.summary is not None else None)
        return compare_files(args.baseline, args.new, rtol=args.rtol, atol=args.atol,
                             summary=summary)
    raise InputError(f"unknown command {args.command!r}")
