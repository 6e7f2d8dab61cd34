"""The runner: one row per metric and case; failures, divergence and n/a are rows, never lost."""

import dataclasses
import math

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.metrics import DYNAMICS_METRICS, KINEMATICS_METRICS, ORDER_METRICS, dynamics_metrics
from simparity.comparisons.execute.case_cost import BATCH_STEPS
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.scenes.profiles import quick
from simparity.core.model.engine import Simulation, Support
from simparity.core.inhouse import InHouseEngine
from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE, OK
from tests.helpers import builtin


class _Crashing(InHouseEngine):
    name = "crashing"

    def build_dynamics(self, scene, integrator, dt):
        raise RuntimeError("boom")

    def build_kinematics(self, chain):
        raise RuntimeError("boom")


def _rewritten(rewrite, name: str = "rewritten"):
    """An in-house engine (rk4 only) whose trajectories are ``rewrite(trajectory)`` instead of their own."""

    class _Engine(InHouseEngine):
        def integrators(self):
            return ("rk4",)

        def build_dynamics(self, scene, integrator, dt):
            sim = super().build_dynamics(scene, integrator, dt)

            class _Sim(Simulation):
                detail = "test"

                def run(self, n):
                    return rewrite(sim.run(n))

            return _Sim()

    _Engine.name = name
    return _Engine()


def _tampered(name: str, field: str, value: float):
    """An in-house engine (rk4 only) whose trajectories get ``field`` at the last sample set to ``value``."""

    def rewrite(traj):
        values = {f: np.array(getattr(traj, f)) for f in ("position_world", "quat_wxyz", "velocity_world",
                                                          "angular_velocity_world")}
        values[field][-1] = value
        return type(traj)(traj.times, **values)

    return _rewritten(rewrite, name)


class _Refusing(InHouseEngine):
    name = "refusing"

    def supports_dynamics(self, scene, integrator):
        return Support.no("cannot, for a reason")


SHORT_RUN_STEPS = 2 * BATCH_STEPS
"""Steps of a case whose rows, not its numerics, are under test: more than the batched timing takes."""


class _Uncounted(InHouseEngine):
    name = "uncounted"

    def integrators(self):
        return ("rk4",)

    def stages(self, integrator):
        return None


def _cases(rows):
    return {(r.engine, r.integrator, r.dt): r.status for r in rows}


def _coarsest(scene):
    """``scene`` at its coarsest time step alone (lecture-projectile: 180 steps instead of the ladder's 2,700): for the
    tests of what a case's rows say, which every time step says alike; the ladder's own tests keep every step."""
    return dataclasses.replace(scene, dts=scene.dts[:1])


@pytest.mark.slow
def test_each_case_has_every_metric_and_crashes_do_not_stop_the_run():
    """A crashing engine gets failed rows with the error; the engines after it still run."""
    scene = _coarsest(builtin("lecture-projectile"))
    rows = run_scene(scene, [_Crashing(), _tampered("diverging", "position_world", np.nan), _Refusing(), make_engine("mujoco")], make_engine, repeats=1)
    per_case = {}
    for r in rows:
        if not math.isnan(r.dt):
            per_case.setdefault((r.engine, r.integrator, r.dt), []).append(r.metric)
    assert all(sorted(m) == sorted(dynamics_metrics(scene)) for m in per_case.values())
    rows = [r for r in rows if not math.isnan(r.dt)]
    statuses = _cases(rows)
    crashing = {s for (e, _, _), s in statuses.items() if e == "crashing"}
    assert FAILED in crashing and crashing <= {FAILED, NOT_AVAILABLE}  # n/a: rules the scene is outside of
    assert {s for (e, _, _), s in statuses.items() if e == "diverging"} == {DIVERGED}
    assert {s for (e, _, _), s in statuses.items() if e == "refusing"} == {NOT_AVAILABLE}
    assert {s for (e, _, _), s in statuses.items() if e == "mujoco"} == {OK}
    crash = next(r for r in rows if r.engine == "crashing")
    assert "RuntimeError: boom" in crash.detail
    assert all(math.isnan(r.value) for r in rows if r.status in (FAILED, NOT_AVAILABLE))
    assert any(r.metric == "time_per_step" and r.value > 0 for r in rows if r.status == DIVERGED)


