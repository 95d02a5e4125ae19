"""Plugins that end, signal or stall the process in each place pdverify calls plugin code
(issue 50); each must become a broken listing, a refusal or a failed run naming the
plugin and its entry point, never a silent, hung or "internal error" pdverify."""
import os
import signal
import sys
import time

import numpy as np

from pdverify.corrections.registry import BondMethod
from pdverify.corrections.treatment import Role, Treatment
from pdverify.pd.closure import Closure


def _uniform(params):
    return Closure(force_factor=lambda model: np.ones(model.bond_a.size))


def _forever(*args):
    while True:
        time.sleep(1)


def _os_exit(params):
    os._exit(3)


def _self_signal(params):
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(5)


def _segfault(params):
    os.kill(os.getpid(), signal.SIGSEGV)
    time.sleep(5)


def _sys_exit_check(cells, params, where):
    sys.exit(3)


def _called_check(cells, params, where):
    """Leaves a trace in $PDVERIFY_TEST_CALLED: the test of an unselected plugin reads it."""
    path = os.environ.get("PDVERIFY_TEST_CALLED")
    if path:
        with open(path, "a") as f:
            f.write(f"check {where}\n")


class RaisingParamsFor(Treatment):
    def params_for(self, scene):
        raise RuntimeError("params_for is broken")


class HangingParamsFor(Treatment):
    def params_for(self, scene):
        _forever()


def _role_check_exit(n, params, where):
    sys.exit(3)


COMMON = dict(description="hostile test plugin", source="tests/plugins/broken_plugins")
#: a role in the wave bars' family whose check exits (called unguarded before issue 50)
ROLE_CHECK_EXIT = Treatment(name="role-check-exit", roles=(
    ("wave-bar", Role(lambda problem, params: None, (), _role_check_exit)),), **COMMON)
CHECK_SYS_EXIT = BondMethod(name="check-sys-exit", closure=_uniform, checker=_sys_exit_check,
                            **COMMON)
CHECK_HANG = BondMethod(name="check-hang", closure=_uniform, checker=_forever, **COMMON)
CLOSURE_OS_EXIT = BondMethod(name="closure-os-exit", closure=_os_exit, **COMMON)
CLOSURE_SIGNAL = BondMethod(name="closure-signal", closure=_self_signal, **COMMON)
CLOSURE_SEGV = BondMethod(name="closure-segv", closure=_segfault, **COMMON)
CLOSURE_HANG = BondMethod(name="closure-hang", closure=_forever, **COMMON)
CALLED = BondMethod(name="called", closure=_uniform, checker=_called_check, **COMMON)
PARAMS_FOR_RAISES = RaisingParamsFor(name="params-for-raises", families=("static-state",),
                                     **COMMON)
PARAMS_FOR_HANGS = HangingParamsFor(name="params-for-hangs", families=("static-state",),
                                    **COMMON)
#: a description with escape codes (clear screen, red): list must show them escaped
ESCAPES = BondMethod(name="escapes", closure=_uniform, description="evil\x1b[2J\x1b[31m red",
                     source="tests/plugins/broken_plugins")
