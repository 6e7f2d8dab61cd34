"""simparity: textbook IK and rigid-body methods beside MuJoCo, PyBullet and Pinocchio.

The project's top-level folders install as this package's subpackages
(``simparity.core``, ``simparity.references``, ``simparity.comparisons``,
``simparity.reports``). The public API, importable from ``simparity``:

- :func:`load_scene` ``(name_or_path) -> Scene``: a built-in scene by name, or a scene file;
- :func:`load_scenes` ``(name_or_path) -> list[Scene]``: the same, or the variants of a file's ``[sweep]``;
- :func:`run_scene` ``(scene, engines=..., repeats=...) -> pandas.DataFrame``: one tidy row
  per scene x engine x integrator x dt x metric;
- :func:`read_run` ``(run_dir) -> (pandas.DataFrame, dict)``: a run stored by ``simparity run``.

They are imported on first use, so ``import simparity.core`` stays free of pandas and the
engines.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # what the lazy names are, for type checkers; nothing is imported at run time
    from simparity.comparisons.api import load_scene as load_scene
    from simparity.comparisons.api import load_scenes as load_scenes
    from simparity.comparisons.api import run_scene as run_scene
    from simparity.reports.store import read_run as read_run

_PUBLIC = {
    "load_scene": "simparity.comparisons.api",
    "load_scenes": "simparity.comparisons.api",
    "run_scene": "simparity.comparisons.api",
    "read_run": "simparity.reports.store",
}

__all__ = sorted(_PUBLIC)


def __getattr__(name: str) -> object:
    if name in _PUBLIC:
        import importlib

        return getattr(importlib.import_module(_PUBLIC[name]), name)
    raise AttributeError(f"module 'simparity' has no attribute {name!r}")