@pytest.mark.slow
def test_missing_reference_keeps_timings_and_says_why():
    """If the reference cannot do the scene, errors are n/a with the reason and timings are still measured."""
    scene = _coarsest(builtin("lecture-projectile"))
    rows = run_scene(scene, [make_engine("mujoco")], lambda name: _Refusing(), repeats=1)
    timing = [r for r in rows if r.metric == "time_per_step"]
    errors = [r for r in rows if r.metric in DYNAMICS_METRICS and "_error_" in r.metric]
    assert all(r.status == OK and r.value > 0 for r in timing)
    assert all(r.status == NOT_AVAILABLE and "cannot, for a reason" in r.detail for r in errors)


def test_every_dynamics_case_has_its_cost_and_its_batched_timing():
    """Issue #26: evaluations_per_second is the declared stages over dt, exactly; core and MuJoCo time copies of the
    scene stepped together; an engine that cannot batch, or declares no stage count, has n/a rows saying why."""
    scene = quick(builtin("dzhanibekov"))
    scene = dataclasses.replace(scene, dts=scene.dts[:1], duration=SHORT_RUN_STEPS * scene.dts[0],
                                integrators=("rk4", "euler"))
    engines = [make_engine(name) for name in ("core", "mujoco", "pybullet", "pinocchio")]
    rows = run_scene(scene, engines + [_Uncounted(), _rewritten(lambda traj: traj, "unbatched")], make_engine,
                     repeats=0)
    cost = {(r.engine, r.integrator): r for r in rows if r.metric == "evaluations_per_second"}
    batched = {(r.engine, r.integrator): r for r in rows if r.metric == "time_per_step_batched"}
    for engine in engines:
        for integrator in set(engine.integrators()) & {"rk4", "euler"}:
            row = cost[(engine.name, integrator)]
            assert row.status == OK and row.unit == "1/s" and row.value == engine.stages(integrator) / scene.dts[0]
    assert cost[("core", "rk4")].value == 4 / scene.dts[0] and cost[("mujoco", "euler")].value == 1 / scene.dts[0]
    for case in (("core", "rk4"), ("mujoco", "rk4"), ("mujoco", "euler")):
        assert batched[case].status == OK and math.isfinite(batched[case].value) and batched[case].value > 0
        assert batched[case].unit == "s"
    for case, reason in ((("pybullet", "euler"), "pybullet steps one world per stepSimulation call"),
                         (("pinocchio", "rk4"), "steps pinocchio's aba one body at a time"),
                         (("unbatched", "rk4"), "declares no batched stepping (Simulation.batched)")):
        assert batched[case].status == NOT_AVAILABLE and reason in batched[case].detail
    assert cost[("unbatched", "rk4")].status == OK
    uncounted = cost[("uncounted", "rk4")]
    assert uncounted.status == NOT_AVAILABLE and uncounted.detail == "uncounted declares no stage count for rk4 " \
        "(Engine.stages)"


def test_kinematics_rows_and_reference_marking():
    """Kinematics cases give every kinematics metric; the reference engine's rows say it is the reference."""
    scene = builtin("lecture-planar-arm")
    rows = run_scene(scene, [make_engine("analytic"), make_engine("core"), _Crashing()], make_engine, repeats=1)
    assert {r.metric for r in rows if r.engine == "core"} == set(KINEMATICS_METRICS)
    assert all(r.detail.startswith("this is the reference") for r in rows if r.engine == "analytic")
    assert {r.status for r in rows if r.engine == "crashing"} == {FAILED}
    assert all(math.isnan(r.dt) and r.integrator == "" for r in rows)


@pytest.mark.slow
def test_order_rows_fit_the_time_step_ladder():
    """With several time steps every engine and integrator gets an order row; Euler's is 1 on the projectile."""
    scene = builtin("lecture-projectile")
    rows = run_scene(scene, [make_engine("mujoco")], make_engine, repeats=1)
    orders = {(r.integrator, r.metric): r for r in rows if r.metric in ORDER_METRICS}
    assert {i for i, _ in orders} == set(make_engine("mujoco").integrators())
    euler = orders[("euler", "order_position")]
    assert euler.status == OK and abs(euler.value - 1.0) < 1e-6  # error g t dt / 2 is exactly linear in dt
    exact = orders[("rk4", "order_position")]
    assert exact.status == NOT_AVAILABLE and "rounding floor" in exact.detail  # RK4 is exact here


