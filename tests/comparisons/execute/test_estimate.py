"""Issue #39: a run that will take long says so before its cases start: how long its cases are modelled to take on its
workers, and which case is modelled past the per-case time limit (a 128-joint chain's joint-space dynamics by the
lecture's O(n^3) route ran past 15 minutes at 20 states and was killed). No wall time is asserted: the model is."""

from __future__ import annotations

import pytest

from simparity.comparisons.engines.registry import EngineSet, make_engine
from simparity.comparisons.pipeline import session as session_module
from simparity.comparisons.execute.estimate import RunEstimate, duration, stability_steps
from simparity.comparisons.execute.execution import estimate
from simparity.comparisons.execute.isolation import CaseLimits
from simparity.comparisons.measure.stability import stable_dt_max
from simparity.comparisons.pipeline.session import ISOLATED, Execution, Session
from simparity.comparisons.scenes.library import load
from simparity.comparisons.scenes.profiles import quick

CASE_LIMIT_SECONDS = 900.0
"""[s] The default per-case time limit (``--case-timeout``)."""

CHAIN_JOINTS = 128
"""Joints of the big chain: the most ``--max-joints`` allows by default."""

SMALL_JOINTS = 8
"""Joints of a chain whose every case is far inside the limit."""


def _chain_file(tmp_path, joints: int):
    """A joint-dynamics scene of a chain of ``joints`` uniform links (0.05 m, 0.1 kg) about alternating axes."""
    text = ['[scene]', f'name = "chain-{joints}-dynamics"', 'kind = "joint_dynamics"', 'reference = "pinocchio"',
            '[chain]', 'end_effector = "tip"', 'end_effector_xyz = [0.05, 0.0, 0.0]']
    for i in range(joints):
        text += ['[[chain.joint]]', f'name = "j{i}"', 'type = "revolute"',
                 f'axis = {[0.0, 0.0, 1.0] if i % 2 == 0 else [0.0, 1.0, 0.0]}',
                 f'origin_xyz = [{0.0 if i == 0 else 0.05}, 0.0, 0.0]', 'mass = 0.1', 'com_xyz = [0.025, 0.0, 0.0]',
                 'inertia = [[2e-06, 0.0, 0.0], [0.0, 2.1e-05, 0.0], [0.0, 0.0, 2.1e-05]]']
    text += ['[world]', 'gravity_world = [0.0, 0.0, -9.81]']
    path = tmp_path / f"chain-{joints}.toml"
    path.write_text("\n".join(text) + "\n", encoding="utf-8")
    return path


def _estimated(tmp_path, joints: int, workers: int = 2) -> RunEstimate:
    engines = EngineSet(("core", "pinocchio"))
    scenes = [quick(s, engines) for s in load([str(_chain_file(tmp_path, joints))], engines=engines)]
    return estimate(scenes, [make_engine(n) for n in engines.names], make_engine, workers)[1]


def test_the_estimate_is_said_before_any_case_starts(tmp_path, monkeypatch):
    """A session says its estimate, naming the case modelled past the per-case limit, before it hands a case on."""
    heard: list[str] = []
    said_when_cases_started: list[list[str]] = []

    def no_cases(*args, **kwargs):
        said_when_cases_started.append(list(heard))
        return iter(())

    monkeypatch.setattr(session_module, "run_scenes", no_cases)
    engines = EngineSet(("core",))
    scenes = load([str(_chain_file(tmp_path, CHAIN_JOINTS))], engines=engines)
    session = Session(scenes, engines, profile="quick", say=heard.append,
                      execution=Execution(ISOLATED, 2, CaseLimits(CASE_LIMIT_SECONDS, None)))
    session.run()
    [before] = said_when_cases_started
    [line] = [line for line in before if line.startswith("estimated ")]
    assert f"chain-{CHAIN_JOINTS}-dynamics core jacobian_sum" in line and "--case-timeout" in line


def test_a_big_chain_is_modelled_past_the_case_limit_by_its_o_n3_method_and_a_small_one_is_not(tmp_path):
    big, small = _estimated(tmp_path, CHAIN_JOINTS), _estimated(tmp_path, SMALL_JOINTS)
    assert big.costliest[1:] == ("core", "jacobian_sum") and big.costliest_seconds > CASE_LIMIT_SECONDS
    assert "past the per-case limit" in big.line(CASE_LIMIT_SECONDS)
    assert small.costliest_seconds < CASE_LIMIT_SECONDS and "past" not in small.line(CASE_LIMIT_SECONDS)
    assert big.cases == small.cases  # the same engines and methods: only the chain differs


def test_a_run_takes_at_least_its_costliest_group_whatever_the_workers(tmp_path):
    """A joint-dynamics scene is one group, run in one worker: more workers do not shorten it."""
    one, many = _estimated(tmp_path, CHAIN_JOINTS, workers=1), _estimated(tmp_path, CHAIN_JOINTS, workers=64)
    assert many.seconds == pytest.approx(one.seconds) and many.seconds >= many.costliest_seconds


@pytest.mark.parametrize("seconds, text", [(0.4, "0s"), (59.4, "59s"), (61, "1m01s"), (3600, "1h00m"),
                                           (7 * 3600 + 125, "7h02m")])
def test_durations_read_as_time(seconds, text):
    assert duration(seconds) == text


STABILITY_MODEL_FACTOR = 2.0
"""How far the modelled steps of a stability search may be from those it ran: the bisection's trials are modelled at
the scene's finest step, the limit being unknown before it is measured (13,725 counted, 18,000 modelled here)."""


@pytest.mark.slow  # one real stability search: ~5 s of CPU
def test_a_stability_search_is_modelled_at_the_steps_its_trials_run():
    """Issue #41: the quick profile's bouncing particle searched its penalty schemes' limits for 4 minutes at the end
    of a 10-minute run: modelled as one run of its ladder (1,000 steps), the group was planned last."""
    engines = EngineSet(("core",))
    [scene] = [quick(s, engines) for s in load(["lecture-bouncing-particle"], engines=engines)]
    counted: list[int] = []
    core = make_engine("core")

    class Counting:
        def build_dynamics(self, *args):
            simulation = core.build_dynamics(*args)

            class Counted:
                def run(self, steps: int):
                    counted.append(steps)
                    return simulation.run(steps)

            return Counted()

    assert stable_dt_max(scene, Counting(), "penalty_semi_implicit_euler").value > 0  # a limit found
    assert sum(counted) / STABILITY_MODEL_FACTOR <= stability_steps(scene) <= sum(counted) * STABILITY_MODEL_FACTOR
