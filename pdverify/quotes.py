"""Numbers a text quotes from this report's runs: placeholders resolved against the records.

A text shown in the report (a Deviations entry of :mod:`pdverify.deviations`, a scene's
docstring) never types a number that one of our runs computes. It writes a placeholder
``{{name}}`` and declares ``name`` as a :class:`Quote`: the run (scene, method, the params
it must have) and the metric, with the format and scale the text prints it in. At render
time :func:`resolve` formats each placeholder from the run's record; a placeholder whose
run is not in the report says so (``[not in this report: ...]``) instead of a number.

Numbers that quote a paper (its printed values), setups we chose, and numbers measured by
a study that is not a report run (a test, a ``pdverify run`` command named in the text)
stay typed, with their source. :func:`typed_near_records` finds typed numbers that look
like one of our results (equal, as printed, to a metric of a run of the text's scenes), so
that a new typed number is caught (tests/pdverify/test_quoted_numbers.py).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

#: a placeholder in a text: ``{{name}}``
PLACEHOLDER = re.compile(r"\{\{([A-Za-z_][\w.-]*)\}\}")


@dataclass(frozen=True)
class Quote:
    """One number a text quotes: ``metric`` of the run of ``scene`` with ``method`` whose
    params include every item of ``where``, printed ``format(value * scale, fmt)`` (then
    ``unit``). ``scene`` empty: the scene the text belongs to (its first)."""

    metric: str
    method: str
    where: dict = field(default_factory=dict)
    fmt: str = ".3g"
    scale: float = 1.0
    scene: str = ""
    unit: str = ""
    minus: float = 0.0

    def describe(self, scene: str) -> str:
        where = ", ".join(f"{k}={v}" for k, v in self.where.items())
        return f"{self.scene or scene} {self.method}" + (f" ({where})" if where else "") \
            + f" {self.metric}"

    def matches(self, run, scene: str) -> bool:
        return (run.scene == (self.scene or scene) and run.method == self.method
                and all(_same(run.params.get(k), v) for k, v in self.where.items()))

    def runs(self, results, scene: str) -> list:
        """The runs of ``results`` this quote names that have its metric (a failed run's
    record may: the depth where it failed)."""
        return [r for r in results if self.matches(r, scene) and self.metric in r.metrics]

    def text(self, value) -> str:
        return format((float(value) - self.minus) * self.scale, self.fmt) + self.unit


def _same(a, b) -> bool:
    """A param equals a quote's: exactly (3 == 3.0; 0.05 is not 0.049999999999999996,
    which the convergence studies' levels may be)."""
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b
    return a == b


def missing_text(quote: Quote, scene: str) -> str:
    return f"[not in this report: {quote.describe(scene)}]"


def resolve(text: str, quotes: dict, results, scene: str) -> str:
    """``text`` with every ``{{name}}`` formatted from the run ``quotes[name]`` names in
    ``results``; a run not among them (or ambiguous: two runs match) says so in place of
    the number; runs that match with one value (the same run in two studies) are one. An
    undeclared name is a programming error (KeyError)."""
    def one(match):
        q = quotes[match.group(1)]
        runs = q.runs(results, scene)
        if len({float(r.metrics[q.metric]) for r in runs}) > 1 or not runs:
            return missing_text(q, scene) if not runs else \
                f"[ambiguous in this report: {q.describe(scene)}, {len(runs)} runs]"
        return q.text(runs[0].metrics[q.metric])
    return PLACEHOLDER.sub(one, text)


def placeholders(text: str) -> list[str]:
    return PLACEHOLDER.findall(text)


# --------------------------------------------------------------------------- the scanner
#: a typed number: a decimal (digits, point, digits; an exponent) or an integer followed by
#: '%', not part of a word, a section or an equation number
_TYPED = re.compile(r"(?<![\w.§(/^-])(-?\d+\.\d+(?:e-?\d+)?|\d+(?= ?%))(?![\w.]\d|\w)")
#: what before a number makes it a reference, not a value: "Eq. (", "Fig. ", "§", ...
_REFERENCE = re.compile(r"(?:§|Sec\. |Secs\. |Eqs?\. \(?|Figs?\. |Tables? |App\. |"
                        r"seed \d{3} )$")


