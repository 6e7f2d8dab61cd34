"""The public Python API behind ``simparity.load_scene``, ``simparity.load_scenes`` and ``simparity.run_scene``."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from simparity.comparisons.engines.registry import DEFAULT_ENGINES, EngineSet, check_engine_names
from simparity.comparisons.execute.execution import default_jobs
from simparity.comparisons.execute.runner import DEFAULT_REPEATS
from simparity.comparisons.pipeline.session import IN_PROCESS, ISOLATED, Execution, Session, engine_specs
from simparity.comparisons.scenes import library
from simparity.comparisons.scenes.loading.scene_file import load_scene as load_scene_file
from simparity.core.model.scenes.kinds import Scene
from simparity.core.model.scene_ranges import check_scene_ranges


def load_scene(name_or_path: str | Path) -> Scene:
    """A built-in scene by name (see ``simparity list``) or a scene file, checked; a file with a ``[sweep]``
    is several scenes: :func:`load_scenes`.

    Raises
    ------
    simparity.core.errors.SimparityError
        For an unknown name or a bad scene file (the message names the file and key).
    """
    return load_scene_file(library.resolve(str(name_or_path)))


def load_scenes(name_or_path: str | Path) -> list[Scene]:
    """The scenes of a built-in scene name or a scene file, checked: its one scene, or the variants of its
    ``[sweep]`` in the sweep's order (each with its swept values in ``scene.sweep``)."""
    return library.load([str(name_or_path)])


def run_scene(scene: Scene | str | Path, engines=DEFAULT_ENGINES, repeats: int = DEFAULT_REPEATS, *,
              isolate: bool = True, jobs: int | None = None, profile: str = "full") -> pd.DataFrame:
    """Run one scene on engines and measure them against the scene's reference.

    Parameters
    ----------
    scene : Scene, str or Path
        A scene object, a built-in scene name or a scene file.
    engines : iterable of str or Engine
        Engine names as ``simparity engines`` lists them, ``module:Class`` specs, or Engine subclasses or
        instances (built again from their class in a worker) (default: ``core, analytic, mujoco, pybullet,
        pinocchio``).
    repeats : int
        Timed repeats per case; the best is kept.
    isolate : bool
        True (default): the cases run in worker processes, as ``simparity run`` runs them, so an engine that
        crashes, hangs or exhausts memory gives ``failed`` rows and this interpreter goes on; it costs a worker
        start (about a second) per call, and an engine defined in ``__main__`` (a script, a notebook) cannot
        be imported there (refused with the way out). False: the cases run in this process — faster, and an
        engine that crashes takes the interpreter with it.
    jobs : int, optional
        Worker processes when isolated (default: one per CPU).
    profile : str
        ``full`` (default) or ``quick`` (the CI profile: shortened).

    Returns
    -------
    pandas.DataFrame
        The columns of ``results.csv`` (``scene, engine, integrator, dt, metric, value, unit,
        reference, status, detail, ...``), one row per case and metric.
    """
    if isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    else:  # built in code: held to the ranges a scene file is held to as it is read
        check_scene_ranges(scene)
    engine_set = EngineSet(check_engine_names(engine_specs(engines)))
    execution = Execution(ISOLATED if isolate else IN_PROCESS, default_jobs() if jobs is None else jobs)
    return Session([scene], engine_set, profile=profile, repeats=repeats, execution=execution).run().table
