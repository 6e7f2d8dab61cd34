"""``simparity bench``'s joint motion (issue #28): simulated copy-steps per second of the falling arms (the iiwa, the
UR5 and the Panda from their scenes' seeded random pose, no damping, no torque), core's RK4 batched over B copies
against MuJoCo's and Pinocchio's RK4 at the same dt, at equal accuracy.

Copies: copy 0 starts at the scene's pose, copy k > 0 at that pose plus seeded normal noise of
:data:`PERTURBATION` rad per joint (the scene's qdot0, zero). Each engine's ``run`` of the B copies is timed (the
trajectory it records included):

- core: its ``rk4``, every copy in one NumPy batch, on one BLAS thread (:mod:`comparisons.bench.blas`, as the
  runner's workers);
- MuJoCo: its ``rk4`` (``mj_RungeKutta``), the B copies as B rollouts of ONE ``mujoco.rollout`` call on the calling
  thread (one ``MjData``, the adapter's path). ``mujoco.rollout.Rollout(nthread=k)`` with k ``MjData`` would split the
  copies over k threads; it is not used, for a like-for-like comparison with core's one batch;
- Pinocchio: its ``rk4`` (4 ``pin.aba`` and 4 ``pin.integrate`` per step), the harness's Python loop over the copies,
  one after the other: its time per copy-step does not depend on B, so it is timed up to :data:`PER_COPY_MAX_BATCH`
  copies only (10,000 copies would repeat B = 100's number; the row gives the call's estimate);
- PyBullet: its only integrator, semi-implicit Euler (first order: NOT at equal accuracy, its error is shown), the
  copies as bodies of one world, up to :data:`PER_COPY_MAX_BATCH` copies (Bullet's cost per copy grows with B).

Equal accuracy: on the first :data:`ERROR_COPIES` copies over :data:`ERROR_STEPS` steps, every engine's largest
joint-angle error against Pinocchio's DOP853 (rtol = atol = 1e-13) and its largest difference to Pinocchio's RK4:
the RK4s are the same scheme on the same dynamics, so they differ by rounding only.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from simparity.comparisons.bench.rows import Meter
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes import library
from simparity.core.model.scenes.joint_motion import JointMotionScene

ARMS = ("iiwa-falling", "ur5-falling", "panda-falling")
"""The built-in falling arms the bench times."""
ENGINES = (("core", "rk4"), ("mujoco", "rk4"), ("pinocchio", "rk4"), ("pybullet", "euler"))
"""(engine, integrator) timed; the first is the one the ratios divide by."""
REFERENCE = ("pinocchio", "dop853")
"""The tight solve each engine's joint angles are compared with."""
SAME_SCHEME = ("pinocchio", "rk4")
"""The engine whose RK4 every other is differenced with (the same scheme: rounding apart, they agree)."""
NOTES = {"core": "one NumPy batch", "mujoco": "one mujoco.rollout call, 1 thread",
         "pinocchio": "harness loop of pin.aba, copy by copy",
         "pybullet": "copies in one world; first order, not at equal accuracy"}
DT = 0.002
"""[s] The time step of every run (the falling arms' second step, of 4, 2, 1 and 0.5 ms)."""
SEED = 28
PERTURBATION = 0.1
"""[rad] Standard deviation of the seeded noise added to the scene's pose for copies 1, 2, ..."""
COPY_STEPS = 100_000
"""Copy-steps aimed at per timed call (steps = this / B, within :data:`MIN_STEPS`..:data:`MAX_STEPS`)."""
MIN_STEPS, MAX_STEPS = 10, 20
LARGE_CALL = 50_000
"""Copy-steps from which a call (a second or more) is timed once after its warm-up, not :data:`REPEATS` times."""
REPEATS = 3
PER_COPY_MAX_BATCH = 100
"""Largest B of the engines of :data:`NOT_BATCHED`."""
NOT_BATCHED = {
    "pinocchio": ("steps the copies one by one from Python, so its time per copy-step is flat in B (the largest "
                  "measured B's rate)", "would take"),
    "pybullet": ("steps its copies in one world whose cost per copy grows with B (12-14x one body's at B = 300, "
                 "references/pybullet/joint_motion.py)", "would take more than"),
}
"""Engines timed up to :data:`PER_COPY_MAX_BATCH` copies: (why, how the larger call compares with its estimate)."""
ERROR_COPIES = 2
"""Copies of the equal-accuracy run (the scene's pose and one perturbation: copies are independent, so the error
does not depend on B)."""
ERROR_STEPS = 200
"""Steps (0.4 s at :data:`DT`) of the equal-accuracy run."""
PROFILE_STEPS = 10

