"""Issue #38 section 3: a user's own chain in motion is checked, not only run.

On a joint-motion scene no bound names, a scheme whose order cannot be measured (its coarse steps on another orbit)
had only its status held: the gate failed a correct run as "unbounded" with 0 metrics outside their bounds. The
built-in engines of one kind of scheme compute one discretisation, so at one step their errors agree up to rounding:
each is held to the others (and a user's engine to them, by the cross-check), and that hold counts as a value bound.
"""

from __future__ import annotations

import sys

import pandas as pd
import pytest

from simparity.comparisons.cli.main import main
from simparity.comparisons.gate.check import UNBOUNDED_SHARE_MAX, check_table
from simparity.comparisons.gate.cross_check import JOINT_AGREEMENT_FACTOR, agreement_checks, held_series
from simparity.comparisons.engines.registry import ENGINE_NAMES
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.core.model.metric_catalogue import (
    END_EFFECTOR_ERROR_MAX, ENERGY_DRIFT_MAX, JOINT_ANGLE_ERROR_MAX, ORDER_JOINT_ANGLE,
)
from simparity.core.model.results import DIMENSIONLESS, NOT_AVAILABLE, OK, ROUNDING_FLOOR, SATURATED
from simparity.reports.store import read_run
from tests.mutation.catalogue import MUTANTS
from tests.mutation.copy_of_core import ENGINE_CLASS, PLUGIN_MODULE, CoreCopy, materialise

MARGIN = 1.5
"""How far over its bound the planted bug must be on at least one line: the engines of one kind agree to 0.1 %, an
explicit step under the semi-implicit name is 2 x off."""

SCENE = "my-arm-falling"
"""A scene name no shipped bound names: a user's own robot."""

SEMI = "semi_implicit_euler"
ERROR = 0.0623
"""A semi-implicit Euler error at one step, the same to rounding in every faithful engine."""

ENGINES = (("core", SEMI), ("mujoco", "euler_explicit_damping"), ("pinocchio", SEMI), ("pybullet", "euler"))
"""The built-in engines' semi-implicit Euler integrators on a chain."""


def _row(engine: str, integrator: str, metric: str, value: float, dt: float = 0.001, status: str = OK,
         flag: str = "", scheme: str = SEMI) -> dict:
    return dict(scene=SCENE, engine=engine, integrator=integrator, dt=dt, metric=metric, value=value,
                unit=DIMENSIONLESS, reference="pinocchio:dop853", status=status, detail="", flag=flag, scheme=scheme)


def _falling(values: dict[str, float] | None = None) -> list[dict]:
    """Every built-in's semi-implicit Euler rows at two steps: the joint angle saturated at the coarse one (no
    order), the end effector measured at both (``values``: the fine step's, by engine)."""
    rows = []
    for engine, integrator in ENGINES:
        value = (values or {}).get(engine, ERROR * (1 + 1e-9 * len(engine)))  # faithful: rounding apart
        rows += [_row(engine, integrator, JOINT_ANGLE_ERROR_MAX, 4.9, dt=0.002, status=NOT_AVAILABLE, flag=SATURATED),
                 _row(engine, integrator, END_EFFECTOR_ERROR_MAX, 2 * value, dt=0.002),
                 _row(engine, integrator, END_EFFECTOR_ERROR_MAX, value),
                 _row(engine, integrator, ENERGY_DRIFT_MAX, 0.1),
                 _row(engine, integrator, ORDER_JOINT_ANGLE, float("nan"), dt=float("nan"), status=NOT_AVAILABLE,
                      flag=SATURATED)]
    return rows


def test_faithful_built_ins_on_a_new_chain_agree_and_are_held_to_a_value():
    table = pd.DataFrame(_falling())
    assert agreement_checks(table, ENGINE_NAMES) == []
    result = check_table(table, load_tolerances())
    assert result.passed
    assert result.unbounded_series == []  # before: all 4 held only to their status, the gate failed as unbounded
    assert held_series(table, ENGINE_NAMES) == {(SCENE, e, i) for e, i in ENGINES}


