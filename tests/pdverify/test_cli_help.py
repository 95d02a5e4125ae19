"""CLI polish (issue 17): --version, and a help line for every option and argument."""
import argparse
import subprocess
import sys

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