def test_blown_up_but_finite_run_is_diverged():
    """A spin that explodes while staying finite (PyBullet caps it at 1e9 rad/s) is diverged; RK4 is not."""
    scene = builtin("fast-spinner")
    rows = run_scene(scene, [make_engine("pybullet"), make_engine("mujoco")], make_engine, repeats=1)
    spin = {(r.engine, r.integrator, r.dt): r for r in rows if r.metric == "angular_velocity_error_max"}
    for dt in scene.dts:
        assert spin[("pybullet", "euler", dt)].status == DIVERGED
        assert "clamped a velocity" in spin[("pybullet", "euler", dt)].detail  # PyBullet's cap, 1e9 rad/s
    assert spin[("mujoco", "rk4", 0.005)].status == OK


@pytest.mark.slow
def test_finite_blow_up_is_diverged_by_the_runner_bound():
    """A finite trajectory faster than the scene's forces allow (DIVERGENCE_MARGIN x the bound) is diverged."""
    scene = _coarsest(builtin("lecture-projectile"))

    rows = run_scene(scene, [_tampered("exploding", "velocity_world", 1e12)], make_engine, repeats=1)
    assert {r.status for r in rows if not math.isnan(r.dt)} == {DIVERGED}
    assert "speed of point reached" in rows[0].detail and "its forces allow" in rows[0].detail


def _retimed(times_of):
    return lambda traj: dataclasses.replace(traj, times=times_of(np.array(traj.times)))


@pytest.mark.slow
@pytest.mark.parametrize("rewrite, problem", [
    (_retimed(lambda t: np.where(np.arange(len(t)) == 3, np.nan, t)), "sample 3 is at t = nan"),
    (_retimed(lambda t: t * 2.0), "sample 1 is at t = "),
    (_retimed(lambda t: t + 0.5 * (t[1] - t[0])), "sample 0 is at t = "),
    (lambda traj: type(traj)(*(np.array(getattr(traj, f.name))[1:] for f in dataclasses.fields(traj))),
     "its times have shape (180,) (expected (181,): the initial state and 180 steps)"),
])
def test_a_trajectory_off_the_time_grid_fails_instead_of_being_measured(rewrite, problem):
    """Samples that are not at k * dt (NaN, twice the step, half a step late, the initial state left out) would be
    compared with the reference's samples at other times: every case fails, naming the first bad sample."""
    scene = _coarsest(builtin("lecture-projectile"))
    rows = run_scene(scene, [_rewritten(rewrite)], make_engine, repeats=1)
    cases = [r for r in rows if not math.isnan(r.dt)]
    assert cases and {r.status for r in cases} == {FAILED}
    assert all("does not sample the scene" in r.detail for r in cases)
    assert problem in cases[0].detail


@pytest.mark.slow
def test_a_trajectory_of_complex_values_fails_instead_of_losing_its_imaginary_part():
    """NumPy casts complex to real with no more than a warning: a state with an imaginary part is refused."""
    def complex_positions(traj):
        values = {f.name: np.array(getattr(traj, f.name)) for f in dataclasses.fields(traj)}
        values["position_world"] = values["position_world"] + 1e-3j
        return type(traj)(**values)

    rows = run_scene(_coarsest(builtin("lecture-projectile")), [_rewritten(complex_positions)], make_engine, repeats=1)
    cases = [r for r in rows if not math.isnan(r.dt)]
    assert cases and {r.status for r in cases} == {FAILED}
    assert all("complex values where real ones (float64) are expected" in r.detail for r in cases)


@pytest.mark.slow
def test_energy_drift_without_energy_is_not_available():
    """A body dropped from rest at the potential's zero has E(0) = 0: drift is measured against its kinetic energy."""
    from dataclasses import replace

    scene = _coarsest(builtin("lecture-projectile"))
    body = replace(scene.bodies[0], velocity_world=np.zeros(3))
    rows = run_scene(replace(scene, bodies=(body,)), [make_engine("mujoco")], make_engine, repeats=1)
    drift = [r for r in rows if r.metric == "energy_drift_max"]
    assert all(r.status == OK and math.isfinite(r.value) for r in drift)
    still = replace(scene, bodies=(body,), forces=replace(scene.forces, gravity_world=None))
    rows = run_scene(still, [make_engine("mujoco")], make_engine, repeats=1)
    drift = [r for r in rows if r.metric == "energy_drift_max"]
    assert all(r.status == NOT_AVAILABLE and "nothing to measure" in r.detail for r in drift)


