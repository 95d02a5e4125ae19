"""Solvers: the front door (``front``: which implementation for which solver name), the
elimination of prescribed unknowns (``condense``), the choice of solver and its
thresholds (``policy``), and the implementations: static (``lu``, ``dense``, ``nested``,
``mixed``, ``iterative``; their checks in ``checks``), Newton, explicit dynamics, modal."""
