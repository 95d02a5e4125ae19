"""CLI polish (issue 17): --version, and a help line for every option and argument."""
import argparse
import subprocess
import sys

import pytest

from pdverify import __version__
from pdverify.cli import build_parser


def test_version():
    out = subprocess.run([sys.executable, "-m", "pdverify", "--version"], capture_output=True,
                         text=True)
    assert out.returncode == 0 and out.stdout.strip() == f"pdverify {__version__}"


def test_every_option_and_argument_has_a_help_line():
    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = []
    for name, sub in subparsers.choices.items():
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            if not action.help:
                missing.append(f"{name} {'/'.join(action.option_strings) or action.dest}")
    assert missing == []


def test_top_level_options_and_every_subcommand_have_a_help_line():
    parser = build_parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    missing = [("top " + ("/".join(a.option_strings) or a.dest)) for a in parser._actions
               if not isinstance(a, argparse._SubParsersAction) and not a.help]
    helped = {a.dest for a in subparsers._choices_actions if a.help}
    missing += [f"command {name}" for name in subparsers.choices if name not in helped]
    assert missing == []
    assert set(subparsers.choices) == {"list", "run", "report", "compare", "export", "score"}


@pytest.mark.parametrize("command", ["list", "run", "report", "compare", "export", "score"])
def test_each_subcommand_help_prints_and_exits_0(command):
    out = subprocess.run([sys.executable, "-m", "pdverify", command, "--help"],
                         capture_output=True, text=True)
    assert out.returncode == 0 and "usage: pdverify " + command in out.stdout
    assert "options:" in out.stdout or "optional arguments:" in out.stdout