@pytest.mark.slow
def test_warnings_raised_in_a_case_go_into_its_rows_not_the_console(recwarn):
    """An engine that warns (here: NumPy overflow) keeps the console clean; the warning is in the case's detail."""
    import warnings as _warnings

    class _Warning(InHouseEngine):
        def build_dynamics(self, scene, integrator, dt):
            sim = super().build_dynamics(scene, integrator, dt)
            stream = sim.stream

            def noisy(n, samples_per_piece):
                _warnings.warn("overflow encountered in multiply", RuntimeWarning)
                yield from stream(n, samples_per_piece)

            sim.stream = noisy
            return sim

    _Warning.name = "warning"
    scene = dataclasses.replace(_coarsest(builtin("lecture-projectile")), integrators=("explicit_euler", "rk4"))
    rows = run_scene(scene, [_Warning()], make_engine, repeats=1)
    per_dt = [r for r in rows if not math.isnan(r.dt)]
    assert per_dt and all("warnings: RuntimeWarning: overflow encountered in multiply" in r.detail for r in per_dt)
    assert len(recwarn) == 0


def _drop_scene(**contact):
    """A particle dropped 0.2 m onto z = 0 with restitution 0.5 (a contact scene built in code)."""
    from simparity.core.model.scenes.bodies import Forces, RigidBody
    from simparity.core.model.scenes.contact import Contact, Material, Plane, Shape
    from simparity.core.model.scenes.dynamics import DynamicsScene

    body = RigidBody("particle", 1.0, np.eye(3) * 1e-3, np.array([0.0, 0.0, 0.2]), np.array([1.0, 0, 0, 0]),
                     np.zeros(3), np.zeros(3))
    settings = dict(methods=("backup", "penalty"), rest_speed=0.01, penalty_stiffness=1e4, penalty_damping=43.1)
    settings.update(contact)
    return DynamicsScene("drop", "-", "analytic", (body,), Forces(gravity_world=np.array([0.0, 0.0, -9.81])), 0.5,
                         (0.0025, 0.005, 0.01), integrators=("backup", "penalty_semi_implicit_euler"),
                         contact=Contact((Plane((0, 0, 1), 0.0, "floor"),), (Shape("point"),), ((Material(0.5),),),
                                         **settings))


CONTACT_EXACT = 1e-12  # [m] backing up time is exact for a dropped particle; rounding of O(1) values is ~1e-15


@pytest.mark.slow
def test_a_contact_scene_gets_contact_metrics_na_orders_and_a_stability_limit():
    """Issue #10: every case of a contact scene has the contact metrics; observed orders are n/a (impacts make the
    error jump with dt); the penalty integrator gets its measured stability limit; backing up time is exact."""
    scene = _drop_scene()
    rows = run_scene(scene, [make_engine("core"), make_engine("analytic")], make_engine, repeats=0)
    per_case = {}
    for r in rows:
        per_case.setdefault((r.engine, r.integrator, r.dt), set()).add(r.metric)
    for (engine, integrator, dt), metrics in per_case.items():
        if not math.isnan(dt):
            assert set(dynamics_metrics(scene)) <= metrics, (engine, integrator, dt)
            assert {"restitution_measured", "penetration_max", "impact_time_error"} <= metrics
    orders = [r for r in rows if r.metric in ORDER_METRICS]
    assert orders and all(r.status == NOT_AVAILABLE and r.detail.startswith("contact") for r in orders)
    limits = [r for r in rows if r.metric == "stable_dt_max"]
    assert [(r.engine, r.integrator) for r in limits] == [("core", "penalty_semi_implicit_euler")]
    assert limits[0].status == OK and limits[0].value > 0
    backup = {r.metric: r for r in rows if r.integrator == "backup" and r.dt == 0.01}
    assert backup["position_error_max"].value <= CONTACT_EXACT
    assert backup["penetration_max"].value <= CONTACT_EXACT
    assert backup["restitution_measured"].value == pytest.approx(0.5, abs=CONTACT_EXACT)


def test_core_runs_only_contact_methods_on_contact_scenes_and_none_elsewhere():
    """A contact scene's cases are core's contact methods (not its free-body integrators); a scene without
    planes has no contact method among its cases."""
    core = make_engine("core")
    contact = core.scene_integrators(_drop_scene())  # methods backup and penalty, not act_after
    schemes = ("explicit_euler", "semi_implicit_euler", "midpoint", "average_velocity", "rk4")
    assert set(contact) == {"backup"} | {f"penalty_{s}" for s in schemes}
    free = core.scene_integrators(builtin("lecture-projectile"))
    assert "rk4" in free and not {"backup", "act_after"} & set(free)
    assert not any(name.startswith("penalty_") for name in free)