def test_a_built_in_that_no_other_of_its_kind_agrees_with_is_named():
    table = pd.DataFrame(_falling({"core": 2.5 * ERROR}))
    found = agreement_checks(table, ENGINE_NAMES)
    assert sorted((v.engine, v.metric, v.dt) for v in found) == [("core", END_EFFECTOR_ERROR_MAX, dt) for dt in (0.001, 0.002)]
    assert "pinocchio" in found[0].reason and check_table(table, load_tolerances()).violations


def test_a_chain_s_energy_drift_is_held_alike_and_a_free_body_s_is_not():
    drifted = [dict(r, value=0.3) if r["engine"] == "core" and r["metric"] == ENERGY_DRIFT_MAX else r
               for r in _falling()]
    assert [(v.engine, v.metric) for v in agreement_checks(pd.DataFrame(drifted), ENGINE_NAMES)] == [
        ("core", ENERGY_DRIFT_MAX)]
    free = [r for r in drifted if r["metric"] == ENERGY_DRIFT_MAX]  # no joint errors: free bodies, held by bounds
    assert agreement_checks(pd.DataFrame(free), ENGINE_NAMES) == []


def test_two_built_ins_that_disagree_are_both_named_and_agreement_is_within_the_factor():
    two = [r for r in _falling({"core": ERROR, "pinocchio": 0.99 * JOINT_AGREEMENT_FACTOR * ERROR})
           if r["engine"] in ("core", "pinocchio")]
    assert agreement_checks(pd.DataFrame(two), ENGINE_NAMES) == []  # within the factor: agreement
    apart = [dict(r, value=1.02 * JOINT_AGREEMENT_FACTOR * ERROR) if r["engine"] == "pinocchio" and r["dt"] == 0.001
             and r["metric"] == END_EFFECTOR_ERROR_MAX else r for r in two]
    assert {v.engine for v in agreement_checks(pd.DataFrame(apart), ENGINE_NAMES)} == {"core", "pinocchio"}


def test_rounding_floors_truths_and_engines_alone_in_their_kind_hold_nothing():
    rows = [_row("core", SEMI, END_EFFECTOR_ERROR_MAX, 1e-15, flag=ROUNDING_FLOOR),
            _row("pinocchio", SEMI, END_EFFECTOR_ERROR_MAX, 1e-13),
            _row("pinocchio", "dop853", END_EFFECTOR_ERROR_MAX, 1e-12, scheme="adaptive"),
            _row("pinocchio", "dop853_coarse", END_EFFECTOR_ERROR_MAX, 1e-9, scheme="adaptive"),
            _row("mujoco", "implicit", END_EFFECTOR_ERROR_MAX, 0.07, scheme="implicit_velocity")]
    table = pd.DataFrame(rows)
    assert agreement_checks(table, ENGINE_NAMES) == [] and held_series(table, ENGINE_NAMES) == set()


def test_a_user_engine_held_by_the_cross_check_counts_as_held_and_a_bug_in_it_is_named():
    faithful = pd.DataFrame(_falling() + [dict(r, engine="mine", integrator=SEMI) for r in _falling()
                                          if r["engine"] == "core"])
    result = check_table(faithful, load_tolerances())
    assert result.passed and result.unbounded_series == []
    buggy = faithful.copy()
    planted = (buggy.engine == "mine") & (buggy.metric == END_EFFECTOR_ERROR_MAX) & (buggy.dt == 0.001)
    buggy.loc[planted, "value"] = 1.5 * ERROR  # a scheme degraded into another of its order, say
    found = check_table(buggy, load_tolerances()).violations
    assert [v.engine for v in found] == ["mine"]


