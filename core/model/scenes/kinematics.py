"""The forward-kinematics scene: :class:`KinematicsScene`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simparity.core.model.scenes.chain import Chain, sample_configurations
from simparity.core.model.scenes.suites import SweepPoint


@dataclass(frozen=True)
class KinematicsScene:
    """A chain whose FK and Jacobian are compared at seeded random configurations.

    Attributes
    ----------
    name, description, reference : str
    chain : Chain
    n_configurations : int
    seed : int
        Seed of the configuration sampler (uniform within limits, [-pi, pi] or
        [-1, 1] m where unlimited).
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
    n_configurations: int
    seed: int
    source: str = field(default="<code>", compare=False)
    suites: tuple[str, ...] = ("default",)
    sweep: SweepPoint | None = None
    kind: str = field(default="kinematics", init=False)

    def configurations(self) -> np.ndarray:
        """(n_configurations, n_joints) seeded random joint values within the limits."""
        return sample_configurations(self.chain, self.n_configurations, self.seed)
