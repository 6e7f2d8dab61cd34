"""pytest plugin (entry point ``pytest11``): run simparity scenes in your own tests and hold them to tolerances.

In a test::

    def test_my_integrator_is_fourth_order(simparity):
        simparity.check("scenes/my-box.toml", engines=["core"], tolerances="my-tolerances.toml")

``simparity.check`` runs the scene (a built-in name, or a scene file: a relative path is found beside
the test file first, then in the current folder) on the engines, holds every row to the tolerances
(default: the shipped ones; a relative path resolves the same way; a file of yours extends the shipped
ones) and fails the test with one line per case and reason; it returns the results table. Bad input (an
unknown scene, a tolerances file with a mistake) fails the test with the one-line message, not a
traceback. ``pytest --simparity-baseline DIR`` also compares each checked scene with the same scene's
rows of the same engines in a stored run of the same profile and fails on any metric that moved
(``--simparity-baseline-rel`` sets the relative threshold). Nothing is imported from the engines until
a test asks for a run.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest


def pytest_addoption(parser) -> None:
    group = parser.getgroup("simparity")
    group.addoption("--simparity-baseline", metavar="DIR", default=None,
                    help="a stored run (simparity run --out DIR) to compare each checked scene with")
    group.addoption("--simparity-baseline-rel", metavar="X", type=float, default=None,
                    help="relative change that counts as a move (default: simparity's BASELINE_RELATIVE)")


class SimparityChecker:
    """What the ``simparity`` fixture gives a test: ``check(scene, ...)``."""

    def __init__(self, baseline: str | None, relative: float | None, test_folder: Path | None = None) -> None:
        if relative is not None and not (relative >= 0 and relative < float("inf")):
            raise pytest.UsageError(f"--simparity-baseline-rel {relative}: out of range (allowed: a number >= 0)")
        if baseline is not None and not baseline.strip():  # never read as "no baseline"
            raise pytest.UsageError("--simparity-baseline '': an empty path (allowed: a stored run's folder, or leave "
                                    "the option out for no baseline)")
        if relative is not None and baseline is None:
            raise pytest.UsageError("--simparity-baseline-rel without --simparity-baseline: it compares with nothing "
                                    "(allowed: both, or neither)")
        self._baseline, self._relative, self._folder = baseline, relative, test_folder

    def _path(self, name: str | Path) -> str | Path:
        """A relative file path as found beside the test file, else as given (the current folder, a built-in)."""
        beside = self._folder / name if self._folder is not None and not Path(name).is_absolute() else None
        return beside if beside is not None and beside.is_file() else name

    def check(self, scene, engines=("core",), tolerances: str | Path | None = None, profile: str = "full",
              repeats: int = 0, isolate: bool = True, allow_unbounded: bool = False,
              check_engines: tuple[str, ...] | None = None, require_engines: tuple[str, ...] | None = None):
        """Run ``scene`` on ``engines``, fail the calling test on any violation; returns the results table.

        ``check_engines``: the engines the check holds (default: the tolerances file's ``check_engines``, else
        every engine run); the others' violations never fail the test. ``require_engines``: fail the test when one of
        these measured nothing (default: the tolerances file's ``require_engines``), as ``simparity check`` does.

        As ``simparity check``, the test also fails when more than a small share of the scene's series have no
        bound on any value (only on their status), unless ``allow_unbounded``.

        The scene runs through the same session as ``simparity run`` (:mod:`comparisons.pipeline.session`): with
        ``isolate`` (default) its cases run in worker processes, so an engine that crashes or hangs fails the test
        with its rows, never the pytest session; ``isolate=False`` runs them in the test's process."""
        from simparity.core.model.errors import SimparityError, one_line

        try:
            return self._check(scene, engines, tolerances, profile, repeats, isolate, allow_unbounded,
                               check_engines, require_engines)
        except SimparityError as err:
            problem = f"simparity: {one_line(err, 1000)}"
        pytest.fail(problem, pytrace=False)  # outside the except: one message, no chained traceback

    def _check(self, scene, engines, tolerances, profile: str, repeats: int, isolate: bool, allow_unbounded: bool,
               check_engines, require_engines):
        from simparity.comparisons.api import load_scene
        from simparity.comparisons.engines.registry import EngineSet, check_engine_names
        from simparity.comparisons.pipeline.session import IN_PROCESS, ISOLATED, Execution, Session, engine_specs
        from simparity.comparisons.gate.check import BASELINE_RELATIVE, compare_with_baseline, held_to
        from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, EngineNames, load_gate
        from simparity.comparisons.gate.violation import grouped
        from simparity.core.model.errors import SimparityError
        from simparity.reports.store import read_run

        from simparity.comparisons.scenes.profiles import PROFILES
        from simparity.core.model.scenes.dynamics import DynamicsScene
        from simparity.core.model.scenes.ik import IKScene
        from simparity.core.model.scenes.kinematics import KinematicsScene
        from simparity.core.model.scene_ranges import check_scene_ranges

        if profile not in PROFILES or not isinstance(repeats, int) or not 0 <= repeats <= 100:
            raise SimparityError(f"profile {profile!r:.40}, repeats {repeats!r:.20}: out of range (allowed: profile "
                                 f"{' or '.join(PROFILES)}, repeats 0 to 100)")
        if not isinstance(scene, (str, Path, DynamicsScene, KinematicsScene, IKScene)):
            raise SimparityError(f"scene {scene!r:.60}: not a scene (allowed: a built-in name, a scene file's path, "
                                 "or a loaded scene)")
        loaded = load_scene(self._path(scene)) if isinstance(scene, (str, Path)) else scene
        check_scene_ranges(loaded)  # a scene built in code, held as a file's is as it is read
        gate = load_gate(self._path(tolerances) if tolerances else DEFAULT_TOLERANCES)
        session = Session([loaded], EngineSet(check_engine_names(engine_specs(engines))), profile=profile,
                          repeats=repeats, execution=Execution(ISOLATED if isolate else IN_PROCESS), bounds=gate.bounds)
        result = session.run()
        table = result.table
        held = EngineNames(tuple(check_engines), "check_engines=") if check_engines else gate.check_engines
        required = EngineNames(tuple(require_engines), "require_engines=") if require_engines else gate.require_engines
        check = held_to(result.check, held, required) if result.check is not None else None
        problems = ([g.line() for g in grouped(check.violations)] + check.absent + [check.nothing_checked]
                    if check is not None else [])
        for line in check.unmatched if check is not None else []:  # loud, never failing: as `simparity check` says it
            warnings.warn(f"simparity: tolerances: {line}", UserWarning, stacklevel=3)
        unbounded = "" if allow_unbounded or check is None else check.too_unbounded()
        problems += [f"unbounded: {unbounded} (here: allow_unbounded=True)"] if unbounded else []
        if self._baseline:
            before, info = read_run(self._baseline)
            if info.profile and info.profile != profile:
                raise SimparityError(f"--simparity-baseline {self._baseline}: a {info.profile}-profile run, the test "
                                     f"runs {profile} (allowed: a baseline run of the {profile} profile)")
            diff = compare_with_baseline(table, before[before["scene"] == loaded.name],
                                         BASELINE_RELATIVE if self._relative is None else self._relative)
            problems += [f"moved since {self._baseline}: {m}" for m in diff.moved]
            problems += [f"missing since {self._baseline}: {m}" for m in diff.missing] + [diff.nothing_compared]
        problems = [problem for problem in problems if problem]  # a check or comparison of nothing is a problem
        if problems:
            pytest.fail(f"simparity: {len(problems)} problem(s) in {loaded.name}:\n" + "\n".join(problems),
                        pytrace=False)
        return table


@pytest.fixture
def simparity(request) -> SimparityChecker:
    """Runs scenes and holds them to tolerances: ``simparity.check(scene, engines=..., tolerances=...)``."""
    return SimparityChecker(request.config.getoption("--simparity-baseline"),
                            request.config.getoption("--simparity-baseline-rel"), Path(str(request.path)).parent)