USER_ARM = """
[scene]
name = "my-so100-falling"
kind = "joint_motion"
reference = "pinocchio"
[chain]
urdf = "example-robot-data:so_arm_description/urdf/so100.urdf"
[world]
gravity_world = [0.0, 0.0, -9.81]
[initial]
q = "random"
seed = 7
[simulation]
duration = 0.2
dt = [0.004, 0.002, 0.001]
"""
"""A user's own robot (the SO-100 arm of the example-robot-data wheel) falling from a random pose under gravity, its
damping as the file gives it: no shipped bound names it. Its steps are coarse (350 chain steps an integrator; a chain's
step is an articulated-body solve, ~1.6 ms in core): the planted bug's error grows with dt, so the coarse steps catch
it by a wider margin than MARGIN asks (measured: its joint angle 1.75 x its cross-check bound at 4 ms, 1.55 x at 2 ms;
at 1 / 0.5 / 0.25 ms over 0.25 s, at most 1.66 x, its joint velocity), and the faithful copy still passes with every
series held to a value (0 of 20 series without a value bound, as at the fine steps). Pinocchio is the built-in
that holds the copies: core itself would run the faithful copy's code again (7 of the run's 22 CPU-s) and
change no verdict (measured without it: the same ratios, 1.75 x at 4 ms, and 0 series without a value bound)."""

OLD_VELOCITY = next(m for m in MUTANTS if m.id == "joint_semi_implicit_old_velocity")
"""Semi-implicit Euler moving the joints with the old velocity (explicit Euler under the semi-implicit name): of the
same order, so only its error tells it."""

SEMI_ONLY = '''from {package}.{module} import {cls}


class SemiOnly({cls}):
    """The mutant offering only the scheme its bug is in: its other schemes are the faithful copy's code."""

    def joint_motion_integrators(self):
        return ("{scheme}",)
'''
"""A plugin module of the mutant offering semi-implicit Euler alone (its other four schemes ran the faithful copy's
code again: 40 % of the copies' stepping)."""


def _semi_only(mutant: CoreCopy) -> str:
    """The ``--engines`` spec of ``mutant`` restricted to :data:`SEMI` (its module written next to the copy)."""
    (mutant.root / "mutant_semi_only.py").write_text(SEMI_ONLY.format(
        package=mutant.package, module=PLUGIN_MODULE, cls=ENGINE_CLASS, scheme=SEMI), encoding="utf-8")
    return "mutant_semi_only:SemiOnly"


@pytest.mark.slow
def test_a_user_s_robot_falling_is_checked_passes_when_right_and_names_a_planted_bug(tmp_path, monkeypatch, capsys):
    """Before: 'unbounded: 13 of 21 series', check FAILED with 0 metrics outside their bounds, whatever the engines
    did; the planted bug's cross-check lines at 1.01-1.03 x their bound."""
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")  # the probes and workers import the copies
    faithful, mutant = materialise(None, tmp_path), materialise(OLD_VELOCITY, tmp_path)
    scene = tmp_path / "my-arm.toml"
    scene.write_text(USER_ARM, encoding="utf-8")
    engines = f"pinocchio,{faithful.spec},{_semi_only(mutant)}"
    code = main(["run", str(scene), "--quick", "--check", "--engines", engines,
                 "--out", str(tmp_path / "run"), "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    lines = capsys.readouterr().out.splitlines()
    violations = [line for line in lines if line.startswith("violation: ")]
    assert code == 1 and not [line for line in lines if line.startswith("unbounded: ")], "\n".join(lines[-20:])
    assert {line.split()[2] for line in violations} == {mutant.engine_name}  # "violation: scene engine ..."
    table, _ = read_run(tmp_path / "run")
    result = check_table(table[table.engine != mutant.engine_name], load_tolerances())
    assert result.passed and result.unbounded_share <= UNBOUNDED_SHARE_MAX  # right: passes, and checked
    planted = [v for v in check_table(table, load_tolerances()).violations if v.engine == mutant.engine_name]
    assert any(float(v.found.split()[0]) > MARGIN * float(v.bound.split()[1]) for v in planted)
