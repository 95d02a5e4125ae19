"""The papers' published numbers in a results file, and the check of each run against them.

A scene's :class:`~pdverify.scenes.base.Published` entries that apply to a run are written
into its record (``published``, one object per metric): the paper's value as printed, its
source, whether the paper prints it or it is read off a figure, what is checked (``equal``
within ``tolerance``, ``below`` or ``above`` a bound, or ``none`` for a statement without
a number) and where the tolerance comes from. Where our number differs for a recorded
reason, the entry names the deviation (:mod:`pdverify.deviations`) and either checks the
value that deviation predicts (``target``) or is a ``known_difference``, shown and not
failed. ``python -m pdverify compare --against-published RESULTS.json`` checks them all.
"""
from __future__ import annotations

import math
import re
from fractions import Fraction

PRINTED = "printed"
FIGURE = "read off a figure"
KINDS = (PRINTED, FIGURE)
#: what a published entry is: a number the paper computes (``value``: reproduced or not),
#: a number it states about its setup that the scene sets itself (``setup``: checked, but
#: it holds by construction and is never counted as a reproduced number), or a statement
#: in words or a bound (``claim``); counted apart by ``compare --against-published`` and
#: the report's pages
ROLES = ("value", "setup", "claim")
#: the check of a statement without a number (shown, not checked)
NO_CHECK = "none"
CHECKS = ("equal", "below", "above", NO_CHECK)

#: an exact printed value (a fraction, an integer of an exact table, a closed-form 0 or 1)
#: is checked to round-off: 1e-9 relative (at least 1e-12 absolute) lies far above the
#: double round-off of these small solves (~1e-15) and far below any real difference
EXACT_RTOL = 1e-9
EXACT_ATOL = 1e-12
EXACT_SOURCE = ("an exact value (fraction or closed form): round-off only, 1e-9 relative "
                "(at least 1e-12)")
DIGITS_SOURCE = "half a unit in the last printed digit"
BOUND_SOURCE = "a bound as printed"

_NUMBER = r"-?\d+(?:\.\d+)?"

#: the source of a known difference's reproduced value that no text of the project states:
#: our own number, recorded from the full report of commit 7c77775 to four significant
#: digits and checked within half a unit in the last (the rule of every printed value:
#: :func:`parse`). The runs are deterministic (the same bits with any worker count,
#: README) and a round-off change of another BLAS kernel is ~1e-12 relative, far inside
#: it; a change of the method, the grid or the measure moves the value and fails the check
RECORDED = ("ours, recorded from pdverify's full report at commit 7c77775 (no text states "
            "it): four significant digits, half a unit in the last")


def printed_text(value) -> str:
    """The value as the paper prints it (a float by its shortest repr: 4.17, 0.06)."""
    return repr(value) if isinstance(value, float) else str(value)


def _half_unit(text: str) -> float:
    """Half a unit in the last printed digit of a decimal number's text."""
    decimals = len(text.split(".", 1)[1]) if "." in text else 0
    return 0.5 * 10.0 ** -decimals


def parse(value) -> tuple[str, float | None, float | None]:
    """(check, number, tolerance from the printed digits) of a printed value: a decimal
    number is ``equal`` within half a unit of its last digit, a fraction ``a/b`` is exact
    (tolerance None: the entry must say so), ``< x`` / ``> x`` are bounds, any other text
    has no number (``none``). A leading number followed by words in brackets ("0 (u_b =
    u_a)") is that number."""
    if isinstance(value, bool):
        return "none", None, None
    if isinstance(value, (int, float)):
        text = printed_text(value)
        return "equal", float(value), _half_unit(text)
    text = str(value).strip()
    m = re.fullmatch(r"([<>])\s*(" + _NUMBER + r")", text)
    if m:
        return ("below" if m.group(1) == "<" else "above"), float(m.group(2)), 0.0
    m = re.fullmatch(r"(-?\d+)/(\d+)", text)
    if m:
        return "equal", float(Fraction(int(m.group(1)), int(m.group(2)))), None
    m = re.fullmatch(r"(" + _NUMBER + r")(?:\s*\(.*\))?", text)
    if m:
        return "equal", float(m.group(1)), _half_unit(m.group(1))
    return "none", None, None


def exact_tolerance(value: float) -> float:
    return max(EXACT_RTOL * abs(value), EXACT_ATOL)


def verdict(entry: dict, ours) -> str:
    """``holds``, ``fails``, ``known difference`` (a named deviation, not failed) or
    ``not numeric`` (a statement without a number: shown, not checked).

    A known difference still bounds ours: it is a known difference only while ours is
    the value we reproduce (``reproduced`` within ``reproduced_tolerance``); any other
    value fails, and so does a known difference that names no reproduced value."""
    check = entry.get("check")
    if check == "none":
        return "not numeric"
    number = _number(ours)
    target = entry.get("target")
    tol = entry.get("tolerance") or 0.0
    if number is None or target is None:
        ok = False
    elif check == "equal":
        ok = abs(number - target) <= tol
    elif check == "below":
        ok = number < target + tol
    elif check == "above":
        ok = number > target - tol
    else:
        ok = False
    if ok:
        return "holds"
    mine = entry.get("reproduced")
    if (entry.get("known_difference") and number is not None
            and isinstance(mine, (int, float)) and not isinstance(mine, bool)
            and abs(number - mine) <= (entry.get("reproduced_tolerance") or 0.0)):
        return "known difference"
    return "fails"


