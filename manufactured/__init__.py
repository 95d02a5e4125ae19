"""Analytic and manufactured references; never imports pdverify.

The symbolic engine (:func:`solution`, sympy) is imported on first use only: the closed
forms that the scenes evaluate (``bar1d``, ``surface3d``, ``wave1d``, ``vibration1d``)
need numpy and scipy alone, so a command that never derives an expression does not pay
for importing sympy.
"""


def __getattr__(name):
    if name in ("solution", "engine"):
        import importlib
        engine = importlib.import_module(f"{__name__}.engine")
        return engine.solution if name == "solution" else engine
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
