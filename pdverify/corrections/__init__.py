"""Boundary treatments ('methods'): the contract (``treatment``), the registry
(``registry``: built in and plugins) and one module per method."""


def describe(name: str) -> str:
    """The one-line description of the treatment ``name`` ('' if unknown)."""
    from .registry import treatments
    m = treatments().get(name)
    return "" if m is None else m.description