def _number(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        v = float(value)
    except OverflowError:       # an integer beyond the doubles: no value of ours
        return None
    return v if math.isfinite(v) else None


def finite_number(value) -> bool:
    """``value`` is an int or float that is a finite double (an integer of 401 digits is
    not: it overflows)."""
    return _number(value) is not None


#: what a published entry of a results file must hold (key -> allowed types)
ENTRY_FIELDS = {"metric": (str,), "value": (str, int, float), "source": (str,), "kind": (str,),
                "check": (str,)}
OPTIONAL_ENTRY_FIELDS = {"target": (int, float, type(None)), "tolerance": (int, float, type(None)),
                         "tolerance_source": (str,), "deviation": (str,),
                         "known_difference": (bool,), "note": (str,), "role": (str,),
                         "reproduced": (int, float), "reproduced_tolerance": (int, float),
                         "reproduced_source": (str,)}


def check_entry(entry, where: str) -> None:
    """Raise ValueError naming ``where`` and the first field of a published entry that
    breaks the results schema."""
    if not isinstance(entry, dict):
        raise ValueError(f"{where} must be an object, got {type(entry).__name__}")
    for name in ENTRY_FIELDS:
        if name not in entry:
            raise ValueError(f"{where} has no {name!r}")
    for name, types in {**ENTRY_FIELDS, **OPTIONAL_ENTRY_FIELDS}.items():
        if name in entry and (not isinstance(entry[name], types)
                              or (isinstance(entry[name], bool) and bool not in types)):
            raise ValueError(f"{where}.{name} has the wrong type ({type(entry[name]).__name__})")
    if entry["kind"] not in KINDS:
        raise ValueError(f"{where}.kind must be one of {', '.join(KINDS)}, got {entry['kind']!r}")
    if entry["check"] not in CHECKS:
        raise ValueError(f"{where}.check must be one of {', '.join(CHECKS)}, "
                         f"got {entry['check']!r}")
    if entry.get("role", "value") not in ROLES:
        raise ValueError(f"{where}.role must be one of {', '.join(ROLES)}, "
                         f"got {entry['role']!r}")
    if entry["check"] != "none" and not isinstance(entry.get("target"), (int, float)):
        raise ValueError(f"{where}: check {entry['check']!r} needs a numeric 'target'")
    for name in ("value", "target", "tolerance", "reproduced", "reproduced_tolerance"):
        v = entry.get(name)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and not finite_number(v):
            text = repr(v) if isinstance(v, float) else f"an integer of {len(str(abs(v)))} digits"
            raise ValueError(f"{where}.{name} is {text}; a finite number is allowed")
    for name in ("tolerance", "reproduced_tolerance"):
        v = entry.get(name)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and v < 0:
            raise ValueError(f"{where}.{name} is {v!r}; a tolerance is 0 or more")


def catalogue_rows(run: dict, scene) -> list[dict]:
    """One row per published entry that pdverify's own catalogue (``scene.published``)
    holds for a results-file run (its scene, method and params): the entry as the
    package states it (target, tolerance, check, reproduced value), ours from the run's
    metrics, and the verdict. The file's own ``published`` entries are not used: a file
    supplies our values only, never what they are checked against."""
    rows = []
    params = run.get("params") or {}
    for p in scene.published_for(run["method"], params).values():
        entry = p.entry(params)
        ours = run.get("metrics", {}).get(p.metric)
        rows.append({"scene": run["scene"], "method": run["method"], "params": params,
                     "entry": entry, "ours": ours, "verdict": verdict(entry, ours)})
    return rows


def check_run(run: dict) -> list[dict]:
    """One row per published entry of a results-file run: the entry, ours and the verdict."""
    rows = []
    for entry in run.get("published", []):
        ours = run.get("metrics", {}).get(entry["metric"])
        rows.append({"scene": run["scene"], "method": run["method"], "params": run["params"],
                     "entry": entry, "ours": ours, "verdict": verdict(entry, ours)})
    return rows



def role_of(entry: dict) -> str:
    """An entry's role (:data:`ROLES`); a results file written before roles: ``claim``
    for a bound or a statement, else ``value``."""
    role = entry.get("role")
    if role in ROLES:
        return role
    return "value" if entry.get("check") == "equal" else "claim"


def counts(rows: list[dict]) -> dict:
    """``{role: {verdict: n}}`` of checked rows (:func:`check_run`'s)."""
    out = {role: {} for role in ROLES}
    for r in rows:
        by = out[role_of(r["entry"])]
        by[r["verdict"]] = by.get(r["verdict"], 0) + 1
    return out


def count_text(rows: list[dict]) -> str:
    """The rows counted apart by role, one phrase each: values the papers compute
    (reproduced, known differences, failed), setups they state (checked, not counted as
    reproduced), claims in words (held, known differences, shown)."""
    c = counts(rows)

    def n(role, verdict):
        return c[role].get(verdict, 0)
    values = sum(c["value"].values())
    setups = sum(c["setup"].values())
    claims = sum(c["claim"].values())
    return (f"values the papers compute: {values} ({n('value', 'holds')} reproduced, "
            f"{n('value', 'known difference')} known differences, {n('value', 'fails')} "
            f"fail); setups they state: {setups} ({n('setup', 'holds')} checked, not counted "
            f"as reproduced, {n('setup', 'fails')} fail); claims in words: {claims} "
            f"({n('claim', 'holds')} hold, {n('claim', 'known difference')} known "
            f"differences, {n('claim', 'not numeric')} shown, {n('claim', 'fails')} fail)")
