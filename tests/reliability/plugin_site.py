"""Broken test plugins installed as ``pip install --target`` lays them out (the packages
of ``tests/plugins/broken_plugins`` with a dist-info naming their entry points), for the
containment tests that run pdverify as a user would, in a subprocess."""
import os
import shutil
from pathlib import Path

PLUGINS = Path(__file__).resolve().parents[1] / "plugins" / "broken_plugins"


def install(target: Path, entry_points: dict, **env_extra) -> dict:
    """The packages of ``entry_points`` (package -> its ``name = module:attr`` lines)
    copied into ``target`` with their dist-info; returns the environment of a subprocess
    that finds them (and a cache of its own, and ``env_extra``)."""
    for package, eps in entry_points.items():
        shutil.copytree(PLUGINS / package, target / package)
        info = target / f"{package}-0.1.0.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\n"
                                       "Version: 0.1.0\n")
        (info / "entry_points.txt").write_text("[pdverify.methods]\n" + "\n".join(eps) + "\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(target), env.get("PYTHONPATH", "")])
    env["PDVERIFY_CACHE_DIR"] = str(target / "cache")
    env.update({k: str(v) for k, v in env_extra.items()})
    return env
