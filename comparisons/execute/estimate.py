"""How long a run will take, said before its cases start: every case's cost modelled from the work its scene
asks for, the cases spread over the workers a group at a time.

A case costs :data:`CASE_OVERHEAD_SECONDS` (its child process forked, its engine's model built, its rows) plus its work
times the seconds one unit of that work took (:data:`SECONDS_PER_UNIT`): body-steps of a dynamics scene (of a penalty
stability search, the steps of the trials it runs: :func:`stability_steps`), IK targets, configurations, chain steps
times joints, and for joint-space dynamics the evaluations per state, each costing ``c n ** p`` for a chain of n
joints, p by the kind of scheme its method declares (:data:`JOINT_DYNAMICS_COST`: the lecture's sum over link Jacobians
is O(n^3) per evaluation, a recursive algorithm O(n)). A group's cases run one after the other in one worker, so a run
takes at least its costliest group, and at least its total over the workers. The model orders the groups (costliest
first) and gives the estimate; its constants were measured on 2 shared cores (2026-11-28, see each), so a faster
machine takes less and a loaded one more. While the cases run, the progress bar's time left is the modelled cost still
to run at the pace measured so far (:mod:`comparisons.execute.progress`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from simparity.comparisons.measure.stability import BISECTIONS, SEARCH_FACTOR, TRIAL_STEPS
from simparity.comparisons.execute.cases import (
    DYNAMICS,
    IK,
    JOINT_DYNAMICS,
    JOINT_MOTION,
    KINEMATICS,
    STABILITY,
    CaseGroup,
    CaseSpec,
)

CASE_OVERHEAD_SECONDS = 0.5
"""A case's cost beside its work [s]: a child forked from its worker, the engine's model of the scene built (PyBullet
starts a client, MuJoCo and Pinocchio read the model), its group's reference shared out, its rows assembled and sent
back. Fitted with the units below to the quick default suite (1,021 cases: 498 s on 2 workers, 2026-11-28)."""

SECONDS_PER_UNIT = {DYNAMICS: 5e-4, STABILITY: 5e-4, IK: 1.7e-2, KINEMATICS: 1.2e-4, JOINT_MOTION: 3e-4}
"""Seconds of one worker per unit of a case's work: a body-step (dynamics, the penalty stability search alike), an
IK target (random and hard: hard ones often run to ``max_iterations``), a configuration, a chain step per joint.
Dynamics and kinematics measured on the default suite (2026-11-23, 2 cores, repeats on); IK on a 3-joint arm's
sweep of 20 variants (2026-11-28: 174 s for 260 cases on 2 workers); chain motion on the quick articulated suite
(2026-11-28: 1,253 s for 603 cases on 2 workers, each time step's group sharing a DOP853 reference)."""

JOINT_DYNAMICS_COST = {"": (1, 1.7e-5), "jacobian_sum": (3, 2e-7)}
"""(p, c) by the kind of scheme a joint-dynamics method declares (:data:`core.model.engine.SCHEME_KINDS`; "" any
other): one evaluation at one state of a chain of n joints costs c n^p [s]. Recursive algorithms are O(n): c measured
on core's, the slowest built-in (0.044 s per inverse dynamics of a 128-joint chain at 20 states, 2026-11-28); the
lecture's sum over n link Jacobians of 3 x n into M (n x n) is O(n^3): 8.2 s there."""

JOINT_DYNAMICS_EVALUATIONS = 12
"""Evaluations per state of a joint-dynamics case beside the n of its mass-matrix identity (RNEA with each unit
acceleration): M, h, RNEA and ABA timed, the force scale, the other identities' and M's central differences."""

SEGMENT_FACTOR = 17
"""Steps a self-consistency segment costs per step of its time step: one run at dt and one at dt / 16."""


def stability_steps(scene) -> int:
    """The steps a penalty stability search on ``scene`` (a dynamics scene) runs, as
    :func:`comparisons.measure.stability.stable_dt_max` searches: its first trial at the finest step tried (at most
    :data:`~comparisons.measure.stability.TRIAL_STEPS`), the octaves above it (together as many steps again), and
    :data:`~comparisons.measure.stability.BISECTIONS` trials between two octaves, each modelled at the scene's finest
    step of its own (the limit is not known before it is measured). Its ladder's steps alone are what one dynamics case
    runs: the quick profile's lecture-bouncing-particle searched 5 penalty schemes for 4 minutes at the end of a
    10-minute run (2026-11-29, load 12 on 2 cores), modelled at 10 s and therefore run last."""
    finest = max(min(scene.dts) / SEARCH_FACTOR, scene.duration / TRIAL_STEPS)
    return 2 * scene.n_steps(finest) + BISECTIONS * scene.n_steps(min(scene.dts))


def case_seconds(group: CaseGroup, scheme: str = "") -> float:
    """The modelled cost [s] of one case of ``group`` on one worker; ``scheme``: the kind of scheme the case's engine
    declares its integrator or method to be ("" unknown)."""
    if group.kind == JOINT_DYNAMICS:
        n = group.joint_dynamics_scene.chain.n_joints
        power, seconds = JOINT_DYNAMICS_COST.get(scheme.split("+")[0], JOINT_DYNAMICS_COST[""])
        evaluations = group.joint_dynamics_scene.n_states * (n + JOINT_DYNAMICS_EVALUATIONS)
        return CASE_OVERHEAD_SECONDS + evaluations * seconds * float(n) ** power
    if group.kind in (DYNAMICS, STABILITY):
        s = group.dynamics_scene
        work = float((s.n_steps(group.dt) if group.kind == DYNAMICS else stability_steps(s)) * len(s.bodies))
    elif group.kind == IK:
        work = float(group.ik_scene.n_targets + len(group.ik_scene.hard_targets))
    elif group.kind == JOINT_MOTION:
        m = group.joint_motion_scene
        work = float(m.n_steps(group.dt) * m.copies * (SEGMENT_FACTOR if m.segments else 1) * m.chain.n_joints)
    else:
        work = float(group.kinematics_scene.n_configurations)
    return CASE_OVERHEAD_SECONDS + work * SECONDS_PER_UNIT[group.kind]


SchemeOf = Callable[[CaseGroup, CaseSpec], str]
"""The kind of scheme a case's engine declares for its integrator or method on the group's scene ("" unknown)."""


def _unknown(group: CaseGroup, spec: CaseSpec) -> str:
    return ""


def _cost(group: CaseGroup, spec: CaseSpec, scheme_of: SchemeOf) -> float:
    """:func:`case_seconds` of ``spec``, its engine asked for its scheme only where the cost depends on it (an engine
    of the references re-derives the scene to answer: 1.4 ms a case, 18 s on a sweep of 1,000 IK variants)."""
    return case_seconds(group, scheme_of(group, spec) if group.kind == JOINT_DYNAMICS else "")


def group_seconds(group: CaseGroup, scheme_of: SchemeOf = _unknown, skip: frozenset[int] = frozenset()) -> float:
    """The modelled cost [s] of ``group``'s cases (those not in ``skip``) run one after the other in one worker."""
    return sum(_cost(group, spec, scheme_of) for c, spec in enumerate(group.cases) if c not in skip)


@dataclass(frozen=True)
class RunEstimate:
    """What a run's cases will cost: ``cases`` to run, ``seconds`` [s] of wall time on ``workers`` (``total_seconds``
    on one), its costliest case (``costliest``: scene, engine, integrator or method; ``costliest_seconds``), and
    ``by_case``: the modelled cost [s] of a case by (scene, engine, integrator) (the mean over a scene's time steps)."""

    cases: int
    seconds: float
    workers: int
    total_seconds: float = 0.0
    costliest: tuple[str, str, str] = ("", "", "")
    costliest_seconds: float = 0.0
    by_case: dict[tuple[str, str, str], float] = field(default_factory=dict, compare=False)

    def line(self, case_limit_seconds: float | None = None) -> str:
        """One line: the estimate and, when a case is modelled to outlast ``case_limit_seconds``, which and how to
        let it finish."""
        text = (f"estimated {duration(self.seconds)} for {self.cases:,} cases on {self.workers} "
                f"worker{'s' if self.workers != 1 else ''} (modelled from each case's work; a loaded machine takes "
                "longer)")
        if case_limit_seconds is not None and self.costliest_seconds > case_limit_seconds:
            scene, engine, integrator = self.costliest
            text += (f"; the costliest case, {scene} {engine} {integrator}".rstrip() + f", is modelled at "
                     f"{duration(self.costliest_seconds)}, past the per-case limit of {duration(case_limit_seconds)}: "
                     "it will be killed unless --case-timeout is raised")
        return text


def estimate_run(groups: list[tuple[CaseGroup, frozenset[int]]], workers: int,
                 scheme_of: SchemeOf = _unknown) -> RunEstimate:
    """The :class:`RunEstimate` of ``groups`` (each with the indices of its cases already done, not run again) on
    ``workers`` workers: the larger of the total over the workers and the costliest group (its cases share one
    worker)."""
    total, longest, cases = 0.0, 0.0, 0
    costliest, costliest_seconds = ("", "", ""), 0.0
    by_case: dict[tuple[str, str, str], list[float]] = {}
    for group, skip in groups:
        seconds = 0.0
        for c, spec in enumerate(group.cases):
            if c in skip:
                continue
            one, key = _cost(group, spec, scheme_of), (group.scene.name, spec.engine, spec.integrator)
            seconds, cases = seconds + one, cases + 1
            by_case.setdefault(key, []).append(one)
            if one > costliest_seconds:
                costliest, costliest_seconds = key, one
        total, longest = total + seconds, max(longest, seconds)
    workers = max(1, workers)
    return RunEstimate(cases, max(total / workers, longest), workers, total, costliest, costliest_seconds,
                       {key: sum(costs) / len(costs) for key, costs in by_case.items()})


def duration(seconds: float) -> str:
    """``12s``, ``4m05s``, ``2h10m``."""
    whole = int(round(seconds))
    if whole < 60:
        return f"{whole}s"
    return f"{whole // 3600}h{whole // 60 % 60:02d}m" if whole >= 3600 else f"{whole // 60}m{whole % 60:02d}s"
