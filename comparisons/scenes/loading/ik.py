"""An inverse-kinematics scene (``kind = "ik"``): ``[chain]`` and ``[targets]``."""

from __future__ import annotations

import numpy as np

from simparity.comparisons.scenes.limits import POSITION_TOLERANCE_OF_REACH, allowed_at_most
from simparity.comparisons.scenes.loading.chain import read_chain, within_limits
from simparity.comparisons.scenes.loading.reader import MAX_SEED, SAMPLES_WHY, TableReader
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.model.errors import echo
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.ik import HARD_TARGETS, IKScene

_TARGETS = ("count", "seed", "kind", "start", "position_tolerance", "orientation_tolerance", "max_iterations",
            "hard")
DEFAULT_POSITION_TOLERANCE = 1e-6  # [m], in any length unit the scene declares


def _start(t: TableReader, chain: Chain) -> np.ndarray:
    """The start pose: "zeros", "mid-range" (limits' middle, 0 where unlimited) or a list."""
    value = t.table.get("start", "zeros")
    allowed = f'"zeros", "mid-range" or a list of {chain.n_joints} numbers'
    if isinstance(value, list):
        prismatic = np.array([j.type == "prismatic" for j in chain.joints])
        q = t.vector("start", chain.n_joints) * np.where(prismatic, t.scale, 1.0)  # lengths in the scene's unit
    elif value in ("zeros", "mid-range"):
        limited = np.isfinite(chain.lower) & np.isfinite(chain.upper)  # continuous joints: 0, no inf - inf
        middle = 0.5 * np.where(limited, chain.lower, 0.0) + 0.5 * np.where(limited, chain.upper, 0.0)
        q = np.zeros(chain.n_joints) if value == "zeros" else middle
    else:
        raise t.fail("start", f"{echo(value)} is not allowed", allowed)
    return within_limits(t, "start", chain, q)


def _position_tolerance(t: TableReader, chain: Chain) -> float:
    """[m]; in its physical range and at most :data:`POSITION_TOLERANCE_OF_REACH` of the chain's reach."""
    if not t.has("position_tolerance"):
        return DEFAULT_POSITION_TOLERANCE
    value = t.number("position_tolerance", positive=True, length=1)
    most = POSITION_TOLERANCE_OF_REACH * reach_upper_bound(chain)[1]
    if value > most:
        raise t.fail("position_tolerance", f"{value:.3g} m is more than a tenth of the chain's reach: misses that "
                     "large would count as solved",
                     f"at most {POSITION_TOLERANCE_OF_REACH:g} x the chain's reach = {most:.3g} m")
    return value


def read_ik(top: TableReader, head: dict) -> IKScene:
    """The inverse-kinematics scene of the file's tables ``top``; ``head``: its ``[scene]`` keys."""
    chain = read_chain(top, head["name"])
    t = top.subtable("targets", _TARGETS)
    count = t.integer("count", 100, minimum=1, maximum=t.limits.max_samples, why=SAMPLES_WHY)
    iterations = t.integer("max_iterations", 200, minimum=1, maximum=t.limits.max_iterations)
    if count * iterations > t.limits.max_steps:
        raise t.fail("max_iterations", f"{count:,} targets x {iterations:,} iterations = {count * iterations:,} solver "
                     "iterations at worst", allowed_at_most(t.limits, "max_steps", "per solver"))
    return IKScene(
        chain=chain, n_targets=count, seed=t.integer("seed", 0, maximum=MAX_SEED),
        target_kind=t.string("kind", "pose", choices=("pose", "position")), q_start=_start(t, chain),
        position_tolerance=_position_tolerance(t, chain),
        orientation_tolerance=t.number("orientation_tolerance", 1e-6, positive=True),
        max_iterations=iterations, hard_targets=t.strings("hard", HARD_TARGETS, "unknown hard target {}") if t.has("hard") else (), **head,
    )