def typed_numbers(text: str, percent: bool = False) -> list[tuple]:
    """(number, position) of every typed number in ``text`` (placeholders removed), not
    counting section, equation, figure and table numbers; ``percent``: a third item, the
    number is a percentage (followed by '%', or by ', ', ' / ', ' and ' and a number
    that is)."""
    text = PLACEHOLDER.sub(lambda m: " " * len(m.group(0)), text)
    out = [(m.group(1), m.start(1), m.end(1)) for m in _TYPED.finditer(text)
           if not _REFERENCE.search(text[max(0, m.start(1) - 12):m.start(1)])]
    if not percent:
        return [(t, p) for t, p, _ in out]
    pcts, follows = [], False
    for t, p, e in reversed(out):   # "0.32 and 0.26 %": a list ending in % is per cent
        tail = text[e:e + 2].lstrip()
        if tail.startswith("%"):
            follows = True
        elif not (follows and re.match(r"(?:,| /| and| or| ->)?\s*$", text[e:_next(out, p)])):
            follows = False
        pcts.append((t, p, follows))
    return pcts[::-1]


def _next(found, pos) -> int:
    later = [p for _, p, _ in found if p > pos]
    return min(later) if later else pos


#: how near a record a typed number counts as a stale or rounded quote of it, besides
#: being equal as printed: 1 % (catches a quote typed once and left behind when the run
#: changed, e.g. 128 % for a record of 128.8 %, which prints 129)
NEAR = 0.01


def _printed_as(value: float, typed: str) -> bool:
    """Whether ``value`` printed with ``typed``'s digits reads ``typed``, or lies within
    :data:`NEAR` of it."""
    t = float(typed)
    if "e" in typed.lower():
        mant = typed.lower().split("e")[0]
        dec = len(mant.split(".")[1]) if "." in mant else 0
        exp = int(typed.lower().split("e")[1])
        step = 10.0 ** (exp - dec)
    else:
        dec = len(typed.split(".")[1]) if "." in typed else 0
        step = 10.0 ** (-dec)
    # a printed value matches a record within half its last digit (round-half either way)
    return t != 0 and (abs(value - t) <= 0.5 * step * (1 + 1e-9)
                       or abs(value - t) <= NEAR * abs(t))


def typed_near_records(text: str, results, scenes, allowed=()) -> list[str]:
    """The typed numbers of ``text`` that equal, as printed (or within :data:`NEAR`), a
    metric of a run of ``scenes`` in ``results``: one phrase each, naming the run. A number followed by '%'
    is compared with ``*_pct`` metrics as they are and with the others times 100; any
    other number with the metrics as they are (magnitudes too). ``allowed``: numbers the
    text types on purpose (a paper's value that happens to equal ours, a setup). Too
    coarse to be told from chance, and not counted: a number with one significant digit,
    or two without '%'."""
    values = []
    for r in results:
        if r.scene not in scenes:
            continue
        for k, v in r.metrics.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                continue
            values.append((r, k, float(v)))
    out = []
    for typed, pos, pct in typed_numbers(text, percent=True):
        if typed in allowed or _significant(typed) < (2 if pct else 3):
            continue
        for r, k, v in values:
            cand = (v if k.endswith("_pct") else 100 * v) if pct else v
            if _printed_as(cand, typed) or _printed_as(abs(cand), typed):
                out.append(f"{typed} (at {pos}: {r.scene} {r.method} {k} = {v:.6g})")
                break
    return out


def _significant(typed: str) -> int:
    mant = typed.lower().lstrip("-").split("e")[0].replace(".", "").lstrip("0")
    return len(mant)


def used(text: str, quotes: dict) -> dict:
    """The quotes ``text`` uses: a family declared by a comprehension, kept to its members
    the text names (in a class body: ``doc_quotes = used(__doc__, {...})``)."""
    names = set(placeholders(text or ""))
    return {k: q for k, q in quotes.items() if k in names}
