"""A plugin's entry point as ``importlib.metadata`` lists an installed one, for tests that
register a plugin in-process (the registry is loaded afresh with it)."""
import importlib.metadata as md

from pdverify.corrections import registry


def register(monkeypatch, name: str, value: str, load) -> None:
    """``importlib.metadata.entry_points`` answers one entry point ``name = value`` whose
    ``load()`` is ``load()``; the registry is reloaded. ``monkeypatch.undo()`` and
    ``registry.reload()`` afterwards forget it."""

    class EP:
        group = registry.ENTRY_POINT_GROUP

        def load(self):
            return load()

    EP.name, EP.value = name, value
    monkeypatch.setattr(md, "entry_points", lambda group=None: [EP()])
    registry.reload()
