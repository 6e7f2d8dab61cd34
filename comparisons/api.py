"""The public Python API behind ``simparity.load_scene``, ``simparity.load_scenes`` and ``simparity.run_scene``."""

from __future__ import annotations

import pandas as pd

from simparity.comparisons import library
from simparity.comparisons.engines import DEFAULT_ENGINES, check_engine_names, make_engine
from simparity.comparisons.runner import DEFAULT_REPEATS, run_scene as _run_scene
from simparity.comparisons.scene_loader import load_scene as load_scene_file
from simparity.core.results import COLUMNS
from simparity.core.scene import Scene


def load_scene(name_or_path: str) -> Scene:
    """A built-in scene by name (see ``simparity list``) or a scene file, checked; a file with a ``[sweep]``
    is several scenes: :func:`load_scenes`.

    Raises
    ------
    simparity.core.errors.SimparityError
        For an unknown name or a bad scene file (the message names the file and key).
    """
    return load_scene_file(library.resolve(str(name_or_path)))


def load_scenes(name_or_path: str) -> list[Scene]:
    """The scenes of a built-in scene name or a scene file, checked: its one scene, or the variants of its
    ``[sweep]`` in the sweep's order (each with its swept values in ``scene.sweep``)."""
    return library.load([str(name_or_path)])


def run_scene(scene: Scene | str, engines=DEFAULT_ENGINES, repeats: int = DEFAULT_REPEATS) -> pd.DataFrame:
    """Run one scene on engines (names) and measure them against the scene's reference.

    Parameters
    ----------
    scene : Scene or str
        A scene object, a built-in scene name or a scene file.
    engines : iterable of str
        Engine names (default: ``core, analytic, mujoco, pybullet, pinocchio``).
    repeats : int
        Timed repeats per case; the best is kept.

    Returns
    -------
    pandas.DataFrame
        The columns of ``results.csv`` (``scene, engine, integrator, dt, metric, value, unit,
        reference, status, detail``), one row per case and metric.
    """
    if isinstance(scene, str):
        scene = load_scene(scene)
    names = check_engine_names(tuple(engines))
    rows = _run_scene(scene, [make_engine(n) for n in names], make_engine, repeats=repeats)
    return pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))
