"""The inverse-kinematics scene: :class:`IKScene` and the hard targets it may ask for."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.scenes.chain import Chain, sample_configurations
from simparity.core.model.scenes.suites import SweepPoint

HARD_TARGETS = ("stretched", "beyond_reach", "at_base", "near_limits", "beyond_limits", "orientation_in_place",
                "wrist_flip")
"""Hard IK targets a scene may ask for (see ``comparisons.execute.ik_targets``)."""


@dataclass(frozen=True)
class IKScene:
    """A chain, seeded random reachable targets and hard targets for every IK solver.

    Attributes
    ----------
    name, description : str
    reference : str
        Engine whose forward kinematics generates the targets and judges cross-evaluation.
    chain : Chain
    n_targets : int
        Random reachable targets: the end-effector poses of seeded random configurations.
    seed : int
    target_kind : str
        ``"pose"`` (position and orientation) or ``"position"``.
    q_start : (n,) ndarray
        The one start configuration of every solve [rad or m] (also the rest pose).
    position_tolerance : float
        [m].
    orientation_tolerance : float
        [rad].
    max_iterations : int
    hard_targets : tuple of str
        Names from :data:`HARD_TARGETS`.
    source : str
    suites : tuple of str
        The built-in suites (:data:`SUITES`) the scene belongs to.
    sweep : SweepPoint or None
        For a variant of a file with a ``[sweep]``: its base scene and swept values; None otherwise.
    """

    name: str
    description: str
    reference: str
    chain: Chain
    n_targets: int
    seed: int
    target_kind: str
    q_start: np.ndarray
    position_tolerance: float
    orientation_tolerance: float
    max_iterations: int
    hard_targets: tuple[str, ...] = ()
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="ik", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "q_start", readonly(self.q_start, shape=(self.chain.n_joints,)))

    def configurations(self) -> np.ndarray:
        """(n_targets, n) seeded random configurations within the limits (as KinematicsScene)."""
        return sample_configurations(self.chain, self.n_targets, self.seed)