SECTION, ACCURACY_SECTION = "joint_motion", "joint_motion_accuracy"
UNIT = "us/copy-step"


def copies(scene: JointMotionScene, count: int, n_steps: int) -> JointMotionScene:
    """The scene from ``count`` initial states for ``n_steps`` steps of :data:`DT`: its own first, then seeded
    perturbations of it (module docstring)."""
    rng = np.random.default_rng(SEED)
    q0 = np.repeat(np.asarray(scene.q0)[:1], count, axis=0)
    q0[1:] += rng.normal(0.0, PERTURBATION, size=q0[1:].shape)
    qdot0 = np.repeat(np.asarray(scene.qdot0)[:1], count, axis=0)
    return scene.starting_from(q0, qdot0, n_steps * DT)


def steps_per_call(batch: int) -> int:
    """Steps of a timed call at ``batch`` copies (about :data:`COPY_STEPS` copy-steps)."""
    return int(min(MAX_STEPS, max(MIN_STEPS, COPY_STEPS // batch)))


def _max_difference(q: np.ndarray, other: np.ndarray) -> float:
    """[rad] Largest |q - other| over samples, copies and joints ((T, B, n) each)."""
    return float(np.max(np.abs(q - other)))


def accuracy(scene: JointMotionScene) -> dict[tuple[str, str], tuple[float, float] | str]:
    """Per (engine, integrator) of :data:`ENGINES`: (largest joint-angle error against :data:`REFERENCE`, largest
    difference to :data:`SAME_SCHEME`) [rad] on :data:`ERROR_COPIES` copies over :data:`ERROR_STEPS` steps, or why
    the engine could not run."""
    small = copies(scene, ERROR_COPIES, ERROR_STEPS)
    engine, integrator = REFERENCE
    truth = make_engine(engine).build_joint_motion(small, integrator, DT).run(ERROR_STEPS).q
    runs: dict[tuple[str, str], np.ndarray | str] = {}
    for engine, integrator in dict.fromkeys(ENGINES + (SAME_SCHEME,)):
        try:
            runs[engine, integrator] = make_engine(engine).build_joint_motion(small, integrator, DT).run(ERROR_STEPS).q
        except Exception as err:  # noqa: BLE001 - an engine that cannot: its rows say why
            runs[engine, integrator] = f"n/a: {err}"
    same = runs[SAME_SCHEME]
    out: dict[tuple[str, str], tuple[float, float] | str] = {}
    for key in ENGINES:
        q = runs[key]
        out[key] = q if isinstance(q, str) else (
            _max_difference(q, truth), math.nan if isinstance(same, str) else _max_difference(q, same))
    return out


def _timed(engine: str, integrator: str, scene: JointMotionScene, batch: int, median_time) -> tuple[float, str, Meter]:
    """(us per copy-step, note, the measurement's load and CPU time) of the engine's ``run`` of ``batch`` copies;
    ``median_time(fn, repeats)`` -> s."""
    steps = steps_per_call(batch)
    sim = make_engine(engine).build_joint_motion(copies(scene, batch, steps), integrator, DT)
    with Meter() as meter:
        seconds = median_time(lambda: sim.run(steps), 1 if batch * steps >= LARGE_CALL else REPEATS)
    return seconds / (batch * steps) * 1e6, f"{NOTES.get(engine, '')}; {steps} steps per call", meter


def _skipped(engine: str, batch: int, measured: dict[int, float]) -> str:
    """Why an engine of :data:`NOT_BATCHED` is not timed at ``batch`` copies, with the call its largest measured B
    predicts."""
    why, compared = NOT_BATCHED[engine]
    if not measured:
        return f"n/a: not timed above B = {PER_COPY_MAX_BATCH}: {engine} {why}"
    largest, steps = max(measured), steps_per_call(batch)
    predicted = measured[largest] * 1e-6 * batch * steps
    return (f"n/a: not timed above B = {PER_COPY_MAX_BATCH}: {engine} {why}; {batch:,} copies x {steps} steps "
            f"{compared} ~{predicted:.0f} s per call at its B = {largest:,} rate")


def joint_motion_rows(batches: list[int], median_time, row, say: Callable[[str], None]) -> list:
    """Bench rows (``row(section, workload, engine, method, batch, value, unit, accuracy, accuracy_unit, note)``) of
    every arm x engine x batch in us per copy-step (accuracy: the error against DOP853 [rad]), and per arm x engine
    an :data:`ACCURACY_SECTION` row: the error against DOP853 (value) and the difference to Pinocchio's RK4
    (accuracy) [rad]. ``median_time(fn, repeats)`` -> seconds (after a warm-up call)."""
    rows = []
    for scene in library.load(list(ARMS)):
        errors = accuracy(scene)
        for (engine, integrator), found in errors.items():
            error, difference = (math.nan, math.nan) if isinstance(found, str) else found
            rows.append(row(ACCURACY_SECTION, scene.name, engine, integrator, ERROR_COPIES, error, "rad vs dop853",
                            difference, "rad vs pinocchio rk4", found if isinstance(found, str) else
                            f"{ERROR_STEPS} steps of {DT:g} s, {ERROR_COPIES} copies"))
            say(f"  {scene.name:<14} {engine:<9} {integrator:<6} error vs dop853 {error:.2e} rad, "
                f"difference to pinocchio rk4 {difference:.1e} rad")
        for engine, integrator in ENGINES:
            found = errors[engine, integrator]
            measured: dict[int, float] = {}
            for batch in batches:
                meter = None
                if isinstance(found, str):
                    value, note = math.nan, found
                elif engine in NOT_BATCHED and batch > PER_COPY_MAX_BATCH:
                    value, note = math.nan, _skipped(engine, batch, measured)
                else:
                    try:
                        value, note, meter = _timed(engine, integrator, scene, batch, median_time)
                        measured[batch] = value
                    except Exception as err:  # noqa: BLE001 - a run that fails at this size: its row says why
                        value, note = math.nan, f"n/a: {err}"
                error = math.nan if isinstance(found, str) else found[0]
                measured_row = row(SECTION, scene.name, engine, integrator, batch, value, UNIT, error, "rad", note)
                rows.append(meter.stamp(measured_row) if meter else measured_row)
                say(f"  {scene.name:<14} {engine:<9} {integrator:<6} B={batch:<6} {value:10.3f} us/copy-step "
                    f"({1e6 / value:,.0f} copy-steps/s) {note}")
    return rows


def _cell(value: float, digits: str = ".3g") -> str:
    return format(value, digits) if math.isfinite(value) else "n/a"


def markdown_lines(rows: list) -> list[str]:
    """The BENCHMARKS.md section: equal accuracy, time per copy-step with copy-steps per second, and core's
    throughput over each engine's at each B (and at core's largest B against each engine's best B)."""
    timed = [r for r in rows if r.section == SECTION]
    if not timed:
        return []
    batches = sorted({r.batch for r in timed})
    lines = [f"## Joint motion: falling arms (us per copy-step at dt {DT:g} s, copy-steps per second)", "",
             "Each engine's `run` of B copies (the scene's random pose and B - 1 seeded perturbations of it), the "
             "recorded trajectory included. core: one NumPy batch on one BLAS thread. "
             "MuJoCo: one `mujoco.rollout` call on ONE thread (one MjData; `mujoco.rollout.Rollout(nthread=k)` could "
             "split the copies over k threads: not used). Pinocchio: the harness's Python loop of `pin.aba` copy by "
             f"copy, flat in B, timed up to B = {PER_COPY_MAX_BATCH}. PyBullet: semi-implicit Euler, its copies in one "
             "world: first order, not at equal accuracy.", "",
             f"Equal accuracy ({ERROR_STEPS} steps, {ERROR_COPIES} copies): largest joint-angle error against "
             "Pinocchio's DOP853 at 1e-13, and largest difference to Pinocchio's RK4.", "",
             "| arm | engine | integrator | error vs DOP853 [rad] | difference to Pinocchio rk4 [rad] |",
             "|---|---|---|---|---|"]
    for r in rows:
        if r.section == ACCURACY_SECTION:
            lines.append(f"| {r.workload} | {r.engine} | {r.method} | {_cell(r.value, '.2e')} | "
                         f"{_cell(r.accuracy, '.1e')} |")
    lines += ["", "| arm | engine | integrator | " + " | ".join(f"B = {b:,}" for b in batches) + " |",
              "|---|---|---|" + "---|" * len(batches)]
    cells = {(r.workload, r.engine, r.method, r.batch): r for r in timed}
    series = list(dict.fromkeys((r.workload, r.engine, r.method) for r in timed))
    for arm, engine, method in series:
        values = [cells[arm, engine, method, b].value for b in batches]
        lines.append(f"| {arm} | {engine} | {method} | " + " | ".join(
            f"{v:.3g} ({1e6 / v:,.0f}/s)" if math.isfinite(v) else "n/a" for v in values) + " |")
    notes = [f"{r.workload} {r.engine} B = {r.batch:,}: {r.note}" for r in timed
             if r.note.startswith("n/a") or r.batch == batches[-1]]
    lines += [""] + [f"- {n}" for n in notes] + ([""] if notes else [])
    core_engine, core_method = ENGINES[0]
    lines += [f"Throughput ratio {core_engine} {core_method} / engine (the engine's time per copy-step over core's; "
              "> 1: core is faster), at each B and at core's largest B against the engine's best B:", "",
              "| arm | engine | integrator | " + " | ".join(f"B = {b:,}" for b in batches) + " | best vs best |",
              "|---|---|---|" + "---|" * (len(batches) + 1)]
    for arm, engine, method in series:
        if (engine, method) == (core_engine, core_method):
            continue
        core = {b: cells[arm, core_engine, core_method, b].value for b in batches}
        mine = {b: cells[arm, engine, method, b].value for b in batches}
        best = min((v for v in mine.values() if math.isfinite(v)), default=math.nan)
        lines.append(f"| {arm} | {engine} | {method} | " + " | ".join(_cell(mine[b] / core[b]) for b in batches)
                     + f" | {_cell(best / core[batches[-1]])} |")
    return lines + [""]


def profile_case(batch: int) -> tuple[str, Callable[[], object]]:
    """(title, call) of one cProfile of core's RK4 on ``batch`` copies of the first arm, :data:`PROFILE_STEPS`
    steps."""
    scene = copies(library.load([ARMS[0]])[0], batch, PROFILE_STEPS)
    sim = make_engine(ENGINES[0][0]).build_joint_motion(scene, ENGINES[0][1], DT)
    return (f"core rk4 joint motion, {batch:,} {ARMS[0]} copies, {PROFILE_STEPS} steps",
            lambda: sim.run(PROFILE_STEPS))
