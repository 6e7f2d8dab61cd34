"""``simparity bench``'s derivatives of the dynamics (issue #44): time per state of ∂τ/∂q, ∂τ/∂q̇ and the forward
partials on the ``articulated`` suite's real arms, each engine's own route against Pinocchio's analytic derivatives
measured in the same run, with each one's error against the complex-step truth.

- core: RNEA differentiated in forward mode, batched over B states (``core/articulated/derivatives.py``);
- Pinocchio: ``computeRNEADerivatives`` + ``computeABADerivatives``, one state per call through its adapter;
- MuJoCo: ``mjd_inverseFD`` (forward differences, two calls per state: q, then q̇), one state per call;
- core by central differences of its own batched inverse dynamics (step 1e-5, :mod:`comparisons.measure
  .finite_differences`): what a user without derivatives pays, and gets.

PyBullet has no derivatives (its rows in a run say so) and is not timed here.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from simparity.comparisons.bench.joint_dynamics import ARMS, ENGINE_STATES, SEED
from simparity.comparisons.bench.rows import Meter, by_batch
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.finite_differences import difference_partial
from simparity.comparisons.scenes import library

SECTION = "derivatives"
ENGINES = (("core", "recursive"), ("pinocchio", "recursive"), ("mujoco", "recursive"))
CENTRAL_STEP = 1e-5
"""[rad] The central-difference step of core's differenced row: near the bottom of the V (ε^(1/3)) on the arms, as
the step sweep of a run finds it."""
DIFFERENCED = ("core", "central differences")
ERROR_STATES = 20
"""States of each arm (its first) whose partials are compared with the complex-step truth."""
ENGINE_STATES_MAX = ENGINE_STATES // 5
"""States an adapter answering one per call is timed on: derivatives cost ~5 inverse dynamics, and the time per state
does not depend on B."""


def _states(scene, count: int) -> tuple[np.ndarray, ...]:
    from dataclasses import replace

    return replace(scene, n_states=count, seed=SEED).states()


def _own(model) -> Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """(∂τ/∂q, ∂τ/∂q̇) of ``model``'s own derivatives (its forward partials computed too, as a user gets them)."""
    def partials(q, qd, tau):
        found = model.derivatives(q, qd, tau)
        return found.dtau_dq, found.dtau_dqdot
    return partials


def _central(model) -> Callable[[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """(∂τ/∂q, ∂τ/∂q̇) by central differences of ``model``'s batched inverse dynamics at q̈ = its forward dynamics."""
    def partials(q, qd, tau):
        qdd, step = model.forward_dynamics(q, qd, tau), np.full(len(q), CENTRAL_STEP)
        return tuple(difference_partial(model.inverse_dynamics, q, qd, qdd, wrt, step, True) for wrt in ("q", "qdot"))
    return partials


def _error(partials: tuple[np.ndarray, np.ndarray], truth) -> float:
    """The larger relative error of (∂τ/∂q, ∂τ/∂q̇) against the truth's (max |D - T| over max |T|)."""
    return max(float(np.max(np.abs(d - t)) / np.max(np.abs(t))) for d, t in zip(partials, (truth.dtau_dq,
                                                                                          truth.dtau_dqdot)))


def derivative_rows(batches: list[int], median_time, row, say: Callable[[str], None]) -> list:
    """Bench rows (``row(section, workload, engine, method, batch, value, unit, accuracy, accuracy_unit, note)``) of
    every arm x route x batch, in us per state; ``median_time(fn)`` -> seconds."""
    from simparity.references.derivatives import complex_step

    rows = []
    for scene in library.load(list(ARMS)):
        judged = _states(scene, ERROR_STATES)
        truth = complex_step.derivatives(complex_step.tree_from_chain(scene.chain, scene.gravity_world),
                                         judged[0], judged[1], judged[3])
        routes = []
        for engine, method in ENGINES:
            model = make_engine(engine).build_joint_dynamics(scene.chain, method, scene.gravity_world)
            routes.append((engine, method, _own(model)))
            if (engine, method) == ("core", "recursive"):
                routes.append((*DIFFERENCED, _central(model)))
        for engine, method, partials in routes:
            error = _error(partials(judged[0], judged[1], judged[3]), truth)
            for batch in batches:
                count = batch if engine == "core" else min(batch, ENGINE_STATES_MAX)
                q, qd, _, tau = _states(scene, count)
                with Meter() as meter:
                    seconds = median_time(lambda: partials(q, qd, tau)) / count
                rows.append(meter.stamp(row(SECTION, scene.name, engine, method, batch, seconds * 1e6, "us/state",
                                            error, "1", "vs the complex-step truth")))
                say(f"  {scene.name:<15} {engine:<9} {method:<19} B={batch:<6} {seconds * 1e6:9.3f} us/state")
    return rows


def markdown_lines(rows: list) -> list[str]:
    """The BENCHMARKS.md section: a row per arm x route, a column per batch size, the time against Pinocchio's at the
    largest B (same run) and the error against the truth."""
    mine = [r for r in rows if r.section == SECTION]
    if not mine:
        return []
    batches = sorted({r.batch for r in mine})
    lines = ["## Derivatives of the dynamics (us per state; Pinocchio's time over each one's at the largest B; "
             "error against the complex-step truth)", "",
             "dtau/dq and dtau/dqdot with the forward partials: core's forward-mode RNEA (batched), Pinocchio's "
             "computeRNEADerivatives + computeABADerivatives and MuJoCo's mjd_inverseFD (one state per call, timed on "
             f"at most {ENGINE_STATES_MAX} states), and core's inverse dynamics by central differences (step "
             f"{CENTRAL_STEP:g}, RNEA partials only). A ratio above 1 is faster than Pinocchio.", "",
             "| arm | engine | method | " + " | ".join(f"B = {b:,}" for b in batches) + " | x Pinocchio | error |",
             "|---|---|---|" + "---|" * (len(batches) + 2)]
    for (arm, engine, method), cells, values, error in by_batch(mine):
        pinocchio = next((r for r in mine if (r.workload, r.engine, r.batch) == (arm, "pinocchio", batches[-1])), None)
        own = cells.get(batches[-1])
        ratio = (f"{pinocchio.value / own.value:.3g}" if pinocchio is not None and own is not None
                 and own.value > 0 else "n/a")
        lines.append(f"| {arm} | {engine} | {method} | {values} | {ratio} | {error:.1e} |")
    return lines + [""]
