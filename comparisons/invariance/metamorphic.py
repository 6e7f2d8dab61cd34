"""Metamorphic invariance: a scene and its transformed version must give the same results.

Physics does not change when a scene is translated, rotated with its gravity, its bodies listed in another
order or its units rescaled (:mod:`comparisons.invariance.transforms`); neither may any result or verdict of an engine,
nor of simparity's own metrics. :func:`check_invariance` runs each scene and its transformed versions on the
same engines, carries every value of the transformed run back into the scene's own units (from its unit
string: m -> / L, m/s -> / (L/T), ...) and its time steps back (dt' / T), and compares row by row (timing rows
``time_per_*`` left out):

- the statuses must be equal. A status change is accepted only where rounding explains it: a one-ulp
  perturbation (:mod:`comparisons.invariance.perturb`: the initial state or the chain's geometry, and the units, each one
  ulp off) of the scene turns that row to the transformed run's status, or one of the transformed scene turns
  it back (the value sits within its spread of the threshold); or one side is ``n/a`` at the rounding floor
  (flag ``rounding-floor``: the value is rounding in that frame); or it is an observed order fitted over an
  error that is itself within its rounding allowance of zero (the fit's slopes, and its verdict, are
  rounding's);
- ok values must agree within the largest of :data:`SPREAD_FACTOR` x the row's ulp spread (how far the value
  moves over :data:`ULP_SEEDS` one-ulp perturbations of the untransformed scene: what chaos, a settling
  contact or a singular pose make of rounding), :data:`ROUNDING_RTOL` x the value, and the rounding allowance
  of the row's unit in either frame (:mod:`comparisons.invariance.rounding_allowance`: rounding alone, 2 km from the
  origin 2000 x what it is at 1 m; for chains also the coarsest forward kinematics of the engines run,
  PyBullet's float32 link states). An observed order is a fit of log errors over the time steps: its
  allowance is what its errors' allowances allow the fit's slope. The perturbed runs are made only for scenes
  whose comparison needs them; a translated scene that still fails is perturbed too, in its own frame: far
  from the origin its positions round at the coarser scale there.

A transform the scene's reference cannot follow (a closed form only in the world's xy plane) is skipped with
that reason: there is nothing to measure the transformed engines against.

:meth:`SceneInvariance.rows` gives the verdict as result rows, per scene x engine x integrator x dt and
transform: ``invariance_ratio_<transform>``, the largest |difference| / allowed over the case's metrics (<= 1:
invariant), and ``invariance_status_changes_<transform>``, the status changes rounding does not explain; each
detail names the transform, the worst metric with both values, the changes, and an engine's known absolute
constant (:mod:`comparisons.invariance.engine_constants`) when the transform scales its dimension. An engine that
hard-codes z-up gravity or the world origin is caught by them without any reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterable, NamedTuple, cast

import numpy as np

from simparity.comparisons.execute.in_process import run_in_process
from simparity.comparisons.invariance.engine_constants import constants_exposed
from simparity.comparisons.measure.joint_motion_metrics import JOINT_ORDER_SOURCES
from simparity.comparisons.measure.metrics import ORDER_SOURCES as BODY_ORDER_SOURCES
from simparity.comparisons.invariance.perturb import ulp_perturbed
from simparity.comparisons.invariance.rounding_allowance import rounding_floors
from simparity.comparisons.invariance.transforms import Transform, transform_scene
from simparity.comparisons.invariance.units import Dimension, unit_dimensions
from simparity.core.model.engine import Engine
from simparity.core.model.metric_catalogue import is_probe, is_timing
from simparity.core.model.errors import TransformError, UnitError, one_line
from simparity.core.model.results import DIMENSIONLESS, FAILED, NOT_AVAILABLE, OK, ROUNDING_FLOOR, ResultRow
from simparity.comparisons.common.integrators import motion_reference_integrator
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.scenes.kinds import Scene

RunScenes = Callable[[list], list[list[ResultRow]]]
"""Runs scenes on the engines being checked: the rows of each scene, in order (:func:`in_process`, or a run's
executor in ``comparisons.cli``)."""

EngineFor = Callable[[str], "Engine | None"]
"""An engine built in this process by name (None: not built here, a user's engine), asked whether the scene's
reference can follow a transform and how fine each engine's forward kinematics is."""

ULP_SEEDS = (1, 2)
"""Seeds of the one-ulp perturbations a row's spread is measured over: two independent sign patterns catch a
chaotic row's spread to within a small factor (covered by :data:`SPREAD_FACTOR`) at twice the cost of one run."""

SPREAD_FACTOR = 10.0
"""Values may differ by this many ulp spreads: a transform perturbs every operation's rounding, not only the
initial state's, and two perturbed runs sample the spread's tail thinly; a real non-invariance (a hard-coded
axis, an absolute threshold crossed) moves a value by orders of magnitude more."""

ROUNDING_RTOL = 1e-9
"""Values may differ by this fraction of their size whatever their spread: rounding in another frame or
unit system changes each operation by ~1e-16 relative, and 10^4 steps of a non-chaotic run compound that to
~1e-12; 1e-9 leaves a margin of 1000 and is still far below any error a metric reports as a finding."""

JOINT_UNIT, REVOLUTE_UNIT = "rad or m", "rad"
"""A joint-value metric's mixed unit, and what it is in a chain without prismatic joints."""

RATIO_METRIC, CHANGES_METRIC = "invariance_ratio_", "invariance_status_changes_"
"""Prefixes of the invariance rows' metrics; the transform's name follows."""

ORDER_SOURCES = BODY_ORDER_SOURCES | JOINT_ORDER_SOURCES
"""Each observed order's error (a free body's and a chain's motion)."""
ORDER_SOURCES_OF = {source: order for order, source in ORDER_SOURCES.items()}
"""The observed order fitted over each error metric."""

SAME, WITHIN, VALUE_DIFFERS, STATUS_CHANGED, AT_THRESHOLD, MISSING, NOT_COMPARABLE, UNKNOWN_UNIT = (
    "same", "within bounds", "value differs", "status changed", "status at its threshold", "missing",
    "not comparable", "unknown unit")
"""Verdicts of one row's comparison."""

FAILING = (VALUE_DIFFERS, STATUS_CHANGED, MISSING, UNKNOWN_UNIT)
"""Verdicts that break invariance."""

Key = tuple[str, str, "float | None", str]
"""A row's (engine, integrator, dt [s of the scene] or None, metric)."""

DT_MATCH = 1e-12
"""Relative difference within which a transformed run's time step is T x one of the scene's: the same product
rounded in another order (T1 T2 dt against T2 (T1 dt)) differs by an ulp or two."""

DETAIL_LIMIT = 160
"""Characters of a row's detail quoted in an invariance row's detail."""

CHANGES_LISTED = 3
"""Status changes an invariance row's detail names (then how many more)."""


@dataclass(frozen=True)
class RowComparison:
    """One row of a scene against the same row of its transformed version, in the scene's own units.

    Attributes
    ----------
    key : Key
    unit : str
    status, status_transformed : str
    value, value_transformed : float
        NaN unless the status is ok (``value_transformed`` carried back into the scene's units).
    allowed : float
        The |difference| allowed; NaN when the values are not compared.
    spread : float
        The row's ulp spread in the scene's units (0 when not measured).
    verdict : str
        One of the verdicts above.
    detail_transformed : str
        The transformed row's detail (why its status is what it is).
    """

    key: Key
    unit: str
    status: str
    status_transformed: str
    value: float
    value_transformed: float
    allowed: float
    spread: float
    verdict: str
    detail_transformed: str = ""

    @property
    def difference(self) -> float:
        return abs(self.value_transformed - self.value)

    @property
    def ratio(self) -> float:
        """|difference| / allowed (0 for equal values, inf for a difference where none is allowed)."""
        if self.difference == 0.0:
            return 0.0
        return self.difference / self.allowed if self.allowed > 0 else math.inf


@dataclass(frozen=True)
class TransformCheck:
    """One scene under one transform: its rows compared, or why the transform was not run.

    Attributes
    ----------
    scene : str
    transform : Transform
    comparisons : tuple of RowComparison
    skipped : str
        Why the transform was not run ("" when it was): it cannot apply to the scene, changes nothing, or the
        scene's reference cannot follow it.
    """

    scene: str
    transform: Transform
    comparisons: tuple[RowComparison, ...] = ()
    skipped: str = ""

    @property
    def failures(self) -> tuple[RowComparison, ...]:
        return tuple(c for c in self.comparisons if c.verdict in FAILING)


@dataclass(frozen=True)
class SceneInvariance:
    """A scene's invariance under every transform checked.

    Attributes
    ----------
    scene : Scene
    base_rows : tuple of ResultRow
        The untransformed run's rows.
    checks : tuple of TransformCheck
    """

    scene: Scene
    base_rows: tuple[ResultRow, ...]
    checks: tuple[TransformCheck, ...]

    def rows(self) -> list[ResultRow]:
        """The invariance rows of every transform, per engine x integrator x dt of the untransformed run."""
        return [row for check in self.checks for row in _check_rows(self.scene, self.base_rows, check)]


def in_process(engines: list[Engine], make_reference: Callable[[str], Engine], repeats: int = 0) -> RunScenes:
    """Runs scenes with :func:`comparisons.execute.in_process.run_in_process` in this process (tests, notebooks);
    ``repeats`` 0 times one cold call (timing is not compared)."""

    def run(scenes: list) -> list[list[ResultRow]]:
        return [run_in_process(scene, engines, make_reference, repeats=repeats) for scene in scenes]

    return run


def check_invariance(scenes: list, transforms: Iterable[Transform], run: RunScenes, engine_for: EngineFor,
                     base_rows: list[list[ResultRow]] | None = None, seeds=ULP_SEEDS) -> list[SceneInvariance]:
    """Every scene under every transform, compared with its untransformed run (module docstring).

    Parameters
    ----------
    scenes : list of Scene
    transforms : iterable of Transform
    run : RunScenes
        Runs a list of scenes on the engines to check (all scenes of one phase in one call, so an executor
        runs them in parallel).
    engine_for : EngineFor
        Builds a built-in engine by name (the scenes' references; the engines whose forward kinematics sets a
        chain's resolution).
    base_rows : list of list of ResultRow, optional
        The untransformed scenes' rows when already run (``simparity run --transform``).
    seeds : tuple of int
        Seeds of the one-ulp perturbations.
    """
    transforms = tuple(transforms)
    base = list(base_rows) if base_rows is not None else run(list(scenes))
    jobs, skipped = [], {}
    for s, scene in enumerate(scenes):
        resolution = _fk_resolution(scene, base[s], engine_for)
        for transform in transforms:
            try:
                transformed = transform_scene(scene, transform) if transform.changes(scene) else None
            except TransformError as err:
                skipped[s, transform.name] = f"does not apply: {err.problem}"
                continue
            reason = _unchanged(scene) if transformed is None else _unfollowed(transformed, engine_for)
            if reason:
                skipped[s, transform.name] = reason
            else:
                jobs.append(_Job(s, transform, scene, cast(Scene, transformed), resolution))  # changed: not None
    for job, rows in zip(jobs, run([job.scene for job in jobs])):
        job.rows = rows
    _measure_spreads(scenes, base, jobs, run, seeds)
    out = []
    for s, scene in enumerate(scenes):
        checks = []
        for transform in transforms:
            if (s, transform.name) in skipped:
                checks.append(TransformCheck(scene.name, transform, skipped=skipped[s, transform.name]))
                continue
            job = next(j for j in jobs if j.index == s and j.transform is transform)
            checks.append(TransformCheck(scene.name, transform, job.compare(base[s])))
        out.append(SceneInvariance(scene, tuple(base[s]), tuple(checks)))
    return out


def _unchanged(scene) -> str:
    what = ("one body has no other order" if isinstance(scene, DynamicsScene) else "a chain has no free bodies"
            if isinstance(scene, (JointDynamicsScene, JointMotionScene))
            else "a chain has no mass, no time and no free bodies")
    return f"changes nothing in this scene ({what})"


def _unfollowed(transformed, engine_for: EngineFor) -> str:
    """Why the scene's reference cannot model ``transformed`` ("" when it can, or is not built here)."""
    reference = engine_for(transformed.reference)
    if reference is None:
        return ""
    if isinstance(transformed, DynamicsScene):
        support = reference.supports_dynamics(transformed, reference.scene_integrators(transformed)[0])
    elif isinstance(transformed, JointDynamicsScene):
        support = reference.supports_joint_dynamics(transformed.chain, reference.joint_dynamics_methods()[0])
    elif isinstance(transformed, JointMotionScene):
        support = reference.supports_joint_motion(transformed, motion_reference_integrator(transformed, reference))
    else:
        support = reference.supports_kinematics(transformed.chain)
    if support.ok:
        return ""
    return (f"not compared: the scene's reference {transformed.reference} cannot model the transformed scene "
            f"({support.reason}), so there is nothing to measure the engines against")


def _fk_resolution(scene, rows: list[ResultRow], engine_for: EngineFor) -> tuple[float, float]:
    """(position [m], orientation [rad]) the coarsest forward kinematics among the engines of ``rows`` can tell
    apart (``KinematicsModel.resolution``); (0, 0) for a dynamics scene."""
    if isinstance(scene, (DynamicsScene, JointMotionScene)):  # errors of motion, not of frames
        return 0.0, 0.0
    position = orientation = 0.0
    for name in dict.fromkeys(row.engine for row in rows):
        try:
            engine = engine_for(name)
            if engine is None or not engine.supports_kinematics(scene.chain).ok:
                continue
            model_resolution = engine.build_kinematics(scene.chain).resolution
        except Exception:  # noqa: BLE001 - an engine that cannot build the chain has no rows to judge
            continue
        position, orientation = max(position, model_resolution[0]), max(orientation, model_resolution[1])
    return position, orientation


class _Row(NamedTuple):
    """A result row as compared: its value in the scene's own units (or the UnitError met converting it)."""

    status: str
    value: float | UnitError
    detail: str
    unit: str
    flag: str


@dataclass
class _Spread:
    """Rounding noise of a run's rows: the largest |change| of each row's value over its one-ulp perturbations
    [scene units], and the statuses a perturbation turned each row to (other than its own)."""

    size: dict
    reached: dict

    @classmethod
    def empty(cls) -> "_Spread":
        return cls({}, {})

    def add(self, reference: dict, perturbed: dict) -> None:
        """Fold in one perturbed run; both :func:`_keyed` rows."""
        for key, row in perturbed.items():
            if key not in reference:
                continue
            row0 = reference[key]
            if row.status != row0.status:
                self.reached.setdefault(key, set()).add(row.status)
            elif row.status == OK and isinstance(row.value, float) and isinstance(row0.value, float) and \
                    math.isfinite(row.value - row0.value):
                self.size[key] = max(self.size.get(key, 0.0), abs(row.value - row0.value))


@dataclass
class _Job:
    """A scene's transformed version to run, then compare with the scene's rows."""

    index: int
    transform: Transform
    original: Scene
    scene: Scene
    resolution: tuple[float, float]
    rows: list | None = None
    spread: _Spread = field(default_factory=_Spread.empty)
    own_spread: _Spread = field(default_factory=_Spread.empty)

    def compare(self, base_rows) -> tuple[RowComparison, ...]:
        return _compare(_keyed(self.original, base_rows, None), _keyed(self.original, self.rows, self.transform),
                        self.spread, self.own_spread, self.floor)

    def __post_init__(self) -> None:
        self._floors = (rounding_floors(self.original), rounding_floors(self.scene))

    def floor(self, unit: str) -> float:
        """The rounding allowance of a result in ``unit`` [scene units]: the scene's or the transformed scene's
        carried back, whichever is larger (each frame rounds at its own scale), plus the coarsest forward
        kinematics' resolution for a chain's lengths and angles."""
        dimensions = unit_dimensions(_row_unit(self.original, unit))
        own, theirs = (max(floors.of(d) for d in dimensions) for floors in self._floors)
        try:
            own = max(own, self.transform.to_scene_units(theirs, _row_unit(self.original, unit)))
        except UnitError:
            pass
        position, orientation = self.resolution
        return own + (position if Dimension(length=1) in dimensions else 0.0) + (
            orientation if Dimension() in dimensions else 0.0)


def _measure_spreads(scenes: list, base: list, jobs: list[_Job], run: RunScenes, seeds) -> None:
    """Give every job whose comparison fails without it the ulp spread of its untransformed scene (measured
    once per scene, shared by its transforms); a translated scene that still fails also gets its own spread."""
    failing = [job for job in jobs if _fails(job, base)]
    indices = sorted({job.index for job in failing})
    perturbed = [(s, *ulp_perturbed(scenes[s], seed)) for s in indices for seed in seeds]
    spreads = {s: _Spread.empty() for s in indices}
    for (s, _, units), rows in zip(perturbed, run([scene for _, scene, _ in perturbed])):
        spreads[s].add(_keyed(scenes[s], base[s], None), _keyed(scenes[s], rows, units))
    for job in failing:
        job.spread = spreads[job.index]
    moved = [job for job in failing if np.any(job.transform.translation_world) and _fails(job, base)]
    own = [(job, *ulp_perturbed(job.scene, seed)) for job in moved for seed in seeds]
    for (job, _, units), rows in zip(own, run([scene for _, scene, _ in own])):
        job.own_spread.add(_keyed(job.original, job.rows, job.transform),
                           _keyed(job.original, rows, job.transform.then(units)))


def _fails(job: _Job, base: list) -> bool:
    return any(c.verdict in FAILING for c in job.compare(base[job.index]))


def _row_unit(scene, unit: str) -> str:
    """The unit a row's value is in: a joint value of a chain without prismatic joints is in radians."""
    chain = getattr(scene, "chain", None)
    if unit == JOINT_UNIT and chain is not None and all(j.type != "prismatic" for j in chain.joints):
        return REVOLUTE_UNIT
    return unit


def _keyed(scene, rows, transform: Transform | None) -> dict:
    """{key: _Row} of ``rows``, timing and floating-point probes left out; ``transform``: the rows are of ``scene`` transformed by it (its
    time steps and values are carried back), None: of ``scene`` itself."""
    steps = list(scene.dts) if isinstance(scene, (DynamicsScene, JointMotionScene)) else []
    scale = transform.time_scale if transform else 1.0
    out = {}
    for row in rows:
        if is_timing(row.metric) or is_probe(row.metric):  # wall times; where an engine's rounding shows
            continue
        dt = None if row.dt != row.dt else next(
            (step for step in steps if abs(row.dt - scale * step) <= DT_MATCH * row.dt), row.dt)
        value: float | UnitError = float(row.value)
        if transform is not None and row.status == OK:
            try:
                value = transform.to_scene_units(float(row.value), _row_unit(scene, row.unit))
            except UnitError as err:
                value = err
        out[row.engine, row.integrator, dt, row.metric] = _Row(row.status, value, row.detail, row.unit,
                                                                getattr(row, "flag", ""))
    return out


def _compare(base: dict, transformed: dict, spread: _Spread, own_spread: _Spread,
             floor: Callable[[str], float]) -> tuple[RowComparison, ...]:
    """Every row of ``base`` and ``transformed`` compared; ``spread``: the untransformed scene's ulp spread,
    ``own_spread``: the transformed scene's (empty unless measured)."""
    sizes = {key: max(spread.size.get(key, 0.0), own_spread.size.get(key, 0.0)) for key in base}
    allowed = {key: max(SPREAD_FACTOR * sizes[key],
                        ROUNDING_RTOL * max(abs(row.value), abs(transformed[key].value)), floor(row.unit))
               for key, row in base.items() if _both_measured(row, transformed.get(key))}
    allowed.update(_order_allowances(base, allowed))
    rounding = _rounding_orders(base, allowed)
    out = []
    for key in list(base) + [k for k in transformed if k not in base]:
        if key not in base or key not in transformed:
            missing = "the untransformed run" if key not in base else "the transformed run"
            out.append(RowComparison(key, (base.get(key) or transformed[key]).unit,
                                     base[key].status if key in base else "",
                                     transformed[key].status if key in transformed else "", math.nan, math.nan,
                                     math.nan, 0.0, MISSING, f"no such row in {missing}"))
            continue
        row0, row1 = base[key], transformed[key]
        reached = row1.status in spread.reached.get(key, ()) or row0.status in own_spread.reached.get(key, ())
        verdict = _verdict(row0, row1, allowed.get(key, math.nan), reached or key in rounding)
        value1 = row1.value if isinstance(row1.value, float) and row1.status == OK else math.nan
        detail = str(row1.value) if verdict in (UNKNOWN_UNIT, NOT_COMPARABLE) else row1.detail
        out.append(RowComparison(key, row0.unit, row0.status, row1.status,
                                 row0.value if row0.status == OK else math.nan, value1, allowed.get(key, math.nan),
                                 sizes.get(key, 0.0), verdict, detail))
    return tuple(out)


def _both_measured(row0: _Row, row1: _Row | None) -> bool:
    return (row1 is not None and row0.status == row1.status == OK and isinstance(row0.value, float)
            and isinstance(row1.value, float) and math.isfinite(row0.value) and math.isfinite(row1.value))


def _order_allowances(base: dict, allowed: dict) -> dict:
    """The allowance of each observed order: the slope of a fit of log errors against log dt moves by at most
    2 x the largest relative allowance of its errors over the smallest log step between the time steps."""
    out = {}
    for key in base:
        engine, integrator, dt, metric = key
        if metric not in ORDER_SOURCES or key not in allowed:
            continue
        sources = [(k[2], base[k].value, allowed[k]) for k in allowed
                   if k[:2] == (engine, integrator) and k[3] == ORDER_SOURCES[metric] and k[2] is not None]
        steps = sorted(np.log([source_dt for source_dt, _, _ in sources]))
        if len(steps) < 2:
            continue
        relative = max((a / abs(v) if v else math.inf) for _, v, a in sources)
        out[key] = max(allowed[key], 2 * relative / float(np.min(np.diff(steps))))
    return out


def _rounding_orders(base: dict, allowed: dict) -> set:
    """The order rows whose fit takes an error that is itself within its rounding allowance of zero: the fit's
    slopes, and its verdict, are then rounding's."""
    level = {k[:2] + (ORDER_SOURCES_OF.get(k[3], ""),) for k in allowed if abs(base[k].value) <= allowed[k]}
    return {k for k in base if k[3] in ORDER_SOURCES and (k[0], k[1], k[3]) in level}


def _verdict(row0: _Row, row1: _Row, allowed: float, rounding_explains: bool) -> str:
    """One row's verdict; ``rounding_explains``: a one-ulp perturbation reaches the other run's status, or the row
    is an order fitted over rounding."""
    if row0.status != row1.status:
        at_floor = ROUNDING_FLOOR in (row0.flag, row1.flag)  # rounding in one frame: within rounding of the floor
        return AT_THRESHOLD if rounding_explains or at_floor else STATUS_CHANGED
    if row0.status != OK:
        return SAME
    if isinstance(row1.value, UnitError):
        try:
            unit_dimensions(row0.unit)
        except UnitError:
            return UNKNOWN_UNIT
        return NOT_COMPARABLE
    difference = abs(cast(float, row1.value) - cast(float, row0.value))  # both measured, converted
    if difference == 0.0:
        return SAME
    return WITHIN if difference <= allowed else VALUE_DIFFERS


def _check_rows(scene, base_rows, check: TransformCheck) -> list[ResultRow]:
    """The two invariance rows of every case (engine x integrator x dt) of the untransformed run."""
    cases: dict[tuple, list] = {}
    references: dict[tuple, str] = {}
    for row in base_rows:
        case = (row.engine, row.integrator, None if row.dt != row.dt else row.dt)
        cases.setdefault(case, [])
        references.setdefault(case, row.reference)
    for comparison in check.comparisons:
        cases.setdefault(comparison.key[:3], []).append(comparison)
    name, text = check.transform.name, check.transform.text()
    out = []
    for (engine, integrator, dt), comparisons in cases.items():
        def row(metric: str, value: float, status: str, detail: str) -> ResultRow:
            return ResultRow(scene=scene.name, engine=engine, integrator=integrator,
                             dt=math.nan if dt is None else dt, metric=metric, value=value, unit=DIMENSIONLESS,
                             reference=f"{references.get((engine, integrator, dt), '')} (transform {name})",
                             status=status, detail=detail)

        if check.skipped:
            why = f"transform {text} {check.skipped}"
            out += [row(RATIO_METRIC + name, math.nan, NOT_AVAILABLE, why),
                    row(CHANGES_METRIC + name, math.nan, NOT_AVAILABLE, why)]
            continue
        out += _case_rows(comparisons, check.transform, engine, scene.kind, row)
    return out


def _case_rows(comparisons: list[RowComparison], transform: Transform, engine: str, kind: str,
               row) -> list[ResultRow]:
    text = transform.text()
    ratio_metric, changes_metric = RATIO_METRIC + transform.name, CHANGES_METRIC + transform.name
    unknown = [c for c in comparisons if c.verdict == UNKNOWN_UNIT]
    if unknown:
        why = (f"transform {text}: {unknown[0].key[3]}: {unknown[0].detail_transformed} (no value is converted by a "
               "guessed factor)")
        return [row(ratio_metric, math.nan, FAILED, why), row(changes_metric, math.nan, FAILED, why)]
    compared = [c for c in comparisons if math.isfinite(c.allowed)]
    changes = [c for c in comparisons if c.verdict in (STATUS_CHANGED, MISSING)]
    at_threshold = [c for c in comparisons if c.verdict == AT_THRESHOLD]
    apart = [c for c in comparisons if c.verdict == NOT_COMPARABLE]
    notes = []
    if at_threshold:
        notes.append(f"{len(at_threshold)} status change(s) within rounding of a threshold (the ulp-perturbed runs "
                     f"change them too, or the value is at the rounding floor): {_listed(at_threshold)}")
    if apart:
        notes.append(f"not comparable: {', '.join(c.key[3] for c in apart)} ({apart[0].detail_transformed})")
    if changes or any(c.verdict == VALUE_DIFFERS for c in compared):
        notes += [f"known: {constant}" for constant in constants_exposed(engine, kind, transform)]
    tail = "".join(f"; {n}" for n in notes)
    if compared:
        worst = max(compared, key=lambda c: c.ratio)
        ratio = row(ratio_metric, worst.ratio, OK, f"transform {text}: worst {_worst(worst)}{tail}")
    else:
        ratio = row(ratio_metric, math.nan, NOT_AVAILABLE, f"transform {text}: no metric measured (ok) in both runs"
                    + tail)
    if not compared and not changes and not at_threshold and not any(OK in (c.status, c.status_transformed)
                                                                      for c in comparisons):
        # nothing measured in either run (every row n/a or failed alike): no status could change, nothing to count
        return [ratio, row(changes_metric, math.nan, NOT_AVAILABLE,
                           f"transform {text}: no metric measured (ok) in either run, every status unchanged{tail}")]
    listed = f": {_listed(changes)}" if changes else ""
    return [ratio, row(changes_metric, float(len(changes)), OK,
                       f"transform {text}: {len(changes)} status change(s) rounding does not explain{listed}{tail}")]


def _worst(c: RowComparison) -> str:
    return (f"{c.key[3]} {c.value:.6g} vs {c.value_transformed:.6g} {c.unit} in the scene's units (|difference| "
            f"{c.difference:.3g}, allowed {c.allowed:.3g}: ulp spread {c.spread:.3g} x {SPREAD_FACTOR:g}, "
            f"{ROUNDING_RTOL:g} x value or the rounding allowance)")


def _listed(comparisons: list[RowComparison]) -> str:
    shown = "; ".join(f"{c.key[3]} {c.status or '(none)'} -> {c.status_transformed or '(none)'}"
                      + (f" ({one_line(c.detail_transformed, DETAIL_LIMIT)})" if c.detail_transformed else "")
                      for c in comparisons[:CHANGES_LISTED])
    more = len(comparisons) - CHANGES_LISTED
    return shown + (f"; and {more} more" if more > 0 else "")
