"""The seed papers' printed tables as data: ``pdverify/data/seed<NNN>_tables.toml``.

:func:`load_tables` reads a seed's file (its format is described at the file's top);
:class:`Formula` evaluates a printed formula f(N) such as ``"(17N+24)/(17(N-1))"``
without ``eval``: a small parser for integers, the variable ``N``, ``+ - * /``,
parentheses and implicit multiplication by juxtaposition (``17N``, ``17(N-1)``). The
formula is evaluated with Python's operators on whatever ``N`` it is given, so an int
gives a float (true division), a :class:`fractions.Fraction` an exact Fraction and a
NumPy array an array.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from importlib import resources

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the same parser, as a package
    import tomli as tomllib

#: the package directory that holds the data files (shipped as package data)
DATA_DIR = "data"

_TOKEN = re.compile(r"\s*(?:(\d+)|(N)|([-+*/()]))")


def _tokens(text: str) -> list[str]:
    out, pos, text = [], 0, text.rstrip()
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None:
            raise ValueError(f"formula {text!r}: unexpected {text[pos:].strip()[:10]!r} at "
                             f"{pos} (allowed: integers, N, + - * / and parentheses)")
        out.append(match.group(match.lastindex))
        pos = match.end()
    return out


class _Parser:
    """Recursive descent: expr = term {(+|-) term}; term = factor {(*|/) factor | factor};
    factor = - factor | integer | N | ( expr ). The tree is nested tuples (op, a, b),
    ("neg", a), ("int", k) or ("N",)."""

    def __init__(self, text: str):
        self.text, self.toks, self.i = text, _tokens(text), 0

    def peek(self):
        return self.toks[self.i] if self.i < len(self.toks) else None

    def take(self, expected=None):
        tok = self.peek()
        if tok is None or (expected is not None and tok != expected):
            raise ValueError(f"formula {self.text!r}: expected {expected or 'more'}, "
                             f"found {tok or 'the end'}")
        self.i += 1
        return tok

    def parse(self):
        tree = self.expr()
        if self.peek() is not None:
            raise ValueError(f"formula {self.text!r}: unexpected {self.peek()!r}")
        return tree

    def expr(self):
        tree = self.term()
        while self.peek() in ("+", "-"):
            tree = (self.take(), tree, self.term())
        return tree

    def term(self):
        tree = self.factor()
        while True:
            tok = self.peek()
            if tok in ("*", "/"):
                tree = (self.take(), tree, self.factor())
            elif tok is not None and (tok == "N" or tok == "(" or tok.isdigit()):
                tree = ("*", tree, self.factor())   # juxtaposition: 17N, 17(N-1)
            else:
                return tree

    def factor(self):
        tok = self.take()
        if tok == "-":
            return ("neg", self.factor())
        if tok == "N":
            return ("N",)
        if tok.isdigit():
            return ("int", int(tok))
        if tok == "(":
            tree = self.expr()
            self.take(")")
            return tree
        raise ValueError(f"formula {self.text!r}: unexpected {tok!r}")


def _evaluate(tree, n):
    op = tree[0]
    if op == "N":
        return n
    if op == "int":
        return tree[1]
    if op == "neg":
        return -_evaluate(tree[1], n)
    a, b = _evaluate(tree[1], n), _evaluate(tree[2], n)
    if op == "+":
        return a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    return a / b


@dataclass(frozen=True)
class Formula:
    """A printed formula f(N), e.g. ``Formula("(N+1)/(N-1)")(5) == 1.5``."""

    text: str
    tree: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "tree", _Parser(self.text).parse())

    def __call__(self, n):
        return _evaluate(self.tree, n)


def load_tables(seed: str) -> dict:
    """The parsed ``data/seed<seed>_tables.toml`` (a fresh dict on every call)."""
    path = resources.files(__package__).joinpath(DATA_DIR).joinpath(f"seed{seed}_tables.toml")
    with path.open("rb") as fh:
        return tomllib.load(fh)
